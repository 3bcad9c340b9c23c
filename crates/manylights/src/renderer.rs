//! `Renderer`: owns the GPU context, the uploaded scene, the lights and the pipelines, and
//! renders frames as a sequence: animate lights -> (clustered pipelines) assign lights ->
//! shade (the chosen [`ShadingPipeline`]) -> post.

use manylights_cluster::{
    AssignmentDesign, ClusterBoxes, ClusterFrame, ClusterGrid, ClusterSettings, ClusterStats,
    FarField, FarFieldMethod, GpuClusters, GpuListStatistics, PreparedStatistics, SpotCulling,
};
use manylights_deferred::{DeferredPipeline, GBufferLayout};
use manylights_forward_plus::ForwardPlusPipeline;
use manylights_gpu::DepthConvention;
use manylights_gpu::{
    Exposure, GpuContext, GpuError, GpuScene, GpuTimer, GpuTimings, PreparedTonemap, RenderTargets,
    ShaderLibrary, SurfaceImage, SurfacePass, Tonemap, TonemapPass, ViewBinding, ViewUniform,
    block_on, wgpu,
};
use manylights_lights::{
    AnimationParams, DEFAULT_SATURATION, Falloff, GpuLights, Light, LightAnimator, LightSet,
    LightSettings, PreparedAnimation, RadiusMode, SpotSettings,
};
use manylights_naive::NaivePipeline;
use manylights_pipeline::{
    EarlyDepth, FrameInputs, FrameRecorder, PipelineBuild, PreparedShading, ShadingPipeline,
};
use manylights_visibility::{GpuSceneBvh, SceneBvh, Shadows, VisibilityError};

use crate::budget::{BudgetAsk, BudgetChoice, BudgetController};
use crate::camera::Camera;
use crate::pipelines::{FrameLightLists, PipelineSettings};
use crate::scenes::LoadedScene;

/// Default light intensity: radiance 0.2 at 1 m (1000 lights light Sponza without
/// saturating the ACES curve at exposure 1).
pub const DEFAULT_INTENSITY: f32 = 0.2;
/// Default luminance threshold: with the default intensity, radius = sqrt(0.2 / 0.05) = 2 m,
/// the reference projects' radius in Sponza.
pub const DEFAULT_THRESHOLD: f32 = 0.05;

/// Everything that decides a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSettings {
    /// The shading pipeline and its own settings.
    pub pipeline: PipelineSettings,
    pub camera: Camera,
    /// Width x height in pixels.
    pub size: (u32, u32),
    pub light_count: u32,
    pub seed: u32,
    pub intensity: f32,
    pub radius: RadiusMode,
    /// Light colour saturation in [0, 1] (1: pure random hues, 0: white).
    pub light_saturation: f32,
    /// Which generated lights are spots, and their cones (the scene's own lights come
    /// from its file, whatever this says).
    pub spots: SpotSettings,
    /// Forward+/deferred: spot lights culled by their cone (default) or by their range
    /// sphere (to measure what the cone test saves).
    pub spot_culling: SpotCulling,
    /// Animation time in seconds (a fixed step gives reproducible frames).
    pub time: f32,
    /// Light motion speed and wander; `None` uses the scene's default.
    pub animation: Option<(f32, f32)>,
    /// A fixed exposure, or one chosen on the GPU from the frame's luminance histogram.
    pub exposure: Exposure,
    pub tonemap: Tonemap,
    /// Cluster grid (Forward+ and deferred).
    pub cluster: ClusterSettings,
    /// Forward+/deferred: how the GPU builds the light lists (the same lists either way;
    /// tile masks sort them all and are faster).
    pub assignment: AssignmentDesign,
    /// Forward+/deferred: the boxes lights are tested against: the visible samples' (when
    /// the pipeline lays depth down first), or the grid's.
    pub cluster_boxes: ClusterBoxes,
    /// Forward+/deferred: what lights add beyond their radius, approximated (the image then
    /// approaches the unbounded inverse-square one; see [`FrameSettings::set_falloff`]).
    /// `None`: lights end at their radius. Naive ignores it (it is exact).
    pub far_field: Option<FarField>,
    /// Compute [`ClusterStats`] on the GPU (a small compute pass; read back without
    /// stalling, so [`FrameStats::cluster_stats`] may describe an earlier frame).
    pub cluster_stats: bool,
    /// With `cluster_stats`: also the false-positive ratio (a GPU pass over the depth
    /// buffer that tests every listed light against the cluster's visible pixels).
    pub false_positives: bool,
    /// Camera-relative rendering (default): positions are expressed relative to the camera
    /// (in f64 on the CPU), so scenes far from the world origin keep their precision. Off
    /// renders in world space, as most engines do (for comparison).
    pub camera_relative: bool,
    /// Whether geometry blocks light: `Exact` traces a shadow ray for every light a pixel
    /// evaluates (every pipeline; the scene's BVH is built on the first such frame).
    pub shadows: Shadows,
    /// A GPU time per frame, in milliseconds, to stay within: the renderer shortens the
    /// generated lights' radius and, with a tree far field, the cut's slots (never beyond
    /// `radius` and the far field's slots) from the GPU times of the frames it has finished
    /// (`crate::budget`); [`FrameStats::radius`] and [`FrameStats::far_slots`] say what it
    /// chose. `None`: they are the asked ones.
    pub budget: Option<f32>,
}

impl FrameSettings {
    /// The far field when it is a light tree this frame cuts: a clustered pipeline's
    /// (whose slots a budget may move).
    pub fn tree_far_field(&self) -> Option<FarField> {
        self.far_field
            .filter(|far| far.method == FarFieldMethod::Tree && self.pipeline.needs_clusters())
    }

    /// The falloff the image has: the pipeline's, or inverse-square where a far field
    /// completes a clustered pipeline's windowed falloff.
    pub fn rendered_falloff(&self) -> Falloff {
        match self.far_field {
            Some(_) if self.pipeline.needs_clusters() => Falloff::InverseSquare,
            _ => self.pipeline.falloff(),
        }
    }

