//! `manylights-cluster` on its own, as another engine would use it: a plain wgpu device
//! (`manylights-gpu` makes it), a camera of your own, lights from `manylights-lights`, then
//! exact light lists built on the GPU and their statistics, checked against the crate's CPU
//! reference. No renderer, no facade.
//!
//! ```sh
//! cargo run -p manylights-cluster --example standalone_clusters
//! ```

use glam::Vec3;
use glam::camera::rh::{proj::directx, view::look_at_mat4};
use manylights_cluster::{
    ClusterFrame, ClusterGrid, ClusterSettings, GpuClusters, GpuListStatistics, assign_lights,
};
use manylights_gpu::{GpuContext, ShaderLibrary, ViewBinding, ViewUniform};
use manylights_lights::{AnimationParams, GpuLights, LightSet, LightSettings, RadiusMode};
use manylights_scene::Aabb;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 1. A device, the shader library and the camera's bind group.
    let context = GpuContext::new_headless()?;
    println!("adapter: {}", context.summary);
    let library = ShaderLibrary::Embedded;
    let view_binding = ViewBinding::new(&context);

    // 2. A camera looking into a 8 x 3 x 10 m room, 1280x720.
    let (screen, near, far) = ((1280, 720), 0.1, 50.0);
    let eye = Vec3::new(0.0, 1.6, 7.0);
    let view = look_at_mat4(eye, Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
    let projection = directx::perspective(60f32.to_radians(), 1280.0 / 720.0, near, far);
    view_binding.update(
        &context,
        &ViewUniform::new(view, projection, eye, screen, near, far),
    );
    let room = Aabb::new(Vec3::new(-4.0, 0.0, -5.0), Vec3::new(4.0, 3.0, 5.0));

    // 3. 10,000 lights of radius 1 m in the room.
    let lights = LightSet::generate(&LightSettings {
        count: 10_000,
        seed: 1,
        intensity: 0.2,
        radius: RadiusMode::Fixed(1.0),
        saturation: 1.0,
        spots: Default::default(),
        animation: AnimationParams::in_box(room),
        shape: manylights_lights::LightShape::Point,
    })?;
    let gpu_lights = GpuLights::upload(&context, &lights)?;

    // 4. The grid (depth range fitted to the room) and the lists, built on the GPU.
    let grid = ClusterGrid::new(
        &ClusterSettings::default(),
        screen,
        projection,
        near,
        far,
        Some(room.transformed(&view)),
    )?;
    let mut clusters = GpuClusters::new(&context, &library, &view_binding)?;
    let mut statistics = GpuListStatistics::new(&context, &library, &view_binding)?;
    // The frame's clustering, as one value. No depth buffer here: every cluster keeps the
    // grid's box (a renderer passes its G-buffer's or pre-pass's depth so that only what is
    // seen is listed).
    let frame = ClusterFrame::new(grid);
    let mut assign = |clusters: &mut GpuClusters| -> Result<(), Box<dyn std::error::Error>> {
        // Rebuilds only what changed since the last frame (here: buffers after growth).
        clusters.prepare(&context, &frame, &gpu_lights, None)?;
        let prepared_statistics = statistics.prepare(&context, clusters, None)?;
        let mut encoder = context.device.create_command_encoder(&Default::default());
        // The prepared passes record without failing; their proof is what a shading pass
        // reading the lists would take.
        let _lists = clusters
            .assignment()?
            .record(&mut encoder, &view_binding, None);
        if let Some(prepared) = prepared_statistics {
            prepared.record(&mut encoder, &view_binding, None);
        }
        context.queue.submit([encoder.finish()]);
        clusters.after_submit();
        statistics.after_submit();
        Ok(())
    };
    assign(&mut clusters)?;
    // A list buffer too small for this frame is grown (a renderer learns it a frame or two
    // later without waiting; this example waits), then the frame is assigned again.
    if clusters.wait_and_grow(&context)?.is_some() {
        assign(&mut clusters)?;
    }

    // 5. Statistics from the GPU, and the lists against the CPU reference.
    let stats = statistics
        .wait(&context)?
        .ok_or("the statistics were recorded")?;
    println!(
        "{} clusters ({:?} tiles x {} slices), {} lights",
        grid.cluster_count(),
        (grid.dims.x, grid.dims.y),
        grid.dims.z,
        lights.lights.len()
    );
    println!("GPU statistics: {stats}");
    let gpu_lists = clusters.read_lists(&context)?;
    let spheres = clusters.read_view_lights(&context, gpu_lights.count)?;
    let cpu_lists = assign_lights(&grid, &grid.cluster_bounds(), &spheres);
    let same = (0..cpu_lists.cluster_count()).all(|c| gpu_lists.list(c) == cpu_lists.list(c));
    println!(
        "GPU lists {} the CPU reference ({} entries)",
        if same { "equal" } else { "DIFFER FROM" },
        cpu_lists.total()
    );
    if !same {
        return Err("the GPU lists differ from the CPU reference".into());
    }
    Ok(())
}
