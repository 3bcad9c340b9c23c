//! The command line's logic (the `manylights` binary lives in the viewer crate): clap
//! arguments for every frame setting ([`RenderArgs`]), their translation into
//! [`manylights::FrameSettings`] (`frame`), the headless `render` command that writes a PNG
//! and prints per-pass GPU times (`render`), and the lab's and the soak's arguments.

use std::path::PathBuf;
use std::str::FromStr;

use clap::Args;
use clap::builder::{PossibleValue, StringValueParser, TypedValueParser};
use manylights::cluster::{OptionalFarField, ZRange, ZScheme};
use manylights::gpu::NamedChoice;
use manylights::lights::Falloff;
use manylights::{DebugView, GBufferLayout, ImageSize, LightingPath, PipelineKind};

mod edges;
mod frame;
mod render;
mod setting_flags;

pub use edges::{EdgesArgs, edges};
pub use frame::frame_settings;
pub use render::render;
pub use setting_flags::{SETTING_FLAGS, SettingArgs, SettingAxisArgs, SettingFlag, url_query_args};

#[derive(Args, Clone, Debug)]
pub struct RenderArgs {
    /// The frame settings given by path (`--set`) and by the shortcuts of
    /// [`SETTING_FLAGS`] (`--lights`, `--size`, `--shadows`, `--tonemap`, `--gbuffer`, ...:
    /// every flag that sets one field as it is written).
    #[command(flatten)]
    pub setting_args: SettingArgs,
    /// `sponza`, `sponza-glass` (Sponza with blended glass banners and embers), `cornell`,
    /// `lamps`, `spheres`, `glass`, `wall`, `pillars`, `pillars:GRIDxSEGMENTS`, or a
    /// .gltf/.glb/.obj file.
    #[arg(long, default_value = "sponza")]
    pub scene: String,
    /// Shading pipeline: `naive` (every fragment loops over every light: the reference),
    /// `forward-plus` (clustered forward) or `deferred` (clustered deferred; the default,
    /// with the compact G-buffer and tiles lighting: the fastest).
    #[arg(long, default_value = "deferred", value_parser = choice::<PipelineKind>())]
    pub pipeline: PipelineKind,
    /// A preset of the scene (e.g. `reference` for Sponza) or `x,y,z,yaw,pitch[,fov[,roll]]`
    /// in degrees. Default: the scene's first preset.
    #[arg(long)]
    pub camera: Option<String>,
    /// An orthographic camera showing this many metres vertically (instead of perspective).
    #[arg(long)]
    pub orthographic: Option<f32>,
    /// Reverse-Z depth (1 at near, 0 at far): keeps depth precision for tiny near planes.
    #[arg(long)]
    pub reverse_z: bool,
    /// Where to write the PNG.
    #[arg(long, default_value = "manylights-frame.png")]
    pub out: PathBuf,
    /// `windowed`: saturate(1-(d/r)^4)^2 / max(d^2, eps); `reference-projects`:
    /// clamp(1-(d/r)^4, 0, 1) / d^2 (the reference projects'); `inverse-square`:
    /// 1 / max(d^2, eps), no radius (the accuracy reference: naive renders it exactly,
    /// Forward+ and deferred with a `--far-field`).
    #[arg(long, default_value = "windowed", value_parser = choice::<Falloff>())]
    pub falloff: Falloff,
    /// Forward+/deferred: what lights add beyond their radius, approximated instead of
    /// dropped (implies `--falloff inverse-square`): `off`, `tree` (a light tree cut per
    /// cluster: deterministic) or `stochastic` (stochastic light culling: unbiased, noisy),
    /// optionally with a tolerance, e.g. `tree:0.05`, and for the tree its slots per cluster,
    /// e.g. `tree:1:192` (default 64: at many lights they bound the error).
    #[arg(long, default_value = "off")]
    pub far_field: OptionalFarField,
    /// The far field's tolerance (overrides one given in `--far-field`): tree, the largest
    /// error bound of an approximated node relative to the cluster's far-field total (0:
    /// exact); stochastic, the scale of the random ranges r / sqrt(tolerance x xi) (0: exact).
    #[arg(long)]
    pub far_tolerance: Option<f32>,
    /// Stochastic far field: the seed of the random ranges (an image is reproducible for a
    /// seed).
    #[arg(long, default_value_t = 0)]
    pub far_seed: u32,
    /// A fixed exposure (radiance multiplier). Without it, exposure is automatic: the
    /// median luminance of the lit pixels maps to mid-grey (a GPU histogram; the viewer
    /// adapts over about half a second, `render` converges in the first frame).
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Automatic exposure: stops added (positive is brighter).
    #[arg(
        long,
        default_value = "0",
        allow_negative_numbers = true,
        conflicts_with = "exposure"
    )]
    pub exposure_compensation: f32,
    /// Generated spots' inner and outer cone half-angles in degrees, e.g. 20,30
    /// (0 <= inner <= outer <= 90, outer > 0).
    #[arg(long, value_parser = parse_spot_angles, default_value = "20,30")]
    pub spot_angles: (f32, f32),
    /// The BRDF: `pbr` (glTF's metallic-roughness) or `blinn-phong` (Lambert plus
    /// Blinn-Phong). Default: the scene file's own model (PBR for glTF, Blinn-Phong for
    /// OBJ/MTL and the built-in procedural scenes).
    #[arg(long, value_parser = choice::<manylights::lights::Shading>())]
    pub shading: Option<manylights::lights::Shading>,
    /// Move the camera through the scene's camera presets during the timed frames (this
    /// many frames from one to the next, positions and angles interpolated, back to the
    /// first at the end), lights animated at 60 frames a second: a walk for `--budget`.
    #[arg(long, value_name = "FRAMES_PER_PRESET")]
    pub walk: Option<u32>,
    /// Cluster tiles across and down, e.g. 16x9 (Forward+).
    #[arg(long, value_parser = parse_size, conflicts_with = "tile_size")]
    pub tiles: Option<(u32, u32)>,
    /// Cluster tile size in pixels, instead of --tiles.
    #[arg(long)]
    pub tile_size: Option<u32>,
    /// Depth slices of the cluster grid.
    #[arg(long)]
    pub slices: Option<u32>,
    /// Depth slicing: `log-near` (a first slice up to --first-slice, logarithmic beyond:
    /// Bevy, Filament), `log` (logarithmic from near to far: Olsson 2012, Doom 2016) or
    /// `linear`.
    #[arg(long, value_parser = choice::<ZScheme>())]
    pub z_scheme: Option<ZScheme>,
    /// Far depth of the first slice for --z-scheme log-near (metres).
    #[arg(long, default_value_t = manylights::cluster::DEFAULT_FIRST_SLICE_FAR)]
    pub first_slice: f32,
    /// The depth range the slices cover: `camera` (near to far) or `fitted` (the depth
    /// range of the scene's bounds in view).
    #[arg(long, value_parser = choice::<ZRange>())]
    pub z_range: Option<ZRange>,
    /// Forward+: skip the depth pre-pass.
    #[arg(long)]
    pub no_depth_prepass: bool,
    /// Draw a debug view instead of shading: `none`; clustered pipelines: `heatmap`
    /// (lights per cluster, legend strip at the bottom, 0 .. --heatmap-max), `slices`
    /// (depth slices in alternating colours), `evaluations` (lights each pixel evaluated,
    /// in the HDR target; with `--tonemap none` 1 light is white); deferred only: `albedo`,
    /// `normal` (0.5 + 0.5 n), `depth` (black at the eye to white at 32 m), `position`
    /// (fractional metres).
    #[arg(long, default_value = "none")]
    pub debug_view: DebugView,
    /// Light count shown as white in the heatmap.
    #[arg(long, default_value = "64")]
    pub heatmap_max: f32,
    /// Print lights-per-cluster statistics and the false-positive ratio (computed on the
    /// GPU in a pass of their own, read back without stalling the frame).
    #[arg(long)]
    pub stats: bool,
    /// `render`: frames to time after the warm-up (the first frame, then frames until the
    /// GPU time has settled; GPU times are the median per pass; default 1). Viewer: frames
    /// to run before exiting (default: until closed).
    #[arg(long)]
    pub frames: Option<u32>,
    /// `render`: seconds after which the warm-up stops even if the GPU time has not
    /// settled (a CPU rasteriser's times never settle within 3%; `0`: the first frame
    /// only) [default: 20].
    #[arg(long, value_parser = parse_seconds, allow_hyphen_values = true)]
    pub warmup_seconds: Option<f64>,
}

