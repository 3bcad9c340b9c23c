// The far field's shared definitions: its parameters, the aggregate lights of the light
// tree, and the one falloff both far-field methods approximate (`cluster::FarField`).
//
// Split of a light's unbounded contribution f = 1 / max(d^2, eps) at radius r:
//   near(d) = window(d)^2 * f      (the windowed falloff: what the cluster lists sum exactly)
//   far(d)  = (1 - window(d)^2) * f (the complement: what a far-field method approximates)
// near + far = f, so a far field that is exact (tolerance 0) gives the unbounded image.

#import manylights::lights::light_set::MIN_DISTANCE_SQUARED

struct FarFieldParams {
    // Method (FAR_FIELD_*), light count, tree levels above the leaves (the leaf grid has
    // 2^levels cells a side), words per cluster row of the far lists (a count, then
    // `cut_slots` entries).
    setup: vec4<u32>,
    // Blocks of 256 lights in the sort, tree node count, stochastic seed, sort passes.
    sizes: vec4<u32>,
    // The tolerance (x); yzw unused.
    tolerance: vec4<f32>,
    // Index of each level's first node, level 0 (the leaves) first; up to 8 levels.
    level_first: array<vec4<u32>, 2>,
}

const FAR_FIELD_OFF: u32 = #FAR_FIELD_OFF;
const FAR_FIELD_TREE: u32 = #FAR_FIELD_TREE;
const FAR_FIELD_STOCHASTIC: u32 = #FAR_FIELD_STOCHASTIC;

// A far-list entry with this bit evaluates every light under the node individually
// (exactly); without it the node is one aggregate light.
const FAR_ENTRY_EXACT: u32 = #FAR_ENTRY_EXACT;

// The most entries a cluster's cut may hold (`cluster::MAX_FAR_CUT_SLOTS`: the cut
// pass's workgroup arrays).
const MAX_CUT_SLOTS: u32 = #MAX_FAR_CUT_SLOTS;

// The entries this frame's cuts may hold (`FarField::slots`): a row of the far lists is a
// count and this many entries.
fn cut_slots(params: FarFieldParams) -> u32 {
    return params.setup.w - 1u;
}

// An aggregate of the lights in one cell of the tree (a leaf cell or a union of 8 cells).
struct FarNode {
    // Weighted centroid of its lights (world space) and the weight (sum of each light's
    // intensity x brightest colour channel).
    centroid: vec3<f32>,
    weight: f32,
    // Sum of colour x intensity, and the largest radius among its lights.
    power: vec3<f32>,
    radius: f32,
    // Bounding box of its lights (world space); `first` is its first light in sorted
    // order, `count` how many (its lights are consecutive in the sorted order).
    box_min: vec3<f32>,
    first: u32,
    box_max: vec3<f32>,
    count: u32,
    // Sum of its flat lights' emission dipoles (`light_emission_dipole`) times their
    // weights: which way its light leans.
    dipole: vec3<f32>,
    _pad: u32,
}

fn far_level_first(params: FarFieldParams, level: u32) -> u32 {
    return params.level_first[level / 4u][level % 4u];
}

// The complement of the windowed falloff at squared distance d2 for radius r:
// (1 - saturate(1 - (d/r)^4)^2) / max(d^2, eps). Zero at the light, 1/d^2 beyond r.
fn window_complement(distance_squared: f32, radius: f32) -> f32 {
    let ratio_squared = distance_squared / (radius * radius);
    let window = saturate(1.0 - ratio_squared * ratio_squared);
    return (1.0 - window * window) / max(distance_squared, MIN_DISTANCE_SQUARED);
}

// Stochastic light culling (Tokuyoshi and Harada 2016) of the complement: a light of
// radius r gets the random range rho = r / sqrt(tolerance * xi), at least r, xi uniform in
// (0, 1]. It reaches a point at d >= r with probability min(1, r^2 / (tolerance d^2)), so its
// complement there is divided by that probability: the estimate is unbiased, and its
// error is noise. Lights closer than r are always reached (weight 1).
fn stochastic_weight(distance_squared: f32, radius: f32, tolerance: f32) -> f32 {
    let radius_squared = radius * radius;
    if distance_squared < radius_squared {
        return 1.0;
    }
    return max(1.0, tolerance * distance_squared / radius_squared);
}
