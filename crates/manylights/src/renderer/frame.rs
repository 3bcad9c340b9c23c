//! One frame, prepared then recorded: the dispatcher that builds and prepares the pipeline
//! a frame's settings choose, [`PreparedFrame`] (every pass prepared, recorded by replay in
//! ARCHITECTURE's order), and [`FrameStats`], what a frame returns.

use manylights_cluster::{ClusterStats, GpuClusters, PreparedStatistics};
use manylights_deferred::DeferredPipeline;
use manylights_forward_plus::ForwardPlusPipeline;
use manylights_gpu::{
    GpuContext, GpuError, GpuScene, GpuTimer, GpuTimings, PreparedPost, RenderTargets, ViewBinding,
    wgpu,
};
use manylights_lights::PreparedAnimation;
use manylights_naive::NaivePipeline;
use manylights_pipeline::{
    FrameInputs, FrameRecorder, PipelineBuild, PreparedShading, ShadingPipeline,
};

use crate::pipelines::{FrameLightLists, PipelineSettings};

/// What a frame produced besides its image. Nothing here waited for the GPU: GPU results
/// are those of the newest frame it had finished (usually the one before).
#[derive(Debug, Clone)]
pub struct FrameStats {
    /// This frame's number (counting from 1 for the renderer's first frame).
    pub frame: u64,
    /// Per-pass GPU times of frame [`FrameStats::timed_frame`]
    /// ([`crate::Renderer::render_frame_timed`] waits for this frame's).
    pub timings: GpuTimings,
    /// The frame `timings` belong to; `None` while no frame has finished.
    pub timed_frame: Option<u64>,
    pub light_count: u32,
    /// Forward+/deferred with `cluster_stats` on: the newest statistics the GPU has
    /// finished (usually this frame's; read back without waiting, so possibly an earlier
    /// frame's; [`crate::Renderer::wait_cluster_stats`] waits for this frame's).
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

/// The shading pipelines of one scene, depth convention and BRDF, each built when a frame
/// first needs it.
#[derive(Debug, Default)]
pub(super) struct Pipelines {
    naive: Option<NaivePipeline>,
    forward_plus: Option<ForwardPlusPipeline>,
    deferred: Option<DeferredPipeline>,
}

impl Pipelines {
    /// The deferred pipeline, if a frame has built it.
    pub(super) fn deferred(&self) -> Option<&DeferredPipeline> {
        self.deferred.as_ref()
    }

    /// Builds the pipeline `settings` choose (unless built) and prepares its frame, handing
    /// it what its light-list type names from `clusters`.
    pub(super) fn prepare<'a>(
        &'a mut self,
        build: &PipelineBuild,
        inputs: &FrameInputs,
        clusters: &'a GpuClusters,
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

    /// A set with the pipeline `settings` choose built (so that a scene whose shaders
    /// fail is refused when loaded, not at its first frame).
    pub(super) fn built_for(
        build: &PipelineBuild,
        settings: &PipelineSettings,
    ) -> Result<Self, GpuError> {
        let mut pipelines = Self::default();
        match settings {
            PipelineSettings::Naive(_) => built(&mut pipelines.naive, build).map(|_| ()),
            PipelineSettings::ForwardPlus(_) => {
                built(&mut pipelines.forward_plus, build).map(|_| ())
            }
            PipelineSettings::Deferred(_) => built(&mut pipelines.deferred, build).map(|_| ()),
        }?;
        Ok(pipelines)
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
    clusters: &'a GpuClusters,
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
pub(super) struct PreparedFrame<'a> {
    /// Generated lights move (fixed lights stay where they were put).
    pub(super) animation: Option<PreparedAnimation<'a>>,
    pub(super) shading: Box<dyn PreparedShading + 'a>,
    pub(super) statistics: Option<PreparedStatistics<'a>>,
    pub(super) post: PreparedPost<'a>,
}

impl PreparedFrame<'_> {
    /// Records the frame's passes, each timed by `timer` (clustered pipelines record their
    /// light assignment between their depth and their shading).
    pub(super) fn record(
        self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        targets: &RenderTargets,
        timer: &mut GpuTimer,
    ) -> wgpu::CommandBuffer {
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
        // 3. Clustered pipelines assign lights to clusters (bounded by the visible samples
        //    when the pipeline laid its depth down), then 4. shade into the HDR target.
        self.shading.record(&mut recorder, depth);
        // 5. Statistics of the light lists (after shading: false positives read the
        //    frame's depth buffer).
        if let Some(statistics) = self.statistics {
            statistics.record(recorder.encoder, view, Some(&mut *recorder.timer));
        }
        // 6. Post: temporal anti-aliasing, then bloom, each written back into the HDR
        //    target; exposure and tonemap into the output.
        self.post
            .record(recorder.encoder, &view.bind_group, recorder.timer);
        recorder.timer.resolve(recorder.encoder);
        encoder.finish()
    }
}
