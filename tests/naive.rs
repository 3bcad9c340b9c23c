//! The naive forward pipeline end to end on the GPU (lavapipe in CI): against the f64
//! reference at every pixel, a golden image of Sponza, and light animation matching the CPU.

#[path = "naive/gpu_reference.rs"]
mod gpu_reference;

use manylights::gpu::SurfaceImage;
use manylights::lights::LightSet;
use manylights::lights::reference::{Shading, SurfacePoint, shade};
use manylights::lights::{
    AnimationParams, Falloff, Light, SPONZA_LIGHT_BOX, animation::animated_position,
};
use manylights::{FrameSettings, LoadedScene, PipelineSettings, Renderer};
use manylights_tests::{assert_matches_golden, golden_mismatch, gpu, load_golden};

const SIZE: (u32, u32) = (128, 96);

fn renderer(scene: &str) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load(scene).expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.pipeline = PipelineSettings::naive(Falloff::default());
    settings.view.size = SIZE;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

/// The stated tolerance (the issue's): relative error at most 1e-3 in linear HDR, compared
/// absolutely below `ABSOLUTE_FLOOR`. The Rgba16Float target alone costs up to one half-float
/// ulp (2^-10 relative: lavapipe converts by truncation), so each value is also held to the
/// tighter bound of one f16 ulp of the reference plus 1e-5 relative for f32 shading: that
/// catches shading errors far smaller than 1e-3.
const RELATIVE_TOLERANCE: f64 = 1e-3;
const ABSOLUTE_FLOOR: f64 = 1e-4;
const F32_SHADING_TOLERANCE: f64 = 1e-5;

/// Renders, reads back HDR, surfaces and lights, and checks every covered pixel against
/// the f64 reference. Returns the largest relative error seen.
fn check_against_reference(renderer: &mut Renderer, settings: &FrameSettings) -> f64 {
    renderer.render_frame(settings).expect("frame");
    let hdr = renderer.read_hdr().expect("hdr");
    let lights: Vec<Light> = renderer.read_lights().expect("lights");
    let surface: SurfaceImage = renderer.capture_surface(settings).expect("surface");
    let camera = settings.view.camera.position.as_dvec3();
    let mut worst: f64 = 0.0;
    let mut covered = 0;
    for (i, gpu) in hdr.iter().enumerate() {
        let p = surface.position[i];
        if p[3] != 1.0 {
            continue;
        }
        covered += 1;
        let point = SurfacePoint::from_capture(&surface, i);
        let reference = shade(&point, camera, &lights, settings.pipeline.falloff());
        for c in 0..3 {
            let want = reference[c];
            let got = gpu[c] as f64;
            let error = (got - want).abs() / want.abs().max(ABSOLUTE_FLOOR);
            worst = worst.max(error);
            let storage_bound =
                manylights_tests::f16_ulp(want) + F32_SHADING_TOLERANCE * want.abs();
            assert!(
                error <= RELATIVE_TOLERANCE && (got - want).abs() <= storage_bound,
                "pixel ({}, {}) channel {c}: GPU {got}, f64 reference {want} (relative error {error:.2e}) with {} lights",
                i as u32 % SIZE.0,
                i as u32 / SIZE.0,
                lights.len()
            );
        }
    }
    assert_eq!(
        covered,
        (SIZE.0 * SIZE.1) as usize,
        "the closed cornell room covers every pixel"
    );
    worst
}

#[test]
fn cornell_matches_the_f64_reference_with_1_8_and_64_lights() {
    let (mut renderer, mut settings) = renderer("cornell");
    settings.lights.time = 1.5;
    for (count, falloff) in [
        (1, Falloff::WindowedInverseSquare),
        (8, Falloff::WindowedInverseSquare),
        (64, Falloff::WindowedInverseSquare),
        (8, Falloff::InverseSquare),
        (8, Falloff::ReferenceProjects),
    ] {
        settings.lights.count = count;
        settings.pipeline = PipelineSettings::naive(falloff);
        let worst = check_against_reference(&mut renderer, &settings);
        println!("{count} lights, {falloff:?}: largest relative error {worst:.2e}");
    }
}

