//! One frame per pipeline, timed by the GPU's timestamps (`iter_custom` returns the GPU
//! total, not wall time). On lavapipe in CI these run once as a smoke test
//! (`cargo test --benches`); on the GPU machine for real (`cargo bench -p manylights`).

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use manylights::gpu::GpuContext;
use manylights::{
    FrameSettings, GBufferLayout, LightingPath, LoadedScene, PipelineSettings, Renderer,
};

fn gpu_frames(c: &mut Criterion) {
    let scene = LoadedScene::load("sponza").expect("sponza");
    let mut settings = FrameSettings::for_scene(&scene);
    settings.view.size = (640, 360);
    settings.lights.count = 1000;
    let context = GpuContext::new_headless()
        .expect("a GPU adapter (lavapipe: apt-get install mesa-vulkan-drivers)");
    let mut renderer = Renderer::new(context, scene).expect("renderer");
    let mut group = c.benchmark_group("gpu_frame");
    group.sample_size(10);
    for (name, pipeline) in [
        ("naive", PipelineSettings::naive(Default::default())),
        ("forward_plus", PipelineSettings::forward_plus()),
        (
            "deferred_compact_compute",
            PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Compute),
        ),
        (
            "deferred_compact_fragment",
            PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Fragment),
        ),
    ] {
        settings.pipeline = pipeline;
        renderer.render_frame(&settings).expect("warm-up frame");
        group.bench_function(name, |b| {
            b.iter_custom(|iterations| {
                let mut gpu = Duration::ZERO;
                for _ in 0..iterations {
                    let stats = renderer.render_frame_timed(&settings).expect("frame");
                    gpu += Duration::from_secs_f64(stats.timings.total().unwrap_or(0.0) / 1000.0);
                }
                gpu
            });
        });
    }
    group.finish();
}

criterion_group!(benches, gpu_frames);
criterion_main!(benches);
