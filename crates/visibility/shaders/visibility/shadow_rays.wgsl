// Shadows with a fixed ray budget (`visibility::Shadows::Rays`): SHADOW_RAYS rays a pixel,
// whatever the light count. A light loop sums every light's term unshadowed, exactly, and
// offers each term here (`offer_shadow_ray`); each ray keeps one of the terms offered to
// it, drawn in proportion to its luminance (weighted reservoir sampling: one pass, no
// list). After the loop the rays are traced, and `shadow_ratio` says what share of the
// sum they found visible, a channel at a time: the pixel is its exact unshadowed sum times
// that share (the ratio estimator of Heitz, Hill and McGuire 2018). Where every light is
// visible, or none is, the share is exactly 1 or 0: noise only where shadows are partial.
//
// The terms are dealt to the rays in turn (term i to ray i mod SHADOW_RAYS), so a pixel
// with at most SHADOW_RAYS contributing lights gives each its own ray: exact shadows.
// Each ray is then an unbiased estimate of its share of the lights (stratified sampling).
//
// Each ray's reservoir jumps (Efraimidis and Spirakis 2006, A-ExpJ): instead of a random
// number for every term, it draws how much weight to skip before its kept term is next
// replaced, so a term costs a subtraction and a comparison, and random numbers are drawn
// only at the replacements (about the logarithm of the term count). The result is the
// same distribution: each term kept with probability its weight over the ray's sum.
//
// A far-field aggregate (a node of the light tree) is offered as one term, its ray aimed
// at its power centroid; a ray that keeps it is told after the loop
// (`kept_aggregate`) and re-aimed (`aim_ray`) at one of the node's lights, drawn by power
// (cluster/cluster_lights.wgsl): the aggregate's visible share is then the share of its
// power that reaches the point, not whether its centroid does.
//
// The random numbers hash the surface's position with the frame's seed
// (`FrameSettings::shadow_seed`): the same seed, the same image.

#import manylights::common::view::view
#import manylights::lights::hash::pcg_hash
#import manylights::lights::light_set::LIGHT_SPHERE
#import manylights::lights::area::area_light_point
#import manylights::visibility::bvh::light_visible
#import manylights::visibility::shadow_pass::{NO_SHADOW_RAY, ShadowPassTargets}

// Rays a pixel: 1 to 4, one component each of the vectors below.
const SHADOW_RAYS: u32 = #SHADOW_RAYS;

// Each ray's kept light (camera-relative) and its term.
var<private> ray_light: array<vec3<f32>, SHADOW_RAYS>;
var<private> ray_term: array<vec3<f32>, SHADOW_RAYS>;
// Each ray's sum of the weights dealt to it, the weight it still skips before its next
// replacement, and the logarithm of its kept term's key (A-ExpJ's; at most 0).
var<private> weight_sum: vec4<f32>;
var<private> weight_to_skip: vec4<f32>;
var<private> log_key: vec4<f32>;
// The aggregate each ray's kept term stands for (NO_AGGREGATE: a light), and the one being
// offered now.
var<private> ray_aggregate: array<u32, SHADOW_RAYS>;
var<private> offering_aggregate: u32 = NO_AGGREGATE;
const NO_AGGREGATE: u32 = 0xffffffffu;
// Terms offered so far (those that add anything; counted only to deal them out, with more
// than one ray), and the random state.
var<private> offered: u32;
var<private> random_state: u32;

// The logarithm of the key of a ray that has kept nothing yet: any term's key beats it
// (the key floor it leaves, exp(weight x NO_KEY), is 0 for any weight above 1e-36).
const NO_KEY: f32 = -3.0e38;

