//! The interface between the renderer and its shading pipelines. A pipeline is built for
//! one uploaded scene ([`PipelineBuild`]). Each frame it is first prepared from the frame's
//! inputs ([`FrameInputs`]): pipelines compiled, bind groups built (kept while what they
//! bind is unchanged), parameters written. The [`PreparedShading`] this returns then records
//! the frame's passes into a [`FrameRecorder`], creating nothing. Its own settings type
//! ([`ShadingPipeline::Settings`]) holds only what that pipeline can do, so a combination
//! it cannot render is a type error rather than a runtime one.
//!
//! ```text
//! prepare -> animate lights -> record_depth -> record ([assign lights to clusters] -> shade) -> post
//! ```
//!
//! What a pipeline shades from is a type, [`ShadingPipeline::LightLists`]: [`EveryLight`]
//! for one that loops over every light, the cluster crate's `GpuClusters` for one that shades
//! from light lists. The renderer prepares lists only for the second kind and hands each
//! pipeline exactly what its type names, so neither can be given what it does not read nor
//! miss what it does (this crate does not depend on clustering). A clustered pipeline
//! records the assignment itself, between its depth and its shading, and its shading
//! passes take the assignment's proof (`ListsBuilt`): shading before the lists are built
//! does not compile, as shading before the depth does not.
//!
//! A pipeline that lays the frame's depth down first (deferred's G-buffer, Forward+'s depth
//! pre-pass) says so before the frame is recorded ([`ShadingPipeline::early_depth`]) and does
//! it in [`PreparedShading::record_depth`]: the assignment then bounds each cluster by its
//! visible samples and lists nothing where nothing is seen. Its [`DepthRecorded`] is what
//! [`PreparedShading::record`] takes, so the order is the type system's, not a check.
//!
//! Adding a pipeline: a crate with its WGSL under `shaders/<crate>/`, a `Settings` type,
//! `impl ShadingPipeline`, and a `programs()` list for `cargo xtask validate-shaders`
//! (ARCHITECTURE.md walks through it).

use std::fmt;

mod blended;
mod lighting;
mod shadow_route;

pub use blended::{BlendedPass, PreparedBlended};
pub use lighting::{
    BoundLighting, FrameLighting, LIGHTING_GROUP, LightingInputs, LightingUniform, ListBuffers,
};
pub use shadow_route::ShadowRoute;

use manylights_gpu::{
    DepthConvention, GpuContext, GpuResult, GpuScene, GpuTimer, RenderTargets, ShaderLibrary,
    ViewBinding, wgpu,
};
use manylights_visibility::{FrameShadows, ShadowPassInputs};

/// What a pipeline is built from: the device, the shader library, the uploaded scene, the
/// view's bind group layout and the depth convention its depth tests follow.
#[derive(Debug, Clone, Copy)]
pub struct PipelineBuild<'a> {
    pub gpu: &'a GpuContext,
    pub library: &'a ShaderLibrary,
    pub scene: &'a GpuScene,
    pub view: &'a ViewBinding,
    pub depth: DepthConvention,
    /// The BRDF every program of the pipeline shades with (a pipeline is built per
    /// shading a frame asks for).
    pub shading: manylights_lights::Shading,
    /// The layout of the frame's lighting binding ([`FrameLighting`]), which every
    /// lighting program is built on at [`LIGHTING_GROUP`].
    pub lighting_layout: &'a wgpu::BindGroupLayout,
    /// The same without the far field's bindings ([`FrameLighting::near_field_layout`]).
    pub near_field_layout: &'a wgpu::BindGroupLayout,
}

/// Everything a pipeline prepares one frame's shading from: what its bind groups bind and
/// what its pipelines are built for. Nothing is recorded while preparing.
#[derive(Clone, Copy)]
pub struct FrameInputs<'a> {
    pub gpu: &'a GpuContext,
    pub scene: &'a GpuScene,
    pub view: &'a ViewBinding,
    /// The frame's lighting binding ([`FrameLighting`]: the lights, the lists or their
    /// stand-ins, the far field, the BVH, the albedo table), which every lighting pass
    /// binds at [`LIGHTING_GROUP`], with the lights' kinds and the BVH it binds.
    pub lighting: &'a BoundLighting<'a>,
    /// Where the frame traces shadow rays through the lighting's BVH, and what follows
    /// them: the route
    /// this pipeline's [`ShadingPipeline::shadow_route`] gave for the frame's settings.
    pub shadow_route: ShadowRoute,
    /// The HDR target to shade into, with the depth buffer (read later by statistics).
    pub targets: &'a RenderTargets,
    /// The camera's position in world space (blended surfaces are drawn farthest first).
    pub eye: glam::DVec3,
    /// How blended surfaces combine with what is behind them.
    pub transparency: manylights_gpu::blended::Transparency,
    /// The last frame was drawn by this pipeline too: what it kept across frames (the
    /// shadow history) belongs to the frame before this one. False after a switch, when
    /// it belongs to a frame further back and is dropped.
    pub follows_own_frame: bool,
}