impl Default for RenderArgs {
    fn default() -> Self {
        #[derive(clap::Parser)]
        struct Defaults {
            #[command(flatten)]
            args: RenderArgs,
        }
        <Defaults as clap::Parser>::parse_from(["manylights"]).args
    }
}

/// The parser of a named choice's option (`manylights::gpu::named_choice!`): a name read
/// with the choice's `FromStr`, and every name of its `ALL` given to clap, so that `--help`
/// lists each value the option accepts (`[possible values: ...]`) and a new value cannot
/// be left out of it.
#[derive(Clone, Debug)]
pub struct ChoiceParser<T>(std::marker::PhantomData<T>);

pub fn choice<T: NamedChoice>() -> ChoiceParser<T> {
    ChoiceParser(std::marker::PhantomData)
}

impl<T> TypedValueParser for ChoiceParser<T>
where
    T: NamedChoice + FromStr<Err = String> + Clone + Send + Sync,
{
    type Value = T;

    fn parse_ref(
        &self,
        command: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        StringValueParser::new()
            .try_map(|text| text.parse::<T>())
            .parse_ref(command, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            T::all().iter().map(|c| PossibleValue::new(c.choice_name())),
        ))
    }
}

fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(seconds) if seconds.is_finite() && seconds >= 0.0 => Ok(seconds),
        _ => Err(format!(
            "'{text}' is not a number of seconds (finite, 0 or more)"
        )),
    }
}

