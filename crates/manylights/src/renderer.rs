//! `Renderer`: owns the GPU context, the uploaded scene, the lights and the pipelines, and
//! renders frames as a sequence: animate lights -> shade (the chosen pipeline) -> post.

use manylights_gpu::{
    GpuContext, GpuError, GpuScene, GpuTimer, GpuTimings, RenderTargets, ShaderLibrary,
    SurfaceImage, SurfacePass, Tonemap, TonemapPass, ViewBinding, ViewUniform,
};
use manylights_lights::{
    AnimationParams, Falloff, GpuLights, LightAnimator, LightSet, LightSettings, PointLight,
    RadiusMode,
};
use manylights_naive::NaivePipeline;

use crate::camera::Camera;
use crate::scenes::LoadedScene;

/// Which shading pipeline renders the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum PipelineKind {
    /// Every fragment loops over every light.
    #[default]
    Naive,
}

/// Default light intensity: radiance 0.2 at 1 m (1000 lights light Sponza without
/// saturating the ACES curve at exposure 1).
pub const DEFAULT_INTENSITY: f32 = 0.2;
/// Default luminance threshold: with the default intensity, radius = sqrt(0.2 / 0.05) = 2 m,
/// the reference projects' radius in Sponza.
pub const DEFAULT_THRESHOLD: f32 = 0.05;

/// Everything that decides a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSettings {
    pub pipeline: PipelineKind,
    pub camera: Camera,
    /// Width x height in pixels.
    pub size: (u32, u32),
    pub light_count: u32,
    pub seed: u32,
    pub intensity: f32,
    pub radius: RadiusMode,
    /// Animation time in seconds (a fixed step gives reproducible frames).
    pub time: f32,
    /// Light motion speed and wander; `None` uses the scene's default.
    pub animation: Option<(f32, f32)>,
    pub falloff: Falloff,
    pub exposure: f32,
    pub tonemap: Tonemap,
}

impl FrameSettings {
    /// Defaults for a scene: its first camera preset, 1280x720, 1000 lights.
    pub fn for_scene(scene: &LoadedScene) -> Self {
        Self {
            pipeline: PipelineKind::Naive,
            camera: scene.default_camera(),
            size: (1280, 720),
            light_count: 1000,
            seed: 1,
            intensity: DEFAULT_INTENSITY,
            radius: RadiusMode::LuminanceThreshold(DEFAULT_THRESHOLD),
            time: 0.0,
            animation: None,
            falloff: Falloff::WindowedInverseSquare,
            exposure: 1.0,
            tonemap: Tonemap::AcesFit,
        }
    }
}

/// What a frame produced besides its image.
#[derive(Debug, Clone)]
pub struct FrameStats {
    pub timings: GpuTimings,
    pub light_count: u32,
}

