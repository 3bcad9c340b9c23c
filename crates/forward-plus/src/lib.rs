//! Forward+ (clustered forward) shading (`shaders/forward_plus/forward_plus.wgsl`): after
//! the cluster assignment, each fragment finds its cluster with the shared
//! `cluster_index` and shades only that cluster's lights. An optional depth pre-pass
//! (`depth_prepass`) lays down depth first, so the shading pass (depth test LessEqual, no
//! writes) shades each pixel once. Material and alpha-mask handling is the scene's, as
//! in naive: one pipeline per `PipelineKey`, built from the scene's `MaterialVariant`.
//!
//! The cluster debug views ([`ClusterView`]: lights-per-cluster heatmap with a legend strip,
//! depth-slice colouring, light evaluations) are programs of the same entry point, one
//! per [`LightLoop`] (as are the falloffs and far fields): built when a frame first asks.
//!
//! ```no_run
//! use manylights_forward_plus::{ForwardPlusPipeline, ForwardPlusSettings};
//! use manylights_cluster::GpuClusters;
//! use manylights_pipeline::{
//!     FrameInputs, FrameRecorder, PipelineBuild, PreparedShading, ShadingPipeline,
//! };
//! # fn frame(build: &PipelineBuild, inputs: &FrameInputs, recorder: &mut FrameRecorder, clusters: &GpuClusters) -> manylights_gpu::GpuResult<()> {
//! let mut pipeline = ForwardPlusPipeline::new(build)?; // once per scene
//! let settings = ForwardPlusSettings::default();
//! // Every frame, with `clusters` prepared for it (and the depth `early_depth` promises):
//! // the depth pre-pass, then (in `record`) the cluster assignment, which given that
//! // depth lists only what is seen, then the shading.
//! let prepared = pipeline.prepare(inputs, clusters, &settings)?;
//! let depth = prepared.record_depth(recorder);
//! prepared.record(recorder, depth);
//! # Ok(()) }
//! ```

use manylights_cluster::{
    ClusterView, ClusteringSettings, GpuClusters, LightLoop, ListsBuilt, PreparedAssignment,
    ShadingOutput, blended_program,
};
use manylights_gpu::{
    DepthConvention, GpuContext, GpuResult, GpuScene, HDR_FORMAT, PassName, PipelineKey, Program,
    ScenePipelineDesc, ShaderLibrary, ShaderModules, Specialized, ViewBinding, shader_files, wgpu,
};
use manylights_lights::{BoundedFalloff, Shading};
use manylights_pipeline::{
    BlendedPass, DepthRecorded, EarlyDepth, FrameInputs, FrameRecorder, LIGHTING_GROUP,
    PipelineBuild, PreparedBlended, PreparedShading, ShadingPipeline,
};
use manylights_visibility::{FORWARD_TARGETS, ShadowFilter};

/// The depth pre-pass's timed name.
pub const DEPTH_PREPASS: PassName = PassName::new("depth pre-pass");
/// The shading pass's timed name.
pub const SHADING_PASS: PassName = PassName::new("forward+ shading");
/// The timed name of the pass drawing a cluster debug view.
pub const DEBUG_VIEW_PASS: PassName = PassName::new("cluster debug view");

/// This crate's WGSL.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "forward_plus",
    files: shader_files!["forward_plus/forward_plus.wgsl"],
    uses: &[&manylights_cluster::SHADERS],
    constants: manylights_gpu::no_constants,
};

/// The Forward+ program running `light_loop`: depth pre-pass, shading and cluster views
/// (composed per material variant of the scene). A shading loop with one shadow ray a
/// pixel keeps it for the shadow pass (`SHADOW_PASS`, entry `fs_shadow_pass`).
pub fn program(light_loop: LightLoop) -> Program {
    let program = Program::shading_materials(
        format!("forward_plus ({})", light_loop.label()),
        &SHADERS,
        "forward_plus/forward_plus.wgsl",
    )
    .with_defs(light_loop.shader_defs());
    if uses_shadow_pass(light_loop) {
        program.with_def("SHADOW_PASS", manylights_gpu::ShaderDef::Bool(true))
    } else {
        program
    }
}

/// Whether `light_loop` shades the image with one shadow ray a pixel, which the shadow
/// pass traces after the shading pass (`visibility::ShadowFilter::record_traced`).
fn uses_shadow_pass(light_loop: LightLoop) -> bool {
    light_loop.shades() && light_loop.shadows().in_shadow_pass()
}

