// Variant: the scene has normal maps; vertices carry tangents in a second stream.

#import manylights::common::scene::VertexOutput
#import manylights::common::material_bindings::sample_material

// Tangent-space normal map (linear; a flat 1x1 map for materials without one).
@group(2) @binding(3) var normal_texture: texture_2d<f32>;

fn surface_normal(in: VertexOutput) -> vec3<f32> {
    let n = normalize(in.world_normal);
    // Gram-Schmidt: interpolation leaves the tangent slightly off perpendicular.
    let t = normalize(in.world_tangent.xyz - n * dot(n, in.world_tangent.xyz));
    let b = cross(n, t) * in.world_tangent.w;
    let texel = sample_material(normal_texture, in.uv).xyz * 2.0 - 1.0;
    let mapped = t * texel.x + b * texel.y + n * texel.z;
    // A degenerate texel (all zero) keeps the geometric normal instead of NaN.
    let length_squared = dot(mapped, mapped);
    return select(n, mapped * inverseSqrt(length_squared), length_squared > 1e-12);
}
