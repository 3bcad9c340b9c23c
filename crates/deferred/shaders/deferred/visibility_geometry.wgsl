// The scene's geometry read from storage (group 3) by the visibility buffer's passes, which
// fetch their vertices themselves: the raster, so that a fragment knows its triangle
// without the optional primitive-index feature (WebGPU lacks it on many adapters), and the
// resolve, which rebuilds a pixel's surface from its triangle.

#import manylights::common::scene::VertexInput

// Mirrors `GpuInstanceMesh`: what a pass needs of an instance besides its transform.
struct InstanceMesh {
    // Added to the mesh's indices, which count from its first vertex.
    base_vertex: i32,
    material: u32,
    // The mesh's first triangle in the index buffer (its first index over 3).
    first_triangle: u32,
}

// `GpuVertex` as floats: position xyz, normal xyz, uv (WGSL would pad a vec3 to 16 bytes).
@group(3) @binding(0) var<storage, read> vertex_floats: array<f32>;
// Every mesh's indices; triangle t of the scene is indices 3t, 3t + 1, 3t + 2.
@group(3) @binding(1) var<storage, read> indices: array<u32>;
@group(3) @binding(2) var<storage, read> instance_meshes: array<InstanceMesh>;
#ifdef NORMAL_MAP
// xyz: tangent, w: bitangent sign, per vertex.
@group(3) @binding(3) var<storage, read> vertex_tangents: array<vec4<f32>>;
#endif

const FLOATS_PER_VERTEX: u32 = 8u;

// The vertex at `index_position` of the index buffer, as `instance` draws it.
fn pulled_vertex(index_position: u32, instance: u32) -> VertexInput {
    let vertex = u32(i32(indices[index_position]) + instance_meshes[instance].base_vertex);
    let first = vertex * FLOATS_PER_VERTEX;
    var input: VertexInput;
    input.position = vec3<f32>(vertex_floats[first], vertex_floats[first + 1u], vertex_floats[first + 2u]);
    input.normal = vec3<f32>(vertex_floats[first + 3u], vertex_floats[first + 4u], vertex_floats[first + 5u]);
    input.uv = vec2<f32>(vertex_floats[first + 6u], vertex_floats[first + 7u]);
#ifdef NORMAL_MAP
    input.tangent = vertex_tangents[vertex];
#endif
    return input;
}

// The material `instance` is drawn with.
fn instance_material(instance: u32) -> u32 {
    return instance_meshes[instance].material;
}

// The first triangle of the mesh `instance` draws.
fn instance_first_triangle(instance: u32) -> u32 {
    return instance_meshes[instance].first_triangle;
}
