//! The command line's flags onto setting paths: one table ([`SETTING_FLAGS`]) names each
//! shortcut (`render --bloom 0.05`, `bench --blooms 0,0.05`) and the path into
//! [`manylights::FrameSettings`] it sets; `--set PATH=VALUE` (render, the viewer, the
//! page's `?PATH=VALUE`) and `--axis PATH=V1,V2` (bench) reach every other path. A value is
//! checked by the field it sets, so the flags need no parser of their own.

use clap::builder::PossibleValuesParser;
use clap::{Arg, ArgAction, ArgMatches, Command, FromArgMatches};
use manylights::cluster::{AssignmentDesign, ClusterBoxes, SpotCulling};
use manylights::gpu::{NamedChoice, Tonemap};
use manylights::{FrameSettings, GBufferLayout, LightingPath};

/// A command-line shortcut onto a setting's path.
#[derive(Debug, Clone, Copy)]
pub struct SettingFlag {
    /// `render`'s and the viewer's flag (one value).
    pub flag: &'static str,
    /// `bench`'s flag for an axis of this path (values separated by commas); none where
    /// the matrix names the axis itself (`--lights`, `--sizes`, `--shadows`, ...).
    pub axis_flag: Option<&'static str>,
    /// The path into the frame settings.
    pub path: &'static str,
    pub help: &'static str,
    /// The names the field takes, where it is a choice of names: `--help` lists them and
    /// the command line refuses another before a frame is built.
    pub names: Option<fn() -> Vec<&'static str>>,
    /// A flag that sets the same field another way (`--radius` and `--threshold`).
    pub conflicts_with: Option<&'static str>,
}

/// Every name of a choice, in its order.
fn names<T: NamedChoice>() -> Vec<&'static str> {
    T::all().iter().map(NamedChoice::choice_name).collect()
}

impl SettingFlag {
    /// A flag of `path` with no axis flag of its own, no names and no conflict.
    const fn new(flag: &'static str, path: &'static str, help: &'static str) -> Self {
        Self {
            flag,
            axis_flag: None,
            path,
            help,
            names: None,
            conflicts_with: None,
        }
    }

    const fn axis(self, axis_flag: &'static str) -> Self {
        Self {
            axis_flag: Some(axis_flag),
            ..self
        }
    }

    const fn names(self, names: fn() -> Vec<&'static str>) -> Self {
        Self {
            names: Some(names),
            ..self
        }
    }

    const fn conflicts_with(self, flag: &'static str) -> Self {
        Self {
            conflicts_with: Some(flag),
            ..self
        }
    }
}

