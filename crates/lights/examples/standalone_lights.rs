//! `manylights-lights` on its own: generate a light set, upload it, animate it on the GPU
//! and check the positions against the CPU's animation (the same function of seed, index
//! and time). No renderer, no facade.
//!
//! ```sh
//! cargo run -p manylights-lights --example standalone_lights
//! ```

use manylights_gpu::{GpuContext, ShaderLibrary};
use manylights_lights::animation::animated_position;
use manylights_lights::{
    AnimationParams, GpuLights, LightAnimator, LightSet, LightSettings, RadiusMode,
};
use manylights_scene::Aabb;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let context = GpuContext::new_headless()?;
    println!("adapter: {}", context.summary);
    let settings = LightSettings {
        count: 50_000,
        seed: 7,
        intensity: 0.2,
        // The radius where the light's luminance falls to 0.05: sqrt(0.2 / 0.05) = 2 m.
        radius: RadiusMode::LuminanceThreshold(0.05),
        saturation: 1.0,
        spots: Default::default(),
        animation: AnimationParams::in_box(Aabb::new(
            glam::Vec3::new(-10.0, 0.0, -5.0),
            glam::Vec3::new(10.0, 8.0, 5.0),
        )),
        shape: manylights_lights::LightShape::Point,
    };
    let lights = LightSet::generate(&settings)?;
    let gpu_lights = GpuLights::upload(&context, &lights)?;
    let mut animator = LightAnimator::new(&context, &ShaderLibrary::Embedded)?;
    let time = 2.5;
    let mut encoder = context.device.create_command_encoder(&Default::default());
    animator
        .prepare(&context, &gpu_lights, &settings, time)
        .record(&mut encoder, None);
    context.queue.submit([encoder.finish()]);
    let moved = gpu_lights.read(&context)?;
    let largest_difference = moved
        .iter()
        .enumerate()
        .map(|(index, light)| {
            let cpu = animated_position(&settings.animation, settings.seed, index as u32, time);
            (glam::Vec3::from_array(light.position) - cpu)
                .abs()
                .max_element()
        })
        .fold(0.0f32, f32::max);
    println!(
        "{} lights of radius {:.2} m animated to t = {time} s on the GPU; first at {:?}",
        moved.len(),
        lights.lights[0].radius,
        moved[0].position
    );
    println!("largest difference from the CPU animation: {largest_difference:.2e} m");
    if largest_difference > 1e-4 {
        return Err(format!("GPU and CPU animation differ by {largest_difference} m").into());
    }
    Ok(())
}
