//! The frame-time budget (`FrameSettings::budget`, issue 29) on the GPU (lavapipe in CI):
//! a budget every frame fits keeps the asked radius; one no frame fits shortens it frame
//! after frame down to its floor, each frame reporting the radius it drew with; a frame at
//! the budget's radius is the frame drawn with that radius asked for directly (the
//! animation pass writes the radius the lights were not regenerated for); and a budget
//! that is not a positive number of milliseconds is refused.

use manylights::budget::BUDGET_MIN_RADIUS_FRACTION;
use manylights::lights::RadiusMode;
use manylights::{FrameSettings, LoadedScene, Renderer};
use manylights_tests::{assert_lit, gpu};

const ASKED_RADIUS: f32 = 4.0;

fn renderer() -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = (64, 48);
    settings.light_count = 2000;
    settings.time = 0.5;
    settings.radius = RadiusMode::Fixed(ASKED_RADIUS);
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

#[test]
fn a_budget_every_frame_fits_keeps_the_asked_radius() {
    let (mut renderer, mut settings) = renderer();
    settings.budget = Some(1e6);
    for _ in 0..6 {
        let stats = renderer.render_frame_timed(&settings).expect("frame");
        assert_eq!(stats.radius, ASKED_RADIUS);
    }
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
    // Turning the budget off gives the asked radius back.
    settings.budget = None;
    let stats = renderer.render_frame_timed(&settings).expect("frame");
    assert_eq!(stats.radius, ASKED_RADIUS);
}

#[test]
fn a_frame_at_the_budgets_radius_is_the_frame_asked_at_that_radius() {
    let (mut renderer, mut settings) = renderer();
    settings.budget = Some(1e-3);
    let mut radius = ASKED_RADIUS;
    for _ in 0..4 {
        radius = renderer
            .render_frame_timed(&settings)
            .expect("frame")
            .radius;
    }
    assert!(radius < ASKED_RADIUS * 0.5, "radius {radius}");
    let budgeted = renderer.read_hdr().expect("hdr");
    assert_lit("budgeted frame", &budgeted, 0.05);

    let (mut fresh, mut asked) = self::renderer();
    asked.radius = RadiusMode::Fixed(radius);
    fresh.render_frame_timed(&asked).expect("frame");
    let direct = fresh.read_hdr().expect("hdr");
    let differing = budgeted
        .iter()
        .zip(&direct)
        .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
        .count();
    assert_eq!(
        differing, 0,
        "the budget's radius {radius} and the same radius asked for differ in {differing} pixels"
    );
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
