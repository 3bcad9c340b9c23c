//! `manylights`: the interactive viewer (the default when a display is available) and the
//! headless `render` command. All rendering lives in the `manylights` facade; this binary
//! owns the window, input and UI.

mod app;
mod camera_controller;
mod measure;
mod script;
mod ui;

// What differs between the native binary and the page: the entry point, where scenes come
// from, the window, screenshots and how a run ends. Each file has the same functions.
#[cfg(not(target_arch = "wasm32"))]
#[path = "native.rs"]
mod platform;
#[cfg(target_arch = "wasm32")]
#[path = "web.rs"]
mod platform;

use std::path::PathBuf;

use clap::Args;
use manylights_lab::cli::RenderArgs;

fn main() -> platform::Exit {
    platform::main()
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
    /// Draw only the rendered image, without the panels (the page's tests read it back).
    #[arg(long)]
    pub hide_ui: bool,
}
