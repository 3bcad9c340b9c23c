//! The lab: runs a matrix of configurations (scenes x pipelines x light counts x sizes x
//! cluster grids x G-buffer layouts x lighting paths x thresholds x falloffs), measuring
//! each pass's GPU time from timestamps (median and p95 over N frames with a fixed time
//! step, lights moving) and the error against the reference, so users can choose a
//! pipeline from the speed/accuracy trade instead of guessing.
//!
//! The reference for a configuration is computed twice: an image (the naive pipeline with
//! unbounded inverse-square falloff, every light on every pixel) for PSNR, FLIP and
//! absolute errors, and the f64 CPU shading at sampled pixels (full-precision surfaces read
//! back from the GPU) for the relative error. The reference image costs pixels x lights on
//! the naive pipeline, so above `reference_light_limit` lights the GPU reference
//! (`lights::GpuReference`: every light at every pixel in compensated f32) draws the image
//! where it can (no visibility, no blended layers), and the f64 samples are always
//! computed.
//!
//! One idea per file: `matrix` (what to run), `run` (the loop), `clock` (re-timing
//! configurations a lowered GPU clock slowed), `job` (a run polled by an application's
//! frame loop), `accuracy` (errors against the reference), `image_metrics` (error maps and
//! the seam measure of whole frames), `motion` (flicker along a camera walk)
//! and `results` (what a run produces).

mod accuracy;
pub mod blotch;
mod clock;
pub mod edges;
mod gpu_reference_checks;
pub mod image_metrics;
mod job;
mod layers;
mod matrix;
mod motion;
pub mod over_cameras;
mod presets;
mod reference;
mod results;
mod run;
mod sample_pixels;
pub mod setting_axes;
mod settling;
#[cfg(test)]
mod tests;
mod timing;

pub use accuracy::{
    FLIP_PIXELS_PER_DEGREE, ImageError, exposure_from_reference, image_error, tonemap_aces,
};
#[cfg(not(target_arch = "wasm32"))]
pub use accuracy::{flip_mean, flip_mean_and_map};
pub use clock::slow_clock_results;
pub use job::{JobProgress, LabJob};
#[cfg(test)]
pub(crate) use matrix::frame_choice;
pub use matrix::{Assignment, BenchConfig, BenchMatrix, DEFAULT_REFERENCE_SHADOW_RAYS, GridSpec};
pub use results::{
    Accuracy, BenchReport, BenchResult, BlendedLayerCounts, ImageReference, PassKey, PassTime,
};
pub use run::{run, run_async};
