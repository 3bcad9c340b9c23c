//! `cargo xtask web`: the viewer built for the browser (wasm32 + WebGPU) into `target/web/`
//! (index.html, the JS glue, the wasm and the scenes it fetches; nothing from a CDN), and
//! `--serve` to serve it on localhost. Installs what it needs where it can:
//!
//! - a Rust standard library for wasm32: rustup cannot fetch one here, Debian's
//!   `rustc-web` (rustc 1.96) with `rust-web-src` (the standard library's source, built
//!   with `-Zbuild-std`) and `lld-22` (`wasm-ld`) can; the build sets `RUSTC` to that
//!   compiler only for itself, so native builds keep rustup's;
//! - the JS glue from `tools/wasm-glue` (the wasm-bindgen CLI's library at the lockfile's
//!   `wasm-bindgen` version, in a workspace of its own), built into `target/web-tools/`;
//! - `wasm-opt` (binaryen) and `playwright-core` from npm, into `web/node_modules/` (pinned
//!   by `web/package-lock.json`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context as _, bail};

/// Debian's rustc-web installs its compiler here (rustup's stays first on `PATH`).
const WEB_RUSTC: &str = "/usr/bin/rustc";
/// The linker for wasm32 (rustc's default, `rust-lld`, is not in Debian's packages).
const WASM_LINKER: &str = "wasm-ld-22";
/// The Debian packages the wasm32 build needs.
const WEB_PACKAGES: [&str; 3] = ["rustc-web", "rust-web-src", "lld-22"];
pub const TARGET: &str = "wasm32-unknown-unknown";
/// The scenes' folders the page fetches from (`LoadedScene::asset_files`), copied beside it.
const PAGE_ASSETS: [&str; 7] = [
    "sponza",
    "sponza-glass",
    "sponza-embers",
    "lamps",
    "spheres",
    "glass",
    "panel",
];

#[derive(Debug, Clone)]
pub struct WebOptions {
    /// Run wasm-opt (minutes on 2 cores; the tests skip it).
    pub wasm_opt: bool,
    /// The cargo profile: [`SHIPPED_PROFILE`] for the page people are given, or
    /// [`TESTED_PROFILE`] for the page's test.
    pub profile: &'static str,
}

/// The page as it is shipped: fat link-time optimisation across every crate, one codegen
/// unit (the smallest, fastest wasm; 8 of CI's minutes on 2 cores).
pub const SHIPPED_PROFILE: &str = "web";
/// The page as `cargo xtask web-test` builds it: the same code and panic strategy without
/// link-time optimisation and at optimisation level 1 (Cargo.toml has the times). The test
/// compares frames, which optimisation does not change: the GPU computes them, and Rust's
/// float arithmetic is the same at every level.
pub const TESTED_PROFILE: &str = "web-test";

/// The workspace's root.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// Where the page is built.
pub fn web_dir() -> PathBuf {
    workspace_root().join("target/web")
}

fn run(command: &mut Command, what: &str) -> anyhow::Result<()> {
    let status = command
        .status()
        .with_context(|| format!("running {what}"))?;
    if !status.success() {
        bail!("{what} failed ({status})");
    }
    Ok(())
}

fn command_works(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .output()
        .is_ok_and(|out| out.status.success())
}

/// Installs Debian packages when run as root, else fails with the command to run.
pub fn apt_install(packages: &[&str], why: &str) -> anyhow::Result<()> {
    let install = format!(
        "apt-get update && apt-get install -y --no-install-recommends {}",
        packages.join(" ")
    );
    if !crate::is_root() {
        bail!("{why} needs Debian packages. Install them with:\n    sudo sh -c '{install}'");
    }
    println!("installing {}: {install}", packages.join(", "));
    run(
        Command::new("sh")
            .arg("-c")
            .arg(format!("DEBIAN_FRONTEND=noninteractive {install}")),
        "apt-get",
    )
}

/// Debian's wasm32 standard library source, its compiler and wasm-ld.
fn ensure_web_toolchain() -> anyhow::Result<()> {
    let library = Path::new("/usr/lib/rustlib/src/rust/library/std");
    let ready = library.is_dir()
        && command_works(WEB_RUSTC, &["--version"])
        && command_works(WASM_LINKER, &["--version"]);
    if !ready {
        apt_install(
            &WEB_PACKAGES,
            "building for wasm32 (rustc-web, its std source, wasm-ld)",
        )?;
    }
    Ok(())
}

/// The version of `package` the lockfile `lock` pins.
#[cfg(test)]
fn locked_version(lock: &Path, package: &str) -> anyhow::Result<String> {
    let lock =
        std::fs::read_to_string(lock).with_context(|| format!("reading {}", lock.display()))?;
    let mut lines = lock.lines();
    let name = format!("name = \"{package}\"");
    while let Some(line) = lines.next() {
        if line == name
            && let Some(version) = lines.next().and_then(|v| v.strip_prefix("version = "))
        {
            return Ok(version.trim_matches('"').to_string());
        }
    }
    bail!("the lockfile has no {package}")
}

/// The page's JS glue and final wasm from the linked `wasm`: what `wasm-bindgen --target
/// web --no-typescript --out-dir out` writes, by `tools/wasm-glue` (built on first use;
/// its Cargo.toml says why it is not the CLI).
fn generate_bindings(wasm: &Path, out: &Path) -> anyhow::Result<()> {
    let root = workspace_root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let tools = root.join("target/web-tools");
    run(
        Command::new(cargo)
            .args(["build", "--release", "--locked", "--manifest-path"])
            .arg(root.join("tools/wasm-glue/Cargo.toml"))
            .arg("--target-dir")
            .arg(&tools),
        "building tools/wasm-glue",
    )?;
    run(
        Command::new(tools.join("release/wasm-glue"))
            .arg(wasm)
            .arg(out),
        "wasm-glue",
    )
}

