// Variant: no normal maps; the interpolated vertex normal is the surface normal.

#import manylights::common::scene::VertexOutput

fn surface_normal(in: VertexOutput) -> vec3<f32> {
    return normalize(in.world_normal);
}
