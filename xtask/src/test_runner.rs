//! `cargo xtask test`'s first step: every test target of the workspace built once, then the
//! test binaries run side by side, as many at a time as the machine has cores, the slowest
//! first, each printing its time; the doctests after.
//!
//! What it buys, measured (fresh clone, the 2-core machine, lavapipe): little time there.
//! The binaries ran in 850 s two at a time against about 880 s one after another with
//! `cargo test`; each took 1.9 times as long beside another (their times sum to 1,682 s),
//! because lavapipe already keeps both cores busy (its rasterizer runs a thread per core).
//! What it buys everywhere: each binary's time in CI's log, which is what cutting the tests
//! to the smallest size that proves their claim starts from, and a machine with more
//! cores than lavapipe fills is used.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::process::Command;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{Context as _, bail};

/// The test binaries that take longest on lavapipe (most first): started first, so that
/// the short ones fill the other cores around them. A binary not named here starts after
/// these, in the order cargo built it. The order of `cargo xtask test` on the 2-core
/// machine (2026-11-29, each beside another: shadows 515 s, soak 298, extremes 264, lab
/// 217, forward_plus 207, far_field 177, deferred 173, xtask 159, soak_leak_check 110,
/// budget 96, then spots, cli and viewer at about 73); the lab's, last until then, ran
/// alone at the end.
const SLOWEST_FIRST: [&str; 13] = [
    "shadows",
    "soak",
    "extremes",
    "lab",
    "forward_plus",
    "far_field",
    "deferred",
    "xtask",
    "soak_leak_check",
    "budget",
    "spots",
    "cli",
    "viewer",
];

/// Each test's time after its verdict (`test name ... ok <12.345s>`), so that CI's log says
/// which test of a slow binary to make smaller. libtest's option is unstable: the binaries
/// accept it when `RUSTC_BOOTSTRAP` is set where they run (the tests are built by the
/// stable compiler as always). A test that runs cargo must remove it from cargo's
/// environment: build scripts see it, and proc-macro2's reruns when it changes, so every
/// crate above it is rebuilt (`build_sharing_tests`).
const REPORT_TIME: [&str; 3] = ["-Z", "unstable-options", "--report-time"];

/// One test executable, run where `cargo test` would run it.
#[derive(Debug, Clone)]
pub struct TestBinary {
    /// The target's name (`soak`, `manylights_cluster`, ...).
    pub name: String,
    /// An integration test (`tests/*.rs`), not a crate's unit tests.
    pub integration: bool,
    executable: PathBuf,
    /// The package's folder: cargo runs a test binary there.
    package_dir: PathBuf,
}

impl TestBinary {
    /// The command that runs it as `cargo test` would (in its package's folder).
    pub fn command(&self) -> Command {
        let mut command = Command::new(&self.executable);
        command
            .current_dir(&self.package_dir)
            .env("CARGO_MANIFEST_DIR", &self.package_dir);
        command
    }
}

