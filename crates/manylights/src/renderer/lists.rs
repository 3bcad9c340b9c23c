//! The frame's light lists on the renderer's side: prepared first of the frame's
//! preparation where the plan has clusters, then bound in the frame's lighting group.

use manylights_cluster::GpuClusters;
use manylights_gpu::{GpuContext, GpuError, RenderTargets};
use manylights_lights::{GpuLights, SpecularTables};
use manylights_pipeline::{BoundLighting, EarlyDepth, FrameLighting, ListBuffers};
use manylights_visibility::GpuSceneBvh;

use crate::plan::FramePlan;

/// The frame's lighting group: its lights, the BVH and the albedo table, with the lists
/// where the plan has them (stand-ins where it has none) and the plan's heatmap scale.
pub(super) fn bind_lighting<'a>(
    lighting: &mut FrameLighting,
    (context, plan, clusters): (&GpuContext, &FramePlan, &GpuClusters),
    lights: &GpuLights,
    tables: (&'a GpuSceneBvh, &SpecularTables),
) -> Result<BoundLighting<'a>, GpuError> {
    let lists = match plan.clusters {
        Some(_) => Some(list_buffers(clusters)?),
        None => None,
    };
    Ok(lighting.bind(context, lists, lights, tables, plan.heatmap_max))
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
