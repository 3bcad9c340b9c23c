// Automatic exposure, as game engines do it: a histogram of the frame's log2 luminance
// built in one compute dispatch, then one workgroup that finds the median luminance of the
// lit pixels and maps it to mid-grey, moving the exposure part of the way there
// (`adaptation`: 1 converges in this frame, smaller values adapt smoothly over frames).
// The result stays on the GPU: the tonemap pass reads it from `state`, so nothing waits.

#import manylights::gpu::exposure_state::ExposureState

struct ExposureParams {
    // log2 luminance of the lower edge of bin 1, and the stops the lit bins span.
    min_log2: f32,
    range_log2: f32,
    // Fraction of the way (in stops) from the current exposure to this frame's target.
    adaptation: f32,
    // Stops added to the target (exposure compensation).
    compensation_ev: f32,
}

// Bin 0 holds black (and non-finite) pixels, which do not count; bins 1..255 are lit.
const BINS: u32 = #HISTOGRAM_BINS;
const LIT_BINS: f32 = 255.0;
// The luminance the median is mapped to: 18% grey, the photographic mid-tone.
const MID_GREY: f32 = 0.18;

// The frame's linear HDR radiance.
@group(0) @binding(0) var hdr: texture_2d<f32>;
// Pixels per bin; emptied again by `resolve_exposure`.
@group(0) @binding(1) var<storage, read_write> histogram: array<atomic<u32>, 256>;
@group(0) @binding(2) var<storage, read_write> state: ExposureState;
@group(0) @binding(3) var<uniform> params: ExposureParams;

var<workgroup> local_bins: array<atomic<u32>, #HISTOGRAM_BINS>;

fn luminance_bin(radiance: vec3<f32>) -> u32 {
    let luminance = dot(radiance, vec3<f32>(0.2126, 0.7152, 0.0722));
    // Written so that NaN fails the test too.
    if !(luminance > exp2(params.min_log2)) {
        return 0u;
    }
    let t = clamp((log2(luminance) - params.min_log2) / params.range_log2, 0.0, 1.0);
    return 1u + min(u32(t * LIT_BINS), BINS - 2u);
}

@compute @workgroup_size(#EXPOSURE_TILE, #EXPOSURE_TILE)
fn build_histogram(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    atomicStore(&local_bins[local], 0u);
    workgroupBarrier();
    let size = textureDimensions(hdr);
    if all(id.xy < size) {
        let bin = luminance_bin(textureLoad(hdr, vec2<i32>(id.xy), 0).rgb);
        atomicAdd(&local_bins[bin], 1u);
    }
    workgroupBarrier();
    // One global atomic per bin and workgroup instead of one per pixel.
    let count = atomicLoad(&local_bins[local]);
    if count > 0u {
        atomicAdd(&histogram[local], count);
    }
}

var<workgroup> counts: array<u32, #HISTOGRAM_BINS>;

@compute @workgroup_size(#HISTOGRAM_BINS)
fn resolve_exposure(@builtin(local_invocation_index) local: u32) {
    counts[local] = atomicLoad(&histogram[local]);
    atomicStore(&histogram[local], 0u);
    workgroupBarrier();
    if local != 0u {
        return;
    }
    var lit = 0u;
    for (var i = 1u; i < BINS; i++) {
        lit += counts[i];
    }
    // A black frame keeps the exposure it had.
    if lit == 0u {
        return;
    }
    let half = (lit + 1u) / 2u;
    var seen = 0u;
    var median_bin = BINS - 1u;
    for (var i = 1u; i < BINS; i++) {
        seen += counts[i];
        if seen >= half {
            median_bin = i;
            break;
        }
    }
    // The centre of the median's bin, in stops.
    let median_log2 = params.min_log2 + (f32(median_bin - 1u) + 0.5) / LIT_BINS * params.range_log2;
    let target_log2 = log2(MID_GREY) - median_log2 + params.compensation_ev;
    var next_log2 = target_log2;
    if state.valid != 0u {
        next_log2 = mix(log2(state.value), target_log2, params.adaptation);
    }
    state.value = exp2(next_log2);
    state.median_luminance = exp2(median_log2);
    state.valid = 1u;
}
