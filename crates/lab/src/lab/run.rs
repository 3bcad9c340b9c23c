//! The run loop: each configuration rendered, warmed up until its GPU time settles, timed
//! and compared with the reference (computed once per scene, size, light count and camera).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context as _, bail};

use manylights::gpu::GpuContext;
use manylights::{DialCombination, FrameSettings, LoadedScene, Renderer};

use super::accuracy::accuracy;
use super::clock::remeasure_slow_clocks;
use super::matrix::{BenchConfig, BenchMatrix, frame_settings};
use super::reference::Reference;
use super::results::{Accuracy, BenchReport, BenchResult, BlendedLayerCounts};
use super::timing::measure_times;

/// Runs the matrix on a new headless device, loading its scenes from their specs, and
/// calls `progress` after each configuration. Stops early (keeping what was measured)
/// when `stop` becomes true. Blocks (native only; the page awaits [`run_async`]).
pub fn run(
    matrix: &BenchMatrix,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(&BenchResult, usize, usize),
) -> anyhow::Result<BenchReport> {
    let context = GpuContext::new_headless().context("creating the GPU context")?;
    manylights::gpu::block_on(run_async(
        matrix,
        context,
        &mut |spec| LoadedScene::load(spec).with_context(|| format!("loading {spec}")),
        &stop,
        &mut progress,
    ))
}

/// [`run`] on a given device, with the scenes from `load_scene` (the page hands over the
/// scene it has loaded: it cannot read files). Natively it blocks on the GPU as `run`
/// does; in the page every wait yields to the browser, and it yields after each frame.
pub async fn run_async(
    matrix: &BenchMatrix,
    context: GpuContext,
    load_scene: &mut dyn FnMut(&str) -> anyhow::Result<LoadedScene>,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&BenchResult, usize, usize),
) -> anyhow::Result<BenchReport> {
    let configs = matrix.configurations()?;
    let summary = context.summary.clone();
    let mut report = BenchReport {
        adapter: summary.name.clone(),
        backend: summary.backend.clone(),
        driver: format!("{} {}", summary.driver, summary.driver_info),
        timestamps: summary.timestamps,
        started: format!(
            "unix time {}",
            web_time::SystemTime::now()
                .duration_since(web_time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0)
        ),
        matrix: matrix.clone(),
        results: Vec::new(),
        interrupted: false,
    };
    let mut renderer: Option<Renderer> = None;
    let mut context = Some(context);
    let mut reference: Option<Reference> = None;
    // The scene spec loaded now, and where the results measured with it start.
    let mut loaded_spec: Option<&str> = None;
    let mut scene_start = 0;
    for (index, config) in configs.iter().enumerate() {
        if stop.load(Ordering::SeqCst) {
            report.interrupted = true;
            break;
        }
        if loaded_spec != Some(config.scene.as_str()) {
            remeasure_slow_clocks(&mut renderer, matrix, &mut report, scene_start, stop).await?;
            scene_start = report.results.len();
            let scene = load_scene(&config.scene)?;
            match &mut renderer {
                Some(r) => r.load_scene(scene)?,
                None => {
                    renderer = Some(Renderer::new(
                        context.take().context("GPU context")?,
                        scene,
                    )?)
                }
            }
            loaded_spec = Some(&config.scene);
            reference = None;
        }
        let Some(renderer) = renderer.as_mut() else {
            bail!("no renderer");
        };
        // Errors no scope caught (in the browser every scope's error arrives this way,
        // after control returns to the page) belong to the configuration that raised them.
        renderer.context().take_uncaptured_errors();
        let measured = run_config(renderer, matrix, config, &mut reference).await;
        let result = unless_gpu_errors(
            config,
            measured.map_err(|error| format!("{error:#}")),
            renderer.context().take_uncaptured_errors(),
        );
        progress(&result, index + 1, configs.len());
        report.results.push(result);
    }
    remeasure_slow_clocks(&mut renderer, matrix, &mut report, scene_start, stop).await?;
    Ok(report)
}