/// `WIDTHxHEIGHT`, as [`ImageSize`] reads it.
fn parse_size(text: &str) -> Result<(u32, u32), String> {
    text.parse::<ImageSize>().map(Into::into)
}

/// `INNER,OUTER` in degrees.
fn parse_spot_angles(text: &str) -> Result<(f32, f32), String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [inner, outer] = parts.as_slice() else {
        return Err(format!(
            "expected INNER,OUTER in degrees (e.g. 20,30), got '{text}'"
        ));
    };
    let parse = |value: &str| {
        value
            .trim()
            .parse::<f32>()
            .map_err(|e| format!("'{value}' in '{text}': {e}"))
    };
    let angles = (parse(inner)?, parse(outer)?);
    manylights::lights::SpotCone {
        inner: angles.0.to_radians(),
        outer: angles.1.to_radians(),
    }
    .validate()
    .map_err(|e| format!("{e} (given in degrees: {text})"))?;
    Ok(angles)
}

/// `manylights bench`: the matrix from a preset, a TOML file or the defaults, with any
/// axis overridden on the command line.
#[derive(Args, Clone, Debug, Default)]
pub struct BenchArgs {
    /// Setting axes by path (`--axis`) and by the shortcuts of [`SETTING_FLAGS`]
    /// (`--msaa`, `--transparencies`, `--aa`, `--blooms`, `--light-shapes`).
    #[command(flatten)]
    pub setting_axes: SettingAxisArgs,
    /// `reference` (Sponza, 500-5,000 lights, 1920x1080, radius 2), `scale` (to 200,000
    /// lights and 8.4 M triangles), `assignment` (the assignment's cost, 1,000 to
    /// 1,000,000 lights, three designs), `far-field` (the unbounded image approached by
    /// the radius alone and by each far-field method, 5,000 lights), `spots`,
    /// `materials` (PBR against Blinn-Phong) or `shadows` (off, exact and each ray budget
    /// unfiltered, filtered, and filtered and accumulated over frames, 1,000 to 1,000,000
    /// lights with the tree far field: error in shadow and in light, flicker, lag) or
    /// `trade-offs` (every pipeline inside and outside the castle, without and with blended
    /// banners and embers, sorted and weighted, without and with MSAA 4x and 8x, 1,000 and
    /// 10,000 lights: where Forward+ wins).
    #[arg(long)]
    pub preset: Option<String>,
    /// A TOML file with the fields of `lab::BenchMatrix`.
    #[arg(long)]
    pub config: Option<PathBuf>,
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Camera presets, each a view (e.g. `reference,outside`).
    #[arg(long, value_delimiter = ',')]
    pub views: Vec<String>,
    /// naive, forward-plus, deferred.
    #[arg(long, value_delimiter = ',')]
    pub pipelines: Vec<PipelineKind>,
    #[arg(long, value_delimiter = ',')]
    pub lights: Vec<u32>,
    /// WIDTHxHEIGHT, comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub sizes: Vec<ImageSize>,
    /// XxYxSLICES[:log-near|log|linear], comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub grids: Vec<crate::lab::GridSpec>,
    #[arg(long, value_delimiter = ',')]
    pub gbuffers: Vec<GBufferLayout>,
    #[arg(long, value_delimiter = ',')]
    pub lighting: Vec<LightingPath>,
    #[arg(long, value_delimiter = ',')]
    pub thresholds: Vec<f32>,
    #[arg(long, value_delimiter = ',')]
    pub falloffs: Vec<Falloff>,
    /// Clustered pipelines: DESIGN/BOXES, e.g. tile-masks/visible,atomic-fill/grid.
    #[arg(long, value_delimiter = ',')]
    pub assignments: Vec<crate::lab::Assignment>,
    /// Clustered pipelines: off or `METHOD:TOLERANCE[:SLOTS]`, e.g. off,tree:0.1,tree:1:192,stochastic:1.
    #[arg(long, value_delimiter = ',')]
    pub far_fields: Vec<OptionalFarField>,
    /// Shadows: off, exact, rays:K (K = 1, 2, 4), rays:K+spatial, rays:K+spatial+temporal,
    /// or several (off,exact,rays:1+spatial).
    #[arg(long, value_delimiter = ',')]
    pub shadows: Vec<manylights::Shadows>,
    /// BRDFs: pbr, blinn-phong, or both (default: each scene's own).
    #[arg(long, value_delimiter = ',')]
    pub shadings: Vec<manylights::lights::Shading>,
    /// The reference's visibility for every configuration (default: each configuration's
    /// own); `exact` measures what leaving shadows out costs.
    #[arg(long)]
    pub reference_shadows: Option<manylights::Shadows>,
    /// Light colour saturation, 0 (white) to 1 (pure hues).
    #[arg(long)]
    pub saturation: Option<f32>,
    #[arg(long)]
    pub frames: Option<u32>,
    /// Warm-up frames at least (then until the GPU time settles).
    #[arg(long)]
    pub warmup: Option<u32>,
    /// Seconds after which a configuration's warm-up stops even if its GPU time has not
    /// settled (default 20).
    #[arg(long)]
    pub warmup_seconds: Option<f64>,
    #[arg(long)]
    pub camera: Option<String>,
    /// Where bench.json, REPORT.md and the charts go.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Measure nothing: redraw REPORT.md and the charts of an earlier run in DIR from its
    /// DIR/bench.json (which stays as it was measured).
    #[arg(long, value_name = "DIR")]
    pub replot: Option<PathBuf>,
}

