// Exact light assignment: for each cluster, the compact list of every light whose volume
// (a point light's sphere, a spot's cone: `bounds.wgsl`) meets the cluster's view-space box. No per-cluster cap, nothing dropped. Two designs
// share this module (`cluster::AssignmentDesign`, measured side by side in
// docs/results/nvidia-h200/assignment):
//
// Tile masks (the default), lists in ascending light order by construction:
//   1. mark_tiles: each light's candidate clusters (conservative, from its projected
//      bounds) are tested by 16 lanes, which count each cluster it meets, set its bit in
//      the mask of every tile where it meets a box and record the first and last slice it
//      meets;
//   2. prefix_sum: one workgroup turns counts into list offsets (offsets[N] = total);
//   3. fill_cluster_lists: one workgroup per tile and group of 8 slices walks the tile's
//      mask in light order, tests each marked light against its slices' boxes and writes
//      each hit at its rank among the hits before it (an ordered compaction), so every list
//      is sorted with no sort and no atomics on the lists.
//
// Atomic fill (the first design, kept for comparison):
//   1. count_lights: each light counts itself into every candidate cluster it intersects;
//   2. prefix_sum, as above, also resetting the counts to serve as fill cursors;
//   3. fill_lists: each light writes its index into its clusters' lists (atomic order);
//   4. sort_lists: lists up to SORT_LIMIT are sorted, one thread per cluster.
//
// If the total exceeds the index buffer, the fills write what fits; the shading loop tests
// every light against a cluster whose list ends past the buffer, and the CPU reads the total
// and grows the buffer for the next frame (`cluster::GpuClusters`).

#import manylights::common::view::{view, relative_to_origin}
#import manylights::lights::light_set::{Light, LIGHT_SPOT}
#import manylights::cluster::cluster_index::{ClusterParams, cluster_slice}
#import manylights::cluster::bounds::{ClusterBounds, bounds_are_empty, LightVolume, ViewLight, light_volume, volume_meets_bounds, SPOT_CULLING_CONE}
#import manylights::cluster::scan::{SCAN_THREADS, scan_values, inclusive_scan}

// Grid description for this frame.
@group(1) @binding(0) var<uniform> grid: ClusterParams;
// View-space box of every cluster: the grid's (`ClusterGrid::cluster_bounds`, uploaded when
// the grid changes) or this frame's visible samples' (`visible_bounds.wgsl`, empty where no
// sample falls).
@group(1) @binding(1) var<storage, read> cluster_bounds: array<ClusterBounds>;
// The lights, animated this frame.
@group(1) @binding(2) var<storage, read> lights: array<Light>;
// Each light in view space (its sphere and, for a spot, its cone; `ViewLight`), written by
// the first pass and read by the later passes, the statistics, the shading of a list cut
// short and the tests. (One binding for both halves: WebGPU allows 8 storage buffers a
// stage, and the mark and walk passes use all 8.)
@group(1) @binding(3) var<storage, read_write> view_lights: array<ViewLight>;
// Per-cluster counts, then fill cursors.
@group(1) @binding(4) var<storage, read_write> counts: array<atomic<u32>>;
// Per-cluster list offsets; offsets[cluster count] is the total.
@group(1) @binding(5) var<storage, read_write> offsets: array<u32>;
// The light lists, back to back.
@group(1) @binding(6) var<storage, read_write> light_indices: array<u32>;
// Tile masks: for each tile and group of walk groups (grid.mask_layout), one bit per light
// (scheme_lights_capacity.w words a mask), set for the lights that meet a box of those
// slices in that tile. Cleared before every frame.
@group(1) @binding(7) var<storage, read_write> tile_masks: array<atomic<u32>>;
// Each light's candidate slices: first in the low 16 bits, last in the high 16 bits.
@group(1) @binding(8) var<storage, read_write> light_slices: array<u32>;
// For each tile and group of 64 slices, the first and last slice whose box holds anything
// (packed as above): every slice with the grid's boxes, the occupied ones with the visible
// samples' (`visible_bounds.wgsl`).
@group(1) @binding(9) var<storage, read> tile_slices: array<u32>;