    /// Sets the falloff and the far field together (the CLI, the lab and the viewer). Naive
    /// renders any falloff exactly and has no far field. Forward+ and deferred render
    /// inverse-square only with a far field, and a far field only for inverse-square: it
    /// approximates what the windowed falloff leaves out beyond each radius, so windowed +
    /// far field = inverse-square.
    pub fn set_falloff(
        &mut self,
        falloff: Falloff,
        far_field: Option<FarField>,
    ) -> Result<(), String> {
        if let Some(far) = &far_field {
            far.validate()?;
        }
        if !self.pipeline.needs_clusters() {
            if far_field.is_some() {
                return Err(format!(
                    "the {} pipeline shades every light exactly: it has no far field",
                    self.pipeline.kind()
                ));
            }
            self.pipeline = self.pipeline.with_falloff(falloff)?;
            self.far_field = None;
            return Ok(());
        }
        match (falloff, far_field) {
            (Falloff::InverseSquare, Some(far)) => {
                self.pipeline = self.pipeline.with_falloff(Falloff::WindowedInverseSquare)?;
                self.far_field = Some(far);
            }
            (Falloff::InverseSquare, None) => {
                return Err(format!(
                    "the {} pipeline renders the unbounded inverse-square falloff only with a far field (lights are culled at their radius; the far field approximates the rest): add --far-field tree or --far-field stochastic",
                    self.pipeline.kind()
                ));
            }
            (bounded, Some(_)) => {
                return Err(format!(
                    "a far field completes the windowed falloff to the unbounded inverse-square one, so it renders `--falloff inverse-square` only (not `{bounded}`)"
                ));
            }
            (bounded, None) => {
                self.pipeline = self.pipeline.with_falloff(bounded)?;
                self.far_field = None;
            }
        }
        Ok(())
    }

    /// Defaults for a scene: its first camera preset, 1280x720, 1000 lights, clustered
    /// deferred (compact G-buffer, compute lighting), vivid light colours and a fixed
    /// exposure of 1 (the viewer and `render` switch on automatic exposure; accuracy
    /// comparisons keep one fixed exposure so it can neither hide nor create error).
    pub fn for_scene(scene: &LoadedScene) -> Self {
        Self {
            pipeline: PipelineSettings::default(),
            camera: scene.default_camera(),
            size: (1280, 720),
            light_count: 1000,
            seed: 1,
            intensity: DEFAULT_INTENSITY,
            radius: RadiusMode::LuminanceThreshold(DEFAULT_THRESHOLD),
            light_saturation: DEFAULT_SATURATION,
            spots: SpotSettings::default(),
            spot_culling: SpotCulling::default(),
            time: 0.0,
            animation: None,
            exposure: Exposure::Manual(1.0),
            tonemap: Tonemap::AcesFit,
            cluster: ClusterSettings::default(),
            assignment: AssignmentDesign::default(),
            cluster_boxes: ClusterBoxes::default(),
            far_field: None,
            cluster_stats: false,
            false_positives: false,
            camera_relative: true,
            shadows: Shadows::Off,
            budget: None,
        }
    }
}

/// What a frame produced besides its image. Nothing here waited for the GPU: GPU results
/// are those of the newest frame it had finished (usually the one before).
#[derive(Debug, Clone)]
pub struct FrameStats {
    /// This frame's number (counting from 1 for the renderer's first frame).
    pub frame: u64,
    /// Per-pass GPU times of frame [`FrameStats::timed_frame`]
    /// ([`Renderer::render_frame_timed`] waits for this frame's).
    pub timings: GpuTimings,
    /// The frame `timings` belong to; `None` while no frame has finished.
    pub timed_frame: Option<u64>,
    pub light_count: u32,
    /// Forward+/deferred with `cluster_stats` on: the newest statistics the GPU has
    /// finished (usually this frame's; read back without waiting, so possibly an earlier
    /// frame's; [`Renderer::wait_cluster_stats`] waits for this frame's).
    pub cluster_stats: Option<ClusterStats>,
    /// Set when an earlier frame's light lists outgrew their buffer (that frame shaded the
    /// overflowing clusters from all lights, so it dropped nothing): the capacity, in list
    /// entries, the buffer grew to before this frame.
    pub list_capacity_grown_to: Option<u32>,
    /// The radius this frame's generated lights had: the settings' own, or with a budget
    /// the one the budget chose.
    pub radius: f32,
    /// With a tree far field, the most entries this frame's cuts held: the settings' own,
    /// or with a budget the budget's.
    pub far_slots: Option<u32>,
    /// With a budget: the newest frame it judged was over it with the radius and slots
    /// at their least, so no choice of them fits.
    pub budget_out_of_reach: bool,
}

/// Errors from rendering: bad settings or the GPU.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("invalid frame settings: {0}")]
    Settings(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("shadows for scene `{scene}`: {source}")]
    Shadows {
        scene: String,
        #[source]
        source: VisibilityError,
    },
}

impl RenderError {
    /// The device is gone: nothing renders until [`Renderer::recover_device`].
    pub fn is_device_lost(&self) -> bool {
        matches!(self, RenderError::Gpu(GpuError::DeviceLost { .. }))
    }
}

/// Where the frame's lights come from.
#[derive(Debug, Clone, PartialEq)]
enum LightSource {
    /// Generated from the frame settings and animated on the GPU.
    Generated(LightSettings),
    /// Given through [`Renderer::set_fixed_lights`]; never animated. Kept on the CPU too,
    /// to upload again after a device loss.
    Fixed(LightSet),
}

/// Frames the CPU may record ahead of the GPU. Without a bound a loop that never waits
/// (headless, or a window without vsync) queues work without limit, and memory with it (the
/// soak test caught 450 MiB a cycle on lavapipe); with it the CPU waits only when the GPU is
/// this many frames behind, never for the frame it just submitted.
pub const MAX_FRAMES_IN_FLIGHT: usize = 2;

/// The shading pipelines of one scene and depth convention, each built when a frame first
/// needs it.
#[derive(Debug, Default)]
struct Pipelines {
    naive: Option<NaivePipeline>,
    forward_plus: Option<ForwardPlusPipeline>,
    deferred: Option<DeferredPipeline>,
}

