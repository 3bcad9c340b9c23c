//! The frame-time budget (`FrameSettings::budget`, issue 29) on the GPU (lavapipe in CI):
//! a budget every frame fits keeps the asked radius (and slots); one no frame fits shortens
//! the radius frame after frame down to its floor, and with a tree far field takes the
//! cut's slots down to their least too, each frame reporting what it drew with and, at the
//! floor, that the budget is out of reach; a frame at the budget's choice is the frame drawn
//! with that radius and those slots asked for directly (the animation pass writes the
//! radius the lights were not regenerated for); and a budget that is not a positive number
//! of milliseconds is refused.

use manylights::budget::{
    BUDGET_FAR_RADIUS_FRACTION, BUDGET_MIN_FAR_SLOTS, BUDGET_MIN_RADIUS_FRACTION,
};
use manylights::cluster::{FarField, FarFieldMethod};
use manylights::lights::RadiusMode;
use manylights::{FrameSettings, LoadedScene, PipelineSettings, Renderer};
use manylights_tests::{assert_lit, clustering_mut, gpu};

const ASKED_RADIUS: f32 = 4.0;

fn renderer() -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    // The controller's choices do not depend on the frame's size or light count (a budget
    // of 1e-3 ms fits no frame, one of 1e6 ms every frame): a small frame with enough
    // lights to light it (with radius 4 in the 1 m box, every pixel evaluates every light;
    // 2000 lights at 64x48 made these the slowest tests on lavapipe).
    settings.view.size = (32, 24);
    settings.lights.count = 250;
    settings.lights.time = 0.5;
    settings.lights.radius = RadiusMode::Fixed(ASKED_RADIUS);
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

#[test]
fn a_budget_every_frame_fits_keeps_the_asked_radius() {
    let (mut renderer, mut settings) = renderer();
    settings.budget = Some(1e6);
    for far_field in [None, Some(tree(ASKED_SLOTS))] {
        clustering_mut(&mut settings).far_field = far_field;
        for _ in 0..6 {
            let stats = renderer.render_frame_timed(&settings).expect("frame");
            assert_eq!(stats.radius, ASKED_RADIUS);
            assert_eq!(stats.far_slots, far_field.map(|_| ASKED_SLOTS));
            assert!(!stats.budget_out_of_reach);
        }
    }
}

const ASKED_SLOTS: u32 = 96;

/// The light tree at tolerance 1 with `slots`.
fn tree(slots: u32) -> FarField {
    FarField {
        slots,
        ..FarField::new(FarFieldMethod::Tree)
    }
}

/// Deferred (a clustered pipeline: the far field needs the lists).
fn clustered(settings: &mut FrameSettings) {
    settings.pipeline = PipelineSettings::deferred(Default::default(), Default::default());
}

#[test]
fn a_budget_no_frame_fits_shortens_the_radius_to_its_floor() {
    let (mut renderer, mut settings) = renderer();
    // A microsecond: no frame on any GPU fits.
    settings.budget = Some(1e-3);
    let mut radii = Vec::new();
    for _ in 0..40 {
        radii.push(
            renderer
                .render_frame_timed(&settings)
                .expect("frame")
                .radius,
        );
    }
    assert!(
        radii.windows(2).all(|w| w[1] <= w[0]),
        "the radius grew under a budget no frame fits: {radii:?}"
    );
    let floor = ASKED_RADIUS * BUDGET_MIN_RADIUS_FRACTION;
    assert!(
        (radii[radii.len() - 1] - floor).abs() <= floor * 1e-5,
        "after 40 frames the radius is {} (floor {floor}): {radii:?}",
        radii[radii.len() - 1]
    );
    assert!(
        renderer
            .render_frame_timed(&settings)
            .expect("frame")
            .budget_out_of_reach,
        "a budget no frame fits, at the floor, is not reported out of reach"
    );
    // Turning the budget off gives the asked radius back.
    settings.budget = None;
    let stats = renderer.render_frame_timed(&settings).expect("frame");
    assert_eq!(stats.radius, ASKED_RADIUS);
}