/// Errors from rendering: bad settings or the GPU.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("invalid frame settings: {0}")]
    Settings(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// Passes the timer reserves room for per frame.
const TIMED_PASSES: u32 = 8;

/// Renders frames of one scene.
#[derive(Debug)]
pub struct Renderer {
    pub context: GpuContext,
    library: ShaderLibrary,
    pub scene: LoadedScene,
    gpu_scene: GpuScene,
    view: ViewBinding,
    animator: LightAnimator,
    naive: NaivePipeline,
    tonemap: TonemapPass,
    timer: GpuTimer,
    targets: Option<RenderTargets>,
    lights: Option<(LightSettings, GpuLights)>,
}

impl Renderer {
    pub fn new(context: GpuContext, scene: LoadedScene) -> Result<Self, RenderError> {
        let library = ShaderLibrary::Embedded;
        let gpu_scene = GpuScene::upload(&context, &scene.scene, &library)?;
        let view = ViewBinding::new(&context);
        let animator = LightAnimator::new(&context, &library)?;
        let naive = NaivePipeline::new(&context, &library, &gpu_scene, &view)?;
        let tonemap = TonemapPass::new(&context, &library)?;
        let timer = GpuTimer::new(&context, TIMED_PASSES);
        Ok(Self {
            context,
            library,
            scene,
            gpu_scene,
            view,
            animator,
            naive,
            tonemap,
            timer,
            targets: None,
            lights: None,
        })
    }

    fn light_settings(&self, settings: &FrameSettings) -> LightSettings {
        let mut animation = AnimationParams::in_box(self.scene.light_box);
        if let Some((speed, wander)) = settings.animation {
            animation.speed = speed;
            animation.wander = wander;
        }
        LightSettings {
            count: settings.light_count,
            seed: settings.seed,
            intensity: settings.intensity,
            radius: settings.radius,
            animation,
        }
    }

    /// Regenerates and uploads the lights when their settings changed.
    fn prepare_lights(&mut self, settings: &FrameSettings) -> Result<(), RenderError> {
        let wanted = self.light_settings(settings);
        if self
            .lights
            .as_ref()
            .is_some_and(|(current, _)| *current == wanted)
        {
            return Ok(());
        }
        let set = LightSet::generate(&wanted).map_err(|e| RenderError::Settings(e.to_string()))?;
        let uploaded = GpuLights::upload(&self.context, &set)?;
        self.lights = Some((wanted, uploaded));
        Ok(())
    }

    fn prepare_targets(&mut self, size: (u32, u32)) -> Result<(), RenderError> {
        if self.targets.as_ref().is_none_or(|t| t.size != size) {
            self.targets = Some(RenderTargets::new(&self.context, size)?);
        }
        Ok(())
    }

    fn update_view(&self, settings: &FrameSettings) {
        let camera = &settings.camera;
        let aspect = settings.size.0 as f32 / settings.size.1 as f32;
        self.view.update(
            &self.context,
            &ViewUniform::new(
                camera.view_matrix(),
                camera.projection(aspect),
                camera.position,
                settings.size,
                camera.near,
                camera.far,
            ),
        );
    }

    fn validate(settings: &FrameSettings) -> Result<(), RenderError> {
        settings.camera.validate().map_err(RenderError::Settings)?;
        if settings.size.0 == 0 || settings.size.1 == 0 {
            return Err(RenderError::Settings(format!(
                "size {}x{} is empty",
                settings.size.0, settings.size.1
            )));
        }
        if !settings.time.is_finite() || !settings.exposure.is_finite() || settings.exposure < 0.0 {
            return Err(RenderError::Settings(
                "time and exposure must be finite, exposure not negative".into(),
            ));
        }
        Ok(())
    }

    /// Renders one frame: animate lights, shade into HDR, tonemap into the output. Returns
    /// per-pass GPU times.
    pub fn render_frame(&mut self, settings: &FrameSettings) -> Result<FrameStats, RenderError> {
        Self::validate(settings)?;
        self.prepare_targets(settings.size)?;
        self.prepare_lights(settings)?;
        self.update_view(settings);
        let (Some(targets), Some((light_settings, lights))) = (&self.targets, &self.lights) else {
            return Err(RenderError::Settings("targets or lights missing".into()));
        };
        let context = &self.context;
        let timer = &mut self.timer;
        context.scoped("rendering a frame", || {
            timer.begin_frame();
            let mut encoder = context.device.create_command_encoder(&Default::default());
            // 1. Lights move (GPU compute).
            self.animator.record(
                context,
                &mut encoder,
                lights,
                light_settings,
                settings.time,
                timer.compute_pass("animate lights"),
            );
            // 2. Shade into the HDR target.
            match settings.pipeline {
                PipelineKind::Naive => self.naive.record(
                    context,
                    &mut encoder,
                    &self.gpu_scene,
                    &self.view,
                    lights,
                    settings.falloff,
                    targets,
                    timer.render_pass("naive forward"),
                ),
            }
            // 3. Post: exposure and tonemap into the output.
            self.tonemap.record(
                context,
                &mut encoder,
                targets,
                settings.exposure,
                settings.tonemap,
                timer.render_pass("tonemap"),
            );
            timer.resolve(&mut encoder);
            context.queue.submit([encoder.finish()]);
        })?;
        let timings = self.timer.read(&self.context)?;
        Ok(FrameStats {
            timings,
            light_count: lights.count,
        })
    }

    fn targets(&self) -> Result<&RenderTargets, RenderError> {
        self.targets
            .as_ref()
            .ok_or_else(|| RenderError::Settings("no frame rendered yet".into()))
    }

    /// The tonemapped output of the last frame.
    pub fn read_output(&self) -> Result<image::RgbaImage, RenderError> {
        Ok(manylights_gpu::targets::read_rgba8(
            &self.context,
            &self.targets()?.output.texture,
        )?)
    }

    /// The linear HDR radiance of the last frame, row-major.
    pub fn read_hdr(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        Ok(manylights_gpu::targets::read_f32_rgba(
            &self.context,
            &self.targets()?.hdr.texture,
        )?)
    }

    /// The lights as the GPU has them this frame (after animation).
    pub fn read_lights(&self) -> Result<Vec<PointLight>, RenderError> {
        let (_, lights) = self
            .lights
            .as_ref()
            .ok_or_else(|| RenderError::Settings("no lights yet".into()))?;
        Ok(lights.read(&self.context)?)
    }

    /// Full-precision surface attributes for the camera of `settings` (for the f64
    /// reference).
    pub fn capture_surface(&self, settings: &FrameSettings) -> Result<SurfaceImage, RenderError> {
        Self::validate(settings)?;
        self.update_view(settings);
        let pass = SurfacePass::new(&self.context, &self.library, &self.gpu_scene, &self.view)?;
        Ok(pass.capture(&self.context, &self.gpu_scene, &self.view, settings.size)?)
    }
}
