//! `cargo xtask test`: the README's test command, everything that guards main, as CI runs
//! it (`.ci/run`). Each [`Step`] is one thing main must pass; the command runs them all in
//! order whatever fails, prints each step's time as it ends and a table at the end, lists
//! every failure, and exits non-zero if any step failed. Each step is also a command of
//! its own (the table's `alone` column), for running one part.
//!
//! The order puts the steps that reuse the release build first (the tests, the benches,
//! the examples, the mutants, the page's native frames), then the two that compile more:
//! the page's wasm (a second build of every dependency, for wasm32) and the lints and docs
//! (a check build of every dependency). The formatting check comes first: it takes a
//! second and fails most often.

use std::process::Command;
use std::time::Instant;

use anyhow::{Context as _, bail};

/// One part of the test command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// `cargo fmt --all --check`.
    Format,
    /// Every test binary and the doctests (`test_runner`).
    Tests,
    /// The criterion benches once each (criterion's test mode).
    Benches,
    /// The standalone examples of the reusable crates, checked with only their own
    /// crates' features, then run.
    Examples,
    /// The fast subset of the shader mutants (`mutants.rs`).
    Mutants,
    /// The page in headless Chromium against native frames (`web_test.rs`).
    Page,
    /// `cargo clippy --workspace --all-targets -- -D warnings`.
    Lints,
    /// `cargo doc --workspace --no-deps` with rustdoc's warnings as errors.
    Docs,
    /// `cargo package` of the library crates, each then built from its `.crate` alone.
    Package,
}

impl Step {
    /// Every step, in the order the test command runs them.
    pub const ALL: [Step; 9] = [
        Step::Format,
        Step::Tests,
        Step::Benches,
        Step::Examples,
        Step::Mutants,
        Step::Page,
        Step::Lints,
        Step::Docs,
        Step::Package,
    ];

    /// The name `--skip` takes and the table prints.
    pub fn name(self) -> &'static str {
        match self {
            Step::Format => "fmt",
            Step::Tests => "tests",
            Step::Benches => "benches",
            Step::Examples => "examples",
            Step::Mutants => "mutants",
            Step::Page => "page",
            Step::Lints => "clippy",
            Step::Docs => "doc",
            Step::Package => "package",
        }
    }

    /// The command that runs this step alone.
    pub fn alone(self) -> &'static str {
        match self {
            Step::Format => "cargo fmt --all --check",
            Step::Tests => "cargo xtask test --only tests",
            Step::Benches => "cargo xtask test --only benches",
            Step::Examples => "cargo xtask test --only examples",
            Step::Mutants => "cargo xtask mutants --fast",
            Step::Page => "cargo xtask web-test",
            Step::Lints => "cargo clippy --release --workspace --all-targets -- -D warnings",
            Step::Docs => "RUSTDOCFLAGS='-D warnings' cargo doc --release --workspace --no-deps",
            Step::Package => "cargo xtask test --only package",
        }
    }

    /// The step named `name`, or an error listing the names.
    pub fn named(name: &str) -> anyhow::Result<Step> {
        Step::ALL
            .into_iter()
            .find(|step| step.name() == name)
            .with_context(|| {
                let names: Vec<_> = Step::ALL.iter().map(|s| s.name()).collect();
                format!("no step named '{name}' (the steps: {})", names.join(", "))
            })
    }
}

/// What the test command was asked to run.
pub struct TestOptions {
    /// Steps left out (`--skip`, or every step but `--only`'s).
    pub skip: Vec<Step>,
    /// Arguments for building the tests; those after `--` go to every test binary.
    pub cargo_args: Vec<String>,
}

/// One step's result, for the final table.
struct StepResult {
    step: Step,
    seconds: u64,
    failure: Option<String>,
}

impl StepResult {
    fn verdict(&self) -> &'static str {
        if self.failure.is_some() {
            "FAILED"
        } else {
            "passed"
        }
    }
}

