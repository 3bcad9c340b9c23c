// Deferred lighting as a compute pass over 8x8-pixel tiles, writing the HDR target as a
// storage texture. On GPUs with few graphics units (the H200) this runs the light loop far
// faster than the fragment path.

#import manylights::deferred::lighting::deferred_pixel
#import manylights::cluster::cluster_lights::grid

// The HDR target.
@group(2) @binding(0) var hdr_output: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_lighting(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(grid.tile_and_screen.zw);
    if any(id.xy >= size) {
        return;
    }
    textureStore(hdr_output, id.xy, deferred_pixel(id.xy));
}
