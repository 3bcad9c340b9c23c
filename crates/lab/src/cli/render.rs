//! `manylights render`: one frame (or a walk of frames) headless, written as a PNG, with
//! the report of per-pass GPU times.

use anyhow::{Context as _, bail};
use manylights::gpu::{Exposure, GpuContext, GpuTimings};
use manylights::{ClusterView, FrameSettings, FrameStats, LoadedScene, Renderer};

use super::{RenderArgs, frame_settings};

/// The camera of frame `frame` of a walk through `presets`, `per_preset` frames from one to
/// the next (the last leads back to the first); `fallback` without presets.
fn walk_camera(
    presets: &[manylights::Camera],
    frame: u32,
    per_preset: u32,
    fallback: &manylights::Camera,
) -> manylights::Camera {
    if presets.is_empty() {
        return *fallback;
    }
    let leg = (frame / per_preset) as usize % presets.len();
    let t = (frame % per_preset) as f32 / per_preset as f32;
    let (from, to) = (presets[leg], presets[(leg + 1) % presets.len()]);
    manylights::Camera {
        position: from.position.lerp(to.position, t),
        yaw: from.yaw + (to.yaw - from.yaw) * t,
        pitch: from.pitch + (to.pitch - from.pitch) * t,
        roll: from.roll + (to.roll - from.roll) * t,
        fov_y: from.fov_y + (to.fov_y - from.fov_y) * t,
        ..from
    }
}

/// `manylights render`: one frame headless, written as a PNG.
pub fn render(args: &RenderArgs) -> anyhow::Result<()> {
    let scene = LoadedScene::load(&args.scene)
        .with_context(|| format!("loading scene '{}'", args.scene))?;
    let settings = frame_settings(args, &scene)?;
    let context = GpuContext::new_headless().context("creating the GPU context")?;
    println!("adapter: {}", context.summary);
    if let Some(line) = manylights::describe_scene_lights(
        &scene.scene.lights,
        settings.lights.radius,
        settings.pipeline.far_field().is_some(),
    ) {
        println!("{line}");
    }
    if settings.lights.emissive
        && let Some(line) =
            manylights::lights::emissive_lights(&scene.scene, settings.lights.radius).describe()
    {
        println!("{line}");
    }
    let mut renderer = Renderer::new(context, scene).context("preparing the renderer")?;
    let default_policy = manylights::WarmUpPolicy::default();
    let policy = manylights::WarmUpPolicy {
        max_seconds: args.warmup_seconds.unwrap_or(default_policy.max_seconds),
        ..default_policy
    };
    let warm_up = manylights::warm_up(&mut renderer, &settings, &policy).context("rendering")?;
    println!("{warm_up}");
    let timed_frames = args.frames.unwrap_or(1).max(1);
    let mut frames = Vec::with_capacity(timed_frames as usize);
    let presets: Vec<manylights::Camera> =
        renderer.scene().presets.iter().map(|(_, c)| *c).collect();
    let started = web_time::Instant::now();
    let mut frame_settings = settings.clone();
    for frame in 0..timed_frames {
        // Each frame its own shadow rays' noise, reproducibly (the last frame is written).
        frame_settings.shadows.seed = settings.shadows.seed.wrapping_add(frame);
        if let Some(per_preset) = args.walk.filter(|n| *n > 0) {
            frame_settings.view.camera =
                walk_camera(&presets, frame, per_preset, &settings.view.camera);
            frame_settings.lights.time = settings.lights.time + frame as f32 / 60.0;
        }
        frames.push(
            renderer
                .render_frame_timed(&frame_settings)
                .context("rendering")?,
        );
    }
    if let Some(budget) = settings.budget {
        println!("{}", budget_summary(budget, &frames, &settings));
    }
    let seconds = started.elapsed().as_secs_f64();
    // The rate of the frame loop itself: CPU work plus waiting for the GPU's results
    // (what a window without vsync could show, before presenting and UI).
    println!(
        "frame loop: {timed_frames} frames in {seconds:.3} s, {:.1} frames per second",
        f64::from(timed_frames) / seconds
    );
    // Statistics arrive without stalling the frames; the report waits for the last one.
    if settings.pipeline.counts_list_statistics()
        && let Some(last) = frames.last_mut()
    {
        last.cluster_stats = renderer
            .wait_cluster_stats()
            .context("reading the statistics")?;
    }
    report(args, &renderer, &settings, &frames)
}

