//! The lab on the GPU at hand (lavapipe in CI), on a tiny matrix: every configuration is
//! measured, the reference compares as it should, and the report files are written.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use manylights::lights::Falloff;
use manylights::{GBufferLayout, LightingPath, PipelineKind};
use manylights_lab::lab::{BenchMatrix, run};
use manylights_lab::report::write_all as write_report;

#[test]
fn a_small_matrix_runs_and_writes_its_report() {
    let matrix = BenchMatrix {
        scenes: vec!["cornell".into()],
        pipelines: PipelineKind::ALL.to_vec(),
        lights: vec![8, 32],
        sizes: vec![manylights::ImageSize::new(64, 48)],
        grids: vec!["8x6x16:log-near".parse().expect("grid")],
        gbuffers: vec![GBufferLayout::Full],
        lighting: vec![LightingPath::Compute],
        falloffs: vec![Falloff::WindowedInverseSquare, Falloff::InverseSquare],
        warmup_frames: 1,
        frames: 3,
        reference_samples: 64,
        ..BenchMatrix::default()
    };
    // naive x 2 falloffs + Forward+ + deferred (inverse-square is naive-only), x 2 counts.
    assert_eq!(matrix.configurations().expect("matrix").len(), 8);
    let mut seen = 0;
    let report = run(
        &matrix,
        Arc::new(AtomicBool::new(false)),
        |_, done, total| {
            seen = done;
            assert_eq!(total, 8);
        },
    )
    .expect("bench run");
    assert_eq!(seen, 8);
    assert!(!report.interrupted);
    for result in &report.results {
        assert!(
            result.error.is_none(),
            "{:?}: {:?}",
            result.config,
            result.error
        );
        if report.timestamps {
            assert!(
                result.gpu_total_median_ms.is_some_and(|ms| ms > 0.0) && !result.passes.is_empty(),
                "{:?}: GPU total {:?}, passes {:?}, re-timed {} time(s)",
                result.config,
                result.gpu_total_median_ms,
                result.passes,
                result.clock_remeasures
            );
        }
        assert!(result.accuracy.psnr_db.is_some() && result.accuracy.samples > 0);
        // The report holds the whole frame that ran, as data.
        let frame = result.frame.as_ref().expect("the frame that ran");
        assert_eq!(
            frame.lights.count, result.config.lights,
            "{:?}",
            result.config
        );
        assert_eq!(frame.pipeline.kind(), result.config.pipeline);
        assert_eq!(frame.view.size, result.config.size);
        assert!(result.light_evaluations > 0);
        if result.config.falloff == Falloff::InverseSquare {
            // Naive with the reference falloff is the reference.
            assert_eq!(result.accuracy.max_abs, Some(0.0), "{:?}", result.config);
            assert!(
                result.accuracy.f64_max_relative < 2e-3,
                "{:?}",
                result.accuracy
            );
        } else {
            // Windowed lights in a 4 m room leave out far contributions: a measurable error.
            assert!(
                result.accuracy.max_abs.is_some_and(|e| e > 0.0),
                "{:?}",
                result.config
            );
        }
        if result.config.pipeline != PipelineKind::Naive {
            assert!(
                result.lights_per_cluster_mean.is_some() && result.false_positive_ratio.is_some()
            );
        }
    }
    let dir = tempfile::tempdir().expect("tempdir");
    write_report(&report, dir.path()).expect("report");
    for file in [
        "bench.json",
        "REPORT.md",
        "gpu_ms_vs_lights.svg",
        "error_vs_time.svg",
        "lights_per_cluster_vs_grid.svg",
    ] {
        let bytes = std::fs::metadata(dir.path().join(file))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(bytes > 200, "{file} is missing or empty");
    }
    let json: manylights_lab::lab::BenchReport = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("bench.json")).expect("json"),
    )
    .expect("parses back");
    assert_eq!(json.results.len(), 8);
}

