// Light animation: moves every light along a smooth noise path inside the light box.
// Positions are a pure function of (seed, light index, time), implemented identically in
// `lights::animation` on the CPU (tests compare the two within 1e-4). The radius, one for
// every generated light, is written each frame (a frame-time budget moves it without new
// lights); colours and intensities are left as uploaded.

#import manylights::lights::light_set::{Light, light_bounding_radius}
#import manylights::lights::hash::{pcg_hash, hash_unit}

struct AnimationParams {
    // Light box corners (xyz; w unused).
    box_min: vec4<f32>,
    box_max: vec4<f32>,
    // Time in noise lattice steps (seconds x speed), multiplied on the CPU so that both
    // implementations add exactly the same f32 values.
    noise_time: f32,
    // The generated lights' radius (`LightSettings::radius` at their intensity).
    radius: f32,
    // How far a light wanders from its anchor, as a fraction of the box.
    wander: f32,
    seed: u32,
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Animation parameters of this frame.
@group(0) @binding(0) var<uniform> params: AnimationParams;
// The lights; only positions and radii are written.
@group(0) @binding(1) var<storage, read_write> lights: array<Light>;

// Key of one light's axis: seed, index and axis mixed so streams do not overlap.
fn axis_key(seed: u32, index: u32, axis: u32) -> u32 {
    return pcg_hash(seed ^ pcg_hash(index * 3u + axis));
}

// 1D gradient (Perlin) noise in t with gradients hashed per lattice point; in [-0.5, 0.5].
fn gradient_noise(key: u32, t: f32) -> f32 {
    let cell = floor(t);
    let f = t - cell;
    let lattice = u32(i32(cell));
    let g0 = hash_unit(key ^ pcg_hash(lattice)) * 2.0 - 1.0;
    let g1 = hash_unit(key ^ pcg_hash(lattice + 1u)) * 2.0 - 1.0;
    // Quintic fade (Perlin 2002).
    let fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    return mix(g0 * f, g1 * (f - 1.0), fade);
}

// Folds any real into [0, 1] as a triangle wave, so wandering lights bounce off the box.
fn fold_unit(u: f32) -> f32 {
    let m = u - 2.0 * floor(u * 0.5);
    return 1.0 - abs(1.0 - m);
}

fn animated_position(index: u32) -> vec3<f32> {
    var unit = vec3<f32>(0.0);
    for (var axis = 0u; axis < 3u; axis++) {
        let key = axis_key(params.seed, index, axis);
        let anchor = hash_unit(key);
        // Each light's path starts at its own place on the noise lattice.
        // (64 steps of range keeps the f32 lattice coordinate precise to ~1e-5.)
        let offset = hash_unit(key ^ 0x9e3779b9u) * 64.0;
        unit[axis] = fold_unit(anchor + params.wander * 2.0 * gradient_noise(key, offset + params.noise_time));
    }
    return params.box_min.xyz + (params.box_max.xyz - params.box_min.xyz) * unit;
}

@compute @workgroup_size(#ANIMATE_WORKGROUP_SIZE)
fn animate(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    lights[id.x].position = animated_position(id.x);
    lights[id.x].radius = params.radius + light_bounding_radius(lights[id.x]);
}
