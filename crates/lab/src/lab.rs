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
//! the naive pipeline, so above `reference_light_limit` lights only the f64 samples are
//! computed.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context as _, bail};
use glam::DVec3;
use serde::{Deserialize, Serialize};

use manylights::cluster::{
    AssignmentDesign, ClusterBoxes, ClusterSettings, FarField, FarFieldMethod, TileSpec, ZScheme,
};
use manylights::gpu::{GpuContext, GpuTimings};
use manylights::lights::reference::{SurfacePoint, shade};
use manylights::lights::{Falloff, RadiusMode};
use manylights::{
    DEFAULT_INTENSITY, FrameSettings, GBufferLayout, LightingPath, LoadedScene, NaiveSettings,
    PipelineKind, PipelineSettings, Renderer,
};

/// The configurations to run. Axes that do not apply to a pipeline are not multiplied
/// (naive has no grid, Forward+ no G-buffer).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct BenchMatrix {
    pub scenes: Vec<String>,
    /// `naive`, `forward-plus`, `deferred`.
    pub pipelines: Vec<String>,
    pub lights: Vec<u32>,
    /// `WIDTHxHEIGHT`.
    pub sizes: Vec<String>,
    /// `TILESXxTILESYxSLICES` or with a scheme suffix: `16x9x48:log-near`, `:log`, `:linear`.
    pub grids: Vec<String>,
    /// `full`, `compact`, `packed` (deferred).
    pub gbuffers: Vec<String>,
    /// `fragment`, `compute` (deferred).
    pub lighting: Vec<String>,
    /// Luminance thresholds (radius = sqrt(intensity / threshold)).
    pub thresholds: Vec<f32>,
    /// `windowed`, `reference-projects` (`inverse-square` only runs on naive).
    pub falloffs: Vec<String>,
    /// Clustered pipelines: how lights are assigned, `DESIGN/BOXES`: `tile-masks/visible`
    /// (the default), `tile-masks/grid`, `atomic-fill/grid` (the first design), ...
    pub assignments: Vec<String>,
    /// Clustered pipelines: `off` (lights end at their radius) or a far field,
    /// `METHOD:TOLERANCE` (`tree:0.1`, `stochastic:1`): the configuration then renders the
    /// unbounded inverse-square falloff (its `falloffs` entry must be `windowed`, the part
    /// the lists sum exactly).
    pub far_fields: Vec<String>,
    /// Stochastic far fields: seeds rendered at the accuracy frame to measure the noise
    /// (standard deviation over seeds) beside the bias (the error of their mean).
    pub noise_seeds: u32,
    pub intensity: f32,
    /// Light colour saturation (0 white, 1 pure hues).
    pub saturation: f32,
    /// The fraction of generated lights that are spots (an axis: 0, 0.5, ...).
    pub spot_fractions: Vec<f32>,
    /// Generated spots' inner and outer cone half-angles, degrees.
    pub spot_angles: (f32, f32),
    /// Clustered pipelines: how spots are culled, `cone` or `sphere` (an axis: the
    /// false-positive ratio of each is what the cone test saves).
    pub spot_cullings: Vec<String>,
    pub camera: Option<String>,
    /// Warm-up frames at least; more until the GPU time settles (`manylights::warm_up`).
    pub warmup_frames: u32,
    pub frames: u32,
    /// Seconds between timed frames (lights keep moving).
    pub time_step: f32,
    pub seed: u32,
    /// Above this light count no reference image is rendered (naive is too slow); the
    /// f64 samples are still computed.
    pub reference_light_limit: u32,
    /// Pixels sampled for the f64 reference.
    pub reference_samples: u32,
    /// Skip naive above this many lights (its cost is pixels x lights).
    pub naive_light_limit: u32,
}

impl Default for BenchMatrix {
    fn default() -> Self {
        Self {
            scenes: vec!["sponza".into()],
            pipelines: vec!["naive".into(), "forward-plus".into(), "deferred".into()],
            lights: vec![1000],
            sizes: vec!["1280x720".into()],
            grids: vec!["16x9x48:log-near".into()],
            gbuffers: vec!["compact".into()],
            lighting: vec!["compute".into()],
            assignments: vec![DEFAULT_ASSIGNMENT.into()],
            far_fields: vec!["off".into()],
            noise_seeds: 8,
            thresholds: vec![manylights::DEFAULT_THRESHOLD],
            falloffs: vec!["windowed".into()],
            intensity: DEFAULT_INTENSITY,
            saturation: manylights::lights::DEFAULT_SATURATION,
            spot_fractions: vec![0.0],
            spot_angles: (20.0, 30.0),
            spot_cullings: vec!["cone".into()],
            camera: None,
            // The H200 lowers its clocks while the CPU computes a configuration's
            // reference: with 3 warm-up frames the next configuration measured up to 5x
            // slow (tonemap 1.62 ms instead of 0.29 ms, scale preset run). At least 20
            // frames, then until the GPU time settles.
            warmup_frames: 20,
            frames: 10,
            time_step: 1.0 / 60.0,
            seed: 1,
            reference_light_limit: 20_000,
            reference_samples: 256,
            naive_light_limit: 20_000,
        }
    }
}

impl BenchMatrix {
    /// `reference`: the reference projects' workload (Sponza, lights in (-10,0,-5) to
    /// (10,8,5), radius 2, 1920x1080, 500 to 5,000 lights), every pipeline and layout.
    pub fn reference() -> Self {
        Self {
            lights: vec![500, 1000, 2000, 5000],
            sizes: vec!["1920x1080".into()],
            gbuffers: GBufferLayout::ALL.map(|l| l.to_string()).to_vec(),
            lighting: LightingPath::ALL.map(|p| p.to_string()).to_vec(),
            ..Self::default()
        }
    }