#[test]
fn presets_and_toml_matrices() {
    assert!(
        BenchMatrix::preset("reference")
            .expect("reference")
            .configurations()
            .expect("configs")
            .len()
            >= 24
    );
    let scale = BenchMatrix::preset("scale").expect("scale");
    assert!(scale.lights.contains(&200_000));
    assert!(BenchMatrix::preset("nope").is_err());
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("matrix.toml");
    std::fs::write(
        &path,
        "scenes = [\"cornell\"]\nlights = [10, 100]\npipelines = [\"forward-plus\"]\n",
    )
    .expect("write");
    let matrix = BenchMatrix::from_toml(&path).expect("toml");
    assert_eq!(matrix.configurations().expect("configs").len(), 2);
    std::fs::write(&path, "lights = [\"many\"]\n").expect("write");
    let error = format!("{:#}", BenchMatrix::from_toml(&path).expect_err("bad toml"));
    assert!(error.contains("matrix.toml"), "{error}");
    // A misspelt name fails when the matrix is read, naming the axis's choices.
    std::fs::write(&path, "pipelines = [\"forward-pluss\"]\n").expect("write");
    let error = format!("{:#}", BenchMatrix::from_toml(&path).expect_err("bad name"));
    assert!(
        error.contains("matrix.toml") && error.contains("forward-pluss") && error.contains("naive"),
        "{error}"
    );
}

/// The viewer's measure panel: the same run, polled a frame at a time on a device of its
/// own, measures every configuration, can be stopped, and its report draws the charts
/// the page shows and replots from its bench.json.
#[test]
fn a_job_polled_once_a_frame_measures_and_stops_when_asked() {
    use manylights::LoadedScene;
    use manylights::gpu::{AdapterRequest, wgpu};
    use manylights_lab::lab::LabJob;
    use web_time::Duration;

    let matrix = BenchMatrix {
        pipelines: vec![PipelineKind::ForwardPlus, PipelineKind::Deferred],
        lights: vec![8, 16],
        sizes: vec![manylights::ImageSize::new(64, 48)],
        // Two warm-up frames and no settling: lavapipe's frame times never settle within
        // 3%, and each configuration then warmed up for the default 20 s.
        warmup_frames: 2,
        warmup_seconds: 0.0,
        frames: 3,
        reference_samples: 32,
        ..BenchMatrix::default()
    };
    let start = |matrix: &BenchMatrix| {
        LabJob::start(
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env()),
            AdapterRequest::from_env(),
            LoadedScene::load("cornell").expect("cornell"),
            "cornell".into(),
            matrix.clone(),
        )
    };
    let mut job = start(&matrix);
    assert_eq!(job.progress().total, 4);
    // No time budget: one frame a call, as in a frame loop that is out of time.
    let mut calls = 0;
    let report = loop {
        calls += 1;
        if let Some(report) = job.advance(Duration::ZERO) {
            break report.expect("the job's run");
        }
        assert!(calls < 100_000, "the job never ended");
    };
    // Each configuration renders warm-up and timed frames, yielding after each one.
    assert!(calls > 4 * 5, "the job yielded only {calls} times");
    assert_eq!(report.matrix.scenes, ["cornell"]);
    assert_eq!(report.results.len(), 4);
    assert!(!report.interrupted);
    for result in &report.results {
        assert!(result.error.is_none(), "{:?}", result.error);
        assert!(result.accuracy.samples > 0 && result.accuracy.f64_mean_relative.is_finite());
    }
    assert_eq!(job.progress().done, 4);

    let charts = manylights_lab::report::charts(&report).expect("charts");
    let error_chart = charts
        .iter()
        .find(|c| c.file == "error_vs_time.svg")
        .expect("the error chart");
    assert!(error_chart.svg.starts_with("<svg") && error_chart.svg.contains("Pareto"));
    let dir = tempfile::tempdir().expect("tempdir");
    let bench = dir.path().join("bench.json");
    std::fs::write(&bench, serde_json::to_string(&report).expect("json")).expect("write");
    manylights_lab::report::replot(&bench, dir.path()).expect("replot");
    assert!(dir.path().join("error_vs_time.svg").exists());

    // Stopped after its first configuration, it keeps what it measured.
    let mut job = start(&matrix);
    let report = loop {
        if job.progress().done >= 1 {
            job.stop();
        }
        if let Some(report) = job.advance(Duration::from_millis(5)) {
            break report.expect("the stopped run");
        }
    };
    assert!(report.interrupted);
    assert!(
        (1..4).contains(&report.results.len()),
        "{}",
        report.results.len()
    );
}

