//! Clustered light assignment for manylights, usable in other engines on its own:
//! [`ClusterGrid`] (tiles x depth slices, three slicing schemes, depth range from the
//! camera or fitted to the scene), the view-space bounds of every cluster, the
//! fragment-to-cluster index, a CPU reference assignment ([`assign_lights`]), exact GPU
//! light lists ([`GpuClusters`]: in ascending light order, no cap, nothing dropped), and
//! per-frame statistics (on the GPU without stalling: [`GpuListStatistics`]).

mod assign;
mod gpu;
mod gpu_stats;
mod grid;
mod shading;
mod stats;

pub use assign::{
    LightLists, ViewSphere, assign_lights, candidate_range, compare_with_reference,
    sphere_box_margin, sphere_intersects_box, view_spheres,
};
pub use gpu::{
    AssignmentDesign, ClusterParamsUniform, GpuClusters, INITIAL_INDEX_CAPACITY, SORTED_LIST_LIMIT,
};
pub use gpu_stats::GpuListStatistics;
pub use grid::{
    ClusterGrid, ClusterSettings, DEPTH_BOUNDS_INFLATION, GridError, MAX_CLUSTERS, TileSpec,
    ZRange, ZScheme,
};
pub use shading::ClusteredShading;
pub use stats::{ClusterStats, false_positive_ratio};