impl<'a> FrameInputs<'a> {
    /// What a forward pipeline's shadow pass prepares from: this frame's, with the
    /// pipeline's shader `library`.
    pub fn shadow_pass(&self, library: &'a ShaderLibrary) -> ShadowPassInputs<'a> {
        ShadowPassInputs {
            context: self.gpu,
            library,
            view: self.view,
            targets: self.targets,
            shadows: self.shadows(),
            bvh: self.lighting.bvh,
        }
    }

    /// The frame's shadows as a shadow filter keeps them: the route's, with whether the
    /// filter's history is the last frame's.
    pub fn shadows(&self) -> FrameShadows {
        FrameShadows {
            shadows: self.shadow_route.shadows(),
            follows_own_frame: self.follows_own_frame,
        }
    }
}

impl fmt::Debug for FrameInputs<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FrameInputs")
            .field("shadow_route", &self.shadow_route)
            .field("size", &self.targets.size)
            .finish_non_exhaustive()
    }
}

/// What recording a prepared frame's passes writes to: the encoder and the timer, with the
/// scene whose draws it replays and the targets its passes attach.
pub struct FrameRecorder<'a> {
    pub encoder: &'a mut wgpu::CommandEncoder,
    pub timer: &'a mut GpuTimer,
    pub scene: &'a GpuScene,
    pub view: &'a ViewBinding,
    pub targets: &'a RenderTargets,
}

impl fmt::Debug for FrameRecorder<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FrameRecorder")
            .field("size", &self.targets.size)
            .finish_non_exhaustive()
    }
}

/// Proof that a frame's early depth was recorded: [`PreparedShading::record`] takes it, so
/// shading before the depth it reads (the G-buffer, the pre-pass) does not compile.
#[derive(Debug)]
pub struct DepthRecorded(());

/// One frame of a pipeline, prepared: its pipelines and bind groups are built, and
/// recording only replays them (no creation, no failure).
pub trait PreparedShading {
    /// The passes that lay the frame's depth down before the lights are assigned, if
    /// [`ShadingPipeline::early_depth`] said there are any.
    fn record_depth_passes(&self, _frame: &mut FrameRecorder) {}

    /// Records the early depth; what it returns is what [`PreparedShading::record`] asks for.
    fn record_depth(&self, frame: &mut FrameRecorder) -> DepthRecorded {
        self.record_depth_passes(frame);
        DepthRecorded(())
    }

    /// Records the frame after its early depth, each pass timed by `frame.timer`: a
    /// clustered pipeline first assigns the lights to the lists it prepared with (the
    /// cluster crate's `PreparedAssignment`, whose proof its shading passes take), then
    /// shades into the HDR target.
    fn record(&self, frame: &mut FrameRecorder, depth: DepthRecorded);
}

/// What a pipeline that evaluates every light at every pixel shades from: no lists, only
/// the frame's lights (in [`FrameInputs::lighting`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EveryLight;

/// What the depth target holds after [`PreparedShading::record_depth`], and so whether the
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

    /// What its frames shade from: [`EveryLight`], or the light lists the pipeline's
    /// [`PreparedShading::record`] assigns before it shades (the cluster crate's
    /// `GpuClusters`, prepared for the frame before the pipeline is, and borrowed by the
    /// prepared frame that records its assignment).
    type LightLists;

    /// One prepared frame, borrowing the pipeline's objects.
    type Prepared<'a>: PreparedShading
    where
        Self: 'a;

    /// Its name in logs and errors.
    const NAME: &'static str;

    /// Builds the pipeline's GPU objects for a scene.
    fn new(build: &PipelineBuild) -> GpuResult<Self>;

    /// Whether these settings draw a debug view into the HDR target instead of radiance
    /// (shown as drawn: no exposure, no tonemap).
    fn shows_debug_view(settings: &Self::Settings) -> bool;

    /// What the depth target will hold after [`PreparedShading::record_depth`] with these
    /// settings (known before the frame is recorded: the assignment is prepared for it).
    fn early_depth(_settings: &Self::Settings) -> EarlyDepth {
        EarlyDepth::None
    }

    /// Where the shaded image's rays go with these settings: the forward route unless a
    /// pipeline says otherwise (deferred's compute lighting).
    fn shaded_shadow_route(
        _settings: &Self::Settings,
        shadows: manylights_visibility::Shadows,
    ) -> ShadowRoute {
        ShadowRoute::forward(shadows)
    }

    /// Where a frame with these settings traces `shadows` and what follows the rays, or
    /// why it cannot (a filter where no pass follows the loop, asked of the shaded
    /// image's route). A debug view's loop shows the rays' raw shares, unfiltered, with no
    /// pass after it. [`FrameInputs::shadow_route`] hands the route back.
    fn shadow_route(
        settings: &Self::Settings,
        shadows: manylights_visibility::Shadows,
    ) -> Result<ShadowRoute, String> {
        let shaded = Self::shaded_shadow_route(settings, shadows)
            .refusing_unfollowed_filter(shadows, Self::NAME)?;
        Ok(if Self::shows_debug_view(settings) {
            shaded.for_debug_view()
        } else {
            shaded
        })
    }

    /// Builds what a frame with these settings records (pipelines compiled on first use,
    /// bind groups rebuilt only when what they bind changed) and writes its parameters.
    /// The lists are prepared but not yet built.
    fn prepare<'a>(
        &'a mut self,
        frame: &FrameInputs,
        lists: &'a Self::LightLists,
        settings: &Self::Settings,
    ) -> GpuResult<Self::Prepared<'a>>;
}
