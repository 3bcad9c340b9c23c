// The far field's GPU passes (`cluster::GpuFarField`), rebuilt every frame from the
// animated lights.
//
// Light tree (deterministic, FAR_FIELD_TREE):
//   1. light_bounds: the box of every light (atomics on order-preserving codes);
//   2. light_keys: each light's leaf cell of a 2^levels grid over that box, as a Morton code;
//   3. sort_histogram / sort_scan / sort_scatter, once per 5-bit digit: a stable radix sort
//      of the lights by leaf cell (ties stay in light order), so every node of the implicit
//      octree owns a run of consecutive sorted lights;
//   4. leaf_nodes: each leaf sums its run of lights (in sorted order) into an aggregate;
//      inner_nodes, once per level: each node sums its 8 children (in child order);
//   5. cut_clusters: each occupied cluster chooses its far-field entries, a cut of the tree
//      refined where the error bound is largest (as in lightcuts, Walter et al. 2005) until
//      every node's bound is at most tolerance x the cut's estimated total, or its slots run
//      out (then the rest stay aggregates: the cost stays bounded); a leaf that may not be
//      approximated is evaluated light by light (every node, with tolerance 0).
// No float atomics and no order that depends on thread timing: a frame is bit-reproducible.
//
// Stochastic culling (FAR_FIELD_STOCHASTIC):
//   stochastic_ranges: each light's random range (far_nodes.wgsl), written as the radius of
//   a copy of the lights that the assignment tests.

#import manylights::common::view::{view, relative_to_origin}
#import manylights::lights::light_set::Light
#import manylights::lights::hash::pcg_hash
#import manylights::lights::shading::{light_power_share, light_emission_dipole}
#import manylights::cluster::bounds::{ClusterBounds, bounds_are_empty, ordered_code, from_ordered_code}
#import manylights::cluster::scan::{SCAN_THREADS, scan_values, inclusive_scan}
#import manylights::cluster::far_nodes::{
    FarFieldParams, FarNode, FAR_ENTRY_EXACT, MAX_CUT_SLOTS, cut_slots, far_level_first, window_complement
}

