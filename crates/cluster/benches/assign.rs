//! CPU reference assignment at 1k, 10k and 100k lights in Sponza's light box, seen from
//! the reference camera at 1920x1080 with the default grid: against the grid's boxes, and
//! against boxes like a frame's visible samples give (each tile sees a surface in 3 of its
//! 48 slices; the others are empty).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use manylights_cluster::{ClusterGrid, ClusterSettings, assign_lights, view_spheres};
use manylights_lights::{AnimationParams, LightSet, LightSettings, RadiusMode, SPONZA_LIGHT_BOX};

fn bench_assignment(c: &mut Criterion) {
    let view = glam::camera::rh::view::look_at_mat4(
        Vec3::new(-7.0, 2.0, 0.0),
        Vec3::new(10.0, 2.0, 0.0),
        Vec3::Y,
    );
    let projection =
        glam::camera::rh::proj::directx::perspective(45f32.to_radians(), 16.0 / 9.0, 0.1, 1000.0);
    let scene_view = SPONZA_LIGHT_BOX.transformed(&view);
    let grid = ClusterGrid::new(
        &ClusterSettings::default(),
        (1920, 1080),
        projection,
        0.1,
        1000.0,
        Some(scene_view),
    )
    .expect("grid");
    let grid_bounds = grid.cluster_bounds();
    // A surface in every tile, 3 slices deep somewhere along the depth range.
    let visible_like: Vec<manylights_scene::Aabb> = grid_bounds
        .iter()
        .enumerate()
        .map(|(i, aabb)| {
            let at = grid.cluster_of_flat(i as u32);
            let first = 10 + (at.x + at.y) % 30;
            if (first..first + 3).contains(&at.z) {
                *aabb
            } else {
                manylights_scene::Aabb::EMPTY
            }
        })
        .collect();
    let mut group = c.benchmark_group("cpu_assign");
    group.sample_size(10);
    for count in [1_000u32, 10_000, 100_000] {
        let lights = LightSet::generate(&LightSettings {
            count,
            seed: 1,
            intensity: 0.2,
            radius: RadiusMode::Fixed(2.0),
            saturation: manylights_lights::DEFAULT_SATURATION,
            spots: Default::default(),
            animation: AnimationParams::in_box(SPONZA_LIGHT_BOX),
            shape: manylights_lights::LightShape::Point,
        })
        .expect("lights");
        let spheres = view_spheres(&view, &lights.lights);
        for (boxes, bounds) in [("grid", &grid_bounds), ("visible-like", &visible_like)] {
            group.bench_with_input(BenchmarkId::new(boxes, count), &spheres, |b, spheres| {
                b.iter(|| assign_lights(&grid, bounds, spheres));
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_assignment);
criterion_main!(benches);
