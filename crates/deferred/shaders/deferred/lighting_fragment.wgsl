// Deferred lighting as a fullscreen fragment pass into the HDR target.

#import manylights::common::fullscreen::{FullscreenOutput, fullscreen_vertex}
#import manylights::deferred::lighting::deferred_pixel

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput {
    return fullscreen_vertex(index);
}

@fragment
fn fs_lighting(in: FullscreenOutput) -> @location(0) vec4<f32> {
    return deferred_pixel(vec2<u32>(in.position.xy));
}
