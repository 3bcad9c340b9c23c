//! Forward+ (clustered forward) shading (`shaders/forward_plus/forward_plus.wgsl`): after
//! the cluster assignment, each fragment finds its cluster with the shared
//! `cluster_index` and shades only that cluster's lights. An optional depth pre-pass
//! (`depth_prepass`) lays down depth first, so the shading pass (depth test LessEqual, no
//! writes) shades each pixel once. Material and alpha-mask handling is the scene's, as
//! in naive: one pipeline per `PipelineKey`, built from the scene's `MaterialVariant`.
//!
//! The cluster debug views (lights-per-cluster heatmap with a legend strip, depth-slice
//! colouring) come from the same pipelines, switched by a uniform.

use manylights_cluster::{ClusteredShading, GpuClusters};
use manylights_gpu::{
    DebugView, DepthConvention, GpuContext, GpuError, GpuResult, GpuScene, GpuTimer, HDR_FORMAT,
    PipelineKey, Program, RenderTargets, ScenePipelineDesc, ShaderLibrary, ViewBinding, wgpu,
};
use manylights_lights::{Falloff, GpuLights};

type Pipelines = Vec<(PipelineKey, wgpu::RenderPipeline)>;

/// The Forward+ pipelines for one uploaded scene.
#[derive(Debug)]
pub struct ForwardPlusPipeline {
    depth: DepthConvention,
    depth_prepass: Pipelines,
    shade_after_prepass: Pipelines,
    shade: Pipelines,
    /// Group 3: cluster params, offsets, indices, lights, shading params.
    shading: ClusteredShading,
}

impl ForwardPlusPipeline {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        scene: &GpuScene,
        view: &ViewBinding,
        depth: DepthConvention,
    ) -> GpuResult<Self> {
        let shading = ClusteredShading::new(context, wgpu::ShaderStages::FRAGMENT);
        let hdr = [Some(HDR_FORMAT.into())];
        let build = |label: &str,
                     fragment: &str,
                     targets: &[Option<wgpu::ColorTargetState>],
                     depth_write: bool,
                     compare: wgpu::CompareFunction|
         -> GpuResult<Pipelines> {
            scene
                .pipeline_keys()
                .into_iter()
                .map(|key| {
                    // Opaque depth-only pipelines need no fragment stage at all.
                    let fragment_entry = if fragment == "fs_depth" && !key.alpha_mask {
                        None
                    } else {
                        Some(fragment)
                    };
                    let desc = ScenePipelineDesc {
                        label,
                        program: Program::ForwardPlus,
                        key,
                        view_layout: &view.layout,
                        extra_layouts: &[&shading.layout],
                        vertex_entry: "vs_main",
                        fragment_entry,
                        color_targets: targets,
                        depth_write,
                        depth_compare: compare,
                    };
                    Ok((key, scene.create_pipeline(context, library, &desc)?))
                })
                .collect()
        };
        Ok(Self {
            depth_prepass: build(
                "forward+ depth pre-pass",
                "fs_depth",
                &[],
                true,
                depth.nearer(),
            )?,
            shade_after_prepass: build(
                "forward+ shading",
                "fs_main",
                &hdr,
                false,
                depth.nearer_or_equal(),
            )?,
            shade: build(
                "forward+ shading (no pre-pass)",
                "fs_main",
                &hdr,
                true,
                depth.nearer(),
            )?,
            depth,
            shading,
        })
    }

    /// Records the optional depth pre-pass and the shading (or debug) pass into the HDR
    /// target. The cluster assignment for this frame must already be recorded.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        view: &ViewBinding,
        clusters: &GpuClusters,
        lights: &GpuLights,
        falloff: Falloff,
        depth_prepass: bool,
        debug_view: DebugView,
        targets: &RenderTargets,
        timer: &mut GpuTimer,
    ) -> GpuResult<()> {
        if debug_view.is_gbuffer_view() {
            return Err(GpuError::Unsupported(format!(
                "Forward+ has no G-buffer to show ({debug_view:?}); use the deferred pipeline"
            )));
        }
        let bind_group = self
            .shading
            .bind_group(context, clusters, lights, falloff, debug_view)?;
        let prepass = depth_prepass && debug_view == DebugView::None;
        if prepass {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("forward+ depth pre-pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(manylights_gpu::binding::depth_attachment(
                    &targets.depth.view,
                    wgpu::LoadOp::Clear(self.depth.clear_value()),
                )),
                timestamp_writes: timer.render_pass("depth pre-pass"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &view.bind_group, &[]);
            pass.set_bind_group(3, &bind_group, &[]);
            for (key, pipeline) in &self.depth_prepass {
                pass.set_pipeline(pipeline);
                scene.draw(&mut pass, *key);
            }
        }
        let (pipelines, name) = match debug_view {
            DebugView::None if prepass => (&self.shade_after_prepass, "forward+ shading"),
            DebugView::None => (&self.shade, "forward+ shading"),
            _ => (&self.shade, "cluster debug view"),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[manylights_gpu::binding::cleared_color(
                &targets.hdr.view,
                wgpu::Color::BLACK,
            )],
            depth_stencil_attachment: Some(manylights_gpu::binding::depth_attachment(
                &targets.depth.view,
                if prepass {
                    wgpu::LoadOp::Load
                } else {
                    wgpu::LoadOp::Clear(self.depth.clear_value())
                },
            )),
            timestamp_writes: timer.render_pass(name),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &view.bind_group, &[]);
        pass.set_bind_group(3, &bind_group, &[]);
        for (key, pipeline) in pipelines {
            pass.set_pipeline(pipeline);
            scene.draw(&mut pass, *key);
        }
        Ok(())
    }
}
