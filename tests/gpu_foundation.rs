//! The GPU foundation's contracts: errors come back as values, limits are checked before
//! creation, adapter choice by name fails clearly, the timer reports per-pass times (or
//! says it cannot), and float targets read back exactly.

use manylights_gpu::targets::read_f32_rgba;
use manylights_gpu::{AdapterRequest, GpuContext, GpuError, GpuTimer, GpuTimings, RenderTargets};
use manylights_tests::gpu;

#[test]
fn validation_errors_are_returned_not_printed() {
    let context = gpu();
    // MAP_READ may only be combined with COPY_DST: a validation error.
    let result = context.scoped("creating an invalid buffer", || {
        context
            .device
            .create_buffer(&manylights_gpu::wgpu::BufferDescriptor {
                label: Some("invalid"),
                size: 16,
                usage: manylights_gpu::wgpu::BufferUsages::MAP_READ
                    | manylights_gpu::wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
    });
    match result {
        Err(GpuError::Validation { context, message }) => {
            assert_eq!(context, "creating an invalid buffer");
            assert!(!message.is_empty());
        }
        other => panic!("expected a validation error, got {other:?}"),
    }
    assert!(
        context.take_uncaptured_errors().is_empty(),
        "the scope captured it"
    );
}

#[test]
fn oversized_targets_are_refused_before_creation() {
    let context = gpu();
    let max = context.device.limits().max_texture_dimension_2d;
    let error = RenderTargets::new(&context, (max + 1, 4)).expect_err("too wide");
    assert!(
        matches!(
            error,
            GpuError::LimitExceeded {
                limit: "max_texture_dimension_2d",
                ..
            }
        ),
        "{error}"
    );
    let error = RenderTargets::new(&context, (0, 4)).expect_err("zero width");
    assert!(error.to_string().contains("zero-sized"), "{error}");
    let error = context
        .check_buffer_size("test", u64::MAX, true)
        .expect_err("huge buffer");
    assert!(matches!(error, GpuError::LimitExceeded { .. }), "{error}");
}

#[test]
fn unknown_adapter_name_is_a_clear_error() {
    let request = AdapterRequest {
        name: Some("no-such-gpu-anywhere".into()),
        ..AdapterRequest::from_env()
    };
    let error = GpuContext::new_headless_with(&request).expect_err("no adapter has that name");
    let message = error.to_string();
    assert!(
        message.contains("no-such-gpu-anywhere") && message.contains("available"),
        "{message}"
    );
}

/// Every pass a frame times comes back, in order, however many there are. The timer makes
/// its queries before a frame is recorded, never while: 35 passes overfill the 32 it holds
/// at first, so that frame times 32 and names the 3 it left untimed, and the next frame,
/// prepared, times all 35 (three query sets).
#[test]
fn timer_reports_named_passes_or_says_it_cannot() {
    let context = gpu();
    let targets = RenderTargets::new(&context, (64, 48)).expect("targets");
    let mut timer = GpuTimer::new(&context);
    assert_eq!(timer.supported(), context.summary.timestamps);
    let names: Vec<manylights_gpu::PassName> = (0..35)
        .map(|i| manylights_gpu::PassName::new(Box::leak(format!("clear {i}").into_boxed_str())))
        .collect();
    let first_capacity = timer.capacity();
    for frame in 0..2 {
        timer.prepare();
        timer.begin_frame();
        let mut encoder = context.device.create_command_encoder(&Default::default());
        for &name in &names {
            clear_timed(&mut encoder, &targets, &mut timer, name);
        }
        timer.resolve(&mut encoder);
        context.queue.submit([encoder.finish()]);
        timer.after_submit();
        let timings = timer.wait_latest(&context).expect("timings");
        let GpuTimings::Measured(passes) = timings else {
            assert!(!context.summary.timestamps);
            assert!(timer.untimed().is_empty());
            return;
        };
        assert!(context.summary.timestamps);
        let timed: Vec<_> = passes.iter().map(|p| p.name).collect();
        if frame == 0 {
            assert_eq!(first_capacity, 32);
            assert_eq!(
                timed,
                names[..32],
                "the first frame times what the queries hold"
            );
            assert_eq!(
                timer.untimed(),
                &names[32..],
                "and names the passes it could not"
            );
        } else {
            assert_eq!(timed, names, "the next frame, prepared, times every pass");
            assert!(timer.untimed().is_empty());
            assert!(timer.capacity() >= 35);
        }
        assert!(
            passes
                .iter()
                .all(|p| p.milliseconds >= 0.0 && p.milliseconds < 1000.0)
        );
    }
    // The HDR target holds values above 1 exactly (half floats: 0.25, 0.5, 2.0 are exact).
    let texels = read_f32_rgba(&context, &targets.hdr.texture).expect("readback");
    assert_eq!(texels.len(), 64 * 48);
    assert!(texels.iter().all(|t| *t == [0.25, 0.5, 2.0, 1.0]));
}

/// A render pass that clears the HDR target, timed under `name`.
fn clear_timed(
    encoder: &mut manylights_gpu::wgpu::CommandEncoder,
    targets: &RenderTargets,
    timer: &mut GpuTimer,
    name: manylights_gpu::PassName,
) {
    let _pass = encoder.begin_render_pass(&manylights_gpu::wgpu::RenderPassDescriptor {
        label: Some(name.as_str()),
        color_attachments: &[Some(manylights_gpu::wgpu::RenderPassColorAttachment {
            view: &targets.hdr.view,
            depth_slice: None,
            resolve_target: None,
            ops: manylights_gpu::wgpu::Operations {
                load: manylights_gpu::wgpu::LoadOp::Clear(manylights_gpu::wgpu::Color {
                    r: 0.25,
                    g: 0.5,
                    b: 2.0,
                    a: 1.0,
                }),
                store: manylights_gpu::wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: timer.render_pass(name),
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// `render_frame_timed` returns the times of the frame it rendered, every time: even when
/// the GPU finishes before `render_frame` collects finished times (tiny frames on a fast
/// device), which once left the wait with nothing in flight and an empty list.
#[test]
fn every_timed_frame_has_its_pass_times() {
    use manylights::{FrameSettings, LoadedScene, PipelineSettings, Renderer};
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (16, 12);
    settings.lights.count = 1;
    settings.pipeline = PipelineSettings::forward_plus();
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    for frame in 0..40 {
        settings.lights.time = frame as f32 * 0.01;
        let stats = renderer.render_frame_timed(&settings).expect("frame");
        match &stats.timings {
            GpuTimings::Unsupported => return,
            GpuTimings::Measured(passes) => assert!(
                passes
                    .iter()
                    .any(|p| p.name == manylights::forward_plus::SHADING_PASS),
                "frame {frame}: passes {passes:?}"
            ),
        }
        assert_eq!(stats.timed_frame, Some(stats.frame));
    }
}

/// The frame with every optional pass on (animated lights, the tree far field's build and
/// cuts, the visibility buffer's raster, classification and resolve, every assignment step,
/// tiles lighting, list statistics, automatic exposure and tonemap: 20 passes, more than one
/// of the timer's query sets) has a time for every pass, tonemap included, and its total
/// is their sum. The timer once held 16 and dropped the tonemap from the printed timings.
#[test]
fn the_frame_with_every_pass_on_times_every_pass() {
    use manylights::cluster::{FarField, FarFieldMethod, passes as cluster_passes};
    use manylights::{
        AutoExposure, Exposure, FrameSettings, GBufferLayout, LightingPath, LoadedScene,
        PipelineSettings, Renderer,
    };
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (16, 12);
    settings.lights.count = 8;
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Visibility, LightingPath::Tiles);
    settings
        .set_falloff(
            manylights::lights::Falloff::InverseSquare,
            Some(FarField::new(FarFieldMethod::Tree)),
        )
        .expect("a far field");
    settings.pipeline.set_list_statistics(true, false);
    settings.post.exposure = Exposure::Auto(AutoExposure::CONVERGE_NOW);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let stats = renderer.render_frame_timed(&settings).expect("frame");
    let GpuTimings::Measured(passes) = &stats.timings else {
        panic!("lavapipe and every GPU the lab runs on time passes; this adapter does not");
    };
    let timed: Vec<_> = passes.iter().map(|p| p.name).collect();
    let expected = [
        manylights::lights::ANIMATE_PASS,
        cluster_passes::FAR_FIELD_NODES,
        cluster_passes::FAR_FIELD_CUTS,
        manylights::deferred::VISIBILITY_PASS,
        manylights::deferred::CLASSIFY_PASS,
        manylights::deferred::RESOLVE_PASS,
        cluster_passes::FILL_LISTS,
        manylights::deferred::LIGHTING_TILES_PASS,
        cluster_passes::STATISTICS,
        manylights::gpu::post::AUTO_EXPOSURE_PASS,
        manylights::gpu::post::TONEMAP_PASS,
    ];
    for name in expected {
        assert!(timed.contains(&name), "{name} has no time: {timed:?}");
    }
    assert!(timed.len() > 16, "{} passes: {timed:?}", timed.len());
    assert_eq!(timed.last(), Some(&manylights::gpu::post::TONEMAP_PASS));
    let sum: f64 = passes.iter().map(|p| p.milliseconds).sum();
    assert_eq!(stats.timings.total(), Some(sum));
}

/// One specialization cache (issue 59): every pipeline is built for a key naming what it is
/// specialized for, and kept. Moving dials away and back (reverse-Z, the BRDF, MSAA,
/// transparency, the pipeline) builds every pipeline once: the second round creates none.
/// Before, reverse-Z or a BRDF switch dropped every pipeline and MSAA dropped a pipeline's
/// own, so the second round compiled them all again.
#[test]
fn dials_moved_away_and_back_build_each_pipeline_once() {
    use manylights::lights::{Falloff, Shading};
    use manylights::{FrameSettings, LoadedScene, PipelineSettings, Renderer, Transparency};
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut base = FrameSettings {
        pipeline: PipelineSettings::forward_plus(),
        ..FrameSettings::for_scene(&loaded)
    };
    base.view.size = (16, 12);
    base.lights.count = 8;
    let mut dials: Vec<FrameSettings> = vec![base.clone()];
    let mut with = |change: &dyn Fn(&mut FrameSettings)| {
        let mut settings = base.clone();
        change(&mut settings);
        dials.push(settings);
    };
    with(&|s| s.view.camera.reverse_z = !s.view.camera.reverse_z);
    with(&|s| {
        s.shading = match s.shading {
            Shading::Pbr => Shading::BlinnPhong,
            Shading::BlinnPhong => Shading::Pbr,
        }
    });
    with(&|s| s.view.msaa = 4);
    with(&|s| s.transparency = Transparency::Weighted);
    with(&|s| s.post.anti_aliasing = manylights::AntiAliasing::Taa);
    with(&|s| s.pipeline = PipelineSettings::naive(Falloff::default()));
    with(&|s| {
        s.pipeline = PipelineSettings::naive(Falloff::default());
        s.view.msaa = 4;
    });
    with(&|s| s.pipeline = PipelineSettings::default());
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let mut created_by_round = Vec::new();
    for _round in 0..2 {
        let before = renderer.context().created();
        for settings in &dials {
            renderer.render_frame(settings).expect("frame");
        }
        created_by_round.push(renderer.context().created().pipelines - before.pipelines);
    }
    assert!(
        created_by_round[0] > dials.len() as u64,
        "the first round built too few pipelines to have built each dial's: {created_by_round:?}"
    );
    assert_eq!(
        created_by_round[1], 0,
        "moving the dials round a second time built pipelines again"
    );
}

/// The prepared frame's promise: once a frame's settings have been rendered, rendering them
/// again (the lights animated on) creates no bind group and no pipeline. Every creation goes
/// through the context's counted constructors, so a pass that built its bind groups while
/// recording, or compiled a pipeline for a frame it had already seen, fails here. Every pass
/// a frame plan can hold, each in a pipeline that has it: shadows (exact, a ray budget in
/// the loop, the forward shadow pass, the filter and its history after deferred's compute
/// lighting), the far field, the visibility buffer, statistics, automatic exposure, a debug
/// view, MSAA, temporal anti-aliasing, bloom, and blended surfaces (sorted and weighted, on a scene that has them).
#[test]
fn an_unchanged_frame_creates_no_bind_group_or_pipeline() {
    use manylights::cluster::{FarField, FarFieldMethod};
    use manylights::lights::Falloff;
    use manylights::{
        AntiAliasing, AutoExposure, Exposure, FrameSettings, GBufferLayout, LightingPath,
        LoadedScene, PipelineSettings, Shadows, Transparency,
    };
    let frames_of = |scene: &LoadedScene, changes: &[(&str, &SettingsChange)]| {
        let mut base = FrameSettings::for_scene(scene);
        base.view.size = (16, 12);
        base.lights.count = 8;
        changes
            .iter()
            .map(|(name, change)| {
                let mut settings = base.clone();
                change(&mut settings);
                (name.to_string(), settings)
            })
            .collect::<Vec<_>>()
    };
    let cornell = LoadedScene::load("cornell").expect("cornell");
    let cornell_frames = frames_of(
        &cornell,
        &[
            ("naive, exact shadows", &|s| {
                s.pipeline = PipelineSettings::naive(Falloff::default());
                s.shadows.mode = Shadows::Exact;
            }),
            ("naive, the shadow pass filtered", &|s| {
                s.pipeline = PipelineSettings::naive(Falloff::default());
                s.shadows.mode = Shadows::RaysSpatial(1);
            }),
            ("naive, 4x MSAA", &|s| {
                s.pipeline = PipelineSettings::naive(Falloff::default());
                s.view.msaa = 4;
            }),
            ("Forward+, statistics", &|s| {
                s.pipeline = PipelineSettings::forward_plus();
                s.pipeline.set_list_statistics(true, false);
            }),
            ("Forward+, a debug view", &|s| {
                s.pipeline = PipelineSettings::forward_plus()
                    .with_debug_view_named("heatmap")
                    .expect("Forward+ draws the heatmap");
            }),
            ("Forward+, a ray budget in the loop", &|s| {
                s.pipeline = PipelineSettings::forward_plus();
                s.shadows.mode = Shadows::Rays(4);
            }),
            (
                "Forward+, the shadow pass with its filter and history",
                &|s| {
                    s.pipeline = PipelineSettings::forward_plus();
                    s.shadows.mode = Shadows::RaysTemporal(1);
                },
            ),
            ("Forward+, 4x MSAA with exact shadows", &|s| {
                s.pipeline = PipelineSettings::forward_plus();
                s.view.msaa = 4;
                s.shadows.mode = Shadows::Exact;
            }),
            ("deferred's default, exact shadows", &|s| {
                s.shadows.mode = Shadows::Exact
            }),
            ("deferred's default, the filter and history", &|s| {
                s.shadows.mode = Shadows::RaysTemporal(2)
            }),
            ("deferred fragment lighting", &|s| {
                s.pipeline =
                    PipelineSettings::deferred(GBufferLayout::Full, LightingPath::Fragment);
            }),
            ("every optional pass", &|s| {
                s.pipeline =
                    PipelineSettings::deferred(GBufferLayout::Visibility, LightingPath::Tiles);
                s.set_falloff(
                    Falloff::InverseSquare,
                    Some(FarField::new(FarFieldMethod::Tree)),
                )
                .expect("a far field");
                s.shadows.mode = Shadows::Exact;
                s.pipeline.set_list_statistics(true, false);
                s.post.exposure = Exposure::Auto(AutoExposure::CONVERGE_NOW);
            }),
            ("naive, temporal anti-aliasing", &|s| {
                s.pipeline = PipelineSettings::naive(Falloff::default());
                s.post.anti_aliasing = AntiAliasing::Taa;
            }),
            ("deferred, temporal anti-aliasing and bloom", &|s| {
                // Large enough for a level of bloom's chain.
                s.view.size = (32, 24);
                s.post.anti_aliasing = AntiAliasing::Taa;
                s.post.bloom = 0.1;
            }),
        ],
    );
    unchanged_frames_create_nothing(cornell, &cornell_frames);
    // Blended surfaces: the glass scene's panes and sparks.
    let glass = LoadedScene::load("glass").expect("the glass scene");
    let glass_frames = frames_of(
        &glass,
        &[
            ("naive, weighted blending", &|s| {
                s.pipeline = PipelineSettings::naive(Falloff::default());
                s.transparency = Transparency::Weighted;
            }),
            ("Forward+, sorted blending with 4x MSAA", &|s| {
                s.pipeline = PipelineSettings::forward_plus();
                s.view.msaa = 4;
            }),
            ("deferred, weighted blending with exact shadows", &|s| {
                s.transparency = Transparency::Weighted;
                s.shadows.mode = Shadows::Exact;
            }),
        ],
    );
    unchanged_frames_create_nothing(glass, &glass_frames);
}

/// A change to a frame's settings, named for the pass it adds.
type SettingsChange = dyn Fn(&mut manylights::FrameSettings);

/// Renders each of `frames` on one renderer of `scene`: twice to build what it needs (and
/// grow the light lists), then twice more with the lights animated on, which must create
/// nothing.
fn unchanged_frames_create_nothing(
    scene: manylights::LoadedScene,
    frames: &[(String, manylights::FrameSettings)],
) {
    use manylights::Renderer;
    let mut renderer = Renderer::new(gpu(), scene).expect("renderer");
    for (name, settings) in frames {
        for _ in 0..2 {
            renderer
                .render_frame_timed(settings)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let before = renderer.context().created();
        for frame in 0..2 {
            let mut settings = settings.clone();
            settings.lights.time += 0.1 * (frame + 1) as f32;
            renderer
                .render_frame_timed(&settings)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let after = renderer.context().created();
        assert!(
            before.bind_groups > 0 && before.pipelines > 0,
            "the context counts nothing: {before:?}"
        );
        assert_eq!(
            after,
            before,
            "{name}: two unchanged frames created {} bind groups and {} pipelines",
            after.bind_groups - before.bind_groups,
            after.pipelines - before.pipelines
        );
    }
}

/// An engine's own device (issue 78's first part): the engine creates its instance,
/// adapter, device and queue, merges what the library needs into its descriptor, and
/// keeps its callbacks. The library renders a frame on that device, its validation
/// errors come back to it as values, and the engine's uncaptured-error callback sees none
/// of them (and still sees the engine's own). A device short of what the library needs is
/// refused by the limit's name, with both values.
#[test]
fn an_engines_own_device_keeps_its_callbacks_and_a_short_one_is_refused_by_name() {
    use manylights_gpu::{DeviceRequirements, block_on, wgpu};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = block_on(async {
        instance
            .request_adapter(&wgpu::RequestAdapterOptions::default())
            .await
            .map_err(|e| GpuError::Unsupported(e.to_string()))
    })
    .unwrap_or_else(|e| manylights_tests::fail_without_gpu(e));
    let engine_device = |needs: &DeviceRequirements| {
        let mut descriptor = wgpu::DeviceDescriptor {
            label: Some("the engine's device"),
            ..Default::default()
        };
        needs.merge_into(&mut descriptor, &adapter);
        block_on(async {
            adapter
                .request_device(&descriptor)
                .await
                .map_err(|e| GpuError::Unsupported(e.to_string()))
        })
        .expect("the engine's device")
    };
    let needs = DeviceRequirements::minimum();
    let (device, queue) = engine_device(&needs);
    let engine_errors = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&engine_errors);
    device.on_uncaptured_error(Arc::new(move |_| {
        counter.fetch_add(1, Ordering::SeqCst);
    }));
    let context = GpuContext::from_device(
        instance.clone(),
        adapter.clone(),
        device.clone(),
        queue,
        &needs,
    )
    .expect("a device made with the library's requirements is enough");
    assert!(context.engine_owned());
    // The library's refusal of a bad input: a validation error, returned to the caller.
    let invalid = context.scoped("an invalid buffer", || {
        context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("invalid"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        })
    });
    assert!(
        matches!(invalid, Err(GpuError::Validation { .. })),
        "{invalid:?}"
    );
    // A whole frame of the library's on the engine's device.
    let loaded = manylights::LoadedScene::load("cornell").expect("cornell");
    let mut settings = manylights::FrameSettings::for_scene(&loaded);
    settings.view.size = (32, 24);
    settings.lights.count = 16;
    let mut renderer = manylights::Renderer::new(context, loaded).expect("renderer");
    renderer
        .render_frame(&settings)
        .expect("a frame on the engine's device");
    let image = renderer.read_hdr().expect("hdr");
    manylights_tests::assert_lit("a frame on the engine's device", &image, 0.2);
    assert_eq!(
        engine_errors.load(Ordering::SeqCst),
        0,
        "the library's errors reached the engine's callback"
    );
    // The engine's callback is still the engine's.
    let _ = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("the engine's own mistake"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let _ = device.poll(wgpu::PollType::wait_indefinitely());
    assert_eq!(
        engine_errors.load(Ordering::SeqCst),
        1,
        "the engine's callback was replaced"
    );

    // A device made with WebGPU's defaults, for a frame that binds twice what they allow.
    let defaults = wgpu::Limits::default().max_storage_buffer_binding_size;
    let larger = DeviceRequirements::minimum().with_storage_binding(2 * defaults);
    let (device, queue) = engine_device(&DeviceRequirements::minimum());
    match GpuContext::from_device(instance, adapter.clone(), device, queue, &larger) {
        Err(error) => {
            let message = error.to_string();
            assert!(
                message.contains("max_storage_buffer_binding_size")
                    && message.contains(&(2 * defaults).to_string())
                    && message.contains(&defaults.to_string()),
                "the refusal names the limit and both values: {message}"
            );
        }
        Ok(_) => panic!("a device short of max_storage_buffer_binding_size was accepted"),
    }
}