/// Every program of this crate: every material variant, with loops covering every falloff,
/// far field and output (what `cargo xtask validate-shaders` validates).
pub fn programs() -> Vec<Program> {
    let outputs: Vec<ShadingOutput> = std::iter::once(ShadingOutput::Shaded)
        .chain(ClusterView::ALL.map(ShadingOutput::Cluster))
        .collect();
    LightLoop::covering(&outputs)
        .into_iter()
        .map(program)
        .chain([program(
            LightLoop::plain().with_shadows(manylights_visibility::Shadows::Rays(1)),
        )])
        .collect()
}

/// What a Forward+ frame can vary.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
// Fields missing from a serialized pipeline are the defaults: a frame's settings can
// switch pipelines by naming another `kind`.
#[serde(default)]
pub struct ForwardPlusSettings {
    /// A falloff with a radius: lights are culled by it.
    pub falloff: BoundedFalloff,
    /// Lay down depth first so hidden fragments are not shaded.
    pub depth_prepass: bool,
    /// A cluster view instead of the shaded image.
    pub debug_view: Option<ClusterView>,
    /// The light lists' grid, assignment and far field.
    pub clustering: ClusteringSettings,
}

impl Default for ForwardPlusSettings {
    fn default() -> Self {
        Self {
            falloff: BoundedFalloff::default(),
            depth_prepass: true,
            debug_view: None,
            clustering: ClusteringSettings::default(),
        }
    }
}

type Pipelines = Vec<(PipelineKey, wgpu::RenderPipeline)>;

/// What a Forward+ pipeline set is drawn with: a fragment entry, its colour targets, its
/// depth state and the targets' samples a pixel.
struct PassShape<'a> {
    label: &'a str,
    fragment: &'a str,
    targets: &'a [Option<wgpu::ColorTargetState>],
    depth_write: bool,
    depth_compare: wgpu::CompareFunction,
    samples: u32,
}

/// What the shading pipelines are specialized for: the light loop, whether the pre-pass
/// laid down depth, and the targets' samples a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct ShadeKey {
    light_loop: LightLoop,
    after_prepass: bool,
    samples: u32,
}

/// The Forward+ pipelines for one uploaded scene.
#[derive(Debug)]
pub struct ForwardPlusPipeline {
    library: ShaderLibrary,
    depth: DepthConvention,
    /// The depth pre-pass's pipelines, by the targets' samples a pixel.
    depth_prepass: Specialized<u32, Pipelines>,
    /// The shading pipelines, built the first time a frame asks for their key.
    shade: Specialized<ShadeKey, Pipelines>,
    /// Group 3: the frame's lighting binding's layout (`FrameLighting`).
    lighting_layout: wgpu::BindGroupLayout,
    /// The BRDF its programs shade with.
    brdf: Shading,
    /// The shadow pass and its filter, made on the first frame with one ray a pixel.
    shadow_pass: Option<ShadowFilter>,
    /// Blended surfaces, shaded forward after the opaque frame.
    blended: BlendedPass<LightLoop>,
}

/// The depth pre-pass's pipelines' shape.
fn depth_only(depth: DepthConvention, samples: u32) -> PassShape<'static> {
    PassShape {
        label: "forward+ depth pre-pass",
        fragment: "fs_depth",
        targets: &[],
        depth_write: true,
        depth_compare: depth.nearer(),
        samples,
    }
}

/// What builds a set of Forward+ pipelines (one per material key of the scene).
struct PipelineMaker<'a> {
    library: &'a ShaderLibrary,
    /// The lists' group (3), which every program of this crate declares.
    lists_layout: &'a wgpu::BindGroupLayout,
    gpu: &'a GpuContext,
    scene: &'a GpuScene,
    view: &'a ViewBinding,
}

