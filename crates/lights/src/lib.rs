//! Point, spot and area lights for manylights, usable on their own: the GPU layout ([`Light`]),
//! seeded generation with radius derived from intensity ([`LightSet`], [`RadiusMode`]),
//! smooth deterministic animation on the CPU ([`animation`]) and the GPU ([`LightAnimator`]),
//! and the f64 reference shading ([`reference`](mod@reference)) every pipeline is measured against. The
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
//!     spots: manylights_lights::SpotSettings::default(),
//!     shape: manylights_lights::LightShape::Point,
//! })?;
//! let context = manylights_gpu::GpuContext::new_headless()?;
//! let on_gpu = GpuLights::upload(&context, &lights)?;
//! # Ok(()) }
//! ```
//! `examples/standalone_lights.rs` also animates them on the GPU and checks the CPU agrees.
//!
//! An engine with lights of its own uploads them as they are ([`GpuLights::new`]: a
//! malformed light is refused by its index) and rewrites the range that changed each
//! frame ([`GpuLights::write`]), before the frame's submission:
//!
//! ```no_run
//! # fn engine(context: &manylights_gpu::GpuContext) -> Result<(), manylights_gpu::GpuError> {
//! use glam::Vec3;
//! use manylights_lights::{GpuLights, Light};
//! let mut lights = vec![Light::point(Vec3::new(0.0, 2.0, 0.0), 4.0, Vec3::ONE, 1.0); 100];
//! let mut on_gpu = GpuLights::new(context, &lights)?;
//! lights[7].position[1] = 2.5; // the engine moved light 7
//! on_gpu.write(context, 7, &lights[7..8])?;
//! # Ok(()) }
//! ```
//!
//! Its light loop can run our BRDF too: [`pbr_wgsl`] is glTF's metallic-roughness as every
//! manylights pipeline shades it, as WGSL for the engine's module, with one table
//! ([`SpecularTables`]) bound at the group the engine picks:
//!
//! ```no_run
//! # fn engine(context: &manylights_gpu::GpuContext) -> Result<(), manylights_gpu::GpuError> {
//! let brdf = manylights_lights::pbr_wgsl(&manylights_gpu::ShaderLibrary::Embedded, 2)?;
//! let tables = manylights_lights::SpecularTables::new(context)?; // bound at group 2, binding 15
//! # let _ = (brdf, tables);
//! # Ok(()) }
//! ```

pub mod animation;
pub mod emissive;
mod error;
mod gpu;
pub mod gpu_reference;
mod light;
pub mod lighting_group;
pub mod ltc;
mod programs;
pub mod reference;
pub mod specular_albedo;

pub use animation::AnimationParams;
pub use emissive::{EmissiveLights, emissive_lights};
pub use error::LightError;
pub use gpu::{
    ANIMATE_PASS, GpuLights, LightAnimator, LightKinds, MANYLIGHTS_GROUP, PBR_WGSL_PREFIX,
    PreparedAnimation, SHADERS, SpecularTables, animate_program, pbr_program, pbr_wgsl,
};
pub use gpu_reference::{GpuReference, GpuReferenceImage};
pub use light::{
    DEFAULT_SATURATION, INTERIOR_SHRINK, LIGHT_POINT, LIGHT_RECT, LIGHT_SPHERE, LIGHT_SPOT,
    LIGHT_TRIANGLE, Light, LightSet, LightSettings, LightShape, RadiusMode, SPONZA_LIGHT_BOX,
    SpotSettings, interior_box, light_color, spot_direction, validate_lights,
};
pub use manylights_scene::SpotCone;
pub use programs::programs;
pub use reference::{BoundedFalloff, Falloff, Shading};

#[cfg(test)]
mod layout_tests {
    use super::Light;
    use crate::gpu::animate_program;
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn light_layout_matches_wgsl() {
        assert_wgsl_layout!(
            animate_program(),
            "lights/light_set.wgsl",
            Light
                == Light {
                    position: position,
                    radius: radius,
                    color: color,
                    intensity: intensity,
                    direction: direction,
                    kind: kind,
                    sin2_outer: sin2_outer,
                    sin2_inner: sin2_inner,
                    extent: extent,
                    unused: _pad,
                }
        );
    }
}
