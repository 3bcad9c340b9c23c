//! Exact shadows end to end (lavapipe in CI): naive with shadow rays against the f64
//! reference with visibility at every pixel, Forward+ and deferred against naive, and the
//! cases where visibility must be exactly zero or stay finite.

use glam::{DVec3, Mat4, Vec3};
use manylights::lights::reference::{SurfacePoint, shade, shade_visible};
use manylights::lights::{Falloff, Light};
use manylights::visibility::test_scenes::{closed_box, merged, plane};
use manylights::visibility::{SceneBvh, shadow_offset};
use manylights::{
    Camera, Exposure, FrameSettings, GBufferLayout, LoadedScene, PipelineSettings, Renderer,
    Shadows,
};
use manylights_tests::{assert_hdr_close, assert_lit, clustered_variants, fixed_lights, gpu};

const SIZE: (u32, u32) = (128, 96);

/// Renders a frame and reads its HDR image.
fn render(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f32; 4]> {
    renderer.render_frame(settings).expect("frame");
    renderer.read_hdr().expect("hdr")
}

fn cornell(lights: u32) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = SIZE;
    settings.light_count = lights;
    settings.shadows = Shadows::Exact;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

/// Whether the f64 shadow ray's answer holds for every point within `delta` of `point`
/// along the axes: where it does not, the GPU's f32 ray (its start a few ulps away) may
/// answer the other way, and the pixel is not held to the reference.
fn robust_visibility(bvh: &SceneBvh, point: DVec3, normal: DVec3, light: DVec3) -> Option<bool> {
    let visible = bvh.light_visible(point, normal, light);
    // 16 f32 ulps of the point's largest coordinate: the surface capture and the shading
    // pass rasterize the same triangles, and the GPU adds the camera-relative origin.
    let delta = 16.0 * point.abs().max_element().max(1.0) * f64::from(f32::EPSILON);
    let moved = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        -DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
    ];
    moved
        .iter()
        .all(|m| bvh.light_visible(point + *m * delta, normal, light) == visible)
        .then_some(visible)
}

/// Naive with exact shadows equals the f64 reference with visibility at every pixel of
/// the cornell room (its two boxes cast shadows), within the naive test's tolerance: 1e-3
/// relative and one half-float ulp. Pixels where a light's shadow ray passes within f32
/// rounding of an edge (see `robust_visibility`) are counted, not compared, and must be
/// few.
#[test]
fn naive_with_exact_shadows_matches_the_f64_reference_with_visibility() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    let hdr = render(&mut renderer, &settings);
    let lights: Vec<Light> = renderer.read_lights().expect("lights");
    let surface = renderer.capture_surface(&settings).expect("surface");
    let bvh = renderer.scene_bvh().expect("bvh");
    let camera = settings.camera.position.as_dvec3();
    let (mut compared, mut fragile, mut shadowed) = (0, 0, 0);
    for (i, got) in hdr.iter().enumerate() {
        if surface.position[i][3] != 1.0 {
            continue;
        }
        let point = SurfacePoint::from_capture(&surface, i);
        let position = |light: &Light| Vec3::from_array(light.position).as_dvec3();
        let decisions: Vec<Option<bool>> = lights
            .iter()
            .map(|light| robust_visibility(&bvh, point.position, point.normal, position(light)))
            .collect();
        if decisions.iter().any(Option::is_none) {
            fragile += 1;
            continue;
        }
        compared += 1;
        let visible =
            |light: &Light| bvh.light_visible(point.position, point.normal, position(light));
        let want = shade_visible(&point, camera, &lights, Falloff::InverseSquare, visible);
        let unshadowed = shade(&point, camera, &lights, Falloff::InverseSquare);
        if (unshadowed - want).max_element() > 0.05 * unshadowed.max_element() {
            shadowed += 1;
        }
        for c in 0..3 {
            let (got, want) = (f64::from(got[c]), want[c]);
            let ulp = 2f64.powi(want.abs().max(2f64.powi(-14)).log2().floor() as i32 - 10);
            assert!(
                (got - want).abs() <= ulp + 1e-3 * want.abs(),
                "pixel ({}, {}) channel {c}: GPU {got}, f64 reference with visibility {want}",
                i as u32 % SIZE.0,
                i as u32 / SIZE.0
            );
        }
    }
    let pixels = (SIZE.0 * SIZE.1) as usize;
    assert!(
        fragile <= pixels / 100,
        "{fragile} pixels have a shadow ray within rounding of an edge"
    );
    assert!(
        compared + fragile == pixels,
        "the closed room covers every pixel"
    );
    assert!(
        shadowed > pixels / 20,
        "only {shadowed} pixels lose 5% to shadows: a test without shadows proves nothing"
    );
}

