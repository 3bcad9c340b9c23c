//! The full-frame reference with visibility on the GPU (`visibility::GpuVisibleReference`)
//! against the f64 reference with visibility, at every pixel of small cornell frames (its
//! boxes cast shadows): exact within a ray budget, and beyond it an estimate that is
//! unbiased, whose standard errors are honest, and that converges as rays are added.

use super::robust_visibility;
use glam::{DVec3, Vec3};
use manylights::gpu::SurfaceImage;
use manylights::lights::reference::{SurfacePoint, shade, shade_visible};
use manylights::lights::{Falloff, Light};
use manylights::visibility::{GpuVisibleReferenceImage, SceneBvh, VisibleReferenceRays};
use manylights::{FrameSettings, LoadedScene, PipelineSettings, Renderer};
use manylights_tests::gpu;

/// The exact image's tolerance, relative to the f64 value (absolute below
/// `ABSOLUTE_FLOOR`), derived as for the reference without visibility
/// (`tests/naive/gpu_reference.rs`): the f32 shading of each term within 1e-5 of its f64
/// twin, terms never negative, and the compensated sum's 2u. The cornell room is
/// Blinn-Phong.
const RELATIVE_TOLERANCE: f64 = 1e-5 + 2.0 * (f32::EPSILON as f64 / 2.0);
const ABSOLUTE_FLOOR: f64 = 1e-4;

/// A cornell frame of `lights` lights, its surface capture, the lights as the GPU animated
/// them, and the BVH.
struct Frame {
    renderer: Renderer,
    settings: FrameSettings,
    surface: SurfaceImage,
    lights: Vec<Light>,
    bvh: std::sync::Arc<SceneBvh>,
}

fn frame(size: (u32, u32), lights: u32) -> Frame {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = size;
    settings.lights.time = 0.7;
    settings.lights.count = lights;
    settings.lights.spots.fraction = 0.25;
    settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    renderer.render_frame(&settings).expect("frame");
    let lights = renderer.read_lights().expect("lights");
    let surface = renderer.capture_surface(&settings).expect("surface");
    let bvh = renderer.scene_bvh().expect("bvh");
    Frame {
        renderer,
        settings,
        surface,
        lights,
        bvh,
    }
}

impl Frame {
    fn camera(&self) -> DVec3 {
        self.settings.view.camera.position.as_dvec3()
    }

    fn reference(&mut self, per_pixel: u32, seed: u32) -> GpuVisibleReferenceImage {
        let (surface, camera) = (self.surface.clone(), self.camera());
        let rays = VisibleReferenceRays { per_pixel, seed };
        self.renderer
            .gpu_visible_reference(&surface, camera, Falloff::InverseSquare, rays)
            .expect("GPU reference with visibility")
    }

    /// The f64 reference with visibility (every ray) and without at pixel `i`, or `None`
    /// where a shadow ray passes within f32 rounding of an edge (`robust_visibility`).
    fn f64_reference(&self, i: usize) -> Option<(DVec3, DVec3)> {
        let point = SurfacePoint::from_capture(&self.surface, i);
        let position = |light: &Light| Vec3::from_array(light.position).as_dvec3();
        let robust = self.lights.iter().all(|light| {
            robust_visibility(&self.bvh, point.position, point.normal, position(light)).is_some()
        });
        robust.then(|| {
            let visible =
                |target: glam::DVec3| self.bvh.light_visible(point.position, point.normal, target);
            let camera = self.camera();
            (
                shade_visible(
                    &point,
                    camera,
                    &self.lights,
                    Falloff::InverseSquare,
                    visible,
                ),
                shade(&point, camera, &self.lights, Falloff::InverseSquare),
            )
        })
    }
}

/// Within its ray budget the GPU reference traces every light's ray: it equals the f64
/// reference with visibility at every pixel whose rays are robust, to the derived
/// tolerance, on a frame where shadows take a visible share. A budget of 0 is refused.
#[test]
fn the_gpu_reference_with_visibility_is_exact_within_its_ray_budget() {
    let size = (48, 36);
    let mut frame = frame(size, 48);
    let image = frame.reference(48, 1);
    assert!(image.exact, "48 lights within a budget of 48 rays");
    let pixels = (size.0 * size.1) as usize;
    let (mut fragile, mut shadowed, mut worst) = (0, 0, 0.0f64);
    for i in 0..pixels {
        if frame.surface.position[i][3] != 1.0 {
            assert_eq!(image.radiance[i], DVec3::ZERO, "background pixel {i}");
            continue;
        }
        let Some((want, unshadowed)) = frame.f64_reference(i) else {
            fragile += 1;
            continue;
        };
        shadowed += usize::from(want.max_element() < 0.95 * unshadowed.max_element());
        let got = image.radiance[i];
        let error = (got - want).abs().max_element() / want.max_element().max(ABSOLUTE_FLOOR);
        worst = worst.max(error);
        assert!(
            error <= RELATIVE_TOLERANCE,
            "pixel ({}, {}): GPU {got}, f64 {want}: relative error {error:.2e} over {RELATIVE_TOLERANCE:.2e}",
            i as u32 % size.0,
            i as u32 / size.0
        );
        assert_eq!(image.standard_error[i], DVec3::ZERO);
    }
    println!("exact: largest relative error {worst:.2e}, {fragile} fragile pixels");
    assert!(
        fragile <= pixels / 50,
        "{fragile} pixels have a ray within rounding of an edge"
    );
    assert!(
        shadowed > pixels / 20,
        "only {shadowed} pixels lose 5% to shadows: a test without shadows proves nothing"
    );
    let surface = frame.surface.clone();
    let zero = VisibleReferenceRays {
        per_pixel: 0,
        seed: 1,
    };
    let refused = frame
        .renderer
        .gpu_visible_reference(&surface, frame.camera(), Falloff::InverseSquare, zero)
        .expect_err("a budget of no rays");
    assert!(
        refused.to_string().contains("at least one shadow ray"),
        "{refused}"
    );
}

