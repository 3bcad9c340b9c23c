// manylights' BRDF for an engine's own light loop: glTF 2.0's metallic-roughness, as
// every manylights pipeline and its f64 reference shade it (`brdf.wgsl`'s
// `surface_for_loop` and `brdf_of_loop`), with no binding of its own. The engine makes
// the surface once per pixel and asks each light's term inside its loop:
//
//     let surface = pbr_surface(world, normal, view_dir, base_color, metallic, roughness);
//     for ... each light that reaches the point ... {
//         let l = normalize(light.position - world);
//         radiance += light.color * light.intensity * its_falloff * pbr_reflected(surface, view_dir, l);
//     }
//
// `lights::pbr_wgsl` gives it as one source with every name prefixed (`manylights_`).

#import manylights::common::surface::{Surface, DIELECTRIC_F0}
#import manylights::lights::brdf::{LitSurface, surface_for_loop, brdf_of_loop}

// The surface at `position` (world space) with unit `normal`, seen from the unit direction
// `view_dir` (from the point to the eye), of glTF's base colour (linear), metallic and
// perceptual roughness: what depends on the pixel alone, worked out once before the loop.
fn pbr_surface(position: vec3<f32>, normal: vec3<f32>, view_dir: vec3<f32>, base_color: vec3<f32>, metallic: f32, roughness: f32) -> LitSurface {
    let surface = Surface(
        position,
        normal,
        base_color * (1.0 - metallic),
        1.0,
        mix(vec3<f32>(DIELECTRIC_F0), base_color, metallic),
        roughness,
        vec3<f32>(0.0),
        0.0,
    );
    return surface_for_loop(surface, view_dir);
}

// The radiance towards the eye per unit of irradiance (colour x intensity x falloff)
// arriving from the unit direction `l` (from the point to the light): the BRDF times n.l,
// zero for light from behind the surface.
fn pbr_reflected(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let n_dot_l = dot(surface.normal, l);
    if n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    return brdf_of_loop(surface, view_dir, l, n_dot_l) * n_dot_l;
}
