//! The post stack (issue 62): temporal anti-aliasing and bloom, in every pipeline.

use glam::Vec3;
use manylights::lights::Falloff;
use manylights::scene::Scene;
use manylights::scene::procedural::glass_room;
use manylights::{AntiAliasing, Exposure, FrameSettings, LoadedScene, PipelineSettings, Renderer};
use manylights_lab::lab::edges::supersampled;
use manylights_tests::{assert_lit, gpu, self_lit_glass_room};

#[path = "post/bloom_twin.rs"]
mod bloom_twin;
#[path = "post/passes.rs"]
mod passes;
#[path = "post/taa_twin.rs"]
mod taa_twin;

const SIZE: (u32, u32) = (96, 72);

fn settings_for(loaded: &LoadedScene, size: (u32, u32)) -> FrameSettings {
    let mut settings = FrameSettings::for_scene(loaded);
    settings.view.size = size;
    settings.lights.count = 24;
    settings.post.exposure = Exposure::Manual(1.0);
    // The self-lit room's surfaces glow without lighting one another.
    settings.lights.emissive = false;
    settings
}

/// `frames` frames of `scene` (the frame's number as its seed, as the viewer counts
/// them), each with `change` applied; the last frame's HDR radiance.
fn frames(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    seeds: std::ops::Range<u32>,
) -> Vec<[f32; 4]> {
    let mut settings = settings.clone();
    for seed in seeds {
        settings.shadows.seed = seed;
        renderer.render_frame(&settings).expect("frame");
    }
    renderer.read_hdr().expect("hdr")
}

fn new_renderer(scene: Scene) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::from_scene("post", scene);
    let settings = settings_for(&loaded, SIZE);
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

/// A still camera with TAA converges to the box-filtered frame at its edges; without it,
/// each pixel is one sample at its centre, and does not.
///
/// The tolerance: a pixel an edge crosses with coverage c is estimated from the 16
/// jittered samples (Halton points) with an error of at most the points' discrepancy for
/// half-planes, about 2/16 for 16 Halton points, so a mean error over edge pixels of
/// 1/8 of their contrast bounds TAA's. One sample at the centre is off by min(c, 1 - c),
/// a mean of 1/4 over coverages spread evenly: asserted above 1/8 too, so the test
/// separates the two.
#[test]
fn taa_converges_to_the_supersampled_frame_at_edges_in_every_pipeline() {
    const TOLERANCE: f32 = 0.125;
    for pipeline in [
        PipelineSettings::naive(Falloff::WindowedInverseSquare),
        PipelineSettings::forward_plus(),
        PipelineSettings::default(),
    ] {
        let (mut renderer, mut settings) = new_renderer(self_lit_glass_room());
        settings.pipeline = pipeline;
        let reference = supersampled(&mut renderer, &settings, 4).expect("supersampled frame");
        if pipeline.kind() == manylights::PipelineKind::ForwardPlus {
            // For the report: MSAA 4x's error on the same edges (the target).
            let mut msaa = settings.clone();
            msaa.view.msaa = 4;
            let image = frames(&mut renderer, &msaa, 0..1);
            let (error, _) = reference.edge_error(&image);
            eprintln!("forward-plus, 4x MSAA: edge error {error:.4}");
        }
        let single = frames(&mut renderer, &settings, 0..1);
        settings.post.anti_aliasing = AntiAliasing::Taa;
        let taa = frames(&mut renderer, &settings, 0..32);
        let (taa_error, edges) = reference.edge_error(&taa);
        let (single_error, _) = reference.edge_error(&single);
        let kind = pipeline.kind();
        assert!(
            edges > 200,
            "{kind}: only {edges} edge pixels: the test sees too few edges"
        );
        assert!(
            taa_error <= TOLERANCE,
            "{kind}: TAA's mean edge error {taa_error:.4} of the contrast, over {edges} edge \
             pixels, above {TOLERANCE}; one sample a pixel: {single_error:.4}"
        );
        assert!(
            single_error > TOLERANCE,
            "{kind}: one sample a pixel is within {single_error:.4} of the supersampled \
             frame: the edges do not test anti-aliasing"
        );
        eprintln!(
            "{kind}: edge error {single_error:.4} without TAA, {taa_error:.4} with ({edges} edge pixels)"
        );
    }
}

/// After a camera cut, no pixel keeps the old view's history: the first frame of the new
/// view equals a fresh renderer's first frame there (with the same jitter), pixel for
/// pixel.
#[test]
fn a_camera_cut_leaves_nothing_of_the_old_image() {
    let (mut renderer, mut settings) = new_renderer(self_lit_glass_room());
    settings.post.anti_aliasing = AntiAliasing::Taa;
    // From the middle of the room: toward the back wall and the panes, then turned round
    // to the floor behind, all of which lay behind the first view's camera.
    let eye = Vec3::new(0.0, 1.5, 0.0);
    let old_view = manylights::Camera::look_at(eye, Vec3::new(0.0, 1.2, -4.0), 60.0, 0.05, 100.0);
    let new_view = manylights::Camera::look_at(eye, Vec3::new(0.0, 0.3, 4.0), 60.0, 0.05, 100.0);
    settings.view.camera = old_view;
    // The jitter repeats every 16 frames: frame 16 has frame 0's.
    frames(&mut renderer, &settings, 0..16);
    settings.view.camera = new_view;
    let cut = frames(&mut renderer, &settings, 16..17);

    let (mut fresh_renderer, _) = new_renderer(self_lit_glass_room());
    let fresh = frames(&mut fresh_renderer, &settings, 0..1);
    assert_lit("the new view", &fresh, 0.3);
    let differing = cut.iter().zip(&fresh).filter(|(a, b)| a != b).count();
    assert_eq!(
        differing, 0,
        "{differing} pixels of the frame after the cut kept history of the view before it"
    );
}

