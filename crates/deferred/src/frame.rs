//! A deferred frame, prepared ([`crate::DeferredPipeline`]'s `prepare`), and its
//! recording: the G-buffer (or the visibility buffer's passes), then the lighting pass.

use manylights_cluster::{ListsBuilt, PreparedAssignment};
use manylights_gpu::{
    DepthConvention, PassName, PipelineKey, RenderTargets, timed_compute_pass, wgpu,
};
use manylights_pipeline::{DepthRecorded, FrameRecorder, PreparedShading};

use crate::visibility::{self, VISIBILITY_PASS};
use crate::{GBUFFER_PASS, GBuffer, LightingPipeline};
use manylights_visibility::ShadowFilter;
use manylights_visibility::shadow_filter::FilterTargets;

/// What lays a deferred frame's depth down: the G-buffer pass, or the visibility buffer's
/// raster, classification and resolve.
#[derive(Debug)]
pub(crate) enum DeferredDepth<'a> {
    GBuffer {
        pipelines: &'a [(PipelineKey, wgpu::RenderPipeline)],
        /// The layout has a specular target the scene does not write (no attachment there).
        specular_gap: bool,
    },
    Visibility {
        visibility: &'a visibility::VisibilityPipelines,
        frame: &'a visibility::VisibilityFrame,
    },
}

/// A deferred frame, prepared: its G-buffer and the passes that write it, its lighting
/// pipeline and the groups that pipeline binds.
#[derive(Debug)]
pub struct DeferredFrame<'a> {
    /// The light assignment, recorded between the G-buffer and the lighting.
    pub(crate) assignment: PreparedAssignment<'a>,
    pub(crate) early: DeferredDepth<'a>,
    pub(crate) gbuffer: &'a GBuffer,
    pub(crate) lighting: &'a LightingPipeline,
    pub(crate) lighting_pass: PassName,
    pub(crate) shading_group: wgpu::BindGroup,
    /// The HDR target as the compute paths' output (with the shadow filter's inputs).
    pub(crate) output_group: Option<wgpu::BindGroup>,
    /// The spatial shadow filter and its targets, when the frame's shadows ask for it.
    pub(crate) shadow_filter: Option<(&'a ShadowFilter, &'a FilterTargets)>,
    /// Blended surfaces, shaded forward from the same clusters after the lighting.
    pub(crate) blended: Option<manylights_cluster::PreparedBlended<'a>>,
    pub(crate) depth: DepthConvention,
}

impl DeferredFrame<'_> {
    fn depth_attachment<'t>(
        &self,
        targets: &'t RenderTargets,
    ) -> Option<wgpu::RenderPassDepthStencilAttachment<'t>> {
        Some(manylights_gpu::binding::depth_attachment(
            &targets.depth.view,
            wgpu::LoadOp::Clear(self.depth.clear_value()),
        ))
    }

    /// The G-buffer pass: clears and writes every target of the layout, and the depth.
    fn record_gbuffer(
        &self,
        frame: &mut FrameRecorder,
        pipelines: &[(PipelineKey, wgpu::RenderPipeline)],
        specular_gap: bool,
    ) {
        let gbuffer = self.gbuffer;
        let mut attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = gbuffer
            .targets
            .iter()
            .map(|t| manylights_gpu::binding::cleared_color(&t.view, wgpu::Color::TRANSPARENT))
            .collect();
        if specular_gap {
            attachments.push(None);
        }
        if let Some(emission) = &gbuffer.emission {
            attachments.push(manylights_gpu::binding::cleared_color(
                &emission.view,
                wgpu::Color::TRANSPARENT,
            ));
        }
        let mut pass = frame
            .encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("g-buffer"),
                color_attachments: &attachments,
                depth_stencil_attachment: self.depth_attachment(frame.targets),
                timestamp_writes: frame.timer.render_pass(GBUFFER_PASS),
                occlusion_query_set: None,
                multiview_mask: None,
            });
        pass.set_bind_group(0, &frame.view.bind_group, &[]);
        for (key, pipeline) in pipelines {
            pass.set_pipeline(pipeline);
            frame.scene.draw(&mut pass, *key);
        }
    }

    /// The visibility buffer: its raster, then classification and the material resolve.
    fn record_visibility(
        &self,
        frame: &mut FrameRecorder,
        visibility: &visibility::VisibilityPipelines,
        visibility_frame: &visibility::VisibilityFrame,
    ) {
        {
            let mut pass = frame
                .encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("visibility"),
                    color_attachments: &[visibility::VisibilityPipelines::attachment(
                        visibility_frame,
                    )],
                    depth_stencil_attachment: self.depth_attachment(frame.targets),
                    timestamp_writes: frame.timer.render_pass(VISIBILITY_PASS),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
            pass.set_bind_group(0, &frame.view.bind_group, &[]);
            visibility.draw(&mut pass, frame.scene);
        }
        visibility.record_resolve(
            frame.encoder,
            Some(&mut *frame.timer),
            frame.scene,
            frame.view,
            visibility_frame,
        );
    }
}

