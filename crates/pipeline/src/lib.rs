//! The interface between the renderer and its shading pipelines. A pipeline is built for
//! one uploaded scene ([`PipelineBuild`]) and records each frame's shading into the HDR
//! target from a [`FrameContext`]; its own settings type ([`ShadingPipeline::Settings`])
//! holds only what that pipeline can do, so a combination it cannot render is a type error
//! rather than a runtime one.
//!
//! ```text
//! animate lights -> record_depth -> [assign lights to clusters, for clustered pipelines] -> record -> post
//! ```
//!
//! What a pipeline shades from is a type, [`ShadingPipeline::LightLists`]: [`EveryLight`]
//! for one that loops over every light, the cluster crate's `GpuClusters` for one that shades
//! from light lists. The renderer assigns lights only for the second kind and hands each
//! pipeline exactly what its type names, so neither can be given what it does not read nor
//! miss what it does (this crate does not depend on clustering).
//!
//! A pipeline that lays the frame's depth down first (deferred's G-buffer, Forward+'s depth
//! pre-pass) says so before the frame is recorded ([`ShadingPipeline::early_depth`]) and does
//! it in [`ShadingPipeline::record_depth`]: the assignment then bounds each cluster by its
//! visible samples and lists nothing where nothing is seen.
//!
//! Adding a pipeline: a crate with its WGSL under `shaders/<crate>/`, a `Settings` type,
//! `impl ShadingPipeline`, and a `programs()` list for `cargo xtask validate-shaders`
//! (ARCHITECTURE.md walks through it).

use std::fmt;

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
    /// The scene's BVH for shadow rays (an empty tree when the frame has no shadows).
    pub bvh: &'a manylights_visibility::GpuSceneBvh,
    /// Whether the frame traces shadow rays through `bvh`.
    pub shadows: manylights_visibility::Shadows,
    /// The HDR target to shade into, with the depth buffer (read later by statistics).
    pub targets: &'a RenderTargets,
    pub timer: &'a mut GpuTimer,
}

impl fmt::Debug for FrameContext<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FrameContext")
            .field("lights", &self.lights.count)
            .field("size", &self.targets.size)
            .finish_non_exhaustive()
    }
}

/// What a pipeline that evaluates every light at every pixel shades from: no lists, only
/// the frame's lights ([`FrameContext::lights`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EveryLight;

/// What the depth target holds after [`ShadingPipeline::record_depth`], and so whether the
/// assignment can bound clusters by their visible samples.
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

    /// What its frames shade from: [`EveryLight`], or the light lists the renderer assigns
    /// between [`ShadingPipeline::record_depth`] and [`ShadingPipeline::record`] (the
    /// cluster crate's `GpuClusters`, prepared for the frame before either is called).
    type LightLists;

    /// Its name in logs and errors.
    const NAME: &'static str;

    /// Builds the pipeline's GPU objects for a scene.
    fn new(build: &PipelineBuild) -> GpuResult<Self>;

    /// Whether these settings draw a debug view into the HDR target instead of radiance
    /// (shown as drawn: no exposure, no tonemap).
    fn shows_debug_view(settings: &Self::Settings) -> bool;

    /// What the depth target will hold after [`ShadingPipeline::record_depth`] with these
    /// settings (known before the frame is recorded: the assignment is prepared for it).
    fn early_depth(_settings: &Self::Settings) -> EarlyDepth {
        EarlyDepth::None
    }

    /// Records the passes that lay the frame's depth down before the lights are assigned,
    /// if [`ShadingPipeline::early_depth`] says there are any. The lists are prepared but
    /// not yet built.
    fn record_depth(
        &mut self,
        _frame: &mut FrameContext,
        _lists: &Self::LightLists,
        _settings: &Self::Settings,
    ) -> GpuResult<()> {
        Ok(())
    }

    /// Records the frame's shading passes (after [`ShadingPipeline::record_depth`] and the
    /// assignment), each timed by `frame.timer`.
    fn record(
        &mut self,
        frame: &mut FrameContext,
        lists: &Self::LightLists,
        settings: &Self::Settings,
    ) -> GpuResult<()>;
}
