// Deferred lighting as a compute pass over 8x8 tiles, writing the HDR target as a
// storage texture. On GPUs with few graphics units (the H200) this runs the light loop far
// faster than the fragment path. With LIGHTING_TILES (the `tiles` path, shaded output) a
// tile's pixels share each cluster's lights through workgroup memory
// (cluster/tile_lights.wgsl); otherwise every pixel runs its own loop.

#import manylights::deferred::lighting::deferred_pixel
#import manylights::cluster::cluster_lights::grid
#ifdef LIGHTING_TILES
#import manylights::deferred::lighting::{deferred_surface, view_direction, DeferredSurface}
#import manylights::cluster::tile_lights::shade_tile_lights
#import manylights::lights::shading::to_hdr_target
#endif

// The HDR target.
@group(2) @binding(0) var hdr_output: texture_storage_2d<rgba16float, write>;

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
        let shaded = to_hdr_target(radiance + pixel.surface.emission);
        textureStore(hdr_output, id.xy, select(vec4<f32>(0.0, 0.0, 0.0, 1.0), shaded, has_surface));
    }
}
#else
@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn cs_lighting(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(grid.tile_and_screen.zw);
    if any(id.xy >= size) {
        return;
    }
    textureStore(hdr_output, id.xy, deferred_pixel(id.xy));
}
#endif
