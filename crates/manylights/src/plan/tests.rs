//! The plan's rules, without a GPU: each refusal with its reason, each route, and the view
//! in f64 far from the world's origin.

use glam::Vec3;
use manylights_deferred::LightingPath;
use manylights_scene::Aabb;
use manylights_visibility::Shadows;

use super::*;
use crate::camera::Camera;
use crate::pipelines::PipelineKind;
use crate::scenes::LoadedScene;

fn settings(kind: PipelineKind) -> FrameSettings {
    let scene = LoadedScene::load("cornell").expect("the procedural cornell scene");
    let mut settings = FrameSettings::for_scene(&scene);
    settings.pipeline = PipelineSettings::of_kind(kind);
    settings.view.size = (64, 36);
    settings
}

fn facts() -> SceneFacts {
    SceneFacts {
        bounds: Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0)),
        blended_bounds: Vec::new(),
    }
}

fn every_count() -> DeviceFacts {
    DeviceFacts {
        msaa_sample_counts: vec![1, 2, 4, 8],
    }
}

fn decide(settings: &FrameSettings) -> Result<FramePlan, String> {
    FramePlan::decide(settings, &facts(), &every_count())
}

fn refusal(settings: &FrameSettings) -> String {
    match decide(settings) {
        Ok(plan) => panic!("planned, expected a refusal: {plan:?}"),
        Err(reason) => reason,
    }
}

fn deferred_with(lighting: LightingPath) -> FrameSettings {
    let mut settings = settings(PipelineKind::Deferred);
    if let PipelineSettings::Deferred(deferred) = &mut settings.pipeline {
        deferred.lighting = lighting;
    }
    settings
}

#[test]
fn only_the_clustered_pipelines_plan_clusters() {
    for (kind, clustered) in [
        (PipelineKind::Naive, false),
        (PipelineKind::ForwardPlus, true),
        (PipelineKind::Deferred, true),
    ] {
        let plan = decide(&settings(kind)).expect("default settings plan");
        assert_eq!(plan.clusters.is_some(), clustered, "{kind}");
        assert_eq!(plan.shadows, ShadowRoute::Off, "{kind}");
    }
}

#[test]
fn statistics_are_planned_only_where_lists_are_built() {
    for kind in [PipelineKind::Naive, PipelineKind::Deferred] {
        let mut settings = settings(kind);
        settings.pipeline.set_list_statistics(true, true);
        let planned = decide(&settings).expect("plan").list_statistics();
        let expected = (kind != PipelineKind::Naive).then_some(ListStatistics {
            false_positives: true,
        });
        assert_eq!(planned, expected, "{kind}");
    }
}

#[test]
fn each_pipeline_traces_its_shadows_on_its_own_route() {
    let forward = settings(PipelineKind::ForwardPlus);
    let route = |settings: &FrameSettings, shadows: Shadows| {
        let mut settings = settings.clone();
        settings.shadows.mode = shadows;
        decide(&settings).map(|plan| plan.shadows)
    };
    assert_eq!(
        route(&forward, Shadows::Exact),
        Ok(ShadowRoute::InShadingLoop(Shadows::Exact))
    );
    assert_eq!(
        route(&forward, Shadows::RaysTemporal(1)),
        Ok(ShadowRoute::ShadowPass(Shadows::RaysTemporal(1)))
    );
    assert_eq!(
        route(&forward, Shadows::Rays(4)),
        Ok(ShadowRoute::InShadingLoop(Shadows::Rays(4)))
    );
    let tiles = deferred_with(LightingPath::Tiles);
    assert_eq!(
        route(&tiles, Shadows::RaysSpatial(2)),
        Ok(ShadowRoute::ComputeLighting(Shadows::RaysSpatial(2)))
    );
    assert_eq!(
        route(&tiles, Shadows::Exact),
        Ok(ShadowRoute::InShadingLoop(Shadows::Exact))
    );
    // The filter follows the forward shadow pass and deferred's compute lighting only.
    for (settings, shadows) in [
        (&forward, Shadows::RaysSpatial(2)),
        (
            &deferred_with(LightingPath::Fragment),
            Shadows::RaysSpatial(1),
        ),
    ] {
        let error = route(settings, shadows).expect_err("an unfiltered route");
        assert!(error.contains("spatial filter follows"), "{error}");
    }
    let error = route(&forward, Shadows::Rays(9)).expect_err("too many rays");
    assert!(error.contains("ray budget of 9"), "{error}");
}

#[test]
fn msaa_is_refused_where_a_pass_reads_one_surface_a_pixel() {
    let mut deferred = settings(PipelineKind::Deferred);
    deferred.view.msaa = 4;
    assert!(refusal(&deferred).contains("G-buffer per sample"));
    let mut forward = settings(PipelineKind::ForwardPlus);
    forward.view.msaa = 4;
    assert_eq!(decide(&forward).expect("Forward+ with MSAA").samples, 4);
    let mut shadow_pass = forward.clone();
    shadow_pass.shadows.mode = Shadows::Rays(1);
    assert!(refusal(&shadow_pass).contains("forward shadow pass"));
    let mut counted = forward.clone();
    counted.pipeline.set_list_statistics(true, true);
    assert!(refusal(&counted).contains("false-positive count"));
    forward.view.msaa = 3;
    assert!(refusal(&forward).contains("1 (off), 2, 4 or 8"));
    // A count the device's formats lack.
    forward.view.msaa = 8;
    let error = FramePlan::decide(&forward, &facts(), &DeviceFacts::default())
        .expect_err("8 samples on a device with 1 and 4");
    assert!(error.contains("[1, 4]"), "{error}");
}