    /// `assignment`: the light assignment's cost against light count (Sponza, 1920x1080,
    /// radius 2 m, deferred compact/compute, 1,000 to 1,000,000 lights), today's design
    /// beside the grid's boxes and the first design (atomic fill and sort).
    pub fn assignment() -> Self {
        Self {
            pipelines: vec!["deferred".into()],
            lights: vec![1000, 5000, 20_000, 100_000, 1_000_000],
            sizes: vec!["1920x1080".into()],
            assignments: vec![
                "tile-masks/visible".into(),
                "tile-masks/grid".into(),
                "atomic-fill/grid".into(),
            ],
            naive_light_limit: 0,
            reference_light_limit: 0,
            reference_samples: 64,
            ..Self::default()
        }
    }

    /// `scale`: up to 200,000 lights, in Sponza and in the pillars scene grown to 8.4
    /// million triangles, across light thresholds and grids.
    pub fn scale() -> Self {
        Self {
            scenes: vec!["sponza".into(), "pillars:32x64".into()],
            lights: vec![1000, 10_000, 50_000, 200_000],
            sizes: vec!["1920x1080".into()],
            grids: vec!["16x9x48:log-near".into(), "32x18x64:log-near".into()],
            thresholds: vec![0.05, 0.2],
            naive_light_limit: 5000,
            reference_light_limit: 5000,
            ..Self::default()
        }
    }

    /// `far-field`: the unbounded image approached by the radius alone and by each far-field
    /// method (Sponza, 1920x1080, 5,000 lights, deferred compact/compute, radius 1 to 14.1 m),
    /// every error against the unbounded reference.
    pub fn far_field() -> Self {
        Self {
            pipelines: vec!["deferred".into()],
            lights: vec![5000],
            sizes: vec!["1920x1080".into()],
            // Radius sqrt(0.2 / threshold): 1, 2, 4, 6.3, 14.1 m.
            thresholds: vec![0.2, 0.05, 0.0125, 0.005, 0.001],
            far_fields: vec![
                "off".into(),
                "tree:0.3".into(),
                "tree:0.1".into(),
                "tree:0.03".into(),
                "stochastic:4".into(),
                "stochastic:1".into(),
                "stochastic:0.25".into(),
            ],
            ..Self::default()
        }
    }

    /// `spots`: point lights against half of them spots (Sponza, 1920x1080, 5,000 and
    /// 100,000 lights, every pipeline; spots culled by their cone and by their range
    /// sphere, to measure the cone test's false positives).
    pub fn spots() -> Self {
        Self {
            lights: vec![5000, 100_000],
            sizes: vec!["1920x1080".into()],
            spot_fractions: vec![0.0, 0.5],
            spot_cullings: vec!["cone".into(), "sphere".into()],
            ..Self::default()
        }
    }

    pub fn preset(name: &str) -> anyhow::Result<Self> {
        match name {
            "reference" => Ok(Self::reference()),
            "scale" => Ok(Self::scale()),
            "assignment" => Ok(Self::assignment()),
            "far-field" => Ok(Self::far_field()),
            "spots" => Ok(Self::spots()),
            other => {
                bail!("unknown preset '{other}' (reference, scale, assignment, far-field, spots)")
            }
        }
    }

    pub fn from_toml(path: &Path) -> anyhow::Result<Self> {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        toml::from_str(&text).with_context(|| format!("{}: invalid bench matrix", path.display()))
    }

