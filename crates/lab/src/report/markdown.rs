//! REPORT.md: the tables of a run.

use std::fmt::Write as _;

use crate::lab::{BenchReport, BenchResult};
use manylights::lights::RadiusMode;

use super::figures::metres;

pub(super) fn opt(value: Option<f64>, digits: usize) -> String {
    value
        .map(|v| format!("{v:.digits$}"))
        .unwrap_or_else(|| "-".into())
}

pub(super) fn markdown(report: &BenchReport, ok: &[&BenchResult]) -> String {
    let mut md = String::new();
    run_description(&mut md, report);
    speed_table(&mut md, ok);
    accuracy_table(&mut md, report, ok);
    whole_frame_table(&mut md, ok);
    drawn_cameras_table(&mut md, ok);
    shadows_table(&mut md, ok);
    blended_layers_table(&mut md, ok);
    failures(&mut md, report);
    md
}

/// The adapter, the timing method, the matrix's settings and the clock check.
fn run_description(md: &mut String, report: &BenchReport) {
    let _ = writeln!(md, "# manylights bench report\n");
    let _ = writeln!(
        md,
        "- adapter: {} ({}), driver {}",
        report.adapter,
        report.backend,
        report.driver.trim()
    );
    let _ = writeln!(
        md,
        "- timestamps: {}; started {}",
        if report.timestamps {
            "yes"
        } else {
            "no (GPU times unavailable)"
        },
        report.started
    );
    let m = &report.matrix;
    let _ = writeln!(
        md,
        "- at least {} warm-up frames (until the GPU time settles, at most {} s) + {} timed frames per configuration, time step {:.4} s, seed {}, intensity {}",
        m.warmup_frames, m.warmup_seconds, m.frames, m.time_step, m.seed, m.intensity
    );
    let _ = writeln!(
        md,
        "- reference: naive + unbounded inverse-square image up to {} lights; f64 CPU shading at {} sampled pixels always",
        m.reference_light_limit, m.reference_samples
    );
    let _ = writeln!(
        md,
        "- the reference's visibility: {}",
        match m.reference_shadows {
            Some(shadows) if shadows.traced() =>
                "with exact shadows (f64 shadow rays through the scene's BVH) for every configuration",
            Some(_) => "without shadows for every configuration",
            None => "each configuration's own (exact shadows: the reference with visibility)",
        }
    );
    let remeasured: Vec<String> = report
        .results
        .iter()
        .filter(|r| r.clock_remeasures > 0)
        .map(|r| format!("{} ({}x)", r.config.describe(), r.clock_remeasures))
        .collect();
    let still_slow: Vec<String> = crate::lab::slow_clock_results(&report.results)
        .into_iter()
        .map(|i| report.results[i].config.describe())
        .collect();
    let _ = writeln!(
        md,
        "- clock check: a configuration whose g-buffer or depth pre-pass (work the lights do not change) took over 10% longer than the same pass elsewhere in the run was measured while the GPU's clock was low, and is measured again; again: {}; still slow: {}",
        if remeasured.is_empty() {
            "none".to_string()
        } else {
            remeasured.join(", ")
        },
        if still_slow.is_empty() {
            "none".to_string()
        } else {
            still_slow.join(", ")
        }
    );
    if report.interrupted {
        let _ = writeln!(
            md,
            "- **interrupted**: only the configurations below were measured"
        );
    }
}

