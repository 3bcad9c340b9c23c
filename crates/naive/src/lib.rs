//! Naive forward shading (`shaders/naive/naive.wgsl`): every fragment of the scene loops
//! over every light. Its cost grows with pixels x lights, but it is exact for every falloff,
//! including the unbounded inverse-square one, so the lab uses it as the GPU reference.
//!
//! The pipeline set comes from the scene's features: one pipeline per `PipelineKey` the
//! scene's draws use (opaque ones without discard keep early depth testing), each built
//! from the `MaterialVariant` for the scene (no texture or normal-map sampling unless the
//! scene has them). The falloff is a constant of the program (`NAIVE_FALLOFF`), not a
//! branch in the loop: a set per falloff, built when a frame first asks for it.
//!
//! ```no_run
//! use manylights_naive::{NaivePipeline, NaiveSettings};
//! use manylights_pipeline::{
//!     EveryLight, FrameInputs, FrameRecorder, PipelineBuild, PreparedShading, ShadingPipeline,
//! };
//! # fn frame(build: &PipelineBuild, inputs: &FrameInputs, recorder: &mut FrameRecorder) -> manylights_gpu::GpuResult<()> {
//! let mut pipeline = NaivePipeline::new(build)?; // once per scene
//! let prepared = pipeline.prepare(inputs, &EveryLight, &NaiveSettings::default())?; // every frame
//! let depth = prepared.record_depth(recorder); // nothing: naive draws depth as it shades
//! prepared.record(recorder, depth);
//! # Ok(()) }
//! ```

use manylights_gpu::{
    DepthConvention, GpuResult, HDR_FORMAT, PassName, PipelineKey, Program, ScenePipelineDesc,
    ShaderDef, ShaderLibrary, ShaderModules, Specialized, shader_files, wgpu,
};
use manylights_lights::{Falloff, Shading};
use manylights_pipeline::{
    BlendedPass, DepthRecorded, EveryLight, FrameInputs, FrameRecorder, LIGHTING_GROUP,
    PipelineBuild, PreparedBlended, PreparedShading, ShadingPipeline,
};
use manylights_visibility::{FORWARD_TARGETS, ShadowFilter, Shadows};

/// What a naive frame can vary.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[derive(serde::Serialize, serde::Deserialize)]
// Fields missing from a serialized pipeline are the defaults: a frame's settings can
// switch pipelines by naming another `kind`.
#[serde(default)]
pub struct NaiveSettings {
    /// Any falloff, the unbounded inverse-square one included: every light is evaluated.
    /// With the frame's shadows (the frame's `ShadowSettings`) every light that adds to a
    /// pixel gets a shadow ray: the GPU's ground truth (one ray per light per pixel).
    pub falloff: Falloff,
}

/// The naive forward pass's timed name.
pub const NAIVE_PASS: PassName = PassName::new("naive forward");

/// This crate's WGSL.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "naive",
    files: shader_files!["naive/naive.wgsl"],
    uses: &[&manylights_lights::SHADERS, &manylights_visibility::SHADERS],
    constants: manylights_gpu::no_constants,
};

/// The naive forward program with `falloff`, `shadows` and `shading`'s BRDF (composed per
/// material variant of the scene).
pub fn program(falloff: Falloff, shadows: Shadows, shading: Shading) -> Program {
    let program = Program::shading_materials(
        format!("naive ({falloff}, shadows {shadows}, {shading})"),
        &SHADERS,
        "naive/naive.wgsl",
    )
    .with_def("NAIVE_FALLOFF", ShaderDef::UInt(falloff.shader_mode()))
    .with_shading(shading);
    program.with_defs(shadows.forward_shader_defs())
}

/// The shadow modes `programs` validates: the ray budgets differ in a constant only.
/// The program of naive's blended surfaces (entry `fs_blended`): `shadows` traced in the
/// fragment shader, unfiltered (the shadow pass and its filter read the opaque surface).
pub fn blended_program(falloff: Falloff, shadows: Shadows, shading: Shading) -> Program {
    Program::shading_materials(
        format!("naive blended ({falloff}, shadows {shadows}, {shading})"),
        &SHADERS,
        "naive/naive.wgsl",
    )
    .with_def("NAIVE_FALLOFF", ShaderDef::UInt(falloff.shader_mode()))
    .with_shading(shading)
    .with_defs(shadows.unfiltered().shader_defs())
}

