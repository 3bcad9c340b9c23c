// The geometry of area lights (spheres, rectangles, triangles; `lights::Light` gives their
// layout), seen from a lit point: the light's cosine-weighted solid angle, and the point
// of the light a specular lobe sees first. Every vector is relative to the lit point;
// `centre` is the light's position, `first` and `second` its two edges (rectangle:
// half-edges; triangle: two corners' offsets from the centroid), `extent` of a sphere is
// its radius (in `second.z`).

#import manylights::lights::light_set::{LIGHT_SPHERE, LIGHT_RECT}

// (brdf.wgsl and shading.wgsl take theirs from here: one name in a composed module.)
const PI: f32 = 3.14159265358979;

// Below this (size / distance)^2 a flat light's integral is taken as a point's,
// A cos(at the light) cos(at the surface) / d^2: that differs from the exact one by about
// (size / distance)^2, 1.6e-5 here, while the polygon formula in f32 loses about
// 6e-8 x distance / size to cancellation between its edges (docs/architecture/area-lights.md).
const SMALL_FLAT_LIGHT: f32 = 1.6e-5;

// The integral over the light of n.l dl, l the direction towards each of its points (the
// "cosine-weighted solid angle", pi times the form factor) for a lit point with unit
// normal `n`: the irradiance a light of unit radiance gives. Zero behind a flat light
// (it emits towards first x second only) and for lights below the horizon.
fn area_cosine_integral(kind: u32, centre: vec3<f32>, first: vec3<f32>, second: vec3<f32>, n: vec3<f32>) -> f32 {
    if kind == LIGHT_SPHERE {
        return sphere_cosine_integral(centre, second.z, n);
    }
    let facing = cross(first, second);
    // Emits towards first x second: the lit point must lie on that side of its plane.
    if !(dot(facing, -centre) > 0.0) {
        return 0.0;
    }
    let distance_squared = dot(centre, centre);
    let rect = kind == LIGHT_RECT;
    // The corners' offsets from the centre (a triangle's fourth is unused).
    let o0 = select(first, -first - second, rect);
    let o1 = select(second, first - second, rect);
    let o2 = select(-first - second, first + second, rect);
    let o3 = second - first;
    let size_squared = max(max(dot(o0, o0), dot(o1, o1)), dot(o2, o2));
    if size_squared < SMALL_FLAT_LIGHT * distance_squared {
        let area = select(1.5, 4.0, rect) * length(facing);
        let inverse_distance = inverseSqrt(distance_squared);
        let cos_light = dot(normalize(facing), -centre) * inverse_distance;
        let cos_surface = max(dot(n, centre) * inverse_distance, 0.0);
        return area * cos_light * cos_surface * inverse_distance * inverse_distance;
    }
    // Wholly above the horizon (most lights, most pixels): the edges straight, without
    // the clip's arrays (which a GPU keeps in slow local memory when indexed at run time).
    let centre_height = dot(centre, n);
    let lowest = min(min(dot(o0, n), dot(o1, n)), select(dot(o2, n), min(dot(o2, n), dot(o3, n)), rect));
    if centre_height + lowest > 0.0 {
        let r0 = inverseSqrt(dot(centre + o0, centre + o0));
        let r1 = inverseSqrt(dot(centre + o1, centre + o1));
        let r2 = inverseSqrt(dot(centre + o2, centre + o2));
        var sum = visible_edge_integral(centre, vec4<f32>(o0, r0), vec4<f32>(o1, r1), n)
            + visible_edge_integral(centre, vec4<f32>(o1, r1), vec4<f32>(o2, r2), n);
        if rect {
            let r3 = inverseSqrt(dot(centre + o3, centre + o3));
            sum += visible_edge_integral(centre, vec4<f32>(o2, r2), vec4<f32>(o3, r3), n)
                + visible_edge_integral(centre, vec4<f32>(o3, r3), vec4<f32>(o0, r0), n);
        } else {
            sum += visible_edge_integral(centre, vec4<f32>(o2, r2), vec4<f32>(o0, r0), n);
        }
        return max(-0.5 * sum, 0.0);
    }
    return polygon_cosine_integral(centre, array<vec3<f32>, 4>(o0, o1, o2, o3), rect, n);
}