/// The glass room lit by the generated lights alone (no fixed lights, no emission).
fn room_lit_by_generated_lights() -> Scene {
    let mut scene = glass_room();
    scene.lights.clear();
    for material in &mut scene.materials {
        material.emissive_factor = Vec3::ZERO;
    }
    scene
}

/// Light that changed leaves no trail: with the camera still, the lights going out make
/// the history (of the lit frames) wrong everywhere while every surface is the same, so
/// only the neighbourhood clipping can drop it. The frame after must be as dark as a fresh
/// one: the clipped history lies within the neighbourhood's mean plus 1.25 standard
/// deviations, and a standard deviation of values in [0, max] is at most max / 2
/// (Popoviciu), so within 1.625 times the fresh frame's brightest pixel (2 is asserted):
/// here, where the fresh frame is black, black.
#[test]
fn taa_clips_history_to_what_the_frame_shows_now() {
    let (mut renderer, mut settings) = new_renderer(room_lit_by_generated_lights());
    settings.post.anti_aliasing = AntiAliasing::Taa;
    let bright = frames(&mut renderer, &settings, 0..16);
    assert_lit("the lit room", &bright, 0.2);
    settings.lights.count = 0;
    let after = frames(&mut renderer, &settings, 16..17);
    let (mut fresh_renderer, _) = new_renderer(room_lit_by_generated_lights());
    let fresh = frames(&mut fresh_renderer, &settings, 0..1);
    let brightest = |image: &[[f32; 4]]| {
        image
            .iter()
            .flat_map(|p| p[..3].iter().copied())
            .fold(0.0f32, f32::max)
    };
    let (after, fresh) = (brightest(&after), brightest(&fresh));
    assert!(
        after <= 2.0 * fresh,
        "the frame after the lights went out peaks at {after:e}, a fresh one at {fresh:e}: \
         the lit history was kept"
    );
}

/// The total HDR radiance of a frame with and without bloom: bloom moves light, it does
/// not make or lose it; and a black frame stays black.
///
/// Every step of the chain is a weighted mean with weights summing to 1, so what it loses
/// is at the frame's border (the filters' reach beyond the edge is read clamped, and the
/// coarsest levels reach it from everywhere) and in the first step's firefly weighting,
/// which moves weight toward darker boxes where neighbouring boxes differ. The bloom image
/// may miss the frame's total by at most 2% for these (0.8% here: 0.5 of the border, 0.3
/// of the weighting), and the frame, a blend toward it, by STRENGTH times that: at 0.1,
/// within a tenth of what 1 loses, plus the half floats' rounding of the frame's write:
/// at most one half-float step a pixel (2^-10 of its value, where a device truncates
/// instead of rounding), so 2^-10 of the total.
#[test]
fn bloom_keeps_the_frames_light_and_black_stays_black() {
    let total = |image: &[[f32; 4]]| -> f64 {
        image
            .iter()
            .map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]))
            .sum()
    };
    let (mut renderer, mut settings) = new_renderer(glass_room());
    let plain = frames(&mut renderer, &settings, 0..1);
    assert_lit("the lit room", &plain, 0.3);
    let mut change = |strength: f32| {
        settings.post.bloom = strength;
        let bloomed = frames(&mut renderer, &settings, 0..1);
        let changed = plain.iter().zip(&bloomed).filter(|(a, b)| a != b).count();
        assert!(
            changed > plain.len() / 2,
            "bloom {strength} changed only {changed} pixels"
        );
        let (before, after) = (total(&plain), total(&bloomed));
        eprintln!("bloom {strength}: total {before:.4} -> {after:.4}");
        after / before - 1.0
    };
    let (full, tenth) = (change(1.0), change(0.1));
    assert!(
        full.abs() <= 0.02,
        "the bloom image's total is {:+.3}% of the frame's: light was made or lost",
        100.0 * full
    );
    assert!(
        (tenth - 0.1 * full).abs() <= 2f64.powi(-10),
        "bloom 0.1 changed the total by {:+.4}%, bloom 1 by {:+.4}%: not a blend",
        100.0 * tenth,
        100.0 * full
    );

    let (mut renderer, mut settings) = new_renderer(room_lit_by_generated_lights());
    settings.lights.count = 0;
    settings.post.bloom = 1.0;
    settings.post.anti_aliasing = AntiAliasing::Taa;
    let black = frames(&mut renderer, &settings, 0..4);
    assert!(
        black.iter().all(|p| p[..3] == [0.0; 3]),
        "a black frame came out of bloom and TAA with light in it"
    );
}
