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
// The random numbers hash the surface's position with the ray's count of offers: a
// static camera and static lights give the same image in every frame.

#import manylights::lights::hash::pcg_hash
#import manylights::visibility::bvh::light_visible

const SHADOW_RAYS: u32 = #SHADOW_RAYS;

// Each ray's kept light (world space), its term, and the luminance of every term it was
// offered: the reservoir of one ray.
var<private> ray_light: array<vec3<f32>, SHADOW_RAYS>;
var<private> ray_term: array<vec3<f32>, SHADOW_RAYS>;
var<private> ray_weight_sum: array<f32, SHADOW_RAYS>;
// Terms offered so far (those that add anything), and the random state.
var<private> offered: u32;
var<private> random_state: u32;

fn luminance(term: vec3<f32>) -> f32 {
    return dot(term, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Start a pixel's rays at the surface point `position` (any space: only its bits are
// hashed).
fn begin_shadow_rays(position: vec3<f32>) {
    let bits = bitcast<vec3<u32>>(position);
    random_state = pcg_hash(bits.x ^ pcg_hash(bits.y ^ pcg_hash(bits.z)));
    offered = 0u;
    for (var ray = 0u; ray < SHADOW_RAYS; ray++) {
        ray_weight_sum[ray] = 0.0;
    }
}

// Offer one light's unshadowed `term` (any common factor of the loop left out: only its
// proportions matter) from the world-space `light` to the next ray in turn.
fn offer_shadow_ray(term: vec3<f32>, light: vec3<f32>) {
    let weight = luminance(term);
    if !(weight > 0.0) {
        return;
    }
    let ray = offered % SHADOW_RAYS;
    offered += 1u;
    let sum = ray_weight_sum[ray] + weight;
    ray_weight_sum[ray] = sum;
    random_state = pcg_hash(random_state);
    let unit = f32(random_state >> 8u) * (1.0 / 16777216.0);
    // Keep this term with probability weight / sum (always for a ray's first term: unit < 1).
    if unit * sum < weight {
        ray_light[ray] = light;
        ray_term[ray] = term;
    }
}

// The share of the offered terms' sum that reaches the world-space surface `point` with
// `normal` (`position_error` as `light_visible`'s), a channel at a time: each ray's term
// scaled to stand for all the terms it was offered, traced, the visible ones over all.
// A channel no kept term lights takes the rays' luminance share. 1 when nothing was
// offered.
fn shadow_ratio(point: vec3<f32>, normal: vec3<f32>, position_error: f32) -> vec3<f32> {
    var visible = vec3<f32>(0.0);
    var all = vec3<f32>(0.0);
    var visible_weight = 0.0;
    var all_weight = 0.0;
    let rays = min(offered, SHADOW_RAYS);
    for (var ray = 0u; ray < rays; ray++) {
        let term = ray_term[ray];
        let weight = ray_weight_sum[ray];
        let estimate = term * (weight / luminance(term));
        all += estimate;
        all_weight += weight;
        if light_visible(point, normal, position_error, ray_light[ray]) {
            visible += estimate;
            visible_weight += weight;
        }
    }
    if rays == 0u {
        return vec3<f32>(1.0);
    }
    let luminance_share = visible_weight / all_weight;
    return select(vec3<f32>(luminance_share), visible / all, all > vec3<f32>(0.0));
}
