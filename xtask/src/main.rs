//! `cargo xtask <task>`: the project's own commands.
//!
//! - `validate-shaders`: composes every program of every crate that owns shaders, in every
//!   variant the crate declares (its `programs()`, each in every material variant it has),
//!   exactly as the renderer does, and validates it with naga; errors name the file and
//!   line; exits non-zero on any failure. This file lists the crates, never their programs.
//! - `test [--skip STEP | --only STEP]`: the README's test command, everything that guards
//!   main (`test_command.rs`): formatting, every test of the workspace (shader validation
//!   among them) and the doctests, the benches once, the standalone examples, the fast
//!   shader mutants, the page's test, clippy and rustdoc, each step's time and a table.
//!   Makes sure a Vulkan driver exists (installs Mesa's lavapipe and Xvfb when run as root
//!   on Debian/Ubuntu, else prints the command).
//! - `web [--serve]`: the viewer built for the browser into `target/web/` (see `web.rs`).
//! - `web-test`: the page's frames in headless Chromium against native ones (`web_test.rs`).
//! - `limits`: what each program needs of a WebGPU adapter, written to
//!   docs/webgpu-limits.md (`limits.rs`).
//! - `fuzz --seconds N`: runs the cargo-fuzz targets of `fuzz/` (see `fuzz.rs`).
//! - `mutants [--fast] [--report FILE] [--only TEXT]`: shader mutation testing (see `mutants.rs`).

mod fuzz;
mod limits;
mod mutants;
mod test_command;
mod test_runner;
mod web;
mod web_test;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{Context as _, bail};
use clap::{Parser, Subcommand};
use manylights_gpu::{Program, ShaderLibrary, ShaderModules};

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
        /// (every crate's `shaders/` folder merged: `cluster/assign.wgsl`, ...).
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
        /// Only the fast subset (run before a change to the shaders or the tests lands).
        #[arg(long)]
        fast: bool,
        /// Write the results as a Markdown table here.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Only the mutants whose name contains this text.
        #[arg(long)]
        only: Option<String>,
    },
    /// Build the viewer for the browser (wasm32 + WebGPU) into target/web/, installing the
    /// toolchain it needs; `--serve` then serves it on localhost.
    Web {
        /// Serve the page on localhost after building it.
        #[arg(long)]
        serve: bool,
        #[arg(long, default_value_t = 8000)]
        port: u16,
        /// Skip wasm-opt (minutes on 2 cores; about a third smaller wasm).
        #[arg(long)]
        no_wasm_opt: bool,
    },
    /// What each program's entry points need of a WebGPU adapter (a Markdown table; fails
    /// if one is over the limits every adapter guarantees).
    Limits,
    /// Build the page and compare its frames in headless Chromium with native renders.
    WebTest,
    /// Everything that guards main, as CI runs it: formatting, every test binary and the
    /// doctests, the benches once, the standalone examples, the fast shader mutants, the
    /// page in headless Chromium, clippy and rustdoc with warnings as errors. Installs
    /// lavapipe and Xvfb if needed (as root). Every step runs whatever fails.
    Test {
        /// Leave out this step (fmt, tests, benches, examples, mutants, page, clippy, doc);
        /// may be repeated.
        #[arg(long, value_parser = test_command::Step::named)]
        skip: Vec<test_command::Step>,
        /// Run only this step (may be repeated).
        #[arg(long, value_parser = test_command::Step::named, conflicts_with = "skip")]
        only: Vec<test_command::Step>,
        /// Extra arguments for building the tests (`cargo test --no-run`); those after `--`
        /// go to every test binary (a test name filters).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        cargo_args: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.task {
        Task::ValidateShaders { shaders_dir } => validate_shaders(shaders_dir.as_deref()),
        Task::Test {
            skip,
            only,
            cargo_args,
        } => {
            let skip = if only.is_empty() {
                skip
            } else {
                test_command::Step::ALL
                    .into_iter()
                    .filter(|step| !only.contains(step))
                    .collect()
            };
            test_command::test(&test_command::TestOptions { skip, cargo_args })
        }
        Task::WebTest => web_test::web_test(),
        Task::Limits => limits::limits(&shader_catalogues()),
        Task::Web {
            serve,
            port,
            no_wasm_opt,
        } => web::build(&web::WebOptions {
            wasm_opt: !no_wasm_opt,
            profile: web::SHIPPED_PROFILE,
        })
        .and_then(|dir| {
            if serve {
                web::serve(&dir, port)
            } else {
                Ok(())
            }
        }),
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

/// Every crate that owns shaders: its module set and its declared programs. A new crate
/// with shaders adds a line here; a program or variant added to a crate adds none.
fn shader_catalogues() -> Vec<(&'static ShaderModules, Vec<Program>)> {
    vec![
        (
            &manylights_gpu::shaders::SHADERS,
            manylights_gpu::programs(),
        ),
        (&manylights_lights::SHADERS, manylights_lights::programs()),
        (
            &manylights_visibility::SHADERS,
            manylights_visibility::programs(),
        ),
        (&manylights_cluster::SHADERS, manylights_cluster::programs()),
        (&manylights_naive::SHADERS, manylights_naive::programs()),
        (
            &manylights_forward_plus::SHADERS,
            manylights_forward_plus::programs(),
        ),
        (
            &manylights_deferred::SHADERS,
            manylights_deferred::programs(),
        ),
    ]
}

/// The `shaders/` folder of the crate that owns `modules` (`forward_plus` is
/// `crates/forward-plus`).
fn shader_folder(modules: &ShaderModules) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../crates")
        .join(modules.owner.replace('_', "-"))
        .join("shaders")
}

