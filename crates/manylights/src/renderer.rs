//! `Renderer`: owns the GPU context, the uploaded scene, the lights and the pipelines, and
//! renders frames as a sequence: animate lights -> (clustered pipelines) assign lights ->
//! shade (the chosen [`manylights_pipeline::ShadingPipeline`]) -> post.

use manylights_cluster::{ClusterGrid, ClusterStats, GpuClusters, GpuListStatistics};
use manylights_deferred::GBufferLayout;
use manylights_gpu::DepthConvention;
use manylights_gpu::{
    GpuContext, GpuError, GpuScene, GpuTimer, GpuTimings, PostStack, RenderTargets, ShaderLibrary,
    Specialized, ViewBinding, block_on, wgpu,
};
use manylights_lights::{
    AnimationParams, GpuLights, Light, LightAnimator, LightSet, LightSettings, Shading,
    SpecularTables,
};
use manylights_pipeline::{FrameInputs, FrameLighting, LightingInputs, ShadowRoute};
use manylights_visibility::{GpuSceneBvh, SceneBvh, VisibilityError};

use crate::budget::{BudgetAsk, BudgetChoice, BudgetController};
use crate::pipelines::PipelineSettings;
use crate::plan::{DeviceFacts, FramePlan, PlannedView, SceneFacts, ViewedFrom};
use crate::scenes::LoadedScene;

mod frame;
mod lights;
mod lists;
mod readback;
mod scene;

use lights::LightSource;

pub use crate::settings::{DEFAULT_INTENSITY, DEFAULT_THRESHOLD, FrameSettings};
pub use frame::FrameStats;
use frame::{Pipelines, PreparedFrame};
use lists::{planned_list_buffers, prepare_clusters, prepare_list_statistics};

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

/// Frames the CPU may record ahead of the GPU. Without a bound a loop that never waits
/// (headless, or a window without vsync) queues work without limit, and memory with it (the
/// soak test caught 450 MiB a cycle on lavapipe); with it the CPU waits only when the GPU is
/// this many frames behind, never for the frame it just submitted.
pub const MAX_FRAMES_IN_FLIGHT: usize = 2;

/// Renders frames of one scene.
#[derive(Debug)]
pub struct Renderer {
    context: GpuContext,
    library: ShaderLibrary,
    scene: LoadedScene,
    gpu_scene: GpuScene,
    /// What frame plans need of the scene and the device.
    scene_facts: SceneFacts,
    device_facts: DeviceFacts,
    view: ViewBinding,
    animator: LightAnimator,
    /// The shading pipelines of each depth convention and BRDF a frame has asked for:
    /// their programs' depth tests, clears and surfaces differ, and a switch back finds
    /// them built (they were dropped on every switch once).
    pipelines: Specialized<(DepthConvention, Shading), Pipelines>,
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
    /// Temporal anti-aliasing (and its history), bloom, exposure and the tonemap.
    post: PostStack,
    timer: GpuTimer,
    targets: Option<RenderTargets>,
    lights: Option<(LightSource, GpuLights)>,
    /// The depth convention of this frame's pipelines.
    depth: DepthConvention,
    /// The last frame had the same depth convention and BRDF as this one: its pipelines'
    /// history (the shadow filter's) belongs to the frame before this one.
    same_pipelines_as_last_frame: bool,
    /// The BRDF of this frame's pipelines.
    shading: Shading,
    /// The scene's BVH, on the CPU and the GPU: built on the first frame with shadows (or
    /// the first call of [`Renderer::scene_bvh`]), dropped with the scene.
    shadow_bvh: Option<(std::sync::Arc<SceneBvh>, GpuSceneBvh)>,
    /// An empty tree, bound where a frame traces no shadow rays.
    no_bvh: GpuSceneBvh,
    /// PBR's specular albedo table, bound by every lighting pass.
    specular_albedo: SpecularTables,
    /// The binding every lighting pass reads (lights, lists, far field, BVH, table): its
    /// layout, on which every pipeline builds, and the group of the last frame.
    lighting: FrameLighting,
    /// With a budget: the radius it chose (reset when the budget is turned off).
    budget: Option<BudgetController>,
    /// The camera of the frame rendered last, for the view's `previous_view_proj`.
    previous_camera: Option<ViewedFrom>,
}

