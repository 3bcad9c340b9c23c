//! Spot lights in every pipeline (issue 17): naive against the f64 reference lives in
//! `naive.rs`; here Forward+ and deferred (both lighting paths) against naive with spots,
//! generated and a scene's own (the `lamps` asset, with a hard-edged cone), the GPU's cone
//! culling against the CPU reference and what it saves over the range sphere, and the
//! extremes: needle (1e-4 rad) and hemisphere (pi/2) cones, a spot at the camera pointing
//! at it and away, a spot inside the cluster it lights, 100,000 spots.

use glam::Vec3;
use manylights::cluster::{
    ClusterBoxes, LightVolume, SpotCulling, assign_light_volumes, compare_volumes_with_reference,
};
use manylights::lights::{Light, LightSet, RadiusMode, SpotCone, SpotSettings};
use manylights::{
    Camera, ClusteringSettings, FrameSettings, GBufferLayout, LoadedScene, PipelineSettings,
    Renderer,
};
use manylights_tests::{
    assert_hdr_close, assert_lit, clustered_variants, clustering, clustering_mut, gpu,
};

fn renderer(scene: &str, size: (u32, u32)) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load(scene).expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = size;
    settings.lights.time = 1.25;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

fn half_spots(inner_deg: f32, outer_deg: f32) -> SpotSettings {
    SpotSettings {
        fraction: 0.5,
        cone: SpotCone {
            inner: inner_deg.to_radians(),
            outer: outer_deg.to_radians(),
        },
    }
}

/// Renders naive, then every clustered variant with both spot cullings and both boxes,
/// each held to naive within one half-float ulp + 1e-4 relative (as without spots).
fn assert_clustered_match_naive(
    label: &str,
    renderer: &mut Renderer,
    settings: &mut FrameSettings,
    lit: f64,
) {
    settings.pipeline = PipelineSettings::naive(Default::default());
    renderer.render_frame(settings).expect("naive");
    let naive = renderer.read_hdr().expect("hdr");
    assert_lit(label, &naive, lit);
    for spot_culling in SpotCulling::ALL {
        for boxes in ClusterBoxes::ALL {
            let lists = ClusteringSettings {
                spot_culling,
                boxes,
                ..ClusteringSettings::default()
            };
            for pipeline in clustered_variants(GBufferLayout::Full) {
                settings.pipeline = pipeline.with_clustering(lists);
                renderer.render_frame(settings).expect("frame");
                let image = renderer.read_hdr().expect("hdr");
                assert_hdr_close(
                    &format!("{label}, {spot_culling} culling, {boxes} boxes: {pipeline:?}"),
                    &naive,
                    &image,
                    1e-4,
                );
            }
        }
    }
}

#[test]
fn clustered_pipelines_match_naive_with_generated_spots() {
    let (mut renderer, mut settings) = renderer("sponza", (97, 61));
    settings.lights.count = 400;
    settings.lights.spots = half_spots(20.0, 30.0);
    assert_clustered_match_naive(
        "sponza, 400 lights, half spots",
        &mut renderer,
        &mut settings,
        0.3,
    );
    // Wide and hard-edged cones too.
    settings.lights.spots = half_spots(60.0, 60.0);
    assert_clustered_match_naive(
        "sponza, hard-edged 60 degree spots",
        &mut renderer,
        &mut settings,
        0.3,
    );
}

/// The lamps asset: the file's point and spot lights (one unbounded, one hard-edged)
/// beside generated spots.
#[test]
fn clustered_pipelines_match_naive_with_the_scenes_own_lights() {
    let (mut renderer, mut settings) = renderer("lamps", (128, 96));
    settings.lights.count = 32;
    settings.lights.spots = half_spots(10.0, 25.0);
    let lights = {
        renderer.render_frame(&settings).expect("frame");
        renderer.read_lights().expect("lights")
    };
    // 32 generated lights, then the file's 5 (3 spots), static.
    assert_eq!(lights.len(), 37);
    assert_eq!(lights[32..].iter().filter(|l| l.is_spot()).count(), 3);
    settings.lights.time = 4.0;
    renderer.render_frame(&settings).expect("frame");
    let later = renderer.read_lights().expect("lights");
    assert_eq!(
        later[32..],
        lights[32..],
        "scene lights stay where the file put them"
    );
    assert_ne!(later[..32], lights[..32], "generated lights move");
    assert_clustered_match_naive("lamps", &mut renderer, &mut settings, 0.5);
}

