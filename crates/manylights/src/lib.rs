//! The manylights facade: load a scene by name or path ([`LoadedScene`]), describe a frame
//! ([`FrameSettings`], with the pipeline's own [`PipelineSettings`]) and render it
//! ([`Renderer`]), getting per-pass GPU times back. It depends on no command-line, plotting
//! or progress crate: the application (`manylights-lab`: the CLI, the lab, its reports and
//! the soak test) and the viewer are built on it.
//!
//! ```no_run
//! use manylights::{FrameSettings, LoadedScene, Renderer, gpu::GpuContext};
//! # fn main() -> anyhow::Result<()> {
//! let scene = LoadedScene::load("cornell")?;
//! let mut settings = FrameSettings::for_scene(&scene);
//! settings.lights.count = 5000;
//! let mut renderer = Renderer::new(GpuContext::new_headless()?, scene)?;
//! // Waits for the GPU to report this frame's times (`render_frame` never waits).
//! let stats = renderer.render_frame_timed(&settings)?;
//! println!("{:?} ms of GPU time", stats.timings.total());
//! renderer.read_output()?.save("frame.png")?;
//! # Ok(())
//! # }
//! ```

pub mod budget;
mod camera;
pub mod drawn_cameras;
mod pipelines;
mod plan;
mod renderer;
mod scenes;
mod setting_paths;
mod settings;
mod warmup;

pub use camera::{Camera, Projection};
pub use manylights_pipeline::ShadowRoute;
pub use pipelines::{DebugView, PipelineKind, PipelineSettings};
pub use plan::{
    ClusterPlan, DeviceFacts, DialCombination, FramePlan, ListStatistics, PlannedView, SceneFacts,
    ViewedFrom,
};
pub use renderer::{
    DEFAULT_INTENSITY, DEFAULT_THRESHOLD, FrameSettings, FrameStats, MAX_FRAMES_IN_FLIGHT,
    RenderError, Renderer,
};
pub use scenes::{LoadedScene, assets_dir, describe_scene_lights, scene_lights};
pub use setting_paths::SettingError;
pub use settings::{
    FrameLights, ImageSize, PostSettings, SceneChoices, ShadowSettings, ViewSettings,
};
pub use warmup::{WarmUp, WarmUpPolicy, warm_up, warm_up_async};

pub use manylights_cluster as cluster;
pub use manylights_cluster::{ClusterView, ClusteringSettings};
pub use manylights_deferred as deferred;
pub use manylights_deferred::{
    DeferredSettings, DeferredView, GBufferChannel, GBufferLayout, LightingPath,
};
pub use manylights_forward_plus as forward_plus;
pub use manylights_forward_plus::ForwardPlusSettings;
pub use manylights_gpu as gpu;
pub use manylights_gpu::blended::Transparency;
pub use manylights_gpu::{AntiAliasing, AutoExposure, Exposure};
pub use manylights_lights as lights;
pub use manylights_naive as naive;
pub use manylights_naive::NaiveSettings;
pub use manylights_scene as scene;
pub use manylights_visibility as visibility;
pub use manylights_visibility::Shadows;
