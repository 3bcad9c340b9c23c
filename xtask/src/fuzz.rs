//! `cargo xtask fuzz`: runs the cargo-fuzz targets in `fuzz/` for a fixed time each,
//! starting from seeds this project writes itself (`manylights_scene::fuzz_harness::seeds`)
//! plus every committed regression input, and reports executions and crashes. A crash
//! input is copied into `fuzz/regressions/<target>/`, where
//! `crates/scene/tests/fuzz_regressions.rs` replays it in every test run.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Instant, SystemTime};

use anyhow::{Context as _, bail};

pub const TARGETS: [&str; 3] = ["gltf_json", "glb", "obj_mtl"];

pub struct FuzzOptions {
    pub seconds: u64,
    pub targets: Vec<String>,
    pub parallel: bool,
    /// Largest input libFuzzer generates, in bytes.
    pub max_len: usize,
}

struct RunningTarget {
    name: String,
    child: Child,
    log: PathBuf,
    started: SystemTime,
    clock: Instant,
}

struct TargetResult {
    name: String,
    seconds: f64,
    executions: u64,
    corpus_files: usize,
    crashes: Vec<PathBuf>,
    log: PathBuf,
}

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz")
}

fn check_tools() -> anyhow::Result<()> {
    let works = |args: &[&str]| {
        Command::new("cargo")
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if !works(&["+nightly", "--version"]) {
        bail!("fuzzing needs a nightly toolchain: `rustup toolchain install nightly`");
    }
    if !works(&["fuzz", "--version"]) {
        bail!("fuzzing needs cargo-fuzz: `cargo install cargo-fuzz`");
    }
    Ok(())
}

/// Writes the seed corpus into `fuzz/corpus/<target>/`.
fn write_seeds(dir: &Path) -> anyhow::Result<()> {
    for (target, name, bytes) in manylights_scene::fuzz_harness::seeds() {
        let folder = dir.join("corpus").join(target);
        std::fs::create_dir_all(&folder).with_context(|| format!("{}", folder.display()))?;
        let path = folder.join(format!("seed-{name}"));
        std::fs::write(&path, bytes).with_context(|| format!("{}", path.display()))?;
    }
    Ok(())
}

fn start(dir: &Path, target: &str, options: &FuzzOptions) -> anyhow::Result<RunningTarget> {
    let regressions = dir.join("regressions").join(target);
    std::fs::create_dir_all(&regressions)?;
    std::fs::create_dir_all(dir.join("logs"))?;
    let log = dir.join("logs").join(format!("{target}.log"));
    let log_file =
        std::fs::File::create(&log).with_context(|| format!("creating {}", log.display()))?;
    let child = Command::new("cargo")
        .current_dir(dir)
        .args(["+nightly", "fuzz", "run", "--release", target])
        .arg(format!("corpus/{target}"))
        .arg(format!("regressions/{target}"))
        .arg("--")
        .arg(format!("-max_total_time={}", options.seconds))
        .arg(format!("-max_len={}", options.max_len))
        // A loader taking 10 s on one input is a hang; 2.5 GiB is past every limit the
        // loaders set (1 GiB per texture decode, inputs themselves are small).
        .arg("-timeout=10")
        .arg("-rss_limit_mb=2560")
        .arg("-print_final_stats=1")
        .stdout(log_file.try_clone()?)
        .stderr(log_file)
        .spawn()
        .context("starting cargo fuzz")?;
    println!(
        "fuzzing {target} for {} s (log: {})",
        options.seconds,
        log.display()
    );
    Ok(RunningTarget {
        name: target.to_string(),
        child,
        log,
        started: SystemTime::now(),
        clock: Instant::now(),
    })
}

fn finish(dir: &Path, mut running: RunningTarget) -> anyhow::Result<TargetResult> {
    running.child.wait()?;
    let seconds = running.clock.elapsed().as_secs_f64();
    let log = std::fs::read_to_string(&running.log).unwrap_or_default();
    // libFuzzer's -print_final_stats line; a crashed run reports its last status line.
    let executions = log
        .lines()
        .filter_map(|line| line.strip_prefix("stat::number_of_executed_units:"))
        .filter_map(|n| n.trim().parse().ok())
        .next_back()
        .or_else(|| {
            log.lines()
                .filter_map(|line| line.strip_prefix('#'))
                .filter_map(|rest| rest.split_whitespace().next()?.parse().ok())
                .next_back()
        })
        .unwrap_or(0);
    let target = &running.name;
    let corpus_files = std::fs::read_dir(dir.join("corpus").join(target))
        .map(|entries| entries.count())
        .unwrap_or(0);
    let mut crashes = Vec::new();
    if let Ok(entries) = std::fs::read_dir(dir.join("artifacts").join(target)) {
        for entry in entries.flatten() {
            let is_new = entry
                .metadata()
                .and_then(|m| m.modified())
                .is_ok_and(|modified| modified >= running.started);
            if is_new {
                let kept = dir.join("regressions").join(target).join(entry.file_name());
                std::fs::copy(entry.path(), &kept)?;
                crashes.push(kept);
            }
        }
    }
    Ok(TargetResult {
        name: target.clone(),
        seconds,
        executions,
        corpus_files,
        crashes,
        log: running.log,
    })
}

pub fn fuzz(options: &FuzzOptions) -> anyhow::Result<()> {
    check_tools()?;
    let dir = fuzz_dir();
    let targets: Vec<String> = if options.targets.is_empty() {
        TARGETS.iter().map(|t| t.to_string()).collect()
    } else {
        options.targets.clone()
    };
    for target in &targets {
        if !TARGETS.contains(&target.as_str()) {
            bail!(
                "unknown fuzz target '{target}' (targets: {})",
                TARGETS.join(", ")
            );
        }
    }
    write_seeds(&dir)?;
    let status = Command::new("cargo")
        .current_dir(&dir)
        .args(["+nightly", "fuzz", "build", "--release"])
        .status()
        .context("building the fuzz targets")?;
    if !status.success() {
        bail!("building the fuzz targets failed");
    }

    let mut results = Vec::new();
    if options.parallel {
        let running: Vec<_> = targets
            .iter()
            .map(|t| start(&dir, t, options))
            .collect::<anyhow::Result<_>>()?;
        for run in running {
            results.push(finish(&dir, run)?);
        }
    } else {
        for target in &targets {
            let run = start(&dir, target, options)?;
            results.push(finish(&dir, run)?);
        }
    }

    println!(
        "\n{:<10} {:>8} {:>14} {:>10} {:>8} {:>8}",
        "target", "seconds", "executions", "exec/s", "corpus", "crashes"
    );
    for r in &results {
        println!(
            "{:<10} {:>8.0} {:>14} {:>10.0} {:>8} {:>8}",
            r.name,
            r.seconds,
            r.executions,
            r.executions as f64 / r.seconds.max(1e-9),
            r.corpus_files,
            r.crashes.len()
        );
    }
    let crashes: Vec<_> = results.iter().flat_map(|r| &r.crashes).collect();
    if !crashes.is_empty() {
        for r in results.iter().filter(|r| !r.crashes.is_empty()) {
            eprintln!("{}: see {}", r.name, r.log.display());
        }
        bail!(
            "{} crash input(s), copied into fuzz/regressions/ (replayed by `cargo test -p manylights-scene --test fuzz_regressions`): {crashes:?}",
            crashes.len()
        );
    }
    Ok(())
}