/// GPU lists with cones equal the CPU reference on the same volumes; the cone lists are a
/// subset of the sphere lists and smaller (the saving is printed: the H200 numbers use the
/// GPU statistics' false-positive ratio for both).
#[test]
fn cone_lists_equal_the_cpu_reference_and_cull_more_than_spheres() {
    let (mut renderer, mut settings) = renderer("sponza", (128, 96));
    settings.pipeline = PipelineSettings::forward_plus();
    settings.lights.count = 3000;
    settings.lights.radius = RadiusMode::Fixed(3.0);
    let loaded = LoadedScene::load("sponza").expect("sponza");
    let cameras: Vec<Camera> = manylights_tests::interior_cameras(&loaded)
        .into_iter()
        .map(|(_, c)| c)
        .collect();
    for (inner, outer) in [(0.0f32, 1e-4f32.to_degrees()), (20.0, 30.0), (45.0, 90.0)] {
        settings.lights.spots = SpotSettings {
            fraction: 0.5,
            cone: SpotCone {
                inner: inner.to_radians(),
                outer: outer.to_radians(),
            },
        };
        for camera in &cameras {
            settings.view.camera = *camera;
            let mut totals = Vec::new();
            for culling in SpotCulling::ALL {
                clustering_mut(&mut settings).spot_culling = culling;
                manylights_tests::render_with_whole_lists(&mut renderer, &settings).expect("frame");
                let lists = renderer.read_light_lists().expect("lists");
                let volumes = renderer.read_light_volumes().expect("volumes");
                let spots = volumes.iter().filter(|v| v.cone.is_some()).count();
                match culling {
                    SpotCulling::Cone => assert!(spots > 1000, "{spots} cones"),
                    SpotCulling::Sphere => assert_eq!(spots, 0),
                }
                let grid = renderer.cluster_grid(&settings).expect("grid");
                let bounds = renderer.read_cluster_bounds().expect("bounds");
                let reference = assign_light_volumes(&grid, &bounds, &volumes);
                let borderline = compare_volumes_with_reference(
                    &lists,
                    &reference,
                    &bounds,
                    &volumes,
                    clustering(&settings).assignment.sorted_list_limit(),
                )
                .unwrap_or_else(|e| panic!("cone {inner}-{outer}, {culling}: {e}"));
                assert!(
                    borderline * 1000 <= reference.total().max(1000),
                    "{borderline} borderline"
                );
                totals.push((reference.total(), volumes));
            }
            let (cone_total, cone_volumes) = &totals[0];
            let (sphere_total, _) = &totals[1];
            // The cone test only removes entries: a cone volume meets a box only where its
            // range sphere does.
            let spheres_only: Vec<LightVolume> = cone_volumes
                .iter()
                .map(|v| LightVolume { cone: None, ..*v })
                .collect();
            let grid = renderer.cluster_grid(&settings).expect("grid");
            let bounds = renderer.read_cluster_bounds().expect("bounds");
            let with_cones = assign_light_volumes(&grid, &bounds, cone_volumes);
            let without = assign_light_volumes(&grid, &bounds, &spheres_only);
            for cluster in 0..with_cones.cluster_count() {
                for light in with_cones.list(cluster) {
                    assert!(
                        without.list(cluster).contains(light),
                        "cluster {cluster} light {light}"
                    );
                }
            }
            assert!(
                cone_total < sphere_total,
                "cone {inner}-{outer}: {cone_total} entries with cones, {sphere_total} with spheres"
            );
            println!(
                "cone {inner}-{outer} deg, camera {:?}: {cone_total} list entries with cones, {sphere_total} with range spheres ({:.1}% fewer)",
                camera.position,
                100.0 * (1.0 - *cone_total as f64 / *sphere_total as f64)
            );
        }
    }
}

fn spot(position: Vec3, direction: Vec3, radius: f32, inner: f32, outer: f32) -> Light {
    Light::spot(
        position,
        radius,
        Vec3::new(1.0, 0.9, 0.8),
        1.0,
        direction,
        SpotCone { inner, outer },
    )
}

