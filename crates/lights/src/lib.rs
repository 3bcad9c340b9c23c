//! Point lights for manylights, usable on their own: the GPU layout ([`PointLight`]),
//! seeded generation with radius derived from intensity ([`LightSet`], [`RadiusMode`]),
//! smooth deterministic animation on the CPU ([`animation`]) and the GPU ([`LightAnimator`]),
//! and the f64 reference shading ([`reference`]) every pipeline is measured against. The
//! WGSL side (the light struct, the shading model, the animation pass) is [`SHADERS`].
//!
//! ```no_run
//! use manylights_lights::{AnimationParams, GpuLights, LightSet, LightSettings, RadiusMode};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let room = manylights_scene::Aabb::new(glam::Vec3::ZERO, glam::Vec3::new(8.0, 3.0, 10.0));
//! let lights = LightSet::generate(&LightSettings {
//!     count: 10_000,
//!     seed: 1,
//!     intensity: 0.2,
//!     radius: RadiusMode::LuminanceThreshold(0.05), // sqrt(0.2 / 0.05) = 2 m
//!     saturation: 1.0,
//!     animation: AnimationParams::in_box(room),
//! })?;
//! let context = manylights_gpu::GpuContext::new_headless()?;
//! let on_gpu = GpuLights::upload(&context, &lights)?;
//! # Ok(()) }
//! ```
//! `examples/standalone_lights.rs` also animates them on the GPU and checks the CPU agrees.

pub mod animation;
mod gpu;
mod light;
pub mod reference;

pub use animation::AnimationParams;
pub use gpu::{GpuLights, LightAnimator, SHADERS, animate_program, programs};
pub use light::{
    DEFAULT_SATURATION, INTERIOR_SHRINK, LightError, LightSet, LightSettings, PointLight,
    RadiusMode, SPONZA_LIGHT_BOX, interior_box, light_color,
};
pub use reference::{BoundedFalloff, Falloff};

#[cfg(test)]
mod layout_tests {
    use super::PointLight;

    /// The Rust struct and the WGSL struct must agree byte for byte.
    #[test]
    fn point_light_layout_matches_wgsl() {
        let source = include_str!("../../../shaders/lights/light_set.wgsl");
        let module = naga::front::wgsl::parse_str(source).expect("light_set.wgsl parses");
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, ty)| ty.name.as_deref() == Some("PointLight"))
            .expect("struct PointLight");
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("PointLight is not a struct");
        };
        assert_eq!(*span as usize, std::mem::size_of::<PointLight>());
        let offsets: Vec<(String, u32)> = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
            .collect();
        let expected = vec![
            (
                "position".to_string(),
                std::mem::offset_of!(PointLight, position) as u32,
            ),
            (
                "radius".to_string(),
                std::mem::offset_of!(PointLight, radius) as u32,
            ),
            (
                "color".to_string(),
                std::mem::offset_of!(PointLight, color) as u32,
            ),
            (
                "intensity".to_string(),
                std::mem::offset_of!(PointLight, intensity) as u32,
            ),
        ];
        assert_eq!(offsets, expected);
    }
}