/// Every shortcut. A dial without one is still `--set PATH=VALUE` and `--axis PATH=...`;
/// the flags that are not rows here combine several fields or convert a unit (the grid's,
/// the far field's, the exposure's, the spots' angles in degrees: `RenderArgs::settings`).
pub const SETTING_FLAGS: [SettingFlag; 23] = [
    SettingFlag::new("lights", "lights.count", "Number of generated lights"),
    SettingFlag::new("size", "view.size", "Image size, WIDTHxHEIGHT"),
    SettingFlag::new("time", "lights.time", "Animation time in seconds").axis("times"),
    SettingFlag::new("seed", "lights.seed", "Seed of the light set"),
    SettingFlag::new(
        "intensity",
        "lights.intensity",
        "Light intensity (radiance at 1 m)",
    ),
    SettingFlag::new(
        "saturation",
        "lights.saturation",
        "Light colour saturation from 0 (white) to 1 (pure random hues)",
    ),
    SettingFlag::new(
        "spot-fraction",
        "lights.spots.fraction",
        "The fraction of generated lights that are spots (0 to 1), pointing down at random",
    ),
    SettingFlag::new(
        "light-shape",
        "lights.shape",
        "The generated lights that are not spots: `point`, `sphere:SIZE` (of diameter SIZE \
         metres) or `rect:SIZE` (a square of side SIZE, facing a random direction of the \
         lower hemisphere, its intensity along its normal)",
    )
    .axis("light-shapes"),
    SettingFlag::new(
        "emissive-lights",
        "lights.emissive",
        "Whether the scene's emissive triangles are lights too (`on`), or only glow (`off`)",
    ),
    SettingFlag::new(
        "radius",
        "lights.radius.fixed",
        "Fixed light radius in metres (instead of deriving it from --threshold)",
    )
    .conflicts_with("threshold"),
    SettingFlag::new(
        "threshold",
        "lights.radius.luminance-threshold",
        "Luminance threshold: radius = sqrt(intensity / threshold)",
    ),
    SettingFlag::new(
        "shadows",
        "shadows.mode",
        "Whether geometry blocks light: `off`, `exact` (a shadow ray through the scene's \
         BVH for every light a pixel evaluates, in every pipeline) or `rays:K` (K = 1, 2 or \
         4 rays a pixel to lights drawn by their unshadowed contribution, whatever the light \
         count: noisy where shadows are partial, exact where a pixel has at most K lights; \
         `--frames` gives each frame its own noise), `rays:K+spatial` (the same with the \
         visible share filtered spatially, edge-aware: deferred's compute and tiles \
         lighting, and with K = 1 Forward+ and naive, whose shadow pass traces after \
         shading) or `rays:K+spatial+temporal` (filtered and accumulated over up to 16 \
         frames, reprojected as the camera moves; `--frames` lets the history fill)",
    )
    .names(names::<manylights::Shadows>),
    SettingFlag::new(
        "msaa",
        "view.msaa",
        "MSAA samples a pixel: 1 (off), 2, 4 or 8 where the GPU offers them (4 everywhere, \
         the page included). Forward+ and naive; deferred refuses it (one G-buffer surface a \
         pixel), as do the forward shadow pass (`rays:1`) and `--false-positives`",
    )
    .axis("msaa"),
    SettingFlag::new(
        "transparency",
        "transparency",
        "How blended (glTF `BLEND`) surfaces combine: `sorted` (objects back to front, each \
         \"over\" what is behind) or `weighted` (weighted blended order-independent \
         transparency, McGuire and Bavoil 2013: no sorting, within coverage x the layers' \
         colour range of sorted)",
    )
    .axis("transparencies"),
    SettingFlag::new(
        "tonemap",
        "post.tonemap",
        "The tonemap curve: `none` (clamp), `reinhard` or `aces` (Narkowicz's fit)",
    )
    .axis("tonemaps")
    .names(names::<Tonemap>),
    SettingFlag::new(
        "aa",
        "post.anti_aliasing",
        "Anti-aliasing after shading: `off` or `taa` (temporal: a sub-pixel jitter a frame, \
         each pixel's samples averaged over up to 16 frames through the camera's motion; \
         every pipeline, not with MSAA). It converges over frames: use `--frames`",
    )
    .axis("aa"),
    SettingFlag::new(
        "bloom",
        "post.bloom",
        "Bloom's strength: how far the frame is blended toward its bloom, from 0 (off) to 1 \
         (0.04 to 0.1 looks like a lens; energy-keeping, before the tonemap)",
    )
    .axis("blooms"),
    SettingFlag::new(
        "budget",
        "budget",
        "A GPU time per frame in milliseconds: the generated lights' radius is shortened \
         (never lengthened beyond --radius or --threshold's) and, with a tree far field, the \
         cut's slots are taken (never more than --far-field's) each frame to stay within \
         it, from the GPU times of the frames already finished; the output says what it \
         chose",
    ),
    SettingFlag::new(
        "gbuffer",
        "pipeline.layout",
        "Deferred: G-buffer layout: `full` (everything in f32, lossless: 52 bytes per \
         pixel, 68 with specular), `compact` (position from depth, octahedral normal, sRGB \
         albedo: 12, 16 with specular), `packed` (one Rgba32Uint target plus depth: 20) or \
         `visibility` (a visibility buffer: depth and each pixel's triangle, resolved into \
         `packed` one material at a time)",
    )
    .names(names::<GBufferLayout>),
    SettingFlag::new(
        "lighting",
        "pipeline.lighting",
        "Deferred: lighting path, `fragment`, `compute` (each pixel runs its cluster's \
         list) or `tiles` (an 8x8 tile's pixels share their clusters' lists through \
         workgroup memory: the same image, faster)",
    )
    .names(names::<LightingPath>),
    SettingFlag::new(
        "assignment",
        "pipeline.clustering.assignment",
        "Forward+/deferred: how the GPU builds the light lists: `tile-masks` (sorted \
         lists) or `atomic-fill` (the first design, for comparison)",
    )
    .names(names::<AssignmentDesign>),
    SettingFlag::new(
        "cluster-boxes",
        "pipeline.clustering.boxes",
        "Forward+/deferred: the boxes lights are tested against: `visible` (each \
         cluster's visible samples, bounded from the G-buffer's or pre-pass's depth; \
         clusters where nothing is seen list nothing) or `grid` (each cluster's whole box)",
    )
    .names(names::<ClusterBoxes>),
    SettingFlag::new(
        "spot-culling",
        "pipeline.clustering.spot_culling",
        "Forward+/deferred: how spot lights are culled: by their `cone`, or by their range \
         `sphere` (to measure what the cone test saves)",
    )
    .names(names::<SpotCulling>),
];

