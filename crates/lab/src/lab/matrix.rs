//! The matrix a run covers (`BenchMatrix`: scenes x pipelines x every axis; its presets
//! are in `presets.rs`) and one configuration of it (`BenchConfig`). Every setting is held as its own
//! type and written in JSON and TOML with that type's one `Display`/`FromStr` (the
//! spelling the command line and the viewer use): a matrix with a misspelt name fails
//! when it is read, and nothing parses a configuration's text again.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use anyhow::{Context as _, bail};
use serde::{Deserialize, Serialize};
use serde_with::{DisplayFromStr, serde_as};

use super::setting_axes::{self, SettingAxes, SettingValues};
use manylights::cluster::{
    AssignmentDesign, ClusterBoxes, ClusterSettings, FarField, OptionalFarField, SpotCulling,
    TileSpec, ZScheme,
};
use manylights::gpu::Exposure;
use manylights::lights::{Falloff, RadiusMode, Shading, SpotCone, SpotSettings};
use manylights::{
    DEFAULT_INTENSITY, DialCombination, FrameLights, FrameSettings, GBufferLayout, ImageSize,
    LightingPath, PipelineKind, PipelineSettings, PostSettings, Renderer, SceneChoices,
    ShadowSettings, Shadows, ViewSettings,
};

/// Shadow rays per sampled pixel for the reference with visibility: every light of a
/// 5,000-light Sponza frame with the unbounded falloff traced exactly (16,384 a pixel,
/// 4.2 million for 256 pixels), an estimate beyond.
pub const DEFAULT_REFERENCE_SHADOW_RAYS: u32 = 16_384;

/// [`BenchMatrix::reference_image_rays`]' default: 256 rays a pixel put the estimate's
/// standard error at a few percent of a half-shadowed pixel (the spread of 8 samplers of 32
/// draws), in seconds at 1080p on the H200.
fn default_reference_image_rays() -> u32 {
    256
}

