//! The library in someone else's renderer: the examples that use the crates from an
//! engine's own wgpu program run here as the examples step runs them, at the smallest size
//! that shows their claim. Forward+ in an engine (`crates/cluster/examples/
//! forward_plus_in_your_engine.rs`, its own device, reverse-Z infinite camera, depth
//! pre-pass and shader) draws the same frame through the lists as from every light, with
//! and without shadow rays through the BVH of its own triangles; deferred in an engine
//! (its own G-buffer and compute lighting) lights it the same through the lists as from
//! every light.

// Each example is a program of its own with its own copy of the engine's module
// (`engine/mod.rs`), as cargo builds it: loaded here twice, once in each.
#![allow(clippy::duplicate_mod)]

#[allow(dead_code)]
#[path = "../crates/cluster/examples/deferred_in_your_engine.rs"]
mod deferred_in_your_engine;
#[allow(dead_code)]
#[path = "../crates/cluster/examples/forward_plus_in_your_engine.rs"]
mod forward_plus_in_your_engine;

use forward_plus_in_your_engine::engine::{differing_channels, lit_pixels};

/// 1,500 lights of 2.8 m over 400 m^2: about a hundred reach a point of the floor, so a
/// dropped or misplaced light changes many pixels. The smallest frame that still has every
/// box.
/// (Each example has its own copy of the engine's module, so of its `Options`.)
macro_rules! small {
    ($example:ident, $shadows:expr) => {
        $example::engine::Options {
            size: (96, 64),
            lights: 1_500,
            check: true,
            shadows: $shadows,
            far_field: None,
            time: 0,
            out: String::new(),
        }
    };
}

#[test]
fn an_engines_far_field_at_tolerance_zero_is_every_lights_unbounded_frame() {
    drop(manylights_tests::gpu());
    // What the lights add beyond their radius, from the cut of the light tree, with the
    // engine's BRDF on it: exact at tolerance 0, so windowed (the lists) plus far (the cut)
    // is every light's plain inverse square, summed in another order.
    let options = forward_plus_in_your_engine::engine::Options {
        far_field: Some(0.0),
        ..small!(forward_plus_in_your_engine, false)
    };
    let frames = forward_plus_in_your_engine::render(&options).expect("the engine's frame");
    let every_light = frames.every_light.expect("drawn with check");
    assert!(lit_pixels(&every_light) > every_light.len() / 2);
    let ulps = forward_plus_in_your_engine::engine::allowed_ulps(&options).expect("exact");
    assert_eq!(differing_channels(&frames.listed, &every_light, ulps), 0);
    // Without the far field the same frame misses what lies beyond the radius: the check
    // above can fail.
    let windowed = forward_plus_in_your_engine::render(&small!(forward_plus_in_your_engine, false))
        .expect("the frame without a far field");
    assert!(differing_channels(&windowed.listed, &every_light, ulps) > every_light.len());
}

/// The frame through the lists equals the frame from every light in every channel, and
/// has content: most of the frame is floor and boxes, lit.
fn assert_lists_drop_nothing(name: &str, listed: &[[f32; 4]], every_light: &[[f32; 4]]) {
    let pixels = listed.len();
    assert!(
        lit_pixels(every_light) > pixels / 2,
        "{name}: {} of {pixels} lit",
        lit_pixels(every_light)
    );
    assert_eq!(lit_pixels(listed), lit_pixels(every_light), "{name}");
    // Both frames sum the same nonzero terms in the same order: a light its cluster does
    // not list adds exactly zero there. 64 f32 ulps a channel allow for the compilers'
    // contractions of two pipelines; a light left out of a list is a whole term.
    assert_eq!(differing_channels(listed, every_light, 64.0), 0, "{name}");
}

#[test]
fn an_engines_forward_plus_frame_through_the_lists_equals_every_lights() {
    // Fails with how to install lavapipe where there is no adapter.
    drop(manylights_tests::gpu());
    let frames = forward_plus_in_your_engine::render(&small!(forward_plus_in_your_engine, false))
        .expect("the engine's frame");
    let every_light = frames.every_light.expect("drawn with check");
    assert_lists_drop_nothing("Forward+", &frames.listed, &every_light);

    // Shadow rays from the engine's shader, through the BVH of its own triangles: the
    // same through the lists, and darker than unshadowed where a box hides a light.
    let shadowed = forward_plus_in_your_engine::render(&small!(forward_plus_in_your_engine, true))
        .expect("shadowed frame");
    let shadowed_every_light = shadowed.every_light.expect("drawn with check");
    assert_lists_drop_nothing(
        "Forward+ with shadows",
        &shadowed.listed,
        &shadowed_every_light,
    );
    let darker = (shadowed.listed.iter().zip(&frames.listed))
        .filter(|(shadowed, unshadowed)| {
            shadowed[0] + shadowed[1] + shadowed[2]
                < 0.99 * (unshadowed[0] + unshadowed[1] + unshadowed[2])
        })
        .count();
    let brighter = (shadowed.listed.iter().zip(&frames.listed))
        .filter(|(shadowed, unshadowed)| (0..3).any(|c| shadowed[c] > unshadowed[c]))
        .count();
    println!(
        "{darker} of {} pixels darker with shadows",
        frames.listed.len()
    );
    assert!(
        darker > frames.listed.len() / 50,
        "{darker} pixels darker with shadows"
    );
    assert_eq!(brighter, 0, "a shadow ray only ever takes light away");
}

