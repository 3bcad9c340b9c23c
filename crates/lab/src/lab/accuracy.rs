//! Accuracy: the f64 reference at sampled pixels, the reference image's exposure, and the
//! image errors (PSNR, absolute, FLIP) of a frame against it.

use anyhow::bail;
use glam::DVec3;

use manylights::cluster::{FarField, FarFieldMethod};
use manylights::{FrameSettings, Renderer};

use super::blotch;
use super::gpu_reference_checks;
use super::image_metrics;
use super::image_metrics::mean;
use super::matrix::{BenchConfig, BenchMatrix};
use super::reference::{
    Reference, at_samples, mean_relative_difference, pixel, relative, render_reference,
};
use super::results::Accuracy;
use super::settling;

/// Renders (or reuses) the reference for this frame and compares.
pub(super) async fn accuracy(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    settings: &FrameSettings,
    image: &[[f32; 4]],
    image_rgba8: &image::RgbaImage,
    reference: &mut Option<Reference>,
) -> anyhow::Result<Accuracy> {
    // The reference's visibility: the configuration's own, or the matrix's choice.
    let reference_shadows = matrix.reference_shadows.unwrap_or(settings.shadows.mode);
    // The BRDF too: a Blinn-Phong configuration after a PBR one must not reuse its
    // reference (found by the far field's error with each BRDF: pi - 1 off).
    let key = (
        config.scene.clone(),
        config.size,
        config.lights,
        reference_shadows.traced(),
        settings.shading,
        config.view.clone(),
        settings.view.msaa,
    );
    if reference.as_ref().is_none_or(|r| r.key != key) {
        *reference = Some(
            render_reference(renderer, matrix, config, settings, reference_shadows, key).await?,
        );
    }
    let Some(reference) = reference.as_ref() else {
        bail!("reference missing");
    };
    let mut accuracy = Accuracy {
        image_reference: reference.image_source,
        reference_image_seconds: reference.image_seconds,
        reference_samples_seconds: Some(reference.samples_seconds),
        gpu_reference_vs_f64: gpu_reference_checks::relative_difference(reference),
        reference_image_standard_error: gpu_reference_checks::mean_relative_standard_error(
            reference,
        ),
        gpu_reference_vs_f64_sigmas: gpu_reference_checks::standard_errors_apart(reference),
        ..Accuracy::default()
    };
    if let Some(ref_image) = &reference.image {
        whole_frame_errors(
            renderer,
            config,
            settings,
            (ref_image, image),
            reference,
            &mut accuracy,
        )?;
        if let Some(ref_rgba8) = &reference.image_rgba8 {
            accuracy.flip_mean = optional_flip_mean(ref_rgba8, image_rgba8);
        }
    }
    let errors = sample_errors(reference, image, &mut accuracy);
    accuracy.shadow_rays_per_frame = shadow_rays_per_frame(reference, settings);
    measure_shadows(renderer, settings, image, reference, &errors, &mut accuracy).await?;
    if matrix.motion_frames > 0 {
        accuracy.motion_flicker =
            super::motion::motion_flicker(renderer, matrix, config, settings, reference_shadows)
                .await?;
    }
    // Stochastic far fields: the same frame under other seeds, for noise and bias.
    if let Some(far) = settings
        .pipeline
        .far_field()
        .filter(|far| far.method == FarFieldMethod::Stochastic && matrix.noise_seeds > 1)
    {
        let (noise, bias) = noise_and_bias(renderer, matrix, settings, far, reference).await?;
        accuracy.f64_noise_relative = Some(noise);
        accuracy.f64_bias_relative = Some(bias);
    }
    Ok(accuracy)
}

/// Each f64 sample's relative error in `image`, with what they say in `accuracy`: their
/// count, mean, worst and the dark and bright thirds' means, and the reference's own 95%
/// half-width where it is estimated.
fn sample_errors(reference: &Reference, image: &[[f32; 4]], accuracy: &mut Accuracy) -> Vec<f64> {
    let errors: Vec<f64> = reference
        .samples
        .iter()
        .map(|(i, want)| relative(pixel(image, *i), *want))
        .collect();
    accuracy.samples = errors.len() as u32;
    accuracy.layered_samples = reference.layered as u32;
    accuracy.blended_coverage = reference.blended_coverage;
    if reference.standard_errors.iter().any(|e| *e != DVec3::ZERO) {
        let half_widths: Vec<f64> = reference
            .samples
            .iter()
            .zip(&reference.standard_errors)
            .map(|((_, want), error)| 1.96 * error.max_element() / want.max_element().max(1e-4))
            .collect();
        accuracy.f64_reference_half_width = Some(mean(&half_widths));
    }
    accuracy.f64_max_relative = errors.iter().copied().fold(0.0, f64::max);
    accuracy.f64_mean_relative = mean(&errors);
    (
        accuracy.f64_mean_relative_dark,
        accuracy.f64_mean_relative_bright,
    ) = mean_of_dark_and_bright_thirds(&errors, &reference.samples);
    errors
}

