// The box of every cluster's visible samples (Olsson, Billeter and Assarsson 2012's
// "explicit bounds"): after the pipeline has laid down the frame's depth (the G-buffer, the
// depth pre-pass), each cluster's box becomes the view-space bounding box of the samples
// that fall in it, and a cluster no sample falls in gets an empty box, so assignment lists
// nothing there. Lights are then tested against what they can actually reach: fewer list
// entries, a shorter walk and less shading work, and the images are unchanged (a light left
// out reaches no sample of the cluster).
//
// Exactness against rounding: the shading passes find a sample's cluster and position from
// their own arithmetic (interpolated positions in Forward+, a stored position in the `full`
// G-buffer), which can differ from this reconstruction in the last bits. So each sample
// counts as the segment between the positions 4 depth-buffer steps (ulps) nearer and farther,
// widened by PAD_RELATIVE of its depth in every axis, and goes into every slice that segment
// touches. Any position the shading computes for the pixel lies in its cluster's box.
//
// Two dispatches:
//   1. bound_visible_samples: one workgroup per band of a tile's rows (the grid's
//      `culling_and_bands.y` bands: up to 8, fewer where a tile has too few pixels to fill
//      them) and group of up to SLICES_PER_GROUP slices (one workgroup per tile left too
//      few threads to hide the depth loads: 0.08 ms at 1080p on the H200). Its threads merge runs of
//      samples in one slice range locally, combine them with workgroup atomics, and the
//      bands combine with global atomics on order-preserving integer codes (cleared to 0,
//      "nothing", before the pass);
//   2. finish_visible_bounds: one workgroup per tile and slice group turns the codes into
//      boxes (empty where nothing fell) and the tile's first and last occupied slice.

#import manylights::common::view::view
#import manylights::cluster::cluster_index::{ClusterParams, cluster_slice}
#import manylights::cluster::bounds::{ClusterBounds, bounds_are_empty, ordered_code, from_ordered_code}

@group(1) @binding(0) var<uniform> grid: ClusterParams;
@group(1) @binding(1) var<storage, read_write> visible_bounds: array<ClusterBounds>;
#ifdef MULTISAMPLED
@group(1) @binding(2) var depth_buffer: texture_depth_multisampled_2d;
// MSAA: a sample lies anywhere in its pixel, and the shading pass shades each surface in a
// pixel once, at the pixel's centre (on its triangle's plane, extended where the triangle
// does not reach it), so each pixel counts as its whole footprint (half a pixel either
// way) over the range of its samples' depths, widened by their surfaces' slopes.
const FOOTPRINT: f32 = 0.5;
#else
@group(1) @binding(2) var depth_buffer: texture_depth_2d;
const FOOTPRINT: f32 = 0.0;
#endif
// For each tile and group of SLICES_PER_GROUP slices, the first and last slice a sample
// falls in (first | last << 16; first > last when none): assignment tests no slice outside.
@group(1) @binding(3) var<storage, read_write> tile_slices: array<u32>;
// Per cluster, six codes: the box's minimum x, y, z as inverted codes (so that 0, the
// cleared value, means nothing and atomicMax finds the minimum), then its maximum x, y, z.
@group(1) @binding(4) var<storage, read_write> box_codes: array<atomic<u32>>;
// The grid's boxes, and the view-space boxes of the scene's blended objects (empty entries,
// min.w 0, are unused room): a blended surface lies in front of the depth this pass
// reads, so each cluster's box also takes the part of its grid box inside any of them.
@group(1) @binding(5) var<storage, read> grid_bounds: array<ClusterBounds>;
@group(1) @binding(6) var<storage, read> blended_boxes: array<ClusterBounds>;

const THREADS: u32 = 256u;
const LOADS_PER_STEP: u32 = 4u;
// From `SLICES_PER_GROUP` in `cluster/src/visible_bounds.rs`.
const SLICES_PER_GROUP: u32 = #TILE_SLICE_GROUP;
// Depth-buffer steps each sample is widened by, nearer and farther.
const DEPTH_ULPS: u32 = 4u;
// Relative widening in every axis (about 80 f32 ulps).
const PAD_RELATIVE: f32 = 1e-5;

