use manylights::{
    DebugView, FrameSettings, GBufferLayout, LightingPath, LoadedScene, PipelineKind, Renderer,
};
fn main() {
    let scene = LoadedScene::load("cornell").unwrap();
    let mut s = FrameSettings::for_scene(&scene);
    s.size = (32, 24);
    s.light_count = 64;
    let mode = std::env::args().nth(1).unwrap_or_default();
    match mode.as_str() {
        "fp" => s.pipeline = PipelineKind::ForwardPlus,
        "fpnopre" => {
            s.pipeline = PipelineKind::ForwardPlus;
            s.depth_prepass = false
        }
        "def" => s.pipeline = PipelineKind::Deferred,
        "deffrag" => {
            s.pipeline = PipelineKind::Deferred;
            s.lighting = LightingPath::Fragment;
            s.gbuffer = GBufferLayout::Packed
        }
        "heat" => {
            s.pipeline = PipelineKind::ForwardPlus;
            s.debug_view = DebugView::ClusterHeatmap { max_lights: 64.0 }
        }
        "v9" => {
            s.camera.reverse_z = true;
            s.falloff = manylights::lights::Falloff::InverseSquare;
            s.light_count = 700
        }
        "v10" => {
            s.pipeline = PipelineKind::ForwardPlus;
            s.camera.reverse_z = true;
            s.cluster.tiles = manylights::cluster::TileSpec::Count { x: 8, y: 4 };
            s.cluster.z_slices = 16;
            s.light_count = 700
        }
        "fp700" => {
            s.pipeline = PipelineKind::ForwardPlus;
            s.light_count = 700
        }
        "stats" => {
            s.pipeline = PipelineKind::ForwardPlus;
            s.cluster_stats = true
        }
        _ => {}
    }
    let mut r = Renderer::new(manylights::gpu::GpuContext::new_headless().unwrap(), scene).unwrap();
    let ring = manylights::lights::LightSet {
        lights: (0..50)
            .map(|i| manylights::lights::PointLight {
                position: [i as f32 * 0.02, 1.0, 0.0],
                radius: 2.0,
                color: [1.0; 3],
                intensity: 0.3,
            })
            .collect(),
    };
    let sw = std::env::args().nth(2).unwrap_or_default();
    for i in 0..2000 {
        s.time = i as f32 / 60.0;
        if i % 4 == 0 {
            let k = (i / 4) % 2 == 1;
            match sw.as_str() {
                "size" => s.size = if k { (40, 32) } else { (32, 24) },
                "fixed" => {
                    if k {
                        r.set_fixed_lights(&ring).unwrap()
                    } else {
                        r.use_generated_lights()
                    }
                }
                "grid" => s.cluster.z_slices = if k { 16 } else { 48 },
                "count" => s.light_count = if k { 0 } else { 2000 },
                "report" => {
                    let _ = r.context.device.generate_allocator_report();
                }
                "idle" => {
                    r.context.wait_idle("x").unwrap();
                }
                "debug" => {
                    s.debug_view = if k {
                        DebugView::Albedo
                    } else {
                        DebugView::None
                    }
                }
                _ => {}
            }
        }
        r.render_frame(&s).unwrap();
        if i % 500 == 0 {
            print!(
                "{i}:{:.1} ",
                manylights::soak::resident_bytes().unwrap() as f64 / 1048576.0
            );
        }
    }
    println!(
        "{mode} end {:.1}",
        manylights::soak::resident_bytes().unwrap() as f64 / 1048576.0
    );
}