/// The errors only a whole frame shows, against the full-frame reference: PSNR and
/// absolute errors in HDR, FLIP at one exposure chosen from the reference, the error map,
/// the blotch measure and (clustered pipelines) the seam measure.
fn whole_frame_errors(
    renderer: &Renderer,
    config: &BenchConfig,
    settings: &FrameSettings,
    (ref_image, image): (&[[f32; 4]], &[[f32; 4]]),
    reference: &Reference,
    accuracy: &mut Accuracy,
) -> anyhow::Result<()> {
    let error = image_error(ref_image, image);
    accuracy.max_abs = Some(error.max_abs);
    accuracy.mean_abs = Some(error.mean_abs);
    accuracy.psnr_db = Some(error.psnr_db);
    if let Some(exposure) = exposure_from_reference(ref_image) {
        let reference_ldr = tonemap_aces(ref_image, exposure, config.size);
        let test_ldr = tonemap_aces(image, exposure, config.size);
        accuracy.reference_exposure = Some(exposure);
        accuracy.flip_at_reference_exposure = optional_flip_mean(&reference_ldr, &test_ldr);
    }
    let errors = image_metrics::relative_luminance_errors(ref_image, image);
    accuracy.error_map = Some(image_metrics::error_map(&errors, config.size));
    let geometry =
        image_metrics::SurfaceGeometry::from_surface(&reference.surface, &settings.view.camera);
    accuracy.blotch =
        blotch::blotch_measure(ref_image, image, &geometry).map(|measure| measure.blotch);
    if let Some(planned) = renderer.plan(settings)?.clusters {
        let clusters = image_metrics::PixelClusters::new(geometry, &planned.frame.grid);
        accuracy.seam_ratio =
            image_metrics::seam_measure(&errors, &clusters).map(|seams| seams.ratio);
    }
    Ok(())
}

/// The mean of `errors` over the darkest and the brightest third of the samples (by the
/// reference's brightest channel); zeros with fewer than three samples.
fn mean_of_dark_and_bright_thirds(errors: &[f64], samples: &[(usize, DVec3)]) -> (f64, f64) {
    let mut by_brightness: Vec<usize> = (0..errors.len()).collect();
    by_brightness.sort_by(|&a, &b| {
        samples[a]
            .1
            .max_element()
            .total_cmp(&samples[b].1.max_element())
    });
    let third = errors.len() / 3;
    if third == 0 {
        return (0.0, 0.0);
    }
    let pick = |indices: &[usize]| mean(&indices.iter().map(|&k| errors[k]).collect::<Vec<_>>());
    (
        pick(&by_brightness[..third]),
        pick(&by_brightness[errors.len() - third..]),
    )
}

/// What shadows do to the frame: its error in shadow and in light (with a reference with
/// visibility), its flicker and its lag.
async fn measure_shadows(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    image: &[[f32; 4]],
    reference: &Reference,
    errors: &[f64],
    accuracy: &mut Accuracy,
) -> anyhow::Result<()> {
    (
        accuracy.f64_mean_relative_shadowed,
        accuracy.f64_mean_relative_lit,
    ) = if reference.key.3 {
        mean_in_shadow_and_lit(errors, &reference.in_shadow)
    } else {
        (None, None)
    };
    accuracy.flicker = Some(flicker(renderer, settings, image, reference).await?);
    accuracy.lag_frames = Some(settling::lag(renderer, settings, reference).await?);
    accuracy.disocclusion_lag_frames = Some(settling::disocclusion_lag(renderer, settings).await?);
    Ok(())
}