#[test]
fn the_lab_asks_the_same_rule_before_a_scene_is_loaded() {
    let mut settings = settings(PipelineKind::Deferred);
    settings.view.msaa = 8;
    assert_eq!(
        DialCombination::of(&settings).check().expect_err("refused"),
        refusal(&settings)
    );
}

#[test]
fn values_no_combination_can_fix_are_refused() {
    let base = settings(PipelineKind::ForwardPlus);
    let mut empty = base.clone();
    empty.view.size = (0, 36);
    assert!(refusal(&empty).contains("is empty"));
    let mut timeless = base.clone();
    timeless.lights.time = f32::NAN;
    assert!(refusal(&timeless).contains("time must be finite"));
    let mut budget = base.clone();
    budget.budget = Some(0.0);
    assert!(refusal(&budget).contains("budget"));
    let mut camera = base.clone();
    camera.view.camera.near = -1.0;
    assert!(refusal(&camera).contains("near"));
}

#[test]
fn a_view_far_from_the_world_origin_is_exact_in_f64() {
    // A unit box 10 km away along x, seen from 2 m in front of it: an f32 world view would
    // round its translation to a few millimetres.
    let centre = Vec3::new(10_000.0, 0.0, 0.0);
    let mut settings = settings(PipelineKind::ForwardPlus);
    settings.view.camera =
        Camera::look_at(centre + Vec3::new(0.0, 0.0, 2.0), centre, 60.0, 0.1, 100.0);
    let unit = Aabb::new(centre - Vec3::splat(0.5), centre + Vec3::splat(0.5));
    let facts = SceneFacts {
        bounds: unit,
        blended_bounds: vec![unit],
    };
    let plan = FramePlan::decide(&settings, &facts, &every_count()).expect("plan");
    let view = &plan.view;
    // Looking down -z from 2 m: the box spans 1.5 to 2.5 m in depth.
    assert!((view.scene_in_view.min.z + 2.5).abs() < 1e-5, "{view:?}");
    assert!((view.scene_in_view.max.z + 1.5).abs() < 1e-5, "{view:?}");
    let (low, high) = plan.clusters.expect("clusters").blended_boxes[0];
    let pad = 1e-5 * 2.5;
    assert!((low.z - (-2.5 - pad)).abs() < 1e-6, "{low}");
    assert!((high.z - (-1.5 + pad)).abs() < 1e-6, "{high}");
    // Camera-relative: the scene's origin is the camera, which sits at the view's origin.
    assert_eq!(view.origin, settings.view.camera.position);
    let uniform = view.uniform(None);
    assert_eq!(uniform.camera_position[..3], [0.0; 3]);
    // A first frame's history is itself.
    assert_eq!(uniform.previous_view_proj, uniform.view_proj);
    // A camera 1 m to the right a frame ago reprojects the box's centre 1 m to the left.
    let mut before = settings.clone();
    before.view.camera.position += Vec3::X;
    let previous = FramePlan::decide(&before, &facts, &every_count())
        .expect("plan")
        .view
        .viewed_from;
    let uniform = view.uniform(Some(previous));
    let clip = glam::Mat4::from_cols_array_2d(&uniform.previous_view_proj)
        * (centre - view.origin).extend(1.0);
    let ndc_x = f64::from(clip.x / clip.w);
    let expected = previous.world_to_clip.project_point3(centre.as_dvec3()).x;
    assert!(
        (ndc_x - expected).abs() < 1e-4,
        "{ndc_x} against {expected}"
    );
    assert!(
        expected < 0.0,
        "the box is left of the earlier camera: {expected}"
    );
}

/// Textures under TAA take the mip bias the design derives: the running mean averages
/// `JITTER_SAMPLES` (16) samples a pixel, as a frame of 4 x 4 the pixels does, whose
/// textures are two mip levels finer; the bias goes half way (-1), so each frame's own
/// samples alias only twice as finely as without TAA (`gpu::taa::TEXTURE_LOD_BIAS` says
/// why). It reaches the view's uniform only under TAA, and not in a debug view.
#[test]
fn taa_biases_texture_mips_half_way_to_its_supersampled_frame() {
    let supersampled_levels = 0.5 * f64::from(manylights_gpu::taa::JITTER_SAMPLES).log2();
    let half_way = -0.5 * supersampled_levels;
    let mut settings = settings(PipelineKind::Deferred);
    let bias = |settings: &FrameSettings| {
        decide(settings)
            .expect("plan")
            .view
            .uniform(None)
            .texture_lod_bias[0]
    };
    assert_eq!(bias(&settings), 0.0, "no bias without TAA");
    settings.post.anti_aliasing = manylights_gpu::AntiAliasing::Taa;
    assert_eq!(
        f64::from(bias(&settings)),
        half_way,
        "TAA's texture mip bias is not half way to its {supersampled_levels}-level finer frame"
    );
}
