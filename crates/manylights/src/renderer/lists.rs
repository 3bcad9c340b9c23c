//! The frame's light lists on the renderer's side: prepared first of the frame's
//! preparation where the plan has clusters, then bound in the frame's lighting group.

use manylights_cluster::{GpuClusters, GpuListStatistics, PreparedStatistics};
use manylights_gpu::{GpuContext, GpuError, RenderTargets};
use manylights_lights::GpuLights;
use manylights_pipeline::{EarlyDepth, ListBuffers};

use crate::plan::FramePlan;

/// The lists the frame's lighting group binds: the prepared lists' buffers where the plan
/// has clusters, `None` (stand-ins) where it has none.
pub(super) fn planned_list_buffers<'a>(
    plan: &FramePlan,
    clusters: &'a GpuClusters,
) -> Result<Option<ListBuffers<'a>>, GpuError> {
    match plan.clusters {
        Some(_) => list_buffers(clusters).map(Some),
        None => Ok(None),
    }
}

/// The prepared lists' buffers, as the frame's lighting binding binds them.
fn list_buffers(clusters: &GpuClusters) -> Result<ListBuffers<'_>, GpuError> {
    Ok(ListBuffers {
        grid: clusters.params_buffer(),
        offsets: clusters.offsets_buffer()?,
        indices: clusters.indices_buffer()?,
        view_lights: clusters.view_lights_buffer()?,
        bounds: clusters.bounds_buffer()?,
        far_field: clusters.far_field().shading_buffers(),
    })
}

/// Prepares the frame's clustering where the plan has one (rebuilding only what changed
/// since the last frame), given the depth the pipeline will have laid down when the
/// lights are assigned.
pub(super) fn prepare_clusters(
    context: &GpuContext,
    clusters: &mut GpuClusters,
    plan: &FramePlan,
    targets: &RenderTargets,
    lights: &GpuLights,
) -> Result<(), GpuError> {
    let Some(cluster_plan) = &plan.clusters else {
        return Ok(());
    };
    clusters.set_blended_bounds(context, &cluster_plan.blended_boxes);
    // The pipeline's early depth holds the visible surfaces when the lights are assigned.
    let visible_depth = (plan.early_depth == EarlyDepth::VisibleSurfaces).then(|| {
        manylights_cluster::VisibleDepth {
            view: targets.depth_view(),
            samples: targets.samples(),
            size: targets.size,
        }
    });
    clusters.prepare(context, &cluster_plan.frame, lights, visible_depth)?;
    Ok(())
}

/// The lists' statistics pass where the plan computes them (the false positives are
/// counted against the frame's depth).
pub(super) fn prepare_list_statistics<'a>(
    statistics: &'a mut GpuListStatistics,
    context: &GpuContext,
    clusters: &'a GpuClusters,
    plan: &FramePlan,
    targets: &RenderTargets,
) -> Result<Option<PreparedStatistics<'a>>, GpuError> {
    match plan.list_statistics() {
        Some(asked) => statistics.prepare(
            context,
            clusters,
            asked.false_positives.then_some(&targets.depth.view),
        ),
        None => Ok(None),
    }
}
