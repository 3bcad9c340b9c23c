//! Shadows with a fixed ray budget (`Shadows::Rays`): exact where the budget covers every
//! light, converging to exact as it grows, reproducible, and exactly dark behind a wall.

use super::{Content, WALL_SIZE, assert_pipelines_see_what_naive_sees, cornell, render, walled};
use glam::Vec3;
use manylights::lights::Falloff;
use manylights::{GBufferLayout, PipelineSettings, Shadows};
use manylights_tests::{assert_hdr_close, assert_lit, clustered_variants};

/// With at most K lights a pixel, K rays give every light its own ray: the same image as
/// exact shadows, in every pipeline, to the lossless comparison's 1e-4 (the sum is scaled
/// by visible terms over all terms instead of summing the visible terms: a few f32
/// roundings apart).
#[test]
fn a_ray_for_every_light_is_exact_shadows() {
    let (mut renderer, mut settings) = cornell(4);
    let mut pipelines = vec![PipelineSettings::naive(Falloff::WindowedInverseSquare)];
    pipelines.extend(clustered_variants(GBufferLayout::Full));
    pipelines.extend(clustered_variants(GBufferLayout::Compact));
    for pipeline in pipelines {
        settings.pipeline = pipeline;
        settings.shadows.mode = Shadows::Exact;
        let exact = render(&mut renderer, &settings);
        assert_lit(&format!("{pipeline:?} with exact shadows"), &exact, 0.3);
        settings.shadows.mode = Shadows::Off;
        assert_ne!(
            exact,
            render(&mut renderer, &settings),
            "the boxes cast shadows"
        );
        settings.shadows.mode = Shadows::Rays(4);
        let rays = render(&mut renderer, &settings);
        assert_hdr_close(
            &format!("{pipeline:?} with 4 rays, 4 lights"),
            &exact,
            &rays,
            1e-4,
        );
    }
}

/// Where shadows are partial, the error of the ray budget's image against exact shadows,
/// a pixel at a time, as a share of the pixel's unshadowed luminance: within [-1, 1], since
/// both images lie between black and the unshadowed pixel; its magnitude if `absolute`.
fn partial_shadow_errors(
    exact: &[[f32; 4]],
    unshadowed: &[[f32; 4]],
    rays: &[[f32; 4]],
    absolute: bool,
) -> Vec<f64> {
    let luminance = |p: &[f32; 4]| {
        0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
    };
    exact
        .iter()
        .zip(unshadowed)
        .zip(rays)
        .filter_map(|((e, u), r)| {
            let (e, u, r) = (luminance(e), luminance(u), luminance(r));
            // Partial: neither every light's term kept nor all lost (1e-3: rounding).
            (u > 0.0 && e > 1e-3 * u && e < (1.0 - 1e-3) * u).then(|| {
                let error = (r - e) / u;
                if absolute { error.abs() } else { error }
            })
        })
        .collect()
}

/// The ratio estimator converges to exact shadows as the budget grows: on the cornell
/// room's 64 lights (up to dozens a pixel), the mean error over the partially shadowed
/// pixels falls with every doubling of the rays. Same seed, same image: every frame is
/// rendered twice and must be identical.
///
/// A statistical test. Each mean is over at least 1,000 pixels drawing independent random
/// numbers, so it is normal to within the central limit theorem, with a standard error
/// from the pixels' own spread. Each doubling must lower the mean by more than 4 standard
/// errors of the difference. An estimator that did not improve would pass one doubling by
/// chance with probability 3e-5 (one-sided, 4 sigma). A converging one is expected to
/// lower its error by 1 - 1/sqrt(2) a doubling (more once the strata hold every light):
/// measured on lavapipe, 12.0 and 17.3 standard errors, so it fails with probability below
/// 1e-12 (7 sigma beyond the threshold).
#[test]
fn the_ray_budget_converges_to_exact_shadows() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline =
        PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Tiles);
    settings.shadows.mode = Shadows::Exact;
    let exact = render(&mut renderer, &settings);
    settings.shadows.mode = Shadows::Off;
    let unshadowed = render(&mut renderer, &settings);
    let mut means = Vec::new();
    for rays in [1, 2, 4] {
        settings.shadows.mode = Shadows::Rays(rays);
        let image = render(&mut renderer, &settings);
        assert_eq!(
            image,
            render(&mut renderer, &settings),
            "{rays} rays: same seed, same image"
        );
        let errors = partial_shadow_errors(&exact, &unshadowed, &image, true);
        let n = errors.len() as f64;
        assert!(n >= 1000.0, "only {n} partially shadowed pixels");
        let mean = errors.iter().sum::<f64>() / n;
        let variance = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0);
        means.push((rays, mean, variance / n));
    }
    for pair in means.windows(2) {
        let ((fewer, before, before_var), (more, after, after_var)) = (pair[0], pair[1]);
        let sigmas = (before - after) / (before_var + after_var).sqrt();
        eprintln!(
            "{fewer} -> {more} rays: mean error {before:.4} -> {after:.4}, {sigmas:.1} sigma"
        );
        assert!(
            sigmas > 4.0,
            "{fewer} -> {more} rays: the error fell by only {sigmas:.1} standard errors ({means:?})"
        );
    }
}

