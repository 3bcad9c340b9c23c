// Post pass: exposure, then a tonemap operator, from the HDR target to the sRGB output
// (the target's format does the sRGB encoding).

#import manylights::common::fullscreen::{FullscreenOutput, fullscreen_vertex}
#import manylights::gpu::exposure_state::ExposureState

struct TonemapParams {
    // 0: none (clamp to [0, 1]), 1: Reinhard, 2: ACES fit.
    curve: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// The frame's linear HDR radiance.
@group(0) @binding(0) var hdr: texture_2d<f32>;
// The operator.
@group(0) @binding(1) var<uniform> tonemap: TonemapParams;
// The exposure (fixed, or resolved on the GPU this frame).
@group(0) @binding(2) var<storage, read> exposure: ExposureState;

// Narkowicz 2015, "ACES Filmic Tone Mapping Curve" (fit of the ACES RRT+ODT).
fn aces_fit(x: vec3<f32>) -> vec3<f32> {
    return saturate((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14));
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOutput {
    return fullscreen_vertex(index);
}

@fragment
fn fs_tonemap(in: FullscreenOutput) -> @location(0) vec4<f32> {
    let radiance = max(textureLoad(hdr, vec2<i32>(in.position.xy), 0).rgb * exposure.value, vec3<f32>(0.0));
    var mapped: vec3<f32>;
    switch tonemap.curve {
        case 1u: {
            mapped = radiance / (1.0 + radiance);
        }
        case 2u: {
            mapped = aces_fit(radiance);
        }
        default: {
            mapped = saturate(radiance);
        }
    }
    return vec4<f32>(mapped, 1.0);
}