/// Forward+ and deferred with exact shadows equal naive with exact shadows (windowed
/// falloff: the same lights reach each pixel), to the clustered tests' tolerance (1e-4 for
/// the lossless full G-buffer, 0.06 for the compact one); the shadows change the image.
#[test]
fn clustered_pipelines_with_exact_shadows_equal_naive() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::naive(Falloff::WindowedInverseSquare);
    let naive = render(&mut renderer, &settings);
    assert_lit("naive with shadows", &naive, 0.5);
    settings.shadows = Shadows::Off;
    let unshadowed = render(&mut renderer, &settings);
    assert_ne!(naive, unshadowed, "the boxes cast shadows");
    settings.shadows = Shadows::Exact;
    for layout in [GBufferLayout::Full, GBufferLayout::Compact] {
        for pipeline in clustered_variants(layout) {
            settings.pipeline = pipeline;
            let image = render(&mut renderer, &settings);
            let relative = if layout == GBufferLayout::Full {
                1e-4
            } else {
                0.06
            };
            assert_hdr_close(
                &format!("{pipeline:?} with exact shadows"),
                &naive,
                &image,
                relative,
            );
        }
    }
}

/// A room of a floor and a wall across it (x = 0), the camera on the wall's -x side.
fn walled(lights: &[(Vec3, f32, f32)]) -> (Renderer, FrameSettings) {
    let floor = plane(4.0, Mat4::IDENTITY);
    let wall = plane(4.0, Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2));
    let wall_back = plane(4.0, Mat4::from_rotation_z(-std::f32::consts::FRAC_PI_2));
    let loaded = LoadedScene::from_scene("walled", merged([floor, wall, wall_back]));
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = SIZE;
    settings.exposure = Exposure::Manual(1.0);
    settings.camera = Camera::look_at(
        Vec3::new(-3.0, 2.0, 0.5),
        Vec3::new(0.0, 0.0, 0.0),
        60.0,
        0.05,
        100.0,
    );
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    renderer
        .set_fixed_lights(&fixed_lights(lights))
        .expect("lights");
    (renderer, settings)
}

fn every_pipeline() -> Vec<PipelineSettings> {
    let mut pipelines = vec![PipelineSettings::naive(Falloff::WindowedInverseSquare)];
    pipelines.extend(clustered_variants(GBufferLayout::Compact));
    pipelines
}

/// A light behind a wall adds exactly nothing to the far side, in every pipeline; without
/// shadows it lights it.
#[test]
fn a_light_behind_a_wall_adds_exactly_nothing() {
    let (mut renderer, mut settings) = walled(&[(Vec3::new(1.0, 0.5, 0.0), 6.0, 4.0)]);
    for pipeline in every_pipeline() {
        settings.pipeline = pipeline;
        settings.shadows = Shadows::Off;
        assert_lit(
            &format!("{pipeline:?} without shadows"),
            &render(&mut renderer, &settings),
            0.3,
        );
        settings.shadows = Shadows::Exact;
        let image = render(&mut renderer, &settings);
        assert!(
            image.iter().all(|p| p[..3] == [0.0; 3]),
            "{pipeline:?}: light crossed the wall"
        );
    }
}

/// A light inside a closed box lights nothing outside it; a camera inside the box (inside
/// geometry) sees its light, and a camera inside a box with the lights outside sees black.
#[test]
fn a_closed_box_keeps_its_light_in_and_the_camera_inside_sees_only_it() {
    // Double-sided, so that a camera inside sees its inner faces (a single-sided box is
    // culled from inside; its faces block shadow rays from either side all the same).
    let mut cube = closed_box(Vec3::new(-0.5, 0.5, -0.5), Vec3::new(0.5, 1.5, 0.5));
    cube.materials[0].double_sided = true;
    let scene = merged([plane(4.0, Mat4::IDENTITY), cube]);
    let loaded = LoadedScene::from_scene("boxed", scene);
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = SIZE;
    settings.exposure = Exposure::Manual(1.0);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let inside = Vec3::new(0.0, 1.0, 0.0);
    renderer
        .set_fixed_lights(&fixed_lights(&[(inside, 8.0, 4.0)]))
        .expect("lights");
    let outside = Camera::look_at(Vec3::new(3.0, 2.5, 3.0), Vec3::ZERO, 60.0, 0.05, 100.0);
    let within = Camera::look_at(
        inside + Vec3::new(0.2, 0.1, 0.0),
        inside + Vec3::X,
        90.0,
        0.01,
        100.0,
    );
    for pipeline in every_pipeline() {
        settings.pipeline = pipeline;
        settings.shadows = Shadows::Exact;
        settings.camera = outside;
        let image = render(&mut renderer, &settings);
        assert!(
            image.iter().all(|p| p[..3] == [0.0; 3]),
            "{pipeline:?}: the box let light out"
        );
        settings.camera = within;
        let image = render(&mut renderer, &settings);
        assert_lit(&format!("{pipeline:?} inside the box"), &image, 0.9);
        assert!(image.iter().all(|p| p.iter().all(|v| v.is_finite())));
    }
    // The lights outside, the camera inside: nothing reaches the inner walls.
    renderer
        .set_fixed_lights(&fixed_lights(&[
            (Vec3::new(2.0, 1.0, 0.0), 8.0, 4.0),
            (Vec3::new(0.0, 3.0, 0.0), 8.0, 4.0),
        ]))
        .expect("lights");
    for pipeline in every_pipeline() {
        settings.pipeline = pipeline;
        settings.camera = within;
        let image = render(&mut renderer, &settings);
        assert!(
            image.iter().all(|p| p[..3] == [0.0; 3]),
            "{pipeline:?}: light entered the closed box"
        );
    }
}