/// The reference with visibility, exact and estimated: naive with exact shadows and the
/// reference's own falloff renders the exact reference, so its error against the f64
/// samples is the estimate's own. Traced exactly (the default budget) it is the f32
/// image's rounding alone and no interval is reported; with 8 rays a pixel for 32 lights
/// the report gives the interval, and the error stays within it on average (the mean
/// absolute deviation of a normal estimate is 0.8 standard errors, 0.41 of the 95%
/// half-width: held to the half-width).
#[test]
fn the_reference_with_visibility_reports_its_interval_when_estimated() {
    let estimated = |rays: u32| {
        let matrix = BenchMatrix {
            scenes: vec!["cornell".into()],
            pipelines: vec![PipelineKind::Naive],
            lights: vec![32],
            sizes: vec![manylights::ImageSize::new(64, 48)],
            falloffs: vec![Falloff::InverseSquare],
            shadows: vec![manylights::Shadows::Exact],
            warmup_frames: 1,
            warmup_seconds: 0.0,
            frames: 1,
            reference_samples: 64,
            reference_shadow_rays: rays,
            ..BenchMatrix::default()
        };
        let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
        let result = &report.results[0];
        assert!(result.error.is_none(), "{:?}", result.error);
        result.accuracy.clone()
    };
    let exact = estimated(manylights_lab::lab::DEFAULT_REFERENCE_SHADOW_RAYS);
    assert_eq!(exact.f64_reference_half_width, None);
    assert!(exact.f64_mean_relative < 2e-3, "{exact:?}");
    let sampled = estimated(8);
    let half_width = sampled
        .f64_reference_half_width
        .expect("an estimated reference reports its interval");
    println!(
        "8 rays a pixel: mean relative error {:.4}, interval +-{half_width:.4}",
        sampled.f64_mean_relative
    );
    assert!(
        half_width > 0.0 && sampled.f64_mean_relative <= half_width,
        "{sampled:?}"
    );
}

/// With the reference's visibility the lab splits each configuration's error into the
/// samples in shadow and in light, and measures flicker: naive with exact shadows (the
/// reference's own falloff) is exact on both sides and does not flicker; one ray a pixel
/// flickers where shadows are partial, and its error shows in shadow. Without shadows the
/// error in shadow is more than the half of the light shadows take there, and less in
/// light.
#[test]
fn shadows_are_measured_in_shadow_in_light_and_for_flicker() {
    let matrix = BenchMatrix {
        scenes: vec!["cornell".into()],
        pipelines: vec![PipelineKind::Naive],
        lights: vec![32],
        sizes: vec![manylights::ImageSize::new(64, 48)],
        falloffs: vec![Falloff::InverseSquare],
        shadows: vec![
            manylights::Shadows::Exact,
            manylights::Shadows::Rays(1),
            manylights::Shadows::Off,
        ],
        reference_shadows: Some(manylights::Shadows::Exact),
        warmup_frames: 1,
        warmup_seconds: 0.0,
        frames: 1,
        reference_samples: 64,
        ..BenchMatrix::default()
    };
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let accuracy = accuracy_of_every_configuration(&report);
    let (exact, one_ray, off) = (&accuracy[0], &accuracy[1], &accuracy[2]);
    let in_shadow = |a: &manylights_lab::lab::Accuracy| {
        a.f64_mean_relative_shadowed.expect("samples in shadow")
    };
    let lit = |a: &manylights_lab::lab::Accuracy| a.f64_mean_relative_lit.expect("lit samples");
    assert!(in_shadow(exact) < 2e-3 && lit(exact) < 2e-3, "{exact:?}");
    assert_eq!(
        exact.flicker,
        Some(0.0),
        "exact shadows are the same every frame"
    );
    assert!(one_ray.flicker.expect("flicker") > 0.01, "{one_ray:?}");
    assert!(in_shadow(one_ray) > 2.0 * lit(one_ray), "{one_ray:?}");
    // A lit sample loses less than half its light to shadows: the unshadowed frame is
    // nearer the reference there than in shadow.
    assert!(in_shadow(off) > 0.5 && lit(off) < in_shadow(off), "{off:?}");
    assert_eq!(off.flicker, Some(0.0));
}

