//! The light buffer and the animation pass from this crate alone (a plain wgpu device, no
//! renderer): what is uploaded reads back bit for bit, and the GPU moves every light where
//! the CPU's `animated_position` puts it. The workspace's GPU tests check the same through
//! the facade; these run when only `lights` changed (`cargo mutants -p manylights-lights`).

use manylights_gpu::{GpuContext, ShaderLibrary};
use manylights_lights::animation::animated_position;
use manylights_lights::{
    AnimationParams, GpuLights, LightAnimator, LightSet, LightSettings, RadiusMode,
};
use manylights_scene::Aabb;

fn context() -> GpuContext {
    GpuContext::new_headless().unwrap_or_else(|error| {
        // Without an adapter the error (GpuError::NoAdapter) says how to install lavapipe.
        panic!("these tests need a GPU: {error}")
    })
}

fn settings(count: u32) -> LightSettings {
    LightSettings {
        count,
        seed: 11,
        intensity: 0.5,
        radius: RadiusMode::Fixed(1.5),
        saturation: 1.0,
        spots: Default::default(),
        animation: AnimationParams::in_box(Aabb::new(
            glam::Vec3::new(-3.0, 0.0, -2.0),
            glam::Vec3::new(3.0, 2.5, 2.0),
        )),
        shape: manylights_lights::LightShape::Point,
    }
}

#[test]
fn uploaded_lights_read_back_exactly() {
    let context = context();
    for count in [0, 1, 200] {
        let lights = LightSet::generate(&settings(count)).expect("lights");
        let gpu = GpuLights::upload(&context, &lights).expect("upload");
        assert_eq!(gpu.count, count);
        assert_eq!(gpu.read(&context).expect("read"), lights.lights);
    }
}

/// Positions within 1e-4 m of the CPU's (the GPU's noise is the same f32 arithmetic, but
/// may fuse multiply-adds); radius, colour and intensity untouched; at several times,
/// including one far from zero.
#[test]
fn gpu_animation_matches_the_cpu() {
    let context = context();
    let mut animator = LightAnimator::new(&context, &ShaderLibrary::from_env()).expect("animator");
    // More lights than one workgroup of 64, and not a multiple of it.
    let settings = settings(130);
    let lights = LightSet::generate(&settings).expect("lights");
    let gpu = GpuLights::upload(&context, &lights).expect("upload");
    for time in [0.37f32, 12.5, 300.0] {
        context
            .scoped("animating the lights", || {
                let mut encoder = context.device.create_command_encoder(&Default::default());
                animator
                    .prepare(&context, &gpu, &settings, time)
                    .record(&mut encoder, None);
                context.queue.submit([encoder.finish()]);
            })
            .expect("the animation passes wgpu's validation");
        let moved = gpu.read(&context).expect("read");
        let mut largest_move = 0.0f32;
        for (index, (after, before)) in moved.iter().zip(&lights.lights).enumerate() {
            let expected =
                animated_position(&settings.animation, settings.seed, index as u32, time);
            let position = glam::Vec3::from_array(after.position);
            assert!(
                (position - expected).abs().max_element() <= 1e-4,
                "t = {time}, light {index}: GPU {position}, CPU {expected}"
            );
            assert_eq!(
                (after.radius, after.color, after.intensity),
                (before.radius, before.color, before.intensity),
                "t = {time}, light {index}: only the position moves"
            );
            largest_move = largest_move.max(position.distance(before.position.into()));
        }
        assert!(largest_move > 0.01, "t = {time}: no light moved");
    }
}
