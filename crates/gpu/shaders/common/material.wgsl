// The surface at a fragment from its material (group 2, `material_bindings.wgsl`). The
// texture bindings and the functions that read them come from the variant files, chosen by
// the program's material variant, so a scene without textures or normal maps gets shaders
// without them.

#import manylights::common::scene::VertexOutput
#import manylights::common::surface::{Surface, DIELECTRIC_F0}
#import manylights::common::material_bindings::material
#ifdef BASE_COLOR_TEXTURE
#import manylights::common::variants::base_color_textured::sample_base_color
#else
#import manylights::common::variants::base_color_flat::sample_base_color
#endif
#ifdef NORMAL_MAP
#import manylights::common::variants::normal_mapped::surface_normal
#else
#import manylights::common::variants::normal_vertex::surface_normal
#endif
#ifdef SHADING_PBR
#ifdef METALLIC_ROUGHNESS_TEXTURE
#import manylights::common::variants::metallic_roughness_textured::sample_metallic_roughness
#else
#import manylights::common::variants::metallic_roughness_flat::sample_metallic_roughness
#endif
#endif
#ifdef EMISSIVE
#import manylights::common::variants::emissive::sample_emission
#else
#import manylights::common::variants::emissive_none::sample_emission
#endif
#ifdef EXPLICIT_UV_GRADIENTS
// A surface rebuilt in compute was cut by its alpha mask when it was rasterised.
#import manylights::common::variants::alpha_opaque::apply_alpha_mask
#else
#ifdef ALPHA_MASK
#import manylights::common::variants::alpha_mask::apply_alpha_mask
#else
#import manylights::common::variants::alpha_opaque::apply_alpha_mask
#endif
#endif

// Builds the surface at a fragment: base colour, alpha test, and a unit normal facing the
// viewer's side for double-sided materials.
fn fragment_surface(in: VertexOutput, front_facing: bool) -> Surface {
    // Sample every texture before the alpha test: after a discard, control flow is no
    // longer uniform and implicit-derivative sampling is not allowed.
    let base = sample_base_color(in.uv);
    let emission = sample_emission(in.uv);
#ifdef SHADING_PBR
    let metallic_roughness = sample_metallic_roughness(in.uv);
#endif
    var normal = surface_normal(in);
    apply_alpha_mask(base.a);
    if !front_facing && material.alpha_cutoff_double_sided.y > 0.5 {
        normal = -normal;
    }
    var surface: Surface;
    surface.position = in.world_position;
    surface.normal = normal;
    surface.alpha = base.a;
#ifdef SHADING_PBR
    // glTF's metallic-roughness (its Appendix B): a metal reflects its base colour
    // specularly and nothing diffusely; a dielectric reflects 4% at normal incidence.
    let metallic = saturate(metallic_roughness.x);
    surface.albedo = base.rgb * (1.0 - metallic);
    surface.specular = mix(vec3<f32>(DIELECTRIC_F0), base.rgb, metallic);
    surface.lobe = saturate(metallic_roughness.y);
#else
    surface.albedo = base.rgb;
    surface.specular = material.specular_shininess.rgb;
    surface.lobe = material.specular_shininess.a;
#endif
    surface.emission = emission;
    return surface;
}
