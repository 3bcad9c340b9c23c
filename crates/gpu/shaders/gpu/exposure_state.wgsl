// The exposure the tonemap pass applies, written by the CPU (a fixed exposure) or by
// `resolve_exposure` in `exposure.wgsl` (automatic exposure). Mirrors
// `gpu::post::ExposureStateGpu`.
struct ExposureState {
    // The exposure the tonemap pass multiplies radiance by.
    value: f32,
    // The median luminance of the lit pixels of the last resolved frame.
    median_luminance: f32,
    // 0 until an automatic exposure was resolved (the next one then converges at once).
    valid: u32,
    _pad: u32,
}

