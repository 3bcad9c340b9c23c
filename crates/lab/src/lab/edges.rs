//! Anti-aliasing measured where it matters, at the frame's edges: a frame compared with
//! the same frame rendered at 4x4 the pixels and box-filtered (each pixel the mean of 16
//! samples on a regular grid over it). `manylights edges` and the post tests use it.

use manylights::{AntiAliasing, FrameSettings, Renderer};

/// The supersampled reference's pixels per frame pixel, on each axis, by default (the
/// issue's 4x4; 4x MSAA's standard sample positions lie on this grid, which favours it:
/// `manylights edges --grid 8` measures against a finer one too).
pub const GRID: u32 = 4;

/// Temporal anti-aliasing's frames before it is measured: two cycles of its jitter.
pub const TAA_FRAMES: u32 = 32;

/// A frame box-filtered from one `grid` x `grid` times larger.
#[derive(Debug, Clone)]
pub struct BoxFiltered {
    /// Each pixel's mean colour.
    pub mean: Vec<[f32; 3]>,
    /// Each pixel's contrast: the largest channel difference among its samples.
    pub contrast: Vec<f32>,
    /// Each pixel's brightest sample channel.
    pub brightest: Vec<f32>,
}

/// A pixel is on an edge where its samples differ by at least this fraction of its
/// brightest sample (a surface's texture and lighting vary much less within a pixel)...
const EDGE_CONTRAST: f32 = 0.25;
/// ... and that sample is not in the dark: at least this fraction of the frame's 99th
/// percentile (lights placed near a surface make a few pixels far brighter than the
/// rest, so the frame's maximum is no scale).
const EDGE_BRIGHTNESS: f32 = 0.01;

impl BoxFiltered {
    /// `image` of `size` (a multiple of `grid` on each axis), filtered down.
    pub fn of(image: &[[f32; 4]], size: (u32, u32), grid: u32) -> Self {
        let small = (size.0 / grid, size.1 / grid);
        let pixels = (small.0 * small.1) as usize;
        let mut mean = vec![[0.0f32; 3]; pixels];
        let mut contrast = vec![0.0f32; pixels];
        let mut brightest = vec![0.0f32; pixels];
        for (i, ((pixel, range), top)) in mean
            .iter_mut()
            .zip(&mut contrast)
            .zip(&mut brightest)
            .enumerate()
        {
            let (x, y) = (i as u32 % small.0, i as u32 / small.0);
            let (mut low, mut high) = ([f32::MAX; 3], [f32::MIN; 3]);
            for sy in 0..grid {
                for sx in 0..grid {
                    let at = ((y * grid + sy) * size.0 + x * grid + sx) as usize;
                    for c in 0..3 {
                        pixel[c] += image[at][c] / (grid * grid) as f32;
                        low[c] = low[c].min(image[at][c]);
                        high[c] = high[c].max(image[at][c]);
                    }
                }
            }
            *range = (0..3).map(|c| high[c] - low[c]).fold(0.0, f32::max);
            *top = high.into_iter().fold(0.0, f32::max);
        }
        Self {
            mean,
            contrast,
            brightest,
        }
    }

    /// The mean, over the pixels an edge crosses (`EDGE_CONTRAST`,
    /// `EDGE_BRIGHTNESS`), of each pixel's largest channel error against this
    /// reference, as a fraction of that pixel's contrast; and how many such pixels there
    /// are.
    pub fn edge_error(&self, image: &[[f32; 4]]) -> (f32, usize) {
        let mut sorted = self.brightest.clone();
        sorted.sort_by(f32::total_cmp);
        let bright = sorted[(sorted.len() * 99 / 100).min(sorted.len().saturating_sub(1))];
        let errors: Vec<f32> = (0..self.mean.len())
            .filter(|&i| {
                self.contrast[i] >= EDGE_CONTRAST * self.brightest[i]
                    && self.brightest[i] >= EDGE_BRIGHTNESS * bright
                    && self.contrast[i] > 0.0
            })
            .map(|i| {
                (0..3)
                    .map(|c| (image[i][c] - self.mean[i][c]).abs())
                    .fold(0.0, f32::max)
                    / self.contrast[i]
            })
            .collect();
        (
            errors.iter().sum::<f32>() / errors.len().max(1) as f32,
            errors.len(),
        )
    }
}

/// `frames` frames of `settings` on `renderer`, the frame's number as each one's seed (as
/// the viewer and `render --frames` count them); the last one's HDR radiance.
pub fn render_frames(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    frames: u32,
) -> anyhow::Result<Vec<[f32; 4]>> {
    let mut settings = settings.clone();
    let first = settings.shadows.seed;
    for frame in 0..frames.max(1) {
        settings.shadows.seed = first.wrapping_add(frame);
        renderer.render_frame(&settings)?;
    }
    Ok(renderer.read_hdr()?)
}

/// The frame of `settings` at `grid` x `grid` its pixels, one sample at each centre,
/// box-filtered.
pub fn supersampled(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    grid: u32,
) -> anyhow::Result<BoxFiltered> {
    let mut big = settings.clone();
    big.view.size = (settings.view.size.0 * grid, settings.view.size.1 * grid);
    big.view.msaa = 1;
    big.post.anti_aliasing = AntiAliasing::Off;
    big.post.bloom = 0.0;
    let image = render_frames(renderer, &big, 1)?;
    // Deferred's blended layers are held to the device's largest storage binding: a
    // frame this large may drop fragments past the pool (reported, not drawn), and a
    // reference without them would be no reference.
    if let Some(counts) = renderer.read_blended_layer_counts()?
        && counts.past_pool > 0
    {
        anyhow::bail!(
            "the frame at {grid}x{grid} the pixels ({}x{}) dropped {} of {} blended fragments \
             past deferred's layer pool (this device's largest storage binding): measure a \
             smaller size, or with another pipeline",
            big.view.size.0,
            big.view.size.1,
            counts.past_pool,
            counts.fragments
        );
    }
    Ok(BoxFiltered::of(&image, big.view.size, grid))
}
