//! The run loop: each configuration rendered, warmed up until its GPU time settles, timed
//! and compared with the reference (computed once per scene, size, light count and camera).

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use web_time::Instant;

use anyhow::{Context as _, bail};
use glam::DVec3;

use manylights::gpu::{Exposure, GpuContext, GpuTimings, PassName};
use manylights::lights::{RadiusMode, SpotCone, SpotSettings};
use manylights::{
    DialCombination, FrameLights, FrameSettings, LoadedScene, PipelineSettings, PostSettings,
    Renderer, SceneChoices, ShadowSettings, ViewSettings,
};

use super::accuracy::accuracy;
use super::clock::remeasure_slow_clocks;
use super::matrix::{BenchConfig, BenchMatrix};
use super::results::{
    Accuracy, BenchReport, BenchResult, BlendedLayerCounts, PassTime, percentile,
};

/// What a reference depends on: scene, size, light count, whether geometry blocks light,
/// and the BRDF.
/// Scene, size, light count, whether geometry blocks light, the BRDF, the view and the
/// MSAA samples (the reference image is drawn with the configuration's).
pub(super) type ReferenceKey = (
    String,
    (u32, u32),
    u32,
    bool,
    manylights::lights::Shading,
    Option<String>,
    u32,
);

/// What the reference of a (scene, size, lights, camera, BRDF) is: computed once, shared
/// by the configurations that differ only in pipeline settings.
pub(super) struct Reference {
    /// What the reference was made for (`ReferenceKey`).
    pub(super) key: ReferenceKey,
    pub(super) image: Option<Vec<[f32; 4]>>,
    pub(super) image_rgba8: Option<image::RgbaImage>,
    /// Which reference drew `image`, and how long it and the f64 samples took.
    pub(super) image_source: Option<super::results::ImageReference>,
    pub(super) image_seconds: Option<f64>,
    /// Per pixel of `image`, its standard error (the GPU reference with visibility where
    /// estimated).
    pub(super) image_standard_error: Option<Vec<DVec3>>,
    pub(super) samples_seconds: f64,
    /// The surface capture the samples (and the GPU reference) read: where the seam
    /// measure finds each pixel's cluster.
    pub(super) surface: manylights::gpu::SurfaceImage,
    pub(super) samples: Vec<(usize, DVec3)>,
    /// Per sample, the standard error of its estimate with visibility (zero where exact).
    pub(super) standard_errors: Vec<DVec3>,
    /// Per sample, whether visibility takes more than half of its light (all false without
    /// the reference's visibility).
    pub(super) in_shadow: Vec<bool>,
    /// The sampled surface points, the lights of the frame and the covered pixels: what
    /// the shadow rays a frame traces are estimated from.
    pub(super) points: Vec<manylights::lights::reference::SurfacePoint>,
    pub(super) lights: Vec<manylights::lights::Light>,
    pub(super) covered: usize,
    /// Samples under blended surfaces (their layers composited).
    pub(super) layered: usize,
    /// The share of covered pixels under blended surfaces (`Accuracy::blended_coverage`).
    pub(super) blended_coverage: Option<f64>,
}

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

/// Asks for every list statistic the frame plan allows: the lists' where there are lists,
/// and the false-positive count where it may be counted (it reads one depth a pixel: not
/// under MSAA).
fn with_every_statistic(settings: &mut FrameSettings) {
    settings.pipeline.set_list_statistics(true, true);
    if DialCombination::of(settings).check().is_err() {
        settings.pipeline.set_list_statistics(true, false);
    }
}

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
