// A cluster's view-space box, the order-preserving float codes that bound boxes with
// integer atomics, the one sphere test assignment and the overflow fallback of the
// shading loop share (its Rust twin: `cluster::sphere_intersects_box`), and the light
// volumes assignment tests: a point light's sphere, a spot's cone (Rust twin:
// `cluster::LightVolume`).

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

// Spot lights are tested by their cone (0: by their range sphere alone, as point lights;
// for measuring what the cone test saves). `ClusterParams.culling_and_bands.x`.
const SPOT_CULLING_CONE: u32 = #SPOT_CULLING_CONE;

// Relative growth of a spot's bounding sphere (mirrored by `cluster::LightVolume`).
const BOUNDING_SPHERE_SLACK: f32 = 1.00001;

// A light in view space as the assignment stores it: position (xyz) and range (w); a
// spot's axis (xyz) and the sine of its outer half-angle (w; -1 for a point light, or a
// spot tested as one).
struct ViewLight {
    sphere: vec4<f32>,
    cone: vec4<f32>,
}

// A light as assignment tests it, in view space: the sphere of its range around its
// position and, for a spot, its cone and the cone's bounding sphere.
struct LightVolume {
    apex: vec3<f32>,
    range: f32,
    // The spot's axis (unit) and the sine of its outer half-angle; sin_outer < 0 for a
    // point light (or a spot tested as one).
    axis: vec3<f32>,
    sin_outer: f32,
    // The smallest sphere around the spot's lit region (the cone cut by the range
    // sphere); the range sphere for a point light. It decides the candidate clusters.
    center: vec3<f32>,
    radius: f32,
}

// `view_light`: view-space position and range; `view_cone`: view-space axis and sine of
// the outer half-angle (negative for point lights), as the assignment stores them.
fn light_volume(view_light: vec4<f32>, view_cone: vec4<f32>) -> LightVolume {
    var volume = LightVolume(view_light.xyz, view_light.w, view_cone.xyz, view_cone.w, view_light.xyz, view_light.w);
    if view_cone.w < 0.0 {
        return volume;
    }
    let sin_outer = view_cone.w;
    let cos_outer = sqrt(max(1.0 - sin_outer * sin_outer, 0.0));
    // Narrow cones (< 45 degrees): the sphere through the apex and the rim of the cap.
    // Wide ones: the sphere around the rim's disc, which holds the apex and the cap too.
    if sin_outer < cos_outer {
        let half_chord = volume.range / (2.0 * cos_outer);
        volume.center = volume.apex + volume.axis * half_chord;
        volume.radius = half_chord;
    } else {
        volume.center = volume.apex + volume.axis * (volume.range * cos_outer);
        volume.radius = volume.range * sin_outer;
    }
    // The sphere passes through the apex and the rim: rounding its far centre (ranges
    // reach 1e15 m with the stochastic far field) must not leave them outside.
    volume.radius *= BOUNDING_SPHERE_SLACK;
    return volume;
}

// Whether the light's volume meets the cluster's box: the range sphere and the bounding
// sphere meet the box, and (spots) the box's bounding sphere meets the infinite cone.
// The cone test is the signed distance of the box's centre from the cone's side,
// |v x axis| cos - (v . axis) sin, which is 1-Lipschitz and <= 0 inside the cone: it
// exceeds the box's half-diagonal only when no point of the box is in the cone, so no lit
// fragment loses its light. |v x axis| rather than sqrt(|v|^2 - (v . axis)^2): no
// cancellation for needle-thin cones.
fn volume_meets_bounds(volume: LightVolume, bounds: ClusterBounds) -> bool {
    if !sphere_meets_bounds(volume.apex, volume.range, bounds) || !sphere_meets_bounds(volume.center, volume.radius, bounds) {
        return false;
    }
    if volume.sin_outer < 0.0 {
        return true;
    }
    let box_center = (bounds.min.xyz + bounds.max.xyz) * 0.5;
    let box_radius = length(bounds.max.xyz - bounds.min.xyz) * 0.5;
    let v = box_center - volume.apex;
    let along = dot(v, volume.axis);
    let across = length(cross(v, volume.axis));
    let cos_outer = sqrt(max(1.0 - volume.sin_outer * volume.sin_outer, 0.0));
    return across * cos_outer - along * volume.sin_outer <= box_radius;
}

// A float's bits mapped so that unsigned order is the floats' order (negatives flipped).
fn ordered_code(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    return select(bits | 0x80000000u, ~bits, (bits & 0x80000000u) != 0u);
}

fn from_ordered_code(code: u32) -> f32 {
    return bitcast<f32>(select(~code, code & 0x7fffffffu, (code & 0x80000000u) != 0u));
}