/// A matrix of filtered ray budgets alone (no exact configuration first to make the
/// reference) measures them: the reference image is naive with exact shadows, whatever
/// mode a configuration measures (naive refuses the filter). The history's flicker is
/// below the filter's alone, and its lag is reported (within the three histories the lab
/// renders after the lights jump), and after a disocclusion it settles within one history;
/// a mode without history has neither.
#[test]
fn a_ray_budget_with_history_is_measured_for_flicker_and_lag() {
    let matrix = deferred_cornell_with_shadows(vec![
        manylights::Shadows::RaysSpatial(1),
        manylights::Shadows::RaysTemporal(1),
    ]);
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let accuracy = accuracy_of_every_configuration(&report);
    assert_eq!(accuracy.len(), 2, "one configuration a mode");
    let (filtered, history) = (&accuracy[0], &accuracy[1]);
    let flicker = |a: &manylights_lab::lab::Accuracy| a.flicker.expect("flicker");
    assert!(flicker(filtered) > 0.0, "{filtered:?}");
    assert!(flicker(history) < flicker(filtered), "{history:?}");
    assert_eq!(filtered.lag_frames, Some(0));
    let lag = history.lag_frames.expect("lag");
    assert!(
        lag < 3 * manylights::visibility::SHADOW_HISTORY_FRAMES,
        "{history:?}"
    );
    // After the camera jumps, what the old view hid starts without history (the surface
    // rule) and the rest is clamped to the new frame: it settles within one history.
    assert_eq!(filtered.disocclusion_lag_frames, Some(0));
    let ghosting = history
        .disocclusion_lag_frames
        .expect("lag after a disocclusion");
    println!("lag {lag}, after a disocclusion {ghosting}");
    assert!(
        ghosting <= manylights::visibility::SHADOW_HISTORY_FRAMES,
        "{history:?}"
    );
}

/// Each configuration's accuracy, in the matrix's order; every configuration must have run.
fn accuracy_of_every_configuration(
    report: &manylights_lab::lab::BenchReport,
) -> Vec<manylights_lab::lab::Accuracy> {
    report
        .results
        .iter()
        .map(|r| {
            assert!(r.error.is_none(), "{:?}", r.error);
            r.accuracy.clone()
        })
        .collect()
}

/// On a scene with blended surfaces the f64 reference composites the blended layers over
/// each sample's opaque surface, farthest first: naive with the reference's own falloff
/// matches it at every sample, to the same 2e-3 as on an opaque scene, with 16 samples or
/// more under panes or sparks. Samples next to a blended edge are left out
/// (the rasterizer and the reference's ray may see the edge on either side). Without the
/// layers a pane's pixel would be off by its own share of the light (alpha 0.35 to 0.6).
#[test]
fn the_f64_reference_composites_blended_layers() {
    let matrix = BenchMatrix {
        scenes: vec!["glass".into()],
        pipelines: vec![PipelineKind::Naive],
        lights: vec![16],
        sizes: vec![manylights::ImageSize::new(64, 48)],
        falloffs: vec![Falloff::InverseSquare],
        warmup_frames: 1,
        frames: 1,
        reference_samples: 256,
        ..BenchMatrix::default()
    };
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let accuracy = accuracy_of_every_configuration(&report);
    let naive = &accuracy[0];
    assert!(naive.samples >= 128, "too few samples: {naive:?}");
    assert!(
        naive.layered_samples >= 16,
        "too few samples under blended surfaces: {naive:?}"
    );
    assert!(naive.f64_max_relative < 2e-3, "{naive:?}");
}