/// Spot lights against the f64 reference (glTF's cone falloff evaluated from its
/// definition in f64, the WGSL's precision-keeping form in f32): half of the lights spots,
/// soft and wide cones, every falloff; the cones must light part of the room.
#[test]
fn cornell_spots_match_the_f64_reference() {
    let (mut renderer, mut settings) = renderer("cornell");
    settings.lights.time = 1.5;
    settings.lights.count = 64;
    for (inner, outer) in [(10.0f32, 25.0f32), (0.0, 60.0), (45.0, 90.0)] {
        settings.lights.spots = manylights::lights::SpotSettings {
            fraction: 0.5,
            cone: manylights::lights::SpotCone {
                inner: inner.to_radians(),
                outer: outer.to_radians(),
            },
        };
        for falloff in [Falloff::WindowedInverseSquare, Falloff::InverseSquare] {
            settings.pipeline = PipelineSettings::naive(falloff);
            let worst = check_against_reference(&mut renderer, &settings);
            println!(
                "64 lights, half spots {inner}-{outer} deg, {falloff:?}: largest relative error {worst:.2e}"
            );
        }
        let lights = renderer.read_lights().expect("lights");
        assert!(lights.iter().filter(|l| l.is_spot()).count() > 20);
    }
}

/// glTF's metallic-roughness BRDF on the GPU against its f64 twin at every pixel, to the
/// same tolerances as Blinn-Phong: dielectrics and metals from glossy to rough, point and
/// spot lights, bounded and unbounded falloffs.
#[test]
fn pbr_matches_its_f64_twin_at_every_pixel() {
    let loaded = manylights_tests::metal_and_dielectric_cornell();
    let mut settings = FrameSettings::for_scene(&loaded);
    assert_eq!(
        settings.shading,
        Shading::Pbr,
        "the scene's model is the default"
    );
    settings.view.size = SIZE;
    settings.lights.time = 1.5;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    for (count, falloff, spots) in [
        (8, Falloff::WindowedInverseSquare, 0.0),
        (64, Falloff::WindowedInverseSquare, 0.5),
        (8, Falloff::InverseSquare, 0.5),
    ] {
        settings.lights.count = count;
        settings.lights.spots.fraction = spots;
        settings.pipeline = PipelineSettings::naive(falloff);
        let worst = check_against_reference(&mut renderer, &settings);
        println!(
            "PBR, {count} lights, {falloff:?}, spots {spots}: largest relative error {worst:.2e}"
        );
    }
    // The surfaces were PBR's (the twin reads them, so it cannot see a wrong blend): every
    // material is a metal (no diffuse albedo, F0 its colour) or a dielectric (F0 0.04),
    // and the room shows both.
    let surface = renderer.capture_surface(&settings).expect("surface");
    assert_eq!(surface.shading, Shading::Pbr);
    let (mut metals, mut dielectrics) = (0, 0);
    for (albedo, f0) in surface.albedo.iter().zip(&surface.specular) {
        let metal = albedo[..3] == [0.0; 3];
        let dielectric = f0[..3].iter().all(|&c| (c - 0.04).abs() < 1e-6);
        assert!(
            metal != dielectric,
            "a surface of albedo {albedo:?} and F0 {f0:?} is neither a metal nor a dielectric"
        );
        metals += usize::from(metal);
        dielectrics += usize::from(dielectric);
    }
    assert!(
        metals > 1000 && dielectrics > 1000,
        "{metals} metal and {dielectrics} dielectric pixels"
    );
}