/// Runs every step not skipped, in [`Step::ALL`]'s order, whatever fails; fails listing
/// each failed step.
pub fn test(options: &TestOptions) -> anyhow::Result<()> {
    crate::ensure_test_packages()?;
    let whole = Instant::now();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut results = Vec::new();
    for step in Step::ALL {
        if options.skip.contains(&step) {
            continue;
        }
        println!("xtask test: step '{}' ({})", step.name(), step.alone());
        let started = Instant::now();
        let failure = run_step(step, &cargo, &options.cargo_args)
            .err()
            .map(|error| format!("{error:#}"));
        let result = StepResult {
            step,
            seconds: started.elapsed().as_secs(),
            failure,
        };
        println!(
            "xtask test: step '{}' {} in {} s",
            step.name(),
            result.verdict(),
            result.seconds
        );
        results.push(result);
    }
    print_table(&results, whole.elapsed().as_secs());
    let failures: Vec<String> = results
        .iter()
        .filter_map(|r| {
            r.failure
                .as_ref()
                .map(|why| format!("{} (`{}`): {why}", r.step.name(), r.step.alone()))
        })
        .collect();
    if !failures.is_empty() {
        bail!(
            "{} of {} step(s) failed:\n  {}",
            failures.len(),
            results.len(),
            failures.join("\n  ")
        );
    }
    let skipped: Vec<_> = options.skip.iter().map(|s| s.name()).collect();
    if skipped.is_empty() {
        println!("xtask test: every step passed");
    } else {
        println!(
            "xtask test: every step run passed (skipped: {})",
            skipped.join(", ")
        );
    }
    Ok(())
}

/// The steps' times and verdicts as a Markdown table (CI's log, and docs/testing.md's).
fn print_table(results: &[StepResult], total: u64) {
    println!("\nxtask test: steps\n\n| step | seconds | result |\n|---|---:|---|");
    for result in results {
        println!(
            "| {} | {} | {} |",
            result.step.name(),
            result.seconds,
            result.verdict()
        );
    }
    println!("| in all | {total} | |\n");
}

fn run_step(step: Step, cargo: &str, cargo_args: &[String]) -> anyhow::Result<()> {
    // Arguments after `--` go to the test binaries (a test name filters).
    let (build_args, test_args) = match cargo_args.iter().position(|a| a == "--") {
        Some(split) => (&cargo_args[..split], &cargo_args[split + 1..]),
        None => (cargo_args, &[][..]),
    };
    match step {
        Step::Format => cargo_command(cargo, &["fmt", "--all", "--check"], "unformatted files"),
        // Shader validation is not a step of its own: xtask's unit tests validate every
        // declared program (`every_declared_program_validates`), within the tests. The
        // test binaries run side by side (`test_runner` says why).
        Step::Tests => crate::test_runner::run(cargo, crate::TEST_PROFILE, build_args, test_args),
        // By name (`--bench '*'`): `--benches` also selects every library (`bench = true`
        // is their default) and ran their unit tests a second time, 80 s of CI's.
        Step::Benches => {
            let mut args = vec!["test"];
            args.extend(crate::TEST_PROFILE);
            args.extend(["--workspace", "--bench", "*", "--no-fail-fast"]);
            cargo_command(cargo, &args, "a bench failed (above)")
        }
        Step::Examples => standalone_examples(cargo),
        Step::Mutants => crate::mutants::mutants(true, None, None),
        Step::Page => crate::web_test::web_test(),
        // In the release profile, as the other builds: the dependencies' build scripts and
        // proc macros are the release build's (only the workspace's crates are linted,
        // and the dependencies are checked, not built).
        Step::Lints => {
            let mut args = vec!["clippy"];
            args.extend(crate::TEST_PROFILE);
            args.extend(["--workspace", "--all-targets", "--", "-D", "warnings"]);
            cargo_command(cargo, &args, "clippy warned (above)")
        }
        Step::Docs => {
            let mut command = Command::new(cargo);
            command
                .arg("doc")
                .args(crate::TEST_PROFILE)
                .args(["--workspace", "--no-deps"])
                .env("RUSTDOCFLAGS", "-D warnings");
            let status = command.status().context("running cargo doc")?;
            if !status.success() {
                bail!("rustdoc warned (above)");
            }
            Ok(())
        }
        // Every crate an engine may take, packaged together (each resolves the others from
        // the packages beside it) and built from its .crate alone: a file it embeds from
        // outside its folder, or a path dependency without a version, fails here.
        Step::Package => {
            forget_unpacked_workspace_packages()?;
            let mut args = vec!["package", "--workspace", "--allow-dirty"];
            for application in APPLICATIONS {
                args.extend(["--exclude", application]);
            }
            cargo_command(cargo, &args, "a library crate does not package (above)")
        }
    }
}

