// What every clustered shading pass (Forward+, deferred lighting) binds at group 3, the
// loop over one cluster's lights, and the cluster debug views (lights-per-cluster heatmap
// with a legend strip, depth-slice colouring).

#import manylights::common::surface::Surface
#import manylights::lights::light_set::PointLight
#import manylights::lights::shading::shade_point_light
#import manylights::cluster::cluster_index::{ClusterParams, cluster_slice}
#import manylights::cluster::bounds::{ClusterBounds, sphere_meets_bounds}

struct ClusteredShadingParams {
    // `lights::Falloff` as FALLOFF_* in lights/shading.wgsl.
    falloff: u32,
    // Light count shown as white in the heatmap.
    heatmap_max: f32,
    // What to output: 0 the shaded image, a DEBUG_* code below (`cluster::ClusterView`), or
    // a code of the pipeline's own views (`deferred::GBufferChannel`).
    debug_view: u32,
    _pad: u32,
}

// The cluster debug views' codes, shader defs from `cluster::ClusterView::shader_code`.
const DEBUG_HEATMAP: u32 = #CLUSTER_VIEW_HEATMAP;
const DEBUG_SLICES: u32 = #CLUSTER_VIEW_SLICES;
const DEBUG_LIGHT_EVALUATIONS: u32 = #CLUSTER_VIEW_LIGHT_EVALUATIONS;

// Grid description (the same as the assignment's).
@group(3) @binding(0) var<uniform> grid: ClusterParams;
// Per-cluster list offsets; offsets[cluster count] is the total.
@group(3) @binding(1) var<storage, read> offsets: array<u32>;
// The light lists, back to back.
@group(3) @binding(2) var<storage, read> light_indices: array<u32>;
// The lights.
@group(3) @binding(3) var<storage, read> lights: array<PointLight>;
// Falloff and debug settings.
@group(3) @binding(4) var<uniform> clustered: ClusteredShadingParams;
// The lights in view space with their radii, and the clusters' boxes, as assignment tested
// them: what a cluster whose list overflowed is shaded from.
@group(3) @binding(5) var<storage, read> view_lights: array<vec4<f32>>;
@group(3) @binding(6) var<storage, read> cluster_bounds: array<ClusterBounds>;

struct ClusterShading {
    // Radiance towards the eye.
    radiance: vec3<f32>,
    // Lights evaluated: the debug view `DEBUG_LIGHT_EVALUATIONS` shows it, so tests can
    // prove a pixel shaded its cluster's list and nothing else.
    evaluations: u32,
}

// Radiance towards the eye from every light of `cluster`, and how many were evaluated.
//
// If the lists outgrew the index buffer this frame (it grows for the next one), this
// cluster's list may have been cut short: its lights are then found again, every light
// whose sphere meets the cluster's box, in ascending order. Those are the lights the list
// would hold (the ones outside the assignment's candidate range reach no sample here and
// add exactly zero), in the same order: the same image, only slower. Nothing is dropped.
// One loop serves both cases (with two, lavapipe's Forward+ draws grew its memory by
// 25 MiB a phase in the soak test).
fn shade_cluster(surface: Surface, view_dir: vec3<f32>, cluster: u32) -> ClusterShading {
    let start = offsets[cluster];
    let end = offsets[cluster + 1u];
    let cut_short = end > grid.scheme_lights_capacity.z;
    let bounds = cluster_bounds[cluster];
    let candidates = select(end - start, grid.scheme_lights_capacity.y, cut_short);
    var result = ClusterShading(vec3<f32>(0.0), 0u);
    for (var i = 0u; i < candidates; i++) {
        var light = i;
        if cut_short {
            let sphere = view_lights[i];
            if !sphere_meets_bounds(sphere.xyz, sphere.w, bounds) {
                continue;
            }
        } else {
            light = light_indices[start + i];
        }
        result.radiance += shade_point_light(surface, view_dir, lights[light], clustered.falloff);
        result.evaluations += 1u;
    }
    return result;
}

// The shaded pixel, or (`DEBUG_LIGHT_EVALUATIONS`) its count of evaluated lights in every
// channel (exact in the half-float target up to 2048).
fn shade_cluster_lights(surface: Surface, view_dir: vec3<f32>, cluster: u32) -> vec3<f32> {
    let shading = shade_cluster(surface, view_dir, cluster);
    if clustered.debug_view == DEBUG_LIGHT_EVALUATIONS {
        return vec3<f32>(f32(shading.evaluations));
    }
    return shading.radiance;
}

// Black -> blue -> cyan -> green -> yellow -> red -> white as t goes 0 -> 1.
fn heat_colour(t: f32) -> vec3<f32> {
    let stops = array<vec3<f32>, 7>(
        vec3<f32>(0.0, 0.0, 0.0),
        vec3<f32>(0.0, 0.0, 1.0),
        vec3<f32>(0.0, 1.0, 1.0),
        vec3<f32>(0.0, 1.0, 0.0),
        vec3<f32>(1.0, 1.0, 0.0),
        vec3<f32>(1.0, 0.0, 0.0),
        vec3<f32>(1.0, 1.0, 1.0),
    );
    let x = saturate(t) * 6.0;
    let i = min(u32(x), 5u);
    return mix(stops[i], stops[i + 1u], x - f32(i));
}

// Height of the legend strip at the bottom of the heatmap, in pixels.
const LEGEND_HEIGHT: f32 = 8.0;

// Heatmap colour of a pixel: the legend strip at the bottom (0 at the left to
// heatmap_max at the right, ticks at quarters), else the cluster's light count, lightly
// shaded by the surface's facing so the geometry stays readable.
fn heatmap_pixel(frag_xy: vec2<f32>, cluster: u32, normal: vec3<f32>) -> vec3<f32> {
    let screen = grid.tile_and_screen.zw;
    if frag_xy.y > screen.y - LEGEND_HEIGHT {
        let t = frag_xy.x / screen.x;
        let tick = abs(fract(t * 4.0 + 0.5) - 0.5) * screen.x / 4.0 < 1.0;
        return select(heat_colour(t), vec3<f32>(1.0), tick);
    }
    let count = f32(offsets[cluster + 1u] - offsets[cluster]);
    let facing = 0.75 + 0.25 * abs(normal.y);
    return heat_colour(count / clustered.heatmap_max) * facing;
}

// Depth-slice colour of a pixel: alternating hues per slice, tiles in a checkerboard.
fn slice_pixel(frag_xy: vec2<f32>, depth: f32) -> vec3<f32> {
    let slice = cluster_slice(grid, depth);
    let hue = f32(slice % 6u) / 6.0;
    let tile = vec2<u32>(frag_xy / grid.tile_and_screen.xy);
    let checker = select(1.0, 0.7, ((tile.x + tile.y) & 1u) == 1u);
    return heat_colour(0.15 + 0.7 * hue) * checker;
}