/// Beyond its budget the reference estimates, and the estimate is what it says it is:
/// - unbiased: the error summed over the frame's pixels, against the f64 reference with
///   every ray, is within 5 of its own standard errors (the pixels' estimates are
///   independent, so the sum is close to normal);
/// - honest: the errors over their standard errors have a mean square near that of
///   Student's t with the samplers' 7 degrees of freedom (7/5); the test allows 1/2 to 3,
///   wide enough for a frame's few hundred pixels, narrow enough to catch errors that
///   are not the estimate's or errors ten times too small;
/// - covering: 90% of the channels lie within 3 standard errors (t with 7 degrees of
///   freedom: 98%), and at most 1% are off where the samplers happen to agree;
/// - converging: 16 times the rays shrink the mean absolute error at least twice (four
///   times, in expectation).
///
/// 1,500 lights through the room's tree also take the pass past llvmpipe's loop limit,
/// which cut it short before dispatches were sized for it.
#[test]
fn beyond_its_budget_the_gpu_reference_estimates_without_bias_and_converges() {
    let size = (32, 24);
    let mut frame = frame(size, 1500);
    let few = frame.reference(64, 7);
    let many = frame.reference(1024, 11);
    assert!(!few.exact && !many.exact);
    let pixels = (size.0 * size.1) as usize;
    let (mut sum_error, mut sum_variance, mut sum_t_squared, mut judged) = (0.0, 0.0, 0.0, 0);
    let (mut few_error, mut many_error, mut shadowed) = (0.0, 0.0, 0);
    let (mut unspread_errors, mut within_3, mut channels) = (0, 0, 0);
    for i in 0..pixels {
        if frame.surface.position[i][3] != 1.0 {
            continue;
        }
        let Some((want, unshadowed)) = frame.f64_reference(i) else {
            continue;
        };
        shadowed += usize::from(want.max_element() < 0.95 * unshadowed.max_element());
        let scale = want.max_element().max(ABSOLUTE_FLOOR);
        for c in 0..3 {
            let error = few.radiance[i][c] - want[c];
            let standard_error = few.standard_error[i][c];
            sum_error += error;
            sum_variance += standard_error * standard_error;
            if standard_error > RELATIVE_TOLERANCE * scale {
                sum_t_squared += (error / standard_error).powi(2);
                judged += 1;
            } else if error.abs() > 4.0 * RELATIVE_TOLERANCE * scale {
                unspread_errors += 1;
            }
            within_3 +=
                usize::from(error.abs() <= 3.0 * standard_error + 4.0 * RELATIVE_TOLERANCE * scale);
            channels += 1;
        }
        few_error += (few.radiance[i] - want).abs().element_sum();
        many_error += (many.radiance[i] - want).abs().element_sum();
    }
    assert!(
        shadowed > pixels / 20,
        "only {shadowed} pixels lose 5% to shadows"
    );
    let bias_sigmas = sum_error / sum_variance.sqrt();
    let mean_t_squared = sum_t_squared / judged as f64;
    println!(
        "estimate: bias {bias_sigmas:.2} sigma, mean t^2 {mean_t_squared:.2} over {judged} channels, {within_3} of {channels} within 3 standard errors, {unspread_errors} wrong without spread, mean error {:.3e} -> {:.3e} with 16x the rays ({} and {} rays)",
        few_error / pixels as f64,
        many_error / pixels as f64,
        few.rays,
        many.rays
    );
    assert!(bias_sigmas.abs() < 5.0, "biased: {bias_sigmas:.2} sigma");
    assert!(
        judged > pixels,
        "only {judged} channels have a spread to judge"
    );
    assert!(
        (0.5..3.0).contains(&mean_t_squared),
        "standard errors not honest: mean (error / standard error)^2 {mean_t_squared:.2}"
    );
    // Student's t with 7 degrees of freedom lies within 3 for 98% of draws.
    assert!(
        within_3 * 10 >= channels * 9,
        "only {within_3} of {channels} channels within 3 standard errors"
    );
    // Eight samplers agree by chance only where few draws decide a pixel.
    assert!(
        unspread_errors * 100 <= channels,
        "{unspread_errors} channels are off with no spread among the samplers"
    );
    assert!(
        many_error * 2.0 < few_error,
        "16x the rays: mean error {few_error:.3e} -> {many_error:.3e}"
    );
}
