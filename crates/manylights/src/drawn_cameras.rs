//! Cameras drawn at random inside a scene, reproducibly, so accuracy is judged from views
//! nobody chose (a setting tuned on a few fixed presets can hide what it does elsewhere).
//!
//! Camera `drawn:SEED:INDEX` of a scene is the first draw of its own random stream (from
//! the seed and the index) that passes three tests against the scene's triangles:
//! - it stands clear of geometry: rays in 14 directions (the axes and the diagonals) meet
//!   nothing nearer than [`CLEARANCE`], so its near plane is not inside a wall;
//! - it is not inside a solid: none of those rays first meets a triangle from behind;
//! - it sees the scene: at least half of a 16x9 grid of rays through its frame meet a
//!   surface (a view mostly of sky measures little).
//!
//! Positions are uniform in the scene's light box (where the generated lights live: the
//! lit volume), yaw uniform, pitch within [`PITCH_RANGE`] and the vertical field of view
//! within [`FOV_RANGE`]. Each index has its own stream, so camera 5 of a seed is the same
//! whether 6 or 60 are drawn.

use glam::{DVec3, Vec3};
use manylights_lights::animation::{hash_unit, pcg_hash};
use manylights_visibility::SceneBvh;

use crate::{Camera, LoadedScene};

/// The least distance from a drawn camera to any surface along the 14 test directions,
/// metres: beyond the corners of its near plane (0.19 m away at Sponza's near plane of
/// 0.1 m and the widest drawn field of view, 75 degrees at 16:9), so none pokes through a
/// wall, and close enough that views within 1 m of a wall are drawn.
pub const CLEARANCE: f64 = 0.25;

/// Drawn cameras' pitch, degrees: from looking down at the floor to up at the vaults.
pub const PITCH_RANGE: (f32, f32) = (-35.0, 35.0);

/// Drawn cameras' vertical field of view, degrees.
pub const FOV_RANGE: (f32, f32) = (45.0, 75.0);

/// The frame the sky test looks through, width over height: the lab's and the README's
/// frames (a camera is drawn once for every size it is rendered at).
const TEST_ASPECT: f64 = 16.0 / 9.0;

/// The least share of the frame's test rays that must meet a surface.
const LEAST_SCENE_IN_VIEW: f64 = 0.5;

/// Draws of one index before it gives up: a scene where none of them passes has no room
/// for a camera in its light box.
const MAX_DRAWS: u32 = 1000;

/// The spelling of drawn camera `index` of `seed`, as `--camera` and a view of the lab
/// take it.
pub fn drawn_camera_name(seed: u32, index: u32) -> String {
    format!("drawn:{seed}:{index}")
}

/// `drawn:SEED:INDEX` read back; `None` for any other camera text.
pub(crate) fn parse_drawn_camera(text: &str) -> Option<Result<(u32, u32), String>> {
    let rest = text.strip_prefix("drawn:")?;
    let parsed = rest
        .split_once(':')
        .and_then(|(seed, index)| Some((seed.parse().ok()?, index.parse().ok()?)));
    Some(parsed.ok_or_else(|| {
        format!("camera '{text}': a drawn camera is drawn:SEED:INDEX, e.g. drawn:1:0")
    }))
}

/// A uniform number in [0, 1) of draw `draw` of stream (`seed`, `index`), dimension `axis`.
fn unit(seed: u32, index: u32, draw: u32, axis: u32) -> f32 {
    let stream = pcg_hash(seed ^ 0x5eed_ca3e) ^ pcg_hash(index.wrapping_mul(0x9e37_79b9));
    hash_unit(stream ^ pcg_hash(draw.wrapping_mul(8) + axis))
}

fn mix(range: (f32, f32), t: f32) -> f32 {
    range.0 + (range.1 - range.0) * t
}

