//! `cargo xtask <task>`: the project's own commands.
//!
//! - `validate-shaders`: composes every WGSL module exactly as the renderer does
//!   (`ShaderLibrary::all_compositions`) and validates it with naga; errors name
//!   `shaders/<file>:<line>`; exits non-zero on any failure.
//! - `test`: the README's test command. Makes sure a Vulkan driver exists (installs Mesa's
//!   lavapipe and Xvfb when run as root on Debian/Ubuntu, else prints the command), validates the
//!   shaders, then runs every test of the workspace.
//! - `fuzz --seconds N`: runs the cargo-fuzz targets of `fuzz/` (see `fuzz.rs`).
//! - `mutants [--fast] [--report FILE] [--only TEXT]`: shader mutation testing (see `mutants.rs`).

mod fuzz;
mod mutants;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{Context as _, bail};
use clap::{Parser, Subcommand};
use manylights_gpu::ShaderLibrary;

#[derive(Parser)]
#[command(about = "manylights project tasks")]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Validate every composed WGSL module with naga.
    ValidateShaders {
        /// Read the WGSL from this folder instead of the copies built into the binary
        /// (same file layout as `shaders/`).
        #[arg(long)]
        shaders_dir: Option<PathBuf>,
    },
    /// Run the cargo-fuzz targets (needs a nightly toolchain and cargo-fuzz).
    Fuzz {
        /// Seconds each target runs.
        #[arg(long, default_value_t = 60)]
        seconds: u64,
        /// Targets to run (gltf_json, glb, obj_mtl); all when none is given.
        #[arg(long = "target")]
        targets: Vec<String>,
        /// Run the targets at the same time instead of one after another.
        #[arg(long)]
        parallel: bool,
        /// Largest input generated, in bytes.
        #[arg(long, default_value_t = 65536)]
        max_len: usize,
    },
    /// Shader mutation testing: apply each mutant of the catalogue to a copy of shaders/
    /// and run its tests against it; fails when one survives.
    Mutants {
        /// Only the fast subset (what `cargo xtask test` runs).
        #[arg(long)]
        fast: bool,
        /// Write the results as a Markdown table here.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Only the mutants whose name contains this text.
        #[arg(long)]
        only: Option<String>,
    },
    /// Install lavapipe and Xvfb if needed (as root), validate shaders, run all tests and
    /// the fast subset of the shader mutants.
    Test {
        /// Extra arguments passed to `cargo test`.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        cargo_args: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.task {
        Task::ValidateShaders { shaders_dir } => validate_shaders(shaders_dir.as_deref()),
        Task::Test { cargo_args } => test(&cargo_args),
        Task::Mutants { fast, report, only } => {
            mutants::mutants(fast, report.as_deref(), only.as_deref())
        }
        Task::Fuzz {
            seconds,
            targets,
            parallel,
            max_len,
        } => fuzz::fuzz(&fuzz::FuzzOptions {
            seconds,
            targets,
            parallel,
            max_len,
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

fn validate_shaders(dir: Option<&Path>) -> anyhow::Result<()> {
    let library = match dir {
        Some(dir) => ShaderLibrary::Directory(dir.to_path_buf()),
        None => ShaderLibrary::Embedded,
    };
    let mut failures = 0;
    let compositions = ShaderLibrary::all_compositions();
    for (program, variant) in &compositions {
        let result = library
            .compose(*program, *variant)
            .and_then(|shader| ShaderLibrary::validate(&shader).map(|_| shader.name));
        match result {
            Ok(name) => println!("ok      {name}"),
            Err(error) => {
                failures += 1;
                eprintln!("FAILED  {error}");
            }
        }
    }
    if failures > 0 {
        bail!(
            "{failures} of {} shader modules failed validation",
            compositions.len()
        );
    }
    println!("all {} shader modules valid", compositions.len());
    Ok(())
}

/// Where Vulkan ICD manifests live on Linux.
const ICD_DIRS: [&str; 2] = ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d"];
/// Mesa's lavapipe (Vulkan on the CPU) and the X server the viewer tests run under.
const TEST_PACKAGES: [&str; 3] = ["mesa-vulkan-drivers", "libvulkan1", "xvfb"];

fn vulkan_available() -> bool {
    let has_icd = ICD_DIRS.iter().any(|dir| {
        std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .flatten()
                    .any(|e| e.path().extension().is_some_and(|x| x == "json"))
            })
            .unwrap_or(false)
    });
    let has_loader = Command::new("ldconfig")
        .arg("-p")
        .output()
        .map(|out| String::from_utf8_lossy(&out.stdout).contains("libvulkan.so.1"))
        .unwrap_or(false);
    has_icd && has_loader
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|out| String::from_utf8_lossy(&out.stdout).trim() == "0")
        .unwrap_or(false)
}

fn xvfb_available() -> bool {
    Command::new("sh")
        .args(["-c", "command -v xvfb-run"])
        .output()
        .map(|out| out.status.success())
        .unwrap_or(false)
}

/// Lavapipe (or any Vulkan driver) and Xvfb: installed when run as root, else the command
/// to run is printed.
fn ensure_test_packages() -> anyhow::Result<()> {
    if vulkan_available() && xvfb_available() {
        return Ok(());
    }
    let install = format!(
        "apt-get update && apt-get install -y {}",
        TEST_PACKAGES.join(" ")
    );
    if !is_root() {
        bail!(
            "no Vulkan driver or no xvfb-run found. Install Mesa's lavapipe (Vulkan on the CPU) and Xvfb with:\n    sudo sh -c '{install}'\nthen run `cargo xtask test` again"
        );
    }
    println!("installing lavapipe and Xvfb: {install}");
    let status = Command::new("sh")
        .arg("-c")
        .arg(format!("DEBIAN_FRONTEND=noninteractive {install}"))
        .status()
        .context("running apt-get")?;
    if !status.success() || !vulkan_available() || !xvfb_available() {
        bail!("installing the test packages failed; run `{install}` by hand");
    }
    Ok(())
}

fn test(cargo_args: &[String]) -> anyhow::Result<()> {
    ensure_test_packages()?;
    let mut failures = Vec::new();
    if let Err(error) = validate_shaders(None) {
        failures.push(format!("shader validation: {error:#}"));
    }
    // `--no-fail-fast`: one red test binary must not hide the others; every failure is
    // listed at the end.
    let runs: [(&str, &[&str]); 2] = [
        (
            "cargo test --workspace",
            &["test", "--workspace", "--no-fail-fast"],
        ),
        // The criterion benches once each, as a smoke test (criterion's test mode).
        (
            "cargo test --workspace --benches",
            &["test", "--workspace", "--benches", "--no-fail-fast"],
        ),
    ];
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    for (name, args) in runs {
        let status = Command::new(&cargo)
            .args(args)
            .args(cargo_args)
            .status()
            .with_context(|| format!("running {name}"))?;
        if !status.success() {
            failures.push(format!(
                "{name} failed (the failing tests are listed above)"
            ));
        }
    }
    // The fast subset of the shader mutants: each must fail its tests.
    if let Err(error) = mutants::mutants(true, None, None) {
        failures.push(format!("shader mutants: {error:#}"));
    }
    if !failures.is_empty() {
        bail!(
            "{} step(s) failed:\n  {}",
            failures.len(),
            failures.join("\n  ")
        );
    }
    println!("xtask test: shaders valid, all tests passed, every fast shader mutant killed");
    Ok(())
}
