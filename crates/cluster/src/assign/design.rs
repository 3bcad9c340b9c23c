//! What decides a frame's clustering, as values: the assignment's design and boxes, the
//! [`ClusterFrame`] a frame is prepared with, and what a `prepare` rebuilt ([`Rebuilt`]).

use super::SORTED_LIST_LIMIT;
use crate::assign_reference::SpotCulling;
use crate::far_field::FarField;
use crate::grid::ClusterGrid;

/// How the GPU builds the lists. Both give the same set per cluster as the CPU reference
/// ([`crate::assign_lights`]); they differ in order and speed (docs/results/nvidia-h200/
/// assignment measures them side by side).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum AssignmentDesign {
    /// Each light (16 lanes sharing its candidate clusters) counts the clusters it meets and
    /// marks their tiles in a per-tile bit mask; after the prefix sum, one workgroup per tile
    /// and group of 8 slices walks the tile's mask in light order, tests each marked light
    /// against those clusters' boxes and writes the hits by an ordered compaction: every
    /// list in ascending light order with no sort and no atomics on the lists. Memory: one
    /// bit per light and tile.
    #[default]
    TileMasks,
    /// The first design: each light counts and then writes itself into its clusters with
    /// atomics, and one thread per cluster insertion-sorts lists up to
    /// [`SORTED_LIST_LIMIT`].
    AtomicFill,
}

impl AssignmentDesign {
    pub const ALL: [AssignmentDesign; 2] =
        [AssignmentDesign::TileMasks, AssignmentDesign::AtomicFill];

    pub fn name(self) -> &'static str {
        match self {
            AssignmentDesign::TileMasks => "tile-masks",
            AssignmentDesign::AtomicFill => "atomic-fill",
        }
    }

    /// Lists up to this long are in ascending light order.
    pub fn sorted_list_limit(self) -> usize {
        match self {
            AssignmentDesign::TileMasks => usize::MAX,
            AssignmentDesign::AtomicFill => SORTED_LIST_LIMIT,
        }
    }
}

manylights_gpu::named_choice!(AssignmentDesign, "assignment design");

/// Which box each cluster's lights are tested against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum ClusterBoxes {
    /// The bounding box of the cluster's visible samples, from the frame's depth, when the
    /// pipeline lays depth down before assignment (deferred, Forward+ with its pre-pass);
    /// empty where no sample falls, so those clusters list nothing. Otherwise the grid's.
    #[default]
    VisibleSamples,
    /// The bounding box of the cluster's whole frustum slab
    /// ([`ClusterGrid::cluster_bounds`]), every cluster listed whether or not anything is
    /// seen in it (the first design; kept to measure against).
    Grid,
}

impl ClusterBoxes {
    pub const ALL: [ClusterBoxes; 2] = [ClusterBoxes::VisibleSamples, ClusterBoxes::Grid];

    pub fn name(self) -> &'static str {
        match self {
            ClusterBoxes::VisibleSamples => "visible",
            ClusterBoxes::Grid => "grid",
        }
    }
}

manylights_gpu::named_choice!(ClusterBoxes, "cluster box");

/// Everything that decides one frame's clustering: what [`GpuClusters::prepare`](crate::GpuClusters::prepare) is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterFrame {
    /// Tiles, slices and their view-space boxes.
    pub grid: ClusterGrid,
    /// How the GPU builds the lists (the same lists either way).
    pub design: AssignmentDesign,
    /// The boxes lights are tested against.
    pub boxes: ClusterBoxes,
    /// What lights add beyond their radius (`None`: they end at it).
    pub far_field: Option<FarField>,
    /// Spot lights culled by their cone or by their range sphere.
    pub spot_culling: SpotCulling,
}

impl ClusterFrame {
    /// A frame on `grid` with the default design, boxes and spot culling, no far field.
    pub fn new(grid: ClusterGrid) -> Self {
        Self {
            grid,
            design: AssignmentDesign::default(),
            boxes: ClusterBoxes::default(),
            far_field: None,
            spot_culling: SpotCulling::default(),
        }
    }
}

/// What a [`GpuClusters::prepare`](crate::GpuClusters::prepare) rebuilt (all false: the frame was prepared as the last).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Rebuilt {
    /// The assignment's buffers (a new grid size, more lights, a grown index list, another
    /// design or mask budget).
    pub buffers: bool,
    /// The grid's boxes and tile slice ranges (a new grid).
    pub grid_boxes: bool,
    /// The parameters uniform.
    pub params: bool,
    /// The assignment's and the far field's bind groups (new buffers, lights or depth).
    pub bind_groups: bool,
}