/// The workspace's packages that are not a library for others (`publish = false`).
const APPLICATIONS: [&str; 4] = [
    "manylights-lab",
    "manylights-viewer",
    "manylights-tests",
    "xtask",
];

/// Removes the sources cargo unpacked from an earlier `cargo package`'s local registry.
///
/// `cargo package --workspace` verifies each crate against the others' `.crate` files
/// through a temporary local registry, and cargo unpacks a registry's crate into
/// `$CARGO_HOME/registry/src/<registry>/<name>-<version>` once: a directory already there
/// is used as it is. Our packages keep version 0.1.0 while their code changes, so a clone
/// at a path packaged before would verify against the sources of that earlier run (CI
/// failed so, on a crate that had since gained serde derives). crates.io's sources live
/// under `index.*` registries and are kept.
fn forget_unpacked_workspace_packages() -> anyhow::Result<()> {
    let cargo_home = match std::env::var_os("CARGO_HOME") {
        Some(home) => std::path::PathBuf::from(home),
        None => home_dir()?.join(".cargo"),
    };
    let sources = cargo_home.join("registry").join("src");
    let Ok(registries) = std::fs::read_dir(&sources) else {
        return Ok(()); // nothing unpacked yet
    };
    for registry in registries {
        let registry = registry.with_context(|| format!("reading {}", sources.display()))?;
        let registry_name = registry.file_name().to_string_lossy().into_owned();
        let Ok(packages) = std::fs::read_dir(registry.path()) else {
            continue;
        };
        for package in packages {
            let package = package.with_context(|| format!("reading {registry_name}"))?;
            let package_name = package.file_name().to_string_lossy().into_owned();
            if is_unpacked_workspace_package(&registry_name, &package_name) {
                std::fs::remove_dir_all(package.path())
                    .with_context(|| format!("removing {}", package.path().display()))?;
            }
        }
    }
    Ok(())
}

/// Whether `package` (a `<name>-<version>` directory) under the registry directory
/// `registry` is one of ours unpacked from a local registry rather than from crates.io.
fn is_unpacked_workspace_package(registry: &str, package: &str) -> bool {
    !registry.starts_with("index.") && package.starts_with("manylights")
}

/// The user's home directory, from `HOME`.
fn home_dir() -> anyhow::Result<std::path::PathBuf> {
    std::env::var_os("HOME")
        .map(std::path::PathBuf::from)
        .context("neither CARGO_HOME nor HOME is set: cannot find cargo's registry")
}

/// `cargo <args>`, failing with `why` when it fails.
fn cargo_command(cargo: &str, args: &[&str], why: &str) -> anyhow::Result<()> {
    let status = Command::new(cargo)
        .args(args)
        .status()
        .with_context(|| format!("running cargo {}", args.join(" ")))?;
    if !status.success() {
        bail!("{why}");
    }
    Ok(())
}

/// The examples that use a reusable crate on its own, from a plain wgpu program: (package,
/// example, arguments).
const STANDALONE_EXAMPLES: [(&str, &str, &[&str]); 7] = [
    ("manylights-cluster", "standalone_clusters", &[]),
    ("manylights-lights", "standalone_lights", &[]),
    // The engine examples at the smallest size that shows their frame equals every
    // light's (`tests/in_your_engine.rs` compares them too); their default is 1280x720.
    (
        "manylights-cluster",
        "forward_plus_in_your_engine",
        SMALL_ENGINE_FRAME,
    ),
    (
        "manylights-cluster",
        "forward_plus_in_your_engine",
        SMALL_SHADOWED_ENGINE_FRAME,
    ),
    (
        "manylights-cluster",
        "deferred_in_your_engine",
        SMALL_ENGINE_FRAME,
    ),
    (
        "manylights-cluster",
        "deferred_in_your_engine",
        SMALL_PBR_ENGINE_FRAME,
    ),
    // Sponza read by the engine, with the lab's lights (how the examples are timed against
    // our renderer), at the smallest size that shows its frame equals every light's.
    (
        "manylights-cluster",
        "deferred_in_your_engine",
        SMALL_SPONZA_ENGINE_FRAME,
    ),
];

