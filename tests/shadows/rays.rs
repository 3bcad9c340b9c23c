//! Shadows with a fixed ray budget (`Shadows::Rays`): exact where the budget covers every
//! light, converging to exact as it grows, reproducible, and exactly dark behind a wall.

use super::{cornell, render, walled};
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
    let (mut renderer, mut settings) = cornell(8);
    let mut pipelines = vec![PipelineSettings::naive(Falloff::WindowedInverseSquare)];
    pipelines.extend(clustered_variants(GBufferLayout::Full));
    pipelines.extend(clustered_variants(GBufferLayout::Compact));
    for pipeline in pipelines {
        settings.pipeline = pipeline;
        settings.shadows = Shadows::Exact;
        let exact = render(&mut renderer, &settings);
        assert_lit(&format!("{pipeline:?} with exact shadows"), &exact, 0.5);
        settings.shadows = Shadows::Off;
        assert_ne!(
            exact,
            render(&mut renderer, &settings),
            "the boxes cast shadows"
        );
        settings.shadows = Shadows::Rays(8);
        let rays = render(&mut renderer, &settings);
        assert_hdr_close(
            &format!("{pipeline:?} with 8 rays, 8 lights"),
            &exact,
            &rays,
            1e-4,
        );
    }
}

/// Where shadows are partial, the error of the ray budget's image against exact shadows,
/// a pixel at a time, as a share of the pixel's unshadowed luminance: within [0, 1], since
/// both images lie between black and the unshadowed pixel.
fn partial_shadow_errors(
    exact: &[[f32; 4]],
    unshadowed: &[[f32; 4]],
    rays: &[[f32; 4]],
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
            (u > 0.0 && e > 1e-3 * u && e < (1.0 - 1e-3) * u).then(|| ((r - e) / u).abs())
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
/// measured on lavapipe, 11.6, 18.1 and 26.8 standard errors, so it fails with probability
/// below 1e-12 (7 sigma beyond the threshold).
#[test]
fn the_ray_budget_converges_to_exact_shadows() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline =
        PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Tiles);
    settings.shadows = Shadows::Exact;
    let exact = render(&mut renderer, &settings);
    settings.shadows = Shadows::Off;
    let unshadowed = render(&mut renderer, &settings);
    let mut means = Vec::new();
    for rays in [1, 2, 4, 8] {
        settings.shadows = Shadows::Rays(rays);
        let image = render(&mut renderer, &settings);
        assert_eq!(
            image,
            render(&mut renderer, &settings),
            "{rays} rays: same seed, same image"
        );
        let errors = partial_shadow_errors(&exact, &unshadowed, &image);
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

/// A light behind a wall adds exactly nothing to the far side with a ray budget, alone or
/// among lights on the near side, in every pipeline: every ray to it is blocked, and the
/// near lights' rays are all visible, so each pixel's ratio is exact.
#[test]
fn a_ray_budget_keeps_the_far_side_of_a_wall_black() {
    let (mut renderer, mut settings) = walled(&[(Vec3::new(1.0, 0.5, 0.0), 6.0, 4.0)]);
    for pipeline in super::every_pipeline() {
        settings.pipeline = pipeline;
        settings.shadows = Shadows::Rays(1);
        let image = render(&mut renderer, &settings);
        assert!(
            image.iter().all(|p| p[..3] == [0.0; 3]),
            "{pipeline:?}: light crossed the wall"
        );
    }
}
