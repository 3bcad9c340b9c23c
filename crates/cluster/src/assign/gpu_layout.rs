//! The assignment's GPU data as the shaders read it: the parameters uniform, the tile
//! masks' layout, the clusters' boxes and the lights' view-space volumes, with what writes
//! the grid's boxes and tile slice ranges.

use manylights_gpu::{GpuContext, wgpu};
use manylights_scene::Aabb;

use super::{SLICES_PER_WALK, WALK_WINDOW_WORDS};
use crate::assign_reference::SpotCulling;
use crate::grid::{ClusterGrid, ZScheme};
use crate::visible_bounds::{SLICES_PER_GROUP, tile_slice_groups};

/// Mirrors `ClusterParams` in `shaders/cluster/cluster_index.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ClusterParamsUniform {
    pub dims: [u32; 4],
    pub tile_and_screen: [f32; 4],
    pub z_params: [f32; 4],
    pub scheme_lights_capacity: [u32; 4],
    /// Tile-mask design: walk groups (of 8 slices) sharing one mask, masks per tile.
    pub mask_layout: [u32; 4],
    /// x: [`SpotCulling::shader_value`]; y: the visible-bounds pass's bands per tile
    /// (`visible_bounds::bands_per_tile`).
    pub culling_and_bands: [u32; 4],
}

/// How the tile-mask design lays out its masks: one bit per light in each mask, a mask per
/// tile and group of [`MaskLayout::walk_groups_per_mask`] walk groups (8 slices each), so
/// that each walk reads only the lights that meet its own slices. Groups share a mask when
/// one per group would pass the memory budget ([`TILE_MASK_BUDGET_BYTES`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MaskLayout {
    /// Words (of 32 lights) in one mask.
    pub words: u32,
    pub walk_groups_per_mask: u32,
    pub masks_per_tile: u32,
    /// Words of window marks per mask: one bit per window of 256 words (8,192 lights) that
    /// holds a marked light, so the walk skips empty windows.
    pub window_mark_words: u32,
}

/// The most the tile masks may take (a mask per tile and walk group takes 108 MiB at
/// 1,000,000 lights on the default 16x9x48 grid; groups then share masks).
pub const TILE_MASK_BUDGET_BYTES: u64 = 64 << 20;

impl MaskLayout {
    /// The finest layout for `lights` on `grid` within `budget` bytes (at worst one mask
    /// per tile, whatever the budget).
    pub fn for_grid(grid: &ClusterGrid, lights: u32, budget: u64) -> Self {
        let words = lights.div_ceil(32);
        let tiles = u64::from(grid.dims.x) * u64::from(grid.dims.y);
        let walk_groups = grid.dims.z.div_ceil(SLICES_PER_WALK);
        let mut walk_groups_per_mask = 1;
        while walk_groups_per_mask < walk_groups
            && tiles * u64::from(walk_groups.div_ceil(walk_groups_per_mask)) * u64::from(words) * 4
                > budget
        {
            walk_groups_per_mask += 1;
        }
        Self {
            words,
            walk_groups_per_mask,
            masks_per_tile: walk_groups.div_ceil(walk_groups_per_mask),
            window_mark_words: words.div_ceil(WALK_WINDOW_WORDS * 32),
        }
    }

    /// Bytes of the window marks.
    pub fn window_mark_bytes(&self, grid: &ClusterGrid) -> u64 {
        u64::from(grid.dims.x)
            * u64::from(grid.dims.y)
            * u64::from(self.masks_per_tile)
            * u64::from(self.window_mark_words)
            * 4
    }

    pub fn bytes(&self, grid: &ClusterGrid) -> u64 {
        u64::from(grid.dims.x)
            * u64::from(grid.dims.y)
            * u64::from(self.masks_per_tile)
            * u64::from(self.words)
            * 4
    }
}

impl ClusterParamsUniform {
    /// `masks`: the tile masks' layout (tile-mask design; zero for the atomic fill).
    pub fn new(
        grid: &ClusterGrid,
        light_count: u32,
        capacity: u32,
        masks: MaskLayout,
        spot_culling: SpotCulling,
    ) -> Self {
        let slices = grid.dims.z as f32;
        let scheme = grid.scheme.shader_code();
        let (first_far, scale) = match grid.scheme {
            ZScheme::Linear => (0.0, slices / (grid.z_far - grid.z_near)),
            ZScheme::Logarithmic => (0.0, slices / (grid.z_far / grid.z_near).ln()),
            ZScheme::LogarithmicWithNearSlice { first_slice_far } => (
                first_slice_far,
                (slices - 1.0) / (grid.z_far / first_slice_far).ln(),
            ),
        };
        Self {
            dims: [grid.dims.x, grid.dims.y, grid.dims.z, grid.cluster_count()],
            tile_and_screen: [
                grid.tile_size.0,
                grid.tile_size.1,
                grid.screen.0 as f32,
                grid.screen.1 as f32,
            ],
            z_params: [grid.z_near, grid.z_far, first_far, scale],
            scheme_lights_capacity: [scheme, light_count, capacity, masks.words],
            mask_layout: [
                masks.walk_groups_per_mask,
                masks.masks_per_tile,
                masks.window_mark_words,
                0,
            ],
            culling_and_bands: [
                spot_culling.shader_value(),
                crate::visible_bounds::bands_per_tile(grid),
                0,
                0,
            ],
        }
    }
}

