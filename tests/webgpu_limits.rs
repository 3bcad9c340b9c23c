//! Every program within what every WebGPU adapter guarantees (issue 30): the device is made
//! with `wgpu::Limits::default()` (WebGPU's guaranteed limits: 8 storage buffers per stage,
//! 4 bind groups, 128 MiB per binding, 16 KiB of workgroup storage, 256 invocations, 32
//! colour-attachment bytes per sample), against which wgpu validates natively exactly as a
//! browser does, and every pipeline, layout, lighting path, assignment design, far field,
//! spot culling and debug view renders a lit frame without a validation error, and so
//! does every pipeline's pass for blended surfaces, in both transparency modes (its scene
//! pipelines bind the instances beside the lighting binding, whose storage buffers are
//! visible to compute for deferred: the two together must stay within 8). The one
//! option that needs more (the full G-buffer's 64 bytes a pixel) fails with an error that
//! names the limit, not a failed pipeline.

use manylights::cluster::{AssignmentDesign, FarField, FarFieldMethod};
use manylights::gpu::{AdapterRequest, DeviceLimits, GpuContext};
use manylights::lights::{Falloff, SpotSettings};
use manylights::{
    FrameSettings, GBufferLayout, LightingPath, LoadedScene, PipelineSettings, Renderer,
};
use manylights_tests::{assert_lit, clustering_mut, fail_without_gpu};

fn webgpu_renderer(scene: &str) -> (Renderer, FrameSettings) {
    let request = AdapterRequest {
        limits: DeviceLimits::WebGpuDefaults,
        ..AdapterRequest::from_env()
    };
    let context = GpuContext::new_headless_with(&request).unwrap_or_else(|e| fail_without_gpu(e));
    assert_eq!(
        context.device.limits().max_storage_buffers_per_shader_stage,
        8,
        "the device must have WebGPU's guaranteed limits, not the adapter's"
    );
    let loaded = LoadedScene::load(scene).expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (48, 32);
    settings.lights.count = 300;
    settings.lights.time = 0.5;
    (Renderer::new(context, loaded).expect("renderer"), settings)
}

/// Renders `settings` with the light lists' statistics where there are lists (their pass
/// must fit the limits too), and checks the image is lit.
fn render_lit(renderer: &mut Renderer, settings: &FrameSettings, label: &str) {
    let mut settings = settings.clone();
    settings.pipeline.set_list_statistics(true, false);
    renderer
        .render_frame(&settings)
        .unwrap_or_else(|e| panic!("{label} under WebGPU's limits: {e}"));
    let image = renderer.read_hdr().expect("read back");
    assert_lit(label, &image, 0.2);
}

#[test]
fn every_pipeline_and_option_renders_within_webgpu_limits() {
    let (mut renderer, mut settings) = webgpu_renderer("cornell");
    let mut pipelines = vec![
        PipelineSettings::naive(Falloff::default()),
        PipelineSettings::forward_plus(),
    ];
    for layout in [
        GBufferLayout::Compact,
        GBufferLayout::Packed,
        GBufferLayout::Visibility,
    ] {
        for path in LightingPath::ALL {
            pipelines.push(PipelineSettings::deferred(layout, path));
        }
    }
    for pipeline in pipelines {
        settings.pipeline = pipeline;
        render_lit(&mut renderer, &settings, &pipeline.describe());
    }
    // The assignment's other design, spots (cone culling), the far fields and a debug view.
    settings.pipeline = PipelineSettings::forward_plus();
    clustering_mut(&mut settings).assignment = AssignmentDesign::AtomicFill;
    render_lit(&mut renderer, &settings, "atomic-fill assignment");
    settings.pipeline = PipelineSettings::default();
    settings.lights.spots = SpotSettings {
        fraction: 0.5,
        ..SpotSettings::default()
    };
    render_lit(&mut renderer, &settings, "half spots");
    settings.lights.spots = SpotSettings::default();
    for method in [FarFieldMethod::Tree, FarFieldMethod::Stochastic] {
        let far_field = Some(FarField::new(method));
        settings
            .set_falloff(Falloff::InverseSquare, far_field)
            .expect("far field");
        render_lit(&mut renderer, &settings, &format!("{method:?} far field"));
        // Shadow rays: the BVH's textures join every shading layout.
        settings.shadows.mode = manylights::Shadows::Exact;
        render_lit(
            &mut renderer,
            &settings,
            &format!("{method:?} far field with shadows"),
        );
        settings.shadows.mode = manylights::Shadows::Off;
    }
    for pipeline in [
        PipelineSettings::naive(Falloff::default()),
        PipelineSettings::forward_plus(),
        PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Fragment),
    ] {
        let mut shadowed = settings.clone();
        shadowed.pipeline = pipeline;
        shadowed.shadows.mode = manylights::Shadows::Exact;
        shadowed
            .set_falloff(Falloff::default(), None)
            .expect("no far field");
        render_lit(
            &mut renderer,
            &shadowed,
            &format!("{} with shadows", pipeline.describe()),
        );
    }
    settings
        .set_falloff(Falloff::default(), None)
        .expect("no far field");
    settings.pipeline = settings
        .pipeline
        .with_debug_view_named("heatmap")
        .expect("heatmap");
    render_lit(&mut renderer, &settings, "heatmap");
    let errors = renderer.context().take_uncaptured_errors();
    assert!(errors.is_empty(), "uncaptured errors: {errors:?}");
}

#[test]
fn every_pipelines_blended_pass_renders_within_webgpu_limits() {
    let (mut renderer, mut settings) = webgpu_renderer("glass");
    for pipeline in [
        PipelineSettings::naive(Falloff::default()),
        PipelineSettings::forward_plus(),
        PipelineSettings::default(),
    ] {
        for transparency in manylights::Transparency::ALL {
            settings.pipeline = pipeline;
            settings.transparency = transparency;
            let label = format!("glass, {}, {transparency}", pipeline.describe());
            renderer
                .render_frame(&settings)
                .unwrap_or_else(|e| panic!("{label} under WebGPU's limits: {e}"));
            let image = renderer.read_hdr().expect("read back");
            assert_lit(&label, &image, 0.05);
        }
    }
    let errors = renderer.context().take_uncaptured_errors();
    assert!(errors.is_empty(), "uncaptured errors: {errors:?}");
}

#[test]
fn the_full_gbuffer_names_the_limit_it_needs() {
    let (mut renderer, mut settings) = webgpu_renderer("cornell");
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Full, LightingPath::Compute);
    let error = renderer
        .render_frame(&settings)
        .expect_err("64 bytes a pixel is over WebGPU's 32")
        .to_string();
    assert!(
        error.contains("max_color_attachment_bytes_per_sample") && error.contains("full"),
        "{error}"
    );
    // The renderer keeps working after the refusal.
    settings.pipeline = PipelineSettings::default();
    render_lit(
        &mut renderer,
        &settings,
        "compact after the refused full layout",
    );
}
