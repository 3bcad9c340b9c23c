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
        sizes: vec!["64x48".into()],
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