impl PreparedShading for DeferredFrame<'_> {
    /// The G-buffer (or the visibility buffer's passes): the depth of the visible surfaces,
    /// which the assignment bounds the clusters by, and their materials.
    fn record_depth_passes(&self, frame: &mut FrameRecorder) {
        match self.early {
            DeferredDepth::GBuffer {
                pipelines,
                specular_gap,
            } => self.record_gbuffer(frame, pipelines, specular_gap),
            DeferredDepth::Visibility {
                visibility,
                frame: visibility_frame,
            } => self.record_visibility(frame, visibility, visibility_frame),
        }
    }

    /// The light assignment, then the lighting pass (fragment or compute) into the HDR
    /// target, reading the G-buffer, then the blended surfaces over it.
    fn record(&self, frame: &mut FrameRecorder, _depth: DepthRecorded) {
        let lists = self
            .assignment
            .record(frame.encoder, frame.view, Some(&mut *frame.timer));
        self.record_lighting(frame, lists);
        if let Some(blended) = &self.blended {
            blended.record(
                frame.encoder,
                frame.timer,
                (frame.scene, frame.view, frame.targets),
            );
        }
    }
}

impl DeferredFrame<'_> {
    /// The lighting pass (fragment or compute) into the HDR target, reading the G-buffer
    /// and the lists just built.
    fn record_lighting(&self, frame: &mut FrameRecorder, _lists: ListsBuilt) {
        let (encoder, timer, view) = (&mut *frame.encoder, &mut *frame.timer, frame.view);
        match (self.lighting, &self.output_group) {
            (LightingPipeline::Fragment(pipeline), _) => {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("deferred lighting (fragment)"),
                    color_attachments: &[manylights_gpu::binding::cleared_color(
                        &frame.targets.hdr.view,
                        wgpu::Color::BLACK,
                    )],
                    depth_stencil_attachment: None,
                    timestamp_writes: timer.render_pass(self.lighting_pass),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &view.bind_group, &[]);
                pass.set_bind_group(1, &self.gbuffer.read_group, &[]);
                pass.set_bind_group(3, &self.shading_group, &[]);
                pass.draw(0..3, 0..1);
            }
            (LightingPipeline::Compute(pipeline), Some(output)) => {
                let mut pass = timed_compute_pass(encoder, Some(timer), self.lighting_pass);
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &view.bind_group, &[]);
                pass.set_bind_group(1, &self.gbuffer.read_group, &[]);
                pass.set_bind_group(2, output, &[]);
                pass.set_bind_group(3, &self.shading_group, &[]);
                let (width, height) = frame.targets.size;
                let tile = manylights_gpu::SCREEN_TILE;
                pass.dispatch_workgroups(width.div_ceil(tile), height.div_ceil(tile), 1);
                drop(pass);
                if let Some((filter, targets)) = self.shadow_filter {
                    filter.record(encoder, timer, view, targets);
                }
            }
            (LightingPipeline::Compute(_), None) => {
                unreachable!("prepare binds the output of every compute path")
            }
        }
    }
}
