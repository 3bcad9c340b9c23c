//! `manylights edges`: each anti-aliasing method's error at the frame's edges against the
//! supersampled frame (`lab::edges`).

use anyhow::Context as _;
use manylights::gpu::GpuContext;
use manylights::{AntiAliasing, LoadedScene, PipelineSettings, Renderer};

use super::{RenderArgs, frame_settings};
use crate::lab::edges::{GRID, TAA_FRAMES, render_frames, supersampled};

/// `manylights edges`: the frame's flags, and the reference's grid.
#[derive(clap::Args, Debug, Clone)]
pub struct EdgesArgs {
    #[command(flatten)]
    pub frame: RenderArgs,
    /// The reference's samples a pixel on each axis: the frame is rendered GRID x GRID
    /// times larger and box-filtered.
    #[arg(long, default_value_t = GRID)]
    pub grid: u32,
}

/// `manylights edges`: one sample a pixel, TAA after [`TAA_FRAMES`] frames and 4x MSAA
/// (in Forward+ where the pipeline refuses MSAA) against the supersampled frame.
pub fn edges(edges_args: &EdgesArgs) -> anyhow::Result<()> {
    let (args, grid) = (&edges_args.frame, edges_args.grid.max(1));
    let scene = LoadedScene::load(&args.scene)
        .with_context(|| format!("loading scene '{}'", args.scene))?;
    let mut settings = frame_settings(args, &scene)?;
    settings.post.anti_aliasing = AntiAliasing::Off;
    settings.post.bloom = 0.0;
    settings.view.msaa = 1;
    let context = GpuContext::new_headless().context("creating the GPU context")?;
    println!("adapter: {}", context.summary);
    let mut renderer = Renderer::new(context, scene).context("preparing the renderer")?;
    let reference = supersampled(&mut renderer, &settings, grid)?;
    let (w, h) = settings.view.size;
    println!(
        "{} {w}x{h}, {} lights, {}: edge error against the frame at {grid}x{grid} the pixels, \
         box-filtered (mean over edge pixels of the largest channel error, as a fraction \
         of the pixel's contrast)",
        args.scene,
        settings.lights.count,
        settings.pipeline.kind(),
    );
    let mut taa = settings.clone();
    taa.post.anti_aliasing = AntiAliasing::Taa;
    let mut msaa = settings.clone();
    msaa.view.msaa = 4;
    let mut msaa_label = "4x MSAA".to_string();
    if manylights::DialCombination::of(&msaa).check().is_err() {
        msaa.pipeline = PipelineSettings::forward_plus();
        msaa_label.push_str(" (forward-plus)");
    }
    for (label, frame, frames) in [
        ("one sample a pixel".to_string(), &settings, 1),
        (format!("TAA after {TAA_FRAMES} frames"), &taa, TAA_FRAMES),
        (msaa_label, &msaa, 1),
    ] {
        let image = render_frames(&mut renderer, frame, frames)?;
        let (error, pixels) = reference.edge_error(&image);
        println!("{label:<34} {error:.4}  ({pixels} edge pixels)");
    }
    Ok(())
}