/// One setting the command line gave by path: through its shortcut (`--lights`) or
/// `--set`.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingArg {
    /// How it was given (`--lights`, `--set`), for the error that refuses it.
    pub given_as: String,
    pub path: String,
    pub text: String,
}

/// `render`'s and the viewer's settings by path: the shortcuts given and every `--set`, in
/// the order the table and then the command line give them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SettingArgs(pub Vec<SettingArg>);

impl SettingArgs {
    /// Sets each on `settings`; an error names the flag, the path and what its field
    /// refuses.
    pub fn apply(&self, settings: &mut FrameSettings) -> Result<(), String> {
        for arg in &self.0 {
            settings
                .set_text(&arg.path, &arg.text)
                .map_err(|error| format!("{} {}: {error}", arg.given_as, arg.text))?;
        }
        Ok(())
    }
}

/// `bench`'s setting axes: each shortcut given and every `--axis`, as (path, values).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SettingAxisArgs(pub Vec<(String, Vec<String>)>);

const SET: &str = "set";

/// The default settings' value at `path`, as a person writes it: what a shortcut's
/// `--help` says it is when not given (`none` where the default frame has no such field:
/// another variant's, such as a fixed radius).
fn default_text(path: &str) -> String {
    match FrameSettings::default().get(path) {
        Ok(serde_json::Value::String(text)) => text,
        Ok(serde_json::Value::Null) | Err(_) => "none".to_string(),
        Ok(value) => value.to_string(),
    }
}
const AXIS: &str = "axis";

fn split_assignment(text: &str) -> Result<(String, String), clap::Error> {
    text.split_once('=')
        .map(|(path, value)| (path.trim().to_string(), value.trim().to_string()))
        .ok_or_else(|| {
            clap::Error::raw(
                clap::error::ErrorKind::InvalidValue,
                format!("`{text}`: expected PATH=VALUE, e.g. post.bloom=0.05\n"),
            )
        })
}

impl FromArgMatches for SettingArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let mut args = Vec::new();
        for flag in SETTING_FLAGS {
            if let Some(value) = matches.get_one::<String>(flag.flag) {
                args.push(SettingArg {
                    given_as: format!("--{}", flag.flag),
                    path: flag.path.to_string(),
                    text: value.clone(),
                });
            }
        }
        for text in matches.get_many::<String>(SET).into_iter().flatten() {
            let (path, text) = split_assignment(text)?;
            args.push(SettingArg {
                given_as: format!("--{SET}"),
                path,
                text,
            });
        }
        Ok(Self(args))
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl clap::Args for SettingArgs {
    fn augment_args(mut command: Command) -> Command {
        for flag in SETTING_FLAGS {
            let mut arg = Arg::new(flag.flag)
                .long(flag.flag)
                .allow_negative_numbers(true)
                .help(format!(
                    "{} (`--set {}=...`) [default: {}]",
                    flag.help,
                    flag.path,
                    default_text(flag.path)
                ));
            if let Some(names) = flag.names {
                arg = arg.value_parser(PossibleValuesParser::new(names()));
            }
            if let Some(other) = flag.conflicts_with {
                arg = arg.conflicts_with(other);
            }
            command = command.arg(arg);
        }
        command.arg(
            Arg::new(SET)
                .long(SET)
                .value_name("PATH=VALUE")
                .action(ArgAction::Append)
                .help(
                    "Any frame setting by its path into `manylights::FrameSettings` \
                     (`post.bloom=0.05`, `pipeline.clustering.grid.z_slices=24`, \
                     `post.exposure={\"manual\":2}`), after the flags; repeatable",
                ),
        )
    }

    fn augment_args_for_update(command: Command) -> Command {
        Self::augment_args(command)
    }
}

