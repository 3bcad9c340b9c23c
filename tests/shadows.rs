//! Exact shadows end to end (lavapipe in CI): naive with shadow rays against the f64
//! reference with visibility at every pixel, Forward+ and deferred against naive, and the
//! cases where visibility must be exactly zero or stay finite.

use glam::{DVec3, Mat4, Vec3};
use manylights::deferred::rebuilt_position_error;
use manylights::lights::reference::{SurfacePoint, shade, shade_visible};
use manylights::lights::{Falloff, Light};
use manylights::visibility::test_scenes::{closed_box, merged, plane};
use manylights::visibility::{SceneBvh, shadow_offset};
use manylights::{
    Camera, Exposure, FrameSettings, GBufferLayout, LoadedScene, PipelineSettings, Renderer,
    Shadows,
};
use manylights_tests::{assert_hdr_close, assert_lit, clustered_variants, fixed_lights, gpu};

#[path = "shadows/filter_twin.rs"]
mod filter_twin;
#[path = "shadows/rays.rs"]
mod rays;
#[path = "shadows/reference.rs"]
mod reference;
#[path = "shadows/temporal.rs"]
mod temporal;

const SIZE: (u32, u32) = (128, 96);

/// Renders a frame and reads its HDR image.
fn render(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f32; 4]> {
    renderer.render_frame(settings).expect("frame");
    renderer.read_hdr().expect("hdr")
}

/// A renderer for a test scene built here (planes and boxes), its frame `size` at manual
/// exposure 1 from `camera`, lit by `lights` (position, radius, intensity).
fn built_scene(
    name: &str,
    scene: manylights::scene::Scene,
    size: (u32, u32),
    camera: Camera,
    lights: &[(Vec3, f32, f32)],
) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::from_scene(name, scene);
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = size;
    settings.post.exposure = Exposure::Manual(1.0);
    settings.view.camera = camera;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    renderer
        .set_fixed_lights(&fixed_lights(lights))
        .expect("lights");
    (renderer, settings)
}

fn cornell(lights: u32) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = SIZE;
    settings.lights.count = lights;
    settings.shadows.mode = Shadows::Exact;
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
    let camera = settings.view.camera.position.as_dvec3();
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
        let visible = |target: DVec3| bvh.light_visible(point.position, point.normal, target);
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
/// falloff: the same lights reach each pixel): the lossless full G-buffer and Forward+ to
/// 1e-4 in HDR; every layout and path decides each pixel's shadow rays as naive does (see
/// `assert_every_pipeline_sees_what_naive_sees`: the lossy layouts start their rays from
/// rebuilt positions, further off the surface).
#[test]
fn clustered_pipelines_with_exact_shadows_equal_naive() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::naive(Falloff::WindowedInverseSquare);
    let naive = render(&mut renderer, &settings);
    assert_lit("naive with shadows", &naive, 0.5);
    settings.shadows.mode = Shadows::Off;
    let unshadowed = render(&mut renderer, &settings);
    assert_ne!(naive, unshadowed, "the boxes cast shadows");
    settings.shadows.mode = Shadows::Exact;
    for pipeline in clustered_variants(GBufferLayout::Full) {
        settings.pipeline = pipeline;
        let image = render(&mut renderer, &settings);
        assert_hdr_close(
            &format!("{pipeline:?} with exact shadows"),
            &naive,
            &image,
            1e-4,
        );
    }
    assert_every_pipeline_sees_what_naive_sees(
        "cornell",
        &mut renderer,
        &settings,
        &every_clustered_pipeline(),
        Content {
            lit: 0.5,
            shadowed: 0.02,
        },
    );
}

/// A floor and a wall across it (x = 0), `wall_height` above the floor (4 m below it).
fn floor_and_wall(wall_height: f32) -> LoadedScene {
    let floor = plane(4.0, Mat4::IDENTITY);
    let lift = Mat4::from_translation(Vec3::new(0.0, wall_height - 4.0, 0.0));
    let wall = plane(
        4.0,
        lift * Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2),
    );
    let wall_back = plane(
        4.0,
        lift * Mat4::from_rotation_z(-std::f32::consts::FRAC_PI_2),
    );
    LoadedScene::from_scene("walled", merged([floor, wall, wall_back]))
}

