//! Recording a prepared frame's assignment: [`PreparedAssignment`], resolved by
//! [`GpuClusters::assignment`] when the frame was prepared, records the passes without
//! failing or building anything and returns the proof the shading takes ([`ListsBuilt`]).

use manylights_gpu::binding::EntryPointPipelines;
use manylights_gpu::{GpuResult, GpuTimer, PassName, ViewBinding, wgpu};

use super::{
    AssignEntry, AssignmentDesign, BindGroups, Buffers, GpuClusters, PreparedFrame,
    SLICES_PER_WALK, WORKGROUP_SIZE, mark_tiles_dispatch,
};
use crate::far_field::PreparedFarField;
use crate::passes;

/// Records the assignment's steps: each a timed compute pass of one dispatch, with the view
/// and the frame's assignment bind group bound.
struct Steps<'a, 'e> {
    encoder: &'e mut wgpu::CommandEncoder,
    timer: Option<&'e mut GpuTimer>,
    view: &'a ViewBinding,
    pipelines: &'a EntryPointPipelines<6>,
    groups: &'a [wgpu::BindGroup; 6],
}

impl Steps<'_, '_> {
    fn run(&mut self, name: PassName, entry: AssignEntry, workgroups: [u32; 3]) {
        let mut pass = crate::view_pass(self.encoder, self.view, self.timer.as_deref_mut(), name);
        pass.set_bind_group(1, &self.groups[entry as usize], &[]);
        pass.set_pipeline(self.pipelines.pipeline(entry as usize));
        let [x, y, z] = workgroups;
        pass.dispatch_workgroups(x, y, z);
    }
}

/// Proof that a frame's light lists were built: what a clustered pipeline's shading takes,
/// so shading from lists not yet assigned does not compile.
#[derive(Debug)]
#[must_use = "the shading that reads the lists takes this proof"]
pub struct ListsBuilt(());

/// One prepared frame of [`GpuClusters`]: its passes with what they bind, recorded without
/// failing or creating anything ([`GpuClusters::assignment`]).
pub struct PreparedAssignment<'a> {
    clusters: &'a GpuClusters,
    frame: &'a PreparedFrame,
    buffers: &'a Buffers,
    groups: &'a BindGroups,
    far_field: PreparedFarField<'a>,
}

impl std::fmt::Debug for PreparedAssignment<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedAssignment")
            .field("lights", &self.frame.light_count)
            .field("design", &self.buffers.design)
            .finish_non_exhaustive()
    }
}

impl PreparedAssignment<'_> {
    /// Records the frame's passes (the frame's view must be uploaded, and its depth, if
    /// given to `prepare`, drawn), each timed by `timer` when given.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        mut timer: Option<&mut GpuTimer>,
    ) -> ListsBuilt {
        let (clusters, prepared, buffers, groups) =
            (self.clusters, self.frame, self.buffers, self.groups);
        let grid = &prepared.frame.grid;
        // 1. The far field's light tree or random ranges come first: stochastic culling
        //    assigns the lights with their random ranges.
        self.far_field
            .record_lights(encoder, view, timer.as_deref_mut());
        encoder.clear_buffer(&buffers.counts, 0, None);
        // 2. The visible samples' boxes.
        if let Some(visible) = &groups.visible {
            encoder.clear_buffer(&buffers.visible_box_codes, 0, None);
            clusters
                .visible_bounds
                .record(encoder, view, visible, grid, timer.as_deref_mut());
        }
        // 3. The lists.
        if buffers.design == AssignmentDesign::TileMasks {
            encoder.clear_buffer(&buffers.tile_masks, 0, None);
            encoder.clear_buffer(&buffers.window_marks, 0, None);
        }
        let mut steps = Steps {
            encoder,
            timer: timer.as_deref_mut(),
            view,
            pipelines: &clusters.assignment.pipelines,
            groups: &groups.assign,
        };
        match buffers.design {
            AssignmentDesign::TileMasks => clusters.record_tile_masks(&mut steps, prepared),
            AssignmentDesign::AtomicFill => {
                clusters.record_atomic_fill(&mut steps, prepared, buffers.clusters)
            }
        }
        // 4. The far field's cuts of the tree, in the boxes just tested.
        self.far_field.record_cuts(encoder, view, timer);
        // 5. The list total, for a later frame to grow the index list by.
        if let Some(slot) = clusters.total_slot {
            let total_at = u64::from(buffers.clusters) * 4;
            clusters
                .total_readback
                .record_reserved_copy(encoder, &buffers.offsets, total_at, slot);
        }
        ListsBuilt(())
    }
}

impl GpuClusters {
    /// The prepared frame's passes, ready to record: what they bind was resolved when the
    /// frame was prepared, so recording them cannot fail. The error is a frame recorded
    /// before any `prepare`.
    pub fn assignment(&self) -> GpuResult<PreparedAssignment<'_>> {
        let (frame, buffers, groups) = self.prepared()?;
        Ok(PreparedAssignment {
            clusters: self,
            frame,
            buffers,
            groups,
            far_field: self.far_field.prepared()?,
        })
    }

    /// The tile-mask design: each light marks the tiles it meets, the offsets follow from
    /// the counts, and one workgroup per tile and group of slices walks its mask in light
    /// order (each far below the 65,535 workgroups a dispatch dimension allows).
    fn record_tile_masks(&self, steps: &mut Steps, prepared: &PreparedFrame) {
        let grid = &prepared.frame.grid;
        let lights = prepared.light_count;
        if lights > 0 {
            let groups = mark_tiles_dispatch(lights);
            steps.run(passes::MARK_TILES, AssignEntry::MarkTiles, groups);
        }
        steps.run(passes::LIST_OFFSETS, AssignEntry::Prefix, [1, 1, 1]);
        if lights > 0 {
            let walks = [
                grid.dims.x,
                grid.dims.y,
                grid.dims.z.div_ceil(SLICES_PER_WALK),
            ];
            steps.run(passes::FILL_LISTS, AssignEntry::FillWalk, walks);
        }
    }

    /// The first design: each light counts its clusters, the offsets follow, each light
    /// writes itself into its clusters with atomics, and one thread per cluster sorts
    /// lists up to [`SORTED_LIST_LIMIT`].
    fn record_atomic_fill(&self, steps: &mut Steps, prepared: &PreparedFrame, clusters: u32) {
        let light_groups = prepared.light_count.div_ceil(WORKGROUP_SIZE);
        let per_light = [light_groups, 1, 1];
        if light_groups > 0 {
            steps.run(passes::COUNT_LISTS, AssignEntry::Count, per_light);
        }
        steps.run(passes::LIST_OFFSETS, AssignEntry::Prefix, [1, 1, 1]);
        if light_groups > 0 {
            let per_cluster = [clusters.div_ceil(WORKGROUP_SIZE), 1, 1];
            steps.run(passes::FILL_LISTS, AssignEntry::Fill, per_light);
            steps.run(passes::SORT_LISTS, AssignEntry::Sort, per_cluster);
        }
    }
}
