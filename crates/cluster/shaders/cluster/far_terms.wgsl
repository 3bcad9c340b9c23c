// The light tree's far field for any shader that walks the cluster lists
// (listed_lights.wgsl): what the lights add beyond their radius, as the cluster's cut of
// the tree (`cluster::GpuFarField`) holds it. manylights' own loop (cluster_lights.wgsl)
// walks the cut through these functions, and so does an engine's shader, with its BRDF:
//
//     let cut = far_cut(list.cluster);
//     for (var k = 0u; k < cut.entries; k++) {
//         let entry = far_entry(cut, k);
//         if entry.aggregate {
//             // Many lights as one: light from `term.l`, `term.incoming` (cosine included).
//             let term = aggregate_term(entry.node, entry.node.centroid - world, normal);
//             radiance += my_brdf(term.l) * term.incoming;
//         } else {
//             // Each light under the node, with the complement of the windowed falloff.
//             for (var i = entry.node.first; i < entry.node.first + entry.node.count; i++) {
//                 let light = lights[far_light(i)];
//                 ... my BRDF, times far_falloff(distance^2, light.radius)
//             }
//         }
//     }
//
// Windowed (the lists) plus far (this) is the plain inverse square: with tolerance 0 the
// sum is every light's (far_nodes.wgsl). Bindings FAR_FIELD to FAR_ORDER of the lists'
// group (lights/lighting_group.wgsl).

#import manylights::cluster::far_nodes::{
    FarFieldParams, FarNode, FAR_ENTRY_EXACT, cut_slots, window_complement
}
#import manylights::lights::light_set::MIN_DISTANCE_SQUARED
#import manylights::lights::lighting_group::{
    FAR_FIELD_BINDING, FAR_NODES_BINDING, FAR_LISTS_BINDING, FAR_ORDER_BINDING
}

// The far field's parameters, the light tree's nodes, each cluster's cut (a count, then
// `cut_slots` entries) and the lights in the tree's order.
@group(#LISTED_LIGHTS_GROUP) @binding(FAR_FIELD_BINDING) var<uniform> far_field: FarFieldParams;
@group(#LISTED_LIGHTS_GROUP) @binding(FAR_NODES_BINDING) var<storage, read> far_nodes: array<FarNode>;
@group(#LISTED_LIGHTS_GROUP) @binding(FAR_LISTS_BINDING) var<storage, read> far_lists: array<u32>;
@group(#LISTED_LIGHTS_GROUP) @binding(FAR_ORDER_BINDING) var<storage, read> far_order: array<u32>;

// One cluster's cut: where its row of the far lists starts and how many entries it holds.
struct FarCut {
    row: u32,
    entries: u32,
}

fn far_cut(cluster: u32) -> FarCut {
    let slots = cut_slots(far_field);
    let row = cluster * (slots + 1u);
    return FarCut(row, min(far_lists[row], slots));
}

// Entry `k` of a cut: the node of the tree at `index`, shaded as one aggregate light, or
// (`aggregate` false: a node marked exact, or of one light) as each of its lights.
struct FarEntry {
    index: u32,
    node: FarNode,
    aggregate: bool,
}

fn far_entry(cut: FarCut, k: u32) -> FarEntry {
    let entry = far_lists[cut.row + 1u + k];
    let index = entry & ~FAR_ENTRY_EXACT;
    let node = far_nodes[index];
    return FarEntry(index, node, (entry & FAR_ENTRY_EXACT) == 0u && node.count > 1u);
}

// The light (an index into the lists' `lights`) at place `i` of the tree's order (a node's
// lights are `node.first` to `node.first + node.count`).
fn far_light(i: u32) -> u32 {
    return far_order[i];
}

// The falloff of a light beyond its windowed part: 1/d^2 times the window's complement.
fn far_falloff(distance_squared: f32, radius: f32) -> f32 {
    return window_complement(distance_squared, radius);
}

// An aggregate's light at a point: arriving from the unit direction `l`, with `incoming`
// radiance already times the clamped cosine and the falloff (a BRDF times it is the
// aggregate's radiance towards the eye).
struct FarTerm {
    l: vec3<f32>,
    incoming: vec3<f32>,
}

// The light of aggregate `node` at a surface point with unit normal `normal`, the node's
// centroid at `to_centroid` from it. The complement of the windowed falloff (far_nodes.wgsl)
// from a tree node (power centroid, box, summed power; spots counted by their cones' share
// of the sphere, the tree has no directions): the geometric term, complement x clamped
// cosine, is averaged over four points that have the mean and per-axis variance of lights
// spread evenly through the node's box (centroid + (+-1, +-1, +-1) x half / sqrt(3), the
// four sign patterns with no covariance); the BRDF is evaluated once, toward those points'
// weighted mean direction `l`. Why not the centroid alone: near a surface a node's box
// straddles it, and the centroid behind a convex stone lit it not at all while half the
// lights were in front (issue 58's dark blocks); at the same slots the four points cut the
// million-light error threefold (docs/results.md, "Whole frames"). They are in the box, and
// the average is a continuous function of the pixel, so neighbouring pixels never jump.
// Nothing arrives (`incoming` zero, `l` the normal) where no point is in front.
fn aggregate_term(node: FarNode, to_centroid: vec3<f32>, normal: vec3<f32>) -> FarTerm {
    let sigma = (0.5 / sqrt(3.0)) * (node.box_max - node.box_min);
    let inverse_radius_squared = 1.0 / (node.radius * node.radius);
    var geometric = 0.0;
    var direction = vec3<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let signs = vec3<f32>(
            select(-1.0, 1.0, k < 2u),
            select(-1.0, 1.0, k == 0u || k == 2u),
            select(-1.0, 1.0, k == 0u || k == 3u),
        );
        let to_point = to_centroid + signs * sigma;
        let distance_squared = max(dot(to_point, to_point), MIN_DISTANCE_SQUARED);
        let inverse_distance = inverseSqrt(distance_squared);
        // window_complement (far_nodes.wgsl), with the squared distance's reciprocal shared.
        let ratio_squared = distance_squared * inverse_radius_squared;
        let window = saturate(1.0 - ratio_squared * ratio_squared);
        let weight = max(dot(normal, to_point), 0.0) * inverse_distance
            * (1.0 - window * window) * (inverse_distance * inverse_distance);
        geometric += weight;
        direction += (weight * inverse_distance) * to_point;
    }
    if geometric <= 0.0 {
        return FarTerm(normal, vec3<f32>(0.0));
    }
    let l = normalize(direction);
    // The node's flat lights send more towards what they face (`light_emission_dipole`):
    // 1 + dipole.w / weight of its mean intensity towards w = -l, never below 0.
    let leaning = select(1.0, max(1.0 - dot(node.dipole, l) / node.weight, 0.0), node.weight > 0.0);
    return FarTerm(l, node.power * (0.25 * geometric * leaning));
}
