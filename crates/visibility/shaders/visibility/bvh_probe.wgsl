// The BVH traversal on the GPU, for tests: each invocation traces one ray both ways
// (nearest hit and any hit) through the very functions the shading passes use, so the
// tests check the shader itself against the f64 traversal.

#import manylights::visibility::bvh::{trace, light_visible}

struct ProbeRay {
    // Origin (xyz) and t_min (w).
    origin: vec4<f32>,
    // Direction (xyz) and t_max (w).
    direction: vec4<f32>,
    // A shadow ray's normal (xyz); w unused.
    normal: vec4<f32>,
}

struct ProbeResult {
    // Nearest hit: 1 or 0.
    closest_hit: u32,
    // Its distance (t_max on a miss).
    closest_t: f32,
    // Any hit in the range: 1 or 0.
    any_hit: u32,
    // `light_visible(origin, normal, 0, origin + direction)`: 1 or 0.
    visible: u32,
    // The triangle of the nearest hit.
    closest_triangle: u32,
}

@group(3) @binding(0) var<storage, read> rays: array<ProbeRay>;
@group(3) @binding(1) var<storage, read_write> results: array<ProbeResult>;

@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&rays) {
        return;
    }
    let ray = rays[id.x];
    let closest = trace(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w, false);
    let any = trace(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w, true);
    let visible = light_visible(ray.origin.xyz, ray.normal.xyz, 0.0, ray.origin.xyz + ray.direction.xyz);
    results[id.x] = ProbeResult(u32(closest.hit), closest.t, u32(any.hit), u32(visible), closest.triangle);
}
