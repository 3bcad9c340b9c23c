//! GPU errors the renderer must survive (issue 9): a lost device is reported as such, and
//! after `Renderer::recover_device` on a new device the next frame equals the frame before
//! the loss, for every pipeline, with generated and with fixed lights.

use glam::Vec3;
use manylights::gpu::GpuError;
use manylights::lights::{Light, LightSet};
use manylights::{
    FrameSettings, LoadedScene, PipelineKind, PipelineSettings, RenderError, Renderer,
};
use manylights_tests::gpu;

fn cornell() -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.pipeline = PipelineSettings::of_kind(PipelineKind::Naive);
    settings.view.size = (64, 48);
    settings.lights.count = 48;
    settings.lights.time = 0.5;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

fn lose_and_recover(renderer: &mut Renderer, settings: &FrameSettings) {
    renderer.context().device.destroy();
    let error = renderer
        .render_frame(settings)
        .expect_err("a destroyed device cannot render");
    assert!(
        error.is_device_lost(),
        "expected a device-lost error, got: {error}"
    );
    assert!(
        matches!(&error, RenderError::Gpu(GpuError::DeviceLost { reason }) if reason.contains("Destroyed")),
        "the reason names the loss: {error}"
    );
    // Every later call says the same instead of failing in some other way.
    assert!(
        renderer
            .render_frame(settings)
            .expect_err("still lost")
            .is_device_lost()
    );
    renderer
        .recover_device(None)
        .expect("a new device and every resource on it");
}

/// The HDR frame before a device loss and the same frame after the recovery.
fn frames_around_a_device_loss(
    renderer: &mut Renderer,
    settings: &FrameSettings,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    renderer.render_frame(settings).expect("frame");
    let before = renderer.read_hdr().expect("read");
    lose_and_recover(renderer, settings);
    renderer
        .render_frame(settings)
        .expect("frame after recovery");
    (before, renderer.read_hdr().expect("read"))
}

#[test]
fn every_pipeline_renders_the_same_frame_after_a_device_loss() {
    let (mut renderer, mut settings) = cornell();
    for pipeline in PipelineKind::ALL {
        settings.pipeline = PipelineSettings::of_kind(pipeline);
        let (before, after) = frames_around_a_device_loss(&mut renderer, &settings);
        assert!(
            before.iter().any(|t| t[0] > 0.0),
            "{pipeline:?}: black frame"
        );
        assert_eq!(
            before, after,
            "{pipeline:?}: frame changed across the recovery"
        );
    }
}

#[test]
fn fixed_lights_survive_a_device_loss() {
    let (mut renderer, mut settings) = cornell();
    settings.pipeline = PipelineSettings::forward_plus();
    let lights = LightSet {
        lights: vec![Light::point(
            Vec3::new(0.0, 1.5, 0.5),
            2.0,
            Vec3::new(1.0, 0.8, 0.6),
            0.5,
        )],
    };
    renderer.set_fixed_lights(&lights).expect("lights");
    let (before, after) = frames_around_a_device_loss(&mut renderer, &settings);
    assert_eq!(renderer.read_lights().expect("lights"), lights.lights);
    assert_eq!(before, after);
}

/// A light count past the device's buffer limits (4 billion lights would be 128 GB) is a
/// clear error before anything is allocated, and the renderer keeps working afterwards.
#[test]
fn too_many_lights_is_an_error_and_the_renderer_carries_on() {
    let (mut renderer, mut settings) = cornell();
    settings.lights.count = u32::MAX;
    let error = renderer
        .render_frame(&settings)
        .expect_err("over the limits");
    let message = error.to_string();
    assert!(
        message.contains("4294967295 lights") && message.contains("limit"),
        "{message}"
    );
    settings.lights.count = 48;
    renderer
        .render_frame(&settings)
        .expect("a frame after the error");
    assert!(
        renderer
            .read_hdr()
            .expect("read")
            .iter()
            .any(|t| t[0] > 0.0)
    );
}