/// Links to the charts, then per configuration its GPU times, passes, image error and list
/// statistics.
fn speed_table(md: &mut String, ok: &[&BenchResult]) {
    let _ = writeln!(
        md,
        "\nCharts: [GPU ms vs lights](gpu_ms_vs_lights.svg), [error vs time](error_vs_time.svg), [lights per cluster vs grid](lights_per_cluster_vs_grid.svg), [assignment ms vs lights](assign_ms_vs_lights.svg). Raw numbers: `bench.json`.\n"
    );
    let _ = writeln!(
        md,
        "| scene | size | pipeline | grid | threshold | falloff | lights | GPU ms median | p95 | passes (median ms) | PSNR dB | FLIP | max abs | f64 max rel | lights/cluster mean / max | false pos. | evals/s |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---:|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in ok {
        let c = &r.config;
        let passes: Vec<String> = r
            .passes
            .iter()
            .map(|p| format!("{} {:.3}", p.name, p.median_ms))
            .collect();
        let _ = writeln!(
            md,
            "| {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2e} | {} | {} | {} |",
            c.scene,
            c.size.0,
            c.size.1,
            c.variant(),
            c.grid.map_or("-".to_string(), |grid| grid.to_string()),
            c.threshold,
            c.falloff,
            c.lights,
            opt(r.gpu_total_median_ms, 3),
            opt(r.gpu_total_p95_ms, 3),
            passes.join(", "),
            opt(r.accuracy.psnr_db, 1),
            opt(r.accuracy.flip_mean, 4),
            opt(r.accuracy.max_abs, 4),
            r.accuracy.f64_max_relative,
            match (r.lights_per_cluster_mean, r.lights_per_cluster_max) {
                (Some(mean), Some(max)) => format!("{mean:.1} / {max}"),
                _ => "-".into(),
            },
            opt(r.false_positive_ratio, 3),
            r.evaluations_per_second
                .map(|e| format!("{e:.3e}"))
                .unwrap_or_else(|| "-".into()),
        );
    }
}

/// Per configuration, the error against the unbounded f64 reference.
fn accuracy_table(md: &mut String, report: &BenchReport, ok: &[&BenchResult]) {
    let m = &report.matrix;
    let _ = writeln!(
        md,
        "\n## Accuracy against the unbounded reference\n\nMean relative error of HDR radiance against the f64 reference at the sampled pixels (all, the darkest third, the brightest third by the reference), FLIP of both images tonemapped at one exposure chosen from the reference (its median lit luminance to mid-grey), and for stochastic far fields the noise (mean relative standard deviation over {} seeds) and bias (mean relative error of the seeds' mean). With shadows, where more lights add to a pixel than {} shadow rays, the reference's visibility is estimated (lights drawn by their contribution, without bias): ref. +-95% is its interval's mean relative half-width.\n",
        m.noise_seeds, m.reference_shadow_rays
    );
    let _ = writeln!(
        md,
        "| pipeline | lights | radius m | far field | GPU ms | mean rel. | dark third | bright third | FLIP @ ref. exposure | exposure | noise | bias | ref. +-95% |"
    );
    let _ = writeln!(
        md,
        "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in ok {
        let c = &r.config;
        let a = &r.accuracy;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {} | {} | {} | {} | {} |",
            c.variant(),
            c.lights,
            metres(RadiusMode::LuminanceThreshold(c.threshold).radius(m.intensity)),
            manylights::cluster::OptionalFarField(c.far_field),
            opt(r.gpu_total_median_ms, 3),
            a.f64_mean_relative,
            a.f64_mean_relative_dark,
            a.f64_mean_relative_bright,
            opt(a.flip_at_reference_exposure, 4),
            opt(a.reference_exposure, 3),
            opt(a.f64_noise_relative, 4),
            opt(a.f64_bias_relative, 4),
            opt(a.f64_reference_half_width, 4),
        );
    }
}

