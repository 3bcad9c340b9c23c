//! A configuration's GPU times: warmed up until they settle, then timed frame by frame with
//! a fixed step, per pass and in all (the run loop and the slow-clock remeasure both time
//! this way).

use std::collections::BTreeMap;
use web_time::Instant;

use manylights::gpu::{GpuTimings, PassName};
use manylights::{FrameSettings, Renderer};

use super::matrix::BenchMatrix;
use super::results::{PassTime, percentile};

/// What the timed frames of one configuration measured.
pub(super) struct MeasuredTimes {
    pub(super) passes: Vec<PassTime>,
    pub(super) gpu_total_median_ms: Option<f64>,
    pub(super) gpu_total_p95_ms: Option<f64>,
    pub(super) cpu_frame_median_ms: f64,
}

/// Warms up until the GPU time settles, then times `matrix.frames` frames with a fixed
/// step (the lights keep moving). Leaves `settings.lights.time` at the first timed frame's.
pub(super) async fn measure_times(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    settings: &mut FrameSettings,
) -> anyhow::Result<MeasuredTimes> {
    let policy = manylights::WarmUpPolicy {
        min_frames: matrix.warmup_frames,
        max_seconds: matrix.warmup_seconds,
        ..manylights::WarmUpPolicy::default()
    };
    let warm_up = manylights::warm_up_async(renderer, settings, &policy).await?;
    log::info!("{warm_up}");
    let start_time = settings.lights.time;
    let mut per_pass: BTreeMap<PassName, Vec<f64>> = BTreeMap::new();
    let mut pass_order: Vec<PassName> = Vec::new();
    let mut totals = Vec::new();
    let mut cpu = Vec::new();
    let start_seed = settings.shadows.seed;
    for frame in 0..matrix.frames.max(1) {
        settings.lights.time = start_time + frame as f32 * matrix.time_step;
        settings.shadows.seed = start_seed.wrapping_add(frame);
        let begin = Instant::now();
        let stats = renderer.render_frame_timed_async(settings).await?;
        cpu.push(begin.elapsed().as_secs_f64() * 1000.0);
        manylights::gpu::yield_now().await;
        if let GpuTimings::Measured(passes) = &stats.timings {
            for pass in passes {
                if !pass_order.contains(&pass.name) {
                    pass_order.push(pass.name);
                }
                per_pass
                    .entry(pass.name)
                    .or_default()
                    .push(pass.milliseconds);
            }
            totals.push(stats.timings.total().unwrap_or(0.0));
        }
    }
    settings.lights.time = start_time;
    settings.shadows.seed = start_seed;
    let passes: Vec<PassTime> = pass_order
        .iter()
        .map(|name| {
            let values = per_pass
                .get_mut(name)
                .map(|v| v.as_mut_slice())
                .unwrap_or(&mut []);
            PassTime {
                name: (*name).into(),
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
