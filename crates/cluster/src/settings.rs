//! [`ClusteringSettings`]: what a clustered pipeline builds its light lists with. A
//! pipeline that clusters holds one in its own settings, so a frame without clusters
//! (naive) cannot be given a grid or a far field it would ignore.

use crate::{
    AssignmentDesign, ClusterBoxes, ClusterFrame, ClusterGrid, ClusterSettings, FarField,
    SpotCulling,
};

/// The dials of a clustered pipeline's light lists (Forward+'s and deferred's).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct ClusteringSettings {
    /// Tiles and depth slices.
    pub grid: ClusterSettings,
    /// How the GPU builds the lists (the same lists either way; tile masks sort them all
    /// and are faster).
    pub assignment: AssignmentDesign,
    /// The boxes lights are tested against: the visible samples' (when the pipeline lays
    /// depth down first), or the grid's.
    pub boxes: ClusterBoxes,
    /// Spot lights culled by their cone (default) or by their range sphere (to measure
    /// what the cone test saves).
    pub spot_culling: SpotCulling,
    /// What lights add beyond their radius, approximated (the image then approaches the
    /// unbounded inverse-square one). `None`: lights end at their radius.
    pub far_field: Option<FarField>,
    /// Statistics of the lists on the GPU (a small compute pass, read back without
    /// stalling, so they may describe an earlier frame).
    pub stats: bool,
    /// With `stats`: also the false-positive ratio (a pass over the depth buffer that
    /// tests every listed light against its cluster's visible pixels).
    pub false_positives: bool,
}

impl ClusteringSettings {
    /// The frame's clustering on `grid` (the grid is laid out from these settings' `grid`
    /// and the frame's view).
    pub fn frame(&self, grid: ClusterGrid) -> ClusterFrame {
        ClusterFrame {
            grid,
            design: self.assignment,
            boxes: self.boxes,
            far_field: self.far_field,
            spot_culling: self.spot_culling,
        }
    }
}
