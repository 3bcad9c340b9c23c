//! Recording a prepared frame's far field: [`PreparedFarField`], resolved from what
//! `prepare` built ([`GpuFarField::prepared`]), records the light tree's build or the
//! random ranges before the assignment and the tree's cuts after it, without failing.

use manylights_gpu::{GpuResult, GpuTimer, ViewBinding, wgpu};

use super::{
    CUT_ROW_WORKGROUPS, FarBindGroups, FarFieldPasses, GpuFarField, SORT_BLOCK, TreeBuffers,
    level_firsts, not_prepared,
};

impl GpuFarField {
    /// The prepared frame's far-field passes, ready to record (nothing to record without a
    /// far field), or the error of a frame recorded before any `prepare`.
    pub(crate) fn prepared(&self) -> GpuResult<PreparedFarField<'_>> {
        let work = match (self.prepared_groups()?, &self.tree) {
            (FarBindGroups::None, _) => FarWork::None,
            (FarBindGroups::Stochastic(group), _) => FarWork::Stochastic(group),
            (
                FarBindGroups::Tree {
                    keys,
                    sort_passes,
                    leaves,
                    levels,
                    cuts,
                },
                Some(tree),
            ) => FarWork::Tree {
                keys,
                sort_passes,
                leaves,
                levels,
                cuts,
                tree,
            },
            (FarBindGroups::Tree { .. }, None) => return Err(not_prepared()),
        };
        Ok(PreparedFarField {
            passes: &self.passes,
            light_count: self.light_count,
            work,
        })
    }
}

/// One frame's far-field passes with what they bind, resolved when the frame was prepared:
/// recording them cannot fail.
pub(crate) struct PreparedFarField<'a> {
    passes: &'a FarFieldPasses,
    light_count: u32,
    work: FarWork<'a>,
}

enum FarWork<'a> {
    None,
    Stochastic(&'a wgpu::BindGroup),
    Tree {
        keys: &'a wgpu::BindGroup,
        sort_passes: &'a [wgpu::BindGroup],
        leaves: &'a wgpu::BindGroup,
        levels: &'a [wgpu::BindGroup],
        cuts: &'a wgpu::BindGroup,
        tree: &'a TreeBuffers,
    },
}

impl PreparedFarField<'_> {
    /// Records what the far field needs before the assignment: the light tree, or each
    /// light's random range. One timed compute pass; nothing without a far field.
    pub(crate) fn record_lights(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        mut timer: Option<&mut GpuTimer>,
    ) {
        let light_groups = self.light_count.div_ceil(crate::assign::WORKGROUP_SIZE);
        match &self.work {
            FarWork::None => {}
            FarWork::Stochastic(group) => {
                let mut pass =
                    crate::view_pass(encoder, view, timer, crate::passes::FAR_FIELD_RANGES);
                pass.set_pipeline(&self.passes.stochastic_ranges);
                pass.set_bind_group(1, *group, &[]);
                if light_groups > 0 {
                    pass.dispatch_workgroups(light_groups, 1, 1);
                }
            }
            FarWork::Tree {
                keys,
                sort_passes,
                leaves,
                levels,
                tree,
                ..
            } => {
                encoder.clear_buffer(&tree.bounds_codes, 0, None);
                // Three timed passes (keys, sort, nodes): the build is a large share of a
                // million-light frame, and each step scales differently.
                let blocks = self.light_count.div_ceil(SORT_BLOCK);
                if light_groups > 0 {
                    let mut pass = crate::view_pass(
                        encoder,
                        view,
                        timer.as_deref_mut(),
                        crate::passes::FAR_FIELD_KEYS,
                    );
                    pass.set_bind_group(1, *keys, &[]);
                    pass.set_pipeline(&self.passes.light_bounds);
                    pass.dispatch_workgroups(light_groups, 1, 1);
                    pass.set_pipeline(&self.passes.light_keys);
                    pass.dispatch_workgroups(light_groups, 1, 1);
                    drop(pass);
                    let mut pass = crate::view_pass(
                        encoder,
                        view,
                        timer.as_deref_mut(),
                        crate::passes::FAR_FIELD_SORT,
                    );
                    for sort_group in sort_passes.iter() {
                        pass.set_bind_group(1, sort_group, &[]);
                        pass.set_pipeline(&self.passes.sort_histogram);
                        pass.dispatch_workgroups(blocks, 1, 1);
                        pass.set_pipeline(&self.passes.sort_scan);
                        pass.dispatch_workgroups(1, 1, 1);
                        pass.set_pipeline(&self.passes.sort_scatter);
                        pass.dispatch_workgroups(blocks, 1, 1);
                    }
                }
                let mut pass =
                    crate::view_pass(encoder, view, timer, crate::passes::FAR_FIELD_NODES);
                let firsts = level_firsts(tree.levels);
                pass.set_bind_group(1, *leaves, &[]);
                pass.set_pipeline(&self.passes.leaf_nodes);
                pass.dispatch_workgroups(firsts[1].div_ceil(crate::assign::WORKGROUP_SIZE), 1, 1);
                pass.set_pipeline(&self.passes.inner_nodes);
                for (level, level_group) in (1..).zip(levels.iter()) {
                    let nodes = firsts[level + 1] - firsts[level];
                    pass.set_bind_group(1, level_group, &[]);
                    pass.dispatch_workgroups(nodes.div_ceil(crate::assign::WORKGROUP_SIZE), 1, 1);
                }
            }
        }
    }

    /// Records each occupied cluster's cut of the tree (after the assignment, which gives
    /// the boxes the cuts read). Nothing for other methods.
    pub(crate) fn record_cuts(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &ViewBinding,
        timer: Option<&mut GpuTimer>,
    ) {
        let FarWork::Tree { cuts, tree, .. } = &self.work else {
            return;
        };
        let mut pass = crate::view_pass(encoder, view, timer, crate::passes::FAR_FIELD_CUTS);
        pass.set_pipeline(&self.passes.cut_clusters);
        pass.set_bind_group(1, *cuts, &[]);
        // A workgroup per cluster, in rows within the 65,535 a dimension may hold.
        let across = tree.clusters.clamp(1, CUT_ROW_WORKGROUPS);
        pass.dispatch_workgroups(across, tree.clusters.div_ceil(across), 1);
    }
}
