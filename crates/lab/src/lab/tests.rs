use super::clock::slow_clock_results;
use super::matrix::BenchConfig;
use super::results::{BenchResult, PassTime};
use super::run::failed;
use manylights::deferred::{GBUFFER_PASS, LIGHTING_COMPUTE_PASS};
use manylights::forward_plus::DEPTH_PREPASS;
use manylights::gpu::PassName;

fn timed(pipeline: &str, size: (u32, u32), probe: PassName, probe_ms: f64) -> BenchResult {
    let config = BenchConfig {
        scene: "sponza".into(),
        pipeline: pipeline.parse().expect(pipeline),
        lights: 5000,
        size,
        grid: None,
        gbuffer: (pipeline == "deferred").then_some(manylights::GBufferLayout::Compact),
        lighting: None,
        assignment: None,
        threshold: 0.05,
        falloff: manylights::lights::Falloff::WindowedInverseSquare,
        far_field: None,
        spot_fraction: 0.0,
        spot_culling: None,
        shadows: Default::default(),
        shading: None,
        view: None,
        settings: Default::default(),
    };
    BenchResult {
        passes: vec![
            PassTime {
                name: probe.into(),
                median_ms: probe_ms,
                p95_ms: probe_ms,
            },
            PassTime {
                name: LIGHTING_COMPUTE_PASS.into(),
                median_ms: 3.0 * probe_ms,
                p95_ms: 3.0 * probe_ms,
            },
        ],
        error: None,
        ..failed(&config, String::new())
    }
}

#[test]
fn slow_clocks_are_found_against_the_same_work_only() {
    let results = [
        timed("deferred", (1920, 1080), GBUFFER_PASS, 1.395),
        // A lowered clock: the same g-buffer 3.3x slower.
        timed("deferred", (1920, 1080), GBUFFER_PASS, 4.605),
        // Within the probe's 10% slack.
        timed("deferred", (1920, 1080), GBUFFER_PASS, 1.50),
        // Other work: a larger size and Forward+'s pre-pass are compared only with
        // their own kind.
        timed("deferred", (3840, 2160), GBUFFER_PASS, 5.6),
        timed("forward-plus", (1920, 1080), DEPTH_PREPASS, 0.5),
        timed("forward-plus", (1920, 1080), DEPTH_PREPASS, 0.56),
        // No probe pass (naive): never flagged.
        BenchResult {
            passes: Vec::new(),
            ..timed("naive", (1920, 1080), GBUFFER_PASS, 0.0)
        },
    ];
    assert_eq!(slow_clock_results(&results), vec![1, 5]);
    assert!(slow_clock_results(&results[2..5]).is_empty());
}