#[test]
fn an_engines_deferred_lighting_through_the_lists_equals_every_lights() {
    drop(manylights_tests::gpu());
    let frames = deferred_in_your_engine::render(&small!(deferred_in_your_engine, false))
        .expect("the engine's frame");
    let every_light = frames.every_light.expect("lit with check");
    assert_lists_drop_nothing("deferred", &frames.listed, &every_light);
}

#[test]
fn an_engines_lights_are_uploaded_and_rewritten_and_bad_ones_refused_by_index() {
    use glam::Vec3;
    use manylights_lights::{GpuLights, Light};
    let context = manylights_tests::gpu();
    let light = |x: f32| Light::point(Vec3::new(x, 1.0, 0.0), 2.0, Vec3::ONE, 0.5);
    let mut lights: Vec<Light> = (0..4).map(|i| light(i as f32)).collect();
    let mut uploaded = GpuLights::new(&context, &lights).expect("four valid lights");
    assert_eq!(
        (uploaded.count, uploaded.animated),
        (4, 0),
        "no animation of ours moves them"
    );
    assert!(!uploaded.has_shaped_lights);

    // A per-frame update of the range that changed.
    let spot = Light::spot(
        Vec3::ZERO,
        3.0,
        Vec3::ONE,
        1.0,
        Vec3::NEG_Y,
        manylights_lights::SpotCone {
            inner: 0.2,
            outer: 0.4,
        },
    );
    uploaded.write(&context, 2, &[spot]).expect("a valid spot");
    lights[2] = spot;
    assert_eq!(uploaded.read(&context).expect("read back"), lights);
    assert!(
        uploaded.has_shaped_lights,
        "the next frame's programs include the cone"
    );

    // Refused with the light's index in the whole array and the field; nothing written.
    let mut nan = light(0.0);
    nan.position[1] = f32::NAN;
    let mut negative = light(0.0);
    negative.radius = -1.0;
    let refusals = [
        (
            GpuLights::new(&context, &[light(0.0), light(1.0), nan]).err(),
            "light 2: position",
        ),
        (
            uploaded.write(&context, 1, &[negative]).err(),
            "light 1: radius",
        ),
        (
            uploaded.write(&context, 3, &[nan]).err(),
            "light 3: position",
        ),
        (
            uploaded.write(&context, 3, &[light(0.0), light(1.0)]).err(),
            "past the 4 lights",
        ),
    ];
    for (error, expected) in refusals {
        let error = error.map(|e| e.to_string()).unwrap_or_default();
        assert!(error.contains(expected), "{expected:?} in {error:?}");
    }
    assert_eq!(
        uploaded.read(&context).expect("read back"),
        lights,
        "nothing written"
    );
}

#[test]
fn bad_input_from_an_engine_is_refused_and_its_own_error_callback_never_called() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    use manylights_cluster::{ClusterFrame, ClusterGrid, GpuClusters, VisibleDepth};
    use manylights_gpu::{
        DeviceRequirements, GpuContext, ShaderLibrary, ViewBinding, ViewUniform, wgpu,
    };
    use manylights_lights::{GpuLights, Light};

    drop(manylights_tests::gpu());
    // The engine's device, with its own uncaptured-error callback.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&Default::default())).expect("an adapter");
    let needs = DeviceRequirements::minimum();
    let mut descriptor = wgpu::DeviceDescriptor::default();
    needs.merge_into(&mut descriptor, &adapter);
    let (device, queue) =
        pollster::block_on(adapter.request_device(&descriptor)).expect("the engine's device");
    let engine_errors = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&engine_errors);
    device.on_uncaptured_error(Arc::new(move |_| {
        counter.fetch_add(1, Ordering::SeqCst);
    }));
    let context = GpuContext::from_device(instance, adapter, device.clone(), queue, &needs)
        .expect("a device with the requirements merged in");

    // A light with a NaN position: refused by index, nothing created.
    let mut lights = vec![Light::point(glam::Vec3::ONE, 1.0, glam::Vec3::ONE, 1.0); 3];
    lights[1].position[0] = f32::NAN;
    let error = GpuLights::new(&context, &lights).expect_err("a NaN position");
    assert!(error.to_string().contains("light 1: position"), "{error}");
    lights[1].position[0] = 0.0;
    let lights = GpuLights::new(&context, &lights).expect("three valid lights");

    // Depth of another size than the grid's: refused with both sizes.
    let (view, projection) = forward_plus_in_your_engine::engine::camera((64, 32));
    let camera = ViewUniform::from_matrices(view, projection, (64, 32)).expect("the camera");
    let view_binding = ViewBinding::new(&context);
    let grid = ClusterGrid::for_view(
        &Default::default(),
        &camera,
        Some(manylights_scene::Aabb::new(
            glam::Vec3::splat(-5.0),
            glam::Vec3::splat(5.0),
        )),
    )
    .expect("the grid");
    let mut clusters =
        GpuClusters::new(&context, &ShaderLibrary::from_env(), &view_binding).expect("clusters");
    let depth = forward_plus_in_your_engine::engine::texture(
        &device,
        (32, 32),
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let depth_view = depth.create_view(&Default::default());
    let error = clusters
        .prepare(
            &context,
            &ClusterFrame::new(grid),
            &lights,
            Some(VisibleDepth::of(&depth, &depth_view)),
        )
        .expect_err("depth of another size");
    assert!(
        error.to_string().contains("32x32") && error.to_string().contains("64x32"),
        "{error}"
    );

    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("the device idles");
    assert_eq!(
        engine_errors.load(Ordering::SeqCst),
        0,
        "the engine's callback saw nothing of ours"
    );
}
