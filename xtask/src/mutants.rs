//! `cargo xtask mutants`: shader mutation testing. Each entry of [`CATALOGUE`] is a small
//! textual change to a named WGSL function (a loop bound, an index, a sign, a constant, a
//! dropped pass). For each, the tool copies every crate's `shaders/` folder into one
//! temporary tree, applies the
//! change, and runs the tests named for it with `MANYLIGHTS_SHADER_DIR` pointing at the
//! copy: the renderer reads its WGSL from there at run time, so the test binaries are
//! built once and never rebuilt (a rebuilt mutated checkout sharing a target directory
//! could silently test the original shaders). A mutant is killed when a test fails.
//!
//! Before the catalogue, a sentinel (an empty `common/view.wgsl`) must be killed: if it
//! survives, the tests are not reading the mutated folder and nothing else is trusted.

use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use anyhow::{Context as _, bail};

/// A test binary of `manylights-tests` and a name filter.
type TestRef = (&'static str, &'static str);

/// One mutation of one WGSL function.
#[derive(Debug)]
pub struct ShaderMutant {
    pub name: &'static str,
    /// Path under the owning crate's `shaders/` folder (`cluster/assign.wgsl`).
    pub file: &'static str,
    pub function: &'static str,
    /// Text that must occur exactly once in the file, and its replacement.
    pub find: &'static str,
    pub replace: &'static str,
    pub tests: &'static [TestRef],
    /// Part of the fast subset (`cargo xtask mutants --fast`).
    pub fast: bool,
}

const EVALUATIONS: TestRef = (
    "forward_plus",
    "clustered_pipelines_evaluate_exactly_their_cluster_lists",
);
const EVERY_GRID: TestRef = (
    "forward_plus",
    "clustered_pipelines_match_naive_on_every_grid",
);
const LISTS: TestRef = (
    "forward_plus",
    "gpu_lists_equal_cpu_lists_for_random_cameras_grids_and_lights",
);
const SLICE_BOUNDARIES: TestRef = (
    "forward_plus",
    "lights_ending_on_slice_boundaries_are_listed_in_the_slices_they_touch",
);
const IN_YOUR_ENGINE: TestRef = (
    "in_your_engine",
    "an_engines_forward_plus_frame_through_the_lists_equals_every_lights",
);
const EMPTY_PIXELS: TestRef = (
    "in_your_engine",
    "empty_pixels_are_nothing_seen_under_either_depth_convention",
);
const ONE_SPOT: TestRef = ("extremes", "one_hundred_thousand_lights_in_one_spot");
const NAIVE_REFERENCE: TestRef = (
    "naive",
    "cornell_matches_the_f64_reference_with_1_8_and_64_lights",
);
const EXPOSURE: TestRef = ("exposure", "");
const GPU_REFERENCE_SUM: TestRef = (
    "naive",
    "compensated_summation_keeps_what_a_plain_f32_sum_loses",
);
const VISIBLE_REFERENCE_ESTIMATE: TestRef = (
    "shadows",
    "beyond_its_budget_the_gpu_reference_estimates_without_bias_and_converges",
);
const DIFFUSE_ONLY: TestRef = ("forward_plus", "diffuse_only_programs_match_naive");
const PBR_REFERENCE: TestRef = ("naive", "pbr_matches_its_f64_twin_at_every_pixel");
const PBR_LAYOUTS: TestRef = (
    "deferred",
    "pbr_metals_and_dielectrics_match_naive_in_every_layout",
);
const SHADOW_RAYS_UNBIASED: TestRef = (
    "shadows",
    "the_ray_budget_is_unbiased_at_every_pixel_under_white_lights",
);
const SHADOW_FILTER_WALL: TestRef = (
    "shadows",
    "the_spatial_filter_keeps_the_far_side_of_a_wall_black",
);
const SHADOW_FILTER_STEP: TestRef = ("shadows", "the_spatial_filter_stops_at_a_depth_step");
const SHADOW_FILTER_CREASE: TestRef = ("shadows", "the_spatial_filter_stops_at_a_crease");
const SHADOW_HISTORY_MOTION: TestRef = (
    "shadows",
    "the_history_follows_surfaces_as_the_camera_moves",
);
const SHADOW_HISTORY_UNCOVERED: TestRef = (
    "shadows",
    "a_surface_uncovered_by_a_camera_move_starts_without_history",
);
const SHADOW_HISTORY_CLAMP: TestRef = (
    "shadows",
    "a_moving_shadow_clamps_the_history_to_the_new_frame",
);
const SHADOW_HISTORY_SWITCH_OFF: TestRef = (
    "shadows",
    "a_light_switched_off_leaves_the_image_within_the_stated_frames",
);
const SHADOW_AGGREGATE_LIGHTS: TestRef = (
    "shadows",
    "a_far_field_aggregate_is_shadowed_light_by_light",
);
const TILES: TestRef = (
    "deferred",
    "the_tile_shared_loop_renders_the_per_pixel_loops_image",
);
const VISIBILITY: TestRef = (
    "deferred",
    "the_visibility_buffer_rebuilds_the_gbuffer_passes_surfaces",
);
const SHADOW_REFERENCE: TestRef = (
    "shadows",
    "naive_with_exact_shadows_matches_the_f64_reference_with_visibility",
);
const SHADOW_WALL: TestRef = ("shadows", "a_light_behind_a_wall_adds_exactly_nothing");
const BLENDED_OVER: TestRef = (
    "blended",
    "overlapping_panes_composite_over_the_room_sorted_or_weighted",
);
const TAA_EDGES: TestRef = (
    "post",
    "taa_converges_to_the_supersampled_frame_at_edges_in_every_pipeline",
);
const TAA_CLIPPING: TestRef = ("post", "taa_clips_history_to_what_the_frame_shows_now");
const BLOOM_LIGHT: TestRef = ("post", "bloom_keeps_the_frames_light_and_black_stays_black");
const TAA_RUNNING_MEAN: TestRef = ("post", "taa_running_mean_matches_its_twin_frame_by_frame");
const TAA_CLIP_BOX: TestRef = ("post", "taa_clips_history_to_its_box_as_its_twin_does");
const TAA_MOVING_HISTORY: TestRef = (
    "post",
    "taa_reads_moving_history_through_catmull_rom_as_its_twin_does",
);
const TAA_SAME_SURFACE: TestRef = (
    "post",
    "taa_keeps_history_of_the_same_surface_only_as_its_twin_does",
);
const TAA_TURNING_SURFACE: TestRef = (
    "post",
    "taa_keeps_history_only_where_the_normal_turned_less_than_its_rule_as_its_twin_does",
);
const BLOOM_TWIN: TestRef = (
    "post",
    "bloom_matches_its_f64_twin_at_every_pixel_and_no_other_design_does",
);
const SHADOW_FILTER_TWIN: TestRef = (
    "shadows",
    "the_spatial_filter_matches_its_twin_at_every_pixel",
);
const SHADOW_HISTORY_TWIN: TestRef = (
    "shadows",
    "the_shadow_history_matches_its_twin_frame_by_frame",
);
const MSAA_FORWARD_PLUS: TestRef = ("msaa", "msaa_forward_plus_equals_naive");
const BLENDED_LAYERS: TestRef = (
    "blended",
    "layers_sort_each_pixel_and_merge_past_their_budget",
);
const BLENDED_BEFORE_DEPTH: TestRef = (
    "blended",
    "a_blended_surface_before_the_visible_depth_is_lit_by_its_lights",
);
const FORWARD_SHADOW_PASS: TestRef = ("shadows", "the_forward_shadow_pass_is_exact_with_one_light");
const REBUILT_SHADOWS: TestRef = (
    "shadows",
    "every_layout_sees_the_lit_floor_beside_a_wall_as_naive_does",
);
const STATISTICS: TestRef = ("forward_plus", "gpu_statistics_equal_the_cpu_reference");
const STATISTICS_EDGES: TestRef = (
    "forward_plus",
    "gpu_statistics_count_the_last_column_and_row",
);
const GOLDEN: TestRef = ("naive", "sponza_with_64_lights_matches_its_golden_image");
const TINY_FRAMES: TestRef = ("extremes", "tiny_odd_and_huge_resolutions");
const LOSSY: TestRef = (
    "deferred",
    "compact_and_packed_stay_within_their_derived_error",
);
const OVERFLOW: TestRef = (
    "forward_plus",
    "an_overflowing_frame_drops_no_light_and_the_buffer_grows_for_the_next",
);
const EVERY_PIXEL: TestRef = ("deferred", "every_pixel_is_written_every_frame");
const ROUNDTRIP: TestRef = (
    "gpu_roundtrip",
    "cornell_base_color_matches_cpu_ray_casting",
);
const ANIMATION: TestRef = ("naive", "gpu_light_animation_matches_the_cpu_within_1e_4");
const FAR_FROM_ORIGIN: TestRef = ("extremes", "geometry_far_from_the_origin");
const FAR_TREE_SORT: TestRef = (
    "far_field",
    "the_trees_sort_is_stable_and_spans_the_lights_box",
);
const FAR_TREE_LATTICE: TestRef = (
    "far_field",
    "the_trees_keys_and_sort_equal_the_cpus_on_a_lattice",
);
const FAR_FIELD_EXACT: TestRef = (
    "far_field",
    "the_tree_at_tolerance_zero_renders_the_unbounded_image_in_every_clustered_loop",
);
const FAR_FIELD_EXTREMES: TestRef = (
    "far_field",
    "extremes_all_lights_in_one_spot_far_outside_inside_a_surface_and_an_empty_far_field",
);
const FAR_FIELD_STRADDLE: TestRef = ("far_field", "an_aggregate_straddling_a_surface_lights_it");
const FAR_FIELD_SEAMS: TestRef = (
    "lab",
    "the_seam_measure_sees_cluster_blocks_where_cuts_disagree_and_the_default_tree_has_none",
);
const BLOTCHES: TestRef = (
    "lab",
    "the_blotch_measure_sees_the_filters_patches_and_the_historys_average",
);
const FAR_FIELD_UNBIASED: TestRef = (
    "far_field",
    "the_stochastic_mean_over_seeds_converges_to_the_reference",
);

