// Material parameters (group 2), shared by every pass that needs a surface's colour: the
// uniform and the sampler; the texture bindings belong to the variant files that read them.

#import manylights::common::view::view

struct Material {
    // Linear RGBA, multiplied with the base colour texture.
    base_color_factor: vec4<f32>,
    // Blinn-Phong specular colour (rgb) and exponent (a).
    specular_shininess: vec4<f32>,
    // x: alpha cutoff for masked materials; y: 1 when double-sided.
    alpha_cutoff_double_sided: vec4<f32>,
    // Emitted radiance (rgb, linear), multiplied with the emissive texture; w unused.
    emissive: vec4<f32>,
    // glTF's metallic (x) and perceptual roughness (y) factors, multiplied with the
    // metallic-roughness texture's blue and green; zw unused.
    metallic_roughness: vec4<f32>,
}

// This draw's material.
@group(2) @binding(0) var<uniform> material: Material;
// Trilinear, repeating sampler for all material textures.
@group(2) @binding(1) var material_sampler: sampler;

#ifdef EXPLICIT_UV_GRADIENTS
// The UV's change one pixel across (xy) and one pixel down (zw) the screen, set by a
// compute pass that rebuilds a surface before it samples the material: compute shaders
// have no implicit derivatives (the visibility buffer's resolve).
var<private> uv_gradients: vec4<f32>;
#endif

// A material texture sampled at `uv`, its mip level from the fragment's implicit
// derivatives, or in compute from `uv_gradients`, moved by the view's mip bias.
fn sample_material(texture: texture_2d<f32>, uv: vec2<f32>) -> vec4<f32> {
    let bias = view.texture_lod_bias.x;
#ifdef EXPLICIT_UV_GRADIENTS
    // A bias of b scales the footprint by 2^b.
    let scale = exp2(bias);
    return textureSampleGrad(
        texture,
        material_sampler,
        uv,
        uv_gradients.xy * scale,
        uv_gradients.zw * scale,
    );
#else
    return textureSampleBias(texture, material_sampler, uv, bias);
#endif
}
