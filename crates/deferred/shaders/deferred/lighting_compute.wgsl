// Deferred lighting as a compute pass over 8x8 tiles, writing the HDR target as a
// storage texture. On GPUs with few graphics units (the H200) this runs the light loop far
// faster than the fragment path. With LIGHTING_TILES (the `tiles` path, shaded output) a
// tile's pixels share each cluster's lights through workgroup memory
// (cluster/tile_lights.wgsl); otherwise every pixel runs its own loop.

#import manylights::deferred::lighting::deferred_pixel
#import manylights::cluster::listed_lights::grid
#ifdef LIGHTING_TILES
#import manylights::deferred::lighting::{deferred_surface, view_direction, DeferredSurface}
#import manylights::cluster::tile_lights::shade_tile_lights
#import manylights::lights::shading::to_hdr_target
#else
#ifdef SHADOW_FILTER
#import manylights::deferred::lighting::{deferred_surface, view_direction}
#import manylights::cluster::cluster_lights::shade_cluster
#import manylights::lights::shading::to_hdr_target
#endif
#endif

// The HDR target.
@group(2) @binding(0) var hdr_output: texture_storage_2d<rgba16float, write>;

#ifdef SHADOW_FILTER
#import manylights::cluster::cluster_lights::pixel_visible_share
// With the spatial shadow filter the pass writes what the filter needs, and the filter
// writes the HDR target (deferred/shadow_filter.wgsl), with the emission carried in the
// inputs' fourth channels. The unshadowed radiance (w: the emission's red):
@group(2) @binding(1) var filter_unshadowed: texture_storage_2d<rgba16float, write>;
// The rays' visible share per channel (w: the emission's green):
@group(2) @binding(2) var filter_share: texture_storage_2d<rgba16float, write>;
// The surface's normal, camera-relative world space (w: the emission's blue); zero
// without a surface:
@group(2) @binding(3) var filter_normal: texture_storage_2d<rgba16float, write>;

// Stores pixel `pixel`'s shading for the filter: its `unshadowed` radiance, visible share,
// `normal` and `emission` (zeros without a surface).
fn store_for_filter(pixel: vec2<u32>, covered: bool, emission: vec3<f32>, unshadowed: vec3<f32>, normal: vec3<f32>) {
    let light = to_hdr_target(unshadowed).rgb;
    let glow = to_hdr_target(emission).rgb;
    let none = vec4<f32>(0.0);
    textureStore(filter_unshadowed, pixel, select(none, vec4<f32>(light, glow.r), covered));
    textureStore(filter_share, pixel, select(none, vec4<f32>(pixel_visible_share, glow.g), covered));
    textureStore(filter_normal, pixel, select(none, vec4<f32>(normal, glow.b), covered));
}
#endif

#ifdef LIGHTING_TILES
@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_lighting(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) thread: u32) {
    let size = vec2<u32>(grid.tile_and_screen.zw);
    let inside = all(id.xy < size);
    // Threads past the screen's edge have no surface but still help their tile load.
    var pixel: DeferredSurface;
    if inside {
        pixel = deferred_surface(id.xy);
    }
    let has_surface = inside && pixel.covered;
    let radiance = shade_tile_lights(thread, has_surface, pixel.surface, view_direction(pixel.surface), pixel.cluster);
    if inside {
#ifdef SHADOW_FILTER
        store_for_filter(id.xy, has_surface, pixel.surface.emission, radiance, pixel.surface.normal);
#else
        let shaded = to_hdr_target(radiance + pixel.surface.emission);
        textureStore(hdr_output, id.xy, select(vec4<f32>(0.0, 0.0, 0.0, 1.0), shaded, has_surface));
#endif
    }
}
#else
@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_lighting(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(grid.tile_and_screen.zw);
    if any(id.xy >= size) {
        return;
    }
#ifdef SHADOW_FILTER
    let pixel = deferred_surface(id.xy);
    var radiance = vec3<f32>(0.0);
    if pixel.covered {
        radiance = shade_cluster(pixel.surface, view_direction(pixel.surface), pixel.cluster).radiance;
    }
    store_for_filter(id.xy, pixel.covered, pixel.surface.emission, radiance, pixel.surface.normal);
#else
    textureStore(hdr_output, id.xy, deferred_pixel(id.xy));
#endif
}
#endif