/// The configurations to run. Axes that do not apply to a pipeline are not multiplied
/// (naive has no grid, Forward+ no G-buffer).
#[serde_as]
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct BenchMatrix {
    pub scenes: Vec<String>,
    /// `naive`, `forward-plus`, `deferred`.
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub pipelines: Vec<PipelineKind>,
    pub lights: Vec<u32>,
    /// `WIDTHxHEIGHT`.
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub sizes: Vec<ImageSize>,
    /// `TILESXxTILESYxSLICES` or with a scheme suffix: `16x9x48:log-near`, `:log`, `:linear`.
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub grids: Vec<GridSpec>,
    /// `full`, `compact`, `packed` (deferred).
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub gbuffers: Vec<GBufferLayout>,
    /// `fragment`, `compute`, `tiles` (deferred).
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub lighting: Vec<LightingPath>,
    /// Luminance thresholds (radius = sqrt(intensity / threshold)).
    pub thresholds: Vec<f32>,
    /// `windowed`, `reference-projects` (`inverse-square` only runs on naive).
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub falloffs: Vec<Falloff>,
    /// Clustered pipelines: how lights are assigned, `DESIGN/BOXES`: `tile-masks/visible`
    /// (the default), `tile-masks/grid`, `atomic-fill/grid` (the first design), ...
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub assignments: Vec<Assignment>,
    /// Clustered pipelines: `off` (lights end at their radius) or a far field,
    /// `METHOD:TOLERANCE` (`tree:0.1`, `tree:1:192` with slots, `stochastic:1`): the configuration then renders the
    /// unbounded inverse-square falloff (its `falloffs` entry must be `windowed`, the part
    /// the lists sum exactly).
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub far_fields: Vec<OptionalFarField>,
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
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub spot_cullings: Vec<SpotCulling>,
    /// Whether geometry blocks light, `off` or `exact` (an axis).
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub shadows: Vec<Shadows>,
    /// The BRDF, `pbr` or `blinn-phong` (an axis); empty: each scene's own model.
    #[serde_as(as = "Vec<DisplayFromStr>")]
    pub shadings: Vec<Shading>,
    /// The visibility of the reference every configuration is compared with: absent, the
    /// configuration's own (exact shadows are compared with the reference with
    /// visibility, none with the one without); `exact`, always with visibility (what
    /// leaving shadows out costs).
    #[serde_as(as = "Option<DisplayFromStr>")]
    pub reference_shadows: Option<Shadows>,
    pub camera: Option<String>,
    /// Camera presets measured, each a view (an axis: e.g. `reference`, inside the castle,
    /// and `outside`; `draw:COUNT[:SEED]` is COUNT cameras drawn at random inside the
    /// scene, reported one by one and as mean, spread and worst over them); empty:
    /// `camera` alone.
    #[serde(default)]
    pub views: Vec<String>,
    /// Axes over any dial of the frame, by its path into `manylights::FrameSettings`
    /// (`"view.msaa" = [1, 4]`, `"post.anti_aliasing" = ["off", "taa"]`, `"lights.shape" =
    /// ["point", "rect:0.4"]`), multiplied in the order listed, the first outermost, inside
    /// the named axes above and outside the pipelines' own (`setting_axes`). A
    /// combination the frame plan refuses (TAA with MSAA, deferred with MSAA) is not run.
    #[serde(skip_serializing_if = "SettingAxes::is_empty")]
    pub settings: SettingAxes,
    /// Whether the scenes' emissive triangles are lights too (`--emissive-lights`; on by
    /// default, off in the presets measured before they were).
    #[serde(default = "on")]
    pub emissive_lights: bool,
    /// Warm-up frames at least; more until the GPU time settles (`manylights::warm_up`).
    pub warmup_frames: u32,
    /// The warm-up stops after this many seconds even if the GPU time has not settled (a
    /// slow GPU, or a CPU one such as SwiftShader, may never settle within a useful time).
    pub warmup_seconds: f64,
    pub frames: u32,
    /// Seconds between timed frames (lights keep moving).
    pub time_step: f32,
    pub seed: u32,
    /// Above this light count no reference image is rendered (naive is too slow); the
    /// f64 samples are still computed.
    pub reference_light_limit: u32,
    /// Pixels sampled for the f64 reference.
    pub reference_samples: u32,
    /// The reference with visibility: shadow rays at most per sampled pixel. Where more
    /// lights add to a pixel, that many are drawn in proportion to their contribution and
    /// the visible sum estimated without bias, with its 95% interval in the report
    /// (`lights::reference::shade_visible_estimate`); below it every ray is traced.
    pub reference_shadow_rays: u32,
    /// The full-frame reference with visibility beyond `reference_light_limit` lights
    /// (`visibility::GpuVisibleReference`): with at most this many lights every shadow
    /// ray is traced; with more, about this many a pixel estimate it, with each pixel's
    /// standard error.
    #[serde(default = "default_reference_image_rays")]
    pub reference_image_rays: u32,
    /// Skip naive above this many lights (its cost is pixels x lights).
    pub naive_light_limit: u32,
    /// Frames of the camera walk that measures flicker under motion (`lab::motion`); 0:
    /// not measured (each frame costs a full-frame reference).
    pub motion_frames: u32,
}

impl Default for BenchMatrix {
    fn default() -> Self {
        Self {
            scenes: vec!["sponza".into()],
            pipelines: PipelineKind::ALL.to_vec(),
            lights: vec![1000],
            sizes: vec![ImageSize::new(1280, 720)],
            grids: vec![GridSpec::default()],
            gbuffers: vec![GBufferLayout::Compact],
            lighting: vec![LightingPath::default()],
            assignments: vec![Assignment::default()],
            far_fields: vec![OptionalFarField(None)],
            noise_seeds: 8,
            thresholds: vec![manylights::DEFAULT_THRESHOLD],
            falloffs: vec![Falloff::WindowedInverseSquare],
            intensity: DEFAULT_INTENSITY,
            saturation: manylights::lights::DEFAULT_SATURATION,
            spot_fractions: vec![0.0],
            spot_angles: (20.0, 30.0),
            spot_cullings: vec![SpotCulling::Cone],
            shadows: vec![Shadows::Off],
            shadings: Vec::new(),
            reference_shadows: None,
            camera: None,
            views: Vec::new(),
            settings: SettingAxes::default(),
            emissive_lights: true,
            // The H200 lowers its clocks while the CPU computes a configuration's
            // reference: with 3 warm-up frames the next configuration measured up to 5x
            // slow (tonemap 1.62 ms instead of 0.29 ms, scale preset run). At least 20
            // frames, then until the GPU time settles.
            warmup_frames: 20,
            warmup_seconds: manylights::WarmUpPolicy::default().max_seconds,
            frames: 10,
            time_step: 1.0 / 60.0,
            seed: 1,
            reference_light_limit: 20_000,
            reference_samples: 256,
            reference_shadow_rays: DEFAULT_REFERENCE_SHADOW_RAYS,
            reference_image_rays: default_reference_image_rays(),
            naive_light_limit: 20_000,
            motion_frames: 0,
        }
    }
}