/// The lab measures whole frames against the GPU reference beyond the naive image's light
/// limit, and its seam measure sees cluster blocks where the far field's cuts disagree:
/// Sponza, 10,000 lights of radius 0.2 m in a 160x90 frame (its 16x9 tiles of 10x10
/// pixels). Without a far field every cluster sums the same windowed falloff, and the error
/// (95% of the light is beyond the radius) steps alike across and beside cluster
/// boundaries. With 16 slots each cluster's cut stops at large aggregates of its own, and
/// its error jumps where clusters meet. With the default 64, the cut ranks nodes that touch
/// its cluster by power x spread (far_field.wgsl's `node_bound`) and aggregates are lit
/// through their box: the blocks are gone (before that ranking: 4.9). Measured on
/// lavapipe: 0.99, 2.1 and 1.19; the bounds leave room either way for another rasteriser.
#[test]
fn the_seam_measure_sees_cluster_blocks_where_cuts_disagree_and_the_default_tree_has_none() {
    let matrix = BenchMatrix {
        pipelines: vec![PipelineKind::Deferred],
        lights: vec![10_000],
        sizes: vec![manylights::ImageSize::new(160, 90)],
        far_fields: ["off", "tree:0.1", "tree:0.1:16"]
            .iter()
            .map(|far| far.parse().expect("far field"))
            .collect(),
        intensity: 0.2,
        warmup_frames: 1,
        warmup_seconds: 1.0,
        frames: 1,
        reference_light_limit: 0,
        reference_samples: 64,
        ..BenchMatrix::default()
    };
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let seams: Vec<f64> = report
        .results
        .iter()
        .map(|result| {
            let accuracy = &result.accuracy;
            assert!(result.error.is_none(), "{:?}", result.error);
            assert_eq!(
                accuracy.image_reference,
                Some(manylights_lab::lab::ImageReference::GpuFullFrame),
                "{:?}: above the naive limit the GPU reference draws the frame",
                result.config.far_field
            );
            // The reference has content, and the frame is compared with it everywhere.
            assert!(accuracy.reference_exposure.is_some());
            assert!(accuracy.flip_at_reference_exposure.is_some());
            assert!(accuracy.error_map.is_some());
            // The GPU reference against the f64 samples: within the f32 shading's bound for
            // PBR at GGX's floor (tests/naive/gpu_reference.rs: 1e-5 + 2u + 8u / alpha, alpha
            // 0.045^2), relative to the brightest channel as the lab's errors are.
            let u = f64::from(f32::EPSILON) / 2.0;
            let bound = 1e-5 + 2.0 * u + 8.0 * u / (0.045f64 * 0.045);
            let difference = accuracy
                .gpu_reference_vs_f64
                .expect("compared with the f64 samples");
            assert!(
                difference <= bound,
                "GPU reference vs f64: {difference:e} over {bound:e}"
            );
            accuracy
                .seam_ratio
                .expect("a clustered frame has a seam measure")
        })
        .collect();
    println!("seam measure: off, tree:0.1, tree:0.1:16: {seams:?}");
    let [off, tree, coarse] = seams[..] else {
        panic!("three configurations, got {seams:?}");
    };
    assert!(off < 1.3, "no far field: seam measure {off}");
    assert!(
        coarse > 1.6,
        "16 slots' cluster blocks are not seen: seam measure {coarse}"
    );
    assert!(
        tree < 1.5,
        "the tree's cuts disagree along cluster edges: seam measure {tree}"
    );
}

