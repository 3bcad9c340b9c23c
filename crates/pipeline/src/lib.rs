//! The interface between the renderer and its shading pipelines. A pipeline is built for
//! one uploaded scene ([`PipelineBuild`]) and records each frame's shading into the HDR
//! target from a [`FrameContext`]; its own settings type ([`ShadingPipeline::Settings`])
//! holds only what that pipeline can do, so a combination it cannot render is a type error
//! rather than a runtime one.
//!
//! ```text
//! animate lights -> record_depth -> [assign lights to clusters, if needs_clusters] -> record -> post
//! ```
//!
//! A pipeline that lays the frame's depth down first (deferred's G-buffer, Forward+'s depth
//! pre-pass) does so in [`ShadingPipeline::record_depth`] and says so
//! ([`EarlyDepth::VisibleSurfaces`]): the assignment then bounds each cluster by its visible
//! samples and lists nothing where nothing is seen.
//!
//! Adding a pipeline: a crate with its WGSL under `shaders/<crate>/`, a `Settings` type,
//! `impl ShadingPipeline`, and a `programs()` list for `cargo xtask validate-shaders`
//! (ARCHITECTURE.md walks through it).

use std::fmt;

use manylights_cluster::GpuClusters;
use manylights_gpu::{
    DepthConvention, GpuContext, GpuResult, GpuScene, GpuTimer, RenderTargets, ShaderLibrary,
    ViewBinding, wgpu,
};
use manylights_lights::GpuLights;

/// What a pipeline is built from: the device, the shader library, the uploaded scene, the
/// view's bind group layout and the depth convention its depth tests follow.
#[derive(Debug, Clone, Copy)]
pub struct PipelineBuild<'a> {
    pub gpu: &'a GpuContext,
    pub library: &'a ShaderLibrary,
    pub scene: &'a GpuScene,
    pub view: &'a ViewBinding,
    pub depth: DepthConvention,
}

/// Everything one frame's shading reads and writes.
pub struct FrameContext<'a> {
    pub gpu: &'a GpuContext,
    pub encoder: &'a mut wgpu::CommandEncoder,
    pub scene: &'a GpuScene,
    pub view: &'a ViewBinding,
    /// The frame's lights, animated.
    pub lights: &'a GpuLights,
    /// This frame's light lists when the pipeline [needs clusters](ShadingPipeline::needs_clusters):
    /// recorded before [`ShadingPipeline::record`], not yet in
    /// [`ShadingPipeline::record_depth`] (where only the buffers exist).
    pub clusters: Option<&'a GpuClusters>,
    /// The HDR target to shade into, with the depth buffer (read later by statistics).
    pub targets: &'a RenderTargets,
    pub timer: &'a mut GpuTimer,
}

impl fmt::Debug for FrameContext<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FrameContext")
            .field("lights", &self.lights.count)
            .field("clustered", &self.clusters.is_some())
            .field("size", &self.targets.size)
            .finish_non_exhaustive()
    }
}

impl FrameContext<'_> {
    /// The frame's light lists, or an error naming the pipeline that needed them.
    pub fn clusters(&self, pipeline: &str) -> GpuResult<&GpuClusters> {
        self.clusters.ok_or_else(|| {
            manylights_gpu::GpuError::Unsupported(format!(
                "{pipeline} shades from cluster light lists, and none were assigned this frame"
            ))
        })
    }
}

/// What the depth target holds after [`ShadingPipeline::record_depth`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EarlyDepth {
    /// The depth of exactly the surfaces the frame will shade (nothing shades behind it).
    VisibleSurfaces,
    /// Nothing yet: the pipeline draws depth while it shades.
    None,
}

/// A way of shading the frame's lights into the HDR target.
pub trait ShadingPipeline: Sized + fmt::Debug {
    /// What a frame of this pipeline can vary: only combinations it renders.
    type Settings: Clone + PartialEq + fmt::Debug;

    /// Its name in logs and errors.
    const NAME: &'static str;

    /// Builds the pipeline's GPU objects for a scene.
    fn new(build: &PipelineBuild) -> GpuResult<Self>;

    /// Whether frames with these settings shade from cluster light lists (the renderer
    /// then assigns the lights first and passes [`FrameContext::clusters`]).
    fn needs_clusters(settings: &Self::Settings) -> bool;

    /// Whether these settings draw a debug view into the HDR target instead of radiance
    /// (shown as drawn: no exposure, no tonemap).
    fn shows_debug_view(settings: &Self::Settings) -> bool;

    /// Records the passes that lay the frame's depth down before the lights are assigned,
    /// if the pipeline has any, and says what the depth target then holds.
    fn record_depth(
        &mut self,
        _frame: &mut FrameContext,
        _settings: &Self::Settings,
    ) -> GpuResult<EarlyDepth> {
        Ok(EarlyDepth::None)
    }

    /// Records the frame's shading passes (after [`ShadingPipeline::record_depth`] and the
    /// assignment), each timed by `frame.timer`.
    fn record(&mut self, frame: &mut FrameContext, settings: &Self::Settings) -> GpuResult<()>;
}
