//! The GPU foundation of manylights, usable on its own: [`GpuContext`] (adapter choice
//! honouring `WGPU_BACKEND`/`WGPU_ADAPTER_NAME`, optional timestamp queries, errors
//! captured with error scopes), [`GpuScene`] (scene upload with GPU mip generation),
//! render [`targets`] and readback, the per-pass [`GpuTimer`], automatic exposure and the
//! tonemap, and the [`ShaderLibrary`] that composes WGSL from `shaders/` by explicit
//! imports, for the programs each crate above declares (this crate knows none of them).
//!
//! ```no_run
//! use manylights_gpu::{GpuContext, MaterialVariant, RenderTargets, ShaderLibrary};
//! # fn main() -> manylights_gpu::GpuResult<()> {
//! let context = GpuContext::new_headless()?; // honours WGPU_BACKEND, WGPU_ADAPTER_NAME
//! let targets = RenderTargets::new(&context, (1280, 720))?;
//! // A program composed from shaders/ by its imports, validated, as a wgpu module.
//! let program = manylights_gpu::post::tonemap_program();
//! let module = ShaderLibrary::Embedded.create_module(&context, &program, MaterialVariant::default())?;
//! # Ok(()) }
//! ```
//!
//! In an engine's own renderer the library makes no device: the engine merges
//! [`DeviceRequirements`] (the limits every WebGPU adapter guarantees; storage for a
//! million lights with [`DeviceRequirements::with_storage_binding`]) into its own
//! `DeviceDescriptor` and lends the device it made with [`GpuContext::from_device`], which
//! keeps the engine's callbacks and refuses a device short of a limit by the limit's name.
//! The camera our passes read is [`ViewUniform::from_matrices`] of the engine's view and
//! projection (any handedness, reverse-Z or not, finite or infinite far), written into a
//! [`ViewBinding`] each frame before the passes that read it are submitted:
//!
//! ```no_run
//! # fn engine(context: &manylights_gpu::GpuContext, view: glam::Mat4, projection: glam::Mat4) -> manylights_gpu::GpuResult<()> {
//! use manylights_gpu::{ViewBinding, ViewUniform};
//! let camera = ViewUniform::from_matrices(view, projection, (1920, 1080))?;
//! let binding = ViewBinding::new(context); // once
//! binding.update(context, &camera); // every frame, before the library's passes
//! # Ok(()) }
//! ```

pub mod base_color;
pub mod binding;
pub mod blended;
pub mod bloom;

/// The side of the square workgroups of every per-pixel compute pass (deferred lighting,
/// tonemap, the visibility buffer's classification and resolve, list statistics): one Rust
/// constant, which the WGSL reads as the shader def `#SCREEN_TILE`.
pub const SCREEN_TILE: u32 = 8;

mod compose_cache;
mod context;
mod depth;
mod device_requirements;
mod error;
pub mod layout;
pub mod mipmap;
mod names;
pub mod post;
pub mod post_stack;
mod programs;
pub mod readback;
pub mod shaders;
pub mod specialized;
pub mod surface;
pub mod taa;
pub mod targets;
pub mod timer;
pub mod upload;
pub mod view;

pub use base_color::{BaseColorPass, DrawTarget};
pub use bloom::{BLOOM_PASS, Bloom, PreparedBloom};
pub use context::{
    AdapterRequest, AdapterSummary, CreationCount, DeviceLimits, GpuContext, block_on, yield_now,
};
pub use depth::DepthConvention;
pub use device_requirements::DeviceRequirements;
pub use error::{GpuError, GpuResult};
pub use names::NamedChoice;
pub use post::{
    AUTO_EXPOSURE_BIN_STOPS, AUTO_EXPOSURE_PASS, AutoExposure, Exposure, ExposureStateGpu,
    PreparedTonemap, TONEMAP_PASS, Tonemap, TonemapPass,
};
pub use post_stack::{PostChoices, PostStack, PreparedPost};
pub use programs::programs;
pub use readback::{AsyncReadback, ReservedSlot};
pub use shaders::{
    ComposedShader, MaterialVariant, Program, SHADER_DIR_VARIABLE, ShaderDef, ShaderFile,
    ShaderLibrary, ShaderModules, no_constants, shading_defs,
};
pub use specialized::Specialized;
pub use surface::{SurfaceImage, SurfacePass};
pub use taa::{AntiAliasing, PreparedTaa, TAA_PASS, TemporalAntiAliasing};
pub use targets::{
    DEPTH_FORMAT, HDR_FORMAT, OUTPUT_FORMAT, OUTPUT_STORAGE_FORMAT, RenderTargets, Target,
};
pub use timer::{GpuTimer, GpuTimings, PassName, PassTiming, stage_of, timed_compute_pass};
pub use upload::{GpuScene, GpuVertex, InstanceMesh, PipelineKey, ScenePipelineDesc, SceneStorage};
pub use view::{CameraMatrices, ProjectionFacts, ViewBinding, ViewUniform};

// Re-exported so users of this crate name the same wgpu version.
/// The WGSL composer our shaders are written for, for engines that compose with it too
/// ([`ShaderLibrary::add_to_composer`]).
pub use naga_oil;
pub use wgpu;