impl Pipelines {
    /// Builds the pipeline `settings` choose (unless built) and prepares its frame, handing
    /// it what its light-list type names from `clusters`.
    fn prepare<'a>(
        &'a mut self,
        build: &PipelineBuild,
        inputs: &FrameInputs,
        clusters: &GpuClusters,
        settings: &PipelineSettings,
    ) -> Result<Box<dyn PreparedShading + 'a>, GpuError> {
        match settings {
            PipelineSettings::Naive(s) => prepare_with(&mut self.naive, build, inputs, clusters, s),
            PipelineSettings::ForwardPlus(s) => {
                prepare_with(&mut self.forward_plus, build, inputs, clusters, s)
            }
            PipelineSettings::Deferred(s) => {
                prepare_with(&mut self.deferred, build, inputs, clusters, s)
            }
        }
    }

    /// Builds the pipeline `settings` choose, unless built (so that a scene whose shaders
    /// fail is refused when loaded, not at its first frame).
    fn build(
        &mut self,
        build: &PipelineBuild,
        settings: &PipelineSettings,
    ) -> Result<(), GpuError> {
        match settings {
            PipelineSettings::Naive(_) => built(&mut self.naive, build).map(|_| ()),
            PipelineSettings::ForwardPlus(_) => built(&mut self.forward_plus, build).map(|_| ()),
            PipelineSettings::Deferred(_) => built(&mut self.deferred, build).map(|_| ()),
        }
    }
}

fn built<'p, P: ShadingPipeline>(
    slot: &'p mut Option<P>,
    build: &PipelineBuild,
) -> Result<&'p mut P, GpuError> {
    if slot.is_none() {
        *slot = Some(P::new(build)?);
    }
    slot.as_mut()
        .ok_or_else(|| GpuError::Unsupported(format!("{} was not built", P::NAME)))
}

fn prepare_with<'a, P: ShadingPipeline>(
    slot: &'a mut Option<P>,
    build: &PipelineBuild,
    inputs: &FrameInputs,
    clusters: &GpuClusters,
    settings: &P::Settings,
) -> Result<Box<dyn PreparedShading + 'a>, GpuError>
where
    P::LightLists: FrameLightLists,
    P::Prepared<'a>: 'a,
{
    let pipeline: &'a mut P = built(slot, build)?;
    let lists = P::LightLists::from_clusters(clusters);
    let prepared: P::Prepared<'a> = P::prepare(pipeline, inputs, lists, settings)?;
    Ok(Box::new(prepared))
}

/// One frame, prepared: every pass's pipelines and bind groups built and its parameters
/// written. Recording replays it in the order of ARCHITECTURE's "a frame, step by step",
/// creating nothing.
struct PreparedFrame<'a> {
    /// Generated lights move (fixed lights stay where they were put).
    animation: Option<PreparedAnimation<'a>>,
    shading: Box<dyn PreparedShading + 'a>,
    /// Clustered pipelines: the assignment, prepared before the shading was.
    assignment: Option<&'a mut GpuClusters>,
    statistics: Option<PreparedStatistics<'a>>,
    post: PreparedTonemap<'a>,
}

impl PreparedFrame<'_> {
    /// Records the frame's passes, each timed by `timer`.
    fn record(
        self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        targets: &RenderTargets,
        timer: &mut GpuTimer,
    ) -> Result<wgpu::CommandBuffer, GpuError> {
        timer.begin_frame();
        let mut encoder = context.device.create_command_encoder(&Default::default());
        // 1. Lights move (GPU compute).
        if let Some(animation) = &self.animation {
            animation.record(&mut encoder, Some(&mut *timer));
        }
        let mut recorder = FrameRecorder {
            encoder: &mut encoder,
            timer,
            scene,
            view,
            targets,
        };
        // 2. The pipeline's depth (G-buffer, depth pre-pass), where it lays it down first.
        let depth = self.shading.record_depth(&mut recorder);
        // 3. Clustered pipelines: assign lights to clusters (bounded by the visible samples
        //    when the pipeline laid its depth down).
        if let Some(clusters) = self.assignment {
            clusters.record(recorder.encoder, view, Some(&mut *recorder.timer))?;
        }
        // 4. Shade into the HDR target.
        self.shading.record(&mut recorder, depth);
        // 5. Statistics of the light lists (after shading: false positives read the
        //    frame's depth buffer).
        if let Some(statistics) = self.statistics {
            statistics.record(recorder.encoder, view, Some(&mut *recorder.timer));
        }
        // 6. Post: exposure and tonemap into the output.
        self.post.record(recorder.encoder, recorder.timer);
        recorder.timer.resolve(recorder.encoder);
        Ok(encoder.finish())
    }
}

/// Renders frames of one scene.
#[derive(Debug)]
pub struct Renderer {
    context: GpuContext,
    library: ShaderLibrary,
    scene: LoadedScene,
    gpu_scene: GpuScene,
    view: ViewBinding,
    animator: LightAnimator,
    pipelines: Pipelines,
    /// The pipeline of the last frame (built eagerly when a scene is loaded).
    last_pipeline: PipelineSettings,
    clusters: GpuClusters,
    list_statistics: GpuListStatistics,
    /// The newest GPU list statistics read back.
    latest_cluster_stats: Option<ClusterStats>,
    /// The newest GPU timings read back, with their frame number.
    latest_timings: Option<(u64, GpuTimings)>,
    /// The submissions of the frames the GPU may still be working on, oldest first.
    frames_in_flight: std::collections::VecDeque<wgpu::SubmissionIndex>,
    tonemap: TonemapPass,
    timer: GpuTimer,
    targets: Option<RenderTargets>,
    lights: Option<(LightSource, GpuLights)>,
    /// The depth convention the pipelines were built for.
    depth: DepthConvention,
    /// The scene's BVH, on the CPU and the GPU: built on the first frame with shadows (or
    /// the first call of [`Renderer::scene_bvh`]), dropped with the scene.
    shadow_bvh: Option<(std::sync::Arc<SceneBvh>, GpuSceneBvh)>,
    /// An empty tree, bound where a frame traces no shadow rays.
    no_bvh: GpuSceneBvh,
    /// With a budget: the radius it chose (reset when the budget is turned off).
    budget: Option<BudgetController>,
}

