//! The boxes of each cluster's visible samples (`shaders/cluster/visible_bounds.wgsl`),
//! bounded from the frame's depth before its lights are assigned, so that a cluster where
//! nothing is seen lists nothing. Two compute passes, timed as `assign: <step>`: each band of
//! a tile's rows bounds its samples slice by slice, then each tile and group of slices
//! combines its bands into the clusters' boxes and the tile's occupied slice ranges.

use manylights_gpu::{
    GpuContext, GpuResult, GpuTimer, MaterialVariant, ShaderLibrary, ViewBinding, wgpu,
};

use crate::grid::ClusterGrid;

/// Slices one workgroup of the visible-bounds pass handles, and the slices one entry of a
/// tile's slice ranges covers (`SLICES_PER_GROUP` in `visible_bounds.wgsl`,
/// `TILE_SLICE_GROUP` in `assign.wgsl`).
pub(crate) const SLICES_PER_GROUP: u32 = 64;

/// The most bands of rows a tile's samples are bounded in, by a workgroup each.
pub(crate) const MAX_BANDS_PER_TILE: u32 = 8;

/// Pixels one step of a band's workgroup loads (256 threads, 4 loads each,
/// `visible_bounds.wgsl`): a band with fewer leaves threads idle.
const PIXELS_PER_BAND_STEP: f32 = 1024.0;

/// Bands per tile (`ClusterParams.culling_and_bands.y`): 8 where tiles are large (1080p on
/// the default 16x9 tiles: 122x122 pixels read per tile), fewer where a band would not
/// fill one step of its workgroup. The samples' boxes do not depend on the bands (they
/// combine by minimum and maximum); the cost does, and on a CPU driver (lavapipe) each
/// workgroup costs about as much whether it has pixels or not: at 48x32 pixels the 1,152
/// workgroups of eight bands took 45 ms, most of a test frame.
pub(crate) fn bands_per_tile(grid: &ClusterGrid) -> u32 {
    // The rectangle a tile reads: one pixel wider on each side.
    let read = (grid.tile_size.0.ceil() + 2.0) * (grid.tile_size.1.ceil() + 2.0);
    ((read / PIXELS_PER_BAND_STEP).ceil() as u32).clamp(1, MAX_BANDS_PER_TILE)
}

/// Entries per tile of the tile slice ranges: one per group of [`SLICES_PER_GROUP`] slices.
pub(crate) fn tile_slice_groups(grid: &ClusterGrid) -> u32 {
    grid.dims.z.div_ceil(SLICES_PER_GROUP)
}

/// What the two passes write: the clusters' boxes, each tile's occupied slice ranges, and
/// the order-preserving codes the bands combine through.
pub(crate) struct VisibleBoundsTargets<'a> {
    pub params: &'a wgpu::Buffer,
    pub boxes: &'a wgpu::Buffer,
    pub tile_slices: &'a wgpu::Buffer,
    pub box_codes: &'a wgpu::Buffer,
    /// Read: the grid's boxes and the blended objects' view-space boxes, which the
    /// clusters' boxes are grown by.
    pub grid_bounds: &'a wgpu::Buffer,
    pub blended: &'a wgpu::Buffer,
}

/// The depth a frame's visible samples are bounded from: the frame's depth view, its
/// samples a pixel (more than one under MSAA, whose every sample is read) and its size in
/// pixels, which must be the grid's screen. Any depth format a shader can read as
/// `texture_depth_2d` serves (`Depth32Float`, `Depth24Plus`, `Depth16Unorm`, or a view of
/// the depth aspect of a depth-stencil texture), in either depth convention: the view's
/// uniform says which (its empty depth, `ViewUniform::near_far[2]`).
#[derive(Debug, Clone, Copy)]
pub struct VisibleDepth<'a> {
    pub view: &'a wgpu::TextureView,
    pub samples: u32,
    pub size: (u32, u32),
}

impl<'a> VisibleDepth<'a> {
    /// An engine's depth texture and a view of it (of its depth aspect, one mip level):
    /// the samples and the size are the texture's.
    pub fn of(texture: &wgpu::Texture, view: &'a wgpu::TextureView) -> Self {
        Self {
            view,
            samples: texture.sample_count(),
            size: (texture.width(), texture.height()),
        }
    }

    /// Refuses depth of another size than the grid's screen: its pixels would be read as
    /// other pixels' clusters.
    pub(crate) fn check_against(&self, grid: &ClusterGrid) -> GpuResult<()> {
        if self.size != grid.screen {
            return Err(manylights_gpu::GpuError::InvalidInput {
                what: "depth texture".into(),
                problem: format!(
                    "it is {}x{}, the cluster grid's screen {}x{}: give the depth of the \
                     frame the grid was made for",
                    self.size.0, self.size.1, grid.screen.0, grid.screen.1
                ),
            });
        }
        Ok(())
    }
}

/// The visible-bounds pipelines: for single-sampled depth, and (made on the first MSAA
/// frame) for multisampled depth.
#[derive(Debug)]
pub(crate) struct VisibleBoundsPasses {
    single: BoundsPasses,
    multisampled: Option<BoundsPasses>,
    library: ShaderLibrary,
    view_layout: wgpu::BindGroupLayout,
}

/// One depth kind's pipelines.
#[derive(Debug)]
struct BoundsPasses {
    layout: wgpu::BindGroupLayout,
    bound_samples: wgpu::ComputePipeline,
    finish_boxes: wgpu::ComputePipeline,
}

/// A prepared frame's visible-bounds group, and whether its depth is multisampled.
#[derive(Debug)]
pub(crate) struct VisibleBoundsGroup {
    group: wgpu::BindGroup,
    multisampled: bool,
}

