// Variant: the scene has base colour textures.

#import manylights::common::material_bindings::{material, sample_material}

// Base colour texture (sRGB; a 1x1 white texture for materials without one).
@group(2) @binding(2) var base_color_texture: texture_2d<f32>;

fn sample_base_color(uv: vec2<f32>) -> vec4<f32> {
    return material.base_color_factor * sample_material(base_color_texture, uv);
}
