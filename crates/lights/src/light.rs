//! The point light and the light set: layout, seeded generation, and radius from intensity.

use glam::Vec3;
use manylights_scene::Aabb;

use crate::animation::{AnimationParams, animated_position};

/// A point light as stored in GPU buffers. Mirrors `struct PointLight` in
/// `shaders/lights/light_set.wgsl` (32 bytes, std430; a test checks the offsets).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PointLight {
    pub position: [f32; 3],
    /// Distance at which windowed falloffs reach zero.
    pub radius: f32,
    /// Linear RGB, brightest channel 1.
    pub color: [f32; 3],
    /// Radiance at 1 m is `color * intensity`.
    pub intensity: f32,
}

/// How each light's radius is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RadiusMode {
    /// The same radius for every light (the reference projects use 2 m in Sponza).
    Fixed(f32),
    /// The distance at which the unwindowed inverse-square illuminance drops to this
    /// threshold: radius = sqrt(intensity / threshold). Lights reach exactly as far as
    /// they matter; the threshold is the main speed/accuracy knob.
    LuminanceThreshold(f32),
}

impl RadiusMode {
    pub fn radius(&self, intensity: f32) -> f32 {
        match *self {
            RadiusMode::Fixed(radius) => radius,
            RadiusMode::LuminanceThreshold(threshold) => (intensity / threshold).sqrt(),
        }
    }
}

/// The light box of the reference projects in Sponza, inside its court.
pub const SPONZA_LIGHT_BOX: Aabb = Aabb {
    min: Vec3::new(-10.0, 0.0, -5.0),
    max: Vec3::new(10.0, 8.0, 5.0),
};

/// The fraction by which other scenes' bounds are shrunk (on each side) to get a light box
/// inside the scene rather than on its walls.
pub const INTERIOR_SHRINK: f32 = 0.1;

/// The light box for a scene: its bounds shrunk by [`INTERIOR_SHRINK`] on every side.
pub fn interior_box(bounds: &Aabb) -> Aabb {
    let margin = bounds.size() * INTERIOR_SHRINK;
    Aabb::new(bounds.min + margin, bounds.max - margin)
}

/// Everything that decides a generated light set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSettings {
    pub count: u32,
    pub seed: u32,
    pub intensity: f32,
    pub radius: RadiusMode,
    /// Colour saturation in [0, 1]: 1 is a pure random hue, 0 is white.
    pub saturation: f32,
    pub animation: AnimationParams,
}

/// Default colour saturation: pure random hues, like the reference projects' random
/// colours, so individual pools of light stay visible. (Before, colours were mixed 80%
/// toward white: saturation 0.2.)
pub const DEFAULT_SATURATION: f32 = 1.0;

/// Why a light set was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LightError {
    #[error("light {index}: {field} is {value}, which is not finite")]
    NonFinite {
        index: usize,
        field: &'static str,
        value: String,
    },
    #[error("light {index}: {field} is {value}; it must be {expected}")]
    OutOfRange {
        index: usize,
        field: &'static str,
        value: f32,
        expected: &'static str,
    },
    #[error("light settings: {0}")]
    Settings(String),
}

/// A set of point lights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightSet {
    pub lights: Vec<PointLight>,
}

impl LightSet {
    /// Generates `settings.count` lights, deterministic for a given seed: positions from
    /// the animation function at time 0, colours a random hue at the settings' saturation,
    /// intensity and radius from the settings.
    pub fn generate(settings: &LightSettings) -> Result<Self, LightError> {
        let check = |name: &str, value: f32, positive: bool| {
            if !value.is_finite() || (positive && value <= 0.0) {
                Err(LightError::Settings(format!(
                    "{name} must be a finite positive number, got {value}"
                )))
            } else {
                Ok(())
            }
        };
        check("intensity", settings.intensity, false)?;
        if settings.intensity < 0.0 {
            return Err(LightError::Settings(format!(
                "intensity must not be negative, got {}",
                settings.intensity
            )));
        }
        match settings.radius {
            RadiusMode::Fixed(r) => check("radius", r, true)?,
            RadiusMode::LuminanceThreshold(t) => check("luminance threshold", t, true)?,
        }
        if !(0.0..=1.0).contains(&settings.saturation) {
            return Err(LightError::Settings(format!(
                "saturation must be between 0 and 1, got {}",
                settings.saturation
            )));
        }
        settings.animation.validate()?;
        let radius = settings.radius.radius(settings.intensity);
        let lights = (0..settings.count)
            .map(|index| PointLight {
                position: animated_position(&settings.animation, settings.seed, index, 0.0)
                    .to_array(),
                radius,
                color: light_color(settings.seed, index, settings.saturation).to_array(),
                intensity: settings.intensity,
            })
            .collect();
        Ok(Self { lights })
    }

