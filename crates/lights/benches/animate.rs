//! CPU light animation (the twin of the GPU pass) and light set generation.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use manylights_lights::animation::animated_position;
use manylights_lights::{AnimationParams, LightSet, LightSettings, RadiusMode, SPONZA_LIGHT_BOX};

fn animation(c: &mut Criterion) {
    let params = AnimationParams::in_box(SPONZA_LIGHT_BOX);
    let mut group = c.benchmark_group("cpu_lights");
    group.sample_size(10);
    for count in [1_000u32, 100_000] {
        group.bench_with_input(BenchmarkId::new("animate", count), &count, |b, &count| {
            b.iter(|| {
                (0..count)
                    .map(|i| animated_position(&params, 1, i, 2.5))
                    .fold(0.0f32, |acc, p| acc + p.x)
            })
        });
        group.bench_with_input(BenchmarkId::new("generate", count), &count, |b, &count| {
            b.iter(|| {
                LightSet::generate(&LightSettings {
                    count,
                    seed: 1,
                    intensity: 0.2,
                    radius: RadiusMode::Fixed(2.0),
                    saturation: manylights_lights::DEFAULT_SATURATION,
                    spots: Default::default(),
                    animation: params,
                    shape: manylights_lights::LightShape::Point,
                })
                .expect("lights")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, animation);
criterion_main!(benches);