// Per slice of the group: the band's box as order-preserving codes of its floats.
var<workgroup> box_min: array<array<atomic<u32>, 3>, SLICES_PER_GROUP>;
var<workgroup> box_max: array<array<atomic<u32>, 3>, SLICES_PER_GROUP>;
// The group's first and last slice holding a sample (finish pass).
var<workgroup> first_occupied: atomic<u32>;
var<workgroup> last_occupied: atomic<u32>;

// The view-space position of the screen point `at` (pixels) at `depth` (0..1).
fn view_position(at: vec2<f32>, depth: f32) -> vec3<f32> {
    let uv = at * view.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let h = view.inverse_proj * ndc;
    return h.xyz / h.w;
}

// The smallest and largest depth of the pixel's samples that hold a surface (x > y when
// none does).
fn depth_range(pixel: vec2<u32>, clear: f32) -> vec2<f32> {
    let none = vec2<f32>(2.0, -1.0);
#ifdef MULTISAMPLED
    let at = vec2<i32>(pixel);
    var range = none;
    for (var s = 0; s < i32(textureNumSamples(depth_buffer)); s++) {
        let depth = textureLoad(depth_buffer, at, s);
        if depth != clear {
            range = vec2<f32>(min(range.x, depth), max(range.y, depth));
        }
    }
    if range.x > range.y {
        return range;
    }
    // A fragment that covers part of the pixel is shaded at the pixel's centre, which its
    // triangle may not reach or where a nearer surface hides it: its depth there is its
    // depth at a sample it wins plus its slope over at most a pixel in each axis. Each sample's slope in an axis is
    // its step in depth to the nearest sample of the pixel on either side (its surface
    // going on there), the steepest sample's taken; an axis with no neighbour's surface
    // takes the pixel's own spread. The range widens by both, short of the clear depth.
    var slope = vec2<f32>(0.0);
    for (var axis = 0; axis < 2; axis++) {
        var offset = vec2<i32>(0);
        offset[axis] = 1;
        var step = min(depth_step(at, at - offset, clear), depth_step(at, at + offset, clear));
        if step == NO_STEP {
            step = range.y - range.x;
        }
        slope[axis] = step;
    }
    let widen = slope.x + slope.y;
    return vec2<f32>(
        max(range.x - widen, min(range.x, WIDEST_DEPTH.x)),
        min(range.y + widen, max(range.y, WIDEST_DEPTH.y)),
    );
#else
    let depth = textureLoad(depth_buffer, vec2<i32>(pixel), 0);
    return select(vec2<f32>(depth), none, depth == clear);
#endif
}

#ifdef MULTISAMPLED
// No surface to step to.
const NO_STEP: f32 = 3.0;
// How far a widened range may reach: short of the clear depth (0 or 1), where a reversed
// or infinite projection puts infinity.
const WIDEST_DEPTH: vec2<f32> = vec2<f32>(1e-7, 1.0 - 1.2e-7);

// How far in depth each sample of `pixel` is from the nearest sample of `neighbour` (its
// surface going on there), at most over the pixel's samples: NO_STEP off screen, or for
// a sample with no surface beside it.
fn depth_step(pixel: vec2<i32>, neighbour: vec2<i32>, clear: f32) -> f32 {
    let size = vec2<i32>(textureDimensions(depth_buffer));
    if any(neighbour < vec2<i32>(0)) || any(neighbour >= size) {
        return NO_STEP;
    }
    let samples = i32(textureNumSamples(depth_buffer));
    var step = 0.0;
    for (var s = 0; s < samples; s++) {
        let own = textureLoad(depth_buffer, pixel, s);
        if own == clear {
            continue;
        }
        var nearest = NO_STEP;
        for (var t = 0; t < samples; t++) {
            let other = textureLoad(depth_buffer, neighbour, t);
            if other != clear {
                nearest = min(nearest, abs(own - other));
            }
        }
        step = max(step, nearest);
    }
    return step;
}
#endif

// A run of samples merged by one thread before it touches the shared boxes.
struct Run {
    slices: vec2<u32>,
    lo: vec3<f32>,
    hi: vec3<f32>,
    open: bool,
}