/// The ray budget is unbiased at every pixel, to within what noise shows, when every light
/// is white. One ray's ratio is the kept light's visibility (0 or 1), a light kept with
/// probability its luminance's share: exactly unbiased. Two rays weigh their lights by
/// what each stands for, and the ratio estimator's bias (it divides two estimates) is far
/// below the noise. Over `FRAMES` seeds, each partially shadowed pixel's mean then
/// differs from exact shadows only by noise: the squared differences summed over the
/// pixels match the sum of the means' variances (estimated from the frames' spread).
///
/// The ratio of the two sums is 1 give or take a few percent over thousands of pixels
/// (measured on lavapipe over 6,174 pixels: 1.04 with one ray, 1.00 with two); it must
/// stay below 1.25. A wrong probability or weight adds each pixel's bias squared:
/// measured, a reservoir skipping by count instead of weight 8.9 (one ray), and an
/// estimate that forgets the weight dealt to its ray 2.9 (two rays).
#[test]
fn the_ray_budget_is_unbiased_at_every_pixel_under_white_lights() {
    for rays in [1, 2] {
        let ratio = squared_bias_over_noise(rays);
        assert!(
            ratio < 1.25,
            "{rays} rays are biased: squared mean errors {ratio:.2} times the means' variance"
        );
    }
}

/// [`the_ray_budget_is_unbiased_at_every_pixel_under_white_lights`]'s statistic for `rays`.
fn squared_bias_over_noise(rays: u32) -> f64 {
    const FRAMES: u32 = 48;
    let (mut renderer, mut settings) = cornell(64);
    settings.lights.saturation = 0.0;
    settings.pipeline =
        PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Compute);
    settings.shadows.mode = Shadows::Exact;
    let exact = render(&mut renderer, &settings);
    settings.shadows.mode = Shadows::Off;
    let unshadowed = render(&mut renderer, &settings);
    settings.shadows.mode = Shadows::Rays(rays);
    let frames: Vec<Vec<[f32; 4]>> = (0..FRAMES)
        .map(|seed| {
            settings.shadows.seed = seed;
            render(&mut renderer, &settings)
        })
        .collect();
    let (mut squared_bias, mut noise, mut pixels) = (0.0, 0.0, 0);
    for i in 0..exact.len() {
        let per_frame: Vec<[f32; 4]> = frames.iter().map(|frame| frame[i]).collect();
        let errors =
            partial_shadow_errors(&exact[i..=i], &unshadowed[i..=i], &per_frame[..1], false);
        if errors.is_empty() {
            continue;
        }
        let samples: Vec<f64> = per_frame
            .iter()
            .flat_map(|sample| {
                partial_shadow_errors(&exact[i..=i], &unshadowed[i..=i], &[*sample], false)
            })
            .collect();
        let n = f64::from(FRAMES);
        let mean = samples.iter().sum::<f64>() / n;
        let variance = samples.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0);
        squared_bias += mean * mean;
        noise += variance / n;
        pixels += 1;
    }
    assert!(pixels >= 1000, "only {pixels} partially shadowed pixels");
    let ratio = squared_bias / noise;
    eprintln!(
        "{rays} rays, white lights, {FRAMES} seeds: squared mean error over the means' variance {ratio:.3} ({pixels} pixels)"
    );
    ratio
}