// For each tile mask, one bit per window of WALK_THREADS mask words (8,192 lights) that
// holds any marked light (grid.mask_layout.z words a mask): the walk skips empty windows
// without scanning them. Cleared before every frame.
@group(1) @binding(10) var<storage, read_write> window_marks: array<atomic<u32>>;
// Slices per entry of tile_slices (`SLICES_PER_GROUP` in visible_bounds.wgsl).
const TILE_SLICE_GROUP: u32 = #TILE_SLICE_GROUP;

// The first and last slice of `tile` whose box holds anything (x > y when none).
fn occupied_slices(tile: u32) -> vec2<u32> {
    let groups = (grid.dims.z + TILE_SLICE_GROUP - 1u) / TILE_SLICE_GROUP;
    var first = 0xffffu;
    var last = 0u;
    for (var group = 0u; group < groups; group++) {
        let entry = tile_slices[tile * groups + group];
        if (entry & 0xffffu) <= (entry >> 16u) {
            first = min(first, entry & 0xffffu);
            last = max(last, entry >> 16u);
        }
    }
    return vec2<u32>(first, last);
}

// Lists up to this long are sorted (insertion sort, one thread per cluster):
// `cluster::SORTED_LIST_LIMIT`, which the tests hold the lists' order to.
const SORT_LIMIT: u32 = #SORTED_LIST_LIMIT;

struct CandidateRange {
    lo: vec3<u32>,
    hi: vec3<u32>,
    empty: bool,
}

// A conservative range of clusters a view-space sphere may touch (mirrors
// `cluster::candidate_range`); the exact sphere/box test decides.
fn candidate_range(center: vec3<f32>, radius: f32) -> CandidateRange {
    var range: CandidateRange;
    let depth_min = -center.z - radius;
    let depth_max = -center.z + radius;
    range.empty = depth_max <= 0.0;
    let last = grid.dims.xyz - vec3<u32>(1u);
    let slice_lo = cluster_slice(grid, max(depth_min, 0.0));
    let slice_hi = cluster_slice(grid, depth_max);
    range.lo = vec3<u32>(0u, 0u, select(slice_lo - 1u, 0u, slice_lo == 0u));
    range.hi = vec3<u32>(last.x, last.y, min(slice_hi + 1u, last.z));
    if depth_min > 0.0 {
        // Entirely in front of the eye: project the corners of the sphere's box.
        var pixel_min = vec2<f32>(1e30);
        var pixel_max = vec2<f32>(-1e30);
        for (var corner = 0u; corner < 8u; corner++) {
            let sign = vec3<f32>(f32(corner & 1u), f32((corner >> 1u) & 1u), f32((corner >> 2u) & 1u)) * 2.0 - 1.0;
            let clip = view.proj * vec4<f32>(center + sign * radius, 1.0);
            let ndc = clip.xy / clip.w;
            let pixel = vec2<f32>(ndc.x + 1.0, 1.0 - ndc.y) * 0.5 * grid.tile_and_screen.zw;
            pixel_min = min(pixel_min, pixel);
            pixel_max = max(pixel_max, pixel);
        }
        let tile_min = floor(pixel_min / grid.tile_and_screen.xy) - 1.0;
        let tile_max = floor(pixel_max / grid.tile_and_screen.xy) + 1.0;
        let limit = vec2<f32>(last.xy);
        range.lo = vec3<u32>(vec2<u32>(clamp(tile_min, vec2<f32>(0.0), limit)), range.lo.z);
        range.hi = vec3<u32>(vec2<u32>(clamp(tile_max, vec2<f32>(0.0), limit)), range.hi.z);
        range.empty = range.empty || any(tile_max < vec2<f32>(0.0)) || any(tile_min > limit);
    }
    return range;
}