// `edge_integral` for corners `a.xyz` and `b.xyz` at the reciprocal distances `a.w` and
// `b.w` from the lit point, without the arc tangent: angle / sin(angle) as a polynomial in
// t = 1 - cos(angle), 1 + t/3 + t^2 p(t) (p fitted by least squares to
// acos(x) / sqrt(1 - x^2) on 0 <= x <= 1, relative error under 3e-7, the fit's own test
// holds it: `lights::reference::area`), exact where the edge spans more than a right
// angle. With the corners' distances shared between their two edges, an edge costs a
// handful of multiply-adds where the arc tangent and the length cost dozens of
// instructions (H200, 10,000 0.3 m squares, lighting pass: 10.84 -> 10.19 ms; docs/results.md).
fn visible_edge_integral(centre: vec3<f32>, a: vec4<f32>, b: vec4<f32>, n: vec3<f32>) -> f32 {
    let across = cross(centre, b.xyz - a.xyz) + cross(a.xyz, b.xyz);
    let inverse_lengths = a.w * b.w;
    let cosine = dot(centre + a.xyz, centre + b.xyz) * inverse_lengths;
    if cosine < 0.0 {
        return edge_integral(centre, a.xyz, b.xyz, n);
    }
    let t = 1.0 - cosine;
    let fit = EDGE_FIT_0 + t * (EDGE_FIT_1 + t * (EDGE_FIT_2 + t * (EDGE_FIT_3 + t * (EDGE_FIT_4 + t * (EDGE_FIT_5 + t * EDGE_FIT_6)))));
    let angle_over_sine = 1.0 + t * (1.0 / 3.0 + t * fit);
    return angle_over_sine * dot(n, across) * inverse_lengths;
}

// The fit's coefficients (`visible_edge_integral`).
const EDGE_FIT_0: f32 = 0.133404706;
const EDGE_FIT_1: f32 = 0.0559697311;
const EDGE_FIT_2: f32 = 0.0327282313;
const EDGE_FIT_3: f32 = -0.0113860422;
const EDGE_FIT_4: f32 = 0.0441324933;
const EDGE_FIT_5: f32 = -0.0322237164;
const EDGE_FIT_6: f32 = 0.0148371321;

// One edge's term of Lambert's formula, angle(a, b) n.(a x b) / |a x b|, for the corners
// centre + a and centre + b (`polygon_cosine_integral` says why from the centre).
fn edge_integral(centre: vec3<f32>, a: vec3<f32>, b: vec3<f32>, n: vec3<f32>) -> f32 {
    let across = cross(centre, b - a) + cross(a, b);
    let sine = length(across);
    if !(sine > 0.0) {
        return 0.0;
    }
    return atan2(sine, dot(centre + a, centre + b)) * dot(n, across) / sine;
}