/// Copies every crate's `shaders/` folder into `into`, one tree with the layout a
/// [`ShaderLibrary::Directory`] reads (each crate's files lie under its own subfolders, so
/// no two collide).
fn merge_shader_folders(into: &Path) -> anyhow::Result<()> {
    for (modules, _) in shader_catalogues() {
        mutants::copy_dir(&shader_folder(modules), into)?;
    }
    Ok(())
}

/// Composes and validates every program of the catalogues in every variant; prints one
/// line per module and returns how many there were and how many failed.
fn validate_programs(
    library: &ShaderLibrary,
    catalogues: &[(&'static ShaderModules, Vec<Program>)],
) -> (usize, usize) {
    let (mut total, mut failures) = (0, 0);
    for (modules, programs) in catalogues {
        for result in library.validate_all(programs) {
            total += 1;
            match result {
                Ok(name) => println!("ok      {}: {name}", modules.owner),
                Err(error) => {
                    failures += 1;
                    eprintln!("FAILED  {}: {error}", modules.owner);
                }
            }
        }
    }
    (total, failures)
}

fn validate_shaders(dir: Option<&Path>) -> anyhow::Result<()> {
    let library = match dir {
        Some(dir) => ShaderLibrary::Directory(dir.to_path_buf()),
        None => ShaderLibrary::Embedded,
    };
    let (total, failures) = validate_programs(&library, &shader_catalogues());
    if failures > 0 {
        bail!("{failures} of {total} shader modules failed validation");
    }
    println!("all {total} shader modules valid");
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
pub(crate) fn ensure_test_packages() -> anyhow::Result<()> {
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

/// The profile every test build uses: the release profile of the README's first command
/// (`cargo run --release`), so the tests, the benches, xtask itself (`cargo xtask` runs it
/// with `--release`), the page's native frames and the mutants share one build of the
/// dependencies instead of compiling wgpu and naga a second time for the test profile.
pub const TEST_PROFILE: &[&str] = &["--release"];

/// Every file under `dir` (recursively) whose name ends in `.extension` (the tests' walks
/// over `shaders/` and the sources).
#[cfg(test)]
fn files_with_extension(dir: &Path, extension: &str) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for path in entries.flatten().map(|entry| entry.path()) {
        if path.is_dir() {
            out.extend(files_with_extension(&path, extension));
        } else if path.extension().is_some_and(|e| e == extension) {
            out.push(path);
        }
    }
    out
}

#[cfg(test)]
mod shader_tests {
    use super::*;

    /// Every WGSL file in a crate's `shaders/` folder is embedded by that crate, under its
    /// own subfolder (the foundation's `common/` beside `gpu/`), and no WGSL lives outside
    /// the crates (a packaged crate could not build it).
    #[test]
    fn every_shader_file_has_one_owning_crate() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        assert!(
            !root.join("shaders").exists(),
            "WGSL belongs in its crate's shaders/"
        );
        let mut on_disk = Vec::new();
        for (modules, _) in shader_catalogues() {
            let folder = shader_folder(modules);
            on_disk.extend(files_with_extension(&folder, "wgsl").iter().map(|path| {
                let relative = path.strip_prefix(&folder).expect("under shaders/");
                relative.to_string_lossy().replace('\\', "/")
            }));
        }
        on_disk.sort();
        // Each crate's module set, and the sets of its own a pass keeps for its program
        // (automatic exposure's), each once.
        let mut sets: Vec<&'static ShaderModules> = Vec::new();
        for (modules, programs) in shader_catalogues() {
            for set in std::iter::once(modules).chain(programs.iter().map(|p| p.modules)) {
                if !sets.iter().any(|seen| std::ptr::eq(*seen, set)) {
                    sets.push(set);
                }
            }
        }
        let mut embedded = Vec::new();
        for modules in sets {
            for file in modules.files {
                let folder = file.path.split('/').next().unwrap_or_default();
                let owned =
                    folder == modules.owner || (modules.owner == "gpu" && folder == "common");
                assert!(
                    owned,
                    "{} embeds {}, outside its folder",
                    modules.owner, file.path
                );
                embedded.push(file.path.to_string());
            }
        }
        embedded.sort();
        assert_eq!(embedded, on_disk);
    }

    #[test]
    fn every_declared_program_validates() {
        let catalogues = shader_catalogues();
        let expected: usize = catalogues
            .iter()
            .flat_map(|(_, programs)| programs.iter().map(|p| p.variants().len()))
            .sum();
        assert_eq!(
            validate_programs(&ShaderLibrary::Embedded, &catalogues),
            (expected, 0)
        );
    }

    /// What xtask validates is what the crates declare: a variant added to a crate's list
    /// (here a G-buffer pass declared without its layout, which cannot compose) is
    /// validated, and fails, with no change to this file.
    #[test]
    fn a_variant_a_crate_adds_is_validated_without_touching_xtask() {
        let mut catalogues = shader_catalogues();
        // What validating them would count, without validating them twice.
        let before: usize = catalogues
            .iter()
            .flat_map(|(_, programs)| programs)
            .map(|program| program.variants().len())
            .sum();
        let deferred = catalogues
            .iter_mut()
            .find(|(modules, _)| modules.owner == "deferred")
            .expect("the deferred crate's catalogue");
        deferred.1.push(Program::shading_materials(
            "gbuffer_without_a_layout",
            &manylights_deferred::SHADERS,
            "deferred/gbuffer.wgsl",
        ));
        let variants = deferred
            .1
            .last()
            .expect("the added program")
            .variants()
            .len();
        let (after, failures) = validate_programs(&ShaderLibrary::Embedded, &catalogues);
        assert_eq!(
            variants, 16,
            "base colour, normal map, alpha mask, emission: on or off (a Blinn-Phong program \
             reads no metallic-roughness texture)"
        );
        assert_eq!(after, before + variants, "one per material variant");
        assert_eq!(failures, variants);
    }

    /// docs/webgpu-limits.md is what `cargo xtask limits` writes from the code as it is,
    /// and every program fits the limits every WebGPU adapter guarantees.
    #[test]
    fn the_limits_doc_matches_the_programs() {
        let (doc, over) = limits::limits_doc(&shader_catalogues()).expect("the table");
        assert!(over.is_empty(), "over WebGPU's guaranteed limits: {over:?}");
        let path = web::workspace_root().join(limits::LIMITS_DOC);
        let written = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            written == doc,
            "{} is not what the programs need now: run `cargo xtask limits`",
            path.display()
        );
    }
}

#[cfg(test)]
mod contract_tests {
    use std::path::{Path, PathBuf};

    use super::files_with_extension;

    /// `Pod` structs that mirror no WGSL struct, and why they need no layout test.
    const NOT_MIRRORED: &[(&str, &str)] = &[
        (
            "CameraBlock",
            "the engine examples' own camera, mirrored in their own WGSL (engine::ENGINE_WGSL), not in shaders/: tests/in_your_engine.rs's frames read it",
        ),
        (
            "GpuVertex",
            "a vertex buffer: its attribute offsets are taken from the struct (GpuVertex::attributes, offset_of!)",
        ),
        (
            "BvhNode",
            "RGBA32F texels, not a WGSL struct: visibility's texel_layout_tests hold each field to its texel",
        ),
        (
            "BvhTriangle",
            "RGBA32F texels, not a WGSL struct: visibility's texel_layout_tests hold each field to its texel",
        ),
        (
            "MaskRect",
            "an element of BvhParams.mask_rects (array<vec4<u32>>), checked through BvhUniform's layout test",
        ),
    ];

    /// Every `Pod` struct in the workspace (the types the CPU writes to or reads from GPU
    /// buffers) has an `assert_wgsl_layout!` test comparing it with the WGSL struct it
    /// mirrors, or is listed in `NOT_MIRRORED` with the reason.
    #[test]
    fn every_gpu_struct_has_a_layout_test() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut files = files_with_extension(&root.join("crates"), "rs");
        files.extend(files_with_extension(&root.join("tests"), "rs"));
        let sources: Vec<(PathBuf, String)> = files
            .into_iter()
            .map(|path| {
                let text = std::fs::read_to_string(&path).expect("read source");
                (path, text)
            })
            .collect();
        let mut pod_structs = Vec::new();
        for (path, text) in &sources {
            let lines: Vec<&str> = text.lines().collect();
            for (i, line) in lines.iter().enumerate() {
                if !(line.contains("#[derive(") && line.contains("Pod")) {
                    continue;
                }
                let name = lines[i + 1..]
                    .iter()
                    .find_map(|l| l.split("struct ").nth(1))
                    .and_then(|rest| rest.split([' ', '{', '(', '<']).next())
                    .expect("a struct after a Pod derive");
                pod_structs.push((name.to_string(), path.clone()));
            }
        }
        assert!(
            pod_structs.len() >= 10,
            "the scan found only {} Pod structs: is it looking in the right place?",
            pod_structs.len()
        );
        let checked = |name: &str| {
            sources.iter().any(|(_, text)| {
                text.split("assert_wgsl_layout!(")
                    .skip(1)
                    .any(|call| call.contains(&format!("== {name} {{")))
            })
        };
        let unchecked: Vec<String> = pod_structs
            .iter()
            .filter(|(name, _)| !checked(name) && !NOT_MIRRORED.iter().any(|(n, _)| n == name))
            .map(|(name, path)| format!("{name} ({})", path.display()))
            .collect();
        assert!(
            unchecked.is_empty(),
            "Pod structs without an assert_wgsl_layout! test beside them: {unchecked:?}"
        );
        for (name, _) in NOT_MIRRORED {
            assert!(
                pod_structs.iter().any(|(found, _)| found == name),
                "NOT_MIRRORED lists {name}, which is no longer a Pod struct"
            );
        }
    }

    /// ARCHITECTURE.md's frame walk names, quoted, every pass the GPU timer can report
    /// (each `PassName::new` of the library and pipeline crates; the engine examples'
    /// own passes are theirs), so a reader of the walk can find every line of a frame's
    /// timings in it.
    #[test]
    fn the_frame_walk_names_every_timed_pass() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let architecture =
            std::fs::read_to_string(root.join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
        let walk = architecture
            .split("## A frame, step by step")
            .nth(1)
            .and_then(|rest| rest.split("\n## ").next())
            .expect("ARCHITECTURE.md has its frame walk");
        let mut names = Vec::new();
        for path in files_with_extension(&root.join("crates"), "rs") {
            let text = std::fs::read_to_string(&path).expect("read source");
            for call in text.split("PassName::new(\"").skip(1) {
                let name = call.split('"').next().expect("a quoted name");
                if !name.starts_with("engine: ") && !names.contains(&name.to_string()) {
                    names.push(name.to_string());
                }
            }
        }
        assert!(names.len() >= 30, "found only {} pass names", names.len());
        // A name may break across the walk's lines.
        let walk = walk.split_whitespace().collect::<Vec<_>>().join(" ");
        let missing: Vec<&String> = names
            .iter()
            .filter(|name| !walk.contains(&format!("`{name}`")))
            .collect();
        assert!(
            missing.is_empty(),
            "the frame walk does not name {missing:?}"
        );
    }

    /// Every Rust constant a module set hands its WGSL (`ShaderModules::constants`) is
    /// read there as `#NAME` (a constant nobody reads is a copy waiting to drift), and no
    /// WGSL file of the workspace writes a Rust constant's value out as a literal `const`
    /// of the same name.
    #[test]
    fn every_shader_constant_is_read_and_never_copied() {
        for (modules, _) in super::shader_catalogues() {
            for (name, _) in (modules.constants)() {
                let token = format!("#{name}");
                let readers: Vec<&str> = (modules.files.iter())
                    .filter(|file| {
                        file.source.match_indices(&token).any(|(at, _)| {
                            let rest = &file.source[at + token.len()..];
                            !rest.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_')
                        })
                    })
                    .map(|file| file.path)
                    .collect();
                assert!(
                    !readers.is_empty(),
                    "{}: constant {name} is handed to the WGSL but no file of the set reads #{name}",
                    modules.owner
                );
            }
        }
        for (modules, _) in super::shader_catalogues() {
            let names: Vec<String> = super::shader_catalogues()
                .iter()
                .flat_map(|(set, _)| (set.constants)())
                .map(|(name, _)| name)
                .collect();
            for file in modules.files {
                for line in file.source.lines() {
                    let Some(rest) = line.trim_start().strip_prefix("const ") else {
                        continue;
                    };
                    let name = rest.split([':', ' ']).next().unwrap_or_default();
                    assert!(
                        !names.iter().any(|constant| constant == name) || line.contains('#'),
                        "shaders/{}: `{}` copies a Rust constant; read #{name} instead",
                        file.path,
                        line.trim()
                    );
                }
            }
        }
    }
}