/// Every pipeline renders the extremes finite, and the clustered ones equal naive.
#[test]
fn spot_extremes_are_finite_and_match_naive() {
    let (mut renderer, mut settings) = renderer("cornell", (128, 96));
    let camera = settings.view.camera;
    let eye = camera.position;
    let forward = camera.forward();
    let cases: Vec<(&str, Vec<Light>)> = vec![
        (
            "needle cone (1e-4 rad) at the back wall, and one on the floor",
            vec![
                spot(Vec3::new(0.0, 1.5, 1.0), Vec3::NEG_Z, 6.0, 0.0, 1e-4),
                spot(Vec3::new(0.3, 2.5, 0.0), Vec3::NEG_Y, 6.0, 1e-4, 1e-4),
            ],
        ),
        (
            "hemisphere cone (pi/2) under the ceiling",
            vec![spot(
                Vec3::new(0.0, 2.9, 0.0),
                Vec3::NEG_Y,
                4.0,
                1.0,
                std::f32::consts::FRAC_PI_2,
            )],
        ),
        (
            "a spot at the camera pointing at it, and one pointing away",
            vec![
                spot(eye + forward * 0.2, -forward, 4.0, 0.3, 0.6),
                spot(eye, forward, 6.0, 0.3, 0.6),
            ],
        ),
        (
            "a spot inside the cluster it lights (1 cm from the back wall)",
            vec![spot(Vec3::new(0.0, 1.2, -1.99), Vec3::NEG_Z, 0.5, 0.5, 1.2)],
        ),
        (
            "a spot touching the floor, pointing along it",
            vec![spot(Vec3::new(0.0, 0.0, 0.0), Vec3::X, 3.0, 0.4, 0.8)],
        ),
    ];
    for (label, lights) in cases {
        renderer
            .set_fixed_lights(&LightSet { lights })
            .expect("lights");
        settings.pipeline = PipelineSettings::naive(Default::default());
        renderer.render_frame(&settings).expect("naive");
        let naive = renderer.read_hdr().expect("hdr");
        assert!(
            naive.iter().flatten().all(|v| v.is_finite()),
            "{label}: naive not finite"
        );
        for pipeline in clustered_variants(GBufferLayout::Full) {
            settings.pipeline = pipeline;
            renderer.render_frame(&settings).expect("frame");
            let image = renderer.read_hdr().expect("hdr");
            assert_hdr_close(&format!("{label}: {pipeline:?}"), &naive, &image, 1e-4);
        }
    }
    // The pointing-away spot lights the room in front; the needle lights almost nothing.
    renderer
        .set_fixed_lights(&LightSet {
            lights: vec![spot(eye, forward, 6.0, 0.3, 0.6)],
        })
        .expect("lights");
    settings.pipeline = PipelineSettings::naive(Default::default());
    renderer.render_frame(&settings).expect("naive");
    assert_lit(
        "spot pointing away from the camera",
        &renderer.read_hdr().expect("hdr"),
        0.05,
    );
    renderer
        .set_fixed_lights(&LightSet {
            lights: vec![spot(Vec3::new(0.0, 1.5, 1.0), Vec3::NEG_Z, 6.0, 0.0, 1e-4)],
        })
        .expect("lights");
    renderer.render_frame(&settings).expect("naive");
    let needle = renderer.read_hdr().expect("hdr");
    let lit = needle.iter().filter(|p| p[0] > 0.0).count();
    assert!(
        lit <= 4,
        "a 1e-4 rad cone 3 m away lights a 0.6 mm disc: at most a pixel or so, got {lit}"
    );
}

/// 100,000 spots: the lists equal the CPU reference and the frame is finite.
#[test]
fn one_hundred_thousand_spots() {
    let (mut renderer, mut settings) = renderer("cornell", (64, 48));
    settings.pipeline = PipelineSettings::forward_plus();
    settings.lights.count = 100_000;
    settings.lights.radius = RadiusMode::Fixed(0.3);
    settings.lights.spots = SpotSettings {
        fraction: 1.0,
        ..half_spots(20.0, 40.0)
    };
    manylights_tests::render_with_whole_lists(&mut renderer, &settings).expect("frame");
    let lists = renderer.read_light_lists().expect("lists");
    let volumes = renderer.read_light_volumes().expect("volumes");
    assert_eq!(volumes.iter().filter(|v| v.cone.is_some()).count(), 100_000);
    let grid = renderer.cluster_grid(&settings).expect("grid");
    let bounds = renderer.read_cluster_bounds().expect("bounds");
    let reference = assign_light_volumes(&grid, &bounds, &volumes);
    compare_volumes_with_reference(
        &lists,
        &reference,
        &bounds,
        &volumes,
        clustering(&settings).assignment.sorted_list_limit(),
    )
    .expect("lists");
    assert!(reference.total() > 1000, "{} entries", reference.total());
    let image = renderer.read_hdr().expect("hdr");
    assert!(image.iter().flatten().all(|v| v.is_finite()));
    assert_lit("100,000 spots", &image, 0.2);
}

/// With spots, the tree far field at tolerance 0 still equals naive inverse-square (the
/// tree's aggregates count a spot by its cone's share, but at 0 every light is exact).
#[test]
fn the_far_field_at_tolerance_zero_is_exact_with_spots() {
    let (mut renderer, mut settings) = renderer("cornell", (96, 64));
    settings.lights.count = 64;
    settings.lights.spots = half_spots(15.0, 35.0);
    settings.pipeline = PipelineSettings::naive(manylights::lights::Falloff::InverseSquare);
    renderer.render_frame(&settings).expect("naive");
    let naive = renderer.read_hdr().expect("hdr");
    assert_lit("64 lights, half spots, inverse-square", &naive, 0.5);
    for pipeline in clustered_variants(GBufferLayout::Full) {
        settings.pipeline = pipeline;
        for method in ["tree:0", "stochastic:0"] {
            let far: manylights::cluster::FarField = method.parse().expect("far field");
            settings
                .set_falloff(manylights::lights::Falloff::InverseSquare, Some(far))
                .expect("far field");
            renderer.render_frame(&settings).expect("frame");
            let image = renderer.read_hdr().expect("hdr");
            assert_hdr_close(&format!("{method}: {pipeline:?}"), &naive, &image, 1e-4);
        }
    }
}