// Lambert's formula for the polygon of corners centre + o0, o1, o2 (and o3 for a
// rectangle), counter-clockwise seen from the side it emits to, clipped first at the lit
// point's horizon:
//   integral = -1/2 sum over edges (a, b) of angle(a, b) n.(a x b) / |a x b|
// The corners are kept as offsets from the centre: a x b = centre x (b' - a') + a' x b'
// is then exact to rounding even for a light far away, where the product of the two
// nearly parallel long vectors would cancel most of its digits.
//
// Without loops: a convex polygon cut by a plane leaves the horizon once and comes back
// once, so each edge adds its part above the horizon, and the horizon's own edge runs
// from where the polygon left it to where it came back. A loop here would count towards llvmpipe's limit of 65,535
// iterations of the light loop around it, even for the point lights that never enter it
// (docs/testing.md).
fn polygon_cosine_integral(centre: vec3<f32>, corners: array<vec3<f32>, 4>, rect: bool, n: vec3<f32>) -> f32 {
    let centre_height = dot(centre, n);
    let e0 = clipped_edge(centre, centre_height, corners[0], corners[1], n);
    let e1 = clipped_edge(centre, centre_height, corners[1], corners[2], n);
    let e2 = clipped_edge(centre, centre_height, corners[2], select(corners[0], corners[3], rect), n);
    let e3 = clipped_edge(centre, centre_height, corners[3], corners[0], n);
    var sum = e0.sum + e1.sum + e2.sum;
    var left = select(select(vec3<f32>(0.0), e2.left, e2.leaves), e1.left, e1.leaves);
    left = select(left, e0.left, e0.leaves);
    var returned = select(select(vec3<f32>(0.0), e2.returned, e2.returns), e1.returned, e1.returns);
    returned = select(returned, e0.returned, e0.returns);
    var cut = (e0.leaves || e1.leaves || e2.leaves) && (e0.returns || e1.returns || e2.returns);
    if rect {
        sum += e3.sum;
        left = select(left, e3.left, e3.leaves);
        returned = select(returned, e3.returned, e3.returns);
        cut = (e0.leaves || e1.leaves || e2.leaves || e3.leaves) && (e0.returns || e1.returns || e2.returns || e3.returns);
    }
    // The horizon's own edge, from where the boundary left it to where it came back.
    if cut {
        sum += edge_integral(centre, left, returned, n);
    }
    return max(-0.5 * sum, 0.0);
}

// One edge's part above the horizon, and where it crosses it.
struct ClippedEdge {
    sum: f32,
    left: vec3<f32>,
    returned: vec3<f32>,
    leaves: bool,
    returns: bool,
}

// The part of the edge from corner a to corner b (offsets from `centre`) above the
// horizon: the whole edge, the part from a to where it sinks below (it leaves the
// horizon there), the part from where it rises to b (it returns there), or nothing.
fn clipped_edge(centre: vec3<f32>, centre_height: f32, a: vec3<f32>, b: vec3<f32>, n: vec3<f32>) -> ClippedEdge {
    let height_a = centre_height + dot(a, n);
    let height_b = centre_height + dot(b, n);
    let above_a = height_a > 0.0;
    let above_b = height_b > 0.0;
    let crossing = a + (b - a) * (height_a / (height_a - height_b));
    var result = ClippedEdge(0.0, crossing, crossing, above_a && !above_b, above_b && !above_a);
    if above_a || above_b {
        result.sum = edge_integral(centre, select(crossing, a, above_a), select(crossing, b, above_b), n);
    }
    return result;
}

// The same integral for a sphere of radius `radius`: pi sin^2(s) cos(t) while the cap it
// subtends (half-angle s) is wholly above the horizon (t: the angle between the normal
// and the centre), and where the horizon cuts the cap, the closed form for the part above
// it (Snyder 1996, "Area light sources for real-time graphics"). Inside the sphere, the
// whole hemisphere: pi.
fn sphere_cosine_integral(centre: vec3<f32>, radius: f32, n: vec3<f32>) -> f32 {
    let distance_squared = dot(centre, centre);
    let radius_squared = radius * radius;
    if distance_squared <= radius_squared {
        return PI;
    }
    let sin2_cap = radius_squared / distance_squared;
    let cos_t = dot(n, centre) * inverseSqrt(distance_squared);
    if cos_t * cos_t >= sin2_cap {
        return PI * sin2_cap * max(cos_t, 0.0);
    }
    // Cut by the horizon.
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let cot_cap = sqrt(1.0 / sin2_cap - 1.0);
    let y = clamp(-cot_cap * cos_t / sin_t, -1.0, 1.0);
    let chord = sin_t * sqrt(1.0 - y * y);
    let value = (cos_t * acos(y) - cot_cap * chord) * sin2_cap + atan2(chord, cot_cap);
    return max(value, 0.0);
}