/// Flicker under motion: along a camera walk with the lights animating, exact shadows
/// change their error only as the error's pattern drifts across the screen (the measure's
/// floor), one ray a pixel without a filter changes it by its noise every frame, and the
/// filter with history keeps most of that noise out while the camera moves.
#[test]
fn motion_flicker_is_at_the_floor_without_randomness_and_small_with_history() {
    let matrix = BenchMatrix {
        motion_frames: 6,
        // Its walk would otherwise drift the third of the light the radius cuts across the
        // screen, and the exact method's error would not be its storage's alone.
        ..unbounded(deferred_cornell_with_shadows(vec![
            manylights::Shadows::Exact,
            manylights::Shadows::Rays(1),
            manylights::Shadows::RaysTemporal(1),
        ]))
    };
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let flicker: Vec<f64> = accuracy_of_every_configuration(&report)
        .iter()
        .map(|a| a.motion_flicker.expect("motion flicker"))
        .collect();
    let [exact, one_ray, history] = flicker[..] else {
        panic!("three configurations, got {flicker:?}");
    };
    println!(
        "motion flicker: exact {exact:.4}, rays:1 {one_ray:.4}, rays:1+spatial+temporal {history:.4}"
    );
    // The floor: each frame's error is its and the reference's rounding to the half-float
    // target, half an ulp (2^-11) of each pixel each, so a change between two frames is at
    // most 4 x 2^-11 of the pixel's luminance, 2e-3.
    assert!(exact < 2e-3, "exact shadows: {exact}");
    assert!(
        one_ray > 10.0 * exact,
        "one ray: {one_ray} against exact {exact}"
    );
    assert!(
        history < 0.5 * one_ray,
        "with history: {history} against one ray {one_ray}"
    );
}

/// `matrix` with lights of radius 1,000 m: the windowed falloff is the reference's
/// unbounded one here to 2 (d/r)^4 < 1e-10, so what a frame errs is its method's alone.
fn unbounded(matrix: BenchMatrix) -> BenchMatrix {
    BenchMatrix {
        thresholds: vec![1e-6 * matrix.intensity],
        ..matrix
    }
}

/// Deferred (full G-buffer, compute lighting) on cornell at 64x48 with 32 lights, one
/// frame each, for each of `shadows`.
fn deferred_cornell_with_shadows(shadows: Vec<manylights::Shadows>) -> BenchMatrix {
    BenchMatrix {
        scenes: vec!["cornell".into()],
        pipelines: vec![PipelineKind::Deferred],
        gbuffers: vec![GBufferLayout::Full],
        lighting: vec![LightingPath::Compute],
        lights: vec![32],
        sizes: vec![manylights::ImageSize::new(64, 48)],
        shadows,
        warmup_frames: 1,
        warmup_seconds: 0.0,
        frames: 1,
        reference_samples: 64,
        ..BenchMatrix::default()
    }
}

/// Beyond `reference_light_limit` a shadowed frame is judged against the GPU reference
/// with visibility, whole: exact within `reference_image_rays` lights (within the f32
/// shading's 1e-5 of the f64 samples, which trace every ray: the default budget covers
/// 32 lights), and estimated beyond with a standard error and its distance from the f64
/// samples in standard errors (how honest those are is `tests/shadows/reference.rs`'s to
/// say: with 2 draws a sampler, as here, a pixel whose brightest light is hidden can be
/// missed by every sampler alike).
#[test]
fn shadowed_frames_beyond_the_naive_limit_are_judged_against_the_gpu_reference_with_visibility() {
    let measure = |rays: u32| {
        let mut matrix = deferred_cornell_with_shadows(vec![manylights::Shadows::Exact]);
        matrix.reference_light_limit = 0;
        matrix.reference_image_rays = rays;
        let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
        accuracy_of_every_configuration(&report).remove(0)
    };
    let exact = measure(256);
    assert_eq!(
        exact.image_reference,
        Some(manylights_lab::lab::ImageReference::GpuFullFrameVisible),
        "{exact:?}"
    );
    assert!(
        exact.gpu_reference_vs_f64.expect("compared") < 1e-4,
        "{exact:?}"
    );
    assert_eq!(exact.reference_image_standard_error, None);
    assert!(exact.flip_at_reference_exposure.is_some(), "{exact:?}");
    let estimated = measure(16);
    let standard_error = estimated
        .reference_image_standard_error
        .expect("an estimated reference reports its standard error");
    let sigmas = estimated.gpu_reference_vs_f64_sigmas.expect("compared");
    println!(
        "16 rays a pixel: mean relative standard error {standard_error:.4}, largest difference from f64 {sigmas:.2} sigma"
    );
    assert!(standard_error > 0.0 && sigmas > 0.0, "{estimated:?}");
}

