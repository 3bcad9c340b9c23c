// A cluster's view-space box, the order-preserving float codes that bound boxes with
// integer atomics, and the one sphere test assignment and the overflow fallback
// of the shading loop share (its Rust twin: `cluster::sphere_intersects_box`).

// min.w is 1 for a box that holds something and 0 for an empty one (a cluster no visible
// sample falls in): empty boxes meet nothing. An explicit flag, because WGSL's clamp of an
// inverted box may return the centre itself.
struct ClusterBounds {
    min: vec4<f32>,
    max: vec4<f32>,
}

fn bounds_are_empty(bounds: ClusterBounds) -> bool {
    return bounds.min.w == 0.0;
}

fn sphere_meets_bounds(center: vec3<f32>, radius: f32, bounds: ClusterBounds) -> bool {
    let offset = clamp(center, bounds.min.xyz, bounds.max.xyz) - center;
    return !bounds_are_empty(bounds) && dot(offset, offset) <= radius * radius;
}

// A float's bits mapped so that unsigned order is the floats' order (negatives flipped).
fn ordered_code(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    return select(bits | 0x80000000u, ~bits, (bits & 0x80000000u) != 0u);
}

fn from_ordered_code(code: u32) -> f32 {
    return bitcast<f32>(select(~code, code & 0x7fffffffu, (code & 0x80000000u) != 0u));
}
