//! A deferred frame: its preparation (`impl ShadingPipeline for DeferredPipeline`, which
//! builds what the frame binds and resolves the lists' assignment), then its recording: the
//! G-buffer (or the visibility buffer's passes), the assignment, the lighting pass and the
//! blended surfaces.

use manylights_cluster::{GpuClusters, LightLoop, ListsBuilt, PreparedAssignment, ShadingOutput};
use manylights_gpu::{
    DepthConvention, GpuResult, PassName, PipelineKey, RenderTargets, timed_compute_pass, wgpu,
};
use manylights_pipeline::{
    DepthRecorded, EarlyDepth, FrameInputs, FrameRecorder, LIGHTING_GROUP, PipelineBuild,
    PreparedShading, ShadingPipeline, ShadowRoute,
};
use manylights_visibility::shadow_filter::FilterTargets;
use manylights_visibility::{ShadowFilter, Shadows};

use crate::blended_layers::{LayersShadeKey, PreparedSurfaces};
use crate::visibility::{self, VISIBILITY_PASS};
use crate::{
    DeferredPipeline, DeferredSettings, DeferredView, GBUFFER_PASS, GBuffer, LIGHTING_COMPUTE_PASS,
    LIGHTING_FRAGMENT_PASS, LIGHTING_TILES_PASS, LightingKey, LightingPath, LightingPipeline,
    has_specular_target, not_drawn,
};

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

impl<'a> DeferredDepth<'a> {
    /// The visibility buffer's passes where the layout's `pipelines` and the frame's
    /// `gbuffer` have them, else the G-buffer pass (`specular_gap`: its layout's specular
    /// target is left without an attachment).
    fn of(pipelines: &'a crate::LayoutPipelines, gbuffer: &'a GBuffer, specular_gap: bool) -> Self {
        match (&pipelines.visibility, &gbuffer.visibility) {
            (Some(visibility), Some(frame)) => DeferredDepth::Visibility { visibility, frame },
            _ => DeferredDepth::GBuffer {
                pipelines: &pipelines.gbuffer,
                specular_gap,
            },
        }
    }
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
    /// Blended surfaces, drawn forward from the same clusters after the lighting or
    /// stored as layers and shaded in compute.
    pub(crate) blended: Option<PreparedSurfaces<'a>>,
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
            blended.record(frame);
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
                pass.set_bind_group(LIGHTING_GROUP, &self.shading_group, &[]);
                pass.draw(0..3, 0..1);
            }
            (LightingPipeline::Compute(pipeline), Some(output)) => {
                let mut pass = timed_compute_pass(encoder, Some(timer), self.lighting_pass);
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &view.bind_group, &[]);
                pass.set_bind_group(1, &self.gbuffer.read_group, &[]);
                pass.set_bind_group(2, output, &[]);
                pass.set_bind_group(LIGHTING_GROUP, &self.shading_group, &[]);
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

impl DeferredPipeline {
    /// The spatial shadow filter and its targets for `frame` where its route is `filtered`
    /// ([`ShadowRoute::ComputeLighting`]: it follows a compute path), made on first use;
    /// otherwise its history is dropped, so the next filtered frame starts afresh.
    fn prepare_shadow_filter(&mut self, frame: &FrameInputs, filtered: bool) -> GpuResult<()> {
        if !filtered {
            if let Some(filter) = &mut self.shadow_filter {
                filter.forget_history();
            }
            return Ok(());
        }
        if self.shadow_filter.is_none() {
            self.shadow_filter = Some(ShadowFilter::new(frame.gpu, &self.library, frame.view)?);
        }
        if let Some(filter) = &mut self.shadow_filter {
            filter.prepare(frame.gpu, frame.targets, frame.shadows())?;
        }
        Ok(())
    }
}

/// The group (of `layout`, kept in `cache`) that binds the HDR target as a compute pass's
/// output.
fn hdr_output(
    cache: &mut manylights_gpu::binding::CachedBindGroup,
    layout: &wgpu::BindGroupLayout,
    context: &manylights_gpu::GpuContext,
    targets: &RenderTargets,
) -> wgpu::BindGroup {
    cache.get(
        context,
        "deferred lighting output",
        layout,
        [(0, wgpu::BindingResource::TextureView(&targets.hdr.view))],
    )
}

/// The timed pass the lighting runs as on `path`.
fn lighting_pass(path: LightingPath) -> PassName {
    match path {
        LightingPath::Fragment => LIGHTING_FRAGMENT_PASS,
        LightingPath::Tiles => LIGHTING_TILES_PASS,
        LightingPath::Compute => LIGHTING_COMPUTE_PASS,
    }
}