/// Drawn cameras in the lab (issue 80): a `draw:COUNT` view runs each setting on that many
/// cameras drawn inside the scene, each measured whole against the full-frame reference
/// (its blotch measure beside FLIP and seams), and the report states each setting over
/// them as mean, spread and worst. The pillars scene, 64x36, 200 lights, deferred.
#[test]
fn drawn_cameras_are_measured_one_by_one_and_summarised_over_them() {
    let matrix = BenchMatrix {
        scenes: vec!["pillars".into()],
        views: vec!["draw:2:5".into()],
        pipelines: vec![PipelineKind::Deferred],
        lights: vec![200],
        sizes: vec![manylights::ImageSize::new(64, 36)],
        warmup_frames: 1,
        warmup_seconds: 0.0,
        frames: 1,
        reference_samples: 32,
        ..BenchMatrix::default()
    };
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let views: Vec<Option<&str>> = (report.results.iter())
        .map(|result| {
            assert!(result.error.is_none(), "{:?}", result.error);
            let accuracy = &result.accuracy;
            assert!(
                accuracy.reference_exposure.is_some(),
                "the reference is lit"
            );
            let blotch = accuracy.blotch.expect("a whole frame has a blotch measure");
            assert!(blotch.is_finite() && blotch >= 0.0, "blotch {blotch}");
            result.config.view.as_deref()
        })
        .collect();
    assert_eq!(views, [Some("drawn:5:0"), Some("drawn:5:1")]);
    let over = manylights_lab::lab::over_cameras::over_drawn_cameras(&report.results);
    assert_eq!(over.len(), 1, "{over:?}");
    assert_eq!(over[0].cameras, 2);
    let flip = over[0].flip.expect("FLIP over the cameras");
    assert!(flip.worst >= flip.mean && flip.spread >= 0.0, "{flip:?}");
    let markdown = manylights_lab::report::report_markdown(&report);
    assert!(markdown.contains("## Over drawn cameras"), "{markdown}");
    // Zero cameras is refused, naming the view.
    let none = BenchMatrix {
        views: vec!["draw:0".into()],
        ..matrix
    };
    let error = none.configurations().unwrap_err().to_string();
    assert!(
        error.contains("draw:0") && error.contains("at least one"),
        "{error}"
    );
}

/// The blotch measure sees what makes shadowed frames blotchy (issue 80) and nothing else:
/// exact shadows are at its floor; one unfiltered ray a pixel is noise independent from
/// pixel to pixel, which it takes out; the spatial filter spreads each ray's noise over its
/// taps (a Gaussian of 3 pixels), patches it measures; and the history averages 16 frames
/// of independent draws, a quarter of those patches' amplitude, so a history reset every
/// frame would measure as the filter alone. Cornell, 128x96, 32 lights (the reference's
/// visibility exact), deferred compute lighting.
#[test]
fn the_blotch_measure_sees_the_filters_patches_and_the_historys_average() {
    let matrix = BenchMatrix {
        sizes: vec![manylights::ImageSize::new(128, 96)],
        // Without the light a radius would cut: a smooth error the measure would see in
        // every frame alike.
        ..unbounded(deferred_cornell_with_shadows(vec![
            manylights::Shadows::Exact,
            manylights::Shadows::Rays(1),
            manylights::Shadows::RaysSpatial(1),
            manylights::Shadows::RaysTemporal(1),
        ]))
    };
    let report = run(&matrix, Arc::new(AtomicBool::new(false)), |_, _, _| {}).expect("run");
    let blotch: Vec<f64> = accuracy_of_every_configuration(&report)
        .iter()
        .map(|a| a.blotch.expect("a whole frame has a blotch measure"))
        .collect();
    let [exact, one_ray, spatial, history] = blotch[..] else {
        panic!("four configurations, got {blotch:?}");
    };
    println!(
        "blotch: exact {exact:.4}, rays:1 {one_ray:.4}, +spatial {spatial:.4}, +temporal {history:.4}"
    );
    assert!(exact < 0.005, "exact shadows: {exact}");
    assert!(
        spatial > 2.0 * one_ray.max(exact),
        "the filter's patches: {spatial} against one ray's {one_ray}"
    );
    assert!(
        history < 0.6 * spatial,
        "with history: {history} against the filter alone {spatial}"
    );
}
