//! What a run measures: each pass's GPU time, the accuracy against the reference, one
//! result per configuration and the report of the whole run.

use manylights::gpu::PassName;
use serde::{Deserialize, Serialize};

use super::matrix::{BenchConfig, BenchMatrix};

/// A timed pass's name as a report keeps it: the [`PassName`] it was timed under, written
/// as its text (`"assign: fill lists"`) so that reports stay readable and older reports,
/// whose passes may since have been renamed, still load. Readers compare it with a
/// [`PassName`] or a stage, never with a literal.
#[derive(
    Debug,
    Clone,
    Serialize,
    Deserialize,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    Hash
)]
#[serde(transparent)]
pub struct PassKey(String);

impl PassKey {
    /// Whether this is the pass `name`.
    pub fn is(&self, name: PassName) -> bool {
        self.0 == name.as_str()
    }

    /// Whether this pass is a step of `stage` (see [`PassName::stage`]). Reports written
    /// before the light assignment was timed step by step name it `assign lights`: a step
    /// of `assign` too.
    pub fn in_stage(&self, stage: &str) -> bool {
        let own_stage = match self.0.as_str() {
            "assign lights" => manylights::cluster::passes::ASSIGN_STAGE,
            name => manylights::gpu::stage_of(name),
        };
        own_stage == stage
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl From<PassName> for PassKey {
    fn from(name: PassName) -> Self {
        Self(name.as_str().to_string())
    }
}

impl std::fmt::Display for PassKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(&self.0)
    }
}

/// Median and 95th percentile of a pass's GPU time, milliseconds.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PassTime {
    pub name: PassKey,
    pub median_ms: f64,
    pub p95_ms: f64,
}

