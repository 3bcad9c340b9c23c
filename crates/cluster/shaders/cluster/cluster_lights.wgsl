// What every clustered shading pass (Forward+, deferred lighting) binds at group 3 (the
// lists and lights of listed_lights.wgsl, the heatmap's scale and the far field), the
// loop over one cluster's lights, and the cluster debug views (lights-per-cluster heatmap
// with a legend strip, depth-slice colouring).
//
// The loop is composed per `cluster::LightLoop`: the falloff and the output are constants
// of the program, and the far field's code is in it only when the frame has one
// (LIGHT_LOOP_FAR_TREE, LIGHT_LOOP_FAR_STOCHASTIC), so no pixel branches on a setting.
// With LIGHT_LOOP_SHADOWS and SHADOWS_EXACT every light that adds to the pixel gets a
// shadow ray through the scene's BVH (visibility/bvh.wgsl); a
// far-field aggregate gets one ray, to its power centroid. With SHADOW_RAYS the pixel
// traces that many rays after its loop, to lights (or aggregates) drawn from its terms,
// and scales its sum by the share they find visible (visibility/shadow_rays.wgsl).

#import manylights::common::surface::Surface
#import manylights::lights::light_set::{Light, LIGHT_SPHERE, MIN_DISTANCE_SQUARED}
#import manylights::common::view::relative_to_origin
#import manylights::lights::lighting_group::LOOP_PARAMS_BINDING
#import manylights::lights::shading::{LoopLight, loop_light, light_power_share, shade_loop_light, loop_second_edge, FALLOFF_WINDOWED_INVERSE_SQUARE, FALLOFF_INVERSE_SQUARE}
#import manylights::lights::brdf::{LitSurface, loop_sum_radiance, surface_for_loop}
#import manylights::cluster::far_nodes::{
    FarFieldParams, FarNode, FAR_ENTRY_EXACT, cut_slots, far_level_first, stochastic_weight
}
#import manylights::cluster::cluster_index::{ClusterParams, cluster_slice}
#import manylights::cluster::bounds::{ClusterBounds, ViewLight, sphere_meets_bounds}
// What an aggregate and a light beyond its radius add (the far field's terms, unshadowed).
#import manylights::cluster::far_shading::{shade_aggregate, shade_light_complement}
// The far field's bindings (7 to 10) and the walk over a cluster's cut of the tree.
#import manylights::cluster::far_terms::{
    far_field, far_nodes, far_order, far_cut, far_entry, far_light
}
// The lists, the lights and the walk over a cluster's list (bindings 0 to 3, 5 and 6).
#import manylights::cluster::listed_lights::{
    grid, offsets, light_indices, lights, view_lights, cluster_bounds, NOT_LISTED,
    cluster_list, listed_light
}
#ifdef LIGHT_LOOP_SHADOWS
#import manylights::common::view::view
#import manylights::visibility::bvh::{unless_shadowed, unless_shadowed_area}
#endif
#ifdef SHADOW_RAYS
#import manylights::visibility::shadow_rays::{
    begin_shadow_rays, offer_shadow_ray, offer_aggregate_shadow_ray, shadow_ratio,
    kept_aggregate, aim_ray, shadow_random, shadow_target, NO_AGGREGATE, SHADOW_RAYS
}
#endif

// The frame's lighting parameters (`pipeline::LightingUniform`), shared with naive's loop.
struct ClusteredShadingParams {
    // Light count shown as white in the heatmap.
    heatmap_max: f32,
    // Lights in the buffer (naive's loop bound; the lists hold the clustered loops').
    light_count: u32,
    _pad_z: u32,
    _pad_w: u32,
}

// The loop's falloff (`lights::Falloff`, FALLOFF_* in lights/shading.wgsl).
const LOOP_FALLOFF: u32 = #LIGHT_LOOP_FALLOFF;
// What the program outputs: 0 the shaded image, a DEBUG_* code below
// (`cluster::ClusterView`), or a code of the pipeline's own views
// (`deferred::GBufferChannel`).
const LOOP_OUTPUT: u32 = #LIGHT_LOOP_OUTPUT;