impl Renderer {
    pub fn new(context: GpuContext, scene: LoadedScene) -> Result<Self, RenderError> {
        let library = ShaderLibrary::from_env();
        let gpu_scene = GpuScene::upload(&context, &scene.scene, &library)?;
        let view = ViewBinding::new(&context);
        let animator = LightAnimator::new(&context, &library)?;
        let depth = DepthConvention::Standard;
        let last_pipeline = PipelineSettings::default();
        let mut pipelines = Pipelines::default();
        pipelines.build(
            &PipelineBuild {
                gpu: &context,
                library: &library,
                scene: &gpu_scene,
                view: &view,
                depth,
            },
            &last_pipeline,
        )?;
        let clusters = GpuClusters::new(&context, &library, &view)?;
        let list_statistics = GpuListStatistics::new(&context, &library, &view)?;
        let tonemap = TonemapPass::new(&context, &library)?;
        let timer = GpuTimer::new(&context);
        let no_bvh = context
            .scoped("creating the empty BVH", || GpuSceneBvh::empty(&context))?
            .map_err(|source| RenderError::Shadows {
                scene: scene.name.clone(),
                source,
            })?;
        Ok(Self {
            shadow_bvh: None,
            no_bvh,
            budget: None,
            depth,
            context,
            library,
            scene,
            gpu_scene,
            view,
            animator,
            pipelines,
            last_pipeline,
            clusters,
            list_statistics,
            latest_cluster_stats: None,
            latest_timings: None,
            frames_in_flight: Default::default(),
            tonemap,
            timer,
            targets: None,
            lights: None,
        })
    }

    /// The GPU context frames render on.
    pub fn context(&self) -> &GpuContext {
        &self.context
    }

    /// The scene being rendered.
    pub fn scene(&self) -> &LoadedScene {
        &self.scene
    }

    /// After the device was lost: creates a new device (the adapter chosen again,
    /// compatible with `surface` when one is given) and rebuilds every GPU resource on it,
    /// keeping the scene and fixed lights; the next frame renders as the lost one would
    /// have. On error the renderer is unchanged (and still lost).
    pub fn recover_device(
        &mut self,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<(), RenderError> {
        let context = self.context.recreate(surface)?;
        let mut fresh = Renderer::new(context, self.scene.clone())?;
        if let Some((LightSource::Fixed(lights), _)) = &self.lights {
            fresh.set_fixed_lights(lights)?;
        }
        *self = fresh;
        Ok(())
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
            saturation: settings.light_saturation,
            animation,
            spots: settings.spots,
        }
    }

    /// Regenerates and uploads the lights when their settings changed (fixed lights stay).
    fn prepare_lights(&mut self, settings: &FrameSettings) -> Result<(), RenderError> {
        let wanted = self.light_settings(settings);
        match self.lights.as_mut() {
            Some((LightSource::Fixed(_), _)) => return Ok(()),
            Some((LightSource::Generated(current), _)) if *current == wanted => return Ok(()),
            // Only the radius moved (a budget moves it every frame) and the scene has no
            // lights of its own (their radii come from theirs): the animation pass writes
            // the generated lights' radius, so they stay.
            Some((LightSource::Generated(current), _))
                if LightSettings {
                    radius: wanted.radius,
                    ..*current
                } == wanted
                    && self.scene.scene.lights.is_empty() =>
            {
                wanted
                    .validate()
                    .map_err(|e| RenderError::Settings(e.to_string()))?;
                *current = wanted;
                return Ok(());
            }
            _ => {}
        }
        // Checked before the CPU generates them: an absurd count (4 billion lights, 128 GB)
        // is a clear error, not an allocation failure that aborts the process.
        let bytes = u64::from(wanted.count.max(1)) * std::mem::size_of::<Light>() as u64;
        self.context
            .check_buffer_size(&format!("{} lights", wanted.count), bytes, true)?;
        let mut set =
            LightSet::generate(&wanted).map_err(|e| RenderError::Settings(e.to_string()))?;
        // The scene's own lights after the generated ones: the animation moves only the
        // first `wanted.count`, so these stay where the file put them.
        set.extend(crate::scenes::scene_lights(
            &self.scene.scene,
            wanted.radius,
        ));
        let mut uploaded = GpuLights::upload(&self.context, &set)?;
        uploaded.animated = wanted.count;
        self.lights = Some((LightSource::Generated(wanted), uploaded));
        Ok(())
    }

    /// Renders with exactly these lights (not animated; the frame settings' light fields
    /// are ignored) until [`Renderer::use_generated_lights`]. Lights with NaN or infinite
    /// fields, negative intensity or a non-positive radius are refused with the reason.
    pub fn set_fixed_lights(&mut self, lights: &LightSet) -> Result<(), RenderError> {
        lights
            .validate()
            .map_err(|e| RenderError::Settings(e.to_string()))?;
        let uploaded = GpuLights::upload(&self.context, lights)?;
        self.lights = Some((LightSource::Fixed(lights.clone()), uploaded));
        Ok(())
    }

    /// Goes back to lights generated and animated from the frame settings.
    pub fn use_generated_lights(&mut self) {
        self.lights = None;
    }

    fn prepare_targets(&mut self, size: (u32, u32)) -> Result<(), RenderError> {
        if self.targets.as_ref().is_none_or(|t| t.size != size) {
            self.targets = Some(RenderTargets::new(&self.context, size)?);
        }
        Ok(())
    }

    /// Uploads the frame's camera, camera-relative: the scene's instances are moved so the
    /// camera is at the origin (computed in f64), the view is only a rotation, and lights
    /// are made relative in the shaders.
    fn update_view(&mut self, settings: &FrameSettings) {
        let camera = &settings.camera;
        let (origin, view) = if settings.camera_relative {
            (camera.position, camera.view_matrix_relative())
        } else {
            (glam::Vec3::ZERO, camera.view_matrix())
        };
        self.gpu_scene.set_origin(&self.context, origin.as_dvec3());
        let aspect = settings.size.0 as f32 / settings.size.1 as f32;
        let mut uniform = ViewUniform::new(
            view,
            camera.projection(aspect),
            camera.position - origin,
            settings.size,
            camera.near,
            camera.far,
        );
        // Shaders tell empty pixels by the clear depth.
        uniform.near_far[2] = camera.depth_convention().clear_value();
        uniform.origin = origin.extend(0.0).to_array();
        self.view.update(&self.context, &uniform);
    }

