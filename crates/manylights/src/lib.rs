//! The manylights facade: load a scene by name or path ([`LoadedScene`]), describe a frame
//! ([`FrameSettings`]) and render it with any pipeline ([`Renderer`]), getting per-pass GPU
//! times back. The `manylights` binary and the tests are built on this.

mod camera;
pub mod cli;
pub mod lab;
mod renderer;
mod report;
mod scenes;
pub mod soak;
mod warmup;

pub use camera::{Camera, Projection};
pub use renderer::{
    DEFAULT_INTENSITY, DEFAULT_THRESHOLD, FrameSettings, FrameStats, PipelineKind, RenderError,
    Renderer,
};
pub use scenes::{LoadedScene, assets_dir};
pub use warmup::{WarmUp, WarmUpPolicy, warm_up};

pub use manylights_cluster as cluster;
pub use manylights_gpu as gpu;
pub use manylights_gpu::{AutoExposure, DebugView, Exposure, GBufferLayout, LightingPath};
pub use manylights_lights as lights;
pub use manylights_scene as scene;