const SPOT_REFERENCE: TestRef = ("naive", "cornell_spots_match_the_f64_reference");
const AREA_REFERENCE: TestRef = (
    "area_lights",
    "area_lights_on_diffuse_surfaces_match_the_f64_twin",
);
const AREA_EXTREMES: TestRef = ("area_lights", "area_lights_at_the_extremes");
const FAR_FLAT_LIGHTS: TestRef = (
    "far_field",
    "an_aggregate_of_flat_lights_lights_what_they_face",
);
const AREA_GLOSSY: TestRef = (
    "area_lights",
    "area_lights_on_glossy_surfaces_match_the_twin_within_ltcs_error",
);
const AREA_EMISSIVE: TestRef = (
    "area_lights",
    "an_emissive_quad_lights_the_floor_under_it_in_every_pipeline",
);
const SPOT_CULLING: TestRef = (
    "spots",
    "clustered_pipelines_match_naive_with_generated_spots",
);

/// The mutant every run starts with: if it survives, the mutated folder is not used.
const SENTINEL: ShaderMutant = ShaderMutant {
    name: "sentinel: empty view.wgsl",
    file: "common/view.wgsl",
    function: "(whole file)",
    find: "",
    replace: "",
    tests: &[EVALUATIONS],
    fast: true,
};