    fn validate(settings: &FrameSettings) -> Result<(), RenderError> {
        settings.camera.validate().map_err(RenderError::Settings)?;
        if settings.size.0 == 0 || settings.size.1 == 0 {
            return Err(RenderError::Settings(format!(
                "size {}x{} is empty",
                settings.size.0, settings.size.1
            )));
        }
        let exposure_ok = match settings.exposure {
            Exposure::Manual(value) => value.is_finite() && value >= 0.0,
            Exposure::Auto(auto) => {
                auto.compensation_ev.is_finite() && (0.0..=1.0).contains(&auto.adaptation)
            }
        };
        if let Some(far) = settings
            .far_field
            .filter(|_| settings.pipeline.needs_clusters())
        {
            far.validate().map_err(RenderError::Settings)?;
            if settings.pipeline.falloff() != Falloff::WindowedInverseSquare {
                return Err(RenderError::Settings(format!(
                    "a far field completes the windowed falloff, not `{}` (FrameSettings::set_falloff)",
                    settings.pipeline.falloff()
                )));
            }
        }
        if let Some(budget) = settings.budget.filter(|ms| !(ms.is_finite() && *ms > 0.0)) {
            return Err(RenderError::Settings(format!(
                "a frame-time budget must be a finite number of milliseconds above 0, got {budget}"
            )));
        }
        if !settings.time.is_finite() || !exposure_ok {
            return Err(RenderError::Settings(format!(
                "time must be finite, a fixed exposure finite and not negative, an automatic one's compensation finite and adaptation within 0..1 (time {}, exposure {:?})",
                settings.time, settings.exposure
            )));
        }
        Ok(())
    }

    /// The cluster grid for a frame: the scene's bounds in view space fit the depth range.
    pub fn cluster_grid(&self, settings: &FrameSettings) -> Result<ClusterGrid, RenderError> {
        let camera = &settings.camera;
        let aspect = settings.size.0 as f32 / settings.size.1 as f32;
        let scene_in_view = self.gpu_scene.bounds.transformed(&camera.view_matrix());
        ClusterGrid::new(
            &settings.cluster,
            settings.size,
            camera.projection(aspect),
            camera.near,
            camera.far,
            Some(scene_in_view),
        )
        .map_err(|e| RenderError::Settings(e.to_string()))
    }

    /// Renders one frame: animate lights, (clustered pipelines) assign them to clusters,
    /// shade into HDR, tonemap into the output. Returns per-pass GPU times.
    pub fn render_frame(&mut self, settings: &FrameSettings) -> Result<FrameStats, RenderError> {
        self.render_frame_checked(settings)
            .map_err(|error| match error {
                RenderError::Gpu(gpu) => RenderError::Gpu(self.context.explain(gpu)),
                settings_error => settings_error,
            })
    }