impl BenchMatrix {
    pub fn from_toml(path: &Path) -> anyhow::Result<Self> {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let invalid = || format!("{}: invalid bench matrix", path.display());
        let mut data: serde_json::Value = toml::from_str(&text).with_context(invalid)?;
        setting_axes::upgrade_matrix(&mut data);
        serde_json::from_value(data).with_context(invalid)
    }

    /// A matrix written as JSON (the page's measure panel, a report's `matrix`), read as
    /// [`Self::from_toml`] reads TOML: named axes written before the setting axes move
    /// into them.
    pub fn from_json(text: &str) -> anyhow::Result<Self> {
        let mut data: serde_json::Value =
            serde_json::from_str(text).context("the matrix is not JSON")?;
        setting_axes::upgrade_matrix(&mut data);
        serde_json::from_value(data).context("invalid bench matrix")
    }

    /// The settings no configuration can run with, refused with their reason.
    fn validate(&self) -> anyhow::Result<()> {
        if !(self.warmup_seconds.is_finite() && self.warmup_seconds >= 0.0) {
            bail!(
                "warm-up seconds {} must be a finite number of seconds, 0 or more",
                self.warmup_seconds
            );
        }
        if self.reference_image_rays == 0 {
            bail!(
                "reference_image_rays 0: the full-frame reference with visibility traces at \
                 least one shadow ray a pixel (the default is 256)"
            );
        }
        self.settings.validate().map_err(anyhow::Error::msg)?;
        if self.reference_samples == 0 {
            bail!(
                "reference_samples 0: every configuration's error is measured at f64 reference \
                 samples, at least 1 (the default is 256); with none the error columns would \
                 read 0"
            );
        }
        Ok(())
    }

    /// Every configuration, in run order.
    pub fn configurations(&self) -> anyhow::Result<Vec<BenchConfig>> {
        self.validate()?;
        let shadings: Vec<Option<Shading>> = if self.shadings.is_empty() {
            vec![None]
        } else {
            self.shadings.iter().copied().map(Some).collect()
        };
        let views: Vec<Option<String>> = if self.views.is_empty() {
            vec![self.camera.clone()]
        } else {
            let mut views = Vec::new();
            for view in &self.views {
                views.extend(
                    expand_view(view)
                        .map_err(anyhow::Error::msg)?
                        .into_iter()
                        .map(Some),
                );
            }
            views
        };
        let mut out = Vec::new();
        for (scene, view) in self
            .scenes
            .iter()
            .flat_map(|scene| views.iter().map(move |view| (scene, view)))
        {
            for &size in &self.sizes {
                let size = size.into();
                for &lights in &self.lights {
                    for &threshold in &self.thresholds {
                        for &falloff in &self.falloffs {
                            for ((&pipeline, &shadows), &shading) in self
                                .pipelines
                                .iter()
                                .flat_map(|p| self.shadows.iter().map(move |s| (p, s)))
                                .flat_map(|ps| shadings.iter().map(move |b| (ps, b)))
                            {
                                let base = BenchConfig {
                                    scene: scene.clone(),
                                    pipeline,
                                    lights,
                                    size,
                                    grid: None,
                                    gbuffer: None,
                                    lighting: None,
                                    assignment: None,
                                    threshold,
                                    falloff,
                                    far_field: None,
                                    spot_fraction: 0.0,
                                    spot_culling: None,
                                    shadows,
                                    shading,
                                    view: view.clone(),
                                    settings: SettingValues::new(),
                                };
                                for settings in self.settings.choices() {
                                    out.extend(self.pipeline_configurations(BenchConfig {
                                        settings,
                                        ..base.clone()
                                    }));
                                }
                            }
                        }
                    }
                }
            }
        }
        if out.is_empty() {
            bail!(
                "the matrix has no configuration to run: naive runs up to naive_light_limit = \
                 {} lights, Forward+ and deferred need a bounded falloff or a far field, and \
                 deferred refuses MSAA",
                self.naive_light_limit
            );
        }
        Ok(out)
    }