/// The 14 directions a camera's clearance is tested along.
fn test_directions() -> impl Iterator<Item = DVec3> {
    let axes = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    let diagonals = (0..8).map(|corner| {
        let sign = |bit: u32| if corner & bit == 0 { 1.0 } else { -1.0 };
        DVec3::new(sign(1), sign(2), sign(4)).normalize()
    });
    axes.into_iter().chain(diagonals)
}

/// Why a draw is rejected, or `None` where it passes.
fn rejection(bvh: &SceneBvh, camera: &Camera) -> Option<&'static str> {
    let eye = camera.position.as_dvec3();
    for direction in test_directions() {
        let Some(hit) = bvh.closest_hit(eye, direction, 0.0, f64::INFINITY) else {
            continue;
        };
        if hit.t < CLEARANCE {
            return Some("too close to a surface");
        }
        let triangle = &bvh.triangles()[hit.triangle as usize];
        let [a, b, c] = [triangle.v0, triangle.v1, triangle.v2].map(|v| Vec3::from(v).as_dvec3());
        if (b - a).cross(c - a).dot(direction) > 0.0 {
            return Some("inside geometry");
        }
    }
    let rotation = camera.rotation().as_dquat();
    let (right, up, forward) = (
        rotation * DVec3::X,
        rotation * DVec3::Y,
        rotation * DVec3::NEG_Z,
    );
    let tan = (f64::from(camera.fov_y) * 0.5).tan();
    let (columns, rows) = (16, 9);
    let mut seen = 0;
    for row in 0..rows {
        for column in 0..columns {
            let x =
                (2.0 * (f64::from(column) + 0.5) / f64::from(columns) - 1.0) * tan * TEST_ASPECT;
            let y = (1.0 - 2.0 * (f64::from(row) + 0.5) / f64::from(rows)) * tan;
            let direction = (forward + right * x + up * y).normalize();
            let far = f64::from(camera.far);
            if bvh.any_hit(eye, direction, f64::from(camera.near), far) {
                seen += 1;
            }
        }
    }
    (f64::from(seen) < LEAST_SCENE_IN_VIEW * f64::from(columns * rows)).then_some("mostly sky")
}

/// Drawn camera `index` of `seed` in `scene` (whose triangles are in `bvh`); the error
/// says why every draw failed.
pub fn drawn_camera(
    scene: &LoadedScene,
    bvh: &SceneBvh,
    seed: u32,
    index: u32,
) -> Result<Camera, String> {
    let bounds = scene.light_box;
    if bounds.is_empty() {
        return Err(format!(
            "scene {}: no light box to draw cameras in",
            scene.name
        ));
    }
    let template = scene.default_camera();
    let mut reasons = std::collections::BTreeMap::new();
    for draw in 0..MAX_DRAWS {
        let random = |axis| unit(seed, index, draw, axis);
        let position =
            bounds.min + (bounds.max - bounds.min) * Vec3::new(random(0), random(1), random(2));
        let camera = Camera {
            position,
            yaw: random(3) * std::f32::consts::TAU,
            pitch: mix(PITCH_RANGE, random(4)).to_radians(),
            roll: 0.0,
            fov_y: mix(FOV_RANGE, random(5)).to_radians(),
            ..template
        };
        match rejection(bvh, &camera) {
            None => return Ok(camera),
            Some(reason) => *reasons.entry(reason).or_insert(0u32) += 1,
        }
    }
    let reasons: Vec<String> = reasons
        .iter()
        .map(|(reason, count)| format!("{count} {reason}"))
        .collect();
    Err(format!(
        "scene {}: no drawn camera {} passes in {MAX_DRAWS} draws ({}): the scene has no \
         room to stand and look at it inside its light box",
        scene.name,
        drawn_camera_name(seed, index),
        reasons.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drawn_cameras_name_reads_back() {
        assert_eq!(
            parse_drawn_camera(&drawn_camera_name(7, 3)),
            Some(Ok((7, 3)))
        );
        assert_eq!(parse_drawn_camera("reference"), None);
        assert!(parse_drawn_camera("drawn:x").unwrap().is_err());
    }
}