impl FromArgMatches for SettingAxisArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let mut axes = Vec::new();
        for flag in SETTING_FLAGS {
            if let Some(values) = flag
                .axis_flag
                .and_then(|axis_flag| matches.get_many::<String>(axis_flag))
            {
                axes.push((flag.path.to_string(), values.cloned().collect()));
            }
        }
        for text in matches.get_many::<String>(AXIS).into_iter().flatten() {
            let (path, values) = split_assignment(text)?;
            axes.push((path, values.split(',').map(str::to_string).collect()));
        }
        Ok(Self(axes))
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl clap::Args for SettingAxisArgs {
    fn augment_args(mut command: Command) -> Command {
        for flag in SETTING_FLAGS {
            let Some(axis_flag) = flag.axis_flag else {
                continue;
            };
            command = command.arg(
                Arg::new(axis_flag)
                    .long(axis_flag)
                    .value_delimiter(',')
                    .action(ArgAction::Append)
                    .help(format!(
                        "An axis of `{}`, comma-separated (replacing the matrix's): {}",
                        flag.path, flag.help
                    )),
            );
        }
        command.arg(
            Arg::new(AXIS)
                .long(AXIS)
                .value_name("PATH=V1,V2")
                .action(ArgAction::Append)
                .help(
                    "An axis over any frame setting by its path into \
                     `manylights::FrameSettings` (`post.bloom=0,0.04`), replacing the \
                     matrix's axis of that path; repeatable",
                ),
        )
    }

    fn augment_args_for_update(command: Command) -> Command {
        Self::augment_args(command)
    }
}

/// The page's URL query, decoded, as command-line arguments: `key=value` is `--key value`,
/// `key` alone `--key`, and a key with a dot is a setting's path (`post.bloom=0.05` is
/// `--set post.bloom=0.05`), so every setting is a URL parameter too (a top-level one as
/// `set=shading=blinn-phong`).
pub fn url_query_args(pairs: impl IntoIterator<Item = (String, String)>) -> Vec<String> {
    let mut argv = Vec::new();
    for (key, value) in pairs {
        if key.contains('.') {
            argv.push(format!("--{SET}"));
            argv.push(format!("{key}={value}"));
        } else {
            argv.push(format!("--{key}"));
            if !value.is_empty() {
                argv.push(value);
            }
        }
    }
    argv
}

#[cfg(test)]
mod tests {
    use clap::Parser as _;

    use super::*;
    use crate::cli::Flags;

    fn settings_of(argv: &[&str]) -> FrameSettings {
        let flags =
            Flags::try_parse_from(std::iter::once("manylights").chain(argv.iter().copied()))
                .unwrap_or_else(|error| panic!("{argv:?}: {error}"));
        flags
            .args
            .settings()
            .unwrap_or_else(|error| panic!("{argv:?}: {error}"))
    }

    /// A value other than the default for each row's field, as a person types it.
    fn sample(flag: &str) -> &'static str {
        match flag {
            "lights" => "16",
            "size" => "64x48",
            "time" => "2.5",
            "seed" => "7",
            "intensity" => "0.5",
            "saturation" => "0.3",
            "spot-fraction" => "0.5",
            "light-shape" => "rect:0.4",
            "emissive-lights" => "off",
            "radius" => "3",
            "threshold" => "0.1",
            "shadows" => "exact",
            "msaa" => "4",
            "transparency" => "weighted",
            "tonemap" => "reinhard",
            "aa" => "taa",
            "bloom" => "0.05",
            "budget" => "8",
            "gbuffer" => "full",
            "lighting" => "compute",
            "assignment" => "atomic-fill",
            "cluster-boxes" => "grid",
            "spot-culling" => "sphere",
            other => panic!("--{other}: give the test a value of its field"),
        }
    }

    /// Each shortcut sets its path and nothing else: `--FLAG VALUE` is `--set PATH=VALUE`,
    /// and moves the frame off its default.
    #[test]
    fn each_shortcut_is_its_path_set() {
        let defaults = settings_of(&[]);
        for flag in SETTING_FLAGS {
            let value = sample(flag.flag);
            let by_flag = settings_of(&[&format!("--{}", flag.flag), value]);
            let assignment = format!("{}={value}", flag.path);
            assert_eq!(
                by_flag,
                settings_of(&["--set", &assignment]),
                "--{}",
                flag.flag
            );
            assert_ne!(by_flag, defaults, "--{} {value} changed nothing", flag.flag);
            if let Some(names) = flag.names {
                assert!(names().contains(&value), "--{}: {value}", flag.flag);
            }
        }
    }

    /// A value a field refuses names the flag it came from, the path and the reason, and
    /// a flag that sets the same field as another cannot be given with it.
    #[test]
    fn a_refused_value_names_its_flag_and_path() {
        let args = Flags::parse_from(["manylights", "--lights", "-5"]).args;
        let error = args.settings().unwrap_err();
        assert!(
            error.contains("--lights -5") && error.contains("lights.count"),
            "{error}"
        );
        let both = Flags::try_parse_from(["manylights", "--radius", "2", "--threshold", "0.1"]);
        assert!(both.is_err(), "--radius with --threshold");
        let unnamed = Flags::try_parse_from(["manylights", "--tonemap", "filmic"]);
        let error = unnamed.err().expect("an unknown tonemap").to_string();
        assert!(error.contains("aces"), "{error}");
    }
}
