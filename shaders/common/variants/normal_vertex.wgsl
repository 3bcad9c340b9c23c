// Variant: no normal maps; the interpolated vertex normal is the surface normal.

struct VertexInput {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

fn vertex_tangent(vertex: VertexInput) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn surface_normal(in: VertexOutput) -> vec3<f32> {
    return normalize(in.world_normal);
}
