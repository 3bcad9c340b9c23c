//! The library in someone else's renderer: the examples that use the crates from an
//! engine's own wgpu program run here as the examples step runs them, at the smallest size
//! that shows their claim. Forward+ in an engine (`crates/cluster/examples/
//! forward_plus_in_your_engine.rs`, its own device, reverse-Z infinite camera, depth
//! pre-pass and shader) draws the same frame through the lists as from every light.

#[allow(dead_code)]
#[path = "../crates/cluster/examples/forward_plus_in_your_engine.rs"]
mod forward_plus_in_your_engine;

use forward_plus_in_your_engine::{Options, differing_channels, render};

#[test]
fn an_engines_forward_plus_frame_through_the_lists_equals_every_lights() {
    // Fails with how to install lavapipe where there is no adapter.
    drop(manylights_tests::gpu());
    // 1,500 lights of 1.5 m over 400 m^2: about 50 reach a point of the floor, so a
    // dropped or misplaced light changes many pixels.
    let options = Options {
        size: (96, 64),
        lights: 1_500,
        check: true,
    };
    let frames = render(&options).expect("the engine's frame");
    let every_light = frames.every_light.expect("drawn with --check");
    let lit = |frame: &[[f32; 4]]| frame.iter().filter(|p| p[0] + p[1] + p[2] > 0.0).count();
    // The reference has content: most of the frame is floor and boxes, lit.
    let pixels = (options.size.0 * options.size.1) as usize;
    assert!(
        lit(&every_light) > pixels / 2,
        "{} of {pixels} lit",
        lit(&every_light)
    );
    assert_eq!(lit(&frames.listed), lit(&every_light));
    // Both frames sum the same nonzero terms in the same order: a light its cluster does
    // not list adds exactly zero there. 64 f32 ulps a channel allow for the compilers'
    // contractions of two pipelines; a light left out of a list is a whole term.
    assert_eq!(differing_channels(&frames.listed, &every_light), 0);
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