    /// The configurations of one pipeline at one scene, size, light count, threshold and
    /// falloff (`base`): every value of the axes that apply to it.
    fn pipeline_configurations(&self, base: BenchConfig) -> Vec<BenchConfig> {
        let pipeline = base.pipeline;
        let naive = pipeline == PipelineKind::Naive;
        if naive && base.lights > self.naive_light_limit {
            return Vec::new();
        }
        let deferred = pipeline == PipelineKind::Deferred;
        // An axis a pipeline does not have is one value: none.
        let grids = axis(!naive, &self.grids);
        let layouts = axis(deferred, &self.gbuffers);
        let paths = axis(deferred, &self.lighting);
        let assignments = axis(!naive, &self.assignments);
        // A far field is listed with the windowed falloff it completes (one configuration
        // for each image: inverse-square with a far field renders the same).
        let far_fields: Vec<Option<FarField>> = if naive {
            vec![None]
        } else {
            self.far_fields
                .iter()
                .map(|far| far.0)
                .filter(|far| far.is_none() || base.falloff == Falloff::WindowedInverseSquare)
                .collect()
        };
        let mut out = Vec::new();
        for &grid in &grids {
            for &gbuffer in &layouts {
                for &lighting in &paths {
                    for &assignment in &assignments {
                        for &far_field in &far_fields {
                            for &spot_fraction in &self.spot_fractions {
                                for spot_culling in
                                    spot_cullings(pipeline, spot_fraction, &self.spot_cullings)
                                {
                                    let config = BenchConfig {
                                        grid,
                                        gbuffer,
                                        lighting,
                                        assignment,
                                        far_field,
                                        spot_fraction,
                                        spot_culling,
                                        ..base.clone()
                                    };
                                    if plan_allows(self, &config) {
                                        out.push(config);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        out
    }
}

fn on() -> bool {
    true
}

/// The seed of `draw:COUNT` without one.
pub const DEFAULT_DRAW_SEED: u32 = 1;

/// A view of the matrix as the cameras it names: `draw:COUNT[:SEED]` is COUNT cameras
/// drawn at random inside the scene (`drawn:SEED:0` to `drawn:SEED:COUNT-1`,
/// `manylights::drawn_cameras`), any other view itself.
pub fn expand_view(view: &str) -> Result<Vec<String>, String> {
    let Some(request) = view.strip_prefix("draw:") else {
        return Ok(vec![view.to_string()]);
    };
    let refuse = |reason: &str| {
        format!("view '{view}': {reason} (draw:COUNT or draw:COUNT:SEED, e.g. draw:8)")
    };
    let (count, seed) = match request.split_once(':') {
        Some((count, seed)) => (
            count,
            seed.parse()
                .map_err(|_| refuse("a seed is a whole number"))?,
        ),
        None => (request, DEFAULT_DRAW_SEED),
    };
    let count: u32 = count
        .parse()
        .map_err(|_| refuse("the count of cameras is a whole number"))?;
    if count == 0 {
        return Err(refuse("draw at least one camera"));
    }
    Ok((0..count)
        .map(|index| manylights::drawn_cameras::drawn_camera_name(seed, index))
        .collect())
}

/// An axis's values for a pipeline it applies to; one value, none, for one it does not.
fn axis<T: Copy>(applies: bool, values: &[T]) -> Vec<Option<T>> {
    if applies {
        values.iter().copied().map(Some).collect()
    } else {
        vec![None]
    }
}

/// How a clustered configuration assigns lights, `DESIGN/BOXES`, e.g. `tile-masks/visible`
/// (names from `AssignmentDesign` and `ClusterBoxes`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Assignment {
    pub design: AssignmentDesign,
    pub boxes: ClusterBoxes,
}

impl Assignment {
    pub fn new(design: AssignmentDesign, boxes: ClusterBoxes) -> Self {
        Self { design, boxes }
    }
}

impl fmt::Display for Assignment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.design, self.boxes)
    }
}

impl FromStr for Assignment {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let (design, boxes) = text.split_once('/').ok_or_else(|| {
            format!("assignment '{text}': expected DESIGN/BOXES, e.g. tile-masks/visible")
        })?;
        Ok(Self::new(design.parse()?, boxes.parse()?))
    }
}

/// The spot-culling variants a configuration runs: one (the default, cone) unless the
/// pipeline clusters and there are spots to cull; `sphere` is recorded, `cone` is not.
pub(super) fn spot_cullings(
    pipeline: PipelineKind,
    spot_fraction: f32,
    cullings: &[SpotCulling],
) -> Vec<Option<SpotCulling>> {
    if pipeline == PipelineKind::Naive || spot_fraction <= 0.0 {
        return vec![None];
    }
    cullings
        .iter()
        .map(|&culling| (culling != SpotCulling::Cone).then_some(culling))
        .collect()
}

/// A cluster grid as the lab writes it: `16x9x48` (tiles across, down, depth slices) with
/// the slicing's `--z-scheme` name after a colon (`:log-near`, the default, `:log`,
/// `:linear`), the near slice ending at the command line's default depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub slices: u32,
    pub scheme: ZScheme,
}

impl Default for GridSpec {
    fn default() -> Self {
        Self {
            tiles_x: 16,
            tiles_y: 9,
            slices: 48,
            scheme: ClusterSettings::default().z_scheme,
        }
    }
}

impl GridSpec {
    /// The cluster settings it names.
    pub fn settings(&self) -> ClusterSettings {
        ClusterSettings {
            tiles: TileSpec::Count {
                x: self.tiles_x,
                y: self.tiles_y,
            },
            z_slices: self.slices,
            z_scheme: self.scheme,
            ..ClusterSettings::default()
        }
    }
}

impl fmt::Display for GridSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}x{}x{}:{}",
            self.tiles_x, self.tiles_y, self.slices, self.scheme
        )
    }
}