/// A configuration's result, failed where the GPU raised errors while it was measured
/// (`gpu_errors`): a frame drawn with an invalid pipeline is no measurement (the page's
/// lab once recorded sponza-glass without its glass, at an error of 1.0, while Tint's
/// refusal of the program sat in the console).
pub(super) fn unless_gpu_errors(
    config: &BenchConfig,
    measured: Result<BenchResult, String>,
    gpu_errors: Vec<String>,
) -> BenchResult {
    match (measured, gpu_errors.is_empty()) {
        (Ok(result), true) => result,
        (Ok(_), false) => failed(config, gpu_errors.join("; ")),
        (Err(error), _) => failed(config, error),
    }
}

pub(super) fn failed(config: &BenchConfig, error: String) -> BenchResult {
    BenchResult {
        config: config.clone(),
        passes: Vec::new(),
        gpu_total_median_ms: None,
        gpu_total_p95_ms: None,
        cpu_frame_median_ms: 0.0,
        accuracy: Accuracy::default(),
        lights_per_cluster_mean: None,
        lights_per_cluster_max: None,
        false_positive_ratio: None,
        cluster_count: None,
        light_evaluations: 0,
        evaluations_per_second: None,
        blended_layers: None,
        error: Some(error),
        clock_remeasures: 0,
        frame: None,
    }
}

/// Asks for every list statistic the frame plan allows: the lists' where there are lists,
/// and the false-positive count where it may be counted (it reads one depth a pixel: not
/// under MSAA).
fn with_every_statistic(settings: &mut FrameSettings) {
    settings.pipeline.set_list_statistics(true, true);
    if DialCombination::of(settings).check().is_err() {
        settings.pipeline.set_list_statistics(true, false);
    }
}

pub(super) async fn run_config(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    reference: &mut Option<Reference>,
) -> anyhow::Result<BenchResult> {
    let mut settings = frame_settings(renderer, matrix, config)?;
    log::info!("{}", config.variant());
    let times = measure_times(renderer, matrix, &mut settings).await?;
    let timed = settings.clone();

    // The measured frame again, at the first timed step, for accuracy and statistics;
    // after the frames a method with history needs to settle there, each with its seed.
    let settle = settings.settle_frames();
    for frame in 0..settle {
        let mut settling = settings.clone();
        settling.shadows.seed = settings.shadows.seed.wrapping_sub(settle - frame);
        renderer.render_frame(&settling)?;
    }
    with_every_statistic(&mut settings);
    renderer.render_frame(&settings)?;
    let image = renderer.read_hdr_async().await?;
    let image_rgba8 = renderer.read_output_async().await?;
    let cluster_stats = renderer.wait_cluster_stats_async().await?;
    let blended_layers = renderer
        .read_blended_layer_counts_async()
        .await?
        .map(|counts| BlendedLayerCounts {
            fragments: counts.fragments,
            past_pool: counts.past_pool,
            merged_pixels: counts.merged_pixels,
        });
    let light_evaluations = if settings.pipeline.needs_clusters() {
        renderer.light_evaluations_async(&settings).await?
    } else {
        renderer.covered_pixels_async().await? * config.lights as u64
    };

    let accuracy = accuracy(
        renderer,
        matrix,
        config,
        &settings,
        &image,
        &image_rgba8,
        reference,
    )
    .await?;
    Ok(BenchResult {
        config: config.clone(),
        passes: times.passes,
        gpu_total_median_ms: times.gpu_total_median_ms,
        gpu_total_p95_ms: times.gpu_total_p95_ms,
        cpu_frame_median_ms: times.cpu_frame_median_ms,
        accuracy,
        lights_per_cluster_mean: cluster_stats.as_ref().map(|s| s.mean_lights),
        lights_per_cluster_max: cluster_stats.as_ref().map(|s| s.max_lights),
        false_positive_ratio: cluster_stats.as_ref().and_then(|s| s.false_positive_ratio),
        cluster_count: cluster_stats.as_ref().map(|s| s.clusters),
        light_evaluations,
        evaluations_per_second: times
            .gpu_total_median_ms
            .map(|ms| light_evaluations as f64 / (ms / 1000.0)),
        blended_layers,
        error: None,
        clock_remeasures: 0,
        frame: Some(timed),
    })
}
