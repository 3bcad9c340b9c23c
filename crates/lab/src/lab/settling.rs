//! How long a method with history (`Shadows::settle_frames`) takes to settle after a
//! change: the lights jumping ahead in their animation, the camera still ([`lag`]), or
//! the camera jumping, uncovering what the old view hid ([`disocclusion_lag`]). Both
//! render three histories' worth of frames after the change, each with its own seed, and
//! count the frames to the first one within a quarter over the settled frames' noise of
//! the last ([`first_settled_frame`]). A method without history settles at once: 0.

use glam::DVec3;

use manylights::{FrameSettings, Renderer};

use super::image_metrics::luminance;
use super::motion::walk_camera;
use super::reference::Reference;
use super::reference::{at_samples, mean_relative_difference};

/// How far the lights jump in their animation for [`lag`].
const LAG_JUMP_SECONDS: f32 = 0.5;

/// How many steps of the motion walk ([`walk_camera`]) the camera jumps in one frame for
/// [`disocclusion_lag`]: 50 cm forward and 5 degrees, so surfaces the old view hid come
/// into sight along every silhouette.
const DISOCCLUSION_JUMP_STEPS: u32 = 10;

/// The first of `frames` (rendered after a change, `history` frames a history) whose
/// `difference` from the last is within a quarter over the noise between settled frames:
/// the last's difference from the frame one history before it.
fn first_settled_frame<T>(frames: &[T], history: u32, difference: impl Fn(&T, &T) -> f64) -> u32 {
    let settled = &frames[frames.len() - 1];
    let noise = difference(&frames[frames.len() - 1 - history as usize], settled);
    let settled_at = frames
        .iter()
        .position(|frame| difference(frame, settled) <= 1.25 * noise)
        .unwrap_or(frames.len() - 1);
    settled_at as u32
}

/// The frames to settle after the lights jump [`LAG_JUMP_SECONDS`] ahead, the camera
/// still, compared at the reference's samples (relative as the errors are).
pub(super) async fn lag(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    reference: &Reference,
) -> anyhow::Result<u32> {
    let history = settings.settle_frames();
    if history == 0 {
        return Ok(0);
    }
    let mut jumped = settings.clone();
    jumped.lights.time = settings.lights.time + LAG_JUMP_SECONDS;
    jumped.pipeline.set_list_statistics(false, false);
    let mut frames: Vec<Vec<DVec3>> = Vec::new();
    for frame in 0..3 * history {
        jumped.shadows.seed = settings.shadows.seed.wrapping_add(2 + frame);
        renderer.render_frame_timed_async(&jumped).await?;
        frames.push(at_samples(&renderer.read_hdr_async().await?, reference));
    }
    Ok(first_settled_frame(&frames, history, |a, b| {
        mean_relative_difference(a, b, reference)
    }))
}

/// Ghosting after a disocclusion: the frames to settle after the camera jumps
/// [`DISOCCLUSION_JUMP_STEPS`] steps of the walk in one frame, the lights still, once the
/// history has filled at the configuration's camera. Over whole frames (the reference's
/// samples belong to the old view): the mean luminance difference over the settled
/// frame's mean luminance.
pub(super) async fn disocclusion_lag(
    renderer: &mut Renderer,
    settings: &FrameSettings,
) -> anyhow::Result<u32> {
    let history = settings.settle_frames();
    if history == 0 {
        return Ok(0);
    }
    let mut frame = settings.clone();
    frame.pipeline.set_list_statistics(false, false);
    for step in 0..history {
        frame.shadows.seed = settings.shadows.seed.wrapping_add(5000 + step);
        renderer.render_frame_timed_async(&frame).await?;
    }
    frame.view.camera = walk_camera(&settings.view.camera, DISOCCLUSION_JUMP_STEPS);
    let mut frames: Vec<Vec<f64>> = Vec::new();
    for step in 0..3 * history {
        frame.shadows.seed = settings.shadows.seed.wrapping_add(6000 + step);
        renderer.render_frame_timed_async(&frame).await?;
        let image = renderer.read_hdr_async().await?;
        frames.push(image.iter().map(|&pixel| luminance(pixel)).collect());
    }
    let brightness: f64 = frames[frames.len() - 1].iter().sum();
    Ok(first_settled_frame(&frames, history, |a, settled| {
        let change: f64 = a.iter().zip(settled).map(|(a, b)| (a - b).abs()).sum();
        change / brightness.max(f64::MIN_POSITIVE)
    }))
}