fn flush(run: Run, group_first: u32) {
    if !run.open {
        return;
    }
    let first = max(run.slices.x, group_first);
    let last = min(run.slices.y, group_first + SLICES_PER_GROUP - 1u);
    for (var slice = first; slice <= last; slice++) {
        let s = slice - group_first;
        for (var axis = 0u; axis < 3u; axis++) {
            atomicMin(&box_min[s][axis], ordered_code(run.lo[axis]));
            atomicMax(&box_max[s][axis], ordered_code(run.hi[axis]));
        }
    }
}

@compute @workgroup_size(256)
fn bound_visible_samples(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    let bands = grid.culling_and_bands.y;
    let tile = vec2<u32>(group.x, group.y / bands);
    let band = group.y % bands;
    let group_first = group.z * SLICES_PER_GROUP;
    if thread < SLICES_PER_GROUP {
        for (var axis = 0u; axis < 3u; axis++) {
            atomicStore(&box_min[thread][axis], 0xffffffffu);
            atomicStore(&box_max[thread][axis], 0u);
        }
    }
    workgroupBarrier();

    // The tile's pixels: those whose centre maps to this tile (the last tile takes the
    // screen's remainder), found in a rectangle one pixel wider than the tile; this band
    // takes every `bands`-th part of its rows.
    let tile_size = grid.tile_and_screen.xy;
    let screen = vec2<u32>(grid.tile_and_screen.zw);
    let last_tile = grid.dims.xy - vec2<u32>(1u);
    let rect_min = vec2<u32>(max(floor(vec2<f32>(tile) * tile_size) - 1.0, vec2<f32>(0.0)));
    var rect_max = vec2<u32>(ceil(vec2<f32>(tile + vec2<u32>(1u)) * tile_size) + 1.0);
    rect_max = select(rect_max, screen, tile == last_tile);
    rect_max = min(rect_max, screen);
    let rows = rect_max.y - min(rect_min.y, rect_max.y);
    let band_rows = (rows + bands - 1u) / bands;
    let band_min = vec2<u32>(rect_min.x, rect_min.y + min(band * band_rows, rows));
    let band_end = rect_min.y + min((band + 1u) * band_rows, rows);
    let width = rect_max.x - min(rect_min.x, rect_max.x);
    let pixels = width * (band_end - band_min.y);
    let clear = view.near_far.z;

    var run: Run;
    run.open = false;
    // Four pixels a step, their depths loaded before any is used, so the loads overlap.
    for (var first = thread; first < pixels; first += THREADS * LOADS_PER_STEP) {
        var depths: array<vec2<f32>, LOADS_PER_STEP>;
        var at: array<vec2<u32>, LOADS_PER_STEP>;
        for (var k = 0u; k < LOADS_PER_STEP; k++) {
            let i = min(first + k * THREADS, pixels - 1u);
            at[k] = band_min + vec2<u32>(i % width, i / width);
            depths[k] = depth_range(at[k], clear);
        }
        for (var k = 0u; k < LOADS_PER_STEP; k++) {
            let pixel = at[k];
            let depth = depths[k];
            let centre = vec2<f32>(pixel) + 0.5;
            let in_tile = all(min(vec2<u32>(centre / tile_size), last_tile) == tile);
            if first + k * THREADS >= pixels || !in_tile || depth.x > depth.y {
                continue;
            }
            let low_bits = bitcast<u32>(depth.x);
            let nearer_depth = bitcast<f32>(select(0u, low_bits - DEPTH_ULPS, low_bits >= DEPTH_ULPS));
            let farther_depth = min(bitcast<f32>(bitcast<u32>(depth.y) + DEPTH_ULPS), 1.0);
            let a = view_position(centre - FOOTPRINT, nearer_depth);
            let b = view_position(centre + FOOTPRINT, farther_depth);
            var lo = min(a, b);
            var hi = max(a, b);
            if FOOTPRINT > 0.0 {
                // View x and y grow with the screen's and with depth: the footprint's other
                // two corners.
                let c = view_position(centre + FOOTPRINT, nearer_depth);
                let d = view_position(centre - FOOTPRINT, farther_depth);
                lo = min(lo, min(c, d));
                hi = max(hi, max(c, d));
            }
            let pad = PAD_RELATIVE * max(abs(lo.z), abs(hi.z));
            lo -= vec3<f32>(pad);
            hi += vec3<f32>(pad);
            let slices = vec2<u32>(cluster_slice(grid, -hi.z), cluster_slice(grid, -lo.z));
            if run.open && all(slices == run.slices) {
                run.lo = min(run.lo, lo);
                run.hi = max(run.hi, hi);
            } else {
                flush(run, group_first);
                run = Run(slices, lo, hi, true);
            }
        }
    }
    flush(run, group_first);
    workgroupBarrier();

    // The band's boxes into the clusters' codes.
    let slice = group_first + thread;
    if thread < SLICES_PER_GROUP && slice < grid.dims.z {
        let lo_x = atomicLoad(&box_min[thread][0]);
        if lo_x != 0xffffffffu {
            let cluster = (slice * grid.dims.y + tile.y) * grid.dims.x + tile.x;
            for (var axis = 0u; axis < 3u; axis++) {
                atomicMax(&box_codes[cluster * 6u + axis], ~atomicLoad(&box_min[thread][axis]));
                atomicMax(&box_codes[cluster * 6u + 3u + axis], atomicLoad(&box_max[thread][axis]));
            }
        }
    }
}

