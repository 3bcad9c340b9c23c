// The cluster grid as the GPU sees it, and the one fragment-to-cluster index function used
// by light assignment and by shading (its Rust twin: `cluster::ClusterGrid`). Clustered
// shading after Olsson, Billeter and Assarsson 2012; logarithmic depth slices as in Doom
// 2016; an optional separate first slice as in Bevy's and Filament's froxels.

struct ClusterParams {
    // Tiles across, tiles down, depth slices, total clusters.
    dims: vec4<u32>,
    // Tile width and height in pixels, screen width and height in pixels.
    tile_and_screen: vec4<f32>,
    // Depth range of the slices (near, far), the first slice's far depth, and the scale
    // of the slicing function (see `cluster_slice`).
    z_params: vec4<f32>,
    // Slicing scheme (0 linear, 1 logarithmic, 2 logarithmic with a near slice), light
    // count, capacity of the index list, words of one tile mask (assignment).
    scheme_lights_capacity: vec4<u32>,
    // Assignment's tile masks: walk groups (of 8 slices) sharing a mask, masks per tile.
    mask_layout: vec4<u32>,
    // x: how spot lights are culled (`SPOT_CULLING_CONE` in bounds.wgsl, or 0: by their
    // range sphere, as point lights); y: bands of rows per tile in the visible-bounds pass.
    culling_and_bands: vec4<u32>,
}

const Z_SCHEME_LINEAR: u32 = #Z_SCHEME_LINEAR;
const Z_SCHEME_LOGARITHMIC: u32 = #Z_SCHEME_LOGARITHMIC;
const Z_SCHEME_LOG_NEAR_SLICE: u32 = #Z_SCHEME_LOG_NEAR_SLICE;

// The depth slice of a view depth (positive distance), clamped to the grid.
fn cluster_slice(grid: ClusterParams, depth: f32) -> u32 {
    let near = grid.z_params.x;
    let scale = grid.z_params.w;
    var slice: f32;
    switch grid.scheme_lights_capacity.x {
        case Z_SCHEME_LINEAR: {
            slice = (depth - near) * scale;
        }
        case Z_SCHEME_LOG_NEAR_SLICE: {
            let first_far = grid.z_params.z;
            slice = select(1.0 + log(depth / first_far) * scale, 0.0, depth < first_far);
        }
        default: {
            slice = log(depth / near) * scale;
        }
    }
    // Depths at or behind the eye give NaN or -inf: slice 0. (max returns the non-NaN
    // operand on every backend we target; the select makes it explicit.)
    slice = select(slice, 0.0, !(slice > 0.0));
    return min(u32(slice), grid.dims.z - 1u);
}

// The flat index (x fastest, then y, then slice) of the cluster holding a fragment at
// pixel position `frag_xy` (pixel centres at .5) and view depth `depth`.
fn cluster_index(grid: ClusterParams, frag_xy: vec2<f32>, depth: f32) -> u32 {
    let tile = min(vec2<u32>(frag_xy / grid.tile_and_screen.xy), grid.dims.xy - vec2<u32>(1u));
    let slice = cluster_slice(grid, depth);
    return (slice * grid.dims.y + tile.y) * grid.dims.x + tile.x;
}