    /// Checks lights given through the API: every field finite, radius positive,
    /// intensity not negative.
    pub fn validate(&self) -> Result<(), LightError> {
        for (index, light) in self.lights.iter().enumerate() {
            let fields: [(&'static str, &[f32]); 4] = [
                ("position", &light.position),
                ("radius", std::slice::from_ref(&light.radius)),
                ("color", &light.color),
                ("intensity", std::slice::from_ref(&light.intensity)),
            ];
            for (field, values) in fields {
                if values.iter().any(|v| !v.is_finite()) {
                    return Err(LightError::NonFinite {
                        index,
                        field,
                        value: format!("{values:?}"),
                    });
                }
            }
            if light.radius <= 0.0 {
                return Err(LightError::OutOfRange {
                    index,
                    field: "radius",
                    value: light.radius,
                    expected: "positive",
                });
            }
            if light.intensity < 0.0 || light.color.iter().any(|c| *c < 0.0) {
                return Err(LightError::OutOfRange {
                    index,
                    field: "intensity/color",
                    value: light
                        .intensity
                        .min(light.color.iter().copied().fold(f32::INFINITY, f32::min)),
                    expected: "non-negative",
                });
            }
        }
        Ok(())
    }

    pub fn len(&self) -> usize {
        self.lights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }
}

/// A random hue, mixed toward white by `1 - saturation` (saturation 1: the pure hue;
/// 0: white).
pub fn light_color(seed: u32, index: u32, saturation: f32) -> Vec3 {
    let hue = crate::animation::hash_unit(
        crate::animation::pcg_hash(seed ^ 0x5bd1e995) ^ crate::animation::pcg_hash(index),
    );
    let h = hue * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let rgb = match h as u32 {
        0 => Vec3::new(1.0, x, 0.0),
        1 => Vec3::new(x, 1.0, 0.0),
        2 => Vec3::new(0.0, 1.0, x),
        3 => Vec3::new(0.0, x, 1.0),
        4 => Vec3::new(x, 0.0, 1.0),
        _ => Vec3::new(1.0, 0.0, x),
    };
    rgb.lerp(Vec3::ONE, 1.0 - saturation)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturation_moves_colours_between_the_pure_hue_and_white() {
        for index in 0..64 {
            let pure = light_color(7, index, 1.0);
            // A pure hue: one channel at 1, one at 0.
            assert_eq!(pure.max_element(), 1.0, "light {index}: {pure}");
            assert_eq!(pure.min_element(), 0.0, "light {index}: {pure}");
            assert_eq!(light_color(7, index, 0.0), Vec3::ONE);
            // The old pastel colours (80% toward white) are saturation 0.2, bit for bit.
            assert_eq!(
                light_color(7, index, 0.2),
                pure.lerp(Vec3::ONE, 0.8),
                "light {index}"
            );
        }
    }

    #[test]
    fn saturation_outside_zero_to_one_is_refused() {
        for saturation in [-0.1, 1.5, f32::NAN] {
            let settings = LightSettings {
                count: 4,
                seed: 1,
                intensity: 0.2,
                radius: RadiusMode::Fixed(1.0),
                saturation,
                animation: AnimationParams::in_box(SPONZA_LIGHT_BOX),
            };
            let error = LightSet::generate(&settings).expect_err("refused");
            assert!(error.to_string().contains("saturation"), "{error}");
        }
    }
}
