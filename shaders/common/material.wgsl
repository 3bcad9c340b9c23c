// Material parameters (group 2), shared by every pass that needs a surface's colour.
// The texture bindings and the functions that read them come from the variant parts, so a
// scene without textures or normal maps gets shaders without them.

struct Material {
    // Linear RGBA, multiplied with the base colour texture.
    base_color_factor: vec4<f32>,
    // Blinn-Phong specular colour (rgb) and exponent (a).
    specular_shininess: vec4<f32>,
    // x: alpha cutoff for masked materials; y: 1 when double-sided.
    alpha_cutoff_double_sided: vec4<f32>,
}

// This draw's material.
@group(2) @binding(0) var<uniform> material: Material;
// Trilinear, repeating sampler for all material textures.
@group(2) @binding(1) var material_sampler: sampler;

// Builds the surface at a fragment: base colour, alpha test, and a unit normal facing the
// viewer's side for double-sided materials.
fn fragment_surface(in: VertexOutput, front_facing: bool) -> Surface {
    // Sample every texture before the alpha test: after a discard, control flow is no
    // longer uniform and implicit-derivative sampling is not allowed.
    let base = sample_base_color(in.uv);
    var normal = surface_normal(in);
    apply_alpha_mask(base.a);
    if !front_facing && material.alpha_cutoff_double_sided.y > 0.5 {
        normal = -normal;
    }
    var surface: Surface;
    surface.position = in.world_position;
    surface.normal = normal;
    surface.albedo = base.rgb;
    surface.alpha = base.a;
    surface.specular = material.specular_shininess.rgb;
    surface.shininess = material.specular_shininess.a;
    return surface;
}