    /// Every configuration, in run order.
    pub fn configurations(&self) -> anyhow::Result<Vec<BenchConfig>> {
        let mut out = Vec::new();
        for scene in &self.scenes {
            for size in &self.sizes {
                let size = parse_size(size)?;
                for &lights in &self.lights {
                    for &threshold in &self.thresholds {
                        for falloff in &self.falloffs {
                            let falloff = parse::<Falloff>(falloff)?;
                            for pipeline in &self.pipelines {
                                let pipeline = parse::<PipelineKind>(pipeline)?;
                                if pipeline == PipelineKind::Naive
                                    && lights > self.naive_light_limit
                                {
                                    continue;
                                }
                                if pipeline != PipelineKind::Naive && !falloff.is_bounded() {
                                    continue;
                                }
                                let grids: Vec<Option<String>> = if pipeline == PipelineKind::Naive
                                {
                                    vec![None]
                                } else {
                                    self.grids.iter().cloned().map(Some).collect()
                                };
                                let layouts: Vec<Option<GBufferLayout>> =
                                    if pipeline == PipelineKind::Deferred {
                                        self.gbuffers
                                            .iter()
                                            .map(|g| parse::<GBufferLayout>(g).map(Some))
                                            .collect::<anyhow::Result<_>>()?
                                    } else {
                                        vec![None]
                                    };
                                let paths: Vec<Option<LightingPath>> =
                                    if pipeline == PipelineKind::Deferred {
                                        self.lighting
                                            .iter()
                                            .map(|l| parse::<LightingPath>(l).map(Some))
                                            .collect::<anyhow::Result<_>>()?
                                    } else {
                                        vec![None]
                                    };
                                let assignments: Vec<Option<String>> =
                                    if pipeline == PipelineKind::Naive {
                                        vec![None]
                                    } else {
                                        self.assignments
                                            .iter()
                                            .map(|a| parse_assignment(a).map(|_| Some(a.clone())))
                                            .collect::<anyhow::Result<_>>()?
                                    };
                                // A far field completes the windowed falloff: only there.
                                let far_fields: Vec<Option<String>> =
                                    if pipeline == PipelineKind::Naive {
                                        vec![None]
                                    } else {
                                        self.far_fields
                                            .iter()
                                            .map(|f| {
                                                parse_far_field(f)
                                                    .map(|far| far.map(|far| far.to_string()))
                                            })
                                            .collect::<anyhow::Result<Vec<_>>>()?
                                            .into_iter()
                                            .filter(|far| {
                                                far.is_none()
                                                    || falloff == Falloff::WindowedInverseSquare
                                            })
                                            .collect()
                                    };
                                for grid in &grids {
                                    for layout in &layouts {
                                        for path in &paths {
                                            for assignment in &assignments {
                                                for far_field in &far_fields {
                                                    for &spot_fraction in &self.spot_fractions {
                                                        for spot_culling in spot_cullings(
                                                            pipeline,
                                                            spot_fraction,
                                                            &self.spot_cullings,
                                                        ) {
                                                            out.push(BenchConfig {
                                                                scene: scene.clone(),
                                                                pipeline: pipeline.to_string(),
                                                                lights,
                                                                size,
                                                                grid: grid.clone(),
                                                                gbuffer: layout
                                                                    .map(|l| l.name().to_string()),
                                                                lighting: path
                                                                    .map(|p| p.name().to_string()),
                                                                assignment: assignment.clone(),
                                                                threshold,
                                                                falloff: falloff.to_string(),
                                                                far_field: far_field.clone(),
                                                                spot_fraction,
                                                                spot_culling,
                                                            });
                                                        }
                                                    }
                                                }
                                            }
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        Ok(out)
    }
}

fn parse_size(text: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = text
        .split_once('x')
        .with_context(|| format!("size '{text}': expected WIDTHxHEIGHT"))?;
    let size = (w.parse()?, h.parse()?);
    if size.0 == 0 || size.1 == 0 {
        bail!("size '{text}' is empty");
    }
    Ok(size)
}

/// Parses a name with the type's one `FromStr` (shared with the CLI and the viewer).
fn parse<T: std::str::FromStr<Err = String>>(text: &str) -> anyhow::Result<T> {
    text.parse().map_err(anyhow::Error::msg)
}

/// What the matrix's `assignments` default to.
pub const DEFAULT_ASSIGNMENT: &str = "tile-masks/visible";

/// `DESIGN/BOXES`, e.g. `tile-masks/visible` (names from `AssignmentDesign` and
/// `ClusterBoxes`).
pub fn parse_assignment(text: &str) -> anyhow::Result<(AssignmentDesign, ClusterBoxes)> {
    let (design, boxes) = text.split_once('/').with_context(|| {
        format!("assignment '{text}': expected DESIGN/BOXES, e.g. tile-masks/visible")
    })?;
    Ok((parse(design)?, parse(boxes)?))
}

/// `off` or a far field, `METHOD[:TOLERANCE]` (names from `FarField`).
/// The spot-culling variants a configuration runs: one (the default, cone) unless the
/// pipeline clusters and there are spots to cull; `sphere` is recorded, `cone` is not.
fn spot_cullings(
    pipeline: PipelineKind,
    spot_fraction: f32,
    cullings: &[String],
) -> Vec<Option<String>> {
    if pipeline == PipelineKind::Naive || spot_fraction <= 0.0 {
        return vec![None];
    }
    cullings
        .iter()
        .map(|c| (c != "cone").then(|| c.clone()))
        .collect()
}

pub fn parse_far_field(text: &str) -> anyhow::Result<Option<FarField>> {
    if text == "off" {
        return Ok(None);
    }
    Ok(Some(parse(text)?))
}

/// `16x9x48` or `16x9x48:log-near` / `:log` / `:linear`.
pub fn parse_grid(text: &str) -> anyhow::Result<ClusterSettings> {
    let (dims, scheme) = text.split_once(':').unwrap_or((text, "log-near"));
    let parts: Vec<u32> = dims
        .split('x')
        .map(|v| v.parse())
        .collect::<Result<_, _>>()
        .with_context(|| format!("grid '{text}': expected XxYxSLICES"))?;
    let [x, y, slices] = parts[..] else {
        bail!("grid '{text}': expected XxYxSLICES");
    };
    let z_scheme = match scheme {
        "log-near" => ZScheme::LogarithmicWithNearSlice {
            first_slice_far: 1.0,
        },
        "log" => ZScheme::Logarithmic,
        "linear" => ZScheme::Linear,
        other => bail!("grid '{text}': unknown slicing '{other}' (log-near, log, linear)"),
    };
    Ok(ClusterSettings {
        tiles: TileSpec::Count { x, y },
        z_slices: slices,
        z_scheme,
        ..ClusterSettings::default()
    })
}

/// One configuration of the matrix.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BenchConfig {
    pub scene: String,
    pub pipeline: String,
    pub lights: u32,
    pub size: (u32, u32),
    pub grid: Option<String>,
    pub gbuffer: Option<String>,
    pub lighting: Option<String>,
    /// Clustered pipelines: `DESIGN/BOXES` (absent in reports written before it existed:
    /// the default then).
    #[serde(default)]
    pub assignment: Option<String>,
    pub threshold: f32,
    /// The pipeline's falloff (with a far field: the windowed one it completes).
    pub falloff: String,
    /// Clustered pipelines: the far field, `METHOD:TOLERANCE` (absent: none; the image then
    /// has the falloff above, with one: unbounded inverse-square).
    #[serde(default)]
    pub far_field: Option<String>,
    /// The fraction of lights that are spots (0 in reports written before spots).
    #[serde(default)]
    pub spot_fraction: f32,
    /// Clustered pipelines with spots: `sphere` when spots were culled by their range
    /// sphere alone (absent: by their cone).
    #[serde(default)]
    pub spot_culling: Option<String>,
}

impl BenchConfig {
    /// A short label: `deferred compact/compute 16x9x48:log-near`.
    pub fn variant(&self) -> String {
        let mut label = self.pipeline.clone();
        if let (Some(g), Some(l)) = (&self.gbuffer, &self.lighting) {
            label.push_str(&format!(" {g}/{l}"));
        }
        if let Some(assignment) = self
            .assignment
            .as_ref()
            .filter(|a| *a != DEFAULT_ASSIGNMENT)
        {
            label.push_str(&format!(" ({assignment})"));
        }
        if let Some(method) = self
            .far_field
            .as_ref()
            .and_then(|far| far.split(':').next())
        {
            label.push_str(&format!(" + far field {method}"));
        }
        if self.spot_fraction > 0.0 {
            label.push_str(&format!(" + {:.0}% spots", self.spot_fraction * 100.0));
        }
        if let Some(culling) = &self.spot_culling {
            label.push_str(&format!(" ({culling} culling)"));
        }
        label
    }

    /// Everything that tells this configuration from the others of a run, for logs:
    /// `deferred compact/compute + far field tree, sponza 1920x1080, 5000 lights,
    /// threshold 0.05, far field tree:0.3`.
    pub fn describe(&self) -> String {
        let mut text = format!(
            "{}, {} {}x{}, {} lights, threshold {}",
            self.variant(),
            self.scene,
            self.size.0,
            self.size.1,
            self.lights,
            self.threshold
        );
        if let Some(grid) = &self.grid {
            text.push_str(&format!(", grid {grid}"));
        }
        if let Some(far) = &self.far_field {
            text.push_str(&format!(", far field {far}"));
        }
        text
    }
}

/// Median and 95th percentile of a pass's GPU time, milliseconds.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PassTime {
    pub name: String,
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
    pub error: Option<String>,
    /// How many times the times were measured again because the clock probe pass ran
    /// slow (see [`slow_clock_results`]); the fastest probe's measurement is kept.
    #[serde(default)]
    pub clock_remeasures: u32,
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

fn percentile(values: &mut [f64], p: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    let index = ((values.len() as f64 - 1.0) * p).round() as usize;
    values[index.min(values.len() - 1)]
}

/// What the reference of a (scene, size, lights, camera) is: computed once, shared by the
/// configurations that differ only in pipeline settings.
struct Reference {
    key: (String, (u32, u32), u32),
    image: Option<Vec<[f32; 4]>>,
    image_rgba8: Option<image::RgbaImage>,
    samples: Vec<(usize, DVec3)>,
}

/// Runs the matrix, calling `progress` after each configuration. Stops early (keeping
/// what was measured) when `stop` becomes true.
pub fn run(
    matrix: &BenchMatrix,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(&BenchResult, usize, usize),
) -> anyhow::Result<BenchReport> {
    let configs = matrix.configurations()?;
    let context = GpuContext::new_headless().context("creating the GPU context")?;
    let summary = context.summary.clone();
    let mut report = BenchReport {
        adapter: summary.name.clone(),
        backend: summary.backend.clone(),
        driver: format!("{} {}", summary.driver, summary.driver_info),
        timestamps: summary.timestamps,
        started: format!(
            "unix time {}",
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0)
        ),
        matrix: matrix.clone(),
        results: Vec::new(),
        interrupted: false,
    };
    let mut renderer: Option<Renderer> = None;
    let mut context = Some(context);
    let mut reference: Option<Reference> = None;
    // The results measured with the scene now loaded start here.
    let mut scene_start = 0;
    for (index, config) in configs.iter().enumerate() {
        if stop.load(Ordering::SeqCst) {
            report.interrupted = true;
            break;
        }
        let loaded_scene = renderer.as_ref().map(|r| r.scene().name.clone());
        if loaded_scene.as_deref() != Some(scene_name(&config.scene).as_str()) {
            remeasure_slow_clocks(&mut renderer, matrix, &mut report, scene_start, &stop)?;
            scene_start = report.results.len();
            let scene = LoadedScene::load(&config.scene)
                .with_context(|| format!("loading {}", config.scene))?;
            match &mut renderer {
                Some(r) => r.load_scene(scene)?,
                None => {
                    renderer = Some(Renderer::new(
                        context.take().context("GPU context")?,
                        scene,
                    )?)
                }
            }
            reference = None;
        }
        let Some(renderer) = renderer.as_mut() else {
            bail!("no renderer");
        };
        let result = match run_config(renderer, matrix, config, &mut reference) {
            Ok(result) => result,
            Err(error) => failed(config, format!("{error:#}")),
        };
        progress(&result, index + 1, configs.len());
        report.results.push(result);
    }
    remeasure_slow_clocks(&mut renderer, matrix, &mut report, scene_start, &stop)?;
    Ok(report)
}

/// Passes whose work does not depend on the lights or the pipeline's light settings: the
/// same geometry drawn at the same size. Their time shows the GPU's clock, which drops
/// when the GPU idles (an H200 falls to 345 MHz while the CPU computes a reference) and
/// sometimes stays low through a configuration's warm-up and timed frames.
const CLOCK_PROBE_PASSES: [&str; 2] = ["g-buffer", "depth pre-pass"];

/// A probe pass slower than this times its fastest twin in the run marks a slow clock.
/// The probe's own spread between frames at a steady clock is well under 1% (H200: the
/// g-buffer pass at 1920x1080 reads 1.395 ms in every configuration), a lowered clock
/// makes it 2-5x slower.
const SLOW_CLOCK_FACTOR: f64 = 1.10;

/// How many more times a configuration with a slow clock is measured.
const SLOW_CLOCK_RETRIES: u32 = 2;

/// The clock probe among a configuration's passes, if it has one.
fn probe_pass(passes: &[PassTime]) -> Option<&PassTime> {
    passes
        .iter()
        .find(|p| CLOCK_PROBE_PASSES.contains(&p.name.as_str()))
}

/// The probe pass's median time of a result, with the work it stands for (scene, size,
/// pipeline, G-buffer layout, pass): results with equal keys draw the same geometry.
fn clock_probe(result: &BenchResult) -> Option<(String, f64)> {
    let pass = probe_pass(&result.passes)?;
    let c = &result.config;
    let key = format!(
        "{} {}x{} {} {:?} {}",
        c.scene, c.size.0, c.size.1, c.pipeline, c.gbuffer, pass.name
    );
    Some((key, pass.median_ms))
}

/// The fastest probe time of each kind of work among `results`.
fn fastest_probes(results: &[BenchResult]) -> BTreeMap<String, f64> {
    let mut fastest: BTreeMap<String, f64> = BTreeMap::new();
    for (key, ms) in results.iter().filter_map(clock_probe) {
        let entry = fastest.entry(key).or_insert(ms);
        *entry = entry.min(ms);
    }
    fastest
}

/// The results (indices) whose clock probe pass ran more than [`SLOW_CLOCK_FACTOR`]
/// times slower than the fastest probe of the same work among `results`: measured while
/// the GPU's clock was low, their times are not the configuration's.
pub fn slow_clock_results(results: &[BenchResult]) -> Vec<usize> {
    let fastest = fastest_probes(results);
    results
        .iter()
        .enumerate()
        .filter(|(_, r)| {
            clock_probe(r).is_some_and(|(key, ms)| ms > fastest[&key] * SLOW_CLOCK_FACTOR)
        })
        .map(|(index, _)| index)
        .collect()
}

/// Measures the times of every result of the loaded scene (`report.results[first..]`)
/// whose clock probe ran slow again, up to [`SLOW_CLOCK_RETRIES`] times, keeping the
/// measurement with the fastest probe. Accuracy is not measured again: it does not depend
/// on the clock.
fn remeasure_slow_clocks(
    renderer: &mut Option<Renderer>,
    matrix: &BenchMatrix,
    report: &mut BenchReport,
    first: usize,
    stop: &AtomicBool,
) -> anyhow::Result<()> {
    let Some(renderer) = renderer.as_mut() else {
        return Ok(());
    };
    let results = &mut report.results[first..];
    let fastest_of = fastest_probes(results);
    for index in slow_clock_results(results) {
        let result = &mut results[index];
        let Some((key, _)) = clock_probe(result) else {
            continue;
        };
        let fastest = fastest_of[&key];
        for _ in 0..SLOW_CLOCK_RETRIES {
            if stop.load(Ordering::SeqCst) {
                return Ok(());
            }
            let Some((_, probe_ms)) = clock_probe(result) else {
                break;
            };
            if probe_ms <= fastest * SLOW_CLOCK_FACTOR {
                break;
            }
            let mut settings = frame_settings(renderer, matrix, &result.config)?;
            let times = measure_times(renderer, matrix, &mut settings)?;
            result.clock_remeasures += 1;
            let probe_again = probe_pass(&times.passes).map_or(f64::INFINITY, |p| p.median_ms);
            log::info!(
                "{}: clock probe {probe_ms:.3} ms against {fastest:.3} ms elsewhere, measured again: {probe_again:.3} ms",
                result.config.describe()
            );
            if probe_again < probe_ms {
                result.passes = times.passes;
                result.gpu_total_median_ms = times.gpu_total_median_ms;
                result.gpu_total_p95_ms = times.gpu_total_p95_ms;
                result.cpu_frame_median_ms = times.cpu_frame_median_ms;
                result.evaluations_per_second = times
                    .gpu_total_median_ms
                    .map(|ms| result.light_evaluations as f64 / (ms / 1000.0));
            }
        }
    }
    Ok(())
}

/// The scene name a spec loads as (for detecting a change of scene).
fn scene_name(spec: &str) -> String {
    match spec {
        "sponza" | "cornell" => spec.to_string(),
        _ => LoadedScene::load(spec)
            .map(|s| s.name)
            .unwrap_or_else(|_| spec.to_string()),
    }
}

fn failed(config: &BenchConfig, error: String) -> BenchResult {
    BenchResult {
        config: config.clone(),
        passes: Vec::new(),
        gpu_total_median_ms: None,
        gpu_total_p95_ms: None,
        cpu_frame_median_ms: 0.0,
        accuracy: Accuracy::default(),
        lights_per_cluster_mean: None,
        lights_per_cluster_max: None,
        false_positive_ratio: None,
        cluster_count: None,
        light_evaluations: 0,
        evaluations_per_second: None,
        error: Some(error),
        clock_remeasures: 0,
    }
}

fn frame_settings(
    renderer: &Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
) -> anyhow::Result<FrameSettings> {
    let mut settings = FrameSettings::for_scene(renderer.scene());
    if let Some(camera) = &matrix.camera {
        settings.camera = renderer
            .scene()
            .camera(camera)
            .map_err(anyhow::Error::msg)?;
    }
    let mut pipeline = PipelineSettings::of_kind(parse(&config.pipeline)?);
    if let PipelineSettings::Deferred(deferred) = &mut pipeline {
        if let Some(layout) = &config.gbuffer {
            deferred.layout = parse(layout)?;
        }
        if let Some(path) = &config.lighting {
            deferred.lighting = parse(path)?;
        }
    }
    settings.pipeline = pipeline;
    let far_field = match &config.far_field {
        Some(far) => parse_far_field(far)?,
        None => None,
    };
    let falloff: Falloff = parse(&config.falloff)?;
    settings
        .set_falloff(
            if far_field.is_some() {
                Falloff::InverseSquare
            } else {
                falloff
            },
            far_field,
        )
        .map_err(anyhow::Error::msg)?;
    settings.size = config.size;
    settings.light_count = config.lights;
    settings.seed = matrix.seed;
    settings.intensity = matrix.intensity;
    settings.light_saturation = matrix.saturation;
    settings.spots = manylights::lights::SpotSettings {
        fraction: config.spot_fraction,
        cone: manylights::lights::SpotCone {
            inner: matrix.spot_angles.0.to_radians(),
            outer: matrix.spot_angles.1.to_radians(),
        },
    };
    if let Some(culling) = &config.spot_culling {
        settings.spot_culling = parse(culling)?;
    }
    settings.radius = RadiusMode::LuminanceThreshold(config.threshold);
    if let Some(grid) = &config.grid {
        settings.cluster = parse_grid(grid)?;
    }
    if let Some(assignment) = &config.assignment {
        (settings.assignment, settings.cluster_boxes) = parse_assignment(assignment)?;
    }
    settings.time = 1.0;
    Ok(settings)
}

/// What the timed frames of one configuration measured.
struct MeasuredTimes {
    passes: Vec<PassTime>,
    gpu_total_median_ms: Option<f64>,
    gpu_total_p95_ms: Option<f64>,
    cpu_frame_median_ms: f64,
}

/// Warms up until the GPU time settles, then times `matrix.frames` frames with a fixed
/// step (the lights keep moving). Leaves `settings.time` at the first timed frame's.
fn measure_times(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    settings: &mut FrameSettings,
) -> anyhow::Result<MeasuredTimes> {
    let policy = manylights::WarmUpPolicy {
        min_frames: matrix.warmup_frames,
        ..manylights::WarmUpPolicy::default()
    };
    let warm_up = manylights::warm_up(renderer, settings, &policy)?;
    log::info!("{warm_up}");
    let start_time = settings.time;
    let mut per_pass: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut pass_order: Vec<String> = Vec::new();
    let mut totals = Vec::new();
    let mut cpu = Vec::new();
    for frame in 0..matrix.frames.max(1) {
        settings.time = start_time + frame as f32 * matrix.time_step;
        let begin = Instant::now();
        let stats = renderer.render_frame_timed(settings)?;
        cpu.push(begin.elapsed().as_secs_f64() * 1000.0);
        if let GpuTimings::Measured(passes) = &stats.timings {
            for pass in passes {
                if !pass_order.contains(&pass.name) {
                    pass_order.push(pass.name.clone());
                }
                per_pass
                    .entry(pass.name.clone())
                    .or_default()
                    .push(pass.milliseconds);
            }
            totals.push(stats.timings.total().unwrap_or(0.0));
        }
    }
    settings.time = start_time;
    let passes: Vec<PassTime> = pass_order
        .iter()
        .map(|name| {
            let values = per_pass
                .get_mut(name)
                .map(|v| v.as_mut_slice())
                .unwrap_or(&mut []);
            PassTime {
                name: name.clone(),
                median_ms: percentile(values, 0.5),
                p95_ms: percentile(values, 0.95),
            }
        })
        .collect();
    let (gpu_total_median_ms, gpu_total_p95_ms) = if totals.is_empty() {
        (None, None)
    } else {
        (
            Some(percentile(&mut totals.clone(), 0.5)),
            Some(percentile(&mut totals, 0.95)),
        )
    };
    Ok(MeasuredTimes {
        passes,
        gpu_total_median_ms,
        gpu_total_p95_ms,
        cpu_frame_median_ms: percentile(&mut cpu, 0.5),
    })
}

fn run_config(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    reference: &mut Option<Reference>,
) -> anyhow::Result<BenchResult> {
    let mut settings = frame_settings(renderer, matrix, config)?;
    log::info!("{}", config.variant());
    let times = measure_times(renderer, matrix, &mut settings)?;

    // The measured frame again, at the first timed step, for accuracy and statistics.
    let clustered = settings.pipeline.needs_clusters();
    settings.cluster_stats = clustered;
    settings.false_positives = clustered;
    renderer.render_frame(&settings)?;
    let image = renderer.read_hdr()?;
    let image_rgba8 = renderer.read_output()?;
    let cluster_stats = renderer.wait_cluster_stats()?;
    let light_evaluations = if clustered {
        renderer.light_evaluations(&settings)?
    } else {
        renderer.covered_pixels()? * config.lights as u64
    };

    let accuracy = accuracy(
        renderer,
        matrix,
        config,
        &settings,
        &image,
        &image_rgba8,
        reference,
    )?;
    Ok(BenchResult {
        config: config.clone(),
        passes: times.passes,
        gpu_total_median_ms: times.gpu_total_median_ms,
        gpu_total_p95_ms: times.gpu_total_p95_ms,
        cpu_frame_median_ms: times.cpu_frame_median_ms,
        accuracy,
        lights_per_cluster_mean: cluster_stats.as_ref().map(|s| s.mean_lights),
        lights_per_cluster_max: cluster_stats.as_ref().map(|s| s.max_lights),
        false_positive_ratio: cluster_stats.as_ref().and_then(|s| s.false_positive_ratio),
        cluster_count: cluster_stats.as_ref().map(|s| s.clusters),
        light_evaluations,
        evaluations_per_second: times
            .gpu_total_median_ms
            .map(|ms| light_evaluations as f64 / (ms / 1000.0)),
        error: None,
        clock_remeasures: 0,
    })
}

/// Renders (or reuses) the reference for this frame and compares.
fn accuracy(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    settings: &FrameSettings,
    image: &[[f32; 4]],
    image_rgba8: &image::RgbaImage,
    reference: &mut Option<Reference>,
) -> anyhow::Result<Accuracy> {
    let key = (config.scene.clone(), config.size, config.lights);
    if reference.as_ref().is_none_or(|r| r.key != key) {
        let mut reference_settings = settings.clone();
        reference_settings.pipeline = PipelineSettings::Naive(NaiveSettings {
            falloff: Falloff::InverseSquare,
        });
        reference_settings.cluster_stats = false;
        reference_settings.false_positives = false;
        let (image, image_rgba8) = if config.lights <= matrix.reference_light_limit {
            renderer.render_frame(&reference_settings)?;
            (Some(renderer.read_hdr()?), Some(renderer.read_output()?))
        } else {
            (None, None)
        };
        let surface = renderer.capture_surface(&reference_settings)?;
        let lights = renderer.read_lights()?;
        let camera = reference_settings.camera.position.as_dvec3();
        let covered: Vec<usize> = (0..surface.position.len())
            .filter(|&i| surface.position[i][3] == 1.0)
            .collect();
        let step = (covered.len() / matrix.reference_samples.max(1) as usize).max(1);
        let samples = covered
            .iter()
            .step_by(step)
            .take(matrix.reference_samples as usize)
            .map(|&i| {
                let point = SurfacePoint::from_capture(&surface, i);
                (i, shade(&point, camera, &lights, Falloff::InverseSquare))
            })
            .collect();
        *reference = Some(Reference {
            key,
            image,
            image_rgba8,
            samples,
        });
    }
    let Some(reference) = reference.as_ref() else {
        bail!("reference missing");
    };
    let mut accuracy = Accuracy::default();
    if let (Some(ref_image), Some(ref_rgba8)) = (&reference.image, &reference.image_rgba8) {
        let error = image_error(ref_image, image);
        accuracy.max_abs = Some(error.max_abs);
        accuracy.mean_abs = Some(error.mean_abs);
        accuracy.psnr_db = Some(error.psnr_db);
        accuracy.flip_mean = Some(flip_mean(ref_rgba8, image_rgba8) as f64);
        if let Some(exposure) = exposure_from_reference(ref_image) {
            let reference_ldr = tonemap_aces(ref_image, exposure, config.size);
            let test_ldr = tonemap_aces(image, exposure, config.size);
            accuracy.reference_exposure = Some(exposure);
            accuracy.flip_at_reference_exposure = Some(flip_mean(&reference_ldr, &test_ldr) as f64);
        }
    }
    let pixel = |image: &[[f32; 4]], i: usize| {
        DVec3::new(image[i][0] as f64, image[i][1] as f64, image[i][2] as f64)
    };
    let relative =
        |got: DVec3, want: DVec3| (got - want).abs().max_element() / want.max_element().max(1e-4);
    let errors: Vec<f64> = reference
        .samples
        .iter()
        .map(|(i, want)| relative(pixel(image, *i), *want))
        .collect();
    accuracy.samples = errors.len() as u32;
    accuracy.f64_max_relative = errors.iter().copied().fold(0.0, f64::max);
    accuracy.f64_mean_relative = mean(&errors);
    // Thirds by the reference's brightness.
    let mut by_brightness: Vec<usize> = (0..errors.len()).collect();
    by_brightness.sort_by(|&a, &b| {
        reference.samples[a]
            .1
            .max_element()
            .total_cmp(&reference.samples[b].1.max_element())
    });
    let third = errors.len() / 3;
    if third > 0 {
        let pick =
            |indices: &[usize]| mean(&indices.iter().map(|&k| errors[k]).collect::<Vec<_>>());
        accuracy.f64_mean_relative_dark = pick(&by_brightness[..third]);
        accuracy.f64_mean_relative_bright = pick(&by_brightness[errors.len() - third..]);
    }
    // Stochastic far fields: the same frame under other seeds, for noise and bias.
    if let Some(far) = settings
        .far_field
        .filter(|far| far.method == FarFieldMethod::Stochastic && matrix.noise_seeds > 1)
    {
        let mut seeded = settings.clone();
        seeded.cluster_stats = false;
        seeded.false_positives = false;
        let mut per_seed: Vec<Vec<DVec3>> = Vec::new();
        for seed in 0..matrix.noise_seeds {
            seeded.far_field = Some(FarField { seed, ..far });
            renderer.render_frame_timed(&seeded)?;
            let hdr = renderer.read_hdr()?;
            per_seed.push(
                reference
                    .samples
                    .iter()
                    .map(|(i, _)| pixel(&hdr, *i))
                    .collect(),
            );
        }
        let seeds = per_seed.len() as f64;
        let (mut noise, mut bias) = (Vec::new(), Vec::new());
        for (k, (_, want)) in reference.samples.iter().enumerate() {
            let values: Vec<DVec3> = per_seed.iter().map(|s| s[k]).collect();
            let mean_value = values.iter().copied().sum::<DVec3>() / seeds;
            let variance = values
                .iter()
                .map(|v| (*v - mean_value).max_element().powi(2))
                .sum::<f64>()
                / (seeds - 1.0);
            noise.push(variance.sqrt() / want.max_element().max(1e-4));
            bias.push(relative(mean_value, *want));
        }
        accuracy.f64_noise_relative = Some(mean(&noise));
        accuracy.f64_bias_relative = Some(mean(&bias));
    }
    Ok(accuracy)
}

fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

/// The exposure that maps the reference's median lit luminance to mid-grey (0.18), as the
/// renderer's automatic exposure does; None for a black reference.
pub fn exposure_from_reference(reference: &[[f32; 4]]) -> Option<f64> {
    let mut luminance: Vec<f64> = reference
        .iter()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .filter(|l| *l > 0.0)
        .collect();
    if luminance.is_empty() {
        return None;
    }
    luminance.sort_by(f64::total_cmp);
    Some(0.18 / luminance[luminance.len() / 2])
}

/// An HDR image tonemapped as the renderer does (exposure, ACES fit, sRGB encoding).
pub fn tonemap_aces(image: &[[f32; 4]], exposure: f64, size: (u32, u32)) -> image::RgbaImage {
    let aces = |x: f64| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let mut out = image::RgbaImage::new(size.0, size.1);
    for (pixel, hdr) in out.pixels_mut().zip(image) {
        for (channel, value) in pixel.0.iter_mut().zip(&hdr[..3]) {
            let tonemapped = aces((*value as f64 * exposure).max(0.0));
            *channel = manylights::scene::color::linear_to_srgb8(tonemapped as f32);
        }
        pixel.0[3] = 255;
    }
    out
}

/// Error of a linear HDR image against a reference (RGB channels, alpha ignored).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    pub max_abs: f64,
    pub mean_abs: f64,
    /// 10 log10(peak^2 / MSE), peak = the reference's largest channel value.
    pub psnr_db: f64,
}

impl std::fmt::Display for ImageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "max abs {:.3e}, mean abs {:.3e}, PSNR {:.1} dB",
            self.max_abs, self.mean_abs, self.psnr_db
        )
    }
}

pub fn image_error(reference: &[[f32; 4]], test: &[[f32; 4]]) -> ImageError {
    let (mut max_abs, mut sum_abs, mut sum_sq, mut peak) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (r, t) in reference.iter().zip(test) {
        for c in 0..3 {
            let d = (r[c] as f64 - t[c] as f64).abs();
            max_abs = max_abs.max(d);
            sum_abs += d;
            sum_sq += d * d;
            peak = peak.max(r[c] as f64);
        }
    }
    let n = (reference.len() * 3).max(1) as f64;
    let mse = sum_sq / n;
    ImageError {
        max_abs,
        mean_abs: sum_abs / n,
        psnr_db: if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (peak * peak / mse).log10()
        },
    }
}

/// FLIP's default viewing condition: a 0.7 m wide 4K monitor seen from 0.7 m.
pub const FLIP_PIXELS_PER_DEGREE: f32 = 67.0;

/// The per-pixel FLIP (nv-flip) error between two tonemapped images of the same size.
fn flip_error(reference: &image::RgbaImage, test: &image::RgbaImage) -> nv_flip::FlipImageFloat {
    let rgb = |image: &image::RgbaImage| {
        let data: Vec<u8> = image
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
            .collect();
        nv_flip::FlipImageRgb8::with_data(image.width(), image.height(), &data)
    };
    nv_flip::flip(rgb(reference), rgb(test), FLIP_PIXELS_PER_DEGREE)
}

/// Mean FLIP between two tonemapped images.
pub fn flip_mean(reference: &image::RgbaImage, test: &image::RgbaImage) -> f32 {
    nv_flip::FlipPool::from_image(&flip_error(reference, test)).mean()
}

/// Mean FLIP and the error map (magma colours), for people to look at.
pub fn flip_mean_and_map(
    reference: &image::RgbaImage,
    test: &image::RgbaImage,
) -> (f32, image::RgbImage) {
    let error = flip_error(reference, test);
    let mean = nv_flip::FlipPool::from_image(&error).mean();
    let map = error.apply_color_lut(&nv_flip::magma_lut());
    let map =
        image::RgbImage::from_raw(map.width(), map.height(), map.to_vec()).unwrap_or_default();
    (mean, map)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timed(pipeline: &str, size: (u32, u32), probe: &str, probe_ms: f64) -> BenchResult {
        let config = BenchConfig {
            scene: "sponza".into(),
            pipeline: pipeline.into(),
            lights: 5000,
            size,
            grid: None,
            gbuffer: (pipeline == "deferred").then(|| "compact".into()),
            lighting: None,
            assignment: None,
            threshold: 0.05,
            falloff: "windowed".into(),
            far_field: None,
            spot_fraction: 0.0,
            spot_culling: None,
        };
        BenchResult {
            passes: vec![
                PassTime {
                    name: probe.into(),
                    median_ms: probe_ms,
                    p95_ms: probe_ms,
                },
                PassTime {
                    name: "lighting (compute)".into(),
                    median_ms: 3.0 * probe_ms,
                    p95_ms: 3.0 * probe_ms,
                },
            ],
            error: None,
            ..failed(&config, String::new())
        }
    }

    #[test]
    fn slow_clocks_are_found_against_the_same_work_only() {
        let results = [
            timed("deferred", (1920, 1080), "g-buffer", 1.395),
            // A lowered clock: the same g-buffer 3.3x slower.
            timed("deferred", (1920, 1080), "g-buffer", 4.605),
            // Within the probe's 10% slack.
            timed("deferred", (1920, 1080), "g-buffer", 1.50),
            // Other work: a larger size and Forward+'s pre-pass are compared only with
            // their own kind.
            timed("deferred", (3840, 2160), "g-buffer", 5.6),
            timed("forward-plus", (1920, 1080), "depth pre-pass", 0.5),
            timed("forward-plus", (1920, 1080), "depth pre-pass", 0.56),
            // No probe pass (naive): never flagged.
            BenchResult {
                passes: Vec::new(),
                ..timed("naive", (1920, 1080), "g-buffer", 0.0)
            },
        ];
        assert_eq!(slow_clock_results(&results), vec![1, 5]);
        assert!(slow_clock_results(&results[2..5]).is_empty());
    }
}
