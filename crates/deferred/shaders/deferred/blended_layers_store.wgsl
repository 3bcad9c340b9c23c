// The blended layers' store pass (`blended_layers.wgsl`): every blended fragment in front
// of the opaque surface, without lighting, becomes a node of its pixel's list. The depth
// test is the shader's own: a fragment shader that writes storage runs before the
// pipeline's depth test may reject it (the test is then late), so the pipeline's would
// not keep hidden fragments out of the lists.

#import manylights::common::view::view
#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface
#import manylights::deferred::blended_layers::{
    LayerNode, LayerCounters, LAYER_PLANES, LINK_PLANE, layer_node, node_planes
}

// Each pixel's first layer (node index plus one; zero: none), row by row.
@group(3) @binding(0) var<storage, read_write> layer_heads: array<atomic<u32>>;
// The nodes, in LAYER_PLANES planes.
@group(3) @binding(1) var<storage, read_write> layer_nodes: array<vec4<u32>>;
@group(3) @binding(2) var<storage, read_write> layer_counters: LayerCounters;
// The opaque frame's depth (the pass attaches it read-only).
@group(3) @binding(3) var opaque_depth: texture_depth_2d;

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

// Whether fragment depth `depth` is nearer than `opaque`, as the forward blended pass's
// depth test (strictly nearer) decides it: the empty pixels' depth (`near_far.z`) is the
// far end, 1 or (reverse-Z) 0.
fn in_front(depth: f32, opaque: f32) -> bool {
    if view.near_far.z > 0.5 {
        return depth < opaque;
    }
    return depth > opaque;
}

@fragment
fn fs_store_layer(in: VertexOutput, @builtin(front_facing) front_facing: bool) {
    // The material first: it samples textures with implicit derivatives, which WGSL
    // allows only in uniform control flow, before any return (Tint refuses it after
    // one; the page's sponza-glass found it).
    let surface = fragment_surface(in, front_facing);
    let pixel = vec2<u32>(in.clip_position.xy);
    if !in_front(in.clip_position.z, textureLoad(opaque_depth, pixel, 0)) {
        return;
    }
    // A layer of alpha 0 leaves what is behind it exactly as it was ("over").
    if !(surface.alpha > 0.0) {
        return;
    }
    let claimed = atomicAdd(&layer_counters.claimed, 1u);
    let capacity = arrayLength(&layer_nodes) / LAYER_PLANES;
    if claimed >= capacity {
        // The pool is full: counted (`claimed` passes its size), reported by the lab.
        return;
    }
    let view_depth = -(view.view * vec4<f32>(surface.position, 1.0)).z;
    let node = layer_node(surface, view_depth);
    // The planes without the link first: their stores need not wait for the exchange's
    // answer (H200, sponza-glass inside: 1.70 -> 1.60 ms).
    let planes = node_planes(node);
    for (var plane = 0u; plane < LAYER_PLANES; plane++) {
        if plane != LINK_PLANE {
            layer_nodes[plane * capacity + claimed] = planes[plane];
        }
    }
    let width = u32(view.viewport.x);
    let next = atomicExchange(&layer_heads[pixel.y * width + pixel.x], claimed + 1u);
    layer_nodes[LINK_PLANE * capacity + claimed] = vec4<u32>(planes[LINK_PLANE].xyz, next);
}
