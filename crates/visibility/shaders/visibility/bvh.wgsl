// The scene's BVH traced in WGSL: the GPU half of `visibility::SceneBvh` (crates/visibility/
// src/bvh.rs), which mirrors every function here in f64 for the accuracy reference. No
// ray-tracing hardware: a depth-first traversal with a stack in private memory, in any
// stage (the naive fragment pass, the clustered lighting passes, the probe's compute).
//
// The tree is bound at group BVH_GROUP (3 in manylights' passes; an engine's choice in its
// own, `visibility::ShadowQueries`) from binding BVH_BINDING (lights/lighting_group.wgsl): a uniform,
// then the nodes and triangles as RGBA32F texels (`BVH_ROW_TEXELS` to a row) and the
// alpha-masked materials' coverage atlas. Textures, because the clustered passes already
// bind the 8 storage buffers WebGPU guarantees a stage.

#import manylights::lights::light_set::{Light, LIGHT_SPHERE, second_edge}
#import manylights::lights::area::area_light_point
#import manylights::lights::lighting_group::{
    BVH_BINDING, BVH_NODES_BINDING, BVH_TRIANGLES_BINDING, COVERAGE_ATLAS_BINDING
}

// Texels in a row of the node and triangle textures.
const BVH_ROW_TEXELS: u32 = #BVH_ROW_TEXELS;
// The traversal stack: one more than the deepest tree `SceneBvh::build` accepts.
const BVH_STACK_SIZE: u32 = #BVH_STACK_SIZE;
const MAX_COVERAGE_MASKS: u32 = #MAX_COVERAGE_MASKS;
// A triangle whose material has no alpha test.
const NO_MASK: u32 = 0xffffffffu;
// The shadow ray's offset (`visibility::shadow_offset`): 0.1 mm plus 2^-17 of the point's
// largest coordinate.
const SHADOW_OFFSET_ABSOLUTE: f32 = 1.0 / f32(#SHADOW_OFFSET_ABSOLUTE_INVERSE);
const SHADOW_OFFSET_RELATIVE: f32 = 1.0 / f32(#SHADOW_OFFSET_RELATIVE_INVERSE);
// The slab test's far distance is widened by 4 f32 ulps (Ize 2013): a ray along a box's
// face is never lost.
const BOX_FAR_WIDENING: f32 = 1.0 + 4.0 * 1.1920929e-7;

struct BvhParams {
    // Nodes, triangles, coverage masks, unused.
    counts: vec4<u32>,
    // Each mask's place in the atlas: x, y, width, height.
    mask_rects: array<vec4<u32>, MAX_COVERAGE_MASKS>,
}

@group(#BVH_GROUP) @binding(BVH_BINDING) var<uniform> bvh: BvhParams;
// Two texels a node: (min, first), (max, count); count 0 marks an inner node whose
// children are nodes first and first + 1, else the node's triangles start at first.
@group(#BVH_GROUP) @binding(BVH_NODES_BINDING) var bvh_nodes: texture_2d<f32>;
// Four texels a triangle: (v0, mask), (v1, u0), (v2, v0's v), (uv1, uv2).
@group(#BVH_GROUP) @binding(BVH_TRIANGLES_BINDING) var bvh_triangles: texture_2d<f32>;
// 1 where an alpha-masked material's texel blocks light, 0 where the alpha test cuts it.
@group(#BVH_GROUP) @binding(COVERAGE_ATLAS_BINDING) var coverage_atlas: texture_2d<f32>;

fn texel_coordinates(index: u32) -> vec2<u32> {
    return vec2<u32>(index % BVH_ROW_TEXELS, index / BVH_ROW_TEXELS);
}

fn node_texel(index: u32) -> vec4<f32> {
    return textureLoad(bvh_nodes, texel_coordinates(index), 0);
}

fn triangle_texel(index: u32) -> vec4<f32> {
    return textureLoad(bvh_triangles, texel_coordinates(index), 0);
}

// Slab test of the box [lo, hi] for t in [t_min, t_max].
fn box_hit(lo: vec3<f32>, hi: vec3<f32>, origin: vec3<f32>, inverse: vec3<f32>, t_min: f32, t_max: f32) -> bool {
    let t0 = (lo - origin) * inverse;
    let t1 = (hi - origin) * inverse;
    let near_t = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), t_min);
    let far_t = min(min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)), t_max) * BOX_FAR_WIDENING;
    return near_t <= far_t;
}

// Whether coverage mask `mask` blocks light at `uv` (repeated, nearest texel of level 0).
fn mask_covered(mask: u32, uv: vec2<f32>) -> bool {
    let rect = bvh.mask_rects[mask];
    let wrapped = uv - floor(uv);
    let x = min(u32(wrapped.x * f32(rect.z)), rect.z - 1u);
    let y = min(u32(wrapped.y * f32(rect.w)), rect.w - 1u);
    return textureLoad(coverage_atlas, vec2<u32>(rect.x + x, rect.y + y), 0).r > 0.5;
}

// The watertight ray-triangle test (Woop, Benthin and Wald 2013) of triangle `index`:
// its distance, or -1 when the ray misses it within (t_min, t_max) or its mask lets the
// ray through there.
fn triangle_hit(index: u32, origin: vec3<f32>, direction: vec3<f32>, t_min: f32, t_max: f32) -> f32 {
    let t0 = triangle_texel(index * 4u);
    let t1 = triangle_texel(index * 4u + 1u);
    let t2 = triangle_texel(index * 4u + 2u);
    let abs_dir = abs(direction);
    var kz = 2u;
    if abs_dir.x > abs_dir.y && abs_dir.x > abs_dir.z {
        kz = 0u;
    } else if abs_dir.y > abs_dir.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if direction[kz] < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let shear_x = direction[kx] / direction[kz];
    let shear_y = direction[ky] / direction[kz];
    let shear_z = 1.0 / direction[kz];
    let a = t0.xyz - origin;
    let b = t1.xyz - origin;
    let c = t2.xyz - origin;
    let ax = a[kx] - shear_x * a[kz];
    let ay = a[ky] - shear_y * a[kz];
    let bx = b[kx] - shear_x * b[kz];
    let by = b[ky] - shear_y * b[kz];
    let cx = c[kx] - shear_x * c[kz];
    let cy = c[ky] - shear_y * c[kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return -1.0;
    }
    let det = u + v + w;
    if det == 0.0 {
        return -1.0;
    }
    let t = (u * a[kz] + v * b[kz] + w * c[kz]) * shear_z / det;
    if !(t > t_min && t < t_max) {
        return -1.0;
    }
    let mask = bitcast<u32>(t0.w);
    if mask != NO_MASK {
        let uv12 = triangle_texel(index * 4u + 3u);
        let uv = (vec2<f32>(t1.w, t2.w) * u + uv12.xy * v + uv12.zw * w) / det;
        if !mask_covered(mask, uv) {
            return -1.0;
        }
    }
    return t;
}

struct TraceResult {
    hit: bool,
    // The nearest hit's distance (closest-hit traces), in units of the direction's length.
    t: f32,
    // The triangle hit (the tree's order, `SceneBvh::triangles`).
    triangle: u32,
}

// Traces `origin + t * direction`, t_min < t < t_max: with `any_hit`, stops at the first
// surface found (shadow rays); otherwise finds the nearest.
fn trace(origin: vec3<f32>, direction: vec3<f32>, t_min: f32, t_max: f32, any_hit: bool) -> TraceResult {
    var result = TraceResult(false, t_max, 0u);
    if bvh.counts.x == 0u || dot(direction, direction) == 0.0 {
        return result;
    }
    // A zero component would divide to infinity, which WGSL does not promise: a tiny one
    // gives the same slab answer with finite numbers.
    let tiny = vec3<f32>(1e-30);
    let inverse = 1.0 / select(direction, tiny, abs(direction) < tiny);
    var stack: array<u32, BVH_STACK_SIZE>;
    var depth = 1u;
    stack[0] = 0u;
    while depth > 0u {
        depth -= 1u;
        let node = stack[depth];
        let lo = node_texel(node * 2u);
        let hi = node_texel(node * 2u + 1u);
        if !box_hit(lo.xyz, hi.xyz, origin, inverse, t_min, result.t) {
            continue;
        }
        let first = bitcast<u32>(lo.w);
        let count = bitcast<u32>(hi.w);
        if count == 0u {
            stack[depth] = first + 1u;
            stack[depth + 1u] = first;
            depth += 2u;
            continue;
        }
        for (var i = first; i < first + count; i++) {
            let t = triangle_hit(i, origin, direction, t_min, result.t);
            if t < 0.0 {
                continue;
            }
            result.hit = true;
            result.t = t;
            result.triangle = i;
            if any_hit {
                return result;
            }
        }
    }
    return result;
}

// Whether a light at `light` (world space) reaches the world-space surface point `point`
// with unit normal `normal`: the shadow ray of `visibility::shadow_ray` (from `offset`
// along the normal to `offset` short of the light) meets nothing. `position_error`: how
// far `point` may lie off its surface beyond the offset rule's roundings (a position
// rebuilt from depth, `Surface::position_error`), added to the start's offset; 0 for
// interpolated positions, which the f64 reference's rule then matches exactly.
fn light_visible(point: vec3<f32>, normal: vec3<f32>, position_error: f32, light: vec3<f32>) -> bool {
    let extent = abs(point);
    let offset = SHADOW_OFFSET_ABSOLUTE + SHADOW_OFFSET_RELATIVE * max(max(extent.x, extent.y), extent.z);
    // The point's error moves where the ray starts, not the light: it still ends `offset`
    // short of it (a light 5 cm behind a wall stays hidden).
    let start_offset = offset + position_error;
    let origin = point + normal * start_offset;
    let to_light = light - origin;
    let length = sqrt(dot(to_light, to_light));
    if length <= offset {
        return true;
    }
    let direction = to_light * (1.0 - offset / length);
    return !trace(origin, direction, 0.0, 1.0, true).hit;
}

// Exact shadows of an area light trace AREA_SHADOW_STRATA^2 rays: one to the centre of
// each cell of a 4 x 4 grid over its area (`lights::area::area_light_point`). Fixed
// points, so a frame is the same every time; a penumbra shows this many steps.
const AREA_SHADOW_STRATA: u32 = 4u;

// `radiance` from an area light (world-space `centre`, edges `first` and `second`, as
// `lights::Light` holds them) times the share of its AREA_SHADOW_STRATA^2 points the
// world-space `point` sees (`light_visible`'s arguments), rays only where it adds
// something.
fn unless_shadowed_area(radiance: vec3<f32>, point: vec3<f32>, normal: vec3<f32>, position_error: f32, kind: u32, centre: vec3<f32>, first: vec3<f32>, second: vec3<f32>) -> vec3<f32> {
    if !any(radiance > vec3<f32>(0.0)) {
        return radiance;
    }
    // One loop over the strata (its rays trace a loop of their own: like every shadow
    // ray's, they count towards llvmpipe's limit on the light loop's iterations, so
    // lavapipe tests keep area lights with exact shadows few: docs/testing.md).
    var seen = 0u;
    for (var k = 0u; k < AREA_SHADOW_STRATA * AREA_SHADOW_STRATA; k++) {
        let uv = (vec2<f32>(f32(k / AREA_SHADOW_STRATA), f32(k % AREA_SHADOW_STRATA)) + 0.5) / f32(AREA_SHADOW_STRATA);
        if light_visible(point, normal, position_error, area_light_point(kind, centre, first, second, uv, point)) {
            seen += 1u;
        }
    }
    return radiance * (f32(seen) / f32(AREA_SHADOW_STRATA * AREA_SHADOW_STRATA));
}

// `radiance` from `light` (world space, any kind) as `unless_shadowed` or, for an area
// light, `unless_shadowed_area` lets it reach `point`.
fn unless_light_shadowed(radiance: vec3<f32>, point: vec3<f32>, normal: vec3<f32>, position_error: f32, light: Light) -> vec3<f32> {
    if light.kind >= LIGHT_SPHERE {
        return unless_shadowed_area(radiance, point, normal, position_error, light.kind, light.position, light.direction, second_edge(light));
    }
    return unless_shadowed(radiance, point, normal, position_error, light.position);
}

// `radiance` from a light at `light` (world space), or nothing where geometry blocks the
// shadow ray from the world-space `point` with unit normal `normal` (`position_error` as
// for `light_visible`): a ray only where the light adds something (in range, in its cone,
// in front of the surface).
fn unless_shadowed(radiance: vec3<f32>, point: vec3<f32>, normal: vec3<f32>, position_error: f32, light: vec3<f32>) -> vec3<f32> {
    if any(radiance > vec3<f32>(0.0)) && !light_visible(point, normal, position_error, light) {
        return vec3<f32>(0.0);
    }
    return radiance;
}