/// CI builds the workspace's dependencies once: `cargo run --release` (the default
/// members), then xtask (`cargo xtask` builds it alone) and the tests (`--workspace` with
/// dev-dependencies) reuse those artifacts only where cargo resolved every shared package
/// with the same features. One feature more on a low crate (memchr's `default`, asked by
/// xtask's own manifest) rebuilt every workspace crate twice: 160 s for xtask and as much
/// for the tests on the 2-core machine (docs/testing.md).
#[cfg(test)]
mod build_sharing_tests {
    use std::collections::{BTreeMap, BTreeSet};
    use std::process::Command;

    /// Each library's artifact hashes (in the files' names: the hash of everything that
    /// built them: features, profile, dependencies) as `cargo <args>` builds them (no work
    /// where they are built already, as in CI, where this runs after those builds).
    fn library_artifacts(args: &[&str]) -> BTreeMap<String, BTreeSet<String>> {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let output = Command::new(cargo)
            .current_dir(crate::web::workspace_root())
            // The test runner sets RUSTC_BOOTSTRAP for libtest's --report-time; cargo would
            // hand it to the build scripts, and proc-macro2's reruns when it changes: every
            // crate above it rebuilt (a whole release build inside CI's test run, b381bca).
            .env_remove("RUSTC_BOOTSTRAP")
            .args(args)
            .args(["--release", "--locked", "--message-format=json"])
            .output()
            .expect("cargo runs");
        assert!(
            output.status.success(),
            "cargo {args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        let mut artifacts = BTreeMap::new();
        for line in String::from_utf8_lossy(&output.stdout).lines() {
            let Ok(message) = serde_json::from_str::<serde_json::Value>(line) else {
                continue;
            };
            let is_library = message["target"]["kind"]
                .as_array()
                .is_some_and(|kinds| kinds.iter().any(|k| k == "lib" || k == "rlib"));
            if message["reason"] != "compiler-artifact"
                || message["profile"]["test"] == true
                || !is_library
            {
                continue;
            }
            // The hash in the files' names (`deps/libmemchr-<hash>.rmeta`; a package the
            // command names is also copied up to `target/release/` without it).
            let hashes = message["filenames"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|file| file.as_str()?.rsplit_once('-'))
                .map(|(_, hash)| hash.split('.').next().unwrap_or(hash).to_string())
                .collect::<BTreeSet<String>>();
            let package = message["package_id"]
                .as_str()
                .unwrap_or_default()
                .to_string();
            // A package built for the host too (for a build script or macro) has two.
            artifacts
                .entry(package)
                .or_insert_with(BTreeSet::new)
                .extend(hashes);
        }
        artifacts
    }

    #[test]
    fn xtask_and_the_tests_reuse_the_release_builds_libraries() {
        let release = library_artifacts(&["build"]);
        assert!(release.len() > 50, "{} libraries", release.len());
        for (what, args) in [
            ("xtask", &["build", "--package", "xtask"][..]),
            ("the tests", &["test", "--workspace", "--no-run"][..]),
        ] {
            let rebuilt: Vec<String> = library_artifacts(args)
                .into_iter()
                .filter(|(package, hashes)| {
                    release.get(package).is_some_and(|r| !hashes.is_subset(r))
                })
                .map(|(package, _)| package)
                .collect();
            assert!(
                rebuilt.is_empty(),
                "{what} build these libraries again, with other features than `cargo run --release` (a dependency's feature differs; compare `cargo tree -e features`): {rebuilt:?}"
            );
        }
    }
}