// The cluster debug views' codes, shader defs from `cluster::ClusterView::shader_code`.
const DEBUG_HEATMAP: u32 = #CLUSTER_VIEW_HEATMAP;
const DEBUG_SLICES: u32 = #CLUSTER_VIEW_SLICES;
const DEBUG_LIGHT_EVALUATIONS: u32 = #CLUSTER_VIEW_LIGHT_EVALUATIONS;

// The frame's lighting parameters: the heatmap's scale.
@group(#LISTED_LIGHTS_GROUP) @binding(LOOP_PARAMS_BINDING) var<uniform> clustered: ClusteredShadingParams;
struct ClusterShading {
    // Radiance towards the eye.
    radiance: vec3<f32>,
    // Lights evaluated: the debug view `DEBUG_LIGHT_EVALUATIONS` shows it, so tests can
    // prove a pixel shaded its cluster's list and nothing else.
    evaluations: u32,
}

// Radiance towards the eye from every light of `cluster`, and how many were evaluated.
//
// If the lists outgrew the index buffer this frame (it grows for the next one), this
// cluster's list may have been cut short: its lights are then found again, every light
// whose sphere meets the cluster's box, in ascending order. Those are the lights the list
// would hold (the ones outside the assignment's candidate range reach no sample here and
// add exactly zero), in the same order: the same image, only slower. Nothing is dropped.
// One loop serves both cases (with two, lavapipe's Forward+ draws grew its memory by
// 25 MiB a phase in the soak test).
fn shade_cluster(surface: Surface, view_dir: vec3<f32>, cluster: u32) -> ClusterShading {
    let list = cluster_list(cluster);
    var result = ClusterShading(vec3<f32>(0.0), 0u);
    let lit = surface_for_loop(surface, view_dir);
    begin_pixel_shadows(surface);
    for (var i = 0u; i < list.candidates; i++) {
        let light = listed_light(list, i);
        if light == NOT_LISTED {
            continue;
        }
        result.radiance += shade_listed_light(lit, view_dir, loop_light(lights[light]), listed_light_range(light));
        result.evaluations += 1u;
    }
#ifdef LIGHT_LOOP_FAR_TREE
    let far = shade_far_tree(lit, view_dir, cluster);
    result.radiance += far.radiance;
    result.evaluations += far.evaluations;
#endif
    result.radiance = with_pixel_shadows(surface, loop_sum_radiance(lit, result.radiance));
    return result;
}

// The radiance one light of a cluster's list sends towards the eye: windowed, and with
// stochastic culling plus its weighted complement out to its random `range`
// (`listed_light_range`); nothing where its shadow ray is blocked.
fn shade_listed_light(surface: LitSurface, view_dir: vec3<f32>, light: LoopLight, range: f32) -> vec3<f32> {
#ifdef LIGHT_LOOP_FAR_STOCHASTIC
    let radiance = shade_stochastic_light(surface, view_dir, light, range);
#else
    let radiance = shade_loop_light(surface, view_dir, light, LOOP_FALLOFF);
#endif
#ifdef SHADOW_RAYS
    offer_shadow_ray(radiance, listed_light_target(light, surface.position));
    return radiance;
#else
#ifdef SHADOWS_EXACT
#ifndef NO_AREA_LIGHTS
    if light.kind >= LIGHT_SPHERE {
        return unless_shadowed_area(radiance, surface.position + view.origin.xyz, surface.normal, surface.position_error, light.kind, light.world_position, light.direction, loop_second_edge(light));
    }
#endif
    return shadowed(surface, radiance, light.world_position);
#else
    return radiance;
#endif
#endif
}

#ifdef SHADOW_RAYS
// Where a ray offered `light` aims (camera-relative): an area light's random point
// (`shadow_target`), a point or spot's position.
fn listed_light_target(light: LoopLight, seen_from: vec3<f32>) -> vec3<f32> {
#ifdef NO_AREA_LIGHTS
    return light.position;
#else
    return shadow_target(light.kind, light.position, light.direction, loop_second_edge(light), seen_from);
#endif
}
#endif

// The random range stochastic culling drew for the light at `index` (the radius the
// assignment tested, view_lights' w); 0, and nothing read, without stochastic culling.
fn listed_light_range(index: u32) -> f32 {
#ifdef LIGHT_LOOP_FAR_STOCHASTIC
    return view_lights[index].sphere.w;
#else
    return 0.0;
#endif
}

// Whether a listed light can add anything (`shade_listed_light`) at some point of the
// box `low`..`high` (camera-relative world space, as `Surface::position`): its radius, or
// its random range when that is longer, reaches the box; always for the unbounded
// inverse-square falloff (`light_reaches`). Conservative: the squared distance has slack
// for the rounding in which it and the shading's `distance_squared < radius^2` differ
// (a few ulps each), so a light that reaches a point of the box is never refused.
fn light_reaches_box(light: LoopLight, range: f32, low: vec3<f32>, high: vec3<f32>) -> bool {
    if LOOP_FALLOFF == FALLOFF_INVERSE_SQUARE {
        return true;
    }
    let reach = max(light.radius, range);
    let center = light.position;
    let offset = clamp(center, low, high) - center;
    return dot(offset, offset) <= reach * reach * REACH_SLACK;
}

// Relative slack of `light_reaches_box`'s squared-distance test (about 800 f32 ulps).
const REACH_SLACK: f32 = 1.0001;

// `radiance` from a light (or aggregate) at the world-space `position`: without shadows
// as it is, with exact ones nothing where geometry blocks the shadow ray
// (visibility/bvh.wgsl). With a ray budget it is offered to the pixel's rays and kept as
// it is: `with_pixel_shadows` scales the sum.
fn shadowed(surface: LitSurface, radiance: vec3<f32>, position: vec3<f32>) -> vec3<f32> {
#ifdef SHADOW_RAYS
    offer_shadow_ray(radiance, relative_to_origin(position));
    return radiance;
#else
#ifdef LIGHT_LOOP_SHADOWS
    return unless_shadowed(radiance, surface.position + view.origin.xyz, surface.normal, surface.position_error, position);
#else
    return radiance;
#endif
#endif
}

// Start a pixel's shadow rays before its loop (with a ray budget; nothing otherwise).
fn begin_pixel_shadows(surface: Surface) {
#ifdef SHADOW_RAYS
    begin_shadow_rays(surface.position);
#endif
}

// A pixel's summed `radiance` after its loop: with a ray budget, traced and scaled by the
// share of its terms the rays find visible; as it is otherwise. With the spatial filter
// (SHADOW_FILTER) the share is kept in `pixel_visible_share` for the filter, and the
// radiance returned unshadowed; with the forward pipelines' shadow pass (SHADOW_PASS) the
// ray is kept for it, untraced, and the radiance returned unshadowed.
fn with_pixel_shadows(surface: Surface, radiance: vec3<f32>) -> vec3<f32> {
#ifdef SHADOW_RAYS
    let point = surface.position + view.origin.xyz;
#ifdef LIGHT_LOOP_FAR_TREE
    aim_at_aggregated_lights(point);
#endif
#ifdef SHADOW_PASS
    // The shadow pass traces the kept ray (`shadow_pass_targets`).
    return radiance;
#else
    let share = shadow_ratio(point, surface.normal, surface.position_error);
#ifdef SHADOW_FILTER
    pixel_visible_share = share;
    return radiance;
#else
    return radiance * share;
#endif
#endif
#else
    return radiance;
#endif
}

#ifdef SHADOW_FILTER
// The share of its unshadowed radiance the pixel's rays found visible (per channel), set
// by `with_pixel_shadows`: the spatial filter's input (visibility/shadow_filter.wgsl).
var<private> pixel_visible_share: vec3<f32> = vec3<f32>(1.0);
#endif

#ifdef LIGHT_LOOP_FAR_STOCHASTIC
// Stochastic culling: the light's windowed contribution, plus its complement divided by
// the probability that its random range `range` reaches this far (far_nodes.wgsl).
fn shade_stochastic_light(surface: LitSurface, view_dir: vec3<f32>, light: LoopLight, range: f32) -> vec3<f32> {
    var radiance = shade_loop_light(surface, view_dir, light, FALLOFF_WINDOWED_INVERSE_SQUARE);
    let to_light = light.position - surface.position;
    let distance_squared = dot(to_light, to_light);
    if distance_squared < range * range {
        let weight = stochastic_weight(distance_squared, light.radius, far_field.tolerance.x);
        radiance += weight * shade_light_complement(surface, view_dir, light);
    }
    return radiance;
}
#endif

#ifdef LIGHT_LOOP_FAR_TREE
// The light tree's far field: the cluster's cut, each entry one aggregate light or (marked
// exact) every light under its node.
fn shade_far_tree(surface: LitSurface, view_dir: vec3<f32>, cluster: u32) -> ClusterShading {
    var result = ClusterShading(vec3<f32>(0.0), 0u);
    let cut = far_cut(cluster);
    for (var k = 0u; k < cut.entries; k++) {
        let entry = far_entry(cut, k);
        let node = entry.node;
        // A node of one light is that light, shaded exactly (for a spot, through its
        // cone: the aggregate would spread its cone's share of power over every direction).
        if entry.aggregate {
            let radiance = shade_aggregate(surface, view_dir, node);
#ifdef SHADOW_RAYS
            offer_aggregate_shadow_ray(radiance, relative_to_origin(node.centroid), entry.index);
            result.radiance += radiance;
#else
            result.radiance += shadowed(surface, radiance, node.centroid);
#endif
            result.evaluations += 1u;
            continue;
        }
        for (var i = node.first; i < node.first + node.count; i++) {
            let light = lights[far_light(i)];
            result.radiance += shadowed(surface, shade_light_complement(surface, view_dir, loop_light(light)), light.position);
        }
        result.evaluations += node.count;
    }
    return result;
}
#endif

#ifdef SHADOW_RAYS
#ifdef LIGHT_LOOP_FAR_TREE
// Each ray that kept a far-field aggregate aims at one of its lights instead of its power
// centroid: a ray to the centroid sees all of the node's lights or none, and a centroid
// behind a wall would darken lights in plain view. `point`: the shaded point (world).
fn aim_at_aggregated_lights(point: vec3<f32>) {
    for (var ray = 0u; ray < SHADOW_RAYS; ray++) {
        let node = kept_aggregate(ray);
        if node != NO_AGGREGATE {
            aim_ray(ray, relative_to_origin(light_drawn_from(node, point)));
        }
    }
}

// The descent toward one of a node's lights stops at the first node that is small as the
// point sees it (its lights' box spans less than SMALL_NODE of its distance: they lie
// within about 3 degrees of each other, where one ray tells as much as any of them), or
// MAX_DESCENT levels below the cut's node (a 64th of its cell), and aims at that node's
// power centroid; only a leaf reached within them draws one of its lights. Measured on
// the H200 at 1,000,000 lights (`--preset shadows`, rays:1+spatial+temporal): down to the
// leaves, the lighting pass took 0.83 ms more than aiming at the cut's centroids, and 2
// levels 0.55 ms, with the same error against the reference with visibility (0.156 and
// 0.147; the centroids' 0.207).
const SMALL_NODE: f32 = 0.05;
const MAX_DESCENT: u32 = 2u;

// The level of the light tree's node `node` (0: the leaves).
fn far_node_level(node: u32) -> u32 {
    var level = 0u;
    while level < far_field.setup.z && node >= far_level_first(far_field, level + 1u) {
        level += 1u;
    }
    return level;
}

// Whether `node` spans less than SMALL_NODE of its distance from `point`.
fn small_from(node: FarNode, point: vec3<f32>) -> bool {
    let span = node.box_max - node.box_min;
    let away = node.centroid - point;
    return dot(span, span) < SMALL_NODE * SMALL_NODE * dot(away, away);
}

// Where a ray toward the light tree's node `node` aims from `point` (world positions): down
// the tree a child at a time, each drawn in proportion to the power the node counts for it
// (`FarNode::weight`), to one of a leaf's lights drawn likewise, or to the power centroid
// of the node where the descent stops (SMALL_NODE, MAX_DESCENT).
fn light_drawn_from(node: u32, point: vec3<f32>) -> vec3<f32> {
    var index = node;
    var level = far_node_level(node);
    var current = far_nodes[index];
    var descended = 0u;
    while level > 0u && descended < MAX_DESCENT && !small_from(current, point) {
        descended += 1u;
        let first_child = far_level_first(far_field, level - 1u) + (index - far_level_first(far_field, level)) * 8u;
        var left = shadow_random() * current.weight;
        var chosen = first_child;
        for (var child = first_child; child < first_child + 8u; child++) {
            let weight = far_nodes[child].weight;
            if weight > 0.0 {
                // The last child with weight, should roundings leave some over.
                chosen = child;
                left -= weight;
                if left <= 0.0 {
                    break;
                }
            }
        }
        index = chosen;
        current = far_nodes[index];
        level -= 1u;
    }
    if level > 0u || small_from(current, point) {
        return current.centroid;
    }
    var left = shadow_random() * current.weight;
    var position = current.centroid;
    for (var i = current.first; i < current.first + current.count; i++) {
        let light = lights[far_order[i]];
        let power = light.color * (light.intensity * light_power_share(light));
        let weight = max(power.x, max(power.y, power.z));
        if weight > 0.0 {
            position = light.position;
            left -= weight;
            if left <= 0.0 {
                break;
            }
        }
    }
    return position;
}
#endif
#endif

// The shaded pixel, or (`DEBUG_LIGHT_EVALUATIONS`) its count of evaluated lights in every
// channel (exact in the half-float target up to 2048).
fn shade_cluster_lights(surface: Surface, view_dir: vec3<f32>, cluster: u32) -> vec3<f32> {
    let shading = shade_cluster(surface, view_dir, cluster);
    if LOOP_OUTPUT == DEBUG_LIGHT_EVALUATIONS {
        return vec3<f32>(f32(shading.evaluations));
    }
    // What the surface emits itself joins what its lights reflect.
    return shading.radiance + surface.emission;
}

// Black -> blue -> cyan -> green -> yellow -> red -> white as t goes 0 -> 1.
fn heat_colour(t: f32) -> vec3<f32> {
    let stops = array<vec3<f32>, 7>(
        vec3<f32>(0.0, 0.0, 0.0),
        vec3<f32>(0.0, 0.0, 1.0),
        vec3<f32>(0.0, 1.0, 1.0),
        vec3<f32>(0.0, 1.0, 0.0),
        vec3<f32>(1.0, 1.0, 0.0),
        vec3<f32>(1.0, 0.0, 0.0),
        vec3<f32>(1.0, 1.0, 1.0),
    );
    let x = saturate(t) * 6.0;
    let i = min(u32(x), 5u);
    return mix(stops[i], stops[i + 1u], x - f32(i));
}

// Height of the legend strip at the bottom of the heatmap, in pixels.
const LEGEND_HEIGHT: f32 = 8.0;

// Heatmap colour of a pixel: the legend strip at the bottom (0 at the left to
// heatmap_max at the right, ticks at quarters), else the cluster's light count, lightly
// shaded by the surface's facing so the geometry stays readable.
fn heatmap_pixel(frag_xy: vec2<f32>, cluster: u32, normal: vec3<f32>) -> vec3<f32> {
    let screen = grid.tile_and_screen.zw;
    if frag_xy.y > screen.y - LEGEND_HEIGHT {
        let t = frag_xy.x / screen.x;
        let tick = abs(fract(t * 4.0 + 0.5) - 0.5) * screen.x / 4.0 < 1.0;
        return select(heat_colour(t), vec3<f32>(1.0), tick);
    }
    let count = f32(offsets[cluster + 1u] - offsets[cluster]);
    let facing = 0.75 + 0.25 * abs(normal.y);
    return heat_colour(count / clustered.heatmap_max) * facing;
}

// Depth-slice colour of a pixel: alternating hues per slice, tiles in a checkerboard.
fn slice_pixel(frag_xy: vec2<f32>, depth: f32) -> vec3<f32> {
    let slice = cluster_slice(grid, depth);
    let hue = f32(slice % 6u) / 6.0;
    let tile = vec2<u32>(frag_xy / grid.tile_and_screen.xy);
    let checker = select(1.0, 0.7, ((tile.x + tile.y) & 1u) == 1u);
    return heat_colour(0.15 + 0.7 * hue) * checker;
}
