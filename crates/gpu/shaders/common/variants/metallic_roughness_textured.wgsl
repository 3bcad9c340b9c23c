// Variant: PBR shading of a scene with metallic-roughness textures.

#import manylights::common::material_bindings::{material, sample_material}

// glTF's metallic-roughness texture (linear: roughness in green, metallic in blue; a 1x1
// white texture for materials without one).
@group(2) @binding(5) var metallic_roughness_texture: texture_2d<f32>;

// Metallic (x) and perceptual roughness (y): the factors times the texture.
fn sample_metallic_roughness(uv: vec2<f32>) -> vec2<f32> {
    let texel = sample_material(metallic_roughness_texture, uv);
    return material.metallic_roughness.xy * texel.bg;
}