@compute @workgroup_size(SLICES_PER_GROUP)
fn finish_visible_bounds(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    if thread == 0u {
        atomicStore(&first_occupied, 0xffffu);
        atomicStore(&last_occupied, 0u);
    }
    workgroupBarrier();
    let slice = group.z * SLICES_PER_GROUP + thread;
    if slice < grid.dims.z {
        let cluster = (slice * grid.dims.y + group.y) * grid.dims.x + group.x;
        let base = cluster * 6u;
        var bounds = ClusterBounds(vec4<f32>(0.0), vec4<f32>(0.0));
        let max_x = atomicLoad(&box_codes[base + 3u]);
        if max_x != 0u {
            bounds.min = vec4<f32>(
                from_ordered_code(~atomicLoad(&box_codes[base])),
                from_ordered_code(~atomicLoad(&box_codes[base + 1u])),
                from_ordered_code(~atomicLoad(&box_codes[base + 2u])),
                1.0,
            );
            bounds.max = vec4<f32>(
                from_ordered_code(max_x),
                from_ordered_code(atomicLoad(&box_codes[base + 4u])),
                from_ordered_code(atomicLoad(&box_codes[base + 5u])),
                0.0,
            );
        }
        bounds = with_blended_objects(bounds, grid_bounds[cluster]);
        if !bounds_are_empty(bounds) {
            atomicMin(&first_occupied, slice);
            atomicMax(&last_occupied, slice);
        }
        visible_bounds[cluster] = bounds;
    }
    workgroupBarrier();
    if thread == 0u {
        let groups = (grid.dims.z + SLICES_PER_GROUP - 1u) / SLICES_PER_GROUP;
        let entry = (group.y * grid.dims.x + group.x) * groups + group.z;
        tile_slices[entry] = atomicLoad(&first_occupied) | (atomicLoad(&last_occupied) << 16u);
    }
}

// `bounds` grown by the part of the cluster's grid box `cell` inside each blended object's
// box.
fn with_blended_objects(bounds: ClusterBounds, cell: ClusterBounds) -> ClusterBounds {
    var grown = bounds;
    for (var i = 0u; i < arrayLength(&blended_boxes); i++) {
        let object = blended_boxes[i];
        let low = max(cell.min.xyz, object.min.xyz);
        let high = min(cell.max.xyz, object.max.xyz);
        if bounds_are_empty(object) || any(low > high) {
            continue;
        }
        if bounds_are_empty(grown) {
            grown = ClusterBounds(vec4<f32>(low, 1.0), vec4<f32>(high, 0.0));
        } else {
            grown = ClusterBounds(vec4<f32>(min(grown.min.xyz, low), 1.0), vec4<f32>(max(grown.max.xyz, high), 0.0));
        }
    }
    return grown;
}
