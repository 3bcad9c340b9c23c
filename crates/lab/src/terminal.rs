//! The commands that run in a terminal: `bench` (a progress bar; Ctrl-C stops after the
//! configuration in flight) and `soak` (a progress bar, or a line per cycle in logs). Only
//! in the native build (the page has no terminal).

use anyhow::Context as _;

use crate::cli::{BenchArgs, SoakArgs};

/// The matrix `args` ask for: a preset, a TOML file or the default, with the axes and
/// settings the command line gives in place of its own.
fn bench_matrix(args: &BenchArgs) -> anyhow::Result<crate::lab::BenchMatrix> {
    let mut matrix = match (&args.preset, &args.config) {
        (Some(preset), _) => crate::lab::BenchMatrix::preset(preset)?,
        (None, Some(path)) => crate::lab::BenchMatrix::from_toml(path)?,
        (None, None) => crate::lab::BenchMatrix::default(),
    };
    macro_rules! override_axis {
        ($field:ident) => {
            if !args.$field.is_empty() {
                matrix.$field = args.$field.clone();
            }
        };
    }
    override_axis!(scenes);
    override_axis!(views);
    override_axis!(pipelines);
    override_axis!(lights);
    override_axis!(sizes);
    override_axis!(grids);
    override_axis!(gbuffers);
    override_axis!(lighting);
    override_axis!(thresholds);
    override_axis!(falloffs);
    override_axis!(assignments);
    override_axis!(far_fields);
    override_axis!(shadows);
    override_axis!(shadings);
    if args.reference_shadows.is_some() {
        matrix.reference_shadows = args.reference_shadows;
    }
    if let Some(saturation) = args.saturation {
        matrix.saturation = saturation;
    }
    if let Some(frames) = args.frames {
        matrix.frames = frames;
    }
    if let Some(warmup) = args.warmup {
        matrix.warmup_frames = warmup;
    }
    if let Some(seconds) = args.warmup_seconds {
        matrix.warmup_seconds = seconds;
    }
    if args.camera.is_some() {
        matrix.camera = args.camera.clone();
    }
    let defaults = manylights::FrameSettings::default();
    for (path, texts) in &args.setting_axes.0 {
        let values = texts
            .iter()
            .map(|text| defaults.value_from_text(path, text))
            .collect();
        matrix.settings.replace(path, values);
    }
    Ok(matrix)
}

/// Runs `manylights bench`, with a progress bar; Ctrl-C stops after the configuration in
/// flight and keeps what was measured.
pub fn bench(args: &BenchArgs) -> anyhow::Result<()> {
    if let Some(dir) = &args.replot {
        crate::report::replot(&dir.join("bench.json"), dir)?;
        println!("redrew REPORT.md and the charts in {}", dir.display());
        return Ok(());
    }
    let matrix = bench_matrix(args)?;
    let total = matrix.configurations()?.len();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let handler_stop = stop.clone();
    ctrlc::set_handler(move || {
        eprintln!(
            "\ninterrupted: finishing the configuration in flight, then writing what was measured"
        );
        handler_stop.store(true, std::sync::atomic::Ordering::SeqCst);
    })
    .context("installing the Ctrl-C handler")?;
    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} configurations, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let report = crate::lab::run(&matrix, stop, |result, _, _| {
        bar.set_message(result.summary_line());
        bar.inc(1);
    })?;
    bar.finish();
    crate::report::write_all(&report, &args.out)?;
    println!(
        "{} configurations measured on {} ({}); wrote {}",
        report.results.len(),
        report.adapter,
        report.backend,
        args.out.join("REPORT.md").display()
    );
    Ok(())
}

/// Runs `manylights soak`; fails (non-zero exit) when memory did not stay flat.
/// `heap_bytes` counts live Rust heap bytes where the binary installs a counting allocator.
pub fn soak(args: &SoakArgs, heap_bytes: Option<fn() -> u64>) -> anyhow::Result<()> {
    let config = crate::soak::SoakConfig {
        scene: args.scene.clone(),
        frames: args.frames,
        phase_frames: args.phase_frames,
        size: args.size.into(),
        max_rss_growth_mib: args.max_rss_growth_mib,
        heap_bytes,
    };
    let bar = indicatif::ProgressBar::new(args.frames);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, ETA {eta} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    // Without a terminal (logs, CI) the bar is hidden: a line per cycle instead.
    let log_cycles = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let report = crate::soak::run(&config, |sample| {
        if log_cycles && (sample.phase + 1) % crate::soak::SCHEDULE_PERIOD == 0 {
            eprintln!(
                "cycle {}: {} frames, {:.0} s, RSS {:.1} MiB, Rust heap {:.2} MiB, GPU {:.1} MiB",
                (sample.phase + 1) / crate::soak::SCHEDULE_PERIOD,
                sample.frames_done,
                sample.seconds,
                sample.rss_bytes.unwrap_or(0) as f64 / 1048576.0,
                sample.heap_bytes.unwrap_or(0) as f64 / 1048576.0,
                sample.gpu_allocated_bytes.unwrap_or(0) as f64 / 1048576.0
            );
        }
        bar.set_position(sample.frames_done);
        bar.set_message(format!(
            "RSS {:.1} MiB, GPU {:.1} MiB",
            sample.rss_bytes.unwrap_or(0) as f64 / 1048576.0,
            sample.gpu_allocated_bytes.unwrap_or(0) as f64 / 1048576.0
        ));
    })?;
    bar.finish();
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(path, json).with_context(|| format!("writing {}", path.display()))?;
    }
    print!("{}", report.summary());
    for mismatch in report.gpu_mismatches.iter().take(10) {
        println!("  {mismatch}");
    }
    anyhow::ensure!(
        report.passed,
        "the soak run failed: {}",
        report.problems.join("; ")
    );
    Ok(())
}