impl FromStr for GridSpec {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let (dims, scheme) = text.split_once(':').unwrap_or((text, "log-near"));
        let parts: Vec<u32> = dims
            .split('x')
            .map(|v| v.parse())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("grid '{text}': expected XxYxSLICES"))?;
        let [tiles_x, tiles_y, slices] = parts[..] else {
            return Err(format!("grid '{text}': expected XxYxSLICES"));
        };
        let scheme = scheme.parse::<ZScheme>().map_err(|_| {
            format!("grid '{text}': unknown slicing '{scheme}' (log-near, log, linear)")
        })?;
        Ok(Self {
            tiles_x,
            tiles_y,
            slices,
            scheme,
        })
    }
}

/// One configuration of the matrix.
#[serde_as]
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BenchConfig {
    pub scene: String,
    #[serde_as(as = "DisplayFromStr")]
    pub pipeline: PipelineKind,
    pub lights: u32,
    pub size: (u32, u32),
    /// Clustered pipelines.
    #[serde_as(as = "Option<DisplayFromStr>")]
    pub grid: Option<GridSpec>,
    /// Deferred.
    #[serde_as(as = "Option<DisplayFromStr>")]
    pub gbuffer: Option<GBufferLayout>,
    /// Deferred.
    #[serde_as(as = "Option<DisplayFromStr>")]
    pub lighting: Option<LightingPath>,
    /// Clustered pipelines (absent in reports written before it existed: the default then).
    #[serde_as(as = "Option<DisplayFromStr>")]
    #[serde(default)]
    pub assignment: Option<Assignment>,
    pub threshold: f32,
    /// The pipeline's falloff (with a far field: the windowed one it completes).
    #[serde_as(as = "DisplayFromStr")]
    pub falloff: Falloff,
    /// Clustered pipelines: the far field (absent: none; the image then has the falloff
    /// above, with one: unbounded inverse-square).
    #[serde_as(as = "Option<DisplayFromStr>")]
    #[serde(default)]
    pub far_field: Option<FarField>,
    /// The fraction of lights that are spots (0 in reports written before spots).
    #[serde(default)]
    pub spot_fraction: f32,
    /// Clustered pipelines with spots: `sphere` when spots were culled by their range
    /// sphere alone (absent: by their cone).
    #[serde_as(as = "Option<DisplayFromStr>")]
    #[serde(default)]
    pub spot_culling: Option<SpotCulling>,
    /// Whether geometry blocked light (`off` in reports written before shadows).
    #[serde_as(as = "DisplayFromStr")]
    #[serde(default)]
    pub shadows: Shadows,
    /// The BRDF; absent: the scene's own model (reports written before PBR: Blinn-Phong,
    /// the only one then).
    #[serde_as(as = "Option<DisplayFromStr>")]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shading: Option<Shading>,
    /// The camera preset (absent: the matrix's `camera`, or the scene's first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view: Option<String>,
    /// The matrix's setting axes' values, by path, as the matrix wrote them (reports
    /// written before they were axes: their MSAA, transparency, anti-aliasing, bloom and
    /// light shape, moved here where not the default, by `setting_axes::upgrade_config`).
    #[serde(default, skip_serializing_if = "SettingValues::is_empty")]
    pub settings: SettingValues,
}