/// `f` on every item, on `workers` threads (each item goes to the next free one); the
/// results in the items' order. `f` is told which worker runs it (0..workers).
pub fn in_parallel<T: Send, R: Send>(
    items: Vec<T>,
    workers: usize,
    f: impl Fn(usize, T) -> R + Sync,
) -> Vec<R> {
    let count = items.len();
    let queue = Mutex::new(items.into_iter().enumerate().collect::<VecDeque<_>>());
    let results = Mutex::new(Vec::with_capacity(count));
    std::thread::scope(|scope| {
        for worker in 0..workers.max(1) {
            let (queue, results, f) = (&queue, &results, &f);
            scope.spawn(move || {
                loop {
                    let next = queue.lock().unwrap_or_else(|e| e.into_inner()).pop_front();
                    let Some((index, item)) = next else { break };
                    let result = f(worker, item);
                    results
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push((index, result));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    results.sort_by_key(|(index, _)| *index);
    results.into_iter().map(|(_, result)| result).collect()
}

/// How many things to run at once: the machine's cores.
pub fn workers() -> usize {
    std::thread::available_parallelism().map_or(2, |n| n.get())
}

/// Builds every test target with `cargo test --no-run` and `build_args`, runs the binaries
/// in parallel with `test_args`, then the doctests. Fails listing the binaries that failed.
pub fn run(
    cargo: &str,
    profile: &[&str],
    build_args: &[String],
    test_args: &[String],
) -> anyhow::Result<()> {
    let binaries = build(cargo, profile, build_args)?;
    let workers = workers();
    let started = Instant::now();
    let failed = run_side_by_side(binaries, workers, test_args);
    println!(
        "xtask test: the test binaries ran in {} s, {workers} at a time",
        started.elapsed().as_secs()
    );
    // Doctests are compiled and run by rustdoc, one crate at a time.
    let doc = Command::new(cargo)
        .arg("test")
        .args(profile)
        .args(["--workspace", "--doc", "--no-fail-fast"])
        .args(build_args)
        .arg("--")
        .args(test_args)
        .status()
        .context("running the doctests")?;
    let mut failures = failed;
    if !doc.success() {
        failures.push("the doctests".to_string());
    }
    if !failures.is_empty() {
        bail!("failed: {} (output above)", failures.join(", "));
    }
    Ok(())
}

/// `cargo test --workspace --no-run`: the test executables, the slowest first.
pub fn build(
    cargo: &str,
    profile: &[&str],
    build_args: &[String],
) -> anyhow::Result<Vec<TestBinary>> {
    let output = Command::new(cargo)
        .arg("test")
        .args(profile)
        .args(["--workspace", "--no-run"])
        .arg("--message-format=json-render-diagnostics")
        .args(build_args)
        .stderr(std::process::Stdio::inherit())
        .output()
        .context("building the tests")?;
    if !output.status.success() {
        bail!("the tests did not build (errors above)");
    }
    let mut binaries = Vec::new();
    for line in String::from_utf8_lossy(&output.stdout).lines() {
        let Ok(message) = serde_json::from_str::<serde_json::Value>(line) else {
            continue;
        };
        let is_test =
            message["reason"] == "compiler-artifact" && message["profile"]["test"] == true;
        let integration = message["target"]["kind"]
            .as_array()
            .is_some_and(|kinds| kinds.iter().any(|kind| kind == "test"));
        let (Some(executable), Some(manifest), Some(name)) = (
            message["executable"].as_str(),
            message["manifest_path"].as_str(),
            message["target"]["name"].as_str(),
        ) else {
            continue;
        };
        if is_test {
            binaries.push(TestBinary {
                name: name.to_string(),
                integration,
                executable: executable.into(),
                package_dir: PathBuf::from(manifest)
                    .parent()
                    .context("a manifest has a folder")?
                    .to_path_buf(),
            });
        }
    }
    if binaries.is_empty() {
        bail!("cargo built no test binary");
    }
    let rank = |binary: &TestBinary| {
        SLOWEST_FIRST
            .iter()
            .position(|name| *name == binary.name)
            .unwrap_or(SLOWEST_FIRST.len())
    };
    binaries.sort_by_key(rank);
    Ok(binaries)
}

/// Runs `binaries` on `workers` threads, each printing a binary's whole output when it
/// ends; returns the names of those that failed.
fn run_side_by_side(
    binaries: Vec<TestBinary>,
    workers: usize,
    test_args: &[String],
) -> Vec<String> {
    // One binary's output at a time, whole.
    let print = Mutex::new(());
    let passed = in_parallel(binaries, workers, |_, binary| {
        let started = Instant::now();
        let output = binary
            .command()
            .args(REPORT_TIME)
            .env("RUSTC_BOOTSTRAP", "1")
            .args(test_args)
            .output();
        let seconds = started.elapsed().as_secs();
        let (passed, text) = match output {
            Ok(out) => (
                out.status.success(),
                format!(
                    "{}{}",
                    String::from_utf8_lossy(&out.stdout),
                    String::from_utf8_lossy(&out.stderr)
                ),
            ),
            Err(error) => (false, format!("could not run it: {error}\n")),
        };
        let verdict = if passed { "ok" } else { "FAILED" };
        let _printing = print.lock().unwrap_or_else(|e| e.into_inner());
        println!(
            "---- {} ({}): {verdict} in {seconds} s\n{text}",
            binary.name,
            binary.executable.display()
        );
        (binary.name, passed)
    });
    passed
        .into_iter()
        .filter(|(_, passed)| !passed)
        .map(|(name, _)| name)
        .collect()
}