const SHADOW_MODES: [Shadows; 4] = [
    Shadows::Off,
    Shadows::Exact,
    Shadows::Rays(1),
    Shadows::Rays(4),
];

/// Every program of this crate, in every falloff, shadow mode, shading and material
/// variant (what `cargo xtask validate-shaders` validates).
pub fn programs() -> Vec<Program> {
    Falloff::ALL
        .into_iter()
        .flat_map(|falloff| SHADOW_MODES.map(|shadows| (falloff, shadows)))
        .flat_map(|(falloff, shadows)| {
            Shading::ALL.map(|shading| program(falloff, shadows, shading))
        })
        .chain([blended_program(
            Falloff::default(),
            Shadows::Rays(1),
            Shading::default(),
        )])
        .collect()
}

type Pipelines = Vec<(PipelineKey, wgpu::RenderPipeline)>;

/// The naive forward pipelines for one uploaded scene.
#[derive(Debug)]
pub struct NaivePipeline {
    library: ShaderLibrary,
    depth: DepthConvention,
    shading: Shading,
    /// The opaque surfaces' pipelines, built the first time a frame asks for their key.
    pipelines: Specialized<ShadeKey, Pipelines>,
    /// The blended surfaces, drawn over the opaque frame with the same loop (its falloff
    /// and shadows).
    blended: BlendedPass<(Falloff, Shadows)>,
    /// Group 3: the frame's lighting binding's layout ([`FrameLighting`]).
    lighting_layout: wgpu::BindGroupLayout,
    /// The shadow pass and its filter, made on the first frame with one ray a pixel.
    shadow_pass: Option<ShadowFilter>,
}

/// What the opaque pipelines are specialized for: the falloff, the (unfiltered) shadows
/// and the targets' samples a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct ShadeKey {
    falloff: Falloff,
    shadows: Shadows,
    samples: u32,
}

/// A naive frame, prepared: the pipelines of its falloff and shadows, and its lights' group.
#[derive(Debug)]
pub struct NaiveFrame<'a> {
    pipelines: &'a Pipelines,
    /// The blended surfaces' draws (none without blended surfaces).
    blended: Option<PreparedBlended<'a>>,
    /// With one shadow ray a pixel: the shadow pass, whose targets the shading pass writes.
    shadow_pass: Option<&'a ShadowFilter>,
    /// The frame's lighting binding.
    lighting: wgpu::BindGroup,
    depth: DepthConvention,
}

impl PreparedShading for NaiveFrame<'_> {
    /// The forward pass: clears HDR colour and depth, draws the scene shaded by every light.
    fn record(&self, frame: &mut FrameRecorder, _depth: DepthRecorded) {
        let hdr = [frame
            .targets
            .hdr_attachment(wgpu::LoadOp::Clear(wgpu::Color::BLACK))];
        let shadow_targets = self.shadow_pass.and_then(ShadowFilter::forward_attachments);
        let color_attachments = match &shadow_targets {
            Some(targets) => targets.as_slice(),
            None => hdr.as_slice(),
        };
        let mut pass = frame
            .encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("naive forward"),
                color_attachments,
                depth_stencil_attachment: Some(manylights_gpu::binding::depth_attachment(
                    frame.targets.depth_view(),
                    wgpu::LoadOp::Clear(self.depth.clear_value()),
                )),
                timestamp_writes: frame.timer.render_pass(NAIVE_PASS),
                occlusion_query_set: None,
                multiview_mask: None,
            });
        pass.set_bind_group(0, &frame.view.bind_group, &[]);
        pass.set_bind_group(LIGHTING_GROUP, &self.lighting, &[]);
        for (key, pipeline) in self.pipelines {
            pass.set_pipeline(pipeline);
            frame.scene.draw(&mut pass, *key);
        }
        drop(pass);
        if let Some(shadow_pass) = self.shadow_pass {
            shadow_pass.record_traced(frame.encoder, frame.timer, frame.view);
        }
        if let Some(blended) = &self.blended {
            blended.record(frame);
        }
    }
}

impl ShadingPipeline for NaivePipeline {
    type Settings = NaiveSettings;
    type LightLists = EveryLight;
    type Prepared<'a> = NaiveFrame<'a>;
    const NAME: &'static str = "naive forward";