#[test]
fn with_a_tree_far_field_a_budget_no_frame_fits_takes_the_radius_then_the_slots() {
    let (mut renderer, mut settings) = renderer();
    clustered(&mut settings);
    clustering_mut(&mut settings).far_field = Some(tree(ASKED_SLOTS));
    settings.budget = Some(1e-3);
    let far_radius = ASKED_RADIUS * BUDGET_FAR_RADIUS_FRACTION;
    let mut frames = Vec::new();
    for _ in 0..80 {
        let stats = renderer.render_frame_timed(&settings).expect("frame");
        frames.push((
            stats.radius,
            stats.far_slots.expect("slots"),
            stats.budget_out_of_reach,
        ));
    }
    for window in frames.windows(2) {
        let ((r0, s0, _), (r1, s1, _)) = (window[0], window[1]);
        assert!(
            r1 <= r0 && s1 <= s0,
            "a dial grew under a budget no frame fits: {frames:?}"
        );
    }
    for &(radius, slots, _) in &frames {
        assert!(
            slots == ASKED_SLOTS || radius <= far_radius,
            "slots taken before the radius was down to {far_radius}: {frames:?}"
        );
        assert!(
            radius >= far_radius || slots == BUDGET_MIN_FAR_SLOTS,
            "the radius went below {far_radius} before the slots were at their least: {frames:?}"
        );
    }
    let floor = ASKED_RADIUS * BUDGET_MIN_RADIUS_FRACTION;
    let (radius, slots, out_of_reach) = frames[frames.len() - 1];
    assert!(
        (radius - floor).abs() <= floor * 1e-5 && slots == BUDGET_MIN_FAR_SLOTS && out_of_reach,
        "after 80 frames: radius {radius}, {slots} slots, out of reach {out_of_reach}: {frames:?}"
    );
}

#[test]
fn a_frame_at_the_budgets_choice_is_the_frame_asked_for_it() {
    // Without a far field (the radius moves) and with the tree (after enough frames the
    // slots move too).
    for (far_field, frames) in [(None, 4), (Some(tree(ASKED_SLOTS)), 24)] {
        let (mut renderer, mut settings) = renderer();
        if far_field.is_some() {
            clustered(&mut settings);
        }
        clustering_mut(&mut settings).far_field = far_field;
        settings.budget = Some(1e-3);
        let mut stats = renderer.render_frame_timed(&settings).expect("frame");
        for _ in 1..frames {
            stats = renderer.render_frame_timed(&settings).expect("frame");
        }
        assert!(stats.radius < ASKED_RADIUS * 0.5, "radius {}", stats.radius);
        if far_field.is_some() {
            assert!(
                stats.far_slots < Some(ASKED_SLOTS),
                "slots {:?}",
                stats.far_slots
            );
        }
        let budgeted = renderer.read_hdr().expect("hdr");
        assert_lit("budgeted frame", &budgeted, 0.05);

        let (mut fresh, mut asked) = self::renderer();
        asked.pipeline = settings.pipeline;
        asked.lights.radius = RadiusMode::Fixed(stats.radius);
        clustering_mut(&mut asked).far_field =
            far_field.map(|far| tree(stats.far_slots.unwrap_or(far.slots)));
        fresh.render_frame_timed(&asked).expect("frame");
        let direct = fresh.read_hdr().expect("hdr");
        let differing = budgeted
            .iter()
            .zip(&direct)
            .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
            .count();
        assert_eq!(
            differing, 0,
            "the budget's radius {} and slots {:?} and the same asked for differ in {differing} pixels",
            stats.radius, stats.far_slots
        );
    }
}

#[test]
fn a_budget_must_be_a_positive_number_of_milliseconds() {
    let (mut renderer, mut settings) = renderer();
    for budget in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        settings.budget = Some(budget);
        let error = renderer.render_frame(&settings).unwrap_err().to_string();
        assert!(error.contains("budget"), "{budget}: {error}");
    }
}

/// A frame the plan refuses (here, 3x MSAA, asking a shorter radius too) is not drawn, so
/// it does not move the budget: with refused frames between them, the budget's frames draw
/// with the radii of the same frames without (the refused frame's ask once clamped the
/// budget's radius for good).
#[test]
fn a_refused_frame_leaves_the_budget_as_it_was() {
    let radii = |refusals: usize| {
        let (mut renderer, mut settings) = renderer();
        settings.budget = Some(1e-3);
        let mut refused = settings.clone();
        refused.view.msaa = 3;
        refused.lights.radius = RadiusMode::Fixed(ASKED_RADIUS * 0.1);
        (0..4)
            .map(|_| {
                for _ in 0..refusals {
                    let error = renderer.render_frame_timed(&refused).unwrap_err();
                    assert!(error.to_string().contains("MSAA"), "{error}");
                }
                renderer
                    .render_frame_timed(&settings)
                    .expect("frame")
                    .radius
            })
            .collect::<Vec<f32>>()
    };
    let plain = radii(0);
    assert!(plain[3] < plain[0], "the budget moved nothing: {plain:?}");
    assert_eq!(radii(5), plain, "refused frames stepped the budget");
}
