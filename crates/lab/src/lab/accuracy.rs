//! Accuracy: the f64 reference at sampled pixels, the reference image's exposure, and the
//! image errors (PSNR, absolute, FLIP) of a frame against it.

use anyhow::bail;
use glam::DVec3;
use web_time::Instant;

use manylights::cluster::{FarField, FarFieldMethod};
use manylights::gpu::SurfaceImage;
use manylights::lights::Falloff;
use manylights::lights::reference::{SurfacePoint, VisibleRadiance, shade, shade_visible_estimate};
use manylights::{FrameSettings, NaiveSettings, PipelineSettings, Renderer};

use super::gpu_reference_checks;
use super::image_metrics;
use super::layers::{BlendedLayers, Layer, composite};
use super::matrix::{BenchConfig, BenchMatrix};
use super::results::{Accuracy, ImageReference};
use super::run::{Reference, ReferenceKey};
use super::sample_pixels::{BlendedReference, SamplePixels};
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
/// absolute errors in HDR, FLIP at one exposure chosen from the reference, the error map
/// and (clustered pipelines) the seam measure.
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
    if let Some(planned) = renderer.plan(settings)?.clusters {
        let grid = planned.frame.grid;
        let clusters = image_metrics::PixelClusters::from_surface(
            &reference.surface,
            &grid,
            &settings.view.camera,
        );
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

/// Pixel `i` of an HDR image in f64.
pub(super) fn pixel(image: &[[f32; 4]], i: usize) -> DVec3 {
    DVec3::new(image[i][0] as f64, image[i][1] as f64, image[i][2] as f64)
}

/// The relative error of `got` against `want`, by their brightest channel.
pub(super) fn relative(got: DVec3, want: DVec3) -> f64 {
    relative_difference(got, want, want)
}

/// The difference of `a` and `b` relative to `want`, by their brightest channel.
fn relative_difference(a: DVec3, b: DVec3, want: DVec3) -> f64 {
    (a - b).abs().max_element() / want.max_element().max(1e-4)
}

/// `image`'s radiance at the reference's samples.
pub(super) fn at_samples(image: &[[f32; 4]], reference: &Reference) -> Vec<DVec3> {
    reference
        .samples
        .iter()
        .map(|(i, _)| pixel(image, *i))
        .collect()
}

/// The mean over the reference's samples of the difference between two frames' radiance
/// there (`at_samples`), relative to the reference's.
pub(super) fn mean_relative_difference(a: &[DVec3], b: &[DVec3], reference: &Reference) -> f64 {
    let differences: Vec<f64> = a
        .iter()
        .zip(b)
        .zip(&reference.samples)
        .map(|((a, b), (_, want))| relative_difference(*a, *b, *want))
        .collect();
    mean(&differences)
}

/// The share of its unshadowed radiance (brightest channel) a sample must lose to
/// visibility to count as in shadow (`Accuracy::f64_mean_relative_shadowed`): more than
/// half. (With a far field nearly every sample of Sponza loses a few percent to the
/// building's walls: a 1% threshold put every sample in shadow, and told nothing.)
const SHADOWED_LOSS: f64 = 0.5;

/// The reference image's frame: naive with the unbounded falloff, the configuration's
/// view, size, lights and MSAA, and exact visibility where `reference_shadows` traces
/// rays, whatever method the configuration measures (a ray budget's noise, or a filter
/// naive does not run, has no place in it).
fn reference_frame(
    settings: &FrameSettings,
    reference_shadows: manylights::Shadows,
) -> FrameSettings {
    let mut reference = settings.clone();
    reference.pipeline = PipelineSettings::Naive(NaiveSettings {
        falloff: Falloff::InverseSquare,
    });
    reference.shadows.mode = if reference_shadows.traced() {
        manylights::Shadows::Exact
    } else {
        manylights::Shadows::Off
    };
    // The reference is one exact sample at each pixel's centre: no jitter, no bloom.
    reference.post.anti_aliasing = manylights::AntiAliasing::Off;
    reference.post.bloom = 0.0;
    reference
}

/// The reference for `key`: the naive image with the unbounded falloff (up to
/// `reference_light_limit` lights) and the f64 samples, with visibility where
/// `reference_shadows` traces rays (every shadow ray, or an estimate beyond
/// `reference_shadow_rays`).
async fn render_reference(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    settings: &FrameSettings,
    reference_shadows: manylights::Shadows,
    key: ReferenceKey,
) -> anyhow::Result<Reference> {
    let reference_settings = reference_frame(settings, reference_shadows);
    let surface = renderer.capture_surface_async(&reference_settings).await?;
    let image_started = Instant::now();
    let full_frame = full_frame_reference(
        renderer,
        matrix,
        config,
        settings,
        reference_shadows,
        &surface,
    )
    .await?;
    let image_seconds = full_frame
        .as_ref()
        .map(|_| image_started.elapsed().as_secs_f64());
    let full_frame = FullFrameParts::of(full_frame);
    let samples_started = Instant::now();
    let lights = renderer.read_lights_async().await?;
    let camera = reference_settings.view.camera.position.as_dvec3();
    // With shadows, the f64 samples trace a shadow ray for every light that adds to them,
    // or estimate beyond `reference_shadow_rays` (the GPU reference image above is naive
    // with exact shadows).
    let bvh = (reference_shadows.traced())
        .then(|| renderer.scene_bvh())
        .transpose()?;
    let blended = blended_reference(renderer, &config.scene, reference_settings.shading)?;
    let pixels = SamplePixels {
        surface: &surface,
        camera,
        blended: &blended,
        interior_only: samples_interior_pixels_only(matrix),
    };
    let covered = pixels.covered_pixels();
    let step = (covered.len() / matrix.reference_samples.max(1) as usize).max(1);
    let blended_coverage = pixels.blended_coverage(&covered, step);
    let sample_shading = SampleShading {
        camera,
        lights: &lights,
        bvh: bvh.as_deref(),
        shadow_rays: matrix.reference_shadow_rays as usize,
    };
    let chosen = pixels.chosen(&covered, step, matrix.reference_samples as usize);
    let ShadedSamples {
        samples,
        standard_errors,
        in_shadow,
        points,
        layered,
    } = shade_samples(&sample_shading, &surface, blended.layers(), chosen);
    Ok(Reference {
        key,
        image: full_frame.image,
        image_rgba8: full_frame.image_rgba8,
        image_source: full_frame.image_source,
        image_seconds,
        image_standard_error: full_frame.image_standard_error,
        samples_seconds: samples_started.elapsed().as_secs_f64(),
        surface,
        samples,
        standard_errors,
        in_shadow,
        points,
        covered: covered.len(),
        layered,
        blended_coverage,
        lights,
    })
}

/// How the f64 samples treat blended surfaces: composited over each sample's opaque
/// surface, farthest first, or (where the reference cannot composite them, said in the log)
/// left out with the pixels under them (`sample_pixels`).
fn blended_reference(
    renderer: &mut Renderer,
    scene_name: &str,
    shading: manylights::lights::Shading,
) -> anyhow::Result<BlendedReference> {
    let scene = &renderer.scene().scene;
    let blended = match scene.features().alpha_blend {
        false => BlendedReference::None,
        true => match BlendedLayers::from_scene(scene, shading) {
            Ok(layers) => BlendedReference::Layers(layers),
            Err(reason) => BlendedReference::LeftOut(reason, renderer.scene_bvh()?),
        },
    };
    if let BlendedReference::LeftOut(reason, _) = &blended {
        log::warn!(
            "scene '{scene_name}': {reason}; the f64 samples leave out the pixels under \
             blended surfaces"
        );
    }
    Ok(blended)
}

/// With MSAA in the matrix, every configuration's samples are interior pixels only (a dark
/// roof pixel beside the lit floor was 450% off its point sample).
fn samples_interior_pixels_only(matrix: &BenchMatrix) -> bool {
    matrix
        .settings
        .values("view.msaa")
        .iter()
        .any(|samples| samples.as_u64().is_some_and(|samples| samples > 1))
}

/// The f64 samples at the `chosen` pixels, each composited under the blended `layers` in
/// front of it.
struct ShadedSamples {
    /// Each pixel's index and radiance.
    samples: Vec<(usize, DVec3)>,
    standard_errors: Vec<DVec3>,
    in_shadow: Vec<bool>,
    points: Vec<SurfacePoint>,
    /// Samples with a blended layer in front.
    layered: usize,
}

fn shade_samples(
    shading: &SampleShading,
    surface: &SurfaceImage,
    layers: Option<&BlendedLayers>,
    chosen: Vec<usize>,
) -> ShadedSamples {
    let mut shaded_samples = ShadedSamples {
        samples: Vec::with_capacity(chosen.len()),
        standard_errors: Vec::with_capacity(chosen.len()),
        in_shadow: Vec::with_capacity(chosen.len()),
        points: Vec::with_capacity(chosen.len()),
        layered: 0,
    };
    for i in chosen {
        let point = SurfacePoint::from_capture(surface, i);
        let over = layers
            .map(|layers| layers.between(shading.camera, point.position))
            .unwrap_or_default();
        shaded_samples.layered += usize::from(!over.is_empty());
        let shaded = shading.shade(&point, &over, i as u64);
        shaded_samples.points.push(point);
        shaded_samples.in_shadow.push(shaded.in_shadow);
        shaded_samples.samples.push((i, shaded.radiance));
        shaded_samples.standard_errors.push(shaded.standard_error);
    }
    shaded_samples
}

/// A full-frame reference's parts as a [`Reference`] keeps them (each `None` without one).
struct FullFrameParts {
    image: Option<Vec<[f32; 4]>>,
    image_rgba8: Option<image::RgbaImage>,
    image_source: Option<ImageReference>,
    image_standard_error: Option<Vec<DVec3>>,
}

impl FullFrameParts {
    fn of(full_frame: Option<FullFrameReference>) -> Self {
        match full_frame {
            Some(full) => Self {
                image: Some(full.hdr),
                image_rgba8: full.rgba8,
                image_source: Some(full.source),
                image_standard_error: full.standard_error,
            },
            None => Self {
                image: None,
                image_rgba8: None,
                image_source: None,
                image_standard_error: None,
            },
        }
    }
}

/// A full-frame reference image: its HDR radiance, naive's tonemapped output (the GPU
/// reference has none), which reference drew it, and where it is estimated each pixel's
/// standard error.
pub(super) struct FullFrameReference {
    pub(super) hdr: Vec<[f32; 4]>,
    pub(super) rgba8: Option<image::RgbaImage>,
    pub(super) source: ImageReference,
    pub(super) standard_error: Option<Vec<DVec3>>,
}

/// The full-frame reference of `frame`, whose surfaces `surface` captured: naive with the
/// unbounded falloff (and exact shadows where `reference_shadows` traces rays) up to
/// `reference_light_limit` lights; beyond it the GPU reference, with visibility where
/// `reference_shadows` traces rays (estimated beyond `reference_image_rays` lights). It
/// has no blended layers, so frames that need them have none.
pub(super) async fn full_frame_reference(
    renderer: &mut Renderer,
    matrix: &BenchMatrix,
    config: &BenchConfig,
    frame: &FrameSettings,
    reference_shadows: manylights::Shadows,
    surface: &manylights::gpu::SurfaceImage,
) -> anyhow::Result<Option<FullFrameReference>> {
    let reference_settings = reference_frame(frame, reference_shadows);
    if config.lights <= matrix.reference_light_limit {
        renderer.render_frame(&reference_settings)?;
        return Ok(Some(FullFrameReference {
            hdr: renderer.read_hdr_async().await?,
            rgba8: Some(renderer.read_output_async().await?),
            source: ImageReference::Naive,
            standard_error: None,
        }));
    }
    if renderer.scene().scene.features().alpha_blend {
        return Ok(None);
    }
    // The GPU reference reads the lights as the GPU has them: animated to `frame`'s time.
    renderer.render_frame_timed_async(frame).await?;
    let camera = reference_settings.view.camera.position.as_dvec3();
    if reference_shadows.traced() {
        let rays = manylights::visibility::VisibleReferenceRays {
            per_pixel: matrix.reference_image_rays,
            seed: matrix.seed,
        };
        let image = renderer
            .gpu_visible_reference_async(surface, camera, Falloff::InverseSquare, rays)
            .await?;
        return Ok(Some(FullFrameReference {
            hdr: image.to_rgba_f32(),
            rgba8: None,
            source: ImageReference::GpuFullFrameVisible,
            standard_error: (!image.exact).then_some(image.standard_error),
        }));
    }
    let image = renderer
        .gpu_reference_async(surface, camera, Falloff::InverseSquare)
        .await?;
    Ok(Some(FullFrameReference {
        hdr: image.to_rgba_f32(),
        rgba8: None,
        source: ImageReference::GpuFullFrame,
        standard_error: None,
    }))
}

/// How the f64 reference shades a sample: the eye, the lights, and with visibility the
/// scene's BVH and the shadow rays a sample may trace before it estimates.
struct SampleShading<'a> {
    camera: DVec3,
    lights: &'a [manylights::lights::Light],
    bvh: Option<&'a manylights::visibility::SceneBvh>,
    shadow_rays: usize,
}

