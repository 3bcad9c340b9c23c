// Blended surfaces (glTF's `BLEND`) as deferred shades them on its compute paths: a
// fragment pass without lighting stores every blended fragment in front of the opaque
// surface as a layer of its pixel (`blended_layers_store.wgsl`), and a compute pass shades
// each pixel's layers with the cluster light loop and composites them over the opaque
// frame (`blended_layers_shade.wgsl`). This module is what the two passes share: the
// layer record and the store's bindings' shapes.

#define_import_path manylights::deferred::blended_layers

#import manylights::common::surface::Surface

// Layers a pixel composites sorted by depth, back to front, exactly as the "over"
// operator does. The pixel's farther layers (beyond this many) are merged by weighted
// blended transparency (`weighted_blended.wgsl`) and laid under the sorted ones
// (`deferred::SORTED_LAYERS`, 4).
const SORTED_LAYERS: u32 = #SORTED_LAYERS;

// A pixel's list ends here (`LayerNode::next`, `layer_heads`): node indices are stored
// plus one, so that a cleared (zero) buffer holds empty lists.
const END_OF_LIST: u32 = 0u;

// One stored layer: the surface as the blended material built it, every attribute in f32
// (the forward blended pass shades these very values), 64 bytes, 80 in scenes with
// emission (EMISSIVE).
struct LayerNode {
    // Camera-relative world position (`Surface::position`), and its distance before the
    // camera along the view axis (the sort key).
    position: vec3<f32>,
    view_depth: f32,
    normal: vec3<f32>,
    alpha: f32,
    albedo: vec3<f32>,
    lobe: f32,
    specular: vec3<f32>,
    // The pixel's next layer (index plus one), or END_OF_LIST.
    next: u32,
    // Zero without EMISSIVE.
    emission: vec3<f32>,
}

// The pool holds its nodes as four planes of 16 bytes, plane k of node i at
// k x (the pool's size) + i (`LAYER_PLANES`): the fragments of a warp claim consecutive
// nodes, so each of the four stores of a warp writes one contiguous run. As an array of
// 64-byte nodes each store wrote 16 bytes of every 64: the store pass took 8.7 ms for
// sponza-glass's 4 million layers (H200), 3.5 with 16-byte stores, against the planes'
// (docs/architecture/transparency.md).
// The link is in the fourth plane (`LINK_PLANE`); emission, with EMISSIVE, in a fifth.
#ifdef EMISSIVE
const LAYER_PLANES: u32 = 5u;
#else
const LAYER_PLANES: u32 = 4u;
#endif
const LINK_PLANE: u32 = 3u;

fn node_planes(node: LayerNode) -> array<vec4<u32>, LAYER_PLANES> {
    return array<vec4<u32>, LAYER_PLANES>(
        bitcast<vec4<u32>>(vec4<f32>(node.position, node.view_depth)),
        bitcast<vec4<u32>>(vec4<f32>(node.normal, node.alpha)),
        bitcast<vec4<u32>>(vec4<f32>(node.albedo, node.lobe)),
        vec4<u32>(bitcast<vec3<u32>>(node.specular), node.next),
#ifdef EMISSIVE
        vec4<u32>(bitcast<vec3<u32>>(node.emission), 0u),
#endif
    );
}

fn node_from_planes(planes: array<vec4<u32>, LAYER_PLANES>) -> LayerNode {
    let first = bitcast<vec4<f32>>(planes[0]);
    let second = bitcast<vec4<f32>>(planes[1]);
    let third = bitcast<vec4<f32>>(planes[2]);
    var emission = vec3<f32>(0.0);
#ifdef EMISSIVE
    emission = bitcast<vec3<f32>>(planes[4].xyz);
#endif
    return LayerNode(first.xyz, first.w, second.xyz, second.w, third.xyz, third.w, bitcast<vec3<f32>>(planes[LINK_PLANE].xyz), planes[LINK_PLANE].w, emission);
}

// The pool's counters: nodes claimed (may pass the pool's size: those past it were not
// stored), and pixels whose layers outnumbered SORTED_LAYERS (merged by weight). One
// counter for the whole pool: a warp's fragments claim consecutive nodes with one atomic
// (the compiler aggregates atomics on one address) and write them side by side. A counter
// for each of 4,096 bins of the pool, the pixels hashed to them, measured 24.4 ms against
// 8.7 for the store pass (H200, sponza-glass inside).
struct LayerCounters {
    claimed: atomic<u32>,
    merged_pixels: atomic<u32>,
}

fn layer_node(surface: Surface, view_depth: f32) -> LayerNode {
    return LayerNode(surface.position, view_depth, surface.normal, surface.alpha, surface.albedo, surface.lobe, surface.specular, END_OF_LIST, surface.emission);
}

fn layer_surface(node: LayerNode) -> Surface {
    var surface: Surface;
    surface.position = node.position;
    surface.normal = node.normal;
    surface.albedo = node.albedo;
    surface.alpha = node.alpha;
    surface.specular = node.specular;
    surface.lobe = node.lobe;
    surface.emission = node.emission;
    // Interpolated by the rasterizer, as the forward pass's.
    surface.position_error = 0.0;
    return surface;
}