/// `manylights soak`: many frames headless with settings changing every phase; resident
/// memory and GPU allocations must stay flat (see `soak`).
#[derive(Args, Clone, Debug)]
pub struct SoakArgs {
    #[arg(long, default_value = "cornell")]
    pub scene: String,
    #[arg(long, default_value_t = 100_000)]
    pub frames: u64,
    /// Frames between settings changes.
    #[arg(long, default_value_t = 250)]
    pub phase_frames: u64,
    /// WIDTHxHEIGHT of even phases (odd ones are 8 pixels larger each way).
    #[arg(long, default_value = "32x24")]
    pub size: ImageSize,
    /// Resident memory growth allowed after the first cycle, in MiB.
    #[arg(long, default_value_t = 16.0)]
    pub max_rss_growth_mib: f64,
    /// Where to write every sample and the verdict as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// `render`'s flags alone, as the crate's tests parse them.
#[cfg(test)]
#[derive(clap::Parser)]
pub(crate) struct Flags {
    #[command(flatten)]
    pub args: RenderArgs,
}

#[cfg(test)]
mod tests {
    use clap::Parser as _;
    use manylights::{AutoExposure, Exposure, FrameSettings};

    use super::{Flags, RenderArgs};

    /// The lab's grid specs (`16x9x48:log-near`) name the grid the command line's flags
    /// (`--tiles 16x9 --slices 48 --z-scheme log-near`) name: the two spell slicings alike.
    #[test]
    fn grid_specs_name_the_grid_the_flags_name() {
        use manylights::cluster::{TileSpec, ZScheme};
        let expected = [
            (
                "16x9x48",
                [
                    "--tiles",
                    "16x9",
                    "--slices",
                    "48",
                    "--z-scheme",
                    "log-near",
                ],
                (16, 9, 48),
                ZScheme::LogarithmicWithNearSlice {
                    first_slice_far: 1.0,
                },
            ),
            (
                "8x4x16:log",
                ["--tiles", "8x4", "--slices", "16", "--z-scheme", "log"],
                (8, 4, 16),
                ZScheme::Logarithmic,
            ),
            (
                "2x3x5:linear",
                ["--tiles", "2x3", "--slices", "5", "--z-scheme", "linear"],
                (2, 3, 5),
                ZScheme::Linear,
            ),
        ];
        for (spec, flags, (x, y, slices), scheme) in expected {
            let parsed = spec.parse::<crate::lab::GridSpec>().expect(spec);
            assert_eq!(
                parsed.to_string().parse::<crate::lab::GridSpec>(),
                Ok(parsed)
            );
            let grid = parsed.settings();
            assert_eq!(
                (grid.tiles, grid.z_slices, grid.z_scheme),
                (TileSpec::Count { x, y }, slices, scheme),
                "{spec}"
            );
            let args = Flags::parse_from(std::iter::once("manylights").chain(flags)).args;
            let settings = args.settings().expect(spec);
            let clustering = settings.pipeline.clustering().expect("deferred clusters");
            assert_eq!(clustering.grid, grid, "{spec}");
        }
        let error = "16x9x48:spiral"
            .parse::<crate::lab::GridSpec>()
            .expect_err("unknown slicing");
        assert!(error.contains("log-near, log, linear"), "{error}");
    }