/// The mean of `errors` where the reference is in shadow and where it is lit (`None` for
/// a side without samples).
fn mean_in_shadow_and_lit(errors: &[f64], in_shadow: &[bool]) -> (Option<f64>, Option<f64>) {
    let side = |shadowed: bool| {
        let values: Vec<f64> = errors
            .iter()
            .zip(in_shadow)
            .filter(|(_, s)| **s == shadowed)
            .map(|(e, _)| *e)
            .collect();
        (!values.is_empty()).then(|| mean(&values))
    };
    (side(true), side(false))
}

/// Flicker: the frame rendered again with the next shadow seed (`FrameSettings::
/// shadow_seed`), the camera and lights as they were, and the mean over the reference's
/// samples of the difference, relative as the errors are (the brightest channel over the
/// reference's). 0 for a method without randomness from frame to frame.
async fn flicker(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    image: &[[f32; 4]],
    reference: &Reference,
) -> anyhow::Result<f64> {
    let mut next = settings.clone();
    next.shadows.seed = settings.shadows.seed.wrapping_add(1);
    next.pipeline.set_list_statistics(false, false);
    renderer.render_frame_timed_async(&next).await?;
    let next_image = renderer.read_hdr_async().await?;
    Ok(mean_relative_difference(
        &at_samples(&next_image, reference),
        &at_samples(image, reference),
        reference,
    ))
}

/// A stochastic far field's noise (the mean relative standard deviation over
/// `noise_seeds` seeds at the reference's samples) and bias (the mean relative error of the
/// seeds' mean).
async fn noise_and_bias(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    settings: &FrameSettings,
    far: FarField,
    reference: &Reference,
) -> anyhow::Result<(f64, f64)> {
    let mut seeded = settings.clone();
    seeded.pipeline.set_list_statistics(false, false);
    let mut per_seed: Vec<Vec<DVec3>> = Vec::new();
    for seed in 0..matrix.noise_seeds {
        if let Some(clustering) = seeded.pipeline.clustering_mut() {
            clustering.far_field = Some(FarField { seed, ..far });
        }
        renderer.render_frame_timed_async(&seeded).await?;
        per_seed.push(at_samples(&renderer.read_hdr_async().await?, reference));
    }
    let seeds = per_seed.len() as f64;
    let (mut noise, mut bias) = (Vec::new(), Vec::new());
    for (k, (_, want)) in reference.samples.iter().enumerate() {
        let values: Vec<DVec3> = per_seed.iter().map(|s| s[k]).collect();
        let mean_value = values.iter().copied().sum::<DVec3>() / seeds;
        let variance = values
            .iter()
            .map(|v| (*v - mean_value).max_element().powi(2))
            .sum::<f64>()
            / (seeds - 1.0);
        noise.push(variance.sqrt() / want.max_element().max(1e-4));
        bias.push(relative(mean_value, *want));
    }
    Ok((mean(&noise), mean(&bias)))
}

/// Most lights the shadow-ray estimate loops over at each sample.
const SHADOW_RAY_ESTIMATE_LIGHT_LIMIT: usize = 200_000;

/// The shadow rays a frame with shadows traces to lights within their radius: at each
/// sampled point, the lights the pipeline's falloff lets add to it (with a ray budget, at
/// most the budget), averaged and scaled to the covered pixels.
fn shadow_rays_per_frame(reference: &Reference, settings: &FrameSettings) -> Option<f64> {
    if !settings.shadows.mode.traced()
        || reference.lights.len() > SHADOW_RAY_ESTIMATE_LIGHT_LIMIT
        || reference.points.is_empty()
    {
        return None;
    }
    let camera = settings.view.camera.position.as_dvec3();
    let falloff = settings.pipeline.falloff();
    let ray_budget = settings
        .shadows
        .mode
        .ray_budget()
        .map_or(usize::MAX, |rays| rays as usize);
    let rays: usize = reference
        .points
        .iter()
        .map(|point| {
            let view_dir = (camera - point.position).normalize_or_zero();
            reference
                .lights
                .iter()
                .filter(|light| {
                    manylights::lights::reference::shade_light(point, view_dir, light, falloff)
                        != DVec3::ZERO
                })
                .count()
                .min(ray_budget)
        })
        .sum();
    Some(rays as f64 / reference.points.len() as f64 * reference.covered as f64)
}

/// The exposure that maps the reference's median lit luminance to mid-grey (0.18), as the
/// renderer's automatic exposure does; None for a black reference.
pub fn exposure_from_reference(reference: &[[f32; 4]]) -> Option<f64> {
    let mut luminance: Vec<f64> = reference
        .iter()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .filter(|l| *l > 0.0)
        .collect();
    if luminance.is_empty() {
        return None;
    }
    luminance.sort_by(f64::total_cmp);
    Some(0.18 / luminance[luminance.len() / 2])
}