/// A light behind a wall adds exactly nothing to the far side with a ray budget, alone or
/// among lights on the near side, in every pipeline: every ray to it is blocked, and the
/// near lights' rays are all visible, so each pixel's ratio is exact.
#[test]
fn a_ray_budget_keeps_the_far_side_of_a_wall_black() {
    let (mut renderer, mut settings) = walled(&[(Vec3::new(1.0, 0.5, 0.0), 6.0, 4.0)]);
    for pipeline in super::every_pipeline() {
        settings.pipeline = pipeline;
        settings.shadows.mode = Shadows::Rays(1);
        let image = render(&mut renderer, &settings);
        assert!(
            image.iter().all(|p| p[..3] == [0.0; 3]),
            "{pipeline:?}: light crossed the wall"
        );
    }
}

/// The paths the spatial filter follows: deferred's compute lighting, and the forward
/// pipelines' shadow pass.
fn filtered_paths() -> [PipelineSettings; 4] {
    [
        PipelineSettings::deferred(GBufferLayout::Compact, manylights::LightingPath::Compute),
        PipelineSettings::deferred(GBufferLayout::Compact, manylights::LightingPath::Tiles),
        PipelineSettings::forward_plus(),
        PipelineSettings::naive(Falloff::WindowedInverseSquare),
    ]
}

/// The spatial filter leaves a frame that nothing shadows exactly as it was: every ray
/// finds its light, every share is 1, and the filter's weighted mean of ones is one (the
/// same sums over and under the fraction). A floor lit by lights above it, nothing in the
/// way: the filtered image equals the unshadowed one, bit for bit.
#[test]
fn the_spatial_filter_leaves_an_unshadowed_frame_unchanged() {
    let lights: Vec<(Vec3, f32, f32)> = (0..16)
        .map(|i| {
            let (x, z) = ((i % 4) as f32 - 1.5, (i / 4) as f32 - 1.5);
            (Vec3::new(x, 0.5 + 0.1 * i as f32, z), 3.0, 2.0)
        })
        .collect();
    let floor = manylights::visibility::test_scenes::plane(4.0, glam::Mat4::IDENTITY);
    let loaded = manylights::LoadedScene::from_scene("floor", floor);
    let mut settings = manylights::FrameSettings::for_scene(&loaded);
    settings.view.size = super::SIZE;
    settings.post.exposure = manylights::Exposure::Manual(1.0);
    settings.view.camera =
        manylights::Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, 60.0, 0.05, 100.0);
    let mut renderer =
        manylights::Renderer::new(manylights_tests::gpu(), loaded).expect("renderer");
    renderer
        .set_fixed_lights(&manylights_tests::fixed_lights(&lights))
        .expect("lights");
    for pipeline in filtered_paths() {
        settings.pipeline = pipeline;
        settings.shadows.mode = Shadows::Off;
        let unshadowed = render(&mut renderer, &settings);
        assert_lit(&format!("{pipeline:?}"), &unshadowed, 0.5);
        // With history too, for several frames: the history holds ones, and a step of
        // zero from one is one.
        for shadows in [Shadows::RaysSpatial(1), Shadows::RaysTemporal(1)] {
            settings.shadows.mode = shadows;
            for frame in 0..3 {
                settings.shadows.seed = frame;
                assert!(
                    unshadowed == render(&mut renderer, &settings),
                    "{pipeline:?}, {shadows}, frame {frame}: the filter changed a frame without shadows"
                );
            }
        }
    }
    // Paths the filter does not follow refuse it, saying what they can trace: deferred's
    // fragment path, and the forward pipelines with more than the shadow pass's one ray.
    for (pipeline, rays) in [
        (PipelineSettings::forward_plus(), 2),
        (PipelineSettings::naive(Falloff::WindowedInverseSquare), 4),
        (
            PipelineSettings::deferred(GBufferLayout::Compact, manylights::LightingPath::Fragment),
            1,
        ),
    ] {
        settings.pipeline = pipeline;
        settings.shadows.mode = Shadows::RaysTemporal(rays);
        let error = renderer
            .render_frame(&settings)
            .expect_err("refused")
            .to_string();
        assert!(
            error.contains("spatial filter") && error.contains("`rays:1`"),
            "{error}"
        );
    }
}