impl VisibleBoundsPasses {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        Ok(Self {
            single: BoundsPasses::new(context, library, &view.layout, false)?,
            multisampled: None,
            library: library.clone(),
            view_layout: view.layout.clone(),
        })
    }

    /// Makes the multisampled depth's pipelines if `depth` needs them and they are not made.
    pub fn prepare(&mut self, context: &GpuContext, depth: VisibleDepth) -> GpuResult<()> {
        if depth.samples > 1 && self.multisampled.is_none() {
            let passes = BoundsPasses::new(context, &self.library, &self.view_layout, true)?;
            self.multisampled = Some(passes);
        }
        Ok(())
    }

    fn passes(&self, multisampled: bool) -> &BoundsPasses {
        match (multisampled, &self.multisampled) {
            (true, Some(passes)) => passes,
            _ => &self.single,
        }
    }

    /// The passes' bind group: they read `depth` (its view and samples a pixel) and write
    /// `targets` (after [`VisibleBoundsPasses::prepare`] with the same depth).
    pub fn bind_group(
        &self,
        context: &GpuContext,
        depth: &wgpu::TextureView,
        samples: u32,
        targets: VisibleBoundsTargets,
    ) -> VisibleBoundsGroup {
        let multisampled = samples > 1;
        VisibleBoundsGroup {
            group: self
                .passes(multisampled)
                .bind_group(context, depth, targets),
            multisampled,
        }
    }

    /// Records both passes (the box codes must be cleared first).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        group: &VisibleBoundsGroup,
        grid: &ClusterGrid,
        timer: Option<&mut GpuTimer>,
    ) {
        self.passes(group.multisampled)
            .record(encoder, view, &group.group, grid, timer);
    }
}

impl BoundsPasses {
    fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view_layout: &wgpu::BindGroupLayout,
        multisampled: bool,
    ) -> GpuResult<Self> {
        use manylights_gpu::binding::{storage_entry, uniform_entry};
        let program = if multisampled {
            crate::multisampled_visible_bounds_program()
        } else {
            crate::visible_bounds_program()
        };
        let module = library.create_module(context, &program, MaterialVariant::default())?;
        let compute = wgpu::ShaderStages::COMPUTE;
        let depth_entry = wgpu::BindGroupLayoutEntry {
            binding: 2,
            visibility: compute,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled,
            },
            count: None,
        };
        let manylights_gpu::binding::ComputePasses {
            layout,
            pipelines: [bound_samples, finish_boxes],
        } = manylights_gpu::binding::ComputePasses::new(
            context,
            &module,
            "visible cluster bounds",
            &[view_layout],
            &[
                uniform_entry(0, compute),
                storage_entry(1, compute, false),
                depth_entry,
                storage_entry(3, compute, false),
                storage_entry(4, compute, false),
                storage_entry(5, compute, true),
                storage_entry(6, compute, true),
            ],
            ["bound_visible_samples", "finish_visible_bounds"],
        )?;
        Ok(Self {
            layout,
            bound_samples,
            finish_boxes,
        })
    }

    fn bind_group(
        &self,
        context: &GpuContext,
        depth: &wgpu::TextureView,
        targets: VisibleBoundsTargets,
    ) -> wgpu::BindGroup {
        manylights_gpu::binding::bind_group(
            context,
            "visible cluster bounds",
            &self.layout,
            [
                (0, targets.params.as_entire_binding()),
                (1, targets.boxes.as_entire_binding()),
                (2, wgpu::BindingResource::TextureView(depth)),
                (3, targets.tile_slices.as_entire_binding()),
                (4, targets.box_codes.as_entire_binding()),
                (5, targets.grid_bounds.as_entire_binding()),
                (6, targets.blended.as_entire_binding()),
            ],
        )
    }

    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        group: &wgpu::BindGroup,
        grid: &ClusterGrid,
        mut timer: Option<&mut GpuTimer>,
    ) {
        // One workgroup per band of a tile and group of slices, then one per tile and group
        // of slices writes every cluster's box.
        let (tiles, slice_groups) = (grid.dims, tile_slice_groups(grid));
        let steps = [
            (
                crate::passes::BOUND_VISIBLE_SAMPLES,
                &self.bound_samples,
                [tiles.x, tiles.y * bands_per_tile(grid), slice_groups],
            ),
            (
                crate::passes::FINISH_VISIBLE_BOXES,
                &self.finish_boxes,
                [tiles.x, tiles.y, slice_groups],
            ),
        ];
        for (name, pipeline, [x, y, z]) in steps {
            let mut pass = crate::view_pass(encoder, view, timer.as_deref_mut(), name);
            pass.set_bind_group(1, group, &[]);
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(x, y, z);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::ClusterSettings;

    fn grid(screen: (u32, u32)) -> ClusterGrid {
        let aspect = screen.0 as f32 / screen.1 as f32;
        let projection = glam::camera::rh::proj::directx::perspective(1.0, aspect, 0.1, 100.0);
        ClusterGrid::new(
            &ClusterSettings::default(),
            screen,
            projection,
            0.1,
            100.0,
            None,
        )
        .expect("grid")
    }

    /// Eight bands where tiles are large (the measured layout at 1080p stays), one where a
    /// tile has a few pixels (test frames on a CPU driver), and in between as many as fill
    /// a workgroup's step.
    #[test]
    fn bands_follow_the_tiles_pixels() {
        assert_eq!(bands_per_tile(&grid((1920, 1080))), MAX_BANDS_PER_TILE);
        assert_eq!(bands_per_tile(&grid((1280, 720))), 7);
        assert_eq!(bands_per_tile(&grid((48, 32))), 1);
        assert_eq!(bands_per_tile(&grid((1, 1))), 1);
    }
}
