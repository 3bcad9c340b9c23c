// Mip chain generation: draws a fullscreen triangle (common/fullscreen.wgsl) into mip level N, sampling level N-1
// with a linear filter (a 2x2 box filter for power-of-two sizes). For sRGB textures the
// sampler decodes and the target encodes, so the averaging happens in linear space.

#import manylights::common::fullscreen::{FullscreenOutput, fullscreen_vertex}

// The previous (larger) mip level.
@group(0) @binding(0) var source_level: texture_2d<f32>;
// Linear, clamp-to-edge.
@group(0) @binding(1) var source_sampler: sampler;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput {
    return fullscreen_vertex(index);
}

@fragment
fn fs_downsample(in: FullscreenOutput) -> @location(0) vec4<f32> {
    return textureSample(source_level, source_sampler, in.uv);
}
