// The lights that reach a point, for any shader that shades with this frame's cluster
// lists (`cluster::GpuClusters`): the lists, the lights they index and the walk over one
// cluster's list. manylights' own loops (cluster_lights.wgsl, tile_lights.wgsl) walk them
// through these functions, and so does an engine's own fragment or compute shader, with
// its own BRDF:
//
//     let list = lights_at(frag_coord.xy, view_depth);
//     for (var i = 0u; i < list.candidates; i++) {
//         let index = listed_light(list, i);
//         if index == NOT_LISTED {
//             continue;
//         }
//         let light = lights[index];
//         // ... the engine's BRDF, times windowed_falloff(distance^2, light.radius)
//     }
//
// The group is a shader def: 3 in manylights' passes, the engine's choice in its own
// (`cluster::ListedLights`); the numbers are the lighting group's
// (lights/lighting_group.wgsl). The loop's parameters, the far field and the BVH are
// manylights' own: the engine's layout (`ListedLights::layout_entries`) holds only these
// six.

#import manylights::lights::light_set::Light
#import manylights::cluster::cluster_index::{ClusterParams, cluster_index}
#import manylights::cluster::bounds::{ClusterBounds, ViewLight, sphere_meets_bounds}
#import manylights::lights::lighting_group::{
    GRID_BINDING, LIST_OFFSETS_BINDING, LIST_INDICES_BINDING, LIGHTS_BINDING, VIEW_LIGHTS_BINDING,
    CLUSTER_BOUNDS_BINDING
}

// Grid description (the same as the assignment's).
@group(#LISTED_LIGHTS_GROUP) @binding(GRID_BINDING) var<uniform> grid: ClusterParams;
// Per-cluster list offsets; offsets[cluster count] is the total.
@group(#LISTED_LIGHTS_GROUP) @binding(LIST_OFFSETS_BINDING) var<storage, read> offsets: array<u32>;
// The light lists, back to back.
@group(#LISTED_LIGHTS_GROUP) @binding(LIST_INDICES_BINDING) var<storage, read> light_indices: array<u32>;
// The lights (`lights::GpuLights`), in world space.
@group(#LISTED_LIGHTS_GROUP) @binding(LIGHTS_BINDING) var<storage, read> lights: array<Light>;
// The lights in view space with their radii, and the clusters' boxes, as assignment tested
// them: what a cluster whose list overflowed is walked from.
@group(#LISTED_LIGHTS_GROUP) @binding(VIEW_LIGHTS_BINDING) var<storage, read> view_lights: array<ViewLight>;
@group(#LISTED_LIGHTS_GROUP) @binding(CLUSTER_BOUNDS_BINDING) var<storage, read> cluster_bounds: array<ClusterBounds>;

// `listed_light`'s answer for a candidate the cluster's list would not hold.
const NOT_LISTED: u32 = 0xffffffffu;

// One cluster's list, as a loop walks it: `candidates` steps, each giving a light or
// NOT_LISTED (`listed_light`).
struct LightList {
    cluster: u32,
    // Where the cluster's entries start in `light_indices`.
    start: u32,
    candidates: u32,
    // Whether the lists outgrew the index buffer this frame (it grows for the next one):
    // the cluster's entries may then be cut short, and every light is a candidate.
    cut_short: bool,
}

// The list of the cluster holding a point seen at pixel position `pixel` (pixel centres
// at .5, as @builtin(position).xy) at view depth `view_depth` (the positive distance along
// the camera's view direction).
fn lights_at(pixel: vec2<f32>, view_depth: f32) -> LightList {
    return cluster_list(cluster_index(grid, pixel, view_depth));
}

// The list of `cluster` (a flat index, `cluster_index`).
fn cluster_list(cluster: u32) -> LightList {
    let start = offsets[cluster];
    let end = offsets[cluster + 1u];
    let cut_short = end > grid.scheme_lights_capacity.z;
    let candidates = select(end - start, grid.scheme_lights_capacity.y, cut_short);
    return LightList(cluster, start, candidates, cut_short);
}

// The light (an index into `lights`) that step `i` of `list`'s walk stands for: entry `i`
// of the cluster's list, or, when the list was cut short, light `i` if its sphere meets
// the cluster's box (NOT_LISTED if not). Those are the lights the list would hold, in the
// same ascending order: the same image, only slower. Nothing is dropped.
fn listed_light(list: LightList, i: u32) -> u32 {
    if list.cut_short {
        let sphere = view_lights[i].sphere;
        if !sphere_meets_bounds(sphere.xyz, sphere.w, cluster_bounds[list.cluster]) {
            return NOT_LISTED;
        }
        return i;
    }
    return light_indices[list.start + i];
}

// The falloff manylights' lights are listed for (`lights::Falloff`'s default, windowed
// inverse square, as `light_falloff` in lights/shading.wgsl computes it): 1/d^2 times a
// window that reaches exactly 0 at the light's radius, so a light its cluster does not
// list would have added exactly nothing. `distance_squared` is clamped at 1 cm^2.
fn windowed_falloff(distance_squared: f32, radius: f32) -> f32 {
    let ratio_squared = distance_squared / (radius * radius);
    let window = saturate(1.0 - ratio_squared * ratio_squared);
    return window * window / max(distance_squared, 1e-4);
}
