//! `--script`: settings changed at given frames, for unattended runs
//! ("10:pipeline=forward-plus;20:pipeline=deferred;25:lights=500;30:post.bloom=0.05"):
//! a key is a setting's path into `FrameSettings`, or one of a few shortcuts.

use anyhow::Context as _;
use manylights::{FrameSettings, PipelineKind};

/// One change: at `frame`, set `key` to `value`.
#[derive(Debug, Clone, PartialEq)]
pub struct ScriptStep {
    pub frame: u64,
    pub key: String,
    pub value: String,
}

/// What a step does besides changing the frame settings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ScriptEffects {
    pub paused: bool,
    /// `lose-device=true`: destroy the GPU device, to exercise the recovery path.
    pub lose_device: bool,
}

/// Parses a script, checking every step, in order, against `settings` (a typo or a setting
/// the pipeline of that moment lacks fails at start-up, not mid-run).
pub fn parse(text: &str, settings: &FrameSettings) -> anyhow::Result<Vec<ScriptStep>> {
    let mut steps = Vec::new();
    let mut settings = settings.clone();
    for item in text.split(';').map(str::trim).filter(|s| !s.is_empty()) {
        let (frame, assignment) = item
            .split_once(':')
            .with_context(|| format!("script step '{item}': expected FRAME:KEY=VALUE"))?;
        let (key, value) = assignment
            .split_once('=')
            .with_context(|| format!("script step '{item}': expected FRAME:KEY=VALUE"))?;
        let frame = frame
            .trim()
            .parse()
            .with_context(|| format!("script step '{item}': '{frame}' is not a frame number"))?;
        let step = ScriptStep {
            frame,
            key: key.trim().to_string(),
            value: value.trim().to_string(),
        };
        apply(&step, &mut settings, &mut ScriptEffects::default())?;
        steps.push(step);
    }
    Ok(steps)
}

/// The script's keys of before that are one setting's path each.
const SHORTCUTS: [(&str, &str); 3] = [
    ("lights", "lights.count"),
    ("gbuffer", "pipeline.layout"),
    ("lighting", "pipeline.lighting"),
];

/// Applies a step to the settings and the effects: `pipeline` (switched with its rules),
/// `debug-view`, `paused` and `lose-device`, then any setting by its path.
pub fn apply(
    step: &ScriptStep,
    settings: &mut FrameSettings,
    effects: &mut ScriptEffects,
) -> anyhow::Result<()> {
    let value = step.value.as_str();
    match step.key.as_str() {
        "pipeline" => {
            let kind: PipelineKind = value
                .parse()
                .map_err(|e: String| anyhow::anyhow!("script: {e}"))?;
            crate::ui::switch_pipeline(settings, kind);
        }
        "debug-view" => {
            settings.pipeline = settings
                .pipeline
                .with_debug_view_named(value)
                .map_err(|e| anyhow::anyhow!("script: {e}"))?;
        }
        "paused" => {
            effects.paused = value
                .parse()
                .with_context(|| format!("script: '{value}' is not true/false"))?
        }
        "lose-device" => {
            effects.lose_device = value
                .parse()
                .with_context(|| format!("script: '{value}' is not true/false"))?
        }
        // Every other key is a setting's path (`post.bloom`), or a shortcut onto one.
        key => {
            let path = SHORTCUTS
                .iter()
                .find(|(shortcut, _)| *shortcut == key)
                .map_or(key, |(_, path)| path);
            settings
                .set_text(path, value)
                .map_err(|error| anyhow::anyhow!("script: {error}"))?;
        }
    }
    Ok(())
}
