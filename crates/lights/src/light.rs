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
    pub animation: AnimationParams,
}

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
    /// the animation function at time 0, colours a random hue mixed 80% toward white (as
    /// in the reference projects), intensity and radius from the settings.
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
        settings.animation.validate()?;
        let radius = settings.radius.radius(settings.intensity);
        let lights = (0..settings.count)
            .map(|index| PointLight {
                position: animated_position(&settings.animation, settings.seed, index, 0.0)
                    .to_array(),
                radius,
                color: light_color(settings.seed, index).to_array(),
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

/// A random hue at full saturation, mixed 80% toward white.
pub fn light_color(seed: u32, index: u32) -> Vec3 {
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
    rgb.lerp(Vec3::ONE, 0.8)
}
