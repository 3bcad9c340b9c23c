// Mip chain generation: draws a fullscreen triangle (common/fullscreen.wgsl) into mip level N, sampling level N-1
// with a linear filter (a 2x2 box filter for power-of-two sizes). For sRGB textures the
// sampler decodes and the target encodes, so the averaging happens in linear space.

// The previous (larger) mip level.
@group(0) @binding(0) var source_level: texture_2d<f32>;
// Linear, clamp-to-edge.
@group(0) @binding(1) var source_sampler: sampler;

@fragment
fn fs_downsample(in: FullscreenOutput) -> @location(0) vec4<f32> {
    return textureSample(source_level, source_sampler, in.uv);
}
