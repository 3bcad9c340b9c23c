// The blended layers' shading pass (`blended_layers.wgsl`), after the opaque frame is lit
// (and its shadows filtered): every pixel walks its list of layers, keeps the
// SORTED_LAYERS nearest in depth order, shades each layer with the cluster light loop the
// forward blended pass runs (`cluster/blended.wgsl`: the cluster found from the layer's
// own depth) and composites them back to front with the "over" operator over the opaque
// frame. Layers beyond the nearest SORTED_LAYERS are merged first, by weighted blended
// transparency (McGuire and Bavoil 2013, the weights of `weighted_blended.wgsl`), and laid
// over the opaque frame under the sorted ones: exact for one merged layer, and within
// `coverage x (largest - smallest merged colour)` of sorting them for more.

#import manylights::common::view::view
#import manylights::deferred::blended_layers::{
    LayerNode, LayerCounters, SORTED_LAYERS, END_OF_LIST, LAYER_PLANES, LINK_PLANE,
    layer_surface, node_from_planes
}
#import manylights::lights::shading::to_hdr_target
#import manylights::cluster::cluster_index::cluster_index
#import manylights::cluster::listed_lights::grid
#import manylights::cluster::cluster_lights::shade_cluster_lights
#import manylights::gpu::weighted_blended::weighted_blended_weight
#import manylights::common::surface::Surface
#ifdef LIGHTING_TILES
#import manylights::cluster::tile_lights::shade_tile_lights
#endif

@group(1) @binding(0) var<storage, read> layer_heads: array<u32>;
// The nodes, in LAYER_PLANES planes (`layer_at`).
@group(1) @binding(1) var<storage, read> layer_nodes: array<vec4<u32>>;
@group(1) @binding(2) var<storage, read_write> layer_counters: LayerCounters;
// The opaque frame, lit (a copy of the HDR target, which this pass writes).
@group(1) @binding(3) var opaque_frame: texture_2d<f32>;
// The HDR target.
@group(2) @binding(0) var hdr_output: texture_storage_2d<rgba16float, write>;

// Node `index` of the pool.
fn layer_at(index: u32) -> LayerNode {
    let capacity = arrayLength(&layer_nodes) / LAYER_PLANES;
    var planes: array<vec4<u32>, LAYER_PLANES>;
    for (var plane = 0u; plane < LAYER_PLANES; plane++) {
        planes[plane] = layer_nodes[plane * capacity + index];
    }
    return node_from_planes(planes);
}

// The node after `index` in its pixel's list (index plus one), or END_OF_LIST.
fn next_layer(index: u32) -> u32 {
    let capacity = arrayLength(&layer_nodes) / LAYER_PLANES;
    return layer_nodes[LINK_PLANE * capacity + index].w;
}

// A layer as the compositing reads it: its shaded radiance (held to the HDR target's
// range, as the forward pass's fragment is) and its alpha.
fn shade_layer(index: u32, pixel: vec2<u32>) -> vec4<f32> {
    let node = layer_at(index);
    let surface = layer_surface(node);
    let cluster = cluster_index(grid, vec2<f32>(pixel) + vec2<f32>(0.5), node.view_depth);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
    return vec4<f32>(to_hdr_target(shade_cluster_lights(surface, view_dir, cluster)).rgb, node.alpha);
}

// A layer's place in the depth order: nearer first, and between layers at the same depth
// an order of their contents (the nodes' indices follow the order fragments happened to
// arrive in, which differs from frame to frame).
struct LayerKey {
    view_depth: f32,
    tie: u32,
}

fn layer_key(index: u32) -> LayerKey {
    let node = layer_at(index);
    let bits = bitcast<vec4<u32>>(vec4<f32>(node.albedo, node.alpha));
    let facing = bitcast<vec3<u32>>(node.normal);
    return LayerKey(node.view_depth, bits.x ^ (bits.y * 3u) ^ (bits.z * 5u) ^ (bits.w * 7u) ^ (facing.x * 11u) ^ (facing.y * 13u) ^ (facing.z * 17u));
}

fn nearer(a: LayerKey, b: LayerKey) -> bool {
    return a.view_depth < b.view_depth || (a.view_depth == b.view_depth && a.tie < b.tie);
}

const NO_LAYER: u32 = 0xffffffffu;

// A pixel's layers after its list is walked: the nearest SORTED_LAYERS, nearest first,
// and the farther ones merged by weight over the opaque frame (`under`).
struct PixelLayers {
    sorted: array<u32, SORTED_LAYERS>,
    kept: u32,
    // The opaque frame with the merged layers over it.
    under: vec3<f32>,
}