/// The warm-up's time limit is a matrix dial: bench.json files written before it existed
/// read with the default, and a limit that is not a number of seconds is refused.
#[test]
fn the_warm_up_limit_is_read_defaulted_and_checked() {
    use super::matrix::BenchMatrix;
    let set: BenchMatrix = serde_json::from_str(r#"{"warmup_seconds": 2.5}"#).unwrap();
    assert_eq!(set.warmup_seconds, 2.5);
    let older: BenchMatrix = serde_json::from_str(r#"{"frames": 3}"#).unwrap();
    assert_eq!(
        older.warmup_seconds,
        manylights::WarmUpPolicy::default().max_seconds
    );
    assert!(older.configurations().is_ok());
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let matrix = BenchMatrix {
            warmup_seconds: bad,
            ..BenchMatrix::default()
        };
        let error = matrix.configurations().unwrap_err().to_string();
        assert!(error.contains("warm-up seconds"), "{bad}: {error}");
    }
    let no_samples = BenchMatrix {
        reference_samples: 0,
        ..BenchMatrix::default()
    };
    let error = no_samples.configurations().unwrap_err().to_string();
    assert!(error.contains("reference_samples 0"), "{error}");
    // Naive alone above its light limit: nothing would run, and the report would be empty.
    let nothing = BenchMatrix {
        pipelines: vec![manylights::PipelineKind::Naive],
        lights: vec![60_000],
        ..BenchMatrix::default()
    };
    let error = nothing.configurations().unwrap_err().to_string();
    assert!(error.contains("naive_light_limit = 20000"), "{error}");
}

/// A report names its passes by text, as the timer named them; reports from before the
/// assignment was timed step by step (`assign lights`, seven of docs/results' files) still
/// count it as assignment.
#[test]
fn pass_keys_are_the_timers_names_and_read_old_reports() {
    use super::results::PassKey;
    use manylights::cluster::passes::{ASSIGN_STAGE, FILL_LISTS};
    let key = PassKey::from(FILL_LISTS);
    assert_eq!(
        serde_json::to_string(&key).unwrap(),
        "\"assign: fill lists\""
    );
    assert!(key.is(FILL_LISTS) && key.in_stage(ASSIGN_STAGE));
    let old: PassKey = serde_json::from_str("\"assign lights\"").unwrap();
    assert!(old.in_stage(ASSIGN_STAGE));
    assert!(!PassKey::from(GBUFFER_PASS).in_stage(ASSIGN_STAGE));
}

/// The trade-offs preset measures MSAA where a pipeline has it (never deferred), naive at
/// its light limit only, and every view, scene and transparency for Forward+.
#[test]
fn the_trade_offs_preset_runs_msaa_where_a_pipeline_has_it() {
    use manylights::{PipelineKind, Transparency};
    let matrix = super::BenchMatrix::trade_offs();
    let configs = matrix.configurations().expect("configurations");
    let msaa_of = |c: &super::BenchConfig| {
        c.settings
            .get("view.msaa")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(1)
    };
    let transparency_of = |c: &super::BenchConfig| {
        c.settings
            .get("transparency")
            .and_then(serde_json::Value::as_str)
            .unwrap_or("sorted")
            .to_string()
    };
    assert!(
        configs
            .iter()
            .all(|c| c.pipeline != PipelineKind::Deferred || msaa_of(c) == 1)
    );
    assert!(
        configs
            .iter()
            .all(|c| c.pipeline != PipelineKind::Naive || c.lights <= matrix.naive_light_limit)
    );
    for scene in &matrix.scenes {
        for view in &matrix.views {
            for transparency in Transparency::ALL {
                for msaa in [1, 4, 8] {
                    assert!(
                        configs
                            .iter()
                            .any(|c| c.pipeline == PipelineKind::ForwardPlus
                                && &c.scene == scene
                                && c.view.as_ref() == Some(view)
                                && transparency_of(c) == transparency.name()
                                && msaa_of(c) == msaa),
                        "Forward+ on {scene} from {view}, {transparency}, {msaa}x"
                    );
                }
            }
        }
    }
}

/// A configuration measured while the GPU raised errors no scope caught fails with them,
/// and one measured cleanly keeps its result.
#[test]
fn gpu_errors_fail_the_configuration_they_happened_in() {
    use super::run::unless_gpu_errors;
    let clean = timed("deferred", (64, 48), GBUFFER_PASS, 1.0);
    let config = clean.config.clone();
    let kept = unless_gpu_errors(&config, Ok(clean.clone()), Vec::new());
    assert_eq!(kept, clean);
    let failed = unless_gpu_errors(
        &config,
        Ok(clean),
        vec!["validation error: invalid pipeline".into()],
    );
    assert_eq!(
        failed.error.as_deref(),
        Some("validation error: invalid pipeline")
    );
    assert!(failed.passes.is_empty());
    let error = unless_gpu_errors(&config, Err("no frame".into()), vec!["later".into()]);
    assert_eq!(error.error.as_deref(), Some("no frame"));
}

/// Every report the docs publish reads back (its matrix's named axes of before as setting
/// axes), and its matrix, run again, gives as many configurations as it ran with the
/// setting values each ran with, in the order it ran them; every matrix file the docs
/// publish reads and has configurations.
#[test]
fn the_published_reports_and_matrices_read_back_and_reproduce_their_configurations() {
    let results = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/results");
    let mut files = Vec::new();
    let mut folders = vec![results];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).expect("docs/results") {
            let path = entry.expect("an entry").path();
            if path.is_dir() {
                folders.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    let (mut reports, mut matrices) = (0, 0);
    let mut differ = Vec::new();
    for file in &files {
        match file.extension().and_then(|e| e.to_str()) {
            Some("json") if file.ends_with("bench.json") => {
                let text = std::fs::read_to_string(file).expect("a report");
                let mut data: serde_json::Value = serde_json::from_str(&text).expect("JSON");
                super::setting_axes::upgrade_report(&mut data);
                let report: super::BenchReport = serde_json::from_value(data)
                    .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
                let ran: Vec<_> = report.results.iter().map(|r| r.config.clone()).collect();
                let again = report.matrix.configurations().expect("configurations");
                // What this run of the matrix decides: the configurations' count and, in
                // order, their setting axes' values (the other fields are as the code of
                // their day wrote them: a view or an assignment named since).
                let settings = |configs: &[super::BenchConfig]| -> Vec<_> {
                    configs.iter().map(|c| c.settings.clone()).collect()
                };
                if !report.interrupted && settings(&again) != settings(&ran) {
                    differ.push(format!(
                        "{}: {:?} again, {:?} ran",
                        file.display(),
                        settings(&again),
                        settings(&ran)
                    ));
                }
                reports += 1;
            }
            Some("toml") => {
                let matrix = super::BenchMatrix::from_toml(file)
                    .unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
                matrix
                    .configurations()
                    .unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
                matrices += 1;
            }
            _ => {}
        }
    }
    assert!(
        reports > 20 && matrices > 5,
        "{reports} reports, {matrices} matrices"
    );
    assert!(differ.is_empty(), "{differ:#?}");
}
