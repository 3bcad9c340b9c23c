// The full-frame reference with visibility (`visibility::GpuVisibleReference`): at every
// pixel of a surface capture, every light's term (the scene's BRDF, the asked falloff)
// counted where its shadow ray, the f64 reference's ray (`visibility::shadow_ray`), is
// clear.
//
// Exact (`rays_per_sampler == 0`): every light that adds to the pixel gets a ray, and the
// visible terms are summed with Neumaier's compensation (estimates[0] the sum, [1] its
// compensation).
//
// Estimated: SAMPLERS independent systematic samples, each of about `rays_per_sampler`
// lights drawn in proportion to their unshadowed term's brightest channel w_i. Scaled by
// s_i = w_i x rays_per_sampler / W (W per pixel, from the unshadowed reference), the
// lights lie end to end on a line, x_i = s_1 + ... + s_i; sampler r draws light i once
// for each point j + xi_r (j = 0, 1, ...; xi_r uniform in [0, 1), its own per pixel) in
// [x_(i-1), x_i). A light is so drawn s_i times on average, whatever W is, and counts its
// term / s_i per draw where its ray is clear: each sampler's sum is unbiased, and exact
// where nothing is shadowed (its draws then add up to the unshadowed sum's share). One
// ray serves every sampler that draws the light. The CPU averages the samplers and takes
// the standard error from their spread.
//
// x is kept as a whole part (u32) and a fraction in [0, 1): the fraction's additions round
// to at most 2^-25, so lights with s_i under that are lost; they add up to at most
// n 2^-25 of the ~rays_per_sampler drawn (n lights): 1.2e-4 of the estimate at a million
// lights and 256 rays a sampler, far inside its standard error.

#import manylights::lights::light_set::Light
#import manylights::lights::shading::shade_loop_light
#import manylights::lights::brdf::surface_for_loop
#import manylights::lights::reference_terms::{CompensatedSum, captured_surface, compensated_add, relative_loop_light}
#import manylights::lights::hash::{pcg_hash, hash_unit}
#import manylights::visibility::bvh::unless_light_shadowed

const SAMPLERS: u32 = #VISIBLE_REFERENCE_SAMPLERS;
// The rays count's top bit: the light loop did not reach its end.
const STOPPED_SHORT: u32 = 0x80000000u;

struct VisibleReferenceParams {
    // The world position the captured positions are relative to (xyz; w unused).
    origin: vec4<f32>,
    // The camera, relative to `origin` (xyz; w unused).
    camera: vec4<f32>,
    // This band's first pixel and its pixel count (the state and estimates hold a band).
    first_pixel: u32,
    band_pixels: u32,
    // The first light of this dispatch, its light count.
    first_light: u32,
    light_count: u32,
    // The falloff (`lights::Falloff`'s shader mode).
    falloff: u32,
    // Always 0, but read at run time: see `reference_terms::opaque`.
    opaque_zero: u32,
    // Rays each sampler draws at a pixel, on average; 0: every light's ray (exact).
    rays_per_sampler: f32,
    // Seeds the samplers' offsets.
    seed: u32,
}

@group(3) @binding(0) var<uniform> params: VisibleReferenceParams;
// The surface capture (`gpu::SurfaceImage`), as `lights::GpuReference` reads it.
@group(3) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(3) @binding(2) var<storage, read> normal_lobes: array<vec4<f32>>;
@group(3) @binding(3) var<storage, read> albedos: array<vec4<f32>>;
@group(3) @binding(4) var<storage, read> speculars: array<vec4<f32>>;
@group(3) @binding(5) var<storage, read> lights: array<Light>;
// Per band pixel: x's whole part, its fraction (f32 bits), W (f32 bits, written by the
// CPU), the rays traced (the top bit: the light loop stopped short, see below).
@group(3) @binding(6) var<storage, read_write> states: array<vec4<u32>>;
// Per band pixel, SAMPLERS running sums (rgb; w unused).
@group(3) @binding(7) var<storage, read_write> estimates: array<vec4<f32>>;

// Sampler `sampler`'s offset at `pixel`, uniform in [0, 1).
fn sampler_offset(pixel: u32, sampler: u32) -> f32 {
    return hash_unit(pcg_hash(pixel * SAMPLERS + sampler) ^ params.seed);
}

