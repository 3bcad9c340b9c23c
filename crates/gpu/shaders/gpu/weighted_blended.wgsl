// Weighted blended order-independent transparency (McGuire and Bavoil 2013): each blended
// fragment adds its premultiplied colour, weighted by its alpha and its depth, to an
// accumulation target and multiplies a revealage target by (1 - alpha); a composite pass
// (`weighted_composite.wgsl`) then lays the weighted average over the opaque frame by
// the coverage the layers leave. No sorting: order enters only through the weight, which
// makes nearer layers count more.

#define_import_path manylights::gpu::weighted_blended

struct WeightedOutput {
    // rgb: colour * alpha * weight; a: alpha * weight (summed: blend One, One).
    @location(0) accumulation: vec4<f32>,
    // alpha (the target keeps the product of 1 - alpha: blend Zero, OneMinusSrc).
    @location(1) revealage: vec4<f32>,
}

// The paper's depth weight (its equation 9, depth in metres) scaled by 1/300: the paper
// tunes the clamp [1e-2, 3e3] for 16-bit accumulation of colours at most 1; HDR colours
// reach thousands, so the weights are kept at most 10 and the sum of colour * weight stays
// within the half float's 65504 for colours below 6,500. Only the ratio of weights enters
// the result, so the scale changes nothing else.
fn weighted_blended_weight(alpha: f32, view_depth: f32) -> f32 {
    let d = max(view_depth, 0.0);
    let falloff = 10.0 / (1e-5 + pow(d / 5.0, 2.0) + pow(d / 200.0, 6.0));
    return alpha * clamp(falloff, 1e-2, 3e3) / 300.0;
}

// A blended fragment as both ways of transparency take it: its HDR colour (not
// premultiplied) and alpha, and its depth before the camera in metres. Sorted blends the
// colour "over" the target; weighted writes `weighted_blended_output`.
struct BlendedFragment {
    colour: vec4<f32>,
    view_depth: f32,
}

// The accumulation targets' outputs of `fragment`.
fn weighted_blended_output(fragment: BlendedFragment) -> WeightedOutput {
    let alpha = fragment.colour.a;
    let weight = weighted_blended_weight(alpha, fragment.view_depth);
    var out: WeightedOutput;
    out.accumulation = vec4<f32>(fragment.colour.rgb * weight, weight);
    out.revealage = vec4<f32>(alpha);
    return out;
}