/// What the lighting pass writes: the shaded image, or a debug view's colours.
fn shading_output(debug_view: Option<DeferredView>) -> ShadingOutput {
    match debug_view {
        None => ShadingOutput::Shaded,
        Some(DeferredView::Cluster(view)) => ShadingOutput::Cluster(view),
        Some(DeferredView::GBuffer(channel)) => ShadingOutput::Pipeline(channel.shader_code()),
    }
}

impl ShadingPipeline for DeferredPipeline {
    type Settings = DeferredSettings;
    type LightLists = GpuClusters;
    type Prepared<'a> = DeferredFrame<'a>;
    const NAME: &'static str = "deferred";

    fn new(build: &PipelineBuild) -> GpuResult<Self> {
        Self::build(build)
    }

    fn shows_debug_view(settings: &DeferredSettings) -> bool {
        settings.debug_view.is_some()
    }

    /// Records the G-buffer pass: the depth of the visible surfaces, which the assignment
    /// bounds the clusters by, and their materials.
    fn early_depth(_: &DeferredSettings) -> EarlyDepth {
        EarlyDepth::VisibleSurfaces
    }

    /// A ray budget on a compute path is traced by the compute lighting, which the filter
    /// and history follow; everything else in the lighting loop, unfiltered.
    fn shaded_shadow_route(settings: &DeferredSettings, shadows: Shadows) -> ShadowRoute {
        match shadows {
            Shadows::Off => ShadowRoute::Off,
            _ if settings.lighting.is_compute() && shadows.ray_budget().is_some() => {
                ShadowRoute::ComputeLighting(shadows)
            }
            _ => ShadowRoute::InShadingLoop(shadows),
        }
    }

    fn prepare<'a>(
        &'a mut self,
        frame: &FrameInputs,
        lists: &'a GpuClusters,
        settings: &DeferredSettings,
    ) -> GpuResult<DeferredFrame<'a>> {
        let (context, targets, layout) = (frame.gpu, frame.targets, settings.layout);
        self.blended.begin_frame();
        self.build_layout_if_new(context, frame.scene, frame.view, layout)?;
        self.prepare_gbuffer(context, frame.scene, layout, targets)?;
        let output = shading_output(settings.debug_view);
        let shading_group = frame.lighting.group.clone();
        let light_loop = LightLoop::for_frame(
            lists,
            frame.lighting.light_kinds,
            self.brdf,
            self.specular_materials,
            settings.falloff.into(),
            output,
            frame.shadow_route.shadows(),
        );
        let filtered = frame.shadow_route.filtered();
        self.prepare_shadow_filter(frame, filtered)?;
        let lighting_key = LightingKey {
            layout,
            path: settings.lighting,
            light_loop,
        };
        self.build_lighting_if_new(context, frame.view, lighting_key)?;
        let shadow_filter = self
            .shadow_filter
            .as_ref()
            .filter(|_| filtered)
            .and_then(|filter| Some((filter, filter.prepared()?)));
        // The HDR target as the compute paths' output: the lighting's (unless the shadow
        // filter writes it) and the blended layers'.
        let hdr_output = (settings.lighting.is_compute())
            .then(|| hdr_output(&mut self.output, &self.output_layout, context, targets));
        let output_group = match shadow_filter {
            Some((_, filter_targets)) if hdr_output.is_some() => {
                Some(filter_targets.output_group.clone())
            }
            _ => hdr_output.clone(),
        };
        let Some((_, gbuffer)) = self.gbuffer.as_ref().filter(|(l, _)| *l == layout) else {
            return Err(not_drawn(layout));
        };
        let (Some(pipelines), Some(lighting)) =
            (self.layouts.get(&layout), self.lighting.get(&lighting_key))
        else {
            return Err(not_drawn(layout));
        };
        let early = DeferredDepth::of(
            pipelines,
            gbuffer,
            has_specular_target(layout) && !self.specular,
        );
        let blended = match light_loop.for_blended() {
            Some(light_loop) => {
                let key = LayersShadeKey {
                    path: settings.lighting,
                    light_loop,
                };
                self.blended.prepare(frame, key, hdr_output)?
            }
            None => None,
        };
        Ok(DeferredFrame {
            assignment: lists.assignment()?,
            early,
            blended,
            gbuffer,
            lighting,
            lighting_pass: lighting_pass(settings.lighting),
            shading_group,
            output_group,
            shadow_filter,
            depth: self.depth,
        })
    }
}
