// Variant: a material of the scene emits light (emissive factor, optionally textured).

#import manylights::common::material_bindings::{material, sample_material}

// Emissive texture (sRGB; a 1x1 white texture for materials without one).
@group(2) @binding(4) var emissive_texture: texture_2d<f32>;

// Radiance the surface emits: factor (times KHR_materials_emissive_strength) x texture.
fn sample_emission(uv: vec2<f32>) -> vec3<f32> {
    return material.emissive.rgb * sample_material(emissive_texture, uv).rgb;
}