/// Error of a configuration against the reference.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct Accuracy {
    /// Against the reference image (absent above `reference_light_limit`).
    pub psnr_db: Option<f64>,
    pub flip_mean: Option<f64>,
    pub max_abs: Option<f64>,
    pub mean_abs: Option<f64>,
    /// Largest and mean relative error against the f64 reference at sampled pixels.
    pub f64_max_relative: f64,
    pub f64_mean_relative: f64,
    /// Mean relative error at the darkest and the brightest third of the sampled pixels
    /// (by the reference's brightest channel): a method that adds light that is not there
    /// shows it in the dark third.
    #[serde(default)]
    pub f64_mean_relative_dark: f64,
    #[serde(default)]
    pub f64_mean_relative_bright: f64,
    /// FLIP of both HDR images tonemapped (ACES fit) at one exposure chosen from the
    /// reference: its median lit luminance mapped to mid-grey (0.18), so that neither
    /// image is saturated by the choice.
    #[serde(default)]
    pub flip_at_reference_exposure: Option<f64>,
    #[serde(default)]
    pub reference_exposure: Option<f64>,
    /// Stochastic far fields, over `noise_seeds` seeds at the sampled pixels: the mean
    /// relative standard deviation (noise) and the mean relative error of the seeds' mean
    /// (bias).
    #[serde(default)]
    pub f64_noise_relative: Option<f64>,
    #[serde(default)]
    pub f64_bias_relative: Option<f64>,
    pub samples: u32,
    /// Of the samples, those under blended surfaces, whose reference composites the
    /// blended layers over the opaque surface.
    #[serde(default)]
    pub layered_samples: u32,
    /// The share of the pixels showing an opaque surface that a blended surface lies in
    /// front of (from the reference's rays at its evenly spread sample pixels, before
    /// those next to blended edges are left out); absent without blended surfaces.
    #[serde(default)]
    pub blended_coverage: Option<f64>,
    /// With shadows: the shadow rays a frame traces to lights within their radius (at the
    /// sampled pixels, each light that adds to the pixel, scaled to the covered pixels;
    /// far-field aggregates' rays are not counted). Absent above 200,000 lights.
    #[serde(default)]
    pub shadow_rays_per_frame: Option<f64>,
    /// Where the reference with visibility was estimated (more lights add to a pixel than
    /// `reference_shadow_rays`): the mean over the sampled pixels of its 95% interval's
    /// half-width relative to the pixel's value, the uncertainty of every error above.
    #[serde(default)]
    pub f64_reference_half_width: Option<f64>,
    /// With the reference's visibility: the mean relative error where the reference is in
    /// shadow (visibility takes more than half of a sample's light) and where it is lit. A
    /// method cannot hide darkening or blurring in one behind the other.
    #[serde(default)]
    pub f64_mean_relative_shadowed: Option<f64>,
    #[serde(default)]
    pub f64_mean_relative_lit: Option<f64>,
    /// The mean relative difference at the samples between this frame and the next one
    /// with the camera and lights unchanged (only the shadow rays' seed moves on): 0 for
    /// exact shadows, the noise a viewer sees for a ray budget.
    #[serde(default)]
    pub flicker: Option<f64>,
    /// Frames the image takes to settle after the lights jump ahead in their animation
    /// (`settling::lag`): 0 for a method without history.
    #[serde(default)]
    pub lag_frames: Option<u32>,
    /// Frames the image takes to settle after the camera jumps half a metre and five
    /// degrees in one frame, uncovering what the old view hid (`settling::
    /// disocclusion_lag`): the ghosting of a history; 0 for a method without one.
    #[serde(default)]
    pub disocclusion_lag_frames: Option<u32>,
    /// Which full-frame reference the image errors above (PSNR, absolute, FLIP) and the
    /// seam measure are against; absent where there is none (see [`ImageReference`]).
    #[serde(default)]
    pub image_reference: Option<ImageReference>,
    /// Seconds the reference took: the image (naive or the GPU reference) and the f64
    /// samples.
    #[serde(default)]
    pub reference_image_seconds: Option<f64>,
    #[serde(default)]
    pub reference_samples_seconds: Option<f64>,
    /// Where the GPU reference drew the image: its largest relative difference (brightest
    /// channel) from the f64 reference at the sampled pixels. The f64 reference decides
    /// the errors above where they disagree; this says by how much they do.
    #[serde(default)]
    pub gpu_reference_vs_f64: Option<f64>,
    /// Where the GPU reference with visibility is estimated: its mean relative standard
    /// error over the covered pixels (the uncertainty of the image errors above), and its
    /// largest difference from the f64 samples in their combined standard errors.
    #[serde(default)]
    pub reference_image_standard_error: Option<f64>,
    #[serde(default)]
    pub gpu_reference_vs_f64_sigmas: Option<f64>,
    /// The seam measure against the full-frame reference (`image_metrics::seam_measure`:
    /// the error's step across cluster boundaries over its step within clusters; 1.0 is
    /// no seam). Clustered pipelines only.
    #[serde(default)]
    pub seam_ratio: Option<f64>,
    /// The blotch measure against the full-frame reference (`blotch::blotch_measure`): the
    /// error's low-frequency structure on smooth surfaces, beyond what independent
    /// per-pixel noise leaves, as a relative luminance error (0: noise alone; absent in
    /// reports written before it).
    #[serde(default)]
    pub blotch: Option<f64>,
    /// Flicker under motion (`lab::motion`): along a camera walk with the lights animated,
    /// the mean change of the relative luminance error from one frame to the next; absent
    /// where not measured or without a full-frame reference.
    #[serde(default)]
    pub motion_flicker: Option<f64>,
    /// The error map's file in the report's folder (`image_metrics::error_map`), and the
    /// map itself until the report writes it.
    #[serde(default)]
    pub error_map_file: Option<String>,
    #[serde(skip)]
    pub error_map: Option<image::RgbImage>,
}