/// What whole frames show: which full-frame reference each is against and how long it and
/// the f64 samples took, FLIP over the frame, the seam and blotch measures and the error
/// map.
fn whole_frame_table(md: &mut String, ok: &[&BenchResult]) {
    let _ = writeln!(
        md,
        "\n## Whole frames\n\nEvery pixel against a full-frame reference: the naive pipeline with the unbounded falloff up to `reference_light_limit` lights, beyond it the GPU reference (every light at every pixel of the surface capture, compensated f32 sums). With shadows it has visibility: every shadow ray up to `reference_image_rays` lights, beyond it an unbiased estimate of about that many rays a pixel, whose mean relative standard error is ref. +-1 sigma. It has no blended layers, so frames that need them have none (`-`). GPU ref. vs f64: the GPU reference's largest relative difference from the f64 samples, or where estimated its largest difference in their combined standard errors (sigma); the f64 reference decides where they differ. FLIP of both images tonemapped at one exposure chosen from the reference; seams, the relative error's step across cluster boundaries (tiles and depth slices) over its steps just beside them within each cluster, on one smooth surface (1.0: none); blotch, the luminance error averaged over boxes of 8 to 64 pixels on smooth surfaces, relative to each box's luminance, beyond what independent per-pixel error would leave there (and its chance deviation), the root of that excess at the worst box size (a relative error: 0 for noise alone, 0.03 for patches 3% off); motion flicker (with `motion_frames`), along a camera walk (5 cm forward and half a degree a frame) with the lights animating, the mean change of that relative error from one frame to the next; the error map is white where the frame equals the reference, red where brighter, blue where darker (full at 10%), grey where not judged.\n"
    );
    let _ = writeln!(
        md,
        "| pipeline | lights | far field | GPU ms | reference | ref. +-1 sigma | image s | samples s | GPU ref. vs f64 | FLIP @ ref. exposure | seams | blotch | motion flicker | error map |"
    );
    let _ = writeln!(
        md,
        "|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"
    );
    for r in ok {
        let (c, a) = (&r.config, &r.accuracy);
        let versus_f64 = match (a.gpu_reference_vs_f64, a.gpu_reference_vs_f64_sigmas) {
            (_, Some(sigmas)) => format!("{sigmas:.1} sigma"),
            (Some(relative), None) => format!("{relative:.1e}"),
            (None, None) => "-".to_string(),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.variant(),
            c.lights,
            manylights::cluster::OptionalFarField(c.far_field),
            opt(r.gpu_total_median_ms, 3),
            a.image_reference
                .map_or("-".to_string(), |source| source.to_string()),
            opt(a.reference_image_standard_error, 4),
            opt(a.reference_image_seconds, 2),
            opt(a.reference_samples_seconds, 2),
            versus_f64,
            opt(a.flip_at_reference_exposure, 4),
            opt(a.seam_ratio, 3),
            opt(a.blotch, 4),
            opt(a.motion_flicker, 4),
            a.error_map_file
                .as_ref()
                .map_or("-".to_string(), |file| format!("[map]({file})")),
        );
    }
}

/// Each setting run on drawn cameras (`draw:COUNT` views): its numbers as mean, spread
/// and worst over them.
fn drawn_cameras_table(md: &mut String, ok: &[&BenchResult]) {
    let settings = crate::lab::over_cameras::over_drawn_cameras(ok.iter().copied());
    if settings.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Over drawn cameras\n\nEach setting over the cameras drawn at random inside the scene for it (`draw:COUNT` views; each camera's row is in the tables above under its `drawn:SEED:INDEX` name): mean +- standard deviation (worst). Error is the mean relative error at the f64 samples; FLIP, seams and blotch as in Whole frames.\n"
    );
    let _ = writeln!(
        md,
        "| setting | lights | far field | cameras | GPU ms | error | FLIP @ ref. exposure | seams | blotch |"
    );
    let _ = writeln!(md, "|---|---:|---|---:|---|---|---|---|---|");
    let shown = |spread: Option<crate::lab::over_cameras::Spread>, digits: usize| {
        spread.map_or("-".to_string(), |s| {
            format!(
                "{:.digits$} +- {:.digits$} ({:.digits$})",
                s.mean, s.spread, s.worst
            )
        })
    };
    for setting in &settings {
        let c = &setting.config;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.variant(),
            c.lights,
            manylights::cluster::OptionalFarField(c.far_field),
            setting.cameras,
            shown(setting.gpu_ms, 3),
            shown(setting.mean_error, 4),
            shown(setting.flip, 4),
            shown(setting.seams, 3),
            shown(setting.blotch, 4),
        );
    }
}