/// The spatial filter never carries light across a wall: a light on one side of a wall
/// lights that side's floor, and reaches the other side's floor only through the wall
/// (unshadowed, it would light it; every ray there is blocked). Seen from high above, both
/// floors lie in one plane either side of the wall's face, a band 3 to 4 pixels wide
/// (fewer than the filter's 6 taps a side): the filter's walk must stop at the wall, or
/// the dark side takes the lit side's share. Every pixel of the dark side stays exactly
/// black, in both compute paths, with the filter alone and with history, while the lit
/// side is lit.
#[test]
fn the_spatial_filter_keeps_the_far_side_of_a_wall_black() {
    let (mut renderer, mut settings) = walled(&[(Vec3::new(1.0, 0.5, 0.0), 6.0, 4.0)]);
    settings.view.camera = manylights::Camera::look_at(
        Vec3::new(-0.3, 8.0, 0.0),
        Vec3::new(0.3, 0.0, 0.0),
        60.0,
        0.05,
        100.0,
    );
    for pipeline in filtered_paths() {
        settings.pipeline = pipeline;
        let [unshadowed, spatial, image] = filtered_frames(&mut renderer, &mut settings);
        let surface = renderer.capture_surface(&settings).expect("surface");
        let (mut dark_side, mut lit_side, mut wall, mut reached) = (0, 0, 0, 0);
        for (i, pixel) in image.iter().enumerate() {
            let position =
                surface.origin + glam::Vec3::from_slice(&surface.position[i][..3]).as_dvec3();
            let normal = surface.normal_lobe[i];
            if surface.position[i][3] != 1.0 {
                continue;
            }
            if normal[1] < 0.5 {
                wall += 1;
                continue;
            }
            if position.x < -1e-3 {
                dark_side += 1;
                reached += usize::from(unshadowed[i][..3] != [0.0; 3]);
                assert_eq!(
                    (&spatial[i][..3], &pixel[..3]),
                    (&[0.0f32; 3][..], &[0.0f32; 3][..]),
                    "{pipeline:?}: light crossed the wall at pixel {i} (spatial filter, with history)"
                );
            } else if pixel[..3] != [0.0; 3] {
                lit_side += 1;
            }
        }
        eprintln!(
            "{pipeline:?}: {dark_side} dark-side pixels ({reached} reached unshadowed), {lit_side} lit, {wall} on the wall"
        );
        assert!(
            reached > 500,
            "the light must reach the dark side unshadowed: a test with nothing to keep out proves nothing"
        );
        assert!(lit_side > 500, "the lit side must be lit");
    }
}

/// The frame unshadowed, with one ray a pixel and the spatial filter, and with history
/// over three frames (the filter's two outputs a test holds against the first).
fn filtered_frames(
    renderer: &mut manylights::Renderer,
    settings: &mut manylights::FrameSettings,
) -> [Vec<[f32; 4]>; 3] {
    settings.shadows.mode = Shadows::Off;
    let unshadowed = render(renderer, settings);
    settings.shadows.mode = Shadows::RaysSpatial(1);
    let spatial = render(renderer, settings);
    settings.shadows.mode = Shadows::RaysTemporal(1);
    let (_, history) = super::temporal::last_frames(renderer, settings, 0, 3);
    [unshadowed, spatial, history]
}