impl PipelineMaker<'_> {
    /// One pipeline per material key of the scene, with `light_loop`'s program.
    fn build(&self, shape: &PassShape, light_loop: LightLoop) -> GpuResult<Pipelines> {
        let program = program(light_loop);
        self.scene
            .pipeline_keys()
            .into_iter()
            .map(|key| {
                // Opaque depth-only pipelines need no fragment stage at all.
                let fragment_entry = if shape.fragment == "fs_depth" && !key.alpha_mask {
                    None
                } else {
                    Some(shape.fragment)
                };
                let desc = ScenePipelineDesc {
                    label: shape.label,
                    program: &program,
                    key,
                    view_layout: &self.view.layout,
                    extra_layouts: &[self.lists_layout],
                    vertex_entry: "vs_main",
                    fragment_entry,
                    color_targets: shape.targets,
                    depth_write: shape.depth_write,
                    depth_compare: shape.depth_compare,
                    pulls_vertices: false,
                    samples: shape.samples,
                };
                Ok((
                    key,
                    self.scene.create_pipeline(self.gpu, self.library, &desc)?,
                ))
            })
            .collect()
    }

    /// The shading pass's pipelines for `key`.
    fn shading(&self, key: ShadeKey, depth: DepthConvention) -> GpuResult<Pipelines> {
        let hdr = [Some(HDR_FORMAT.into())];
        let shadow_pass_targets = FORWARD_TARGETS.map(|format| Some(format.into()));
        let (fragment, targets): (_, &[_]) = if uses_shadow_pass(key.light_loop) {
            ("fs_shadow_pass", &shadow_pass_targets)
        } else {
            ("fs_main", &hdr)
        };
        let label = format!("forward+ shading ({})", key.light_loop.label());
        // After the pre-pass the depth is laid down: the shading pass only tests it.
        let (depth_write, depth_compare) = if key.after_prepass {
            (false, depth.nearer_or_equal())
        } else {
            (true, depth.nearer())
        };
        let shape = PassShape {
            label: &label,
            fragment,
            targets,
            depth_write,
            depth_compare,
            samples: key.samples,
        };
        self.build(&shape, key.light_loop)
    }
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
    type Prepared<'a> = ForwardPlusFrame<'a>;
    const NAME: &'static str = "Forward+";

    fn new(build: &PipelineBuild) -> GpuResult<Self> {
        let mut pipeline = Self {
            library: build.library.clone(),
            depth: build.depth,
            depth_prepass: Specialized::default(),
            shade: Specialized::default(),
            lighting_layout: build.lighting_layout.clone(),
            brdf: build.shading,
            shadow_pass: None,
            blended: BlendedPass::new(build.library, build.depth),
        };
        // Built now, so that a scene whose shaders fail is refused when it loads. The
        // pre-pass never runs the light loop: any loop composes it.
        let maker = PipelineMaker {
            library: &pipeline.library,
            lists_layout: &pipeline.lighting_layout,
            gpu: build.gpu,
            scene: build.scene,
            view: build.view,
        };
        pipeline.depth_prepass.get_or_build(1, |samples| {
            maker.build(&depth_only(build.depth, samples), LightLoop::plain())
        })?;
        Ok(pipeline)
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

    fn prepare<'a>(
        &'a mut self,
        frame: &FrameInputs,
        lists: &'a GpuClusters,
        settings: &ForwardPlusSettings,
    ) -> GpuResult<ForwardPlusFrame<'a>> {
        let output = settings
            .debug_view
            .map_or(ShadingOutput::Shaded, ShadingOutput::Cluster);
        // The pre-pass programs share the lighting layout (group 3), which they do not
        // read: the lists are not built yet when it runs.
        let bind_group = frame.lighting.group.clone();
        let light_loop = LightLoop::for_frame(
            lists,
            frame.lighting.light_kinds,
            self.brdf,
            frame.scene.features.specular,
            settings.falloff.into(),
            output,
            // The shadow pass filters: the loop traces or keeps its rays unfiltered.
            frame.shadow_route.loop_shadows(),
        );
        let prepass = Self::uses_prepass(settings);
        let shadow_pass = frame.shadow_route.in_shadow_pass();
        let samples = frame.targets.samples();
        let maker = PipelineMaker {
            library: &self.library,
            lists_layout: &self.lighting_layout,
            gpu: frame.gpu,
            scene: frame.scene,
            view: frame.view,
        };
        let depth = self.depth;
        let depth_prepass = &*self.depth_prepass.get_or_build(samples, |samples| {
            maker.build(&depth_only(depth, samples), LightLoop::plain())
        })?;
        let shade_key = ShadeKey {
            light_loop,
            after_prepass: prepass,
            samples,
        };
        let shade = &*self
            .shade
            .get_or_build(shade_key, |key| maker.shading(key, depth))?;
        ShadowFilter::prepare_slot(
            &mut self.shadow_pass,
            shadow_pass,
            frame.shadow_pass(&self.library),
        )?;
        let blended = match light_loop.for_blended() {
            Some(blended_loop) => {
                self.blended
                    .prepare(frame, &self.lighting_layout, blended_loop, blended_program)?
            }
            None => None,
        };
        Ok(ForwardPlusFrame {
            assignment: lists.assignment()?,
            prepass: prepass.then_some(depth_prepass),
            blended,
            shade,
            shadow_pass: self.shadow_pass.as_ref().filter(|_| shadow_pass),
            bind_group,
            name: match settings.debug_view {
                None => SHADING_PASS,
                Some(_) => DEBUG_VIEW_PASS,
            },
            depth: self.depth,
        })
    }
}