/// A sample's f64 radiance, its standard error, and whether visibility takes more than
/// half of its surface's light.
struct ShadedSample {
    radiance: DVec3,
    standard_error: DVec3,
    in_shadow: bool,
}

impl SampleShading<'_> {
    /// One surface's radiance towards the eye, with visibility where there is a BVH
    /// (`seed`, the pixel's index, seeds its draws: the same reference every run).
    fn shade_point(&self, point: &SurfacePoint, seed: u64) -> VisibleRadiance {
        match self.bvh {
            Some(bvh) => shade_visible_estimate(
                point,
                self.camera,
                self.lights,
                Falloff::InverseSquare,
                |target: DVec3| bvh.light_visible(point.position, point.normal, target),
                self.shadow_rays,
                seed,
            ),
            None => {
                let radiance = shade(point, self.camera, self.lights, Falloff::InverseSquare);
                VisibleRadiance {
                    radiance,
                    unshadowed: radiance,
                    standard_error: DVec3::ZERO,
                    rays: 0,
                }
            }
        }
    }

    /// The sample's opaque `point` with the blended layers `over` it composited farthest
    /// first; the standard errors combined by the weight each input ends with.
    fn shade(&self, point: &SurfacePoint, over: &[Layer], seed: u64) -> ShadedSample {
        let shaded = self.shade_point(point, seed);
        let mut errors = vec![shaded.standard_error];
        let (radiance, weights) = composite(shaded.radiance, over, |layer| {
            let layer = self.shade_point(layer, seed);
            errors.push(layer.standard_error);
            layer.radiance
        });
        let standard_error = errors
            .iter()
            .zip(&weights)
            .map(|(error, weight)| (*error * *weight) * (*error * *weight))
            .sum::<DVec3>()
            .map(f64::sqrt);
        ShadedSample {
            radiance,
            standard_error,
            in_shadow: self.bvh.is_some()
                && shaded.radiance.max_element()
                    < (1.0 - SHADOWED_LOSS) * shaded.unshadowed.max_element(),
        }
    }
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

pub(super) fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
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