/// The filter's plane rule: a floor with a step up, seen from above the upper floor, so
/// that the lower floor's pixels lie next to the upper floor's edge on screen with the same
/// normal and 0.3 m further down. One low light over the upper floor lights the upper floor
/// (share 1) and leaves the visible lower floor in the step's shadow (share 0) while
/// facing it (unshadowed light above 0). The walk must stop at the depth step: every pixel
/// of the lower floor stays exactly black with the spatial filter and with history, in
/// every path that filters. A filter that no longer compares the taps' planes lets the
/// edge's light onto the lower floor.
#[test]
fn the_spatial_filter_stops_at_a_depth_step() {
    use manylights::visibility::test_scenes::{merged, plane};
    let lower = plane(2.0, glam::Mat4::from_translation(Vec3::new(-1.0, 0.0, 0.0)));
    let upper = plane(2.0, glam::Mat4::from_translation(Vec3::new(2.0, 0.3, 0.0)));
    let camera = manylights::Camera::look_at(
        Vec3::new(0.8, 1.2, 0.0),
        Vec3::new(-1.5, 0.0, 0.0),
        60.0,
        0.05,
        100.0,
    );
    let light = (Vec3::new(3.0, 0.5, 0.0), 6.0, 4.0);
    let (mut renderer, mut settings) =
        super::built_scene("step", merged([lower, upper]), (64, 48), camera, &[light]);
    for pipeline in filtered_paths() {
        settings.pipeline = pipeline;
        let [unshadowed, spatial, history] = filtered_frames(&mut renderer, &mut settings);
        let surface = renderer.capture_surface(&settings).expect("surface");
        let (mut lower_floor, mut reached, mut upper_lit) = (0, 0, 0);
        for i in 0..history.len() {
            if surface.position[i][3] != 1.0 {
                continue;
            }
            let height = surface.origin.y + f64::from(surface.position[i][1]);
            if height < 0.15 {
                lower_floor += 1;
                reached += usize::from(unshadowed[i][..3] != [0.0; 3]);
                assert_eq!(
                    (&spatial[i][..3], &history[i][..3]),
                    (&[0.0f32; 3][..], &[0.0f32; 3][..]),
                    "{pipeline:?}: the upper floor's light crossed the step at pixel {i} (spatial filter, with history)"
                );
            } else if history[i][..3] != [0.0; 3] {
                upper_lit += 1;
            }
        }
        eprintln!(
            "{pipeline:?}: {lower_floor} lower-floor pixels ({reached} reached unshadowed), {upper_lit} upper lit"
        );
        assert!(
            reached > 300,
            "the light must reach the lower floor unshadowed: a test with nothing to keep out proves nothing"
        );
        assert!(upper_lit > 300, "the upper floor must be lit");
    }
}

/// The filter's normal rule: a floor meets a ramp rising at 30 degrees (normals 30 degrees
/// apart, beyond the filter's 25), seen from 8 m above the crease. A low light beyond a
/// low wall leaves the floor up to the crease in the wall's shadow (share 0, while the
/// light is above the floor's plane) and lights the ramp from 3.5 cm up (share 1). Near
/// the crease the ramp's first taps lie within the plane rule's 1% of 8 m of the floor's
/// plane, so only the normals tell them apart: every floor pixel between the wall and the
/// crease stays exactly black with the spatial filter and with history, in every path
/// that filters. A filter that no longer compares normals blurs the ramp's light onto the
/// floor it meets.
#[test]
fn the_spatial_filter_stops_at_a_crease() {
    use manylights::visibility::test_scenes::{closed_box, merged, plane};
    let slope = 30f32.to_radians();
    let floor = plane(2.0, glam::Mat4::from_translation(Vec3::new(-2.0, 0.0, 0.0)));
    let ramp = plane(
        1.0,
        glam::Mat4::from_translation(Vec3::new(slope.cos(), slope.sin(), 0.0))
            * glam::Mat4::from_rotation_z(slope),
    );
    let wall = closed_box(Vec3::new(-2.05, 0.0, -2.0), Vec3::new(-1.95, 0.334, 2.0));
    let camera =
        manylights::Camera::look_at(Vec3::new(-0.3, 8.0, 0.0), Vec3::ZERO, 30.0, 0.05, 100.0);
    let light = (Vec3::new(-3.0, 0.5, 0.0), 6.0, 4.0);
    let scene = merged([floor, ramp, wall]);
    let (mut renderer, mut settings) =
        super::built_scene("crease", scene, super::SIZE, camera, &[light]);
    for pipeline in filtered_paths() {
        settings.pipeline = pipeline;
        let [unshadowed, spatial, history] = filtered_frames(&mut renderer, &mut settings);
        let surface = renderer.capture_surface(&settings).expect("surface");
        let (mut shadowed_floor, mut reached, mut ramp_lit) = (0, 0, 0);
        for i in 0..history.len() {
            if surface.position[i][3] != 1.0 {
                continue;
            }
            let x = surface.origin.x + f64::from(surface.position[i][0]);
            let up = surface.normal_lobe[i][1];
            if up > 0.99 && x > -1.9 && x < -1e-3 {
                shadowed_floor += 1;
                reached += usize::from(unshadowed[i][..3] != [0.0; 3]);
                assert_eq!(
                    (&spatial[i][..3], &history[i][..3]),
                    (&[0.0f32; 3][..], &[0.0f32; 3][..]),
                    "{pipeline:?}: the ramp's light crossed the crease at pixel {i}, x = {x:.3} (spatial filter, with history)"
                );
            } else if up < 0.9 && x > 0.0 && history[i][..3] != [0.0; 3] {
                ramp_lit += 1;
            }
        }
        eprintln!(
            "{pipeline:?}: {shadowed_floor} shadowed floor pixels ({reached} reached unshadowed), {ramp_lit} ramp lit"
        );
        assert!(
            reached > 1000,
            "the light must reach the floor unshadowed: a test with nothing to keep out proves nothing"
        );
        assert!(ramp_lit > 1000, "the ramp must be lit");
    }
}

