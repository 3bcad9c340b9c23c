// Material parameters (group 2), shared by every pass that needs a surface's colour: the
// uniform and the sampler; the texture bindings belong to the variant files that read them.

struct Material {
    // Linear RGBA, multiplied with the base colour texture.
    base_color_factor: vec4<f32>,
    // Blinn-Phong specular colour (rgb) and exponent (a).
    specular_shininess: vec4<f32>,
    // x: alpha cutoff for masked materials; y: 1 when double-sided.
    alpha_cutoff_double_sided: vec4<f32>,
    // Emitted radiance (rgb, linear), multiplied with the emissive texture; w unused.
    emissive: vec4<f32>,
}

// This draw's material.
@group(2) @binding(0) var<uniform> material: Material;
// Trilinear, repeating sampler for all material textures.
@group(2) @binding(1) var material_sampler: sampler;
