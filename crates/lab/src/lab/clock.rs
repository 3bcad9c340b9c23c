//! The clock check: a configuration whose clock probe (a pass that does not depend on the
//! lights) ran slower than its fastest twin in the run is timed again.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};

use manylights::Renderer;
use manylights::gpu::PassName;

use super::matrix::BenchMatrix;
use super::matrix::frame_settings;
use super::results::{BenchReport, BenchResult, PassTime};
use super::timing::measure_times;

/// Passes whose work does not depend on the lights or the pipeline's light settings: the
/// same geometry drawn at the same size. Their time shows the GPU's clock, which drops
/// when the GPU idles (an H200 falls to 345 MHz while the CPU computes a reference) and
/// sometimes stays low through a configuration's warm-up and timed frames.
pub(super) const CLOCK_PROBE_PASSES: [PassName; 2] = [
    manylights::deferred::GBUFFER_PASS,
    manylights::forward_plus::DEPTH_PREPASS,
];

/// A probe pass slower than this times its fastest twin in the run marks a slow clock.
/// The probe's own spread between frames at a steady clock is well under 1% (H200: the
/// g-buffer pass at 1920x1080 reads 1.395 ms in every configuration), a lowered clock
/// makes it 2-5x slower.
pub(super) const SLOW_CLOCK_FACTOR: f64 = 1.10;

/// How many more times a configuration with a slow clock is measured.
pub(super) const SLOW_CLOCK_RETRIES: u32 = 2;

/// The clock probe among a configuration's passes, if it has one.
pub(super) fn probe_pass(passes: &[PassTime]) -> Option<&PassTime> {
    passes
        .iter()
        .find(|p| CLOCK_PROBE_PASSES.iter().any(|&probe| p.name.is(probe)))
}

/// The probe pass's median time of a result, with the work it stands for (scene, size,
/// pipeline, G-buffer layout, pass): results with equal keys draw the same geometry.
pub(super) fn clock_probe(result: &BenchResult) -> Option<(String, f64)> {
    let pass = probe_pass(&result.passes)?;
    let c = &result.config;
    let key = format!(
        "{} {}x{} {} {:?} {}",
        c.scene, c.size.0, c.size.1, c.pipeline, c.gbuffer, pass.name
    );
    Some((key, pass.median_ms))
}

/// The fastest probe time of each kind of work among `results`.
pub(super) fn fastest_probes(results: &[BenchResult]) -> BTreeMap<String, f64> {
    let mut fastest: BTreeMap<String, f64> = BTreeMap::new();
    for (key, ms) in results.iter().filter_map(clock_probe) {
        let entry = fastest.entry(key).or_insert(ms);
        *entry = entry.min(ms);
    }
    fastest
}

/// The results (indices) whose clock probe pass ran more than `SLOW_CLOCK_FACTOR`
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
pub(super) async fn remeasure_slow_clocks(
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
            let times = measure_times(renderer, matrix, &mut settings).await?;
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
