// Deferred lighting, shared by the fragment and compute paths: for one pixel, read the
// G-buffer, find the pixel's cluster with the shared `cluster_index`, and shade that
// cluster's lights (or draw a debug view: cluster views or G-buffer channels).

#import manylights::common::view::view
#import manylights::common::surface::Surface
#import manylights::lights::shading::to_hdr_target
#import manylights::cluster::cluster_index::cluster_index
#import manylights::cluster::listed_lights::grid
#import manylights::cluster::cluster_lights::{DEBUG_HEATMAP, DEBUG_SLICES, LEGEND_HEIGHT, LOOP_OUTPUT, heatmap_pixel, shade_cluster_lights, slice_pixel}
#ifdef GBUFFER_FULL
#import manylights::deferred::full_read::read_gbuffer
#endif
#ifdef GBUFFER_COMPACT
#import manylights::deferred::compact_read::read_gbuffer
#endif
#ifdef GBUFFER_PACKED
#import manylights::deferred::packed_read::read_gbuffer
#endif

#ifdef EMISSIVE
// Emitted radiance, written by the G-buffer pass (only when a material emits).
@group(1) @binding(5) var gbuffer_emission: texture_2d<f32>;
#endif

// The G-buffer debug views' codes, shader defs from `deferred::GBufferChannel::shader_code`.
const DEBUG_ALBEDO: u32 = #GBUFFER_VIEW_ALBEDO;
const DEBUG_NORMAL: u32 = #GBUFFER_VIEW_NORMAL;
const DEBUG_DEPTH: u32 = #GBUFFER_VIEW_DEPTH;
const DEBUG_POSITION: u32 = #GBUFFER_VIEW_POSITION;

// What lighting knows of a pixel: whether a surface covers it, the surface (with its
// emission), its view depth and its cluster.
struct DeferredSurface {
    covered: bool,
    surface: Surface,
    view_depth: f32,
    cluster: u32,
}

fn deferred_surface(pixel: vec2<u32>) -> DeferredSurface {
    let sample = read_gbuffer(vec2<i32>(pixel));
    var surface = sample.surface;
#ifdef EMISSIVE
    surface.emission = textureLoad(gbuffer_emission, vec2<i32>(pixel), 0).rgb;
#endif
    let cluster = cluster_index(grid, vec2<f32>(pixel) + 0.5, sample.view_depth);
    return DeferredSurface(sample.covered, surface, sample.view_depth, cluster);
}

// The direction from the surface towards the eye.
fn view_direction(surface: Surface) -> vec3<f32> {
    return normalize(view.camera_position.xyz - surface.position);
}

fn deferred_pixel(pixel: vec2<u32>) -> vec4<f32> {
    let frag_xy = vec2<f32>(pixel) + 0.5;
    let sample = deferred_surface(pixel);
    let in_legend = frag_xy.y > grid.tile_and_screen.w - LEGEND_HEIGHT;
    if !sample.covered && !(LOOP_OUTPUT == DEBUG_HEATMAP && in_legend) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let surface = sample.surface;
    let cluster = sample.cluster;
    switch LOOP_OUTPUT {
        case DEBUG_HEATMAP: {
            return vec4<f32>(heatmap_pixel(frag_xy, cluster, surface.normal), 1.0);
        }
        case DEBUG_SLICES: {
            return vec4<f32>(slice_pixel(frag_xy, sample.view_depth), 1.0);
        }
        case DEBUG_ALBEDO: {
            return vec4<f32>(surface.albedo, 1.0);
        }
        case DEBUG_NORMAL: {
            return vec4<f32>(surface.normal * 0.5 + 0.5, 1.0);
        }
        case DEBUG_DEPTH: {
            // A ramp over 32 m: black at the eye, white at 32 m and beyond.
            return vec4<f32>(vec3<f32>(saturate(sample.view_depth / 32.0)), 1.0);
        }
        case DEBUG_POSITION: {
            return vec4<f32>(fract(surface.position), 1.0);
        }
        default: {
            return to_hdr_target(shade_cluster_lights(surface, view_direction(surface), cluster));
        }
    }
}