// Draws of sampler `sampler` below x = whole + fraction: the points j + offset < x.
fn draws_below(whole: u32, fraction: f32, offset: f32) -> u32 {
    return whole + select(0u, 1u, fraction > offset);
}

@compute @workgroup_size(64)
fn visible_reference(@builtin(global_invocation_id) id: vec3<u32>) {
    let local = id.x;
    if local >= params.band_pixels {
        return;
    }
    let pixel = params.first_pixel + local;
    let position = positions[pixel];
    if position.w != 1.0 {
        return;
    }
    let surface = captured_surface(position, normal_lobes[pixel], albedos[pixel], speculars[pixel]);
    let view_dir = normalize(params.camera.xyz - position.xyz);
    let shaded = surface_for_loop(surface, view_dir);
    // The shadow ray starts from the world-space point, as the f64 reference's does.
    let world = position.xyz + params.origin.xyz;
    let state = states[local];
    var whole = state.x;
    var fraction = bitcast<f32>(state.y);
    let weight = bitcast<f32>(state.z);
    var rays = state.w;
    let exact = params.rays_per_sampler == 0.0;
    // s_i per unit of w_i; no light reaches a pixel whose W is 0.
    let scale = params.rays_per_sampler / weight;
    if !exact && !(weight > 0.0) {
        return;
    }
    var sums: array<vec3<f32>, SAMPLERS>;
    var offsets: array<f32, SAMPLERS>;
    for (var r = 0u; r < SAMPLERS; r++) {
        sums[r] = estimates[local * SAMPLERS + r].xyz;
        offsets[r] = sampler_offset(pixel, r);
    }
    var exact_sum = CompensatedSum(sums[0], sums[1]);
    let end = params.first_light + params.light_count;
    var i = params.first_light;
    for (; i < end; i++) {
        let light = lights[i];
        let term = shade_loop_light(shaded, view_dir, relative_loop_light(light, params.origin.xyz), params.falloff);
        if all(term == vec3<f32>(0.0)) {
            continue;
        }
        if exact {
            rays += 1u;
            // An area light's share of AREA_SHADOW_STRATA^2 points, as the pipelines'.
            let seen = unless_light_shadowed(term, world, surface.normal, 0.0, light);
            if any(seen > vec3<f32>(0.0)) {
                exact_sum = compensated_add(exact_sum, seen, params.opaque_zero);
            }
            continue;
        }
        let share = max(max(term.x, term.y), term.z) * scale;
        let advanced = fraction + share;
        let carried = floor(advanced);
        let next_whole = whole + u32(carried);
        let next_fraction = advanced - carried;
        var draws: array<u32, SAMPLERS>;
        var drawn = false;
        for (var r = 0u; r < SAMPLERS; r++) {
            draws[r] = draws_below(next_whole, next_fraction, offsets[r]) - draws_below(whole, fraction, offsets[r]);
            drawn = drawn || draws[r] > 0u;
        }
        whole = next_whole;
        fraction = next_fraction;
        if !drawn {
            continue;
        }
        rays += 1u;
        // A drawn area light's visible share on its strata, as in the exact sum: one ray
        // to a random point of it would be 0 or 1 for every sampler at once, a spread the
        // samplers' standard error could not see.
        let seen = unless_light_shadowed(term, world, surface.normal, 0.0, light);
        if any(seen > vec3<f32>(0.0)) {
            let per_draw = seen / share;
            for (var r = 0u; r < SAMPLERS; r++) {
                sums[r] += f32(draws[r]) * per_draw;
            }
        }
    }
    // llvmpipe leaves a loop after 65,535 iterations of it and every loop inside it
    // together (its guard against endless loops): the CPU sizes the dispatches to stay
    // under that, and a loop that still stopped short says so here.
    if i < end {
        rays |= STOPPED_SHORT;
    }
    if exact {
        sums[0] = exact_sum.sum;
        sums[1] = exact_sum.compensation;
    }
    for (var r = 0u; r < SAMPLERS; r++) {
        estimates[local * SAMPLERS + r] = vec4<f32>(sums[r], 0.0);
    }
    states[local] = vec4<u32>(whole, bitcast<u32>(fraction), state.z, rays);
}
