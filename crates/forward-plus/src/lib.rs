//! Forward+ (clustered forward) shading (`shaders/forward_plus/forward_plus.wgsl`): after
//! the cluster assignment, each fragment finds its cluster with the shared
//! `cluster_index` and shades only that cluster's lights. An optional depth pre-pass
//! (`depth_prepass`) lays down depth first, so the shading pass (depth test LessEqual, no
//! writes) shades each pixel once. Material and alpha-mask handling is the scene's, as
//! in naive: one pipeline per `PipelineKey`, built from the scene's `MaterialVariant`.
//!
//! The cluster debug views ([`ClusterView`]: lights-per-cluster heatmap with a legend strip,
//! depth-slice colouring, light evaluations) come from the same pipelines, switched by a
//! uniform.
//!
//! ```no_run
//! use manylights_forward_plus::{ForwardPlusPipeline, ForwardPlusSettings};
//! use manylights_cluster::GpuClusters;
//! use manylights_pipeline::{FrameContext, PipelineBuild, ShadingPipeline};
//! # fn frame(build: &PipelineBuild, frame: &mut FrameContext, clusters: &mut GpuClusters) -> manylights_gpu::GpuResult<()> {
//! let mut pipeline = ForwardPlusPipeline::new(build)?; // once per scene
//! let settings = ForwardPlusSettings::default();
//! // Every frame: the depth pre-pass, then the cluster assignment (given that depth, it
//! // lists only what is seen), then the shading.
//! // (`clusters` prepared for the frame, with the depth `early_depth` promises.)
//! pipeline.record_depth(frame, clusters, &settings)?;
//! clusters.record(frame.encoder, frame.view, None)?;
//! pipeline.record(frame, clusters, &settings)?;
//! # Ok(()) }
//! ```

use manylights_cluster::{ClusterView, ClusteredShading, GpuClusters, ShadingOutput};
use manylights_gpu::{
    DepthConvention, GpuResult, HDR_FORMAT, PipelineKey, Program, ScenePipelineDesc, ShaderModules,
    shader_files, wgpu,
};
use manylights_lights::BoundedFalloff;
use manylights_pipeline::{EarlyDepth, FrameContext, PipelineBuild, ShadingPipeline};

/// This crate's WGSL.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "forward_plus",
    files: shader_files!["forward_plus/forward_plus.wgsl"],
    uses: &[&manylights_cluster::SHADERS],
    constants: manylights_gpu::no_constants,
};

/// The Forward+ program: depth pre-pass, shading and cluster views (composed per material
/// variant of the scene).
pub fn program() -> Program {
    Program::shading_materials("forward_plus", &SHADERS, "forward_plus/forward_plus.wgsl")
}

/// Every program of this crate, in every variant (what `cargo xtask validate-shaders`
/// validates).
pub fn programs() -> Vec<Program> {
    vec![program()]
}

/// What a Forward+ frame can vary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForwardPlusSettings {
    /// A falloff with a radius: lights are culled by it.
    pub falloff: BoundedFalloff,
    /// Lay down depth first so hidden fragments are not shaded.
    pub depth_prepass: bool,
    /// A cluster view instead of the shaded image.
    pub debug_view: Option<ClusterView>,
}

impl Default for ForwardPlusSettings {
    fn default() -> Self {
        Self {
            falloff: BoundedFalloff::default(),
            depth_prepass: true,
            debug_view: None,
        }
    }
}

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
    /// The pre-pass runs when asked for, except under a debug view (drawn in one pass).
    fn uses_prepass(settings: &ForwardPlusSettings) -> bool {
        settings.depth_prepass && settings.debug_view.is_none()
    }
}

impl ShadingPipeline for ForwardPlusPipeline {
    type Settings = ForwardPlusSettings;
    type LightLists = GpuClusters;
    const NAME: &'static str = "Forward+";

    fn new(build: &PipelineBuild) -> GpuResult<Self> {
        let PipelineBuild {
            gpu: context,
            library,
            scene,
            view,
            depth,
        } = *build;
        let shading = ClusteredShading::new(context, wgpu::ShaderStages::FRAGMENT);
        let program = program();
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
                        program: &program,
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

    fn shows_debug_view(settings: &ForwardPlusSettings) -> bool {
        settings.debug_view.is_some()
    }

    /// Records the depth pre-pass (when on): the depth of the visible surfaces, which the
    /// assignment bounds the clusters by.
    fn early_depth(settings: &ForwardPlusSettings) -> EarlyDepth {
        if Self::uses_prepass(settings) {
            EarlyDepth::VisibleSurfaces
        } else {
            EarlyDepth::None
        }
    }

    fn record_depth(
        &mut self,
        frame: &mut FrameContext,
        lists: &GpuClusters,
        settings: &ForwardPlusSettings,
    ) -> GpuResult<()> {
        if !Self::uses_prepass(settings) {
            return Ok(());
        }
        // The pre-pass programs share the shading module's layout (group 3), which they do
        // not read: the lists are not built yet.
        let bind_group = self.shading.bind_group(
            frame.gpu,
            lists,
            frame.lights,
            settings.falloff.into(),
            ShadingOutput::Shaded,
        )?;
        let mut pass = frame
            .encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("forward+ depth pre-pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(manylights_gpu::binding::depth_attachment(
                    &frame.targets.depth.view,
                    wgpu::LoadOp::Clear(self.depth.clear_value()),
                )),
                timestamp_writes: frame.timer.render_pass("depth pre-pass"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
        pass.set_bind_group(0, &frame.view.bind_group, &[]);
        pass.set_bind_group(3, &bind_group, &[]);
        for (key, pipeline) in &self.depth_prepass {
            pass.set_pipeline(pipeline);
            frame.scene.draw(&mut pass, *key);
        }
        Ok(())
    }

    /// Records the shading (or debug) pass into the HDR target, after the pre-pass if on.
    fn record(
        &mut self,
        frame: &mut FrameContext,
        lists: &GpuClusters,
        settings: &ForwardPlusSettings,
    ) -> GpuResult<()> {
        let output = settings
            .debug_view
            .map_or(ShadingOutput::Shaded, ShadingOutput::Cluster);
        let bind_group = self.shading.bind_group(
            frame.gpu,
            lists,
            frame.lights,
            settings.falloff.into(),
            output,
        )?;
        let targets = frame.targets;
        let prepass = Self::uses_prepass(settings);
        let (pipelines, name) = match settings.debug_view {
            None if prepass => (&self.shade_after_prepass, "forward+ shading"),
            None => (&self.shade, "forward+ shading"),
            Some(_) => (&self.shade, "cluster debug view"),
        };
        let mut pass = frame
            .encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
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
                timestamp_writes: frame.timer.render_pass(name),
                occlusion_query_set: None,
                multiview_mask: None,
            });
        pass.set_bind_group(0, &frame.view.bind_group, &[]);
        pass.set_bind_group(3, &bind_group, &[]);
        for (key, pipeline) in pipelines {
            pass.set_pipeline(pipeline);
            frame.scene.draw(&mut pass, *key);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_program_validates() {
        for result in manylights_gpu::ShaderLibrary::Embedded.validate_all(&super::programs()) {
            if let Err(error) = result {
                panic!("{error}");
            }
        }
    }
}