/// A far-field aggregate's ray aims at one of its lights, drawn by power, not at its power
/// centroid. Two lights of equal power 2 m either side of a small closed box that holds
/// their centroid, above a floor beyond their radius: the floor's light is all far field,
/// one aggregate of both (a tolerance that takes the tree's root). Every ray to the
/// centroid is blocked, so exact shadows (one ray to each aggregate's centroid) leave the
/// floor black. With both lights in plain view every drawn light is visible: one ray a
/// pixel gives the unshadowed image. With the second light shut in a box of its own, half
/// the node's power reaches the floor: one ray's share is 0 or 1 with probability 1/2 each,
/// and over 32 seeds and thousands of floor pixels (each pixel's draws independent) the
/// mean share must lie within 5 standard errors of 1/2 (a false failure once in 1.7
/// million runs).
#[test]
fn a_far_field_aggregate_is_shadowed_light_by_light() {
    use manylights::cluster::{FarField, FarFieldMethod};
    use manylights::visibility::test_scenes::{closed_box, merged, plane};
    let (left, right) = (Vec3::new(-1.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0));
    let centroid_box = closed_box(Vec3::new(-0.25, 1.75, -0.25), Vec3::new(0.25, 2.25, 0.25));
    let shut = |centre: Vec3| closed_box(centre - Vec3::splat(0.2), centre + Vec3::splat(0.2));
    let scenes = [
        (
            "both lights in view",
            merged([plane(4.0, glam::Mat4::IDENTITY), centroid_box.clone()]),
        ),
        (
            "the right light shut in",
            merged([plane(4.0, glam::Mat4::IDENTITY), centroid_box, shut(right)]),
        ),
    ];
    for (name, scene) in scenes {
        let loaded = manylights::LoadedScene::from_scene(name, scene);
        let mut settings = manylights::FrameSettings::for_scene(&loaded);
        settings.view.size = super::SIZE;
        settings.post.exposure = manylights::Exposure::Manual(1.0);
        settings.view.camera = manylights::Camera::look_at(
            Vec3::new(0.0, 1.2, 4.0),
            Vec3::new(0.0, 0.0, 0.0),
            60.0,
            0.05,
            100.0,
        );
        settings.pipeline =
            PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Compute);
        manylights_tests::clustering_mut(&mut settings).far_field = Some(FarField {
            tolerance: 1000.0,
            ..FarField::new(FarFieldMethod::Tree)
        });
        let mut renderer =
            manylights::Renderer::new(manylights_tests::gpu(), loaded).expect("renderer");
        renderer
            .set_fixed_lights(&manylights_tests::fixed_lights(&[
                (left, 0.3, 4.0),
                (right, 0.3, 4.0),
            ]))
            .expect("lights");
        settings.shadows.mode = Shadows::Off;
        let unshadowed = render(&mut renderer, &settings);
        let surface = renderer.capture_surface(&settings).expect("surface");
        let floor: Vec<usize> = (0..unshadowed.len())
            .filter(|&i| {
                surface.position[i][3] == 1.0
                    && surface.normal_lobe[i][1] > 0.99
                    && unshadowed[i][1] > 0.0
            })
            .collect();
        assert!(
            floor.len() > 2000,
            "{name}: only {} lit floor pixels",
            floor.len()
        );
        settings.shadows.mode = Shadows::Exact;
        let centroid_rule = render(&mut renderer, &settings);
        assert!(
            floor.iter().all(|&i| centroid_rule[i][..3] == [0.0; 3]),
            "{name}: the centroid's box must block every ray to it (the aggregate's lights are not in it)"
        );
        settings.shadows.mode = Shadows::Rays(1);
        if name == "both lights in view" {
            let image = render(&mut renderer, &settings);
            for &i in &floor {
                let share = image[i][1] / unshadowed[i][1];
                assert!(
                    (share - 1.0).abs() < 1e-3,
                    "{name}: pixel {i} keeps {share} of its light, not all"
                );
            }
            continue;
        }
        const SEEDS: u32 = 32;
        let mut shares = vec![0.0f64; floor.len()];
        for seed in 0..SEEDS {
            settings.shadows.seed = seed;
            let image = render(&mut renderer, &settings);
            for (share, &i) in shares.iter_mut().zip(&floor) {
                *share += f64::from(image[i][1] / unshadowed[i][1]) / f64::from(SEEDS);
            }
        }
        let mean = shares.iter().sum::<f64>() / shares.len() as f64;
        // Each draw is 0 or 1 with probability 1/2: standard deviation 1/2.
        let standard_error = 0.5 / ((shares.len() as f64) * f64::from(SEEDS)).sqrt();
        eprintln!(
            "{name}: mean share {mean:.4} over {} pixels, standard error {standard_error:.5}",
            shares.len()
        );
        assert!(
            (mean - 0.5).abs() < 5.0 * standard_error,
            "{name}: the floor keeps {mean:.4} of its light on average, not 1/2"
        );
    }
}