    /// The command line without flags chooses the facade's default frame, but for the
    /// exposure: `render` and the viewer show frames at an automatic exposure, where a
    /// library frame keeps a fixed one. The two cannot drift apart.
    #[test]
    fn the_command_lines_defaults_are_the_default_frame() {
        let args = RenderArgs::default();
        assert_eq!(
            args.settings(),
            Ok(FrameSettings {
                post: manylights::PostSettings {
                    exposure: Exposure::Auto(AutoExposure::CONVERGE_NOW),
                    ..FrameSettings::default().post
                },
                ..FrameSettings::default()
            })
        );
        assert_eq!(args.scene_choices(), manylights::SceneChoices::default());
    }

    /// `render --light-shape` takes the spelling of `bench --light-shapes`' values, and a
    /// shape without its size is refused saying how to give it.
    #[test]
    fn render_and_bench_spell_a_light_shape_alike() {
        use manylights::lights::LightShape;
        for (spelling, shape) in [
            ("point", LightShape::Point),
            ("sphere:0.5", LightShape::Sphere(0.5)),
            ("rect:0.4", LightShape::Rect(0.4)),
        ] {
            let flags = ["manylights", "--light-shape", spelling];
            let args = Flags::parse_from(flags).args;
            let settings = args.settings().expect(spelling);
            assert_eq!(settings.lights.shape, shape, "{spelling}");
            assert_eq!(
                shape.to_string().parse(),
                Ok(shape),
                "bench's axis reads it back"
            );
        }
        // The shape is checked by the setting it sets: a shape without its size names
        // the path and how to give it; the flag of old is gone.
        let args = Flags::parse_from(["manylights", "--light-shape", "rect"]).args;
        let refused = args.settings().unwrap_err();
        assert!(refused.contains("lights.shape"), "{refused}");
        assert!(refused.contains("NAME:METRES"), "{refused}");
        let old = [
            "manylights",
            "--light-shape",
            "rect:0.4",
            "--light-size",
            "0.4",
        ];
        let refused = Flags::try_parse_from(old)
            .err()
            .expect("--light-size refused");
        assert!(refused.to_string().contains("--light-size"), "{refused}");
    }

    /// A flag of the light lists on naive is refused, not dropped.
    #[test]
    fn naive_refuses_the_light_lists_flags() {
        for flags in [
            &["--stats"][..],
            &["--tiles", "8x6"],
            &["--far-field", "tree"],
        ] {
            let args = Flags::parse_from(
                [
                    "manylights",
                    "--pipeline",
                    "naive",
                    "--falloff",
                    "inverse-square",
                ]
                .into_iter()
                .chain(flags.iter().copied()),
            )
            .args;
            let error = args.settings().expect_err("naive has no lists");
            assert!(error.contains("naive"), "{flags:?}: {error}");
        }
    }
}
