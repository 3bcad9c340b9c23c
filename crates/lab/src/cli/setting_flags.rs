//! The command line's flags onto setting paths: one table ([`SETTING_FLAGS`]) names each
//! shortcut (`render --bloom 0.05`, `bench --blooms 0,0.05`) and the path into
//! [`manylights::FrameSettings`] it sets; `--set PATH=VALUE` (render, the viewer, the
//! page's `?PATH=VALUE`) and `--axis PATH=V1,V2` (bench) reach every other path. A value is
//! checked by the field it sets, so the flags need no parser of their own.

use clap::{Arg, ArgAction, ArgMatches, Command, FromArgMatches};
use manylights::FrameSettings;

/// A command-line shortcut onto a setting's path.
#[derive(Debug, Clone, Copy)]
pub struct SettingFlag {
    /// `render`'s and the viewer's flag (one value).
    pub flag: &'static str,
    /// `bench`'s flag (an axis: values separated by commas).
    pub axis_flag: &'static str,
    /// The path into the frame settings.
    pub path: &'static str,
    pub help: &'static str,
}

/// Every shortcut. A dial without one is still `--set PATH=VALUE` and `--axis PATH=...`.
pub const SETTING_FLAGS: [SettingFlag; 5] = [
    SettingFlag {
        flag: "msaa",
        axis_flag: "msaa",
        path: "view.msaa",
        help: "MSAA samples a pixel: 1 (off), 2, 4 or 8 where the GPU offers them (4 \
               everywhere, the page included). Forward+ and naive; deferred refuses it (one \
               G-buffer surface a pixel), as do the forward shadow pass (`rays:1`) and \
               `--false-positives`",
    },
    SettingFlag {
        flag: "transparency",
        axis_flag: "transparencies",
        path: "transparency",
        help: "How blended (glTF `BLEND`) surfaces combine: `sorted` (objects back to front, \
               each \"over\" what is behind) or `weighted` (weighted blended order-independent \
               transparency, McGuire and Bavoil 2013: no sorting, within coverage x the \
               layers' colour range of sorted)",
    },
    SettingFlag {
        flag: "aa",
        axis_flag: "aa",
        path: "post.anti_aliasing",
        help: "Anti-aliasing after shading: `off` or `taa` (temporal: a sub-pixel jitter a \
               frame, each pixel's samples averaged over up to 16 frames through the camera's \
               motion; every pipeline, not with MSAA). It converges over frames: use \
               `--frames`",
    },
    SettingFlag {
        flag: "bloom",
        axis_flag: "blooms",
        path: "post.bloom",
        help: "Bloom's strength: how far the frame is blended toward its bloom, from 0 (off) \
               to 1 (0.04 to 0.1 looks like a lens; energy-keeping, before the tonemap)",
    },
    SettingFlag {
        flag: "light-shape",
        axis_flag: "light-shapes",
        path: "lights.shape",
        help: "The generated lights that are not spots: `point`, `sphere:SIZE` (of diameter \
               SIZE metres) or `rect:SIZE` (a square of side SIZE, facing a random direction \
               of the lower hemisphere, its intensity along its normal)",
    },
];

/// `render`'s and the viewer's settings by path: the shortcuts given and every `--set`, in
/// the order the table and then the command line give them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SettingArgs(pub Vec<(String, String)>);

impl SettingArgs {
    /// Sets each on `settings`; an error names the path and what its field refuses.
    pub fn apply(&self, settings: &mut FrameSettings) -> Result<(), String> {
        for (path, text) in &self.0 {
            settings
                .set_text(path, text)
                .map_err(|error| error.to_string())?;
        }
        Ok(())
    }
}

/// `bench`'s setting axes: each shortcut given and every `--axis`, as (path, values).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SettingAxisArgs(pub Vec<(String, Vec<String>)>);

const SET: &str = "set";

/// The default settings' value at `path`, as a person writes it: what a shortcut's
/// `--help` says it is when not given.
fn default_text(path: &str) -> String {
    match FrameSettings::default().get(path) {
        Ok(serde_json::Value::String(text)) => text,
        Ok(value) => value.to_string(),
        Err(error) => error.to_string(),
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
        let mut pairs = Vec::new();
        for flag in SETTING_FLAGS {
            if let Some(value) = matches.get_one::<String>(flag.flag) {
                pairs.push((flag.path.to_string(), value.clone()));
            }
        }
        for text in matches.get_many::<String>(SET).into_iter().flatten() {
            pairs.push(split_assignment(text)?);
        }
        Ok(Self(pairs))
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl clap::Args for SettingArgs {
    fn augment_args(mut command: Command) -> Command {
        for flag in SETTING_FLAGS {
            command = command.arg(Arg::new(flag.flag).long(flag.flag).help(format!(
                "{} (`--set {}=...`) [default: {}]",
                flag.help,
                flag.path,
                default_text(flag.path)
            )));
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
            if let Some(values) = matches.get_many::<String>(flag.axis_flag) {
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
            command = command.arg(
                Arg::new(flag.axis_flag)
                    .long(flag.axis_flag)
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