impl BenchConfig {
    /// A short label: `deferred compact/compute 16x9x48:log-near`.
    pub fn variant(&self) -> String {
        let mut label = self.pipeline.to_string();
        if let (Some(g), Some(l)) = (&self.gbuffer, &self.lighting) {
            label.push_str(&format!(" {g}/{l}"));
        }
        if let Some(assignment) = self.assignment.filter(|a| *a != Assignment::default()) {
            label.push_str(&format!(" ({assignment})"));
        }
        if let Some(far) = &self.far_field {
            label.push_str(&format!(" + far field {}", far.method));
        }
        if self.spot_fraction > 0.0 {
            label.push_str(&format!(" + {:.0}% spots", self.spot_fraction * 100.0));
        }
        if let Some(culling) = &self.spot_culling {
            label.push_str(&format!(" ({culling} culling)"));
        }
        if let Some(shading) = &self.shading {
            label.push_str(&format!(" [{shading}]"));
        }
        if self.shadows.traced() {
            label.push_str(&format!(" + {} shadows", self.shadows));
        }
        if let Some(view) = &self.view {
            label.push_str(&format!(" @ {view}"));
        }
        label.push_str(&setting_axes::label(&self.settings));
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

/// A configuration's frame, placed in the renderer's scene.
pub(super) fn frame_settings(
    renderer: &Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
) -> anyhow::Result<FrameSettings> {
    let (settings, scene_choices) = frame_choice(matrix, config).map_err(anyhow::Error::msg)?;
    settings
        .placed_in(renderer.scene(), &scene_choices)
        .map_err(anyhow::Error::msg)
}

/// The frame `config` of `matrix` chooses, before a scene is loaded (what the matrix asks
/// the frame plan's rules of), and the camera and BRDF the scene places. Built on
/// [`FrameSettings::default`], as `render`'s flags are, so the lab cannot render a
/// configuration differently from `manylights render` with the same flags.
pub(crate) fn frame_choice(
    matrix: &BenchMatrix,
    config: &BenchConfig,
) -> Result<(FrameSettings, SceneChoices), String> {
    let mut pipeline = PipelineSettings::of_kind(config.pipeline);
    if let PipelineSettings::Deferred(deferred) = &mut pipeline {
        deferred.layout = config.gbuffer.unwrap_or(deferred.layout);
        deferred.lighting = config.lighting.unwrap_or(deferred.lighting);
    }
    if let Some(clustering) = pipeline.clustering_mut() {
        clustering.grid = config.grid.map_or(clustering.grid, |grid| grid.settings());
        clustering.assignment = config
            .assignment
            .map_or(clustering.assignment, |a| a.design);
        clustering.boxes = config.assignment.map_or(clustering.boxes, |a| a.boxes);
        clustering.spot_culling = config.spot_culling.unwrap_or(clustering.spot_culling);
    }
    let defaults = FrameSettings::default();
    let mut settings = FrameSettings {
        // The configuration names the pipeline's falloff: with a far field, the windowed
        // one it completes.
        pipeline: pipeline.with_asked_falloff(config.falloff, config.far_field)?,
        view: ViewSettings {
            size: config.size,
            ..defaults.view
        },
        lights: FrameLights {
            count: config.lights,
            seed: matrix.seed,
            intensity: matrix.intensity,
            radius: RadiusMode::LuminanceThreshold(config.threshold),
            saturation: matrix.saturation,
            spots: SpotSettings {
                fraction: config.spot_fraction,
                cone: SpotCone {
                    inner: matrix.spot_angles.0.to_radians(),
                    outer: matrix.spot_angles.1.to_radians(),
                },
            },
            emissive: matrix.emissive_lights,
            time: 1.0,
            // The rest as the default frame's (a field added there needs nothing here).
            ..defaults.lights
        },
        shadows: ShadowSettings {
            mode: config.shadows,
            ..defaults.shadows
        },
        // One fixed exposure (the default's): accuracy compares images at the reference's
        // exposure.
        post: PostSettings {
            exposure: Exposure::Manual(1.0),
            ..defaults.post
        },
        ..defaults
    };
    super::setting_axes::apply(&mut settings, &config.settings)?;
    let scene_choices = SceneChoices {
        camera: config.view.clone().or_else(|| matrix.camera.clone()),
        shading: config.shading,
        ..SceneChoices::default()
    };
    Ok((settings, scene_choices))
}

/// Whether the frame plan's rules allow `config`'s combination of dials, whatever its
/// scene and camera (deferred with MSAA, a clustered pipeline's unbounded falloff without
/// a far field, ... are refused).
pub(super) fn plan_allows(matrix: &BenchMatrix, config: &BenchConfig) -> bool {
    frame_choice(matrix, config)
        .and_then(|(settings, _)| DialCombination::of(&settings).check())
        .is_ok()
}
