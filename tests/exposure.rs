//! Automatic exposure on the GPU (lavapipe in CI): the exposure maps the median luminance
//! of the lit pixels to mid-grey within one histogram bin, follows the scene's brightness,
//! moves part of the way when asked to adapt, keeps its value over a black frame, and a
//! fixed exposure is exactly what was asked.

use manylights::gpu::AUTO_EXPOSURE_BIN_STOPS;
use manylights::lights::RadiusMode;
use manylights::{AutoExposure, Exposure, FrameSettings, LoadedScene, Renderer};
use manylights_tests::gpu;

/// The luminance the median is mapped to.
const MID_GREY: f64 = 0.18;
/// Pixels at or below this luminance count as black (the shader's bin 0: 2^-20).
const BLACK: f64 = 1.0 / 1048576.0;

fn renderer() -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (96, 64);
    settings.lights.count = 64;
    settings.lights.time = 0.5;
    // A fixed radius: scaling the intensity then scales every pixel by the same factor.
    settings.lights.radius = RadiusMode::Fixed(2.0);
    settings.post.exposure = Exposure::Auto(AutoExposure::CONVERGE_NOW);
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

/// The median luminance of the lit pixels, as the shader picks it: the smallest value
/// with at least half of the lit pixels at or below it.
fn median_lit_luminance(hdr: &[[f32; 4]]) -> f64 {
    let mut lit: Vec<f64> = hdr
        .iter()
        .map(|t| 0.2126 * f64::from(t[0]) + 0.7152 * f64::from(t[1]) + 0.0722 * f64::from(t[2]))
        .filter(|&l| l > BLACK)
        .collect();
    assert!(
        lit.len() > hdr.len() / 2,
        "most of the frame should be lit: {} of {}",
        lit.len(),
        hdr.len()
    );
    lit.sort_by(f64::total_cmp);
    lit[lit.len().div_ceil(2) - 1]
}

/// Renders and returns (exposure, median luminance the GPU found, CPU median).
fn render(renderer: &mut Renderer, settings: &FrameSettings) -> (f64, f64, f64) {
    renderer.render_frame(settings).expect("frame");
    let hdr = renderer.read_hdr().expect("hdr");
    let state = renderer.read_exposure().expect("exposure");
    assert_eq!(state.valid, 1, "an automatic exposure was resolved");
    (
        f64::from(state.value),
        f64::from(state.median_luminance),
        median_lit_luminance(&hdr),
    )
}

/// The GPU takes the centre of the median's bin: at most half a bin from the true median
/// (in stops); one bin leaves room for the f16 rounding of the HDR target at a bin edge.
const STOPS_TOLERANCE: f64 = AUTO_EXPOSURE_BIN_STOPS as f64;

/// The histogram must count the last pixel column and row: in a frame one pixel wide (or
/// high) every pixel is in it, so a pass that skipped it would find nothing lit and leave
/// the exposure unresolved (`render` asserts it resolved), or find a different median.
#[test]
fn the_histogram_counts_the_last_column_and_row() {
    for size in [(1, 64), (96, 1)] {
        let (mut renderer, mut settings) = renderer();
        settings.view.size = size;
        let (_, gpu_median, cpu_median) = render(&mut renderer, &settings);
        let stops_off = (gpu_median / cpu_median).log2().abs();
        assert!(
            stops_off <= STOPS_TOLERANCE,
            "{size:?}: GPU median {gpu_median} vs CPU median {cpu_median}: {stops_off} stops apart"
        );
    }
}

#[test]
fn converges_in_one_frame_to_the_median_at_mid_grey() {
    let (mut renderer, settings) = renderer();
    let (exposure, gpu_median, cpu_median) = render(&mut renderer, &settings);
    let stops_off = (gpu_median / cpu_median).log2().abs();
    assert!(
        stops_off <= STOPS_TOLERANCE,
        "GPU median {gpu_median} vs CPU median {cpu_median}: {stops_off} stops apart"
    );
    let expected = MID_GREY / cpu_median;
    let stops_off = (exposure / expected).log2().abs();
    assert!(
        stops_off <= STOPS_TOLERANCE,
        "exposure {exposure} vs 0.18 / median = {expected}: {stops_off} stops apart"
    );
}