const SMALL_ENGINE_FRAME: &[&str] = &[
    "--size",
    "320x180",
    "--lights",
    "2000",
    "--check",
    "--out",
    "target/engine-example.png",
];
const SMALL_SHADOWED_ENGINE_FRAME: &[&str] = &[
    "--size",
    "320x180",
    "--lights",
    "2000",
    "--check",
    "--shadows",
    "--out",
    "target/engine-example.png",
];

const SMALL_SPONZA_ENGINE_FRAME: &[&str] = &[
    "--scene",
    "assets/sponza/sponza.gltf",
    "--size",
    "160x90",
    "--lights",
    "5000",
    "--check",
    "--brdf",
    "pbr",
    "--out",
    "target/engine-example.png",
];

const SMALL_PBR_ENGINE_FRAME: &[&str] = &[
    "--size",
    "320x180",
    "--lights",
    "2000",
    "--check",
    "--brdf",
    "pbr",
    "--out",
    "target/engine-example.png",
];

/// The standalone examples: checked with only the features these two crates turn on (one
/// `cargo check` of both: a feature a crate forgot to ask for fails to compile here, where
/// the workspace's other crates would have turned it on), then run as the test build built
/// them (`cargo test` builds every example).
fn standalone_examples(cargo: &str) -> anyhow::Result<()> {
    let mut check = Command::new(cargo);
    // In the release profile: its build scripts and proc macros are the release build's.
    check
        .args(["check", "--examples"])
        .args(crate::TEST_PROFILE);
    for (package, _, _) in STANDALONE_EXAMPLES {
        check.args(["-p", package]);
    }
    if !check.status().context("checking the examples")?.success() {
        bail!("the standalone examples do not build with their own crates' features");
    }
    // The tests' build builds every example (a no-op after the tests' step; `-p` here
    // would resolve other features and build the dependencies a second time).
    crate::test_runner::build(cargo, crate::TEST_PROFILE, &[])?;
    let examples = crate::web::workspace_root().join("target/release/examples");
    for (package, example, arguments) in STANDALONE_EXAMPLES {
        let status = Command::new(examples.join(example))
            .args(arguments)
            .current_dir(crate::web::workspace_root())
            .status()
            .with_context(|| format!("running {package}'s example {example}"))?;
        if !status.success() {
            bail!("{package}'s example {example} failed ({status})");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_our_packages_from_a_local_registry_are_forgotten() {
        let local = "-14cd1cce6819ff87";
        assert!(is_unpacked_workspace_package(
            local,
            "manylights-scene-0.1.0"
        ));
        assert!(!is_unpacked_workspace_package(local, "serde-1.0.229"));
        let crates_io = "index.crates.io-1949cf8c6b5b557f";
        assert!(!is_unpacked_workspace_package(
            crates_io,
            "manylights-scene-0.1.0"
        ));
        assert!(!is_unpacked_workspace_package(crates_io, "glam-0.30.0"));
    }

    #[test]
    fn every_step_has_a_unique_name_that_finds_it() {
        for step in Step::ALL {
            assert_eq!(Step::named(step.name()).unwrap(), step);
        }
        let error = Step::named("lint").unwrap_err().to_string();
        assert!(
            error.contains("clippy") && error.contains("page"),
            "{error}"
        );
    }

    /// The package step leaves out exactly the packages that may not be published: a new
    /// library crate is packaged, and a new application is named here.
    #[test]
    fn the_package_step_leaves_out_exactly_the_applications() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut manifests: Vec<_> = std::fs::read_dir(root.join("crates"))
            .expect("crates/")
            .map(|entry| entry.expect("entry").path().join("Cargo.toml"))
            .collect();
        manifests.extend([root.join("tests/Cargo.toml"), root.join("xtask/Cargo.toml")]);
        let mut unpublished = Vec::new();
        for manifest in manifests {
            let text = std::fs::read_to_string(&manifest).expect("a manifest");
            let name = text
                .lines()
                .find_map(|line| line.strip_prefix("name = \""))
                .and_then(|rest| rest.strip_suffix('"'))
                .expect("a package name");
            if text.lines().any(|line| line.starts_with("publish")) {
                unpublished.push(name.to_string());
            }
        }
        unpublished.sort();
        let mut applications = APPLICATIONS.map(String::from).to_vec();
        applications.sort();
        assert_eq!(unpublished, applications);
    }
}