// Walks pixel `pixel`'s list from `head`: keeps the nearest SORTED_LAYERS in depth order,
// and shades and merges the farther ones as it meets them.
fn gather_layers(pixel: vec2<u32>, head: u32) -> PixelLayers {
    var layers: PixelLayers;
    var keys: array<LayerKey, SORTED_LAYERS>;
    layers.kept = 0u;
    // The merged layers' weighted colours and weights, and the share of the light behind
    // them they let through.
    var merged_colour = vec3<f32>(0.0);
    var merged_weight = 0.0;
    var revealed = 1.0;
    var next = head;
    loop {
        if next == END_OF_LIST {
            break;
        }
        let index = next - 1u;
        next = next_layer(index);
        let key = layer_key(index);
        // With every sorted place taken, the farther of this layer and the farthest kept
        // one is merged, and the other keeps (or takes) a sorted place.
        var merged = NO_LAYER;
        var merged_key = key;
        if layers.kept == SORTED_LAYERS {
            if !nearer(key, keys[SORTED_LAYERS - 1u]) {
                merged = index;
            } else {
                layers.kept -= 1u;
                merged = layers.sorted[layers.kept];
                merged_key = keys[layers.kept];
            }
        }
        if merged != index {
            var at = layers.kept;
            while at > 0u && nearer(key, keys[at - 1u]) {
                layers.sorted[at] = layers.sorted[at - 1u];
                keys[at] = keys[at - 1u];
                at -= 1u;
            }
            layers.sorted[at] = index;
            keys[at] = key;
            layers.kept += 1u;
        }
        if merged != NO_LAYER {
            let layer = shade_layer(merged, pixel);
            let weight = weighted_blended_weight(layer.a, merged_key.view_depth);
            merged_colour += layer.rgb * weight;
            merged_weight += weight;
            revealed *= 1.0 - layer.a;
        }
    }
    layers.under = textureLoad(opaque_frame, pixel, 0).rgb;
    if merged_weight > 0.0 {
        atomicAdd(&layer_counters.merged_pixels, 1u);
        layers.under = merged_colour / merged_weight * (1.0 - revealed) + revealed * layers.under;
    }
    return layers;
}

// `layer` (shaded radiance, alpha) "over" `below` (glTF's non-premultiplied alpha).
fn over(layer: vec4<f32>, below: vec3<f32>) -> vec3<f32> {
    return layer.a * layer.rgb + (1.0 - layer.a) * below;
}

#ifdef LIGHTING_TILES
// The tiles path: the sorted layers shaded with the tile-shared loop the opaque surfaces
// use (cluster/tile_lights.wgsl), one depth rank at a time, farthest first: at each step
// every pixel of the tile shades its next layer back to front (or helps load, without
// one), so the pixels whose layers lie in one cluster share its lights. The merged layers
// are rare (the pixels past the budget) and are shaded per pixel while gathering.

// The most sorted layers any pixel of the tile has.
var<workgroup> most_kept: atomic<u32>;
var<workgroup> tile_steps: u32;

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_shade_layers(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) thread: u32) {
    let size = vec2<u32>(view.viewport.xy);
    let pixel = id.xy;
    var head = END_OF_LIST;
    if all(pixel < size) {
        head = layer_heads[pixel.y * size.x + pixel.x];
    }
    var layers: PixelLayers;
    layers.kept = 0u;
    if head != END_OF_LIST {
        layers = gather_layers(pixel, head);
    }
    if thread == 0u {
        atomicStore(&most_kept, 0u);
    }
    workgroupBarrier();
    atomicMax(&most_kept, layers.kept);
    workgroupBarrier();
    if thread == 0u {
        tile_steps = atomicLoad(&most_kept);
    }
    let steps = workgroupUniformLoad(&tile_steps);
    var colour = layers.under;
    for (var step = 0u; step < steps; step++) {
        let has_layer = step < layers.kept;
        var surface: Surface;
        var cluster = 0u;
        var alpha = 0.0;
        if has_layer {
            let index = layers.sorted[layers.kept - 1u - step];
            let node = layer_at(index);
            surface = layer_surface(node);
            cluster = cluster_index(grid, vec2<f32>(pixel) + vec2<f32>(0.5), node.view_depth);
            alpha = node.alpha;
        }
        let view_dir = normalize(view.camera_position.xyz - surface.position);
        let radiance = shade_tile_lights(thread, has_layer, surface, view_dir, cluster);
        if has_layer {
            colour = over(vec4<f32>(to_hdr_target(radiance + surface.emission).rgb, alpha), colour);
        }
    }
    if head != END_OF_LIST {
        textureStore(hdr_output, pixel, to_hdr_target(colour));
    }
}
#else
// The compute path: every pixel shades its own layers with the per-pixel loop.
@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_shade_layers(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(view.viewport.xy);
    let pixel = id.xy;
    if any(pixel >= size) {
        return;
    }
    let head = layer_heads[pixel.y * size.x + pixel.x];
    if head == END_OF_LIST {
        // No layer: the opaque frame stays as it is.
        return;
    }
    let layers = gather_layers(pixel, head);
    var colour = layers.under;
    // Back to front.
    for (var k = layers.kept; k > 0u; k--) {
        colour = over(shade_layer(layers.sorted[k - 1u], pixel), colour);
    }
    textureStore(hdr_output, pixel, to_hdr_target(colour));
}
#endif