/// A light resting on the floor (exactly in its plane) and many lights at one point: finite
/// images, the floor unlit by the light in its plane, the wall lit; every pipeline agrees
/// with naive.
#[test]
fn lights_on_a_surface_and_in_one_spot_stay_finite() {
    let mut lights = vec![(Vec3::new(-1.0, 0.0, 0.5), 3.0, 2.0)];
    lights.extend(std::iter::repeat_n(
        (Vec3::new(-1.5, 1.0, -1.0), 2.5, 0.01),
        1000,
    ));
    let (mut renderer, mut settings) = walled(&lights);
    settings.shadows = Shadows::Exact;
    settings.pipeline = PipelineSettings::naive(Falloff::WindowedInverseSquare);
    let naive = render(&mut renderer, &settings);
    assert!(naive.iter().all(|p| p.iter().all(|v| v.is_finite())));
    assert_lit("lights on the floor and in one spot", &naive, 0.3);
    for pipeline in clustered_variants(GBufferLayout::Full) {
        settings.pipeline = pipeline;
        assert_hdr_close(
            &format!("{pipeline:?}"),
            &naive,
            &render(&mut renderer, &settings),
            1e-4,
        );
    }
    // The offset rule keeps a light in the plane from being hidden by the plane itself:
    // points of the wall see it.
    let bvh = renderer.scene_bvh().expect("bvh");
    let light = DVec3::new(-1.0, 0.0, 0.5);
    let wall_point = DVec3::new(0.0, 1.0, 0.5);
    assert!(shadow_offset(wall_point) < 1e-3);
    assert!(bvh.light_visible(wall_point, -DVec3::X, light));
}

/// 100,000 lights with exact shadows: a finite image, and the BVH's memory does not grow
/// with the lights (it is the scene's).
#[test]
fn a_hundred_thousand_lights_with_shadows_stay_finite() {
    let (mut renderer, mut settings) = cornell(100_000);
    settings.radius = manylights::lights::RadiusMode::Fixed(0.25);
    settings.pipeline = PipelineSettings::forward_plus();
    let image = render(&mut renderer, &settings);
    assert!(image.iter().all(|p| p.iter().all(|v| v.is_finite())));
    assert_lit("100,000 lights with shadows", &image, 0.5);
    let bvh = renderer.scene_bvh().expect("bvh");
    assert_eq!(
        bvh.triangles().len(),
        renderer.scene().scene.triangle_count(),
        "the tree holds the scene's triangles, whatever the lights"
    );
}

/// The far field with shadows: at tolerance 0 every cut entry of the tree is exact (each
/// light its own ray) and the stochastic method keeps every light, so both equal naive
/// inverse-square with exact shadows, to the far-field tests' tolerance (the aggregates'
/// rays, one to each power centroid, are the approximation above tolerance 0).
#[test]
fn the_far_field_with_shadows_at_tolerance_zero_is_exact() {
    use manylights::cluster::{FarField, FarFieldMethod};
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    let reference = render(&mut renderer, &settings);
    assert_lit("naive inverse-square with shadows", &reference, 0.5);
    for pipeline in clustered_variants(GBufferLayout::Full) {
        for method in [FarFieldMethod::Tree, FarFieldMethod::Stochastic] {
            let mut far = settings.clone();
            far.pipeline = pipeline;
            far.set_falloff(
                Falloff::InverseSquare,
                Some(FarField {
                    seed: 3,
                    ..FarField::with_tolerance(method, 0.0)
                }),
            )
            .expect("settings");
            let image = render(&mut renderer, &far);
            assert_hdr_close(
                &format!("{pipeline:?} {method} far field at tolerance 0 with shadows"),
                &reference,
                &image,
                1e-4,
            );
        }
    }
}