// The point of the light nearest the ray from the lit point along `mirror` (the specular
// lobe's peak), relative to the lit point (Karis 2013, "Real Shading in Unreal Engine 4",
// for spheres; for flat lights where the ray meets the light's plane, clamped into the
// rectangle along its edges or into the triangle by its barycentric coordinates; the
// centre where the ray leaves the plane behind).
fn representative_point(kind: u32, centre: vec3<f32>, first: vec3<f32>, second: vec3<f32>, mirror: vec3<f32>) -> vec3<f32> {
    if kind == LIGHT_SPHERE {
        let across = dot(centre, mirror) * mirror - centre;
        let length_across = length(across);
        if length_across <= 0.0 {
            return centre;
        }
        return centre + across * min(second.z / length_across, 1.0);
    }
    let facing = cross(first, second);
    let approach = dot(mirror, facing);
    let depth = dot(centre, facing);
    // The ray meets the plane ahead (depth / approach > 0) from the lit side.
    if !(approach < 0.0 && depth < 0.0) {
        return centre;
    }
    let offset = mirror * (depth / approach) - centre;
    if kind == LIGHT_RECT {
        let u = clamp(dot(offset, first) / dot(first, first), -1.0, 1.0);
        let v = clamp(dot(offset, second) / dot(second, second), -1.0, 1.0);
        return centre + u * first + v * second;
    }
    // Barycentric coordinates of the corners first and second against the third,
    // -first - second (the 2x2 system of the plane's dot products), held inside.
    let third = -first - second;
    let e0 = first - third;
    let e1 = second - third;
    let p = offset - third;
    let d00 = dot(e0, e0);
    let d01 = dot(e0, e1);
    let d11 = dot(e1, e1);
    let determinant = d00 * d11 - d01 * d01;
    var s = (d11 * dot(p, e0) - d01 * dot(p, e1)) / determinant;
    var t = (d00 * dot(p, e1) - d01 * dot(p, e0)) / determinant;
    s = max(s, 0.0);
    t = max(t, 0.0);
    let total = s + t;
    if total > 1.0 {
        s /= total;
        t /= total;
    }
    return centre + third + s * e0 + t * e1;
}

// The integral of Blinn-Phong's lobe (n.h)^s times n.l over the hemisphere, seen head-on
// (v = n, so h lies half-way to l): with u = cos(angle(n, l) / 2),
//   8 pi [2 u^(s+4) / (s+4) - u^(s+2) / (s+2)] from 1/sqrt(2) to 1,
// which is pi for s = 0 and falls as 8 pi / s. An area light's Blinn-Phong specular term
// never exceeds it (times the specular colour).
fn blinn_phong_lobe_albedo(s: f32) -> f32 {
    let low = exp2(-0.5 * (s + 2.0));
    return 8.0 * PI * ((2.0 / (s + 4.0) - 1.0 / (s + 2.0)) - low * (1.0 / (s + 4.0) - 1.0 / (s + 2.0)));
}

// The point of an area light at parameters `uv` in [0, 1]^2, spread uniformly over its
// area (a sphere's: over the disk through its centre facing `seen_from`), in the space
// `centre` and `seen_from` are in: where shadow rays aim (`visibility::bvh`'s stratified rays
// for exact shadows, `visibility::shadow_rays`' random ones for a ray budget).
fn area_light_point(kind: u32, centre: vec3<f32>, first: vec3<f32>, second: vec3<f32>, uv: vec2<f32>, seen_from: vec3<f32>) -> vec3<f32> {
    if kind == LIGHT_SPHERE {
        let axis = normalize(centre - seen_from);
        // Any two unit vectors across the axis (Duff et al. 2017).
        let sign = select(-1.0, 1.0, axis.z >= 0.0);
        let a = -1.0 / (sign + axis.z);
        let b = axis.x * axis.y * a;
        let across_u = vec3<f32>(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
        let across_v = vec3<f32>(b, sign + axis.y * axis.y * a, -axis.y);
        let radius = second.z * sqrt(uv.x);
        let angle = 2.0 * PI * uv.y;
        return centre + radius * (cos(angle) * across_u + sin(angle) * across_v);
    }
    if kind == LIGHT_RECT {
        return centre + (2.0 * uv.x - 1.0) * first + (2.0 * uv.y - 1.0) * second;
    }
    // The square onto the triangle, area for area.
    let root = sqrt(uv.x);
    return centre + first * (1.0 - root) + second * (root * (1.0 - uv.y)) + (-first - second) * (root * uv.y);
}
