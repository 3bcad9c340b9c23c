// Variant: PBR shading of a scene without metallic-roughness textures.

#import manylights::common::material_bindings::material

// Metallic (x) and perceptual roughness (y): the material's factors.
fn sample_metallic_roughness(uv: vec2<f32>) -> vec2<f32> {
    return material.metallic_roughness.xy;
}
