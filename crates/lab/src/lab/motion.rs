//! Flicker under motion. Users move the camera, and a temporal filter that looks steady
//! with the camera still may smear or shimmer once it moves. So the camera walks forward
//! and turns, the lights animate, and each frame's error against its own full-frame
//! reference is compared with the frame before's.
//!
//! The change of the error, not of the image: the image changes because the camera moved
//! and the lights did, and the reference changes alike. What is left is the method's own
//! change: noise from frame to frame, or an error that jumps. A method without
//! randomness measures the slow drift of its error pattern across the screen (the noise
//! floor of this measure); one shadow ray a pixel without a filter measures its noise.

use glam::Vec3;

use manylights::{Camera, FrameSettings, Renderer};

use super::image_metrics::luminance_errors;
use super::matrix::{BenchConfig, BenchMatrix};
use super::reference::full_frame_reference;

/// How far the camera moves a frame: 5 cm forward and half a degree to the left, a brisk
/// walk (3 m/s and 30 degrees a second) at 60 frames a second.
const WALK_STEP_METRES: f32 = 0.05;
const WALK_TURN_DEGREES: f32 = 0.5;

/// The camera `frame` steps along the walk from `start`.
pub fn walk_camera(start: &Camera, frame: u32) -> Camera {
    let forward: Vec3 = start.forward();
    Camera {
        position: start.position + forward * (WALK_STEP_METRES * frame as f32),
        yaw: start.yaw + (WALK_TURN_DEGREES * frame as f32).to_radians(),
        ..*start
    }
}

/// The mean change of the luminance error between consecutive frames of a walk, over the
/// reference's mean luminance (absolute, not per pixel: a relative error per pixel made the
/// measure's floor the f16 target's rounding in the darkest corners),
/// `matrix.motion_frames` steps from the configuration's camera, lights animating at
/// the matrix's time step. `None` without a full-frame reference for the frames. The
/// method's frames are rendered first, in one run, so that no reference frame breaks
/// their history; a method with history settles at the start first.
pub(super) async fn motion_flicker(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    settings: &FrameSettings,
    reference_shadows: manylights::Shadows,
) -> anyhow::Result<Option<f64>> {
    let frame_at = |step: u32| {
        let mut frame = settings.clone();
        frame.view.camera = walk_camera(&settings.view.camera, step);
        frame.lights.time = settings.lights.time + matrix.time_step * step as f32;
        frame.shadows.seed = settings.shadows.seed.wrapping_add(1000 + step);
        frame.pipeline.set_list_statistics(false, false);
        frame
    };
    let settle = settings.settle_frames();
    for step in 0..settle {
        let mut settling = frame_at(0);
        settling.shadows.seed = settings.shadows.seed.wrapping_add(900 + step);
        renderer.render_frame_timed_async(&settling).await?;
    }
    let mut images = Vec::new();
    for step in 0..=matrix.motion_frames {
        renderer.render_frame_timed_async(&frame_at(step)).await?;
        images.push(renderer.read_hdr_async().await?);
    }
    let mut previous: Option<Vec<f64>> = None;
    let mut changes = Vec::new();
    for (step, image) in (0..).zip(&images) {
        let frame = frame_at(step);
        let surface = renderer.capture_surface_async(&frame).await?;
        let Some(reference) = full_frame_reference(
            renderer,
            matrix,
            config,
            &frame,
            reference_shadows,
            &surface,
        )
        .await?
        else {
            return Ok(None);
        };
        let (errors, mean_luminance) = luminance_errors(&reference.hdr, image);
        if let Some(before) = &previous
            && mean_luminance > 0.0
        {
            changes.push(mean_change(before, &errors) / mean_luminance);
        }
        previous = Some(errors);
    }
    Ok((!changes.is_empty()).then(|| changes.iter().sum::<f64>() / changes.len() as f64))
}

/// The mean |change| of the error from one frame to the next.
fn mean_change(before: &[f64], after: &[f64]) -> f64 {
    before
        .iter()
        .zip(after)
        .map(|(a, b)| (b - a).abs())
        .sum::<f64>()
        / before.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_walk_moves_forward_and_turns_from_its_start() {
        let start = Camera::look_at(Vec3::ZERO, Vec3::X, 60.0, 0.1, 100.0);
        assert_eq!(walk_camera(&start, 0), start);
        let later = walk_camera(&start, 10);
        assert!(
            (later.position - Vec3::X * 0.5).length() < 1e-5,
            "{later:?}"
        );
        assert!((later.yaw - start.yaw - 5f32.to_radians()).abs() < 1e-6);
    }

    #[test]
    fn the_change_is_the_mean_over_every_pixel() {
        assert!((mean_change(&[0.1, 0.5], &[0.3, 0.5]) - 0.1).abs() < 1e-12);
    }
}
