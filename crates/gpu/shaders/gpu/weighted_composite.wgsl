// Weighted blended transparency's composite (`weighted_blended.wgsl`): over the opaque
// frame in the HDR target, the layers' weighted average colour with alpha 1 - revealage
// (the coverage all layers together leave), through the "over" blend.

#import manylights::common::fullscreen::{FullscreenOutput, fullscreen_vertex}

@group(0) @binding(0) var accumulation: texture_2d<f32>;
@group(0) @binding(1) var revealage: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput {
    return fullscreen_vertex(index);
}

@fragment
fn fs_composite(in: FullscreenOutput) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    let coverage = 1.0 - textureLoad(revealage, pixel, 0).r;
    if coverage <= 0.0 {
        discard;
    }
    let sum = textureLoad(accumulation, pixel, 0);
    return vec4<f32>(sum.rgb / max(sum.a, 1e-12), coverage);
}