/// The forward pipelines' shadow pass decides every ray as naive's exact shadows do. With
/// `rays:1`, Forward+ (with its depth pre-pass and without) and naive keep each pixel's
/// ray in the fragment shader and trace it in compute, from the position rebuilt from
/// depth and further off the surface by that position's error bound. With one light a
/// pixel, one ray a pixel is exact shadows: on issue 46's wall scene (one light), from
/// above and tilted, with standard and reversed Z, every pixel keeps what naive with
/// exact shadows keeps, to the lossless tolerance, but where the ray origins may decide
/// otherwise (`offset_sensitive_pixels`, at most a tenth of the frame).
#[test]
fn the_forward_shadow_pass_is_exact_with_one_light() {
    let loaded = manylights::LoadedScene::load("wall").expect("the wall scene");
    let above = loaded.presets[0].1;
    let mut settings = manylights::FrameSettings::for_scene(&loaded);
    settings.view.size = WALL_SIZE;
    settings.lights.count = 0;
    settings.post.exposure = manylights::Exposure::Manual(1.0);
    let mut renderer =
        manylights::Renderer::new(manylights_tests::gpu(), loaded).expect("renderer");
    let without_prepass =
        manylights::PipelineSettings::ForwardPlus(manylights::forward_plus::ForwardPlusSettings {
            depth_prepass: false,
            ..Default::default()
        });
    let pipelines = [
        PipelineSettings::naive(Falloff::WindowedInverseSquare),
        PipelineSettings::forward_plus(),
        without_prepass,
    ];
    let tilted = manylights::Camera::look_at(
        Vec3::new(1.5, 6.0, 3.0),
        Vec3::new(-1.5, 0.0, 0.0),
        60.0,
        0.07,
        72.0,
    );
    for (name, camera) in [("from above", above), ("tilted", tilted)] {
        for reverse_z in [false, true] {
            settings.view.camera = manylights::Camera {
                reverse_z,
                ..camera
            };
            assert_pipelines_see_what_naive_sees(
                &format!("wall {name}, reverse Z {reverse_z}"),
                &mut renderer,
                &settings,
                &pipelines,
                Shadows::Rays(1),
                Content {
                    lit: 0.1,
                    shadowed: 0.02,
                },
            );
        }
    }
}