/// A Forward+ frame, prepared: the pre-pass's pipelines (when on), the shading pipelines of
/// its light loop and the lists' group both bind.
#[derive(Debug)]
pub struct ForwardPlusFrame<'a> {
    /// The light assignment, recorded between the pre-pass and the shading.
    assignment: PreparedAssignment<'a>,
    prepass: Option<&'a Pipelines>,
    shade: &'a Pipelines,
    /// With one shadow ray a pixel: the shadow pass, whose targets the shading pass writes.
    shadow_pass: Option<&'a ShadowFilter>,
    /// The blended surfaces, drawn last.
    blended: Option<PreparedBlended<'a>>,
    bind_group: wgpu::BindGroup,
    /// The shading pass's timed name (a debug view's, under one).
    name: PassName,
    depth: DepthConvention,
}

impl ForwardPlusFrame<'_> {
    fn draw(
        &self,
        frame: &mut FrameRecorder,
        pipelines: &Pipelines,
        mut pass: wgpu::RenderPass<'_>,
    ) {
        pass.set_bind_group(0, &frame.view.bind_group, &[]);
        pass.set_bind_group(LIGHTING_GROUP, &self.bind_group, &[]);
        for (key, pipeline) in pipelines {
            pass.set_pipeline(pipeline);
            frame.scene.draw(&mut pass, *key);
        }
    }
}

impl PreparedShading for ForwardPlusFrame<'_> {
    /// The depth pre-pass (when on): the depth of the visible surfaces, which the
    /// assignment bounds the clusters by.
    fn record_depth_passes(&self, frame: &mut FrameRecorder) {
        let Some(prepass) = self.prepass else {
            return;
        };
        let pass = frame
            .encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("forward+ depth pre-pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(manylights_gpu::binding::depth_attachment(
                    frame.targets.depth_view(),
                    wgpu::LoadOp::Clear(self.depth.clear_value()),
                )),
                timestamp_writes: frame.timer.render_pass(DEPTH_PREPASS),
                occlusion_query_set: None,
                multiview_mask: None,
            })
            .forget_lifetime();
        self.draw(frame, prepass, pass);
    }

    /// The light assignment, then the shading.
    fn record(&self, frame: &mut FrameRecorder, _depth: DepthRecorded) {
        let lists = self
            .assignment
            .record(frame.encoder, frame.view, Some(&mut *frame.timer));
        self.record_shading(frame, lists);
    }
}

impl ForwardPlusFrame<'_> {
    /// The shading (or debug) pass into the HDR target, after the pre-pass if on; with one
    /// shadow ray a pixel, into the shadow pass's targets, then the shadow pass.
    fn record_shading(&self, frame: &mut FrameRecorder, _lists: ListsBuilt) {
        let depth_load = match self.prepass {
            Some(_) => wgpu::LoadOp::Load,
            None => wgpu::LoadOp::Clear(self.depth.clear_value()),
        };
        let hdr = [frame
            .targets
            .hdr_attachment(wgpu::LoadOp::Clear(wgpu::Color::BLACK))];
        let shadow_targets = self.shadow_pass.and_then(ShadowFilter::forward_attachments);
        let color_attachments = match &shadow_targets {
            Some(targets) => targets.as_slice(),
            None => hdr.as_slice(),
        };
        let pass = frame
            .encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(self.name.as_str()),
                color_attachments,
                depth_stencil_attachment: Some(manylights_gpu::binding::depth_attachment(
                    frame.targets.depth_view(),
                    depth_load,
                )),
                timestamp_writes: frame.timer.render_pass(self.name),
                occlusion_query_set: None,
                multiview_mask: None,
            })
            .forget_lifetime();
        self.draw(frame, self.shade, pass);
        if let Some(shadow_pass) = self.shadow_pass {
            shadow_pass.record_traced(frame.encoder, frame.timer, frame.view);
        }
        if let Some(blended) = &self.blended {
            blended.record(frame);
        }
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
