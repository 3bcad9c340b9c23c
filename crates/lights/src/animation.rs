//! Light motion: each light follows a smooth 1D gradient-noise path per axis inside the
//! light box (the reference projects use 2D Perlin noise of (light index, time); a per-light
//! hashed lattice is the same idea without a permutation table). Positions are a pure
//! function of (seed, light index, time), so a fixed time step gives reproducible frames.
//!
//! This CPU implementation mirrors `shaders/lights/animate.wgsl` operation for operation;
//! tests compare them within 1e-4.

use glam::Vec3;
use manylights_scene::Aabb;

use crate::error::LightError;

/// How lights move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnimationParams {
    /// The box lights stay in.
    pub bounds: Aabb,
    /// Noise lattice steps per second (about how many direction changes per second).
    pub speed: f32,
    /// How far a light wanders from its anchor, as a fraction of the box (0 = static).
    pub wander: f32,
}

impl AnimationParams {
    /// The default motion in a box: a slow drift over a quarter of the box.
    pub fn in_box(bounds: Aabb) -> Self {
        Self {
            bounds,
            speed: 0.25,
            wander: 0.25,
        }
    }

    pub fn validate(&self) -> Result<(), LightError> {
        let finite = self.bounds.min.is_finite()
            && self.bounds.max.is_finite()
            && self.speed.is_finite()
            && self.wander.is_finite();
        if !finite || self.bounds.is_empty() {
            return Err(LightError::Settings(format!(
                "the light box {:?} and the animation speed/wander must be finite and non-empty",
                self.bounds
            )));
        }
        Ok(())
    }

    /// The lattice coordinate for a time: multiplied once, here, for both implementations.
    pub fn noise_time(&self, time: f32) -> f32 {
        time * self.speed
    }
}

/// PCG hash (Jarzynski and Olano 2020).
pub fn pcg_hash(input: u32) -> u32 {
    let state = input.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// Uniform in [0, 1) from the top 24 bits (exact in f32).
pub fn hash_unit(key: u32) -> f32 {
    (pcg_hash(key) >> 8) as f32 * (1.0 / 16777216.0)
}

fn axis_key(seed: u32, index: u32, axis: u32) -> u32 {
    pcg_hash(seed ^ pcg_hash(index.wrapping_mul(3).wrapping_add(axis)))
}

/// WGSL's `mix`: e1 * (1 - t) + e2 * t.
fn mix(e1: f32, e2: f32, t: f32) -> f32 {
    e1 * (1.0 - t) + e2 * t
}

fn gradient_noise(key: u32, t: f32) -> f32 {
    let cell = t.floor();
    let f = t - cell;
    let lattice = cell as i32 as u32;
    let g0 = hash_unit(key ^ pcg_hash(lattice)) * 2.0 - 1.0;
    let g1 = hash_unit(key ^ pcg_hash(lattice.wrapping_add(1))) * 2.0 - 1.0;
    let fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    mix(g0 * f, g1 * (f - 1.0), fade)
}

fn fold_unit(u: f32) -> f32 {
    let m = u - 2.0 * (u * 0.5).floor();
    1.0 - (1.0 - m).abs()
}

/// Where light `index` is at `time` seconds.
pub fn animated_position(params: &AnimationParams, seed: u32, index: u32, time: f32) -> Vec3 {
    let noise_time = params.noise_time(time);
    let mut unit = [0.0f32; 3];
    for (axis, value) in unit.iter_mut().enumerate() {
        let key = axis_key(seed, index, axis as u32);
        let anchor = hash_unit(key);
        let offset = hash_unit(key ^ 0x9e3779b9) * 64.0;
        *value = fold_unit(anchor + params.wander * 2.0 * gradient_noise(key, offset + noise_time));
    }
    params.bounds.min + (params.bounds.max - params.bounds.min) * Vec3::from_array(unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> AnimationParams {
        AnimationParams::in_box(crate::SPONZA_LIGHT_BOX)
    }

    #[test]
    fn positions_stay_in_the_box_and_move_smoothly() {
        let p = params();
        for index in 0..500 {
            let mut previous = animated_position(&p, 7, index, 0.0);
            for step in 1..200 {
                let t = step as f32 / 60.0;
                let position = animated_position(&p, 7, index, t);
                assert!(
                    position.cmpge(p.bounds.min).all() && position.cmple(p.bounds.max).all(),
                    "{position}"
                );
                // At 60 Hz a light moves at most a few centimetres per frame.
                assert!(
                    position.distance(previous) < 0.25,
                    "light {index} jumped at t={t}"
                );
                previous = position;
            }
        }
    }

    #[test]
    fn deterministic_and_seed_dependent() {
        let p = params();
        assert_eq!(
            animated_position(&p, 1, 42, 3.5),
            animated_position(&p, 1, 42, 3.5)
        );
        assert_ne!(
            animated_position(&p, 1, 42, 3.5),
            animated_position(&p, 2, 42, 3.5)
        );
        assert_ne!(
            animated_position(&p, 1, 42, 3.5),
            animated_position(&p, 1, 43, 3.5)
        );
    }

    #[test]
    fn lights_spread_over_the_box() {
        let p = params();
        let n = 10_000;
        let mean = (0..n)
            .map(|i| animated_position(&p, 3, i, 0.0))
            .sum::<Vec3>()
            / n as f32;
        assert!(mean.distance(p.bounds.center()) < 0.3, "mean {mean}");
    }
}