pub const CATALOGUE: &[ShaderMutant] = &[
    ShaderMutant {
        name: "shade as many lights as there are instead of the cluster's list",
        file: "cluster/listed_lights.wgsl",
        function: "cluster_list",
        find: "let candidates = select(end - start, grid.scheme_lights_capacity.y, cut_short);",
        replace: "let candidates = grid.scheme_lights_capacity.y;",
        tests: &[EVALUATIONS],
        fast: true,
    },
    ShaderMutant {
        name: "an engine's walk over a cluster's list drops its last light",
        file: "cluster/listed_lights.wgsl",
        function: "cluster_list",
        find: "let candidates = select(end - start, grid.scheme_lights_capacity.y, cut_short);",
        replace: "let candidates = select(end - start - min(end - start, 1u), grid.scheme_lights_capacity.y, cut_short);",
        tests: &[IN_YOUR_ENGINE],
        fast: true,
    },
    ShaderMutant {
        name: "a cluster whose list overflowed shades no light",
        file: "cluster/listed_lights.wgsl",
        function: "listed_light",
        find: "if !sphere_meets_bounds(sphere.xyz, sphere.w, cluster_bounds[list.cluster]) {",
        replace: "if true {",
        tests: &[OVERFLOW],
        fast: true,
    },
    ShaderMutant {
        name: "linear slice off by half a slice",
        file: "cluster/cluster_index.wgsl",
        function: "cluster_slice",
        find: "slice = (depth - near) * scale;",
        replace: "slice = (depth - near) * scale + 0.5;",
        tests: &[EVERY_GRID],
        fast: true,
    },
    ShaderMutant {
        name: "logarithmic slice one too far",
        file: "cluster/cluster_index.wgsl",
        function: "cluster_slice",
        find: "slice = log(depth / near) * scale;",
        replace: "slice = log(depth / near) * scale + 1.0;",
        tests: &[EVERY_GRID],
        fast: false,
    },
    ShaderMutant {
        name: "lists not sorted",
        file: "cluster/assign.wgsl",
        function: "sort_lists",
        find: "    let capacity = grid.scheme_lights_capacity.z;\n    let start = offsets[cluster];",
        replace: "    if cluster < 0xffffffffu { return; }\n    let capacity = grid.scheme_lights_capacity.z;\n    let start = offsets[cluster];",
        tests: &[LISTS],
        fast: true,
    },
    ShaderMutant {
        name: "fill writes light 0 into lists over 256",
        file: "cluster/assign.wgsl",
        function: "fill_lists",
        find: "light_indices[at] = index;",
        replace: "light_indices[at] = select(index, 0u, offsets[cluster + 1u] - offsets[cluster] > 256u);",
        tests: &[ONE_SPOT],
        fast: false,
    },
    ShaderMutant {
        name: "tile walk ranks hits within their batch only",
        file: "cluster/assign.wgsl",
        function: "walk_tile",
        find: "let at = offsets[cluster] + found[s] + rank_in_batch;",
        replace: "let at = offsets[cluster] + rank_in_batch;",
        // The random list test (LISTS) kills it only when a drawn case has a cluster with
        // more than one batch of hits (a fresh-clone CI run drew none, so it survived);
        // 100,000 lights in one spot always have.
        tests: &[ONE_SPOT],
        fast: true,
    },
    ShaderMutant {
        name: "tile walk stops after the first batch of a window",
        file: "cluster/assign.wgsl",
        function: "walk_tile",
        find: "for (var batch = 0u; batch < marked; batch += WALK_THREADS) {",
        replace: "for (var batch = 0u; batch < min(marked, WALK_THREADS); batch += WALK_THREADS) {",
        tests: &[ONE_SPOT],
        fast: false,
    },
    ShaderMutant {
        name: "tile marks skip the last candidate row",
        file: "cluster/assign.wgsl",
        function: "mark_tiles",
        find: "let y = range.lo.y + (i / span.x) % span.y;",
        replace: "let y = range.lo.y + (i / span.x) % max(span.y - 1u, 1u);",
        tests: &[LISTS],
        fast: false,
    },
    ShaderMutant {
        name: "tile walk takes the slice range one short",
        file: "cluster/assign.wgsl",
        function: "walk_tile",
        find: "hi = min(slices >> 16u, group_last);",
        replace: "hi = min(slices >> 16u, group_last) - 1u;",
        tests: &[LISTS],
        fast: false,
    },
    ShaderMutant {
        name: "sphere test with half the squared radius",
        file: "cluster/bounds.wgsl",
        function: "sphere_meets_bounds",
        find: "return !bounds_are_empty(bounds) && dot(offset, offset) <= radius * radius;",
        replace: "return !bounds_are_empty(bounds) && dot(offset, offset) <= 0.5 * radius * radius;",
        tests: &[LISTS],
        fast: false,
    },
    ShaderMutant {
        name: "candidate slices without their margin",
        file: "cluster/assign.wgsl",
        function: "candidate_range",
        find: "min(slice_hi + 1u, last.z)",
        replace: "min(slice_hi, last.z)",
        tests: &[SLICE_BOUNDARIES, LISTS, EVERY_GRID],
        fast: true,
    },
    ShaderMutant {
        name: "candidate tiles without their margin",
        file: "cluster/assign.wgsl",
        function: "candidate_range",
        find: "let tile_max = floor(pixel_max / grid.tile_and_screen.xy) + 1.0;",
        replace: "let tile_max = floor(pixel_max / grid.tile_and_screen.xy);",
        tests: &[LISTS, EVERY_GRID],
        fast: false,
    },
    ShaderMutant {
        name: "prefix sum total one short",
        file: "cluster/assign.wgsl",
        function: "prefix_sum",
        find: "offsets[n] = carry;",
        replace: "offsets[n] = carry - 1u;",
        tests: &[LISTS],
        fast: false,
    },
    ShaderMutant {
        name: "reference's compensated sum turned plain",
        file: "lights/reference_terms.wgsl",
        function: "compensated_add",
        find: "let compensation = opaque(running.compensation + opaque(excess + smaller, zero), zero);",
        replace: "let compensation = vec3<f32>(0.0);",
        tests: &[GPU_REFERENCE_SUM],
        fast: true,
    },
    ShaderMutant {
        name: "visible reference's draws not divided by their share",
        file: "visibility/visible_reference.wgsl",
        function: "visible_reference",
        find: "let per_draw = seen / share;",
        replace: "let per_draw = seen;",
        tests: &[VISIBLE_REFERENCE_ESTIMATE],
        fast: true,
    },
    ShaderMutant {
        name: "lights behind the surface shaded",
        file: "lights/shading.wgsl",
        function: "shade_loop_light",
        find: "let n_dot_to_light = dot(surface.normal, to_light);",
        replace: "let n_dot_to_light = abs(dot(surface.normal, to_light));",
        tests: &[NAIVE_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "window squared once",
        file: "lights/shading.wgsl",
        function: "light_falloff",
        find: "return w * w * min(inverse_square, MAX_INVERSE_SQUARE);",
        replace: "return w * min(inverse_square, MAX_INVERSE_SQUARE);",
        tests: &[NAIVE_REFERENCE],
        fast: false,
    },
    ShaderMutant {
        name: "a far-field aggregate forgets which way its flat lights face",
        file: "cluster/far_terms.wgsl",
        function: "aggregate_term",
        find: "let leaning = select(1.0, max(1.0 - dot(node.dipole, l) / node.weight, 0.0), node.weight > 0.0);",
        replace: "let leaning = 1.0;",
        tests: &[FAR_FLAT_LIGHTS],
        fast: true,
    },
    ShaderMutant {
        name: "a flat light's emission dipole points behind it",
        file: "lights/shading.wgsl",
        function: "light_emission_dipole",
        find: "return 2.0 * normalize(cross(light.direction, second_edge(light)));",
        replace: "return -2.0 * normalize(cross(light.direction, second_edge(light)));",
        tests: &[FAR_FLAT_LIGHTS],
        fast: true,
    },
    ShaderMutant {
        name: "the LTC matrix transposed",
        file: "lights/brdf.wgsl",
        function: "to_cosine",
        find: "entries.x * t + entries.y * n, cross(n, t), entries.z * t + entries.w * n",
        replace: "entries.x * t + entries.z * n, cross(n, t), entries.y * t + entries.w * n",
        tests: &[AREA_GLOSSY],
        fast: true,
    },
    ShaderMutant {
        name: "the LTC frame's view turned to the other side of the normal",
        file: "lights/brdf.wgsl",
        function: "to_cosine",
        find: "normalize(along), dot(along, along) > 1e-12",
        replace: "-normalize(along), dot(along, along) > 1e-12",
        tests: &[AREA_GLOSSY],
        fast: true,
    },
    ShaderMutant {
        name: "an area light's cosine at the light dropped (it emits alike at every angle)",
        file: "lights/area.wgsl",
        function: "area_cosine_integral",
        find: "let cos_light = dot(normalize(facing), -centre) * inverse_distance;",
        replace: "let cos_light = 1.0;",
        tests: &[AREA_EXTREMES],
        fast: true,
    },
    ShaderMutant {
        name: "an area light's polygon not clipped at the horizon",
        file: "lights/area.wgsl",
        function: "clipped_edge",
        find: "result.sum = edge_integral(centre, select(crossing, a, above_a), select(crossing, b, above_b), n);",
        replace: "result.sum = edge_integral(centre, a, b, n);",
        tests: &[AREA_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "a triangle light's area forgotten in its power (radiance = intensity)",
        file: "lights/shading.wgsl",
        function: "emitted_per_intensity",
        find: "return (2.0 / 3.0) / length(cross(light.direction, second));",
        replace: "return 1.0;",
        tests: &[AREA_EMISSIVE],
        fast: true,
    },
    ShaderMutant {
        name: "a sphere light cut by the horizon counted whole",
        file: "lights/area.wgsl",
        function: "sphere_cosine_integral",
        find: "    if cos_t * cos_t >= sin2_cap {",
        replace: "    if true {",
        tests: &[AREA_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "specular dropped",
        file: "lights/brdf.wgsl",
        function: "blinn_phong_brdf",
        find: "return surface.albedo + blinn_phong_specular(surface, view_dir, l);",
        replace: "return surface.albedo;",
        tests: &[NAIVE_REFERENCE],
        fast: false,
    },
    ShaderMutant {
        name: "octahedral fold with the wrong sign",
        file: "deferred/codecs.wgsl",
        function: "octahedral_encode",
        find: "return (1.0 - abs(p.yx)) * sign;",
        replace: "return (1.0 - abs(p.yx)) * -sign;",
        tests: &[LOSSY],
        fast: false,
    },
    ShaderMutant {
        name: "position from depth half a pixel off",
        file: "visibility/rebuilt.wgsl",
        function: "position_from_depth",
        find: "let uv = (vec2<f32>(pixel) + 0.5) * view.viewport.zw;",
        replace: "let uv = (vec2<f32>(pixel) + 1.0) * view.viewport.zw;",
        tests: &[LOSSY],
        fast: false,
    },
    ShaderMutant {
        name: "compute lighting skips the last column",
        file: "deferred/lighting_compute.wgsl",
        function: "cs_lighting",
        find: "if any(id.xy >= size) {",
        replace: "if any(id.xy + vec2<u32>(1u, 0u) >= size) {",
        tests: &[EVERY_PIXEL],
        fast: false,
    },
    // Every other compute pass that walks pixels gets the same boundary mutant.
    ShaderMutant {
        name: "false positives skip the last pixel column",
        file: "cluster/stats.wgsl",
        function: "mark_reached",
        find: "if any(id.xy >= size) {",
        replace: "if any(id.xy + vec2<u32>(1u, 0u) >= size) {",
        tests: &[STATISTICS_EDGES],
        fast: true,
    },
    ShaderMutant {
        name: "tonemap skips the last column",
        file: "gpu/tonemap.wgsl",
        function: "cs_tonemap",
        find: "if any(id.xy >= size) {",
        replace: "if any(id.xy + vec2<u32>(1u, 0u) >= size) {",
        tests: &[GOLDEN],
        fast: false,
    },
    ShaderMutant {
        name: "exposure histogram skips the last column",
        file: "gpu/exposure.wgsl",
        function: "build_histogram",
        find: "if all(id.xy < size) {",
        replace: "if all(id.xy + vec2<u32>(1u, 0u) < size) {",
        tests: &[EXPOSURE],
        fast: false,
    },
    ShaderMutant {
        name: "the visible bounds read empty pixels in the other depth convention (reverse-Z as standard)",
        file: "cluster/visible_bounds.wgsl",
        function: "bound_visible_samples",
        find: "let clear = view.near_far.z;",
        replace: "let clear = 1.0 - view.near_far.z;",
        tests: &[EMPTY_PIXELS],
        fast: true,
    },
    ShaderMutant {
        name: "visible-sample boxes skip the last column",
        file: "cluster/visible_bounds.wgsl",
        function: "bound_visible_samples",
        find: "rect_max = min(rect_max, screen);",
        replace: "rect_max = min(rect_max, screen - vec2<u32>(1u, 0u));",
        tests: &[TINY_FRAMES, EVERY_GRID],
        fast: false,
    },
    ShaderMutant {
        name: "exposure maps the median to twice mid-grey",
        file: "gpu/exposure.wgsl",
        function: "resolve_exposure",
        find: "const MID_GREY: f32 = 0.18;",
        replace: "const MID_GREY: f32 = 0.36;",
        tests: &[EXPOSURE],
        fast: true,
    },
    ShaderMutant {
        name: "exposure takes the lower quartile",
        file: "gpu/exposure.wgsl",
        function: "resolve_exposure",
        find: "let half = (lit + 1u) / 2u;",
        replace: "let half = (lit + 3u) / 4u;",
        tests: &[EXPOSURE],
        fast: false,
    },
    ShaderMutant {
        name: "exposure ignores adaptation",
        file: "gpu/exposure.wgsl",
        function: "resolve_exposure",
        find: "next_log2 = mix(log2(state.value), target_log2, params.adaptation);",
        replace: "next_log2 = target_log2;",
        tests: &[EXPOSURE],
        fast: false,
    },
    ShaderMutant {
        name: "statistics histogram one bucket up",
        file: "cluster/stats.wgsl",
        function: "list_statistics",
        find: "let bucket = select(32u - countLeadingZeros(count), 0u, count == 0u);",
        replace: "let bucket = select(33u - countLeadingZeros(count), 0u, count == 0u);",
        tests: &[STATISTICS],
        fast: false,
    },
    ShaderMutant {
        name: "false positives: every light reaches",
        file: "cluster/stats.wgsl",
        function: "mark_reached",
        find: "if distance_squared < light.w * light.w && in_cone {",
        replace: "if distance_squared >= 0.0 {",
        tests: &[STATISTICS],
        fast: false,
    },
    ShaderMutant {
        name: "animation hash of the wrong axis",
        file: "lights/animate.wgsl",
        function: "axis_key",
        find: "return pcg_hash(seed ^ pcg_hash(index * 3u + axis));",
        replace: "return pcg_hash(seed ^ pcg_hash(index * 3u));",
        tests: &[ANIMATION],
        fast: false,
    },
    ShaderMutant {
        name: "base colour sampled with v flipped",
        file: "common/variants/base_color_textured.wgsl",
        function: "sample_base_color",
        find: "sample_material(base_color_texture, uv)",
        replace: "sample_material(base_color_texture, vec2<f32>(uv.x, 1.0 - uv.y))",
        tests: &[ROUNDTRIP],
        fast: false,
    },
    ShaderMutant {
        name: "lights not made camera-relative",
        file: "common/view.wgsl",
        function: "relative_to_origin",
        find: "return world - view.origin.xyz;",
        replace: "return world;",
        tests: &[NAIVE_REFERENCE, FAR_FROM_ORIGIN],
        fast: false,
    },
    ShaderMutant {
        name: "the far field's complement drops the window's square",
        file: "cluster/far_nodes.wgsl",
        function: "window_complement",
        find: "return (1.0 - window * window) / max(distance_squared, MIN_DISTANCE_SQUARED);",
        replace: "return (1.0 - window) / max(distance_squared, MIN_DISTANCE_SQUARED);",
        tests: &[FAR_FIELD_EXACT],
        fast: true,
    },
    ShaderMutant {
        name: "far-field aggregates are lit from their centroid alone",
        file: "cluster/far_terms.wgsl",
        function: "aggregate_term",
        find: "let to_point = to_centroid + signs * sigma;",
        replace: "let to_point = to_centroid + 0.0 * signs * sigma;",
        tests: &[FAR_FIELD_STRADDLE],
        fast: true,
    },
    ShaderMutant {
        name: "nodes touching a cluster tie at an infinite bound again (split in tree order)",
        file: "cluster/far_field.wgsl",
        function: "node_bound",
        find: "let error = power * spread * (2.0 / (m * m * m) + peak / m);",
        replace: "let error = power * spread * (2.0 / (m * m * m) + peak / max(a, 1e-30));",
        tests: &[FAR_FIELD_SEAMS],
        fast: true,
    },
    ShaderMutant {
        name: "stochastic culling forgets to divide by the probability of reaching",
        file: "cluster/far_nodes.wgsl",
        function: "stochastic_weight",
        find: "return max(1.0, tolerance * distance_squared / radius_squared);",
        replace: "return 1.0;",
        tests: &[FAR_FIELD_UNBIASED],
        fast: true,
    },
    ShaderMutant {
        name: "tree leaves take the run of the next cell",
        file: "cluster/far_field.wgsl",
        function: "lower_bound",
        find: "if keys_in[mid] < key {",
        replace: "if keys_in[mid] <= key {",
        // Lights in leaf 0 are the ones lost: all lights in one spot have only leaf 0.
        tests: &[FAR_FIELD_EXACT, FAR_FIELD_EXTREMES],
        fast: false,
    },
    ShaderMutant {
        name: "the light sort scatters without the rank in its block",
        file: "cluster/far_field.wgsl",
        function: "sort_scatter",
        find: "let at = next_slot[digit] + rank;",
        replace: "let at = next_slot[digit];",
        tests: &[FAR_FIELD_EXACT, FAR_TREE_SORT],
        fast: false,
    },
    ShaderMutant {
        name: "the light sort's rounds do not move a block's next slots on",
        file: "cluster/far_field.wgsl",
        function: "sort_scatter",
        find: "next_slot[thread] += count;",
        replace: "next_slot[thread] += 0u * count;",
        tests: &[FAR_TREE_SORT],
        fast: true,
    },
    ShaderMutant {
        name: "the light sort counts a rank from the thread's own bit up",
        file: "cluster/far_field.wgsl",
        function: "sort_scatter",
        find: "& (bit - 1u));",
        replace: "& ~(bit - 1u));",
        tests: &[FAR_TREE_SORT],
        fast: true,
    },
    ShaderMutant {
        name: "the lights' box is the first workgroup's",
        file: "cluster/far_field.wgsl",
        function: "light_bounds",
        find: "atomicMax(&bounds_codes[thread], atomicLoad(&group_codes[thread]));",
        replace: "atomicMax(&bounds_codes[thread], select(0u, atomicLoad(&group_codes[thread]), id.x == thread));",
        tests: &[FAR_TREE_LATTICE],
        fast: true,
    },
    ShaderMutant {
        name: "spots point backwards",
        file: "lights/shading.wgsl",
        function: "spot_attenuation",
        find: "let cos_angle = -dot(l, light.direction);",
        replace: "let cos_angle = dot(l, light.direction);",
        tests: &[SPOT_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "cone culling forgets the box's size",
        file: "cluster/bounds.wgsl",
        function: "volume_meets_bounds",
        find: "across * cos_outer - along * volume.sin_outer <= box_radius",
        replace: "across * cos_outer - along * volume.sin_outer <= 0.0",
        tests: &[SPOT_CULLING],
        fast: false,
    },
    ShaderMutant {
        name: "the traversal never visits a node's second child",
        file: "visibility/bvh.wgsl",
        function: "trace",
        find: "stack[depth] = first + 1u;",
        replace: "stack[depth] = first;",
        tests: &[SHADOW_REFERENCE, SHADOW_WALL],
        fast: true,
    },
    ShaderMutant {
        name: "the box test measures the slabs from the wrong side",
        file: "visibility/bvh.wgsl",
        function: "box_hit",
        find: "let t0 = (lo - origin) * inverse;",
        replace: "let t0 = (origin - lo) * inverse;",
        tests: &[SHADOW_REFERENCE, SHADOW_WALL],
        fast: true,
    },
    ShaderMutant {
        name: "shadow rays start on the surface (no offset)",
        file: "visibility/bvh.wgsl",
        function: "light_visible",
        find: "let origin = point + normal * start_offset;",
        replace: "let origin = point;",
        tests: &[SHADOW_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        // Issue 46: a lit floor went black in blocks where the depth-rebuilt position lay
        // a few depth ulps below it.
        name: "shadow rays from rebuilt positions ignore the reconstruction's error",
        file: "visibility/bvh.wgsl",
        function: "light_visible",
        find: "let start_offset = offset + position_error;",
        replace: "let start_offset = offset;",
        tests: &[REBUILT_SHADOWS],
        fast: true,
    },
    ShaderMutant {
        name: "the rebuilt position's error bound leaves out the depth's ulps",
        file: "visibility/rebuilt.wgsl",
        function: "rebuilt_position_error",
        find: "return (REBUILT_DEPTH_ULPS * ulp * view_depth_per_depth + RASTER_PLANE_PIXELS * footprint) * along_ray;",
        replace: "return RASTER_PLANE_PIXELS * footprint * along_ray;",
        tests: &[REBUILT_SHADOWS],
        fast: true,
    },
    ShaderMutant {
        name: "the tile keeps lights by the box's centre, not its nearest point",
        file: "cluster/cluster_lights.wgsl",
        function: "light_reaches_box",
        find: "let offset = clamp(center, low, high) - center;",
        replace: "let offset = (low + high) * 0.5 - center;",
        tests: &[TILES],
        fast: true,
    },
    ShaderMutant {
        name: "kept lights of the tile's second half overwrite the first half's",
        file: "cluster/tile_lights.wgsl",
        function: "shade_tile_lights",
        find: "let slot = select(0u, countOneBits(bits.x), word == 1u) + countOneBits(bits[word] & before);",
        replace: "let slot = countOneBits(bits[word] & before);",
        tests: &[TILES],
        fast: true,
    },
    ShaderMutant {
        name: "a tile shades only its first cluster's pixels",
        file: "cluster/tile_lights.wgsl",
        function: "shade_tile_lights",
        find: "        if mine {\n            pending = false;\n        }",
        replace: "        pending = false;",
        tests: &[TILES],
        fast: true,
    },
    ShaderMutant {
        name: "the tile loop drops the second light of each pair",
        file: "cluster/tile_lights.wgsl",
        function: "shade_tile_lights",
        find: "radiance += second;",
        replace: "_ = second;",
        tests: &[TILES],
        fast: true,
    },
    ShaderMutant {
        name: "diffuse programs forget the albedo",
        file: "lights/brdf.wgsl",
        function: "loop_sum_radiance",
        find: "return min(sum, vec3<f32>(SUM_CEILING)) * surface.albedo;",
        replace: "return min(sum, vec3<f32>(SUM_CEILING));",
        tests: &[DIFFUSE_ONLY],
        fast: true,
    },
    ShaderMutant {
        name: "GGX forgets alpha squared in its denominator",
        file: "lights/brdf.wgsl",
        function: "pbr_specular",
        find: "let d = (dot(across, across) + n_dot_half_sum * n_dot_half_sum * alpha2) * (inverse_half_length * inverse_half_length);",
        replace: "let d = (dot(across, across) + n_dot_half_sum * n_dot_half_sum * sqrt(alpha2)) * (inverse_half_length * inverse_half_length);",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "the visibility term is not height-correlated",
        file: "lights/brdf.wgsl",
        function: "pbr_specular",
        find: "let lambda_l = surface.n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - alpha2) + alpha2);",
        replace: "let lambda_l = surface.n_dot_v * n_dot_l;",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "Fresnel is F0 at every angle",
        file: "lights/brdf.wgsl",
        function: "pbr_specular",
        find: "let v_dot_h = saturate(0.5 * half_length_squared * inverse_half_length);",
        replace: "let v_dot_h = 1.0;",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "the diffuse keeps what the specular lobe takes towards the eye",
        file: "lights/brdf.wgsl",
        function: "pbr_diffuse_weight",
        find: "let out = vec3<f32>(1.0) - specular_albedo(surface.specular, n_dot_v, fit);",
        replace: "let out = vec3<f32>(1.0);",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "the loop's albedo fit takes p for p^2",
        file: "lights/brdf.wgsl",
        function: "pbr_diffuse",
        find: "let p2 = p * p;",
        replace: "let p2 = p;",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "the specular fits are read one roughness row too far",
        file: "lights/specular_albedo.wgsl",
        function: "roughness_cell",
        find: "let row = min(u32(y), ROUGHNESS_CELLS - 1u);",
        replace: "let row = min(u32(y) + 1u, ROUGHNESS_CELLS - 1u);",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "the G-buffers keep roughness in 4 bits",
        file: "deferred/codecs.wgsl",
        function: "encode_lobe",
        find: "    return saturate(lobe);",
        replace: "    return round(saturate(lobe) * 15.0) / 15.0;",
        tests: &[PBR_LAYOUTS],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow rays' reservoirs keep terms by count, not weight",
        file: "visibility/shadow_rays.wgsl",
        function: "offer_shadow_ray",
        find: "let left = weight_to_skip[ray] - weight;",
        replace: "let left = weight_to_skip[ray] - 1.0;",
        tests: &[SHADOW_RAYS_UNBIASED],
        fast: true,
    },
    ShaderMutant {
        name: "a shadow ray's estimate forgets the weight dealt to it",
        file: "visibility/shadow_rays.wgsl",
        function: "shadow_ratio",
        find: "let estimate = term * (weight / luminance(term));",
        replace: "let estimate = term;",
        tests: &[SHADOW_RAYS_UNBIASED],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter's walk steps over a wall instead of stopping there",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "            if !covered(tap_normal) || dot(tap_normal.xyz, normal.xyz) < NORMAL_COS {\n                break;",
        replace: "            if !covered(tap_normal) || dot(tap_normal.xyz, normal.xyz) < NORMAL_COS {\n                continue;",
        tests: &[SHADOW_FILTER_WALL],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter's taps are not compared by normal",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "if !covered(tap_normal) || dot(tap_normal.xyz, normal.xyz) < NORMAL_COS {",
        replace: "if !covered(tap_normal) {",
        tests: &[SHADOW_FILTER_CREASE],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter's taps are not compared by plane",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "if abs(along - plane) > PLANE_TOLERANCE * abs(plane) {",
        replace: "if false {",
        tests: &[SHADOW_FILTER_STEP],
        fast: false,
    },
    ShaderMutant {
        name: "the shadow history is read where the pixel is now, not where its surface was",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "let before = previous_pixel(position);",
        replace: "let before = pixel;",
        tests: &[SHADOW_HISTORY_MOTION],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow history is kept for another surface after a disocclusion",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "let surface_kept = same_surface(seen.x, expected, 0.0);",
        replace: "let surface_kept = true;",
        tests: &[SHADOW_HISTORY_UNCOVERED],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow history is not clamped to the new frame's share",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "kept = clamp(previous.rgb, filtered - HISTORY_MARGIN, filtered + HISTORY_MARGIN);",
        replace: "kept = previous.rgb;",
        tests: &[SHADOW_HISTORY_CLAMP],
        fast: true,
    },
    // Issue 80: what makes shadowed frames blotchy, caught by the blotch measure.
    ShaderMutant {
        name: "the shadow history is reset every frame",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "frames = min(frames + 1.0, HISTORY_FRAMES);",
        replace: "frames = 1.0;",
        tests: &[BLOTCHES],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter takes no taps: each pixel's ray is white noise again",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "const RADIUS: i32 = 6;",
        replace: "const RADIUS: i32 = 0;",
        tests: &[BLOTCHES, SHADOW_FILTER_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow history is kept when the pixel's unshadowed light changes",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "let same_light = abs(seen.y - brightness) <= LIGHT_CHANGE * max(seen.y, brightness);",
        replace: "let same_light = true;",
        tests: &[SHADOW_HISTORY_SWITCH_OFF],
        fast: true,
    },
    ShaderMutant {
        name: "the forward pipelines' shadow pass starts its rays at the rebuilt position, unmoved",
        file: "visibility/shadow_trace.wgsl",
        function: "cs_trace",
        find: "visible = select(0.0, 1.0, light_visible(point, normalize(normal), error, ray.xyz + view.origin.xyz));",
        replace: "visible = select(0.0, 1.0, light_visible(point, normalize(normal), 0.0, ray.xyz + view.origin.xyz));",
        tests: &[FORWARD_SHADOW_PASS],
        fast: true,
    },
    ShaderMutant {
        name: "blended surfaces are drawn with alpha 1",
        file: "cluster/blended.wgsl",
        function: "shade_blended",
        find: "return BlendedFragment(vec4<f32>(shaded.rgb, surface.alpha), depth);",
        replace: "return BlendedFragment(vec4<f32>(shaded.rgb, 1.0), depth);",
        tests: &[BLENDED_OVER],
        fast: true,
    },
    ShaderMutant {
        name: "the tiles path composites a pixel's blended layers front to back",
        file: "deferred/blended_layers_shade.wgsl",
        function: "cs_shade_layers",
        find: "let index = layers.sorted[layers.kept - 1u - step];",
        replace: "let index = layers.sorted[step];",
        tests: &[BLENDED_LAYERS],
        fast: true,
    },
    ShaderMutant {
        name: "the compute path composites a pixel's blended layers front to back",
        file: "deferred/blended_layers_shade.wgsl",
        function: "cs_shade_layers",
        find: "colour = over(shade_layer(layers.sorted[k - 1u], pixel), colour);",
        replace: "colour = over(shade_layer(layers.sorted[layers.kept - k], pixel), colour);",
        tests: &[BLENDED_LAYERS],
        fast: true,
    },
    ShaderMutant {
        name: "a pixel's blended layers are kept in the order they were stored, not sorted",
        file: "deferred/blended_layers_shade.wgsl",
        function: "gather_layers",
        find: "while at > 0u && nearer(key, keys[at - 1u]) {",
        replace: "while at > 0u && false {",
        tests: &[BLENDED_LAYERS],
        fast: true,
    },
    ShaderMutant {
        name: "the layers past the budget are dropped, not merged",
        file: "deferred/blended_layers_shade.wgsl",
        function: "gather_layers",
        find: "if merged_weight > 0.0 {",
        replace: "if false {",
        tests: &[BLENDED_LAYERS],
        fast: true,
    },
    ShaderMutant {
        name: "weighted transparency weighs layers by their alpha alone, not their depth",
        file: "gpu/weighted_blended.wgsl",
        function: "weighted_blended_weight",
        find: "return alpha * clamp(falloff, 1e-2, 3e3) / 300.0;",
        replace: "return alpha * 0.1;",
        tests: &[BLENDED_OVER],
        fast: true,
    },
    ShaderMutant {
        name: "under MSAA the visible bounds read one sample of each pixel",
        file: "cluster/visible_bounds.wgsl",
        function: "depth_range",
        find: "for (var s = 0; s < i32(textureNumSamples(depth_buffer)); s++) {",
        replace: "for (var s = 0; s < 1; s++) {",
        tests: &[MSAA_FORWARD_PLUS],
        fast: true,
    },
    ShaderMutant {
        name: "under MSAA a pixel's depth range is not widened by its surfaces' slopes",
        file: "cluster/visible_bounds.wgsl",
        function: "depth_range",
        find: "let widen = slope.x + slope.y;",
        replace: "let widen = 0.0;",
        tests: &[MSAA_FORWARD_PLUS],
        fast: true,
    },
    ShaderMutant {
        name: "the cluster boxes are not grown over the blended objects",
        file: "cluster/visible_bounds.wgsl",
        function: "finish_visible_bounds",
        find: "bounds = with_blended_objects(bounds, grid_bounds[cluster]);",
        replace: "bounds = with_blended_objects(bounds, ClusterBounds(vec4<f32>(0.0), vec4<f32>(0.0)));",
        tests: &[BLENDED_BEFORE_DEPTH],
        fast: true,
    },
    ShaderMutant {
        name: "a ray that keeps a far-field aggregate aims at its power centroid",
        file: "cluster/cluster_lights.wgsl",
        function: "aim_at_aggregated_lights",
        find: "aim_ray(ray, relative_to_origin(light_drawn_from(node, point)));",
        replace: "aim_ray(ray, relative_to_origin(far_nodes[node].centroid));",
        tests: &[SHADOW_AGGREGATE_LIGHTS],
        fast: true,
    },
    ShaderMutant {
        name: "metals keep their diffuse albedo",
        file: "common/material.wgsl",
        function: "fragment_surface",
        find: "surface.albedo = base.rgb * (1.0 - metallic);",
        replace: "surface.albedo = base.rgb;",
        tests: &[PBR_REFERENCE],
        fast: true,
    },
    ShaderMutant {
        name: "the visibility raster ignores alpha masks",
        file: "deferred/visibility.wgsl",
        function: "fs_visibility",
        find: "    apply_alpha_mask(sample_base_color(in.uv).a);",
        replace: "    _ = sample_base_color(in.uv);",
        tests: &[VISIBILITY],
        fast: true,
    },
    ShaderMutant {
        name: "the resolve interpolates with the corners' weights rotated",
        file: "deferred/visibility_resolve.wgsl",
        function: "perspective_barycentrics",
        find: "        dot(cross(clip[1], clip[2]), ray),\n        dot(cross(clip[2], clip[0]), ray),",
        replace: "        dot(cross(clip[2], clip[0]), ray),\n        dot(cross(clip[1], clip[2]), ray),",
        tests: &[VISIBILITY],
        fast: true,
    },
    ShaderMutant {
        name: "the resolve takes every triangle for front-facing",
        file: "deferred/visibility_resolve.wgsl",
        function: "rebuild_fragment",
        find: "dot(clip[0], cross(clip[1], clip[2])) > 0.0",
        replace: "true",
        tests: &[VISIBILITY],
        fast: true,
    },
    ShaderMutant {
        name: "the resolve samples every texture at its finest mip",
        file: "deferred/visibility_resolve.wgsl",
        function: "rebuild_fragment",
        find: "uv_gradients = vec4<f32>(interpolate2(b_across, uvs) - uv_corner, interpolate2(b_down, uvs) - uv_corner);",
        replace: "uv_gradients = vec4<f32>(0.0);",
        tests: &[VISIBILITY],
        fast: true,
    },
    ShaderMutant {
        name: "TAA reads its history where last frame's jittered sample was (the jitter not undone)",
        file: "gpu/taa.wgsl",
        function: "cs_resolve",
        find: "previous_clip.xy / previous_clip.w - view.jitter.zw + view.jitter.xy;",
        replace: "previous_clip.xy / previous_clip.w;",
        tests: &[TAA_EDGES],
        fast: true,
    },
    ShaderMutant {
        name: "TAA keeps its history unclipped",
        file: "gpu/taa.wgsl",
        function: "cs_resolve",
        find: "let clipped = clip_to_box(perceptual(history_at(uv), exposed), mean, CLIP_SIGMAS * spread);",
        replace: "let clipped = perceptual(history_at(uv), exposed);",
        tests: &[TAA_CLIPPING],
        fast: true,
    },
    ShaderMutant {
        name: "bloom is added to the displayed (clamped) frame, as after tonemapping",
        file: "gpu/bloom.wgsl",
        function: "cs_composite",
        find: "let frame = textureLoad(detail, id.xy, 0);",
        replace: "let frame = min(textureLoad(detail, id.xy, 0), vec4<f32>(1.0));",
        tests: &[BLOOM_LIGHT],
        fast: true,
    },
    // Issue 84: the post stack's and the shadow filter's defining parameters, each held by
    // its f64 twin, and the blended layers' budget.
    ShaderMutant {
        name: "the shadow filter takes 3 taps each side, not 6",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "const RADIUS: i32 = 6;",
        replace: "const RADIUS: i32 = 3;",
        tests: &[SHADOW_FILTER_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter's Gaussian is 4.5 pixels wide, not 3",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "const SIGMA: f32 = 3.0;",
        replace: "const SIGMA: f32 = 4.5;",
        tests: &[SHADOW_FILTER_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter's normal rule allows 37 degrees, not 25",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "const NORMAL_COS: f32 = 0.9;",
        replace: "const NORMAL_COS: f32 = 0.8;",
        tests: &[SHADOW_FILTER_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow filter's plane rule allows 2%, not 1%",
        file: "visibility/shadow_filter.wgsl",
        function: "filtered_share",
        find: "const PLANE_TOLERANCE: f32 = 0.01;",
        replace: "const PLANE_TOLERANCE: f32 = 0.02;",
        tests: &[SHADOW_FILTER_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow history averages 8 frames, not 16",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "const HISTORY_FRAMES: f32 = 16.0;",
        replace: "const HISTORY_FRAMES: f32 = 8.0;",
        tests: &[SHADOW_HISTORY_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow history survives a 10% change of light, not 5%",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "const LIGHT_CHANGE: f32 = 0.05;",
        replace: "const LIGHT_CHANGE: f32 = 0.10;",
        tests: &[SHADOW_HISTORY_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the shadow history is held within 0.5 of the share, not 0.15",
        file: "visibility/shadow_filter.wgsl",
        function: "cs_columns_temporal",
        find: "const HISTORY_MARGIN: f32 = 0.15;",
        replace: "const HISTORY_MARGIN: f32 = 0.5;",
        tests: &[SHADOW_HISTORY_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "the blended layers sort three a pixel, not the budget's four",
        file: "deferred/blended_layers.wgsl",
        function: "(the layers' budget)",
        find: "const SORTED_LAYERS: u32 = #SORTED_LAYERS;",
        replace: "const SORTED_LAYERS: u32 = 3u;",
        tests: &[BLENDED_LAYERS],
        fast: true,
    },
    ShaderMutant {
        name: "TAA's running mean averages 4 frames, not a jitter cycle's 16",
        file: "gpu/taa.wgsl",
        function: "cs_resolve",
        find: "const HISTORY_FRAMES: f32 = 16.0;",
        replace: "const HISTORY_FRAMES: f32 = 4.0;",
        tests: &[TAA_RUNNING_MEAN],
        fast: true,
    },
    ShaderMutant {
        name: "TAA's clip box is 4 standard deviations wide, not 1.25",
        file: "gpu/taa.wgsl",
        function: "cs_resolve",
        find: "const CLIP_SIGMAS: f32 = 1.25;",
        replace: "const CLIP_SIGMAS: f32 = 4.0;",
        tests: &[TAA_CLIP_BOX],
        fast: true,
    },
    ShaderMutant {
        name: "TAA's history reaches 4 pixels, not a pixel and a half",
        file: "gpu/taa.wgsl",
        function: "cs_resolve",
        find: "const HISTORY_REACH: f32 = 1.5;",
        replace: "const HISTORY_REACH: f32 = 4.0;",
        tests: &[TAA_SAME_SURFACE],
        fast: true,
    },
    ShaderMutant {
        name: "the history's same-surface rule allows 4% of the distance, not 1%",
        file: "common/history.wgsl",
        function: "same_surface",
        find: "const SAME_SURFACE: f32 = 0.01;",
        replace: "const SAME_SURFACE: f32 = 0.04;",
        tests: &[TAA_SAME_SURFACE],
        fast: true,
    },
    ShaderMutant {
        name: "TAA's history survives a normal turned by 60 degrees, not 37",
        file: "gpu/taa.wgsl",
        function: "history_of_surface",
        find: "const NORMAL_COS: f32 = 0.8;",
        replace: "const NORMAL_COS: f32 = 0.5;",
        tests: &[TAA_TURNING_SURFACE],
        fast: true,
    },
    ShaderMutant {
        name: "TAA reads its history bilinearly, not through Catmull-Rom",
        file: "gpu/taa.wgsl",
        function: "history_at",
        find: "let w0 = f * (-0.5 + f * (1.0 - 0.5 * f));\n    let w1 = 1.0 + f * f * (-2.5 + 1.5 * f);\n    let w2 = f * (0.5 + f * (2.0 - 1.5 * f));\n    let w3 = f * f * (-0.5 + 0.5 * f);",
        replace: "let w0 = vec2<f32>(0.0);\n    let w1 = 1.0 - f;\n    let w2 = f;\n    let w3 = vec2<f32>(0.0);",
        tests: &[TAA_MOVING_HISTORY],
        fast: true,
    },
    ShaderMutant {
        name: "bloom's first step without the firefly weighting (Karis's average)",
        file: "gpu/bloom.wgsl",
        function: "cs_downsample_first",
        find: "downsample(destination_uv(id), true)",
        replace: "downsample(destination_uv(id), false)",
        tests: &[BLOOM_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "bloom's down filter weighs its five boxes equally",
        file: "gpu/bloom.wgsl",
        function: "downsample",
        find: "var weight = select(0.125, 0.5, n == 0);",
        replace: "var weight = 0.2;",
        tests: &[BLOOM_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "bloom's up chain filters with a box, not a tent",
        file: "gpu/bloom.wgsl",
        function: "tent",
        find: "let weight = f32((2 - abs(dx)) * (2 - abs(dy)));",
        replace: "let weight = 16.0 / 9.0;",
        tests: &[BLOOM_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "bloom's up chain spreads half of each level, not the dial's",
        file: "gpu/bloom.wgsl",
        function: "cs_upsample",
        find: "let spread = own + params.spread * (tent(destination_uv(id)) - own);",
        replace: "let spread = own + 0.5 * (tent(destination_uv(id)) - own);",
        tests: &[BLOOM_TWIN],
        fast: true,
    },
    ShaderMutant {
        name: "bloom blends the frame toward its bloom by half the strength",
        file: "gpu/bloom.wgsl",
        function: "cs_composite",
        find: "let bloomed = frame.rgb + params.strength * (tent(destination_uv(id)) - frame.rgb);",
        replace: "let bloomed = frame.rgb + 0.5 * params.strength * (tent(destination_uv(id)) - frame.rgb);",
        tests: &[BLOOM_TWIN],
        fast: true,
    },
];

/// What happened to one mutant.
#[derive(Debug)]
pub enum Outcome {
    Killed(String),
    Survived,
}

pub fn copy_dir(from: &Path, to: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), &target)?;
        }
    }
    Ok(())
}

/// A copy of the merged shader tree `shaders` with the mutant applied.
fn mutated_copy(shaders: &Path, mutant: &ShaderMutant, into: &Path) -> anyhow::Result<()> {
    if into.exists() {
        std::fs::remove_dir_all(into)?;
    }
    copy_dir(shaders, into)?;
    let path = into.join(mutant.file);
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", mutant.file))?;
    let mutated = if mutant.find.is_empty() {
        String::new()
    } else {
        let found = text.matches(mutant.find).count();
        if found != 1 {
            bail!(
                "mutant '{}': its text occurs {found} times in shaders/{} (must be once); update the catalogue",
                mutant.name,
                mutant.file
            );
        }
        text.replace(mutant.find, mutant.replace)
    };
    std::fs::write(&path, mutated)?;
    Ok(())
}

/// The built test binaries, to run a mutant's tests without cargo (one cargo at a time
/// may hold the build folder; the mutants run side by side).
struct TestBinaries(Vec<crate::test_runner::TestBinary>);

impl TestBinaries {
    /// Runs one integration test binary (already built) with the shaders from `dir`:
    /// `Some(why)` when it failed or timed out.
    fn run(
        &self,
        (binary, filter): TestRef,
        dir: &Path,
        timeout: Duration,
    ) -> anyhow::Result<Option<String>> {
        let Some(test) = self.0.iter().find(|b| b.integration && b.name == binary) else {
            bail!("no integration test binary named {binary}");
        };
        let mut command = test.command();
        command
            .arg("-q")
            .env(manylights_gpu::SHADER_DIR_VARIABLE, dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null());
        if !filter.is_empty() {
            command.arg(filter);
        }
        let mut child = command.spawn().context("running a test binary")?;
        let started = Instant::now();
        loop {
            if let Some(status) = child.try_wait()? {
                return Ok((!status.success()).then(|| format!("{binary} {filter} failed")));
            }
            if started.elapsed() > timeout {
                let _ = child.kill();
                let _ = child.wait();
                return Ok(Some(format!("{binary} {filter} timed out")));
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    /// Applies `mutant` to a copy of `shaders` in `work` and runs its tests until one fails.
    fn run_mutant(
        &self,
        shaders: &Path,
        work: &Path,
        mutant: &ShaderMutant,
        timeout: Duration,
    ) -> anyhow::Result<Outcome> {
        mutated_copy(shaders, mutant, work)?;
        for &test in mutant.tests {
            if let Some(reason) = self.run(test, work, timeout)? {
                return Ok(Outcome::Killed(reason));
            }
        }
        Ok(Outcome::Survived)
    }
}

/// Runs the catalogue (or its fast subset); fails when a mutant survives.
pub fn mutants(fast_only: bool, report: Option<&Path>, only: Option<&str>) -> anyhow::Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let work = std::env::temp_dir().join(format!("manylights-mutants-{}", std::process::id()));
    let shaders = work.join("source");
    crate::merge_shader_folders(&shaders)?;
    // Build the test binaries once, with the real shaders, as `cargo xtask test` builds
    // them (`--workspace`: `-p manylights-tests` alone resolves other dependency features
    // and rebuilt every dependency into a second copy).
    let binaries = TestBinaries(crate::test_runner::build(&cargo, crate::TEST_PROFILE, &[])?);
    let timeout = Duration::from_secs(600);
    println!("sentinel (the tests must read the mutated folder) ...");
    match binaries.run_mutant(&shaders, &work.join("sentinel"), &SENTINEL, timeout)? {
        Outcome::Killed(_) => println!("  killed: mutated shaders are in use"),
        Outcome::Survived => bail!(
            "the sentinel survived: the tests do not read shaders from {} ({})",
            work.display(),
            manylights_gpu::SHADER_DIR_VARIABLE
        ),
    }
    let chosen: Vec<&ShaderMutant> = CATALOGUE
        .iter()
        .filter(|m| m.fast || !fast_only)
        .filter(|m| only.is_none_or(|text| m.name.contains(text)))
        .collect();
    // The control: every test the chosen mutants rely on passes on an unmutated copy, so a
    // kill means the mutant, not a test that fails anyway.
    let mut tests: Vec<TestRef> = chosen
        .iter()
        .flat_map(|m| m.tests.iter().copied())
        .collect();
    tests.sort_unstable();
    tests.dedup();
    let unmutated = work.join("unmutated");
    copy_dir(&shaders, &unmutated)?;
    let workers = crate::test_runner::workers();
    let control = crate::test_runner::in_parallel(tests.clone(), workers, |_, test| {
        binaries.run(test, &unmutated, timeout)
    });
    for result in control {
        if let Some(reason) = result? {
            bail!("control: {reason} on the unmutated shaders; fix it before mutating");
        }
    }
    println!("control: {} tests pass on the unmutated copy", tests.len());
    // The mutants side by side, each worker in a folder of its own.
    let count = chosen.len();
    let outcomes = crate::test_runner::in_parallel(
        chosen.iter().copied().enumerate().collect(),
        workers,
        |worker, (i, mutant)| {
            let started = Instant::now();
            let folder = work.join(format!("worker-{worker}"));
            let outcome = binaries.run_mutant(&shaders, &folder, mutant, timeout);
            let verdict = match &outcome {
                Ok(Outcome::Killed(by)) => format!("killed ({by})"),
                Ok(Outcome::Survived) => "SURVIVED".to_string(),
                Err(error) => format!("ERROR ({error:#})"),
            };
            println!(
                "[{}/{count}] {} ({}, {}): {verdict}, {:.0} s",
                i + 1,
                mutant.name,
                mutant.file,
                mutant.function,
                started.elapsed().as_secs_f64()
            );
            (mutant, outcome.map(|_| verdict))
        },
    );
    let mut rows = Vec::new();
    let mut survivors = Vec::new();
    for (mutant, verdict) in outcomes {
        let verdict = verdict?;
        if verdict == "SURVIVED" {
            survivors.push(mutant.name);
        }
        rows.push(format!(
            "| {} | `{}` | `{}` | {verdict} |",
            mutant.name, mutant.file, mutant.function
        ));
    }
    let _ = std::fs::remove_dir_all(&work);
    let killed = chosen.len() - survivors.len();
    let summary = format!(
        "{killed} of {} shader mutants killed ({:.0}%)",
        chosen.len(),
        100.0 * killed as f64 / chosen.len().max(1) as f64
    );
    println!("{summary}");
    if let Some(path) = report {
        let table = format!(
            "{summary}\n\n| mutant | file | function | result |\n|---|---|---|---|\n{}\n",
            rows.join("\n")
        );
        std::fs::write(path, table).with_context(|| format!("writing {}", path.display()))?;
    }
    if !survivors.is_empty() {
        bail!("surviving mutants: {}", survivors.join("; "));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every mutant's text occurs exactly once in today's shaders, so a shader edit that
    /// moves it away fails here rather than at mutation time.
    #[test]
    fn every_mutant_applies_to_the_current_shaders() {
        let shaders = tempfile::tempdir().expect("temporary folder");
        crate::merge_shader_folders(shaders.path()).expect("the crates' shaders");
        for mutant in CATALOGUE {
            let text =
                std::fs::read_to_string(shaders.path().join(mutant.file)).expect("shader file");
            assert_eq!(
                text.matches(mutant.find).count(),
                1,
                "{}: '{}' in {}",
                mutant.name,
                mutant.find,
                mutant.file
            );
            assert_ne!(mutant.find, mutant.replace, "{}", mutant.name);
            assert!(!mutant.tests.is_empty(), "{}", mutant.name);
        }
    }
}