    fn render_frame_checked(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<FrameStats, RenderError> {
        self.context.check_device()?;
        Self::validate(settings)?;
        let budgeted;
        let choice = self.budget_choice(settings);
        let settings = match choice {
            Some(choice) => {
                budgeted = FrameSettings {
                    radius: RadiusMode::Fixed(choice.radius),
                    far_field: settings.far_field.map(|far| FarField {
                        slots: choice.far_slots.unwrap_or(far.slots),
                        ..far
                    }),
                    ..settings.clone()
                };
                &budgeted
            }
            None => settings,
        };
        self.use_depth_convention(settings.camera.depth_convention())?;
        self.prepare_targets(settings.size)?;
        self.prepare_lights(settings)?;
        if settings.shadows.traced() {
            self.scene_bvh()?;
        }
        self.update_view(settings);
        // Frame pacing: wait for the frame MAX_FRAMES_IN_FLIGHT back, if still running.
        while self.frames_in_flight.len() >= MAX_FRAMES_IN_FLIGHT {
            if let Some(oldest) = self.frames_in_flight.pop_front() {
                self.context
                    .wait_for_submission(oldest, "waiting for an earlier frame")?;
            }
        }
        let clustered = settings.pipeline.needs_clusters();
        let mut list_capacity_grown_to = None;
        if clustered {
            // Earlier frames' list totals, as far as the GPU got: grow if one overflowed.
            list_capacity_grown_to = self.clusters.grow_for_earlier_frames(&self.context)?;
            self.prepare_clusters(settings)?;
        }
        self.record_and_submit(settings)?;
        self.context.check_device()?;
        if let Some((frame, timings)) = self.timer.latest(&self.context)? {
            self.latest_timings = Some((frame, timings));
        }
        if clustered && settings.cluster_stats {
            if let Some(stats) = self.list_statistics.poll(&self.context)? {
                self.latest_cluster_stats = Some(stats);
            }
        } else {
            self.latest_cluster_stats = None;
        }
        Ok(FrameStats {
            frame: self.timer.frame(),
            timings: self
                .latest_timings
                .as_ref()
                .map_or(GpuTimings::Measured(Vec::new()), |(_, t)| t.clone()),
            timed_frame: self.latest_timings.as_ref().map(|(frame, _)| *frame),
            light_count: self.lights.as_ref().map_or(0, |(_, l)| l.count),
            cluster_stats: self.latest_cluster_stats.clone(),
            list_capacity_grown_to,
            radius: settings.radius.radius(settings.intensity),
            far_slots: settings.tree_far_field().map(|far| far.slots),
            budget_out_of_reach: choice.is_some_and(|choice| choice.out_of_reach),
        })
    }

    /// With a budget, the radius and slots this frame draws with (from the newest
    /// finished frame's GPU time); `None` without one.
    fn budget_choice(&mut self, settings: &FrameSettings) -> Option<BudgetChoice> {
        let Some(budget) = settings.budget else {
            self.budget = None;
            return None;
        };
        let ask = BudgetAsk {
            radius: settings.radius.radius(settings.intensity),
            far_slots: settings.tree_far_field().map(|far| far.slots),
        };
        let next_frame = self.timer.frame() + 1;
        let controller = self
            .budget
            .get_or_insert_with(|| BudgetController::new(ask, next_frame));
        let finished = self
            .latest_timings
            .as_ref()
            .and_then(|(frame, timings)| timings.total().map(|ms| (*frame, ms)));
        Some(controller.next(f64::from(budget), ask, next_frame, finished))
    }

    /// Renders one frame and waits for the GPU to finish it: its stats carry this frame's
    /// GPU times and list statistics (benchmarks and reports; interactive use calls
    /// [`Renderer::render_frame`], which never waits). If the frame's lists overflowed,
    /// the buffer is grown before this returns.
    pub fn render_frame_timed(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<FrameStats, RenderError> {
        block_on(self.render_frame_timed_async(settings))
    }

    /// [`Renderer::render_frame_timed`] without blocking: natively the same wait, in the
    /// page it yields to the browser until the frame's readbacks arrived (the lab's runs).
    pub async fn render_frame_timed_async(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<FrameStats, RenderError> {
        let mut stats = self.render_frame(settings)?;
        let timings = self.timer.wait_latest_async(&self.context).await?;
        self.latest_timings = Some((stats.frame, timings.clone()));
        stats.timings = timings;
        stats.timed_frame = Some(stats.frame);
        if settings.pipeline.needs_clusters() {
            if let Some(grown) = self.clusters.wait_and_grow_async(&self.context).await? {
                stats.list_capacity_grown_to = Some(grown);
            }
            if settings.cluster_stats {
                stats.cluster_stats = self.wait_cluster_stats_async().await?;
            }
        }
        Ok(stats)
    }

    /// Prepares the frame's clustering (rebuilding only what changed since the last frame).
    fn prepare_clusters(&mut self, settings: &FrameSettings) -> Result<(), RenderError> {
        let frame = ClusterFrame {
            grid: self.cluster_grid(settings)?,
            design: settings.assignment,
            boxes: settings.cluster_boxes,
            far_field: settings.far_field,
            spot_culling: settings.spot_culling,
        };
        let (Some(targets), Some((_, lights))) = (&self.targets, &self.lights) else {
            return Err(RenderError::Settings("targets or lights missing".into()));
        };
        // The pipeline's early depth holds the visible surfaces when the lights are assigned.
        let visible_depth = (settings.pipeline.early_depth() == EarlyDepth::VisibleSurfaces)
            .then_some(&targets.depth.view);
        self.clusters
            .prepare(&self.context, &frame, lights, visible_depth)?;
        Ok(())
    }

    fn record_and_submit(&mut self, settings: &FrameSettings) -> Result<(), RenderError> {
        let Renderer {
            context,
            library,
            gpu_scene,
            view,
            animator,
            pipelines,
            clusters,
            list_statistics,
            tonemap,
            timer,
            targets,
            lights,
            shadow_bvh,
            no_bvh,
            depth,
            frames_in_flight,
            ..
        } = self;
        let (Some(targets), Some((light_source, lights))) = (&*targets, &*lights) else {
            return Err(RenderError::Settings("targets or lights missing".into()));
        };
        let (shadows, bvh) = match (&*shadow_bvh, settings.shadows.traced()) {
            (Some((_, bvh)), true) => (settings.shadows, bvh),
            _ => (Shadows::Off, &*no_bvh),
        };
        let inputs = FrameInputs {
            gpu: context,
            scene: gpu_scene,
            view,
            lights,
            bvh,
            shadows,
            targets,
        };
        let build = PipelineBuild {
            gpu: context,
            library,
            scene: gpu_scene,
            view,
            depth: *depth,
        };
        let clustered = settings.pipeline.needs_clusters();
        let commands = context.scoped("rendering a frame", || {
            // Debug views are shown as drawn: no exposure, no tonemap.
            let (exposure, curve) = if settings.pipeline.shows_debug_view() {
                (Exposure::Manual(1.0), Tonemap::None)
            } else {
                (settings.exposure, settings.tonemap)
            };
            let statistics = match clustered && settings.cluster_stats {
                true => list_statistics.prepare(
                    context,
                    clusters,
                    settings.false_positives.then_some(&targets.depth.view),
                )?,
                false => None,
            };
            let frame = PreparedFrame {
                animation: match light_source {
                    LightSource::Generated(light_settings) => {
                        Some(animator.prepare(context, lights, light_settings, settings.time))
                    }
                    LightSource::Fixed(_) => None,
                },
                shading: pipelines.prepare(&build, &inputs, clusters, &settings.pipeline)?,
                statistics,
                post: tonemap.prepare(context, targets, exposure, curve),
                assignment: None,
            };
            let frame = PreparedFrame {
                assignment: clustered.then_some(&mut *clusters),
                ..frame
            };
            frame.record(context, gpu_scene, view, targets, timer)
        })??;
        frames_in_flight.push_back(context.queue.submit([commands]));
        timer.after_submit();
        if clustered {
            clusters.after_submit();
        }
        list_statistics.after_submit();
        self.last_pipeline = settings.pipeline;
        Ok(())
    }

    /// Waits for the GPU list statistics of the last frame (rendered with `cluster_stats`).
    pub fn wait_cluster_stats(&mut self) -> Result<Option<ClusterStats>, RenderError> {
        block_on(self.wait_cluster_stats_async())
    }

    /// [`Renderer::wait_cluster_stats`] without blocking.
    pub async fn wait_cluster_stats_async(&mut self) -> Result<Option<ClusterStats>, RenderError> {
        if let Some(stats) = self.list_statistics.wait_async(&self.context).await? {
            self.latest_cluster_stats = Some(stats);
        }
        Ok(self.latest_cluster_stats.clone())
    }

    /// The CPU reference for the GPU list statistics of the last clustered frame: reads
    /// the lists back (and, with `settings.false_positives`, the depth buffer and the
    /// view-space lights). Slow at large light counts: for tests.
    pub fn cpu_cluster_stats(&self, settings: &FrameSettings) -> Result<ClusterStats, RenderError> {
        let offsets = self.clusters.read_offsets(&self.context)?;
        let mut stats = ClusterStats::from_offsets(&offsets);
        if settings.false_positives {
            let grid = self.cluster_grid(settings)?;
            let lists = self.clusters.read_lists(&self.context)?;
            let count = self.lights.as_ref().map_or(0, |(_, l)| l.count);
            let spheres = self.clusters.read_view_lights(&self.context, count)?;
            let positions = self.view_positions(settings)?;
            stats.false_positive_ratio = Some(manylights_cluster::false_positive_ratio(
                &grid, &lists, &spheres, &positions,
            ));
        }
        Ok(stats)
    }

    /// View-space position of every pixel of the last frame, reconstructed from its depth
    /// buffer (`None` where nothing was drawn).
    pub fn view_positions(
        &self,
        settings: &FrameSettings,
    ) -> Result<Vec<Option<glam::Vec3>>, RenderError> {
        block_on(self.view_positions_async(settings))
    }

    /// [`Renderer::view_positions`] without blocking.
    pub async fn view_positions_async(
        &self,
        settings: &FrameSettings,
    ) -> Result<Vec<Option<glam::Vec3>>, RenderError> {
        let depth = manylights_gpu::targets::read_f32_rgba_async(
            &self.context,
            &self.targets()?.depth.texture,
        )
        .await?;
        let aspect = settings.size.0 as f32 / settings.size.1 as f32;
        let inverse = settings.camera.projection(aspect).inverse();
        let (w, h) = (settings.size.0 as f32, settings.size.1 as f32);
        let clear = self.depth.clear_value();
        Ok(depth
            .iter()
            .enumerate()
            .map(|(i, d)| {
                (d[0] != clear).then(|| {
                    let x = (i as u32 % settings.size.0) as f32 + 0.5;
                    let y = (i as u32 / settings.size.0) as f32 + 0.5;
                    let ndc = glam::Vec4::new(x / w * 2.0 - 1.0, 1.0 - y / h * 2.0, d[0], 1.0);
                    let p = inverse * ndc;
                    p.truncate() / p.w
                })
            })
            .collect())
    }

    /// Pixels of the last frame that show geometry.
    pub fn covered_pixels(&self) -> Result<u64, RenderError> {
        block_on(self.covered_pixels_async())
    }

    /// [`Renderer::covered_pixels`] without blocking.
    pub async fn covered_pixels_async(&self) -> Result<u64, RenderError> {
        let depth = manylights_gpu::targets::read_f32_rgba_async(
            &self.context,
            &self.targets()?.depth.texture,
        )
        .await?;
        let clear = self.depth.clear_value();
        Ok(depth.iter().filter(|d| d[0] != clear).count() as u64)
    }

    /// Light evaluations the last clustered frame made: the sum over visible pixels of
    /// their cluster's list length (the lab's work counter).
    pub fn light_evaluations(&self, settings: &FrameSettings) -> Result<u64, RenderError> {
        block_on(self.light_evaluations_async(settings))
    }

    /// [`Renderer::light_evaluations`] without blocking.
    pub async fn light_evaluations_async(
        &self,
        settings: &FrameSettings,
    ) -> Result<u64, RenderError> {
        let grid = self.cluster_grid(settings)?;
        let offsets = self.clusters.read_offsets_async(&self.context).await?;
        let width = settings.size.0 as usize;
        Ok(self
            .view_positions_async(settings)
            .await?
            .iter()
            .enumerate()
            .filter_map(|(i, p)| p.map(|p| (i, p)))
            .map(|(i, p)| {
                let cluster = grid.cluster_of_fragment(
                    (i % width) as f32 + 0.5,
                    (i / width) as f32 + 0.5,
                    -p.z,
                );
                let c = grid.flat_index(cluster) as usize;
                u64::from(offsets[c + 1] - offsets[c])
            })
            .sum())
    }

    /// The GPU light lists of the last clustered frame (tests, the lab).
    pub fn read_light_lists(&self) -> Result<manylights_cluster::LightLists, RenderError> {
        Ok(self.clusters.read_lists(&self.context)?)
    }

    /// Each cluster's far-field cut as the last frame with the tree chose it: entries
    /// (node index, exact flag in the top bit) per cluster (tests, the lab).
    pub fn read_far_field_cuts(&self) -> Result<Vec<Vec<u32>>, RenderError> {
        Ok(self.clusters.far_field().read_cuts(&self.context)?)
    }

    /// The light tree's sorted lights as the last frame with the tree sorted them: (leaf
    /// key, light index) in the tree's order (tests).
    pub fn read_far_field_order(&self) -> Result<Vec<(u32, u32)>, RenderError> {
        Ok(self.clusters.far_field().read_order(&self.context)?)
    }

    /// The view-space spheres the last clustered frame assigned.
    pub fn read_view_lights(&self) -> Result<Vec<manylights_cluster::ViewSphere>, RenderError> {
        let count = self.lights.as_ref().map_or(0, |(_, l)| l.count);
        Ok(self.clusters.read_view_lights(&self.context, count)?)
    }

    /// Every light's volume as the last clustered frame's assignment tested it (spots
    /// with their view-space cones): the CPU reference's input with spots.
    pub fn read_light_volumes(&self) -> Result<Vec<manylights_cluster::LightVolume>, RenderError> {
        let count = self.lights.as_ref().map_or(0, |(_, l)| l.count);
        Ok(self.clusters.read_light_volumes(&self.context, count)?)
    }

    /// The boxes the last clustered frame tested its lights against (the visible samples'
    /// or the grid's; empty where no sample falls): the CPU reference's input for it.
    pub fn read_cluster_bounds(&self) -> Result<Vec<manylights_scene::Aabb>, RenderError> {
        Ok(self.clusters.read_bounds(&self.context)?)
    }

    /// Which boxes the last clustered frame tested (visible ones need the pipeline's early
    /// depth).
    pub fn cluster_boxes_used(&self) -> ClusterBoxes {
        self.clusters.boxes_used()
    }

    /// Starts the light index list over at `capacity` entries (tests use a tiny one to
    /// exercise growth).
    pub fn reset_light_list_capacity(&mut self, capacity: u32) -> Result<(), RenderError> {
        self.clusters =
            GpuClusters::with_capacity(&self.context, &self.library, &self.view, capacity)?;
        Ok(())
    }

    /// Rebuilds the shading pipelines when the camera switches between standard and
    /// reverse-Z (their depth tests and clears differ).
    fn use_depth_convention(&mut self, depth: DepthConvention) -> Result<(), RenderError> {
        if depth != self.depth {
            self.pipelines = Pipelines::default();
            self.depth = depth;
        }
        Ok(())
    }

    /// Replaces the scene, keeping the device. Everything for the new scene is built
    /// before anything is replaced, so on error the renderer still shows the old one.
    pub fn load_scene(&mut self, scene: LoadedScene) -> Result<(), RenderError> {
        let gpu_scene = GpuScene::upload(&self.context, &scene.scene, &self.library)?;
        let mut pipelines = Pipelines::default();
        pipelines.build(
            &PipelineBuild {
                gpu: &self.context,
                library: &self.library,
                scene: &gpu_scene,
                view: &self.view,
                depth: self.depth,
            },
            &self.last_pipeline,
        )?;
        self.scene = scene;
        self.gpu_scene = gpu_scene;
        self.pipelines = pipelines;
        self.shadow_bvh = None;
        // The light box belongs to the scene: regenerate the lights on the next frame.
        self.lights = None;
        Ok(())
    }

    /// The scene's BVH (what shadow rays are traced through, on the CPU for the f64
    /// reference): built and uploaded on the first call, kept until the scene changes.
    pub fn scene_bvh(&mut self) -> Result<std::sync::Arc<SceneBvh>, RenderError> {
        if let Some((bvh, _)) = &self.shadow_bvh {
            return Ok(bvh.clone());
        }
        let shadow_error = |source| RenderError::Shadows {
            scene: self.scene.name.clone(),
            source,
        };
        let started = web_time::Instant::now();
        let bvh = SceneBvh::build(&self.scene.scene).map_err(shadow_error)?;
        let gpu = self
            .context
            .scoped("uploading the scene's BVH", || {
                GpuSceneBvh::new(&self.context, &bvh)
            })?
            .map_err(shadow_error)?;
        log::info!(
            "scene BVH: {} triangles, {} nodes, depth {}, {:.1} MiB on the GPU, built in {:.0} ms",
            bvh.triangles().len(),
            bvh.nodes().len(),
            bvh.depth(),
            gpu.bytes as f64 / (1024.0 * 1024.0),
            started.elapsed().as_secs_f64() * 1000.0
        );
        let bvh = std::sync::Arc::new(bvh);
        self.shadow_bvh = Some((bvh.clone(), gpu));
        Ok(bvh)
    }

    /// Bytes per pixel of a G-buffer layout for this scene (depth included).
    pub fn gbuffer_bytes_per_pixel(&self, layout: GBufferLayout) -> u32 {
        manylights_deferred::bytes_per_pixel(layout, self.gpu_scene.features.specular)
    }

    /// Capacity of the light index list now (entries).
    pub fn light_list_capacity(&self) -> u32 {
        self.clusters.capacity()
    }

    fn targets(&self) -> Result<&RenderTargets, RenderError> {
        self.targets
            .as_ref()
            .ok_or_else(|| RenderError::Settings("no frame rendered yet".into()))
    }

    /// The view of the tonemapped output of the last frame (for presenting it).
    pub fn output_view(&self) -> Option<&manylights_gpu::wgpu::TextureView> {
        self.targets.as_ref().map(|t| &t.output.view)
    }

    /// The tonemapped output of the last frame.
    pub fn read_output(&self) -> Result<image::RgbaImage, RenderError> {
        block_on(self.read_output_async())
    }

    /// [`Renderer::read_output`] without blocking.
    pub async fn read_output_async(&self) -> Result<image::RgbaImage, RenderError> {
        Ok(manylights_gpu::targets::read_rgba8_async(
            &self.context,
            &self.targets()?.output.texture,
        )
        .await?)
    }

    /// The linear HDR radiance of the last frame, row-major.
    pub fn read_hdr(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        block_on(self.read_hdr_async())
    }

    /// [`Renderer::read_hdr`] without blocking (the page's lab awaits it).
    pub async fn read_hdr_async(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        Ok(manylights_gpu::targets::read_f32_rgba_async(
            &self.context,
            &self.targets()?.hdr.texture,
        )
        .await?)
    }

    /// The exposure the last frame was tonemapped with, and (automatic exposure) the
    /// median luminance of its lit pixels. Waits for the GPU.
    pub fn read_exposure(&self) -> Result<manylights_gpu::ExposureStateGpu, RenderError> {
        Ok(self.tonemap.read_state(&self.context)?)
    }

    /// The lights as the GPU has them this frame (after animation).
    pub fn read_lights(&self) -> Result<Vec<Light>, RenderError> {
        block_on(self.read_lights_async())
    }

    /// [`Renderer::read_lights`] without blocking.
    pub async fn read_lights_async(&self) -> Result<Vec<Light>, RenderError> {
        let (_, lights) = self
            .lights
            .as_ref()
            .ok_or_else(|| RenderError::Settings("no lights yet".into()))?;
        Ok(lights.read_async(&self.context).await?)
    }

    /// Full-precision surface attributes for the camera of `settings` (for the f64
    /// reference).
    pub fn capture_surface(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<SurfaceImage, RenderError> {
        block_on(self.capture_surface_async(settings))
    }

    /// [`Renderer::capture_surface`] without blocking.
    pub async fn capture_surface_async(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<SurfaceImage, RenderError> {
        Self::validate(settings)?;
        self.update_view(settings);
        let pass = SurfacePass::new(
            &self.context,
            &self.library,
            &self.gpu_scene,
            &self.view,
            settings.camera.depth_convention(),
        )?;
        let origin = if settings.camera_relative {
            settings.camera.position.as_dvec3()
        } else {
            glam::DVec3::ZERO
        };
        Ok(pass
            .capture_async(
                &self.context,
                &self.gpu_scene,
                &self.view,
                settings.size,
                origin,
            )
            .await?)
    }
}