/// With shadows or a history (temporal anti-aliasing): each configuration's error where
/// the reference is in shadow and where it is lit, and its flicker and lags.
fn shadows_table(md: &mut String, ok: &[&BenchResult]) {
    if !ok.iter().any(|r| {
        r.accuracy.f64_mean_relative_shadowed.is_some()
            || r.accuracy.lag_frames.is_some_and(|frames| frames > 0)
    }) {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Shadows and histories: error in shadow and in light, flicker and lag\n\nMean relative error against the reference with visibility where it is in shadow (visibility takes more than half of a sample's light) and where it is lit; flicker, the mean relative difference at the samples between the frame and the next one with only the frame's seed changed (the shadow rays' noise, temporal anti-aliasing's jitter; camera and lights still); lag, the frames the image takes to settle after the lights jump half a second ahead in their animation (its difference from the settled image down to the noise between two settled frames); lag after a disocclusion, the same after the camera jumps 50 cm and 5 degrees in one frame, the lights still, over the whole frame (the ghosting of what the old view hid).\n"
    );
    let _ = writeln!(
        md,
        "| pipeline | lights | far field | GPU ms | mean rel. | in shadow | lit | flicker | lag | lag after a disocclusion |"
    );
    let _ = writeln!(md, "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    for r in ok {
        let (c, a) = (&r.config, &r.accuracy);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.4} | {} | {} | {} | {} | {} |",
            c.variant(),
            c.lights,
            manylights::cluster::OptionalFarField(c.far_field),
            opt(r.gpu_total_median_ms, 3),
            a.f64_mean_relative,
            opt(a.f64_mean_relative_shadowed, 4),
            opt(a.f64_mean_relative_lit, 4),
            opt(a.flicker, 4),
            a.lag_frames.map_or("-".to_string(), |f| f.to_string()),
            a.disocclusion_lag_frames
                .map_or("-".to_string(), |f| f.to_string()),
        );
    }
}

/// Deferred's blended layers (its compute paths): fragments stored, any past the pool
/// (not drawn), and pixels whose farthest layers were merged by weight.
fn blended_layers_table(md: &mut String, ok: &[&BenchResult]) {
    if !ok.iter().any(|r| r.blended_layers.is_some()) {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Blended layers\n\nDeferred's compute paths store blended fragments as per-pixel layers, sort the nearest {} of each pixel and merge any farther ones by weighted blending: the fragments stored in the measured frame, those past the node pool (not drawn: {} nodes a pixel), and the pixels with merged layers.\n",
        manylights::deferred::SORTED_LAYERS,
        manylights::deferred::POOL_LAYERS_PER_PIXEL,
    );
    let _ = writeln!(
        md,
        "| scene | pipeline | lights | GPU ms | fragments | past the pool | pixels merged |"
    );
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|");
    for r in ok {
        let Some(layers) = r.blended_layers else {
            continue;
        };
        let c = &r.config;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            c.scene,
            c.variant(),
            c.lights,
            opt(r.gpu_total_median_ms, 3),
            layers.fragments,
            layers.past_pool,
            layers.merged_pixels,
        );
    }
}

/// The configurations that failed, with their errors.
fn failures(md: &mut String, report: &BenchReport) {
    let failed: Vec<&BenchResult> = report
        .results
        .iter()
        .filter(|r| r.error.is_some())
        .collect();
    if !failed.is_empty() {
        let _ = writeln!(md, "\n## Configurations that failed\n");
        for r in failed {
            let _ = writeln!(
                md,
                "- {} {} lights {}x{}: {}",
                r.config.scene,
                r.config.lights,
                r.config.size.0,
                r.config.size.1,
                r.error.clone().unwrap_or_default()
            );
        }
    }
}