/// How frames under a budget went: how many fit, the 95th percentile, the radii (and
/// slots) the budget chose, and how often it was out of reach.
fn budget_summary(budget: f32, frames: &[FrameStats], settings: &FrameSettings) -> String {
    let mut totals: Vec<f64> = frames.iter().filter_map(|f| f.timings.total()).collect();
    let within = totals.iter().filter(|ms| **ms <= f64::from(budget)).count();
    totals.sort_by(f64::total_cmp);
    let p95 = totals.get(totals.len() * 95 / 100).copied().unwrap_or(0.0);
    let radii: Vec<f32> = frames.iter().map(|f| f.radius).collect();
    let (low, high) = radii
        .iter()
        .fold((f32::MAX, 0.0f32), |(l, h), r| (l.min(*r), h.max(*r)));
    // With a tree far field, the slots it chose too.
    let slots = frames
        .iter()
        .filter_map(|f| f.far_slots)
        .fold(None, |range: Option<(u32, u32)>, s| {
            Some(range.map_or((s, s), |(l, h)| (l.min(s), h.max(s))))
        })
        .map(|(l, h)| format!(", slots {l} to {h}"))
        .unwrap_or_default();
    let out_of_reach = frames.iter().filter(|f| f.budget_out_of_reach).count();
    format!(
        "budget {budget} ms: {within} of {} frames within it, p95 {p95:.3} ms, radius {low:.3} to {high:.3} m (asked {:.3} m){slots}{}",
        totals.len(),
        settings.lights.radius.radius(settings.lights.intensity),
        if out_of_reach > 0 {
            format!(
                "; out of reach (every dial at its least and still over) at {out_of_reach} frames"
            )
        } else {
            String::new()
        }
    )
}

/// Prints each pass's GPU time, the assignment's steps together and the frame's, each the
/// median over `frames` (the same time step: the same work).
fn print_pass_times(stats: &FrameStats, frames: &[FrameStats]) {
    let GpuTimings::Measured(passes) = &stats.timings else {
        println!("{}", stats.timings);
        return;
    };
    let median = |mut values: Vec<f64>| {
        values.sort_by(f64::total_cmp);
        values[values.len() / 2]
    };
    for (i, pass) in passes.iter().enumerate() {
        let times: Vec<f64> = frames
            .iter()
            .filter_map(|f| match &f.timings {
                GpuTimings::Measured(p) => p.get(i).map(|p| p.milliseconds),
                GpuTimings::Unsupported => None,
            })
            .collect();
        println!("gpu {:<18} {:>9.3} ms", pass.name, median(times));
    }
    let assign: Vec<f64> = frames
        .iter()
        .filter_map(|f| {
            f.timings
                .total_of(manylights::cluster::passes::ASSIGN_STAGE)
        })
        .collect();
    if !assign.is_empty() {
        println!(
            "gpu {:<18} {:>9.3} ms (all steps)",
            "assign lights",
            median(assign)
        );
    }
    let total: Vec<f64> = (frames.iter())
        .map(|frame| frame.timings.total().unwrap_or(0.0))
        .collect();
    println!(
        "gpu {:<18} {:>9.3} ms (median of {} frames)",
        "total",
        median(total),
        frames.len()
    );
}

/// Writes the image and prints the adapter-independent report of `render`.
fn report(
    args: &RenderArgs,
    renderer: &Renderer,
    settings: &FrameSettings,
    frames: &[FrameStats],
) -> anyhow::Result<()> {
    let Some(stats) = frames.last().cloned() else {
        bail!("no frame rendered");
    };
    let image = renderer.read_output().context("reading the image back")?;
    image
        .save(&args.out)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let written = std::fs::canonicalize(&args.out).unwrap_or_else(|_| args.out.clone());
    let plan = renderer.plan(settings)?;
    println!(
        "wrote {} ({}x{}, scene {}, {} lights, {} pipeline, falloff {}{}, camera {})",
        written.display(),
        settings.view.size.0,
        settings.view.size.1,
        renderer.scene().name,
        stats.light_count,
        settings.pipeline.describe(),
        plan.falloff,
        plan.clusters
            .and_then(|clusters| clusters.frame.far_field)
            .map(|far| format!(" with far field {far}"))
            .unwrap_or_default(),
        settings.view.camera.to_argument()
    );
    print_pass_times(&stats, frames);
    let exposure = renderer.read_exposure().context("reading the exposure")?;
    match settings.post.exposure {
        Exposure::Manual(value) => println!("exposure: fixed {value}"),
        Exposure::Auto(auto) => println!(
            "exposure: automatic {:.4} (median luminance of lit pixels {:.4} -> mid-grey 0.18, compensation {:+} EV)",
            exposure.value, exposure.median_luminance, auto.compensation_ev
        ),
    }
    if let Some(cluster_stats) = &stats.cluster_stats {
        println!("clusters: {cluster_stats}");
        println!(
            "clusters: histogram of lights per cluster (0, 1, 2-3, 4-7, ...): {:?}",
            cluster_stats.histogram
        );
    }
    if let Some(layers) = renderer
        .read_blended_layer_counts()
        .context("reading the blended layers' counts")?
    {
        println!(
            "blended layers: {} fragments stored, {} past the pool (not drawn), {} pixels with more than {} layers (the farthest merged by weight)",
            layers.fragments - layers.past_pool,
            layers.past_pool,
            layers.merged_pixels,
            manylights::deferred::SORTED_LAYERS
        );
    }
    if let Some(ClusterView::Heatmap { max_lights }) = settings.pipeline.cluster_view() {
        println!(
            "heatmap legend: black = 0 lights, white = {max_lights} or more; ticks at quarters"
        );
    }
    Ok(())
}
