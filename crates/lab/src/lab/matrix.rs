//! The matrix a run covers (`BenchMatrix`: scenes x pipelines x every axis, with its
//! presets) and one configuration of it (`BenchConfig`), parsed from the CLI's and TOML's
//! text.

use std::path::Path;

use anyhow::{Context as _, bail};
use serde::{Deserialize, Serialize};

use manylights::cluster::{AssignmentDesign, ClusterBoxes, ClusterSettings, FarField, TileSpec};
use manylights::lights::Falloff;
use manylights::{DEFAULT_INTENSITY, GBufferLayout, LightingPath, PipelineKind};

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

pub(super) fn parse_size(text: &str) -> anyhow::Result<(u32, u32)> {
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
pub(super) fn parse<T: std::str::FromStr<Err = String>>(text: &str) -> anyhow::Result<T> {
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
pub(super) fn spot_cullings(
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
    // The command line's names (`--z-scheme`), with its default first slice.
    let z_scheme = <crate::cli::ZSchemeArg as clap::ValueEnum>::from_str(scheme, false)
        .map_err(|_| {
            anyhow::anyhow!("grid '{text}': unknown slicing '{scheme}' (log-near, log, linear)")
        })?
        .scheme(crate::cli::RenderArgs::default().first_slice);
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