impl Renderer {
    pub fn new(context: GpuContext, scene: LoadedScene) -> Result<Self, RenderError> {
        let library = ShaderLibrary::from_env();
        let gpu_scene = GpuScene::upload(&context, &scene.scene, &library)?;
        let view = ViewBinding::new(&context);
        let animator = LightAnimator::new(&context, &library)?;
        let depth = DepthConvention::Standard;
        let shading = scene.scene.shading;
        let last_pipeline = PipelineSettings::default();
        let mut pipelines = Specialized::default();
        let lighting = FrameLighting::new(&context);
        let build = lighting.pipeline_build(&context, &library, &gpu_scene, &view, depth, shading);
        pipelines.get_or_build((depth, shading), |_| {
            Pipelines::built_for(&build, &last_pipeline)
        })?;
        let clusters = GpuClusters::new(&context, &library, &view)?;
        let list_statistics = GpuListStatistics::new(&context, &library, &view)?;
        let post = PostStack::new(&context, &library, &view.layout)?;
        let timer = GpuTimer::new(&context);
        let no_bvh = context
            .scoped("creating the empty BVH", || GpuSceneBvh::empty(&context))?
            .map_err(|source| RenderError::Shadows {
                scene: scene.name.clone(),
                source,
            })?;
        let specular_albedo = SpecularTables::new(&context)?;
        Ok(Self {
            scene_facts: SceneFacts::of(&gpu_scene),
            device_facts: DeviceFacts::of(&context),
            shadow_bvh: None,
            no_bvh,
            specular_albedo,
            lighting,
            budget: None,
            previous_camera: None,
            depth,
            same_pipelines_as_last_frame: true,
            shading,
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
            post,
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

    fn prepare_targets(&mut self, size: (u32, u32), msaa: u32) -> Result<(), RenderError> {
        if self
            .targets
            .as_ref()
            .is_none_or(|t| t.size != size || t.samples() != msaa)
        {
            self.targets = Some(RenderTargets::with_samples(&self.context, size, msaa)?);
        }
        Ok(())
    }

    /// Uploads the frame's view (camera-relative: the scene's instances are moved so the
    /// camera is at the origin, computed in f64, and the view is only a rotation), with
    /// the last frame's as its history's.
    fn update_view(&mut self, view: &PlannedView) {
        self.gpu_scene
            .set_origin(&self.context, view.origin.as_dvec3());
        let previous = self.previous_camera.replace(view.viewed_from);
        self.view.update(&self.context, &view.uniform(previous));
    }

    /// What a frame with `settings` would do on this renderer's scene and device, or why
    /// it cannot be rendered (the lab and the viewer ask before they render).
    pub fn plan(&self, settings: &FrameSettings) -> Result<FramePlan, RenderError> {
        FramePlan::decide(settings, &self.scene_facts, &self.device_facts)
            .map_err(RenderError::Settings)
    }

    /// The cluster grid for a frame of a clustered pipeline: the scene's bounds in view
    /// space fit the depth range.
    pub fn cluster_grid(&self, settings: &FrameSettings) -> Result<ClusterGrid, RenderError> {
        let clustering = settings.pipeline.clustering().ok_or_else(|| {
            RenderError::Settings(format!(
                "the {} pipeline has no cluster grid",
                settings.pipeline.kind()
            ))
        })?;
        PlannedView::new(settings, &self.scene_facts)
            .cluster_grid(&clustering.grid, settings.view.size)
            .map_err(RenderError::Settings)
    }

    /// Renders one frame: animate lights, (clustered pipelines) assign them to clusters,
    /// shade into HDR, tonemap into the output. Returns per-pass GPU times.
    pub fn render_frame(&mut self, settings: &FrameSettings) -> Result<FrameStats, RenderError> {
        self.render_planned(settings).map(|(stats, _)| stats)
    }

    /// [`Renderer::render_frame`], returning the frame's plan too.
    fn render_planned(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<(FrameStats, FramePlan), RenderError> {
        self.render_frame_checked(settings)
            .map_err(|error| match error {
                RenderError::Gpu(gpu) => RenderError::Gpu(self.context.explain(gpu)),
                settings_error => settings_error,
            })
    }

    fn render_frame_checked(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<(FrameStats, FramePlan), RenderError> {
        self.context.check_device()?;
        if settings.budget.is_some() {
            // Refused settings must not step the budget (it would count a frame never drawn).
            FramePlan::check_dials(settings).map_err(RenderError::Settings)?;
        }
        let budgeted;
        let choice = self.budget_choice(settings);
        let settings = match choice {
            Some(choice) => {
                budgeted = choice.applied_to(settings);
                &budgeted
            }
            None => settings,
        };
        let plan = self.plan(settings)?;
        self.use_pipelines_for(plan.depth, plan.shading);
        self.prepare_targets(settings.view.size, plan.samples)?;
        self.prepare_lights(settings)?;
        if plan.shadows.traced() {
            self.scene_bvh()?;
        }
        self.update_view(&plan.view);
        // Frame pacing: wait for the frame MAX_FRAMES_IN_FLIGHT back, if still running.
        while self.frames_in_flight.len() >= MAX_FRAMES_IN_FLIGHT {
            if let Some(oldest) = self.frames_in_flight.pop_front() {
                self.context
                    .wait_for_submission(oldest, "waiting for an earlier frame")?;
            }
        }
        let mut list_capacity_grown_to = None;
        if plan.clusters.is_some() {
            // Earlier frames' list totals, as far as the GPU got: grow if one overflowed
            // (the lists are then prepared with the frame's other passes).
            list_capacity_grown_to = self.clusters.grow_for_earlier_frames(&self.context)?;
        }
        self.record_and_submit(&plan)?;
        self.context.check_device()?;
        if let Some((frame, timings)) = self.timer.latest(&self.context)? {
            self.latest_timings = Some((frame, timings));
        }
        if plan.list_statistics().is_some() {
            if let Some(stats) = self.list_statistics.poll(&self.context)? {
                self.latest_cluster_stats = Some(stats);
            }
        } else {
            self.latest_cluster_stats = None;
        }
        let stats = FrameStats {
            frame: self.timer.frame(),
            timings: self
                .latest_timings
                .as_ref()
                .map_or(GpuTimings::Measured(Vec::new()), |(_, t)| t.clone()),
            timed_frame: self.latest_timings.as_ref().map(|(frame, _)| *frame),
            light_count: self.lights.as_ref().map_or(0, |(_, l)| l.count),
            cluster_stats: self.latest_cluster_stats.clone(),
            list_capacity_grown_to,
            radius: settings.lights.radius.radius(settings.lights.intensity),
            far_slots: plan.tree_far_field().map(|far| far.slots),
            budget_out_of_reach: choice.is_some_and(|choice| choice.out_of_reach),
        };
        Ok((stats, plan))
    }

    /// With a budget, the radius and slots this frame draws with (from the newest
    /// finished frame's GPU time); `None` without one.
    fn budget_choice(&mut self, settings: &FrameSettings) -> Option<BudgetChoice> {
        let Some(budget) = settings.budget else {
            self.budget = None;
            return None;
        };
        let ask = BudgetAsk {
            radius: settings.lights.radius.radius(settings.lights.intensity),
            far_slots: settings.pipeline.tree_far_field().map(|far| far.slots),
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
        let (mut stats, plan) = self.render_planned(settings)?;
        let timings = self.timer.wait_latest_async(&self.context).await?;
        self.latest_timings = Some((stats.frame, timings.clone()));
        stats.timings = timings;
        stats.timed_frame = Some(stats.frame);
        if plan.clusters.is_some() {
            if let Some(grown) = self.clusters.wait_and_grow_async(&self.context).await? {
                stats.list_capacity_grown_to = Some(grown);
            }
            if plan.list_statistics().is_some() {
                stats.cluster_stats = self.wait_cluster_stats_async().await?;
            }
        }
        Ok(stats)
    }

    fn record_and_submit(&mut self, plan: &FramePlan) -> Result<(), RenderError> {
        let follows_own_frame =
            self.same_pipelines_as_last_frame && self.last_pipeline.kind() == plan.pipeline.kind();
        let commands = self.prepare_and_record(plan, follows_own_frame)?;
        let submission = self.context.queue.submit([commands]);
        self.frames_in_flight.push_back(submission);
        self.timer.after_submit();
        if plan.clusters.is_some() {
            self.clusters.after_submit();
        }
        self.list_statistics.after_submit();
        self.last_pipeline = plan.pipeline;
        Ok(())
    }

    /// Prepares every pass of the frame into a [`PreparedFrame`], then records it (steps 4
    /// to 9 of ARCHITECTURE's frame).
    fn prepare_and_record(
        &mut self,
        plan: &FramePlan,
        follows_own_frame: bool,
    ) -> Result<wgpu::CommandBuffer, RenderError> {
        let Renderer {
            context,
            library,
            gpu_scene,
            view,
            animator,
            pipelines,
            clusters,
            list_statistics,
            post,
            timer,
            targets,
            lights,
            shadow_bvh,
            no_bvh,
            specular_albedo,
            lighting,
            depth,
            shading,
            ..
        } = self;
        let (Some(targets), Some((light_source, lights))) = (&*targets, &*lights) else {
            return Err(RenderError::Settings("targets or lights missing".into()));
        };
        // The lists first: the pipelines' bind groups bind what their prepare allocates.
        prepare_clusters(context, clusters, plan, targets, lights)?;
        // A frame without shadow rays binds an empty tree.
        let (shadow_route, bvh) = match (&*shadow_bvh, plan.shadows.traced()) {
            (Some((_, bvh)), true) => (plan.shadows, bvh),
            _ => (ShadowRoute::Off, &*no_bvh),
        };
        let lighting_bound = lighting.bind(
            context,
            LightingInputs {
                lists: planned_list_buffers(plan, clusters)?,
                lights,
                bvh,
                specular_tables: specular_albedo,
                heatmap_max: plan.heatmap_max,
            },
        );
        let inputs = FrameInputs {
            gpu: context,
            scene: gpu_scene,
            view,
            lighting: &lighting_bound,
            shadow_route,
            targets,
            eye: plan.eye,
            follows_own_frame,
            transparency: plan.transparency,
        };
        let build = lighting.pipeline_build(context, library, gpu_scene, view, *depth, *shading);
        // The timer's queries hold the most passes a frame has timed: recording makes none.
        timer.prepare();
        let commands = context.scoped("rendering a frame", || {
            let frame = PreparedFrame {
                animation: light_source.animation(animator, context, lights, plan.light_time),
                shading: pipelines
                    .get_or_build((*depth, *shading), |_| Ok(Pipelines::default()))?
                    .prepare(&build, &inputs, clusters, &plan.pipeline)?,
                statistics: prepare_list_statistics(
                    list_statistics,
                    context,
                    clusters,
                    plan,
                    targets,
                )?,
                post: post.prepare(context, targets, plan.post_choices(follows_own_frame))?,
            };
            Ok::<_, GpuError>(frame.record(context, gpu_scene, view, targets, timer))
        })??;
        Ok(commands)
    }

    /// Bytes per pixel of a G-buffer layout for this scene (depth included).
    pub fn gbuffer_bytes_per_pixel(&self, layout: GBufferLayout) -> u32 {
        let specular =
            manylights_deferred::stores_specular(self.gpu_scene.features.specular, self.shading);
        manylights_deferred::bytes_per_pixel(layout, specular)
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
}
