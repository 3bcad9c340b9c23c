//! The full-frame reference on the GPU (`lights::GpuReference`) against the f64 reference,
//! at every pixel of small frames: both BRDFs, point and spot lights, both falloffs, and a
//! light set built so that a plain f32 sum loses a thousandth of every pixel.

use glam::{DVec3, Vec3};
use manylights::gpu::SurfaceImage;
use manylights::lights::reference::{SurfacePoint, shade};
use manylights::lights::{Falloff, Light, LightSet};
use manylights::{FrameSettings, LoadedScene, PipelineSettings, Renderer};
use manylights_tests::gpu;

const SIZE: (u32, u32) = (48, 36);

/// The tolerance, relative to the f64 value (absolute below `ABSOLUTE_FLOOR`), derived:
/// each term is the f32 shading every pipeline runs (shading.wgsl), a few dozen roundings
/// of u = 2^-24 each and the f32 table interpolation, which the naive pipeline's tests
/// measure within 1e-5 of the same twin (`tests/naive.rs`, `F32_SHADING_TOLERANCE`); terms
/// are never negative, so their errors add to at most that share of the sum; the
/// compensated sum adds at most 2u (Neumaier's bound, for any count). A plain f32 sum of n
/// terms may be off by (n - 1) u: 6e-3 at 100,000 lights.
const RELATIVE_TOLERANCE: f64 = 1e-5 + 2.0 * U;
/// PBR adds the conditioning of GGX's peak in f32: D divides by
/// d = |n x h|^2 + (n.h)^2 alpha^2, whose first term carries an absolute error of about
/// 4u |n x h| (h and the cross product are rounded to u), so d's relative error is at most
/// 2u / alpha (where |n x h| = alpha) and D's, 1/d^2, twice that; the half vector's own
/// rounding doubles it again: 8u / alpha, at the scene's smoothest alpha.
fn pbr_tolerance(smoothest_roughness: f64) -> f64 {
    RELATIVE_TOLERANCE + 8.0 * U / (smoothest_roughness * smoothest_roughness)
}
/// f32's unit roundoff.
const U: f64 = f32::EPSILON as f64 / 2.0;
const ABSOLUTE_FLOOR: f64 = 1e-4;

/// The GPU reference and the f64 one at every covered pixel: the largest relative error.
/// Fails on the first pixel beyond `RELATIVE_TOLERANCE`, or on a frame without light.
fn check_every_pixel(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    falloff: Falloff,
    tolerance: f64,
    label: &str,
) -> f64 {
    renderer.render_frame(settings).expect("frame");
    let lights: Vec<Light> = renderer.read_lights().expect("lights");
    let surface: SurfaceImage = renderer.capture_surface(settings).expect("surface");
    let camera = settings.view.camera.position.as_dvec3();
    let image = renderer
        .gpu_reference(&surface, camera, falloff)
        .expect("GPU reference");
    assert_eq!(image.radiance.len(), surface.position.len());
    let mut worst: f64 = 0.0;
    let mut lit = 0;
    for (i, got) in image.radiance.iter().enumerate() {
        if surface.position[i][3] != 1.0 {
            assert_eq!(
                *got,
                DVec3::ZERO,
                "{label}: background pixel {i} is not black"
            );
            continue;
        }
        let want = shade(
            &SurfacePoint::from_capture(&surface, i),
            camera,
            &lights,
            falloff,
        );
        lit += usize::from(want.max_element() > ABSOLUTE_FLOOR);
        let error = (*got - want).abs().max_element() / want.max_element().max(ABSOLUTE_FLOOR);
        worst = worst.max(error);
        assert!(
            error <= tolerance,
            "{label}: pixel ({}, {}): GPU reference {got}, f64 reference {want}: relative error {error:.2e} over {tolerance:.2e}",
            i as u32 % settings.view.size.0,
            i as u32 / settings.view.size.0,
        );
    }
    // The comparison means something only where the reference has content.
    assert!(
        lit * 2 > image.radiance.len(),
        "{label}: only {lit} of {} pixels are lit",
        image.radiance.len()
    );
    println!(
        "{label}: largest relative error {worst:.2e} ({} lights)",
        lights.len()
    );
    worst
}

#[test]
fn gpu_reference_equals_the_f64_reference_at_every_pixel() {
    for (name, loaded, tolerance) in [
        (
            "Blinn-Phong cornell",
            LoadedScene::load("cornell").expect("scene"),
            RELATIVE_TOLERANCE,
        ),
        (
            "PBR metals and dielectrics",
            manylights_tests::metal_and_dielectric_cornell(),
            // Its smoothest material (`metal_and_dielectric_cornell`).
            pbr_tolerance(0.05),
        ),
    ] {
        let mut settings = FrameSettings::for_scene(&loaded);
        settings.view.size = SIZE;
        settings.lights.time = 1.5;
        settings.lights.count = 500;
        settings.lights.spots.fraction = 0.5;
        settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
        let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
        for falloff in [Falloff::InverseSquare, Falloff::WindowedInverseSquare] {
            let label = format!("{name}, {falloff:?}");
            check_every_pixel(&mut renderer, &settings, falloff, tolerance, &label);
        }
    }
}

/// One light of intensity 1 and 100,000 of 1e-8 at the same place: each faint term is under
/// half an f32 ulp of the running sum (2^-25 of it at least), so a plain f32 sum drops every
/// one of them and is 1e-3 short at every pixel, a hundred times the tolerance. The
/// compensated sum keeps them (the mutant that sums plainly fails here). 100,000 lights
/// also take the pass past one dispatch's 65,535 (llvmpipe's loop limit).
#[test]
fn compensated_summation_keeps_what_a_plain_f32_sum_loses() {
    let loaded = LoadedScene::load("cornell").expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (16, 12);
    settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let centre = Vec3::new(0.0, 1.5, -1.0);
    let faint_count = 100_000;
    let light = |intensity| Light::point(centre, 10.0, Vec3::new(1.0, 0.9, 0.8), intensity);
    let lights = LightSet {
        lights: std::iter::once(light(1.0))
            .chain(std::iter::repeat_n(light(1e-8), faint_count))
            .collect(),
    };
    renderer.set_fixed_lights(&lights).expect("lights");
    // What the faint lights add is far beyond the tolerance: a sum that dropped them fails.
    let faint_share = faint_count as f64 * 1e-8 / (1.0 + faint_count as f64 * 1e-8);
    assert!(faint_share > 50.0 * RELATIVE_TOLERANCE);
    let label = "one bright and 100,000 faint lights";
    let worst = check_every_pixel(
        &mut renderer,
        &settings,
        Falloff::InverseSquare,
        RELATIVE_TOLERANCE,
        label,
    );
    assert!(worst < faint_share / 10.0);
}
