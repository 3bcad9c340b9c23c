//! The native binary: the command line (`render`, `view`, `bench`, `soak`), scenes from the
//! disk, screenshots written as files, and start-up that blocks (the page's twin is
//! `web.rs`, with the same functions).

use std::future::Future;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context as _;
use clap::{Parser, Subcommand};
use manylights::{LoadedScene, Renderer};
use manylights_lab::cli::RenderArgs;
use stats_alloc::{INSTRUMENTED_SYSTEM, StatsAlloc};
use winit::event_loop::{EventLoop, EventLoopProxy};
use winit::window::{Window, WindowAttributes};

use crate::ViewArgs;
use crate::app::{App, AppEvent};

pub type Exit = ExitCode;

/// Screenshots are read from the renderer's output (no panels in it): the window's frame
/// keeps its panels.
pub const SCREENSHOT_FROM_WINDOW: bool = false;

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
    Bench(Box<manylights_lab::cli::BenchArgs>),
    /// Render many frames headless while changing settings; fail if resident memory or
    /// GPU allocations grow.
    Soak(manylights_lab::cli::SoakArgs),
    /// Measure anti-aliasing at the frame's edges: one sample a pixel, TAA and 4x MSAA,
    /// each against the frame rendered at 4x4 the pixels and box-filtered.
    Edges(manylights_lab::cli::EdgesArgs),
}

/// Whether a window can be opened (X11 or Wayland).
fn has_display() -> bool {
    std::env::var_os("DISPLAY").is_some() || std::env::var_os("WAYLAND_DISPLAY").is_some()
}

/// Headless work must not touch a display server. Mesa's implicit Vulkan layer
/// `VK_LAYER_MESA_device_select` connects to Wayland and X11 while listing GPUs (to find the
/// display's GPU), and libwayland prints `error: XDG_RUNTIME_DIR is invalid or not set`
/// where that variable is unset (containers, CI, ssh): errors that are not errors. The
/// layer's manifest names the variable that turns it off; headless commands set it unless
/// the user set it (the viewer keeps the layer: on a laptop it picks the display's GPU).
#[allow(unsafe_code)]
fn headless_without_display_servers() {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called first thing in `main`, before any thread exists that could read
        // the environment at the same time.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

pub fn main() -> ExitCode {
    let command = Cli::parse().command;
    let headless = match &command {
        Some(Command::View(_)) => false,
        Some(_) => true,
        None => !has_display(),
    };
    if headless {
        headless_without_display_servers();
    }
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let result = match command {
        Some(Command::Render(args)) => manylights_lab::cli::render(&args),
        Some(Command::View(args)) => view(args),
        Some(Command::Bench(args)) => manylights_lab::terminal::bench(&args),
        Some(Command::Soak(args)) => manylights_lab::terminal::soak(&args, Some(live_heap_bytes)),
        Some(Command::Edges(args)) => manylights_lab::cli::edges(&args),
        None if has_display() => view(ViewArgs::default()),
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

/// Runs the viewer in a window until it is closed (or its `--frames` are drawn).
fn view(args: ViewArgs) -> anyhow::Result<()> {
    let event_loop = EventLoop::<AppEvent>::with_user_event()
        .build()
        .context("opening the window system (is a display available?)")?;
    let mut app = App::new(args, event_loop.create_proxy());
    event_loop
        .run_app(&mut app)
        .context("running the event loop")?;
    app.into_outcome()
}

/// A named scene or a file from the disk.
pub async fn load_scene(spec: &str) -> anyhow::Result<LoadedScene> {
    Ok(LoadedScene::load(spec)?)
}

/// The window is as large as the frame asked for.
pub fn window_attributes(
    attributes: WindowAttributes,
    args: &ViewArgs,
) -> anyhow::Result<WindowAttributes> {
    // The size is a setting like any other (`--size`, `size=`, `--set view.size=...`).
    let (width, height) = args.frame.settings().map_err(anyhow::Error::msg)?.view.size;
    Ok(attributes.with_inner_size(winit::dpi::PhysicalSize::new(width, height)))
}

/// Runs `future` to its end here and now (the page spawns it and gets the result back
/// through `proxy` instead).
pub fn launch<T>(
    _proxy: &EventLoopProxy<AppEvent>,
    future: impl Future<Output = T> + 'static,
    _event: impl FnOnce(T) -> AppEvent + 'static,
) -> Option<T> {
    Some(pollster::block_on(future))
}

/// The frame's image without the UI, read back from the GPU and written as a PNG.
pub fn save_screenshot(renderer: &Renderer, _window: &Window, path: &Path) -> anyhow::Result<()> {
    let image = renderer.read_output().context("reading the frame back")?;
    image
        .save(path)
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// A scripted run (`--frames`) drew its frames: print its frame rate, then `finish`
/// (writes `--screenshot`).
pub fn frames_done(
    summary: &str,
    _window: &Window,
    finish: impl FnOnce() -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    println!("{summary}");
    finish()
}

/// The viewer stopped; `main` prints the error, if any.
pub fn stopped(_outcome: &anyhow::Result<()>) {}

/// A scene asked for from the UI loaded (the panel says so; nothing else to do here).
pub fn scene_loaded(_spec: &str, _error: Option<&String>) {}

/// The GPU and scene are ready and the first frame is on its way.
pub fn started() {}

/// The measure panel started a run.
pub fn measure_started() {}

/// The measure panel's run ended: its report is written as `manylights bench` writes one
/// (bench.json, REPORT.md, the charts) into a new folder here; returns what was written.
pub fn measure_ended(outcome: Result<&manylights_lab::lab::BenchReport, &str>) -> String {
    let Ok(report) = outcome else {
        return String::new();
    };
    let seconds = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let dir = PathBuf::from(format!("manylights-measure-{seconds}"));
    match manylights_lab::report::write_all(report, &dir) {
        Ok(()) => {
            let written = format!("wrote {} (bench.json, REPORT.md, charts)", dir.display());
            println!("{written}");
            written
        }
        Err(error) => format!("could not write the report: {error:#}"),
    }
}
