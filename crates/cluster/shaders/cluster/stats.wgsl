// Light-list statistics on the GPU, so that asking for them neither stalls the frame nor
// costs CPU time (mirrors `cluster::ClusterStats::from_offsets` and
// `cluster::false_positive_ratio`, which stay as the CPU reference):
//   1. list_statistics: one thread per cluster: histogram of list lengths by powers of
//      two, the longest list, the total;
//   2. mark_reached (false positives only): one thread per pixel reconstructs its
//      view-space position from depth, marks its cluster occupied, and marks every list
//      entry of that cluster whose light reaches it;
//   3. count_false_positives: one thread per cluster: in occupied clusters, entries and
//      entries no pixel was reached by.

#import manylights::common::view::view
#import manylights::cluster::cluster_index::{ClusterParams, cluster_index}
#import manylights::cluster::bounds::ViewLight

struct ListStatistics {
    // offsets[cluster count]: the sum of all list lengths.
    total_entries: u32,
    max_lights: atomic<u32>,
    // Entries of clusters with at least one visible pixel, and those among them whose
    // light reaches none of the cluster's pixels.
    visible_entries: atomic<u32>,
    useless_entries: atomic<u32>,
    // Clusters with 0, 1, 2-3, 4-7, ... lights (bucket k: 2^(k-1) to 2^k - 1).
    histogram: array<atomic<u32>, #STATISTICS_HISTOGRAM_BUCKETS>,
}

@group(1) @binding(0) var<uniform> grid: ClusterParams;
@group(1) @binding(1) var<storage, read> offsets: array<u32>;
@group(1) @binding(2) var<storage, read> light_indices: array<u32>;
@group(1) @binding(3) var<storage, read> view_lights: array<ViewLight>;
@group(1) @binding(4) var<storage, read_write> statistics: ListStatistics;
// One bit per list entry: reached by at least one pixel of its cluster.
@group(1) @binding(5) var<storage, read_write> reached: array<atomic<u32>>;
// One bit per cluster: holds at least one visible pixel.
@group(1) @binding(6) var<storage, read_write> occupied: array<atomic<u32>>;
@group(1) @binding(7) var depth: texture_depth_2d;

// The part of a cluster's list that was written (a list cut short at the index capacity
// is shaded from all lights that frame, and the buffer grows for the next).
fn list_range(cluster: u32) -> vec2<u32> {
    let capacity = grid.scheme_lights_capacity.z;
    return vec2<u32>(min(offsets[cluster], capacity), min(offsets[cluster + 1u], capacity));
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn list_statistics(@builtin(global_invocation_id) id: vec3<u32>) {
    let cluster = id.x;
    let clusters = grid.dims.w;
    if cluster == 0u {
        statistics.total_entries = offsets[clusters];
    }
    if cluster >= clusters {
        return;
    }
    let count = offsets[cluster + 1u] - offsets[cluster];
    atomicMax(&statistics.max_lights, count);
    let bucket = select(32u - countLeadingZeros(count), 0u, count == 0u);
    atomicAdd(&statistics.histogram[bucket], 1u);
}

// Bit sets. (Separate functions per buffer: WGSL passes no pointers to storage buffers.)
// Each reads first: most bits are set many times, and a load is cheaper than an atomic
// read-modify-write.
fn mark_occupied(cluster: u32) {
    let mask = 1u << (cluster & 31u);
    if (atomicLoad(&occupied[cluster >> 5u]) & mask) == 0u {
        atomicOr(&occupied[cluster >> 5u], mask);
    }
}

fn is_occupied(cluster: u32) -> bool {
    return (atomicLoad(&occupied[cluster >> 5u]) & (1u << (cluster & 31u))) != 0u;
}

fn mark_reached_entry(entry: u32) {
    let mask = 1u << (entry & 31u);
    if (atomicLoad(&reached[entry >> 5u]) & mask) == 0u {
        atomicOr(&reached[entry >> 5u], mask);
    }
}

fn is_reached(entry: u32) -> bool {
    return (atomicLoad(&reached[entry >> 5u]) & (1u << (entry & 31u))) != 0u;
}

@compute @workgroup_size(#SCREEN_TILE, #SCREEN_TILE)
fn mark_reached(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(depth);
    if any(id.xy >= size) {
        return;
    }
    let d = textureLoad(depth, vec2<i32>(id.xy), 0);
    if d == view.near_far.z {
        return;
    }
    let pixel = vec2<f32>(id.xy) + 0.5;
    let ndc = vec4<f32>(pixel.x / f32(size.x) * 2.0 - 1.0, 1.0 - pixel.y / f32(size.y) * 2.0, d, 1.0);
    let unprojected = view.inverse_proj * ndc;
    let position = unprojected.xyz / unprojected.w;
    let cluster = cluster_index(grid, pixel, -position.z);
    mark_occupied(cluster);
    let range = list_range(cluster);
    for (var i = range.x; i < range.y; i++) {
        let light = view_lights[light_indices[i]].sphere;
        let cone = view_lights[light_indices[i]].cone;
        let offset = position - light.xyz;
        let distance_squared = dot(offset, offset);
        // A spot reaches the pixel only inside its outer cone (sin^2 of the angle from
        // the axis below sin^2 of the outer half-angle, in front of the light).
        let across = cross(offset, cone.xyz);
        let in_cone = cone.w < 0.0 || (dot(offset, cone.xyz) > 0.0 && dot(across, across) < cone.w * cone.w * distance_squared);
        if distance_squared < light.w * light.w && in_cone {
            mark_reached_entry(i);
        }
    }
}

@compute @workgroup_size(#CLUSTER_WORKGROUP_SIZE)
fn count_false_positives(@builtin(global_invocation_id) id: vec3<u32>) {
    let cluster = id.x;
    if cluster >= grid.dims.w || !is_occupied(cluster) {
        return;
    }
    let range = list_range(cluster);
    var useless = 0u;
    for (var i = range.x; i < range.y; i++) {
        useless += u32(!is_reached(i));
    }
    atomicAdd(&statistics.visible_entries, range.y - range.x);
    atomicAdd(&statistics.useless_entries, useless);
}
