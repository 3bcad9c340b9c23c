// Variant: no material of the scene has a base colour texture.

#import manylights::common::material_bindings::material

fn sample_base_color(uv: vec2<f32>) -> vec4<f32> {
    return material.base_color_factor;
}