fn view_light_of(index: u32) -> ViewLight {
    let light = lights[index];
    let center = (view.view * vec4<f32>(relative_to_origin(light.position), 1.0)).xyz;
    var cone = vec4<f32>(0.0, 0.0, 0.0, -1.0);
    if light.kind == LIGHT_SPOT && grid.culling_and_bands.x == SPOT_CULLING_CONE {
        cone = vec4<f32>(normalize((view.view * vec4<f32>(light.direction, 0.0)).xyz), sqrt(light.sin2_outer));
    }
    return ViewLight(vec4<f32>(center, light.radius), cone);
}

// Light `index` in view space, stored in view_lights for the later passes, the statistics
// and the tests.
fn store_view_light(index: u32) -> LightVolume {
    let light = view_light_of(index);
    view_lights[index] = light;
    return light_volume(light.sphere, light.cone);
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn count_lights(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if index >= grid.scheme_lights_capacity.y {
        return;
    }
    let volume = store_view_light(index);
    let range = candidate_range(volume.center, volume.radius);
    if range.empty {
        return;
    }
    for (var z = range.lo.z; z <= range.hi.z; z++) {
        for (var y = range.lo.y; y <= range.hi.y; y++) {
            for (var x = range.lo.x; x <= range.hi.x; x++) {
                let cluster = (z * grid.dims.y + y) * grid.dims.x + x;
                let bounds = cluster_bounds[cluster];
                if volume_meets_bounds(volume, bounds) {
                    atomicAdd(&counts[cluster], 1u);
                }
            }
        }
    }
}

// Workgroups of 256 threads scan 256 values: the prefix sum's per-thread sums, the tile
// walk's mask-word bit counts.
// Counts each thread of prefix_sum reads per chunk: chunks of 1,024 clusters, read with
// consecutive threads on consecutive words so that the loads of a chunk overlap.
const PREFIX_PER_THREAD: u32 = 4u;

@compute @workgroup_size(256)
fn prefix_sum(@builtin(local_invocation_index) thread: u32) {
    let n = grid.dims.w;
    var carry = 0u;
    for (var chunk = 0u; chunk < n; chunk += SCAN_THREADS * PREFIX_PER_THREAD) {
        let base = chunk + thread * PREFIX_PER_THREAD;
        var values: array<u32, PREFIX_PER_THREAD>;
        var sum = 0u;
        for (var k = 0u; k < PREFIX_PER_THREAD; k++) {
            if base + k < n {
                values[k] = atomicLoad(&counts[base + k]);
            }
            sum += values[k];
        }
        inclusive_scan(thread, sum);
        var running = carry + scan_values[thread] - sum;
        for (var k = 0u; k < PREFIX_PER_THREAD; k++) {
            if base + k < n {
                offsets[base + k] = running;
                running += values[k];
                // The counts become the fill cursors (atomic fill).
                atomicStore(&counts[base + k], 0u);
            }
        }
        // (A barrier: every thread has read its scan value before the next chunk's scan.)
        carry += workgroupUniformLoad(&scan_values[SCAN_THREADS - 1u]);
    }
    if thread == 0u {
        offsets[n] = carry;
    }
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn fill_lists(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if index >= grid.scheme_lights_capacity.y {
        return;
    }
    let volume = light_volume(view_lights[index].sphere, view_lights[index].cone);
    let range = candidate_range(volume.center, volume.radius);
    if range.empty {
        return;
    }
    let capacity = grid.scheme_lights_capacity.z;
    for (var z = range.lo.z; z <= range.hi.z; z++) {
        for (var y = range.lo.y; y <= range.hi.y; y++) {
            for (var x = range.lo.x; x <= range.hi.x; x++) {
                let cluster = (z * grid.dims.y + y) * grid.dims.x + x;
                let bounds = cluster_bounds[cluster];
                if volume_meets_bounds(volume, bounds) {
                    let at = offsets[cluster] + atomicAdd(&counts[cluster], 1u);
                    if at < capacity {
                        light_indices[at] = index;
                    }
                }
            }
        }
    }
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn sort_lists(@builtin(global_invocation_id) id: vec3<u32>) {
    let cluster = id.x;
    if cluster >= grid.dims.w {
        return;
    }
    let capacity = grid.scheme_lights_capacity.z;
    let start = offsets[cluster];
    let end = min(offsets[cluster + 1u], capacity);
    if end <= start || end - start > SORT_LIMIT {
        return;
    }
    for (var i = start + 1u; i < end; i++) {
        let value = light_indices[i];
        var j = i;
        while j > start && light_indices[j - 1u] > value {
            light_indices[j] = light_indices[j - 1u];
            j--;
        }
        light_indices[j] = value;
    }
}

// ---- Tile masks ----

// Lanes that share one light's candidate (tile, walk group) pairs in mark_tiles, and lights per workgroup
// of 64. A light near the eye has thousands of candidate clusters (its projection covers
// many tiles and the near slices are thin): one thread walking them all kept the whole
// dispatch waiting (0.6 ms at 5,000 lights on the H200); 16 lanes share them.
const MARK_LANES: u32 = 16u;
const MARK_LIGHTS_PER_GROUP: u32 = #MARK_LIGHTS_PER_GROUP;
// Each light's first and last slice met, combined over its lanes.
var<workgroup> mark_first_slice: array<atomic<u32>, MARK_LIGHTS_PER_GROUP>;
var<workgroup> mark_last_slice: array<atomic<u32>, MARK_LIGHTS_PER_GROUP>;

// Marks the light in the mask of every tile where its sphere meets at least one cluster
// box, and records the first and last slice it meets (the walks test nothing outside).
// MARK_LANES threads per light share its candidate (tile, run of slices) pairs. Dispatched
// in two dimensions when the light groups outnumber one dimension's 65,535 workgroups.
@compute @workgroup_size(MARK_LANES * MARK_LIGHTS_PER_GROUP)
fn mark_tiles(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    let slot = thread / MARK_LANES;
    let lane = thread % MARK_LANES;
    let index = (group.y * groups.x + group.x) * MARK_LIGHTS_PER_GROUP + slot;
    if lane == 0u {
        // An empty slice range (first > last) unless a box is met below.
        atomicStore(&mark_first_slice[slot], 0xffffu);
        atomicStore(&mark_last_slice[slot], 0u);
    }
    workgroupBarrier();
    if index < grid.scheme_lights_capacity.y {
        let light = view_light_of(index);
        if lane == 0u {
            view_lights[index] = light;
        }
        let volume = light_volume(light.sphere, light.cone);
        let range = candidate_range(volume.center, volume.radius);
        if !range.empty {
            let words_per_mask = grid.scheme_lights_capacity.w;
            let bit = 1u << (index & 31u);
            let span = range.hi - range.lo + vec3<u32>(1u);
            // Runs are the walk groups (SLICES_PER_WALK slices) the light's slices touch.
            let first_run = range.lo.z / SLICES_PER_WALK;
            let runs = range.hi.z / SLICES_PER_WALK - first_run + 1u;
            let candidates = span.x * span.y * runs;
            var first_slice = 0xffffu;
            var last_slice = 0u;
            for (var i = lane; i < candidates; i += MARK_LANES) {
                let x = range.lo.x + i % span.x;
                let y = range.lo.y + (i / span.x) % span.y;
                let run = first_run + i / (span.x * span.y);
                // Only the tile's slices that hold anything are tested.
                let occupied = occupied_slices(y * grid.dims.x + x);
                let run_first = max(max(run * SLICES_PER_WALK, range.lo.z), occupied.x);
                let run_last = min(min(run * SLICES_PER_WALK + SLICES_PER_WALK - 1u, range.hi.z), occupied.y);
                var met = false;
                for (var z = run_first; z <= run_last; z++) {
                    let cluster = (z * grid.dims.y + y) * grid.dims.x + x;
                    if volume_meets_bounds(volume, cluster_bounds[cluster]) {
                        met = true;
                        first_slice = min(first_slice, z);
                        last_slice = max(last_slice, z);
                        // Counted here, where the test is made once: the walk only writes.
                        atomicAdd(&counts[cluster], 1u);
                    }
                }
                if met {
                    let mask = (y * grid.dims.x + x) * grid.mask_layout.y + run / grid.mask_layout.x;
                    let word = index >> 5u;
                    let before = atomicOr(&tile_masks[mask * words_per_mask + word], bit);
                    if before == 0u {
                        // The word's first light: its window is no longer empty.
                        let window = word / WALK_THREADS;
                        atomicOr(&window_marks[mask * grid.mask_layout.z + window / 32u], 1u << (window % 32u));
                    }
                }
            }
            atomicMin(&mark_first_slice[slot], first_slice);
            atomicMax(&mark_last_slice[slot], last_slice);
        }
    }
    workgroupBarrier();
    if lane == 0u && index < grid.scheme_lights_capacity.y {
        light_slices[index] = atomicLoad(&mark_first_slice[slot]) | (atomicLoad(&mark_last_slice[slot]) << 16u);
    }
}

// The walk's threads: one scan of SCAN_THREADS mask words a window.
const WALK_THREADS: u32 = SCAN_THREADS;
// Slices one walk handles: a workgroup per tile and group of slices.
const SLICES_PER_WALK: u32 = #SLICES_PER_WALK;
// For each slice of the walk, one bit per thread of a batch: did its light meet the
// slice's cluster?
var<workgroup> batch_hits: array<array<atomic<u32>, 8>, SLICES_PER_WALK>;
// For each slice, the hits in the batch's words before each word (exclusive prefix), and
// in the whole batch (index 8).
var<workgroup> hit_prefix: array<array<u32, 9>, SLICES_PER_WALK>;

// Whether any cluster of the walk's slices has a non-empty box.
var<workgroup> walk_has_boxes: u32;
// One word of the walk's window marks, as thread 0 read it.
var<workgroup> walk_window_marks: u32;

// The position of the `rank`-th (from 0) set bit of `bits`.
fn nth_set_bit(bits: u32, rank: u32) -> u32 {
    var remaining = rank;
    var word = bits;
    var position = 0u;
    // Halve the search range five times: is the bit in the low half?
    for (var width = 16u; width > 0u; width >>= 1u) {
        let low = word & ((1u << width) - 1u);
        let low_count = countOneBits(low);
        if remaining >= low_count {
            remaining -= low_count;
            word >>= width;
            position += width;
        } else {
            word = low;
        }
    }
    return position;
}

// Walks the tile's mask in light order for the slices group_first.. of one group, testing
// each marked light against those slices' clusters, and stores each hit at
// `offsets[cluster]` plus its rank among the hits before it (found[s] counts the hits of
// slice s in earlier batches; every thread keeps the same counts).
fn walk_tile(tile: u32, group_first: u32, thread: u32) {
    let light_count = grid.scheme_lights_capacity.y;
    let words_per_mask = grid.scheme_lights_capacity.w;
    let words = (light_count + 31u) / 32u;
    // This group's mask (shared with neighbouring groups when the budget asked for it).
    let mask = tile * grid.mask_layout.y + (group_first / SLICES_PER_WALK) / grid.mask_layout.x;
    let mask_base = mask * words_per_mask;
    let capacity = grid.scheme_lights_capacity.z;
    let group_last = min(group_first + SLICES_PER_WALK, grid.dims.z) - 1u;
    let tiles = grid.dims.x * grid.dims.y;
    var found: array<u32, SLICES_PER_WALK>;
    // Groups of slices where no box holds anything (no visible sample falls in them) list
    // nothing: the walk is skipped. One thread looks, all read its answer.
    if thread == 0u {
        let occupied = occupied_slices(tile);
        walk_has_boxes = u32(occupied.x <= group_last && occupied.y >= group_first);
    }
    if workgroupUniformLoad(&walk_has_boxes) == 0u {
        return;
    }
    // Only windows holding marked lights, in order: 32 windows per word of window marks.
    let window_words = (words + WALK_THREADS * 32u - 1u) / (WALK_THREADS * 32u);
    for (var marks_word = 0u; marks_word < window_words; marks_word++) {
        if thread == 0u {
            walk_window_marks = atomicLoad(&window_marks[mask * grid.mask_layout.z + marks_word]);
        }
        var pending = workgroupUniformLoad(&walk_window_marks);
        // Every thread has read the marks before thread 0 may overwrite them.
        workgroupBarrier();
        while pending != 0u {
            let window = (marks_word * 32u + firstTrailingBit(pending)) * WALK_THREADS;
            pending &= pending - 1u;
            let word_index = window + thread;
            var bits = 0u;
            if word_index < words {
                bits = atomicLoad(&tile_masks[mask_base + word_index]);
            }
            // Inclusive prefix sums of the words' bit counts.
            inclusive_scan(thread, countOneBits(bits));
            let marked = workgroupUniformLoad(&scan_values[WALK_THREADS - 1u]);
            // The window's marked lights, 256 at a time, in light order.
            for (var batch = 0u; batch < marked; batch += WALK_THREADS) {
                if thread < 8u * SLICES_PER_WALK {
                    atomicStore(&batch_hits[thread / 8u][thread % 8u], 0u);
                }
                workgroupBarrier();
                let rank = batch + thread;
                var light = 0u;
                var lo = 1u;
                var hi = 0u;
                if rank < marked {
                    // The word holding the rank-th marked light: the first whose inclusive
                    // prefix exceeds the rank (binary search).
                    var first = 0u;
                    var last = WALK_THREADS - 1u;
                    while first < last {
                        let mid = (first + last) / 2u;
                        if scan_values[mid] > rank {
                            last = mid;
                        } else {
                            first = mid + 1u;
                        }
                    }
                    let before = select(0u, scan_values[first - 1u], first > 0u);
                    let word = atomicLoad(&tile_masks[mask_base + window + first]);
                    light = (window + first) * 32u + nth_set_bit(word, rank - before);
                    let slices = light_slices[light];
                    lo = max(slices & 0xffffu, group_first);
                    hi = min(slices >> 16u, group_last);
                    let volume = light_volume(view_lights[light].sphere, view_lights[light].cone);
                    for (var slice = lo; slice <= hi; slice++) {
                        let bounds = cluster_bounds[slice * tiles + tile];
                        if volume_meets_bounds(volume, bounds) {
                            atomicOr(&batch_hits[slice - group_first][thread >> 5u], 1u << (thread & 31u));
                        }
                    }
                }
                workgroupBarrier();
                // Per slice, the words' hit counts turned into exclusive prefixes, by one thread
                // a slice.
                if thread < SLICES_PER_WALK {
                    var sum = 0u;
                    for (var w = 0u; w < 8u; w++) {
                        hit_prefix[thread][w] = sum;
                        sum += countOneBits(atomicLoad(&batch_hits[thread][w]));
                    }
                    hit_prefix[thread][8] = sum;
                }
                workgroupBarrier();
                let word = thread >> 5u;
                let below = (1u << (thread & 31u)) - 1u;
                for (var slice = lo; slice <= hi; slice++) {
                    let s = slice - group_first;
                    let own = atomicLoad(&batch_hits[s][word]);
                    if (own & (1u << (thread & 31u))) != 0u {
                        let cluster = slice * tiles + tile;
                        let rank_in_batch = hit_prefix[s][word] + countOneBits(own & below);
                        let at = offsets[cluster] + found[s] + rank_in_batch;
                        if at < capacity {
                            light_indices[at] = light;
                        }
                    }
                }
                for (var s = 0u; s <= group_last - group_first; s++) {
                    found[s] += hit_prefix[s][8];
                }
                // Everyone has read the hits and the prefix before the next batch or window
                // overwrites them.
                workgroupBarrier();
            }
        }
    }
}

// One workgroup per tile (x, y) and group of SLICES_PER_WALK slices (z).
@compute @workgroup_size(256)
fn fill_cluster_lists(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    let tile = group.y * grid.dims.x + group.x;
    walk_tile(tile, group.z * SLICES_PER_WALK, thread);
}
