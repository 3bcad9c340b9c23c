//! `--script`: settings changed at given frames, for unattended runs
//! ("10:pipeline=forward-plus;20:pipeline=deferred;25:lights=500").

use anyhow::{Context as _, bail};
use manylights::{DebugView, FrameSettings, GBufferLayout, LightingPath, PipelineKind};

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

/// Parses a script, checking every step against `settings` (a typo fails at start-up,
/// not mid-run).
pub fn parse(text: &str, settings: &FrameSettings) -> anyhow::Result<Vec<ScriptStep>> {
    let mut steps = Vec::new();
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
        apply(&step, &mut settings.clone(), &mut ScriptEffects::default())?;
        steps.push(step);
    }
    Ok(steps)
}

/// Applies a step to the settings and the effects.
pub fn apply(
    step: &ScriptStep,
    settings: &mut FrameSettings,
    effects: &mut ScriptEffects,
) -> anyhow::Result<()> {
    let value = step.value.as_str();
    match step.key.as_str() {
        "pipeline" => {
            settings.pipeline = match value {
                "naive" => PipelineKind::Naive,
                "forward-plus" => PipelineKind::ForwardPlus,
                "deferred" => PipelineKind::Deferred,
                _ => bail!("script: unknown pipeline '{value}' (naive, forward-plus, deferred)"),
            }
        }
        "lights" => {
            settings.light_count = value
                .parse()
                .with_context(|| format!("script: '{value}' is not a light count"))?
        }
        "gbuffer" => {
            settings.gbuffer = match value {
                "full" => GBufferLayout::Full,
                "compact" => GBufferLayout::Compact,
                "packed" => GBufferLayout::Packed,
                _ => bail!("script: unknown G-buffer layout '{value}'"),
            }
        }
        "lighting" => {
            settings.lighting = match value {
                "fragment" => LightingPath::Fragment,
                "compute" => LightingPath::Compute,
                _ => bail!("script: unknown lighting path '{value}'"),
            }
        }
        "debug-view" => {
            settings.debug_view = match value {
                "none" => DebugView::None,
                "heatmap" => DebugView::ClusterHeatmap { max_lights: 64.0 },
                "slices" => DebugView::ZSlices,
                "albedo" => DebugView::Albedo,
                "normal" => DebugView::Normal,
                "depth" => DebugView::Depth,
                "position" => DebugView::Position,
                "evaluations" => DebugView::LightEvaluations,
                _ => bail!("script: unknown debug view '{value}'"),
            }
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
        other => bail!(
            "script: unknown key '{other}' (pipeline, lights, gbuffer, lighting, debug-view, paused, lose-device)"
        ),
    }
    Ok(())
}