#[test]
fn follows_the_brightness_and_adapts_part_of_the_way() {
    let (mut renderer, mut settings) = renderer();
    let (bright, _, _) = render(&mut renderer, &settings);
    // 16x dimmer lights: the exposure converges 4 stops higher.
    settings.lights.intensity /= 16.0;
    let (dim, _, _) = render(&mut renderer, &settings);
    let stops = (dim / bright).log2();
    assert!(
        (stops - 4.0).abs() <= STOPS_TOLERANCE,
        "16x dimmer moved the exposure {stops} stops"
    );
    // Back to bright, half of the way (in stops) in one frame.
    settings.lights.intensity *= 16.0;
    settings.post.exposure = Exposure::Auto(AutoExposure {
        adaptation: 0.5,
        ..AutoExposure::CONVERGE_NOW
    });
    let (halfway, _, _) = render(&mut renderer, &settings);
    let moved = (dim / halfway).log2();
    assert!(
        (moved - 2.0).abs() <= STOPS_TOLERANCE,
        "half of a 4-stop change moved {moved} stops"
    );
    // The viewer's time constant: one 1/60 s frame covers 1 - e^(-1/30) of a change.
    let viewer = AutoExposure::adapting(0.0, 1.0 / 60.0, 0.5);
    assert!((f64::from(viewer.adaptation) - (1.0 - (-1.0f64 / 30.0).exp())).abs() < 1e-6);
}

/// The viewer's adaptation speed, as designed: 63% of a change (1 - 1/e) in half a second.
/// From a converged frame, lights 16 times dimmer (4 stops) and 30 frames of 1/60 s
/// adapting as the viewer does: the exposure has moved 4 (1 - 1/e) = 2.53 stops. Each
/// frame moves it a fixed share of the way, in stops, toward that frame's target, which is
/// within a bin of the true one; a mean of such targets stays within a bin too. A time
/// constant of 0.25 s would move it 3.46 stops, one of 1 s 1.57.
#[test]
fn the_viewers_exposure_covers_63_percent_of_a_change_in_half_a_second() {
    const HALF_A_SECOND_OF_FRAMES: u32 = 30;
    let (mut renderer, mut settings) = renderer();
    let (bright, _, _) = render(&mut renderer, &settings);
    settings.lights.intensity /= 16.0;
    settings.post.exposure = Exposure::Auto(AutoExposure::adapting(
        0.0,
        1.0 / 60.0,
        AutoExposure::VIEWER_TIME_CONSTANT_S,
    ));
    let mut adapted = bright;
    for _ in 0..HALF_A_SECOND_OF_FRAMES {
        adapted = render(&mut renderer, &settings).0;
    }
    let moved = (adapted / bright).log2();
    let expected = 4.0 * (1.0 - (-1.0f64).exp());
    assert!(
        (moved - expected).abs() <= STOPS_TOLERANCE,
        "half a second of the viewer's adaptation moved the exposure {moved:.3} stops of a \
         4-stop change; 63% of it is {expected:.3}"
    );
}

#[test]
fn compensation_adds_stops_and_a_black_frame_keeps_the_exposure() {
    let (mut renderer, mut settings) = renderer();
    let (plain, _, _) = render(&mut renderer, &settings);
    settings.post.exposure = Exposure::Auto(AutoExposure {
        compensation_ev: 1.0,
        ..AutoExposure::CONVERGE_NOW
    });
    let (brighter, _, _) = render(&mut renderer, &settings);
    assert!(
        ((brighter / plain) - 2.0).abs() < 1e-5,
        "+1 EV: {plain} -> {brighter}"
    );
    // No lights: nothing is lit, the exposure stays and the image is black, not NaN.
    settings.lights.count = 0;
    renderer.render_frame(&settings).expect("black frame");
    let state = renderer.read_exposure().expect("exposure");
    assert_eq!(f64::from(state.value), brighter);
    let image = renderer.read_output().expect("image");
    assert!(image.pixels().all(|p| p.0[..3] == [0, 0, 0]));
}

#[test]
fn a_fixed_exposure_is_exactly_what_was_asked() {
    let (mut renderer, mut settings) = renderer();
    render(&mut renderer, &settings);
    settings.post.exposure = Exposure::Manual(2.5);
    renderer.render_frame(&settings).expect("frame");
    let state = renderer.read_exposure().expect("exposure");
    assert_eq!(state.value, 2.5);
    assert_eq!(
        state.valid, 0,
        "the next automatic exposure converges at once"
    );
}