/// A room of a floor and a wall across it (x = 0), the camera on the wall's -x side.
fn walled(lights: &[(Vec3, f32, f32)]) -> (Renderer, FrameSettings) {
    let loaded = floor_and_wall(4.0);
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = SIZE;
    settings.post.exposure = Exposure::Manual(1.0);
    settings.view.camera = Camera::look_at(
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
        settings.shadows.mode = Shadows::Off;
        assert_lit(
            &format!("{pipeline:?} without shadows"),
            &render(&mut renderer, &settings),
            0.3,
        );
        settings.shadows.mode = Shadows::Exact;
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
    settings.view.size = SIZE;
    settings.post.exposure = Exposure::Manual(1.0);
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
        settings.shadows.mode = Shadows::Exact;
        settings.view.camera = outside;
        let image = render(&mut renderer, &settings);
        assert!(
            image.iter().all(|p| p[..3] == [0.0; 3]),
            "{pipeline:?}: the box let light out"
        );
        settings.view.camera = within;
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
        settings.view.camera = within;
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
    settings.shadows.mode = Shadows::Exact;
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
    settings.lights.radius = manylights::lights::RadiusMode::Fixed(0.25);
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

/// What fraction of its unshadowed radiance each pixel keeps with shadows (the largest
/// channel's), or `None` where the unshadowed pixel is darker than
/// [`manylights_tests::DARK_FRACTION_OF_MEDIAN`] of the median lit channel. The ratio
/// cancels what a lossy G-buffer does to every light's term alike (the 8-bit albedo and
/// specular colour), so it isolates the shadow rays' decisions.
fn kept_fraction(shadowed: &[[f32; 4]], unshadowed: &[[f32; 4]]) -> Vec<Option<f32>> {
    let mut lit: Vec<f32> = unshadowed
        .iter()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .filter(|&v| v > 0.0)
        .collect();
    lit.sort_by(f32::total_cmp);
    let floor = lit.get(lit.len() / 2).copied().unwrap_or(0.0)
        * manylights_tests::DARK_FRACTION_OF_MEDIAN as f32;
    shadowed
        .iter()
        .zip(unshadowed)
        .map(|(s, u)| {
            let u = u[0].max(u[1]).max(u[2]);
            (u > floor).then(|| s[0].max(s[1]).max(s[2]) / u)
        })
        .collect()
}

/// How far a pixel's kept fraction may move between pipelines that decide every shadow
/// ray alike. If each light's term changes by a relative error within [-e, e], the kept
/// fraction f moves by at most 2 e f (1 - f) / (1 - e), under e / (2 (1 - e)). Lossless
/// frames (Forward+, the full G-buffer) sum the same f32 terms: e = 1e-4. The lossy layouts
/// quantize the albedo, the specular colour, the shininess and the normal:
/// e = `lossy_relative_bound()` (half an 8-bit sRGB step, 5%), so 2.6%. A lost light
/// (acne) or a black block moves it by the light's whole share.
fn kept_fraction_tolerance(pipeline: &PipelineSettings) -> f32 {
    let relative = match pipeline {
        PipelineSettings::Deferred(deferred) if deferred.layout != GBufferLayout::Full => {
            manylights_tests::lossy_relative_bound()
        }
        _ => 1e-4,
    };
    (relative / (2.0 * (1.0 - relative))) as f32
}

/// Asserts that `test` (shadowed and unshadowed frames) decides visibility as `naive` does
/// at every pixel: kept fractions within `tolerance` (see [`kept_fraction_tolerance`]),
/// except at the `sensitive` pixels (see [`offset_sensitive_pixels`]), which must be few.
/// Pixel by pixel: a block of wrong pixels or acne fails, where a mean over the frame
/// could hide either.
fn assert_same_visibility(
    label: &str,
    width: u32,
    tolerance: f32,
    sensitive: &[bool],
    naive: (&[[f32; 4]], &[[f32; 4]]),
    test: (&[[f32; 4]], &[[f32; 4]]),
) {
    let want = kept_fraction(naive.0, naive.1);
    let got = kept_fraction(test.0, test.1);
    let (mut compared, mut wrong) = (0, Vec::new());
    for (i, (want_here, got_here)) in want.iter().zip(&got).enumerate() {
        let (Some(want_here), Some(got_here)) = (want_here, got_here) else {
            continue;
        };
        if sensitive[i] {
            continue;
        }
        compared += 1;
        if (got_here - want_here).abs() > tolerance {
            let (x, y) = (i as u32 % width, i as u32 / width);
            wrong.push(format!(
                "({x}, {y}) keeps {got_here:.4}, naive {want_here:.4}"
            ));
        }
    }
    assert!(
        compared >= want.len() / 4,
        "{label}: only {compared} of {} pixels are lit enough to compare",
        want.len()
    );
    assert!(
        wrong.is_empty(),
        "{label}: {} of {compared} pixels keep another fraction of their unshadowed light \
         than naive's (tolerance {tolerance}): shadow rays decided otherwise. First: {}",
        wrong.len(),
        wrong.iter().take(8).cloned().collect::<Vec<_>>().join("; ")
    );
}

/// The pixels where a pipeline may decide a shadow ray otherwise than naive without being
/// wrong: a light's ray from the surface point passes an occluder's edge within the
/// distance by which the pipelines' ray origins may differ. Naive starts its ray from the
/// interpolated position at the offset rule's distance; a layout that rebuilds the
/// position from depth starts it `deferred::rebuilt_position_error` further off the
/// surface, from a point up to that far along the view ray; and every GPU ray carries a
/// few f32 roundings (16 ulps of the coordinates each way, as in
/// `robust_visibility`). The f64 tree decides each light's ray from every such origin;
/// where they disagree the pixel is sensitive.
fn offset_sensitive_pixels(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<bool> {
    let surface = renderer.capture_surface(settings).expect("surface");
    let lights = renderer.read_lights().expect("lights");
    let bvh = renderer.scene_bvh().expect("bvh");
    let camera = settings.view.camera;
    let eye = camera.position.as_dvec3();
    let aspect = settings.view.size.0 as f32 / settings.view.size.1 as f32;
    let projection = camera.projection(aspect).as_dmat4();
    let view = camera.view_matrix().as_dmat4();
    (0..surface.position.len())
        .map(|i| {
            if surface.position[i][3] != 1.0 {
                return false;
            }
            let point = SurfacePoint::from_capture(&surface, i);
            let (p, n) = (point.position, point.normal);
            let in_view = view.transform_point3(p);
            let clip = projection * in_view.extend(1.0);
            let error = rebuilt_position_error(
                projection,
                f64::from(settings.view.size.1),
                (clip.z / clip.w) as f32,
                (p - eye).length(),
                -in_view.z,
            );
            let along = (p - eye).normalize();
            let rounding = 16.0 * p.abs().max_element().max(1.0) * f64::from(f32::EPSILON);
            let mut origins = Vec::new();
            // The rebuilt point, anywhere within `error` along the view ray, starts its ray
            // `error` further along the normal than naive's.
            for ray_shift in [-error, 0.0, error] {
                origins.push(p + n * error + along * ray_shift);
            }
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                origins.push(p + axis * rounding);
                origins.push(p - axis * rounding);
            }
            lights.iter().any(|light| {
                let at = Vec3::from_array(light.position).as_dvec3();
                let reaches = (at - p).length() < f64::from(light.radius) && (at - p).dot(n) > 0.0;
                reaches && {
                    let visible = bvh.light_visible(p, n, at);
                    origins
                        .iter()
                        .any(|&o| bvh.light_visible(o, n, at) != visible)
                }
            })
        })
        .collect()
}

/// Sensitive pixels (see [`offset_sensitive_pixels`]) may be at most this fraction of the
/// frame: they are where shadows' edges and contacts fall, not whole surfaces.
const SENSITIVE_FRACTION: f64 = 0.1;

/// The frames a pipeline draws with `shadows` and without.
fn shadowed_and_unshadowed(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    shadows: Shadows,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut settings = settings.clone();
    settings.shadows.mode = shadows;
    let shadowed = render(renderer, &settings);
    settings.shadows.mode = Shadows::Off;
    (shadowed, render(renderer, &settings))
}

/// How much of naive's frame must be lit, and in shadow (keeping under half its light):
/// a comparison of two black frames, or of two unshadowed ones, would prove nothing.
#[derive(Clone, Copy)]
struct Content {
    lit: f64,
    shadowed: f64,
}

/// Most of the frame lit, a fiftieth of it in shadow.
const LIT_WITH_SHADOWS: Content = Content {
    lit: 0.3,
    shadowed: 0.02,
};

fn assert_content(label: &str, naive: (&[[f32; 4]], &[[f32; 4]]), content: Content) {
    assert_lit(label, naive.0, content.lit);
    let kept = kept_fraction(naive.0, naive.1);
    let shadowed = kept.iter().flatten().filter(|&&k| k < 0.5).count();
    assert!(
        shadowed as f64 >= content.shadowed * kept.len() as f64,
        "{label}: only {shadowed} pixels lose half their light to shadows"
    );
}

/// Every G-buffer layout, lighting path and Forward+ against naive, both with and without
/// exact shadows, for one scene and camera.
fn assert_every_pipeline_sees_what_naive_sees(
    label: &str,
    renderer: &mut Renderer,
    settings: &FrameSettings,
    pipelines: &[PipelineSettings],
    content: Content,
) {
    assert_pipelines_see_what_naive_sees(
        label,
        renderer,
        settings,
        pipelines,
        Shadows::Exact,
        content,
    );
}

/// `pipelines` with `shadows` (a mode that traces every light a pixel evaluates, on this
/// scene) against naive with exact shadows, both with and without shadows.
fn assert_pipelines_see_what_naive_sees(
    label: &str,
    renderer: &mut Renderer,
    settings: &FrameSettings,
    pipelines: &[PipelineSettings],
    shadows: Shadows,
    content: Content,
) {
    let mut naive_settings = settings.clone();
    naive_settings.pipeline = PipelineSettings::naive(Falloff::WindowedInverseSquare);
    let naive = shadowed_and_unshadowed(renderer, &naive_settings, Shadows::Exact);
    assert_content(label, (&naive.0, &naive.1), content);
    let sensitive = offset_sensitive_pixels(renderer, settings);
    let count = sensitive.iter().filter(|&&s| s).count();
    assert!(
        count as f64 <= SENSITIVE_FRACTION * sensitive.len() as f64,
        "{label}: {count} pixels have a shadow ray that the pipelines' origins may decide \
         otherwise"
    );
    for &pipeline in pipelines {
        let mut settings = settings.clone();
        settings.pipeline = pipeline;
        let frames = shadowed_and_unshadowed(renderer, &settings, shadows);
        assert_same_visibility(
            &format!("{label}, {pipeline:?}, shadows {shadows}"),
            settings.view.size.0,
            kept_fraction_tolerance(&pipeline),
            &sensitive,
            (&naive.0, &naive.1),
            (&frames.0, &frames.1),
        );
    }
}

/// Forward+ and every deferred layout with every lighting path.
fn every_clustered_pipeline() -> Vec<PipelineSettings> {
    GBufferLayout::ALL
        .into_iter()
        .flat_map(clustered_variants)
        .collect()
}

/// Forward+ and each layout that rebuilds positions from depth, with tiles lighting (the
/// default): the scenes beyond the wall's, where every path would cost CI minutes.
fn rebuilt_position_pipelines() -> Vec<PipelineSettings> {
    use manylights::LightingPath;
    let mut pipelines = vec![PipelineSettings::forward_plus()];
    pipelines.extend(
        [
            GBufferLayout::Compact,
            GBufferLayout::Packed,
            GBufferLayout::Visibility,
        ]
        .map(|layout| PipelineSettings::deferred(layout, LightingPath::Tiles)),
    );
    pipelines
}

const WALL_SIZE: (u32, u32) = (64, 64);

/// The frame of issue 46: a floor seen from straight above, a wall across it, one light on
/// one side. Layouts that rebuild positions from depth once drew a black block on the lit
/// side (a ray starting below the floor); now every pipeline, layout and lighting path
/// sees what naive sees, with standard and reversed Z, from above, at grazing angles and
/// at tilts and yaws between.
#[test]
fn every_layout_sees_the_lit_floor_beside_a_wall_as_naive_does() {
    let loaded = LoadedScene::load("wall").expect("the wall scene");
    let above = loaded.presets[0].1;
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = WALL_SIZE;
    settings.lights.count = 0;
    settings.post.exposure = Exposure::Manual(1.0);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let look = |position: Vec3, target: Vec3| Camera::look_at(position, target, 60.0, 0.07, 72.0);
    let cameras = [
        // A 0.1 mm near plane: with standard Z a depth ulp is then 4 cm at 8 m, and the
        // depth's ulps, not the pixel's footprint, bound the rebuilt position's error.
        // (First: the mutant that drops the ulps fails here at once.)
        (
            "from above, near 0.1 mm",
            Camera {
                near: 1e-4,
                ..above
            },
        ),
        ("from above", above),
        // Tilted and turned: the light's side and the wall's shadow in view.
        (
            "tilted",
            look(Vec3::new(1.5, 6.0, 3.0), Vec3::new(-1.5, 0.0, 0.0)),
        ),
        (
            "turned",
            look(Vec3::new(2.5, 9.0, -5.0), Vec3::new(-1.5, 0.0, 1.0)),
        ),
        // Grazing: the lit floor at 3 degrees and less (no shadow in view).
        (
            "grazing",
            look(Vec3::new(-4.9, 0.25, 4.9), Vec3::new(0.0, 0.0, -1.0)),
        ),
    ];
    for (name, camera) in cameras {
        let shadowed = if name == "grazing" { 0.0 } else { 0.02 };
        // Every path on the issue's own frame; the layouts that rebuild positions on the
        // others.
        let pipelines = if name == "from above" {
            every_clustered_pipeline()
        } else {
            rebuilt_position_pipelines()
        };
        for reverse_z in [false, true] {
            settings.view.camera = Camera {
                reverse_z,
                ..camera
            };
            assert_every_pipeline_sees_what_naive_sees(
                &format!("wall {name}, reverse Z {reverse_z}"),
                &mut renderer,
                &settings,
                &pipelines,
                Content { lit: 0.1, shadowed },
            );
        }
    }
}

/// A floor 200 m across with a wall 1 cm thick 60 m from the camera and lights beside
/// it: depth precision at 30 to 100 m, where a standard-Z depth ulp is a millimetre and
/// more, with standard and reversed Z.
#[test]
fn far_floors_and_a_thin_wall_are_shadowed_as_naive_does() {
    let floor = plane(100.0, Mat4::IDENTITY);
    let wall = closed_box(Vec3::new(60.0, 0.0, -30.0), Vec3::new(60.01, 4.0, 30.0));
    let loaded = LoadedScene::from_scene("far", merged([floor, wall]));
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (96, 64);
    settings.post.exposure = Exposure::Manual(1.0);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    // Lights on the camera's side of the wall, 1 to 3 m up and 2 to 8 m from it: the near
    // floor lit, the wall's shadow on the floor behind it.
    let lights: Vec<(Vec3, f32, f32)> = (0..12)
        .map(|i| {
            let z = -25.0 + 50.0 * (i / 2) as f32 / 5.0;
            let x = 60.0 - 2.0 - 6.0 * (i % 2) as f32;
            (Vec3::new(x, 1.0 + (i % 3) as f32, z), 30.0, 40.0)
        })
        .collect();
    renderer
        .set_fixed_lights(&fixed_lights(&lights))
        .expect("lights");
    for reverse_z in [false, true] {
        settings.view.camera = Camera {
            reverse_z,
            // 60 m above the floor, looking down past the wall's top at its shadow.
            ..Camera::look_at(
                Vec3::new(45.0, 60.0, 8.0),
                Vec3::new(64.0, 0.0, 0.0),
                50.0,
                0.05,
                500.0,
            )
        };
        assert_every_pipeline_sees_what_naive_sees(
            &format!("far floor, reverse Z {reverse_z}"),
            &mut renderer,
            &settings,
            &rebuilt_position_pipelines(),
            LIT_WITH_SHADOWS,
        );
    }
}

/// Sponza from three cameras (the gallery's corridor where the million-light frame showed
/// dotted acne 20 to 30 m away, its floor, and the gallery), at a size CI can afford:
/// every layout that rebuilds positions sees what naive sees.
#[test]
fn sponza_is_shadowed_as_naive_shadows_it_from_several_cameras() {
    let loaded = LoadedScene::load("sponza").expect("sponza");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (96, 54);
    settings.lights.count = 48;
    settings.lights.radius = manylights::lights::RadiusMode::Fixed(6.0);
    settings.post.exposure = Exposure::Manual(1.0);
    settings.lights.time = 4.1;
    let corridor = loaded.camera("10,6.5,-3.5,107,-13,65").expect("camera");
    let cameras = [
        ("corridor", corridor),
        ("floor", loaded.preset("floor").expect("floor preset")),
        ("gallery", loaded.preset("gallery").expect("gallery preset")),
    ];
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    for (name, camera) in cameras {
        settings.view.camera = camera;
        assert_every_pipeline_sees_what_naive_sees(
            &format!("sponza {name}"),
            &mut renderer,
            &settings,
            &rebuilt_position_pipelines(),
            LIT_WITH_SHADOWS,
        );
    }
}