struct PassConstants {
    // Sort: the digit's first bit. Inner nodes: the level built.
    value: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(0) var<uniform> params: FarFieldParams;
@group(1) @binding(1) var<uniform> pass_constants: PassConstants;
// The lights, animated this frame.
@group(1) @binding(2) var<storage, read> lights: array<Light>;
// Sort keys (leaf Morton codes) and values (light indices): read from one pair, written to
// the other.
@group(1) @binding(3) var<storage, read> keys_in: array<u32>;
@group(1) @binding(4) var<storage, read> values_in: array<u32>;
@group(1) @binding(5) var<storage, read_write> keys_out: array<u32>;
@group(1) @binding(6) var<storage, read_write> values_out: array<u32>;
// Per digit and block: how many lights of the block have the digit, then (scanned) where
// the block's first such light goes. Digit-major: digit * blocks + block.
@group(1) @binding(7) var<storage, read_write> histogram: array<u32>;
// The tree: level 0 (the leaves) first, the root last.
@group(1) @binding(8) var<storage, read_write> nodes: array<FarNode>;
// The lights' box: min as complemented codes (atomicMax), then max codes. Cleared each frame.
@group(1) @binding(9) var<storage, read_write> bounds_codes: array<atomic<u32>, 6>;
// The clusters' view-space boxes, as the assignment tested them.
@group(1) @binding(10) var<storage, read> cluster_bounds: array<ClusterBounds>;
// Per cluster: a count then up to `cut_slots` entries (node index, FAR_ENTRY_EXACT flag).
@group(1) @binding(11) var<storage, read_write> far_lists: array<u32>;
// Stochastic: the lights with their random ranges as radii (what the assignment tests).
@group(1) @binding(12) var<storage, read_write> cull_lights: array<Light>;

// Lights per sort block, and the block's threads (each takes BLOCK / SORT_THREADS lights,
// round by round in light order).
const BLOCK: u32 = #FAR_SORT_BLOCK;
const SORT_THREADS: u32 = #FAR_SORT_THREADS;
const SORT_ROUNDS: u32 = BLOCK / SORT_THREADS;
const RADIX_BITS: u32 = #FAR_RADIX_BITS;
const RADIX_BINS: u32 = #FAR_RADIX_BINS;

// The workgroup's box, then one atomic per code and workgroup: a million lights' atomics
// on the same six words serialise.
var<workgroup> group_codes: array<atomic<u32>, 6>;

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn light_bounds(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    if thread < 6u {
        atomicStore(&group_codes[thread], 0u);
    }
    workgroupBarrier();
    if id.x < params.setup.y {
        let p = lights[id.x].position;
        for (var axis = 0u; axis < 3u; axis++) {
            atomicMax(&group_codes[axis], ~ordered_code(p[axis]));
            atomicMax(&group_codes[3u + axis], ordered_code(p[axis]));
        }
    }
    workgroupBarrier();
    if thread < 6u {
        atomicMax(&bounds_codes[thread], atomicLoad(&group_codes[thread]));
    }
}

fn lights_box_min() -> vec3<f32> {
    return vec3<f32>(
        from_ordered_code(~atomicLoad(&bounds_codes[0])),
        from_ordered_code(~atomicLoad(&bounds_codes[1])),
        from_ordered_code(~atomicLoad(&bounds_codes[2])),
    );
}

fn lights_box_max() -> vec3<f32> {
    return vec3<f32>(
        from_ordered_code(atomicLoad(&bounds_codes[3])),
        from_ordered_code(atomicLoad(&bounds_codes[4])),
        from_ordered_code(atomicLoad(&bounds_codes[5])),
    );
}

// Interleaves the low 10 bits of x, y and z (x lowest).
fn morton3(cell: vec3<u32>) -> u32 {
    var code = 0u;
    for (var bit = 0u; bit < 10u; bit++) {
        code |= ((cell.x >> bit) & 1u) << (3u * bit);
        code |= ((cell.y >> bit) & 1u) << (3u * bit + 1u);
        code |= ((cell.z >> bit) & 1u) << (3u * bit + 2u);
    }
    return code;
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn light_keys(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.setup.y {
        return;
    }
    let lo = lights_box_min();
    let extent = max(lights_box_max() - lo, vec3<f32>(1e-30));
    let cells_per_side = 1u << params.setup.z;
    let unit = (lights[id.x].position - lo) / extent;
    // Clamped: the box's far faces belong to the last cell.
    let cell = min(vec3<u32>(max(unit, vec3<f32>(0.0)) * f32(cells_per_side)), vec3<u32>(cells_per_side - 1u));
    keys_out[id.x] = morton3(cell);
    values_out[id.x] = id.x;
}

var<workgroup> block_histogram: array<atomic<u32>, RADIX_BINS>;
// Per digit, which of a round's threads hold it: a bit per thread, MASK_WORDS words a
// digit. A thread's rank among the round's earlier threads with its digit is the count of
// bits below its own, at most MASK_WORDS reads (a loop over the earlier threads took up to
// 255, and most of the sort's time).
const MASK_WORDS: u32 = SORT_THREADS / 32u;
var<workgroup> round_masks: array<atomic<u32>, RADIX_BINS * MASK_WORDS>;
// Per digit, where the block's next light with it goes.
var<workgroup> next_slot: array<u32, RADIX_BINS>;

// The sorted light of `block` that `thread` takes in `round`: consecutive threads read
// consecutive lights.
fn block_light(block: u32, round: u32, thread: u32) -> u32 {
    return block * BLOCK + round * SORT_THREADS + thread;
}

fn digit_of(key: u32) -> u32 {
    return (key >> pass_constants.value) & (RADIX_BINS - 1u);
}

@compute @workgroup_size(SORT_THREADS)
fn sort_histogram(
    @builtin(workgroup_id) block: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    if thread < RADIX_BINS {
        atomicStore(&block_histogram[thread], 0u);
    }
    workgroupBarrier();
    for (var round = 0u; round < SORT_ROUNDS; round++) {
        let index = block_light(block.x, round, thread);
        if index < params.setup.y {
            atomicAdd(&block_histogram[digit_of(keys_in[index])], 1u);
        }
    }
    workgroupBarrier();
    if thread < RADIX_BINS {
        histogram[thread * params.sizes.x + block.x] = atomicLoad(&block_histogram[thread]);
    }
}

// One workgroup: the histogram becomes exclusive prefix sums (digit-major, so each
// digit's lights follow the smaller digits', block by block: a stable order). Its threads
// walk their shares one entry at a time, so the blocks are large (BLOCK lights) to keep
// the histogram short: with 256-light blocks a million lights' scan took 0.4 ms a digit.
@compute @workgroup_size(256)
fn sort_scan(@builtin(local_invocation_index) thread: u32) {
    let n = RADIX_BINS * params.sizes.x;
    let per_thread = (n + SCAN_THREADS - 1u) / SCAN_THREADS;
    let begin = min(thread * per_thread, n);
    let end = min(begin + per_thread, n);
    var sum = 0u;
    for (var i = begin; i < end; i++) {
        sum += histogram[i];
    }
    inclusive_scan(thread, sum);
    var running = scan_values[thread] - sum;
    for (var i = begin; i < end; i++) {
        let count = histogram[i];
        histogram[i] = running;
        running += count;
    }
}

@compute @workgroup_size(SORT_THREADS)
fn sort_scatter(
    @builtin(workgroup_id) block: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    if thread < RADIX_BINS {
        next_slot[thread] = histogram[thread * params.sizes.x + block.x];
    }
    // Round by round in light order, and within a round by rank among the round's earlier
    // lights with the same digit: the sort is stable.
    let word = thread / 32u;
    let bit = 1u << (thread % 32u);
    for (var round = 0u; round < SORT_ROUNDS; round++) {
        for (var entry = thread; entry < RADIX_BINS * MASK_WORDS; entry += SORT_THREADS) {
            atomicStore(&round_masks[entry], 0u);
        }
        workgroupBarrier();
        let index = block_light(block.x, round, thread);
        let inside = index < params.setup.y;
        var key = 0u;
        var digit = 0u;
        if inside {
            key = keys_in[index];
            digit = digit_of(key);
            atomicOr(&round_masks[digit * MASK_WORDS + word], bit);
        }
        workgroupBarrier();
        if inside {
            var rank = countOneBits(atomicLoad(&round_masks[digit * MASK_WORDS + word]) & (bit - 1u));
            for (var earlier = 0u; earlier < word; earlier++) {
                rank += countOneBits(atomicLoad(&round_masks[digit * MASK_WORDS + earlier]));
            }
            let at = next_slot[digit] + rank;
            keys_out[at] = key;
            values_out[at] = values_in[index];
        }
        workgroupBarrier();
        if thread < RADIX_BINS {
            var count = 0u;
            for (var w = 0u; w < MASK_WORDS; w++) {
                count += countOneBits(atomicLoad(&round_masks[thread * MASK_WORDS + w]));
            }
            next_slot[thread] += count;
        }
        workgroupBarrier();
    }
}

// The first sorted light whose key is at least `key` (keys_in holds the sorted keys).
fn lower_bound(key: u32) -> u32 {
    var lo = 0u;
    var hi = params.setup.y;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if keys_in[mid] < key {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

fn empty_node() -> FarNode {
    return FarNode(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0, vec3<f32>(3.0e38), 0u, vec3<f32>(-3.0e38), 0u, vec3<f32>(0.0), 0u);
}

// Adds lights (a light or a child node) to a node being summed. The centroid holds the
// weighted sum of positions relative to `anchor` (a position of the node's own) until
// `finish_centroid`: relative sums lose no precision to the positions' magnitude, and
// lights at one point give that point exactly.
fn add_to_node(node: ptr<function, FarNode>, anchor: vec3<f32>, position: vec3<f32>, weight: f32, power: vec3<f32>, radius: f32, box_min: vec3<f32>, box_max: vec3<f32>, count: u32, dipole: vec3<f32>) {
    (*node).centroid += (position - anchor) * weight;
    (*node).dipole += dipole;
    (*node).weight += weight;
    (*node).power += power;
    (*node).radius = max((*node).radius, radius);
    (*node).box_min = min((*node).box_min, box_min);
    (*node).box_max = max((*node).box_max, box_max);
    (*node).count += count;
}

fn finish_centroid(node: ptr<function, FarNode>, anchor: vec3<f32>) {
    if (*node).weight > 0.0 {
        (*node).centroid = anchor + (*node).centroid / (*node).weight;
    } else {
        // Black lights only: the box's centre (they add nothing anyway).
        (*node).centroid = 0.5 * ((*node).box_min + (*node).box_max);
    }
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn leaf_nodes(@builtin(global_invocation_id) id: vec3<u32>) {
    let leaves = far_level_first(params, 1u);
    if id.x >= leaves {
        return;
    }
    let first = lower_bound(id.x);
    let end = lower_bound(id.x + 1u);
    var node = empty_node();
    node.first = first;
    var anchor = vec3<f32>(0.0);
    if first < end {
        anchor = lights[values_in[first]].position;
    }
    for (var i = first; i < end; i++) {
        let light = lights[values_in[i]];
        let power = light.color * (light.intensity * light_power_share(light));
        let weight = max(power.x, max(power.y, power.z));
        add_to_node(&node, anchor, light.position, weight, power, light.radius, light.position, light.position, 1u, weight * light_emission_dipole(light));
    }
    finish_centroid(&node, anchor);
    nodes[id.x] = node;
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn inner_nodes(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = pass_constants.value;
    let first = far_level_first(params, level);
    let count = far_level_first(params, level + 1u) - first;
    if id.x >= count {
        return;
    }
    let children = far_level_first(params, level - 1u) + id.x * 8u;
    var node = empty_node();
    node.first = nodes[children].first;
    var anchor = vec3<f32>(0.0);
    var anchored = false;
    for (var k = 0u; k < 8u; k++) {
        let child = nodes[children + k];
        if child.count > 0u {
            if !anchored {
                anchor = child.centroid;
                anchored = true;
            }
            add_to_node(&node, anchor, child.centroid, child.weight, child.power, child.radius, child.box_min, child.box_max, child.count, child.dipole);
        }
    }
    finish_centroid(&node, anchor);
    nodes[first + id.x] = node;
}

// The level of a node, from the level table.
fn node_level(node: u32) -> u32 {
    var level = 0u;
    while level + 1u < params.setup.z + 1u && node >= far_level_first(params, level + 1u) {
        level++;
    }
    return level;
}

struct NodeBound {
    // A bound on the error of using the node as one light anywhere in the cluster, and
    // the node's estimated contribution there (luminance-free: brightest channel).
    error: f32,
    estimate: f32,
}

// Largest value the window's complement takes, (2u - u^3) at u = sqrt(2/3), times r^2.
const COMPLEMENT_PEAK: f32 = 1.0887;

// Error bound of approximating `node` by one aggregate for every point of the cluster box
// (view-space centre and half extents). Its lights lie within `spread` of the centroid;
// at distance at least a from the box the complement's slope is at most 2 / max(a, r)^3
// and its value at most min(1.089 / r^2, 1 / a^2); the cosine and the half-vector change
// by at most the angle spread / a. So the error is at most
// power x spread x (2 / max(a, r)^3 + peak(a) / a), infinite when the node touches the box.
// The angle term takes max(a, r) too: within r of the box the complement is small where
// the angle changes fast, and an infinite bound made every touching node tie, split in
// tree order until the slots ran out, so each cluster kept large aggregates in a
// different corner of its box and neighbouring clusters disagreed along their edges
// (issue 58's seams). Floored at r, touching nodes rank by power x spread: the brightest,
// widest split first, wherever they lie. There it is an estimate, no longer a bound.
fn node_bound(node: FarNode, box_center: vec3<f32>, box_half: vec3<f32>) -> NodeBound {
    let power = max(node.power.x, max(node.power.y, node.power.z));
    let rows = mat3x3<f32>(view.view[0].xyz, view.view[1].xyz, view.view[2].xyz);
    let node_center = (view.view * vec4<f32>(relative_to_origin(0.5 * (node.box_min + node.box_max)), 1.0)).xyz;
    let world_half = 0.5 * (node.box_max - node.box_min);
    let node_half = abs(rows[0]) * world_half.x + abs(rows[1]) * world_half.y + abs(rows[2]) * world_half.z;
    let gap = max(abs(node_center - box_center) - box_half - node_half, vec3<f32>(0.0));
    let a = length(gap);
    let centroid = (view.view * vec4<f32>(relative_to_origin(node.centroid), 1.0)).xyz;
    let to_centroid = centroid - box_center;
    let estimate = power * window_complement(dot(to_centroid, to_centroid), node.radius);
    let spread = length(node.box_max - node.box_min);
    if spread == 0.0 {
        // Its lights are at one point: the aggregate is exact.
        return NodeBound(0.0, estimate);
    }
    let radius = max(node.radius, 1e-6);
    let m = max(a, radius);
    let peak = min(COMPLEMENT_PEAK / (radius * radius), 1.0 / max(a * a, 1e-30));
    let error = power * spread * (2.0 / (m * m * m) + peak / m);
    return NodeBound(error, estimate);
}

// Threads that choose one cluster's cut together.
const CUT_THREADS: u32 = #CLUSTER_WORKGROUP_SIZE;

// The cut being chosen: entries (node index, FAR_ENTRY_EXACT), their error bounds and
// estimates; entries in use and the estimated total; whether another round runs.
var<workgroup> cut: array<u32, MAX_CUT_SLOTS>;
var<workgroup> cut_error: array<f32, MAX_CUT_SLOTS>;
var<workgroup> cut_estimate: array<f32, MAX_CUT_SLOTS>;
var<workgroup> cut_used: u32;
var<workgroup> cut_total: f32;
var<workgroup> cut_go_on: u32;
// The search for the entry with the largest bound: each thread's best, then the tree.
var<workgroup> worst_error: array<f32, CUT_THREADS>;
var<workgroup> worst_entry: array<u32, CUT_THREADS>;

// One workgroup per cluster (x + y x num_workgroups.x: clusters may outnumber one
// dimension's 65,535 workgroups). Each round, the workgroup finds the entry with the
// largest bound (the first such entry, as a serial scan would), and one thread settles or
// splits it: the cut is the serial lightcut's, entry for entry, with the search that grew
// with the slots squared spread over the threads and the cut in workgroup memory.
@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn cut_clusters(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    let cluster = group.y * groups.x + group.x;
    let slots = min(cut_slots(params), MAX_CUT_SLOTS);
    let row = cluster * (slots + 1u);
    if cluster >= arrayLength(&cluster_bounds) || row + slots >= arrayLength(&far_lists) {
        return;
    }
    let bounds = cluster_bounds[cluster];
    let root = far_level_first(params, params.setup.z);
    if bounds_are_empty(bounds) || params.setup.y == 0u {
        if thread == 0u {
            far_lists[row] = 0u;
        }
        return;
    }
    let box_center = 0.5 * (bounds.min.xyz + bounds.max.xyz);
    let box_half = 0.5 * (bounds.max.xyz - bounds.min.xyz);
    let tolerance = params.tolerance.x;
    if thread == 0u {
        cut_used = 1u;
        cut_go_on = 1u;
        cut[0] = root;
        let root_bound = node_bound(nodes[root], box_center, box_half);
        cut_error[0] = root_bound.error;
        cut_estimate[0] = root_bound.estimate;
        cut_total = root_bound.estimate;
        if nodes[root].count == 0u {
            cut_used = 0u;
            cut_go_on = 0u;
        }
    }
    // Each round settles or splits the entry with the largest bound; at most 2 x slots rounds
    // (every split adds an entry, every settling marks one).
    for (var round = 0u; round < 2u * slots + 1u; round++) {
        if workgroupUniformLoad(&cut_go_on) == 0u {
            break;
        }
        // This thread's entries, ascending: the first of the largest.
        var best = 0u;
        var best_error = -1.0;
        for (var k = thread; k < cut_used; k += CUT_THREADS) {
            if cut_error[k] > best_error {
                best = k;
                best_error = cut_error[k];
            }
        }
        worst_error[thread] = best_error;
        worst_entry[thread] = best;
        workgroupBarrier();
        for (var stride = CUT_THREADS / 2u; stride > 0u; stride /= 2u) {
            if thread < stride {
                let other_error = worst_error[thread + stride];
                let other = worst_entry[thread + stride];
                if other_error > worst_error[thread] || (other_error == worst_error[thread] && other < worst_entry[thread]) {
                    worst_error[thread] = other_error;
                    worst_entry[thread] = other;
                }
            }
            workgroupBarrier();
        }
        if thread == 0u {
            refine(worst_entry[0], box_center, box_half, tolerance, slots);
        }
    }
    workgroupBarrier();
    // With tolerance 0, whatever still exceeds the bound (rounds ran out) is evaluated
    // exactly.
    let used = cut_used;
    for (var k = thread; k < used; k += CUT_THREADS) {
        var entry = cut[k];
        if tolerance == 0.0 && cut_error[k] > 0.0 {
            entry |= FAR_ENTRY_EXACT;
        }
        far_lists[row + 1u + k] = entry;
    }
    if thread == 0u {
        far_lists[row] = used;
    }
}

// One round of the cut, by one thread: the entry `worst` (the largest bound) is within
// tolerance (the cut is done), or is settled (a leaf, evaluated light by light; a node
// there is no room to split, left an aggregate beyond its bound), or is split into its
// occupied children (the first takes its slot, the others are appended).
fn refine(worst: u32, box_center: vec3<f32>, box_half: vec3<f32>, tolerance: f32, slots: u32) {
    if cut_error[worst] <= tolerance * cut_total {
        cut_go_on = 0u;
        return;
    }
    let index = cut[worst];
    let level = node_level(index);
    var children = 0u;
    var first_child = 0u;
    if level > 0u {
        first_child = far_level_first(params, level - 1u) + (index - far_level_first(params, level)) * 8u;
        for (var k = 0u; k < 8u; k++) {
            children += select(0u, 1u, nodes[first_child + k].count > 0u);
        }
    }
    if level == 0u || cut_used + children - 1u > slots {
        // A leaf's few lights are evaluated one by one (exact). A node there is no room
        // to split stays one aggregate light, beyond its bound: the cost per pixel
        // stays bounded (slots plus leaves). Only tolerance 0 (exact) evaluates it
        // light by light, whatever that costs.
        if level == 0u || tolerance == 0.0 {
            cut[worst] = index | FAR_ENTRY_EXACT;
        }
        cut_error[worst] = 0.0;
        return;
    }
    cut_total -= cut_estimate[worst];
    var placed = 0u;
    for (var k = 0u; k < 8u; k++) {
        let child = first_child + k;
        let node = nodes[child];
        if node.count == 0u {
            continue;
        }
        var slot = worst;
        if placed > 0u {
            slot = cut_used;
            cut_used++;
        }
        placed++;
        let bound = node_bound(node, box_center, box_half);
        cut[slot] = child;
        cut_error[slot] = bound.error;
        cut_estimate[slot] = bound.estimate;
        cut_total += bound.estimate;
    }
}

// A light's random range for stochastic culling: at least its radius.
@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn stochastic_ranges(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.setup.y {
        return;
    }
    var light = lights[id.x];
    // xi uniform in (0, 1]: the top 24 bits of a PCG hash of (seed, index), plus one step.
    let xi = (f32(pcg_hash(params.sizes.z ^ pcg_hash(id.x)) >> 8u) + 1.0) * (1.0 / 16777216.0);
    let tolerance = params.tolerance.x;
    // Past 1e15 m a range reaches every cluster anyway (and tolerance 0 means every light
    // reaches everywhere); the cap keeps squares finite in f32.
    var range = 1e15;
    if tolerance > 0.0 {
        range = min(light.radius / sqrt(tolerance * xi), 1e15);
    }
    light.radius = max(light.radius, range);
    cull_lights[id.x] = light;
}