    fn new(build: &PipelineBuild) -> GpuResult<Self> {
        Ok(Self {
            library: build.library.clone(),
            depth: build.depth,
            shading: build.shading,
            pipelines: Specialized::default(),
            blended: BlendedPass::new(build.library, build.depth),
            lighting_layout: build.lighting_layout.clone(),
            shadow_pass: None,
        })
    }

    fn shows_debug_view(_: &NaiveSettings) -> bool {
        false
    }

    fn prepare<'a>(
        &'a mut self,
        frame: &FrameInputs,
        _: &EveryLight,
        settings: &NaiveSettings,
    ) -> GpuResult<NaiveFrame<'a>> {
        // The shadow pass filters: the program traces or keeps its rays unfiltered.
        let shade_key = ShadeKey {
            falloff: settings.falloff,
            shadows: frame.shadow_route.loop_shadows(),
            samples: frame.targets.samples(),
        };
        let maker = PipelineMaker {
            library: &self.library,
            lights_layout: &self.lighting_layout,
            depth: self.depth,
            brdf: self.shading,
            frame,
        };
        let pipelines = &*self
            .pipelines
            .get_or_build(shade_key, |key| maker.opaque(key))?;
        let brdf = self.shading;
        let blended = self.blended.prepare(
            frame,
            &self.lighting_layout,
            (shade_key.falloff, shade_key.shadows),
            |(falloff, shadows)| blended_program(falloff, shadows, brdf),
        )?;
        let shadow_pass = frame.shadow_route.in_shadow_pass();
        ShadowFilter::prepare_slot(
            &mut self.shadow_pass,
            shadow_pass,
            frame.shadow_pass(&self.library),
        )?;
        Ok(NaiveFrame {
            pipelines,
            blended,
            shadow_pass: self.shadow_pass.as_ref().filter(|_| shadow_pass),
            lighting: frame.lighting.group.clone(),
            depth: self.depth,
        })
    }
}

/// What builds naive's pipelines for one frame's scene and view.
struct PipelineMaker<'a> {
    library: &'a ShaderLibrary,
    /// Group 3: the frame's lighting binding's layout.
    lights_layout: &'a wgpu::BindGroupLayout,
    depth: DepthConvention,
    brdf: Shading,
    frame: &'a FrameInputs<'a>,
}

impl PipelineMaker<'_> {
    /// One pipeline per material key of the scene, shading with the key's falloff and
    /// shadows.
    fn opaque(&self, key: ShadeKey) -> GpuResult<Pipelines> {
        let hdr = [Some(HDR_FORMAT.into())];
        let shadow_pass_targets = FORWARD_TARGETS.map(|format| Some(format.into()));
        let (fragment, targets): (_, &[_]) = if key.shadows.in_shadow_pass() {
            ("fs_shadow_pass", &shadow_pass_targets)
        } else {
            ("fs_main", &hdr)
        };
        let program = program(key.falloff, key.shadows, self.brdf);
        let scene = self.frame.scene;
        scene
            .pipeline_keys()
            .into_iter()
            .map(|material| {
                let desc = ScenePipelineDesc {
                    label: "naive forward",
                    program: &program,
                    key: material,
                    view_layout: &self.frame.view.layout,
                    extra_layouts: &[self.lights_layout],
                    vertex_entry: "vs_main",
                    fragment_entry: Some(fragment),
                    color_targets: targets,
                    depth_write: true,
                    depth_compare: self.depth.nearer(),
                    pulls_vertices: false,
                    samples: key.samples,
                };
                Ok((
                    material,
                    scene.create_pipeline(self.frame.gpu, self.library, &desc)?,
                ))
            })
            .collect()
    }
}

#[cfg(test)]
mod layout_tests {
    use super::program;
    use manylights_gpu::assert_wgsl_layout;
    use manylights_pipeline::LightingUniform;

    #[test]
    fn lighting_uniform_matches_wgsl() {
        assert_wgsl_layout!(
            program(Default::default(), Default::default(), Default::default()),
            "naive/naive.wgsl",
            LightingParams
                == LightingUniform {
                    heatmap_max: heatmap_max,
                    light_count: light_count,
                    _pad0: _pad,
                    _pad1: _pad + 4,
                }
        );
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
