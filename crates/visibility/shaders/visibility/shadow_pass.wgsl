// The forward pipelines' shadow pass (SHADOW_PASS, one ray a pixel): the fragment shader
// keeps its ray instead of tracing it, and writes it beside the unshadowed radiance and the
// normal (`visibility::FORWARD_TARGETS`); a compute pass traces it from the position
// rebuilt from depth (visibility/shadow_trace.wgsl). The emission rides in the fourth
// channels, as the spatial filter reads it (visibility/shadow_filter.wgsl).
struct ShadowPassTargets {
    // The unshadowed radiance as the HDR target holds it; w: the emission's red.
    @location(0) unshadowed: vec4<f32>,
    // The shading normal (camera-relative world space); w: the emission's blue.
    @location(1) normal: vec4<f32>,
    // The kept light in scene coordinates (x NO_SHADOW_RAY: none); w: the emission's green.
    @location(2) ray: vec4<f32>,
}

// The ray target's x where the pixel kept no light: nothing to trace, all of it visible.
const NO_SHADOW_RAY: f32 = 3.0e38;
