//! Warming the GPU up before timing it. A GPU that idled (while the process started, or
//! while the CPU worked between frames) runs at a low clock (the H200 drops to 345 MHz
//! from 1980), and its first frames also pay for pipeline compilation and uploads. So
//! `render --frames N` and the lab render frames until the GPU time has settled: until the
//! median total of the last few frames is within a tolerance of the median of the few
//! before them.
//!
//! Each warm-up frame draws its shadow rays with a seed of its own (counting down from the
//! settings' seed, so the frames timed after, counting up, draw others). A history the
//! warm-up fills (temporal shadows) then averages that many independent draws; with one
//! seed it held sixteen copies of one frame's filtered noise, which outweighed the next
//! ten frames' and stood still as blotches tens of pixels wide (issue 80).

use crate::renderer::{FrameSettings, RenderError, Renderer};

/// When the warm-up stops.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmUpPolicy {
    /// Frames always rendered (the first compiles pipelines and uploads).
    pub min_frames: u32,
    /// Frames per window of the settling test.
    pub window: usize,
    /// Settled when two consecutive windows' medians differ by at most this fraction.
    pub tolerance: f64,
    /// Stop here even if not settled (the report says so).
    pub max_frames: u32,
    pub max_seconds: f64,
}

impl Default for WarmUpPolicy {
    fn default() -> Self {
        Self {
            min_frames: 2,
            window: 5,
            tolerance: 0.03,
            max_frames: 300,
            max_seconds: 20.0,
        }
    }
}

/// What a warm-up did.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmUp {
    pub frames: u32,
    pub seconds: f64,
    /// The median GPU time of the last window, once settled (`None` without timestamps or
    /// when the limits stopped the warm-up first).
    pub settled_ms: Option<f64>,
    pub timestamps: bool,
    pub policy: WarmUpPolicy,
}

impl std::fmt::Display for WarmUp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "warm-up: {} frames in {:.1} s",
            self.frames, self.seconds
        )?;
        match (self.timestamps, self.settled_ms) {
            (false, _) => write!(f, " (no GPU timestamps: fixed count)"),
            (true, Some(ms)) => write!(
                f,
                ", GPU frame time settled at {ms:.3} ms (median of the last {} frames within {:.0}% of the {} before)",
                self.policy.window,
                self.policy.tolerance * 100.0,
                self.policy.window
            ),
            (true, None) => write!(
                f,
                ", GPU frame time NOT settled within {} frames / {:.0} s (timings may include clock ramp-up)",
                self.policy.max_frames, self.policy.max_seconds
            ),
        }
    }
}

fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len() / 2]
}

/// Whether the last two windows of `totals` agree within `tolerance`; returns the last
/// window's median if so.
pub fn settled(totals: &[f64], window: usize, tolerance: f64) -> Option<f64> {
    let window = window.max(1);
    if totals.len() < 2 * window {
        return None;
    }
    let last = median(&totals[totals.len() - window..]);
    let before = median(&totals[totals.len() - 2 * window..totals.len() - window]);
    ((last - before).abs() <= tolerance * before).then_some(last)
}

/// Renders `settings` until the GPU time settles (see the module docs).
pub fn warm_up(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    policy: &WarmUpPolicy,
) -> Result<WarmUp, RenderError> {
    manylights_gpu::block_on(warm_up_async(renderer, settings, policy))
}

/// [`warm_up`] without blocking: the page's lab awaits it, and it yields after every
/// frame so a caller that polls it once per displayed frame stays responsive.
pub async fn warm_up_async(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    policy: &WarmUpPolicy,
) -> Result<WarmUp, RenderError> {
    let started = web_time::Instant::now();
    let mut totals = Vec::new();
    let mut frames = 0;
    let mut timestamps = false;
    let mut settled_ms = None;
    let mut frame_settings = settings.clone();
    loop {
        frame_settings.shadows.seed = settings.shadows.seed.wrapping_sub(frames + 1);
        let stats = renderer.render_frame_timed_async(&frame_settings).await?;
        manylights_gpu::yield_now().await;
        frames += 1;
        // The first frame's time includes compilation: not part of the test.
        if frames > 1
            && let Some(total) = stats.timings.total()
        {
            timestamps = true;
            totals.push(total);
        }
        if frames < policy.min_frames.max(1) {
            continue;
        }
        if !timestamps {
            break;
        }
        settled_ms = settled(&totals, policy.window, policy.tolerance);
        if settled_ms.is_some()
            || frames >= policy.max_frames
            || started.elapsed().as_secs_f64() >= policy.max_seconds
        {
            break;
        }
    }
    Ok(WarmUp {
        frames,
        seconds: started.elapsed().as_secs_f64(),
        settled_ms,
        timestamps,
        policy: policy.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settles_only_when_two_windows_agree() {
        // A GPU clocking up: times fall, then hold.
        let ramp = [
            9.0, 7.0, 5.0, 3.0, 2.1, 2.0, 2.02, 1.99, 2.0, 2.01, 2.0, 1.98,
        ];
        assert_eq!(settled(&ramp[..6], 3, 0.03), None);
        assert_eq!(settled(&ramp[..8], 3, 0.03), None, "2.1 vs 3.0");
        assert_eq!(settled(&ramp, 3, 0.03), Some(2.0));
        assert_eq!(settled(&ramp[..4], 3, 0.03), None, "fewer than two windows");
    }
}