/// An HDR image tonemapped as the renderer does (exposure, ACES fit, sRGB encoding).
pub fn tonemap_aces(image: &[[f32; 4]], exposure: f64, size: (u32, u32)) -> image::RgbaImage {
    let aces = |x: f64| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let mut out = image::RgbaImage::new(size.0, size.1);
    for (pixel, hdr) in out.pixels_mut().zip(image) {
        for (channel, value) in pixel.0.iter_mut().zip(&hdr[..3]) {
            let tonemapped = aces((*value as f64 * exposure).max(0.0));
            *channel = manylights::scene::color::linear_to_srgb8(tonemapped as f32);
        }
        pixel.0[3] = 255;
    }
    out
}

/// Error of a linear HDR image against a reference (RGB channels, alpha ignored).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    pub max_abs: f64,
    pub mean_abs: f64,
    /// 10 log10(peak^2 / MSE), peak = the reference's largest channel value.
    pub psnr_db: f64,
}

impl std::fmt::Display for ImageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "max abs {:.3e}, mean abs {:.3e}, PSNR {:.1} dB",
            self.max_abs, self.mean_abs, self.psnr_db
        )
    }
}

pub fn image_error(reference: &[[f32; 4]], test: &[[f32; 4]]) -> ImageError {
    let (mut max_abs, mut sum_abs, mut sum_sq, mut peak) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (r, t) in reference.iter().zip(test) {
        for c in 0..3 {
            let d = (r[c] as f64 - t[c] as f64).abs();
            max_abs = max_abs.max(d);
            sum_abs += d;
            sum_sq += d * d;
            peak = peak.max(r[c] as f64);
        }
    }
    let n = (reference.len() * 3).max(1) as f64;
    let mse = sum_sq / n;
    ImageError {
        max_abs,
        mean_abs: sum_abs / n,
        psnr_db: if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (peak * peak / mse).log10()
        },
    }
}

/// FLIP's default viewing condition: a 0.7 m wide 4K monitor seen from 0.7 m.
pub const FLIP_PIXELS_PER_DEGREE: f32 = 67.0;

/// Mean FLIP where the build has it: nv-flip is C++ and the browser build has no C++
/// toolchain for wasm32, so the page's results leave FLIP out (`None`, "-" in reports).
#[cfg(not(target_arch = "wasm32"))]
fn optional_flip_mean(reference: &image::RgbaImage, test: &image::RgbaImage) -> Option<f64> {
    Some(f64::from(flip_mean(reference, test)))
}

#[cfg(target_arch = "wasm32")]
fn optional_flip_mean(_reference: &image::RgbaImage, _test: &image::RgbaImage) -> Option<f64> {
    None
}

/// The per-pixel FLIP (nv-flip) error between two tonemapped images of the same size.
#[cfg(not(target_arch = "wasm32"))]
pub(super) fn flip_error(
    reference: &image::RgbaImage,
    test: &image::RgbaImage,
) -> nv_flip::FlipImageFloat {
    let rgb = |image: &image::RgbaImage| {
        let data: Vec<u8> = image
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
            .collect();
        nv_flip::FlipImageRgb8::with_data(image.width(), image.height(), &data)
    };
    nv_flip::flip(rgb(reference), rgb(test), FLIP_PIXELS_PER_DEGREE)
}

/// Mean FLIP between two tonemapped images.
#[cfg(not(target_arch = "wasm32"))]
pub fn flip_mean(reference: &image::RgbaImage, test: &image::RgbaImage) -> f32 {
    nv_flip::FlipPool::from_image(&flip_error(reference, test)).mean()
}

/// Mean FLIP and the error map (magma colours), for people to look at.
#[cfg(not(target_arch = "wasm32"))]
pub fn flip_mean_and_map(
    reference: &image::RgbaImage,
    test: &image::RgbaImage,
) -> (f32, image::RgbImage) {
    let error = flip_error(reference, test);
    let mean = nv_flip::FlipPool::from_image(&error).mean();
    let map = error.apply_color_lut(&nv_flip::magma_lut());
    let map =
        image::RgbImage::from_raw(map.width(), map.height(), map.to_vec()).unwrap_or_default();
    (mean, map)
}