/// The full-frame reference an image error is against.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ImageReference {
    /// The naive pipeline with the unbounded falloff (and exact shadows where the
    /// reference has visibility), up to `reference_light_limit` lights.
    Naive,
    /// The GPU reference (`lights::GpuReference`): every light at every pixel of the
    /// surface capture, compensated f32 sums, without visibility and blended layers.
    GpuFullFrame,
    /// The GPU reference with visibility (`visibility::GpuVisibleReference`): every light
    /// whose shadow ray is clear, exact up to `reference_image_rays` lights, estimated
    /// beyond (each pixel with its standard error); without blended layers.
    GpuFullFrameVisible,
}

impl std::fmt::Display for ImageReference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ImageReference::Naive => "naive",
            ImageReference::GpuFullFrame => "GPU full frame",
            ImageReference::GpuFullFrameVisible => "GPU full frame, visibility",
        })
    }
}

/// Everything measured for one configuration.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BenchResult {
    pub config: BenchConfig,
    pub passes: Vec<PassTime>,
    pub gpu_total_median_ms: Option<f64>,
    pub gpu_total_p95_ms: Option<f64>,
    pub cpu_frame_median_ms: f64,
    pub accuracy: Accuracy,
    pub lights_per_cluster_mean: Option<f64>,
    pub lights_per_cluster_max: Option<u32>,
    pub false_positive_ratio: Option<f64>,
    pub cluster_count: Option<u32>,
    /// Light evaluations per frame: for clustered pipelines the sum over visible pixels of
    /// their cluster's list length; for naive visible pixels x lights (a lower bound:
    /// overdraw is not counted).
    pub light_evaluations: u64,
    pub evaluations_per_second: Option<f64>,
    /// Deferred's blended layers on its compute paths (issue 61): what the frame's store
    /// counted. `None` where blended surfaces were drawn forward, or there were none.
    #[serde(default)]
    pub blended_layers: Option<BlendedLayerCounts>,
    pub error: Option<String>,
    /// How many times the times were measured again because the clock probe pass ran
    /// slow (see `slow_clock_results`); the fastest probe's measurement is kept.
    #[serde(default)]
    pub clock_remeasures: u32,
    /// The whole frame the configuration's times were measured with, as data
    /// (`manylights::FrameSettings`, its camera placed in the scene): what ran, not only
    /// what the matrix varied. Absent in reports written before, and for a configuration
    /// that failed before its frame was made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<manylights::FrameSettings>,
}

/// What deferred's blended layers counted in a measured frame
/// (`manylights::deferred::LayerCounts`).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq)]
pub struct BlendedLayerCounts {
    /// Blended fragments in front of the opaque surfaces.
    pub fragments: u32,
    /// Of those, the ones past the node pool: not drawn.
    pub past_pool: u32,
    /// Pixels with more layers than are sorted, their farthest merged by weight.
    pub merged_pixels: u32,
}

/// The whole run: machine, settings and every result.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BenchReport {
    pub adapter: String,
    pub backend: String,
    pub driver: String,
    pub timestamps: bool,
    pub started: String,
    pub matrix: BenchMatrix,
    pub results: Vec<BenchResult>,
    /// True when the run was interrupted (Ctrl-C) before every configuration ran.
    pub interrupted: bool,
}

pub(super) fn percentile(values: &mut [f64], p: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    let index = ((values.len() as f64 - 1.0) * p).round() as usize;
    values[index.min(values.len() - 1)]
}

impl BenchResult {
    /// The configuration and its GPU time on one line (progress bars, the measure panel).
    pub fn summary_line(&self) -> String {
        let mut line = format!(
            "{} {} {} lights: {} ms",
            self.config.scene,
            self.config.variant(),
            self.config.lights,
            self.gpu_total_median_ms
                .map(|ms| format!("{ms:.3}"))
                .unwrap_or_else(|| "-".into())
        );
        if let Some(rays) = self.accuracy.shadow_rays_per_frame {
            line.push_str(&format!(", {rays:.3e} shadow rays"));
        }
        line
    }
}