/// `web/node_modules` (wasm-opt, playwright-core) as `web/package-lock.json` pins it.
pub fn ensure_npm_tools() -> anyhow::Result<PathBuf> {
    let web = workspace_root().join("web");
    let modules = web.join("node_modules");
    let ready = modules.join("playwright-core/package.json").is_file()
        && modules.join(".bin/wasm-opt").is_file();
    if !ready {
        if !command_works("npm", &["--version"]) {
            apt_install(&["nodejs", "npm"], "the page's tools (npm)")?;
        }
        run(
            Command::new("npm")
                .args(["ci", "--no-audit", "--no-fund"])
                .current_dir(&web),
            "npm ci in web/",
        )?;
    }
    Ok(modules)
}

/// Builds the page into `target/web/` and returns the folder.
pub fn build(options: &WebOptions) -> anyhow::Result<PathBuf> {
    ensure_web_toolchain()?;
    let node_modules = ensure_npm_tools()?;
    let root = workspace_root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let started = std::time::Instant::now();
    run(
        Command::new(&cargo)
            .current_dir(&root)
            .env("RUSTC", WEB_RUSTC)
            .env("RUSTC_BOOTSTRAP", "1")
            .env("RUSTFLAGS", "--cfg getrandom_backend=\"wasm_js\"")
            .env("CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER", WASM_LINKER)
            .env_remove("RUSTC_WRAPPER")
            .args([
                "build",
                "-p",
                "manylights-viewer",
                "--profile",
                options.profile,
            ])
            .args(["--target", TARGET, "-Zbuild-std=std,panic_abort"])
            .arg("--target-dir")
            .arg(root.join("target/wasm")),
        "the wasm32 build",
    )?;
    println!("built the wasm in {:.0} s", started.elapsed().as_secs_f64());
    let out = web_dir();
    if out.exists() {
        std::fs::remove_dir_all(&out).with_context(|| format!("clearing {}", out.display()))?;
    }
    std::fs::create_dir_all(&out)?;
    let wasm = root.join(format!(
        "target/wasm/{TARGET}/{}/manylights.wasm",
        options.profile
    ));
    generate_bindings(&wasm, &out)?;
    let bindgen_wasm = out.join("manylights_bg.wasm");
    if options.wasm_opt {
        let started = std::time::Instant::now();
        run(
            Command::new(node_modules.join(".bin/wasm-opt"))
                .args(["-O3", "--all-features", "--strip-debug", "-o"])
                .arg(&bindgen_wasm)
                .arg(&bindgen_wasm),
            "wasm-opt",
        )?;
        println!("wasm-opt took {:.0} s", started.elapsed().as_secs_f64());
    }
    std::fs::copy(root.join("web/index.html"), out.join("index.html"))?;
    for scene in PAGE_ASSETS {
        copy_scene(
            &root.join("assets").join(scene),
            &out.join("assets").join(scene),
        )?;
    }
    let raw = std::fs::metadata(&bindgen_wasm)?.len();
    let gzip = gzip_size(&bindgen_wasm).map_or("?".into(), |bytes| format!("{:.2}", mib(bytes)));
    println!(
        "wrote {} (wasm {:.2} MiB, {gzip} MiB gzipped)",
        out.display(),
        mib(raw)
    );
    Ok(out)
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / 1048576.0
}

fn gzip_size(file: &Path) -> Option<u64> {
    let out = Command::new("gzip").arg("-9c").arg(file).output().ok()?;
    out.status.success().then_some(out.stdout.len() as u64)
}

/// A scene's files the page can fetch: the text and image files of its folder (not the
/// compressed `.glb` variants, which the page does not open).
fn copy_scene(from: &Path, to: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from).with_context(|| format!("reading {}", from.display()))? {
        let path = entry?.path();
        let keep = path
            .extension()
            .is_some_and(|e| ["gltf", "bin", "jpg", "png", "md"].contains(&&*e.to_string_lossy()));
        if path.is_file() && keep {
            std::fs::copy(&path, to.join(path.file_name().unwrap_or_default()))?;
        }
    }
    Ok(())
}

/// Serves `dir` on localhost until stopped (Python's `http.server`: it serves `.wasm` and
/// `.gltf` with the right types).
pub fn serve(dir: &Path, port: u16) -> anyhow::Result<()> {
    println!(
        "serving {} at http://localhost:{port}/ (Ctrl-C stops)",
        dir.display()
    );
    run(
        Command::new("python3")
            .args([
                "-m",
                "http.server",
                &port.to_string(),
                "--bind",
                "127.0.0.1",
            ])
            .arg("--directory")
            .arg(dir),
        "python3 -m http.server",
    )
}

#[cfg(test)]
mod tests {
    /// The glue's generator reads the custom sections the `wasm-bindgen` macros write; its
    /// schema changes between versions, so the two must be the same release.
    #[test]
    fn the_glue_generator_is_the_locked_wasm_bindgen() {
        let root = super::workspace_root();
        let macros = super::locked_version(&root.join("Cargo.lock"), "wasm-bindgen")
            .expect("wasm-bindgen is locked");
        let generator = super::locked_version(
            &root.join("tools/wasm-glue/Cargo.lock"),
            "wasm-bindgen-cli-support",
        )
        .expect("the generator is locked");
        assert_eq!(
            generator, macros,
            "tools/wasm-glue/Cargo.toml pins wasm-bindgen-cli-support: set it to ={macros} and run cargo update there"
        );
    }
}