/// The Khronos MetalRoughSpheres' claim on `assets/spheres/spheres.gltf` (black
/// dielectrics under gold metals, roughness rising left to right), lit by one white light:
/// in each row the highlight's peak falls and its half-peak area grows with roughness, and
/// a metal's peak outshines the dielectric's below it (F0 of gold against 0.04). The mirror
/// column (roughness 0: GGX's floor, alpha 0.002) is left out of the ordering: its
/// highlight is narrower than a pixel at this size, so a pixel may or may not land on it.
#[test]
fn spheres_order_by_highlight_width_and_brightness() {
    use manylights::scene::procedural::{SPHERE_RADIUS, SPHERE_ROUGHNESS, sphere_centre};
    let loaded = LoadedScene::load("spheres").expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    assert_eq!(settings.shading, Shading::Pbr);
    settings.view.size = (480, 240);
    settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    renderer
        .set_fixed_lights(&LightSet {
            lights: vec![Light::point(
                glam::Vec3::new(-1.0, 2.5, 3.0),
                100.0,
                glam::Vec3::ONE,
                20.0,
            )],
        })
        .expect("light");
    renderer.render_frame(&settings).expect("frame");
    let hdr = renderer.read_hdr().expect("hdr");
    let surface = renderer.capture_surface(&settings).expect("surface");
    let columns = SPHERE_ROUGHNESS.len();
    // Per sphere: the luminance of every pixel showing it.
    let mut seen = vec![Vec::new(); 2 * columns];
    for (i, radiance) in hdr.iter().enumerate() {
        let p = surface.position[i];
        if p[3] != 1.0 {
            continue;
        }
        let world =
            surface.origin + glam::DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
        let luminance = 0.2126 * radiance[0] + 0.7152 * radiance[1] + 0.0722 * radiance[2];
        for (sphere, pixels) in seen.iter_mut().enumerate() {
            let centre = sphere_centre(sphere / columns, sphere % columns).as_dvec3();
            if world.distance(centre) < f64::from(SPHERE_RADIUS) * 1.01 {
                pixels.push(luminance);
            }
        }
    }
    let highlight = |sphere: usize| {
        let pixels = &seen[sphere];
        assert!(
            pixels.len() > 500,
            "sphere {sphere} covers {} pixels",
            pixels.len()
        );
        let peak = pixels.iter().copied().fold(0.0f32, f32::max);
        let wide = pixels.iter().filter(|&&l| l >= 0.5 * peak).count();
        (peak, wide)
    };
    for row in 0..2 {
        for column in 1..columns - 1 {
            let (peak, wide) = highlight(row * columns + column);
            let (rougher_peak, rougher_wide) = highlight(row * columns + column + 1);
            println!(
                "row {row}, roughness {}: peak {peak:.3}, {wide} pixels at half of it",
                SPHERE_ROUGHNESS[column]
            );
            assert!(
                peak > rougher_peak && wide < rougher_wide,
                "row {row}: roughness {} peaks at {peak} over {wide} pixels, roughness {} at {rougher_peak} over {rougher_wide}",
                SPHERE_ROUGHNESS[column],
                SPHERE_ROUGHNESS[column + 1]
            );
        }
    }
    for (column, roughness) in SPHERE_ROUGHNESS.iter().enumerate().skip(1) {
        let (dielectric, _) = highlight(column);
        let (metal, _) = highlight(columns + column);
        assert!(
            metal > 2.0 * dielectric,
            "roughness {roughness}: metal {metal}, dielectric {dielectric}"
        );
    }
}

/// The golden frame's settings: 64 bright lights in Sponza, naive, Blinn-Phong (the model
/// the golden image was rendered with).
fn golden_settings(renderer_settings: &mut FrameSettings) {
    renderer_settings.shading = Shading::BlinnPhong;
    renderer_settings.lights.count = 64;
    // 64 lights are sparse: brighter ones show the shading clearly.
    renderer_settings.lights.intensity = 1.0;
    renderer_settings.lights.radius = manylights::lights::RadiusMode::Fixed(4.0);
    renderer_settings.lights.time = 2.0;
    // The golden image was rendered with the colours of that time: hues mixed 80% toward
    // white (saturation 0.2; `lights::light_color` gives them bit for bit).
    renderer_settings.lights.saturation = 0.2;
}