/// Writes the grid's tile slice ranges: every slice of every group (first | last << 16).
pub(super) fn upload_tile_slices(context: &GpuContext, buffer: &wgpu::Buffer, grid: &ClusterGrid) {
    let groups = tile_slice_groups(grid);
    let ranges: Vec<u32> = (0..grid.dims.x * grid.dims.y)
        .flat_map(|_| {
            (0..groups).map(|group| {
                let first = group * SLICES_PER_GROUP;
                let last = (first + SLICES_PER_GROUP - 1).min(grid.dims.z - 1);
                first | (last << 16)
            })
        })
        .collect();
    context
        .queue
        .write_buffer(buffer, 0, bytemuck::cast_slice(&ranges));
}

/// Mirrors `ClusterBounds` in `shaders/cluster/bounds.wgsl`: a cluster's view-space box,
/// `min.w` 1 where it holds something and 0 where it is empty (no visible sample).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuClusterBounds {
    pub(super) min: [f32; 4],
    pub(super) max: [f32; 4],
}

impl GpuClusterBounds {
    pub(super) fn holding(bounds: &Aabb) -> Self {
        Self {
            min: bounds.min.extend(1.0).to_array(),
            max: bounds.max.extend(0.0).to_array(),
        }
    }

    /// The box, or [`Aabb::EMPTY`] where the cluster holds nothing.
    pub(super) fn aabb(&self) -> Aabb {
        if self.min[3] == 0.0 {
            Aabb::EMPTY
        } else {
            Aabb::new(
                glam::Vec3::from_slice(&self.min[..3]),
                glam::Vec3::from_slice(&self.max[..3]),
            )
        }
    }
}

/// Bytes of one `ClusterBounds`.
pub(super) const BOUNDS_BYTES: u64 = std::mem::size_of::<GpuClusterBounds>() as u64;

/// Mirrors `ViewLight` in `shaders/cluster/bounds.wgsl`: a light's view-space sphere
/// (centre, radius) and its spot cone.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuViewLight {
    pub(super) sphere: [f32; 4],
    pub(super) cone: [f32; 4],
}

/// Writes the view-space bounds of every cluster of `grid` (`ClusterGrid::cluster_bounds`),
/// each flagged as holding something.
pub(super) fn upload_bounds(context: &GpuContext, buffer: &wgpu::Buffer, grid: &ClusterGrid) {
    let bounds: Vec<GpuClusterBounds> = grid
        .cluster_bounds()
        .iter()
        .map(GpuClusterBounds::holding)
        .collect();
    context
        .queue
        .write_buffer(buffer, 0, bytemuck::cast_slice(&bounds));
}

/// Bytes of one `ViewLight` (`bounds.wgsl`): the view-space sphere and the spot cone.
pub(super) const VIEW_LIGHT_BYTES: u64 = std::mem::size_of::<GpuViewLight>() as u64;

#[cfg(test)]
mod layout_tests {
    use super::{ClusterParamsUniform, GpuClusterBounds, GpuViewLight};
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn cluster_bounds_and_view_lights_match_wgsl() {
        assert_wgsl_layout!(
            crate::assign_program(),
            "cluster/bounds.wgsl",
            ClusterBounds == GpuClusterBounds { min: min, max: max }
        );
        assert_wgsl_layout!(
            crate::assign_program(),
            "cluster/bounds.wgsl",
            ViewLight
                == GpuViewLight {
                    sphere: sphere,
                    cone: cone
                }
        );
    }

    #[test]
    fn cluster_params_match_wgsl() {
        assert_wgsl_layout!(
            crate::assign_program(),
            "cluster/cluster_index.wgsl",
            ClusterParams
                == ClusterParamsUniform {
                    dims: dims,
                    tile_and_screen: tile_and_screen,
                    z_params: z_params,
                    scheme_lights_capacity: scheme_lights_capacity,
                    mask_layout: mask_layout,
                    culling_and_bands: culling_and_bands,
                }
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ClusterSettings, TileSpec, ZRange};

    fn grid(slices: u32) -> ClusterGrid {
        let settings = ClusterSettings {
            tiles: TileSpec::Count { x: 16, y: 9 },
            z_slices: slices,
            z_scheme: ZScheme::Logarithmic,
            z_range: ZRange::Camera,
        };
        let projection = glam::camera::rh::proj::directx::perspective(1.0, 16.0 / 9.0, 0.1, 100.0);
        ClusterGrid::new(&settings, (1920, 1080), projection, 0.1, 100.0, None).expect("grid")
    }

    #[test]
    fn masks_are_per_walk_group_until_the_budget_makes_groups_share() {
        let grid = grid(48);
        // 5,000 lights: 157 words, 6 groups, 144 tiles: 0.5 MiB, one mask per group.
        let fine = MaskLayout::for_grid(&grid, 5_000, TILE_MASK_BUDGET_BYTES);
        assert_eq!(
            (fine.words, fine.walk_groups_per_mask, fine.masks_per_tile),
            (157, 1, 6)
        );
        assert_eq!(fine.window_mark_words, 1);
        assert_eq!(fine.bytes(&grid), 144 * 6 * 157 * 4);
        // 1,000,000 lights: 108 MiB per group would pass 64 MiB; pairs of groups share.
        let paired = MaskLayout::for_grid(&grid, 1_000_000, TILE_MASK_BUDGET_BYTES);
        assert_eq!((paired.walk_groups_per_mask, paired.masks_per_tile), (2, 3));
        assert!(paired.bytes(&grid) <= TILE_MASK_BUDGET_BYTES);
        // No budget at all still leaves one mask per tile.
        let coarsest = MaskLayout::for_grid(&grid, 1_000_000, 0);
        assert_eq!(
            (coarsest.walk_groups_per_mask, coarsest.masks_per_tile),
            (6, 1)
        );
    }
}
