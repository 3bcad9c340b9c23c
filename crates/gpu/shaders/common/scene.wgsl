// Scene geometry shared by every pass that rasterises the scene: per-instance transforms
// (group 1), the vertex input (with a tangent stream only for normal-mapped scenes) and the
// vertex transform into world and clip space.

#import manylights::common::view::view

struct VertexInput {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
#ifdef NORMAL_MAP
    @location(3) tangent: vec4<f32>,
#endif
}

fn vertex_tangent(vertex: VertexInput) -> vec4<f32> {
#ifdef NORMAL_MAP
    return vertex.tangent;
#else
    return vec4<f32>(0.0);
#endif
}

struct InstanceData {
    // Object to world.
    model: mat4x4<f32>,
    // Inverse transpose of the model matrix's upper 3x3 (columns padded to vec4).
    normal_matrix: mat4x4<f32>,
}

// One entry per instance, indexed by the draw's instance index.
@group(1) @binding(0) var<storage, read> instances: array<InstanceData>;

struct VertexOutput {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // xyz: world tangent, w: bitangent sign; zero when the scene has no normal maps.
    @location(3) world_tangent: vec4<f32>,
}

fn scene_vertex(vertex: VertexInput, instance_index: u32) -> VertexOutput {
    let instance = instances[instance_index];
    let world = instance.model * vec4<f32>(vertex.position, 1.0);
    let normal_matrix = mat3x3<f32>(instance.normal_matrix[0].xyz, instance.normal_matrix[1].xyz, instance.normal_matrix[2].xyz);
    let tangent = vertex_tangent(vertex);
    var out: VertexOutput;
    out.clip_position = view.view_proj * world;
    out.world_position = world.xyz;
    out.world_normal = normal_matrix * vertex.normal;
    out.uv = vertex.uv;
    // Tangents transform with the model matrix (they lie in the surface).
    let model3 = mat3x3<f32>(instance.model[0].xyz, instance.model[1].xyz, instance.model[2].xyz);
    out.world_tangent = vec4<f32>(model3 * tangent.xyz, tangent.w);
    return out;
}