#[test]
fn sponza_with_64_lights_matches_its_golden_image() {
    let (mut renderer, mut settings) = renderer("sponza");
    golden_settings(&mut settings);
    renderer.render_frame(&settings).expect("frame");
    let image = renderer.read_output().expect("output");
    assert_matches_golden("sponza_64_lights", &image);
}

/// The golden check must see a single missing light: the frame is rendered again without
/// each of the 64 lights in turn, and every light whose absence changes more pixels than
/// the check allows must fail the comparison with the golden file.
#[test]
fn golden_check_sees_any_one_missing_light() {
    let (mut renderer, mut settings) = renderer("sponza");
    golden_settings(&mut settings);
    renderer.render_frame(&settings).expect("frame");
    let complete = renderer.read_output().expect("output");
    let lights = renderer.read_lights().expect("lights");
    let golden = load_golden("sponza_64_lights");
    let mut visible = 0;
    for missing in 0..lights.len() {
        let mut fewer = lights.clone();
        fewer.remove(missing);
        renderer
            .set_fixed_lights(&LightSet { lights: fewer })
            .expect("lights");
        renderer.render_frame(&settings).expect("frame");
        let image = renderer.read_output().expect("output");
        let (changed_by_light, allowed) = golden_mismatch(&complete, &image);
        let (changed_from_golden, _) = golden_mismatch(&golden, &image);
        if changed_by_light > allowed {
            visible += 1;
            assert!(
                changed_from_golden > allowed,
                "without light {missing} ({changed_by_light} pixels change) the golden check passes ({changed_from_golden} pixels beyond tolerance, {allowed} allowed)"
            );
        }
    }
    println!(
        "{visible} of {} lights visible; each one's absence fails the golden check",
        lights.len()
    );
    // Not vacuous: most of the 64 lights light the frame (measured: 46 on lavapipe).
    assert!(
        visible >= lights.len() / 2,
        "only {visible} lights change the golden frame"
    );
}

#[test]
fn gpu_light_animation_matches_the_cpu_within_1e_4() {
    let (mut renderer, mut settings) = renderer("sponza");
    settings.lights.count = 10_000;
    settings.view.size = (8, 8);
    let params = AnimationParams::in_box(SPONZA_LIGHT_BOX);
    for time in [0.0, 0.37, 12.5, 300.0] {
        settings.lights.time = time;
        renderer.render_frame(&settings).expect("frame");
        let lights = renderer.read_lights().expect("lights");
        assert_eq!(lights.len(), 10_000);
        let mut worst = 0.0f32;
        for (index, light) in lights.iter().enumerate() {
            let cpu = animated_position(&params, settings.lights.seed, index as u32, time);
            let difference = (glam::Vec3::from_array(light.position) - cpu)
                .abs()
                .max_element();
            worst = worst.max(difference);
            assert!(
                difference <= 1e-4,
                "light {index} at t={time}: GPU {:?}, CPU {cpu}",
                light.position
            );
        }
        println!("t={time}: largest GPU/CPU difference {worst:.2e} m");
    }
}

#[test]
fn frames_are_reproducible() {
    let (mut renderer, mut settings) = renderer("cornell");
    settings.lights.count = 32;
    settings.lights.time = 4.25;
    renderer.render_frame(&settings).expect("frame");
    let first = renderer.read_output().expect("output");
    // Another time in between, then back: the same image, bit for bit.
    settings.lights.time = 9.0;
    renderer.render_frame(&settings).expect("frame");
    let other = renderer.read_output().expect("output");
    settings.lights.time = 4.25;
    renderer.render_frame(&settings).expect("frame");
    let again = renderer.read_output().expect("output");
    assert_eq!(first, again, "same seed and time must give the same image");
    assert_ne!(first, other, "lights must move between t=4.25 and t=9");
    // A fresh renderer (new device, new lights) gives the same image too.
    let (mut fresh, _) = renderer_with_same_scene();
    fresh.render_frame(&settings).expect("frame");
    assert_eq!(first, fresh.read_output().expect("output"));
}

fn renderer_with_same_scene() -> (Renderer, FrameSettings) {
    renderer("cornell")
}
