//! The reference a configuration is judged against: the naive image with the unbounded
//! falloff (or the GPU full-frame reference beyond `reference_light_limit` lights) and the
//! f64 samples, with visibility where asked, made once per scene, size, light count,
//! camera, BRDF and MSAA and shared by the configurations that differ in pipeline settings.
//! The accuracy (`accuracy.rs`), the motion flicker and the settling lag compare with it;
//! it knows none of them.

use glam::DVec3;
use web_time::Instant;

use manylights::gpu::SurfaceImage;
use manylights::lights::Falloff;
use manylights::lights::reference::{SurfacePoint, VisibleRadiance, shade, shade_visible_estimate};
use manylights::{FrameSettings, NaiveSettings, PipelineSettings, Renderer};

use super::image_metrics::mean;
use super::layers::{BlendedLayers, Layer, composite};
use super::matrix::{BenchConfig, BenchMatrix};
use super::results::ImageReference;
use super::sample_pixels::{BlendedReference, SamplePixels};

/// What a reference depends on: scene, size, light count, whether geometry blocks light,
/// and the BRDF.
/// Scene, size, light count, whether geometry blocks light, the BRDF, the view and the
/// MSAA samples (the reference image is drawn with the configuration's).
pub(super) type ReferenceKey = (
    String,
    (u32, u32),
    u32,
    bool,
    manylights::lights::Shading,
    Option<String>,
    u32,
);

/// What the reference of a (scene, size, lights, camera, BRDF) is: computed once, shared
/// by the configurations that differ only in pipeline settings.
pub(super) struct Reference {
    /// What the reference was made for (`ReferenceKey`).
    pub(super) key: ReferenceKey,
    pub(super) image: Option<Vec<[f32; 4]>>,
    pub(super) image_rgba8: Option<image::RgbaImage>,
    /// Which reference drew `image`, and how long it and the f64 samples took.
    pub(super) image_source: Option<super::results::ImageReference>,
    pub(super) image_seconds: Option<f64>,
    /// Per pixel of `image`, its standard error (the GPU reference with visibility where
    /// estimated).
    pub(super) image_standard_error: Option<Vec<DVec3>>,
    pub(super) samples_seconds: f64,
    /// The surface capture the samples (and the GPU reference) read: where the seam
    /// measure finds each pixel's cluster.
    pub(super) surface: manylights::gpu::SurfaceImage,
    pub(super) samples: Vec<(usize, DVec3)>,
    /// Per sample, the standard error of its estimate with visibility (zero where exact).
    pub(super) standard_errors: Vec<DVec3>,
    /// Per sample, whether visibility takes more than half of its light (all false without
    /// the reference's visibility).
    pub(super) in_shadow: Vec<bool>,
    /// The sampled surface points, the lights of the frame and the covered pixels: what
    /// the shadow rays a frame traces are estimated from.
    pub(super) points: Vec<manylights::lights::reference::SurfacePoint>,
    pub(super) lights: Vec<manylights::lights::Light>,
    pub(super) covered: usize,
    /// Samples under blended surfaces (their layers composited).
    pub(super) layered: usize,
    /// The share of covered pixels under blended surfaces (`Accuracy::blended_coverage`).
    pub(super) blended_coverage: Option<f64>,
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
pub(super) async fn render_reference(
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
