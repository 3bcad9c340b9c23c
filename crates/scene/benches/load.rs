//! Scene loading on the CPU: Sponza from glTF and from OBJ, and the procedural scenes.

use criterion::{Criterion, criterion_group, criterion_main};
use manylights_scene::{load, procedural};

fn loading(c: &mut Criterion) {
    let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/sponza");
    let mut group = c.benchmark_group("scene_load");
    group.sample_size(10);
    group.bench_function("sponza_gltf", |b| {
        b.iter(|| load(assets.join("sponza.gltf")).expect("sponza.gltf"))
    });
    group.bench_function("sponza_obj", |b| {
        b.iter(|| load(assets.join("sponza.obj")).expect("sponza.obj"))
    });
    group.bench_function("cornell", |b| b.iter(procedural::cornell));
    group.bench_function("pillars_16x32", |b| {
        b.iter(|| {
            procedural::pillars(procedural::PillarsParams {
                grid: 16,
                segments: 32,
            })
        })
    });
    group.finish();
}

criterion_group!(benches, loading);
criterion_main!(benches);
