//! `manylights`: the interactive viewer (the default when a display is available) and the
//! headless `render` command. All rendering lives in the `manylights` facade; this binary
//! owns the window, input and UI.

mod app;
mod camera_controller;
mod script;
mod ui;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use manylights_lab::cli::RenderArgs;
use stats_alloc::{INSTRUMENTED_SYSTEM, StatsAlloc};

/// Counts live heap bytes for `manylights soak` (a few atomic adds per allocation).
#[global_allocator]
static GLOBAL: &StatsAlloc<std::alloc::System> = &INSTRUMENTED_SYSTEM;

fn live_heap_bytes() -> u64 {
    manylights_lab::soak::live_heap_bytes(GLOBAL.stats())
}

#[derive(Parser)]
#[command(name = "manylights", version, about = "A many-light renderer and lab")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render one frame headless and write it as a PNG.
    Render(RenderArgs),
    /// Open the interactive viewer (the default when a display is available).
    View(ViewArgs),
    /// Run a benchmark matrix: GPU time per pass and error against the reference for
    /// every configuration; writes bench.json, REPORT.md and SVG charts.
    Bench(manylights_lab::cli::BenchArgs),
    /// Render many frames headless while changing settings; fail if resident memory or
    /// GPU allocations grow.
    Soak(manylights_lab::cli::SoakArgs),
}

/// The viewer's options: every frame setting of `render` (as the starting state), plus
/// scripting for unattended runs.
#[derive(Args, Clone, Debug, Default)]
pub struct ViewArgs {
    #[command(flatten)]
    pub frame: RenderArgs,
    /// Write the rendered image (without the UI) here after the last frame (with --frames).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Settings to change at given frames, e.g. "10:pipeline=forward-plus;20:pipeline=deferred".
    /// Keys: pipeline, lights, gbuffer, lighting, debug-view, paused, lose-device.
    #[arg(long)]
    pub script: Option<String>,
    /// Start with the animation paused (time stays at --time).
    #[arg(long)]
    pub paused: bool,
    /// Present without waiting for vertical sync.
    #[arg(long)]
    pub no_vsync: bool,
}

/// Whether a window can be opened (X11 or Wayland).
fn has_display() -> bool {
    std::env::var_os("DISPLAY").is_some() || std::env::var_os("WAYLAND_DISPLAY").is_some()
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let result = match Cli::parse().command {
        Some(Command::Render(args)) => manylights_lab::cli::render(&args),
        Some(Command::View(args)) => app::run(args),
        Some(Command::Bench(args)) => manylights_lab::cli::bench(&args),
        Some(Command::Soak(args)) => manylights_lab::cli::soak(&args, Some(live_heap_bytes)),
        None if has_display() => app::run(ViewArgs::default()),
        None => {
            println!(
                "no display found (DISPLAY/WAYLAND_DISPLAY unset): rendering the default scene headless (see `manylights --help`)"
            );
            manylights_lab::cli::render(&RenderArgs::default())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
