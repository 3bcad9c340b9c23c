// Mip chain generation: draws a fullscreen triangle into mip level N, sampling level N-1
// with a linear filter (a 2x2 box filter for power-of-two sizes). For sRGB textures the
// sampler decodes and the target encodes, so the averaging happens in linear space.

struct FullscreenOutput {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput {
    // One triangle covering the screen: (-1,-1), (3,-1), (-1,3).
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: FullscreenOutput;
    out.position = vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
    out.uv = uv;
    return out;
}

// The previous (larger) mip level.
@group(0) @binding(0) var source_level: texture_2d<f32>;
// Linear, clamp-to-edge.
@group(0) @binding(1) var source_sampler: sampler;

@fragment
fn fs_downsample(in: FullscreenOutput) -> @location(0) vec4<f32> {
    return textureSample(source_level, source_sampler, in.uv);
}