fn luminance(term: vec3<f32>) -> f32 {
    return dot(term, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Uniform in (0, 1]: never 0, whose logarithm the jumps would divide by.
fn next_random() -> f32 {
    random_state = pcg_hash(random_state);
    return f32((random_state >> 8u) + 1u) * (1.0 / 16777216.0);
}

// Start a pixel's rays at the surface point `position` (any space: only its bits are
// hashed, with the frame's seed).
fn begin_shadow_rays(position: vec3<f32>) {
    let bits = bitcast<vec3<u32>>(position);
    random_state = pcg_hash(bits.x ^ pcg_hash(bits.y ^ pcg_hash(bits.z ^ pcg_hash(view.seeds.x))));
    offered = 0u;
    weight_sum = vec4<f32>(0.0);
    // Nothing to skip: each ray keeps the first term dealt to it.
    weight_to_skip = vec4<f32>(0.0);
    log_key = vec4<f32>(NO_KEY);
}

// Offer one light's unshadowed `term` (any common factor of the loop left out: only its
// proportions matter) from `light` (camera-relative: `relative_to_origin`) to the next
// ray in turn.
//
// A term costs a few operations, each measurable at 100,000 lights (H200: the luminance's
// dot product alone 0.5 ms of 12.5), so one ray does the least: no count, no sum, and no
// test of the weight (a term of weight 0, or NaN, never makes `left` negative).
fn offer_shadow_ray(term: vec3<f32>, light: vec3<f32>) {
    let weight = luminance(term);
    if SHADOW_RAYS == 1u {
        let left = weight_to_skip[0] - weight;
        weight_to_skip[0] = left;
        if left < 0.0 {
            keep_term(0u, term, light, weight);
        }
        return;
    }
    if !(weight > 0.0) {
        return;
    }
    let ray = offered % SHADOW_RAYS;
    offered += 1u;
    weight_sum[ray] += weight;
    let left = weight_to_skip[ray] - weight;
    weight_to_skip[ray] = left;
    if left < 0.0 {
        keep_term(ray, term, light, weight);
    }
}

// Offer a far-field aggregate's `term` from its power centroid `centroid`
// (camera-relative), the light tree's node `node`.
fn offer_aggregate_shadow_ray(term: vec3<f32>, centroid: vec3<f32>, node: u32) {
    offering_aggregate = node;
    offer_shadow_ray(term, centroid);
    offering_aggregate = NO_AGGREGATE;
}

// The aggregate `ray`'s kept term stands for, or NO_AGGREGATE (a light, or nothing kept).
fn kept_aggregate(ray: u32) -> u32 {
    if log_key[ray] == NO_KEY {
        return NO_AGGREGATE;
    }
    return ray_aggregate[ray];
}

// Aims `ray` at `light` (camera-relative) instead of the position its term came from.
fn aim_ray(ray: u32, light: vec3<f32>) {
    ray_light[ray] = light;
}

// Where a ray offered a light at `centre` aims (camera-relative, as `offer_shadow_ray`'s
// `light`; `first` and `second` its edges, `lights::Light`'s): an area light's point drawn
// uniformly over its area from the pixel's random numbers (so its rays' visible share is,
// on average, the share of it the lit point `seen_from` sees: penumbrae, which the filter and
// history then smooth as they do any shadow's noise); a point or spot's position.
fn shadow_target(kind: u32, centre: vec3<f32>, first: vec3<f32>, second: vec3<f32>, seen_from: vec3<f32>) -> vec3<f32> {
    if kind < LIGHT_SPHERE {
        return centre;
    }
    let uv = vec2<f32>(next_random(), next_random());
    return area_light_point(kind, centre, first, second, uv, seen_from);
}

// The pixel's next random number, uniform in (0, 1].
fn shadow_random() -> f32 {
    return next_random();
}

// `ray` keeps `term` (of `weight`): its key is drawn above what the old key allows, and
// the weight to skip before the next replacement from the new key.
fn keep_term(ray: u32, term: vec3<f32>, light: vec3<f32>, weight: f32) {
    let floor = exp(weight * log_key[ray]);
    let key_log = log(mix(floor, 1.0, next_random())) / weight;
    log_key[ray] = key_log;
    weight_to_skip[ray] = log(next_random()) / key_log;
    ray_light[ray] = light;
    ray_term[ray] = term;
    ray_aggregate[ray] = offering_aggregate;
}

// The share of the offered terms' sum that reaches the world-space surface `point` with
// `normal` (`position_error` as `light_visible`'s), a channel at a time: each ray's term
// scaled to stand for all the terms dealt to it, traced, the visible ones over all.
// A channel no kept term lights takes the rays' luminance share. 1 when nothing was
// offered.
fn shadow_ratio(point: vec3<f32>, normal: vec3<f32>, position_error: f32) -> vec3<f32> {
    // One ray: its term stands for every term, in every channel alike, so the share is
    // its visibility. Said outright, so that the loop keeps neither the kept term nor the
    // sum of weights (H200: fewer registers live across the loop).
    if SHADOW_RAYS == 1u {
        if log_key[0] == NO_KEY {
            return vec3<f32>(1.0);
        }
        return vec3<f32>(select(0.0, 1.0, light_visible(point, normal, position_error, ray_light[0] + view.origin.xyz)));
    }
    if offered == 0u {
        return vec3<f32>(1.0);
    }
    var visible = vec3<f32>(0.0);
    var all = vec3<f32>(0.0);
    var visible_weight = 0.0;
    var all_weight = 0.0;
    let rays = min(offered, SHADOW_RAYS);
    for (var ray = 0u; ray < rays; ray++) {
        let term = ray_term[ray];
        let weight = weight_sum[ray];
        let estimate = term * (weight / luminance(term));
        all += estimate;
        all_weight += weight;
        if light_visible(point, normal, position_error, ray_light[ray] + view.origin.xyz) {
            visible += estimate;
            visible_weight += weight;
        }
    }
    let luminance_share = visible_weight / all_weight;
    return select(vec3<f32>(luminance_share), visible / all, all > vec3<f32>(0.0));
}

// A pixel's shadow pass targets, after its loop: `unshadowed` radiance and `emission` as
// the HDR target holds them, its unit `normal`, and the light its ray kept.
fn shadow_pass_targets(unshadowed: vec3<f32>, emission: vec3<f32>, normal: vec3<f32>) -> ShadowPassTargets {
    var ray = vec3<f32>(NO_SHADOW_RAY, 0.0, 0.0);
    if log_key[0] != NO_KEY {
        ray = ray_light[0];
    }
    return ShadowPassTargets(vec4<f32>(unshadowed, emission.r), vec4<f32>(normal, emission.b), vec4<f32>(ray, emission.g));
}
