//! Clustered deferred on the GPU (lavapipe in CI): the lossless `full` layout matches naive
//! within Forward+'s tolerance on both lighting paths; `compact` and `packed` stay within
//! the error their encodings can cause on Sponza; fragment and compute lighting agree; the
//! G-buffer debug views draw.

use glam::Vec3;
use manylights::{
    Camera, DebugView, FrameSettings, GBufferLayout, LightingPath, LoadedScene, PipelineKind,
    Renderer,
};
use manylights_tests::{assert_hdr_close, gpu};

fn renderer(scene: &str, size: (u32, u32)) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load(scene).expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = size;
    settings.time = 1.25;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

fn render_hdr(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f32; 4]> {
    renderer.render_frame(settings).expect("frame");
    renderer.read_hdr().expect("hdr")
}

fn deferred(settings: &FrameSettings, layout: GBufferLayout, path: LightingPath) -> FrameSettings {
    FrameSettings {
        pipeline: PipelineKind::Deferred,
        gbuffer: layout,
        lighting: path,
        ..settings.clone()
    }
}

/// The same tolerance as Forward+ against naive: one half-float ulp plus 1e-4 relative.
const FULL_LAYOUT_RELATIVE: f32 = 1e-4;

#[test]
fn full_layout_matches_naive_on_both_lighting_paths() {
    for scene in ["cornell", "sponza"] {
        let (mut renderer, mut settings) = renderer(scene, (96, 64));
        // 6 m lights: with 2 m ones, 16 lights in Sponza's 20 m x 10 m box light under 2% of
        // some views, and a comparison of dark pixels proves little.
        settings.radius = manylights::lights::RadiusMode::Fixed(6.0);
        let cameras: Vec<Camera> = renderer.scene.presets.iter().map(|(_, c)| *c).collect();
        for camera in cameras {
            for count in [16, 300] {
                settings.camera = camera;
                settings.light_count = count;
                settings.pipeline = PipelineKind::Naive;
                let naive = render_hdr(&mut renderer, &settings);
                manylights_tests::assert_lit(&format!("{scene} {count} lights"), &naive, 0.05);
                for path in LightingPath::ALL {
                    let full = render_hdr(
                        &mut renderer,
                        &deferred(&settings, GBufferLayout::Full, path),
                    );
                    let worst = assert_hdr_close(
                        &format!("{scene} {count} lights full/{path:?}"),
                        &naive,
                        &full,
                        FULL_LAYOUT_RELATIVE,
                    );
                    println!(
                        "{scene}, {count} lights, full/{path:?}: largest relative difference {worst:.2e}"
                    );
                }
            }
        }
    }
}

/// Largest relative change of a linear colour channel that half an 8-bit sRGB step can
/// make, for channels at or above sRGB value `srgb` (0..1): the sRGB curve's relative slope
/// there is 2.4 / (srgb + 0.055), times half a step (0.5 / 255).
fn srgb8_half_step_relative(srgb: f64) -> f64 {
    2.4 * (0.5 / 255.0) / (srgb + 0.055)
}

/// Relative error bound for a lit pixel's channel in the lossy layouts, derived from what
/// their encodings can change (not fitted to a machine):
/// - albedo and specular in 8-bit sRGB: at most half a step, which is at most 5.0% in
///   linear for any channel at or above sRGB 0.04 (linear 0.003), see
///   `srgb8_half_step_relative`;
/// - the normal in 2 x 16-bit octahedral coordinates: under 1e-4 rad, changing n.l by under
///   1e-4 (negligible beside the albedo);
/// - position from 32-bit depth: a relative depth error of about 2^-22, changing 1/d^2 by
///   under 1e-6 relative.
///
/// So the albedo's half step bounds the error of every lit pixel whose colour channels are
/// not nearly black. The exceptions are texels darker than sRGB 0.04 (relative error up to
/// 0.5 / (255 s)), grazing lights, and the 8-bit shininess code on sharp highlights; they
/// are bounded by count, not size: see `LOSSY_OUTLIER_FRACTION`.
fn lossy_relative_bound() -> f64 {
    srgb8_half_step_relative(0.04)
}

/// Pixel-channels beyond `lossy_relative_bound` may be at most this fraction of the lit
/// ones (Sponza's textures have few texels darker than sRGB 0.04; a test that wrote
/// garbage to the G-buffer would fail nearly every pixel).
const LOSSY_OUTLIER_FRACTION: f64 = 0.01;

/// Channels darker than this fraction of the image's median lit channel are left out: an
/// absolute error there that no exposure showing the median could reveal becomes a large
/// relative one (f16 storage alone is 2^-11 of the value).
const DARK_FRACTION_OF_MEDIAN: f64 = 0.01;

/// Per-channel relative errors of `image` against `reference` over lit channels (above the
/// dark floor), sorted.
fn relative_errors(reference: &[[f32; 4]], image: &[[f32; 4]]) -> Vec<f64> {
    let mut lit: Vec<f64> = reference
        .iter()
        .flat_map(|t| t[..3].iter().map(|&v| f64::from(v)))
        .filter(|&v| v > 0.0)
        .collect();
    assert!(!lit.is_empty(), "the reference image is black");
    lit.sort_by(f64::total_cmp);
    let floor = lit[lit.len() / 2] * DARK_FRACTION_OF_MEDIAN;
    let mut errors: Vec<f64> = reference
        .iter()
        .zip(image)
        .flat_map(|(r, i)| (0..3).map(move |c| (f64::from(r[c]), f64::from(i[c]))))
        .filter(|&(r, _)| r > floor)
        .map(|(r, i)| (i - r).abs() / r)
        .collect();
    errors.sort_by(f64::total_cmp);
    errors
}

#[test]
fn compact_and_packed_stay_within_their_derived_error() {
    let (mut renderer, mut settings) = renderer("sponza", (160, 90));
    settings.light_count = 500;
    let bound = lossy_relative_bound();
    let cameras: Vec<(String, Camera)> = renderer.scene.presets.clone();
    for (name, camera) in cameras {
        settings.camera = camera;
        settings.pipeline = PipelineKind::Naive;
        let naive = render_hdr(&mut renderer, &settings);
        for layout in [GBufferLayout::Compact, GBufferLayout::Packed] {
            let image = render_hdr(
                &mut renderer,
                &deferred(&settings, layout, LightingPath::Compute),
            );
            let errors = relative_errors(&naive, &image);
            // Most of the frame is lit: a camera that saw nothing proves nothing.
            assert!(
                errors.len() > naive.len(),
                "sponza {name}: only {} lit channels of {} pixels",
                errors.len(),
                naive.len()
            );
            let outliers = errors.iter().filter(|&&e| e > bound).count();
            let p99 = errors[errors.len() * 99 / 100];
            let mean = errors.iter().sum::<f64>() / errors.len() as f64;
            println!(
                "sponza {name}, {layout:?}: relative error mean {mean:.2e}, p99 {p99:.2e}, max {:.2e}; {outliers} of {} lit channels above {bound:.3}",
                errors[errors.len() - 1],
                errors.len()
            );
            assert!(
                outliers as f64 <= LOSSY_OUTLIER_FRACTION * errors.len() as f64,
                "sponza {name}, {layout:?}: {outliers} of {} lit channels beyond the {bound:.3} relative error 8-bit sRGB albedo can cause (at most {LOSSY_OUTLIER_FRACTION} allowed)",
                errors.len()
            );
            // Half a step on average is a quarter step: the mean stays well inside.
            assert!(
                mean <= bound / 2.0,
                "sponza {name}, {layout:?}: mean relative error {mean:.2e} above half the bound"
            );
        }
    }
}

/// Every pass writes every pixel every frame: after a lit naive frame (naive draws every
/// pixel), a frame with no lights is black everywhere, on every pipeline and lighting path.
/// A pass that skipped pixels would leave the lit values there; comparisons against naive
/// cannot see that, since naive drew into the same target just before.
#[test]
fn every_pixel_is_written_every_frame() {
    let (mut renderer, mut settings) = renderer("cornell", (97, 61));
    settings.light_count = 64;
    settings.pipeline = PipelineKind::Naive;
    let variants = [
        (PipelineKind::Naive, LightingPath::Compute),
        (PipelineKind::ForwardPlus, LightingPath::Compute),
        (PipelineKind::Deferred, LightingPath::Fragment),
        (PipelineKind::Deferred, LightingPath::Compute),
    ];
    for (pipeline, path) in variants {
        let lit = render_hdr(&mut renderer, &settings);
        let lit_pixels = lit
            .iter()
            .filter(|t| t[..3].iter().any(|&v| v > 0.0))
            .count();
        assert_eq!(
            lit_pixels,
            lit.len(),
            "cornell is closed: naive lights every pixel"
        );
        let dark = render_hdr(
            &mut renderer,
            &FrameSettings {
                pipeline,
                lighting: path,
                light_count: 0,
                ..settings.clone()
            },
        );
        if let Some(i) = dark.iter().position(|t| t[..3].iter().any(|&v| v != 0.0)) {
            panic!(
                "{pipeline:?}/{path:?}: pixel ({}, {}) kept {:?} from the frame before",
                i % 97,
                i / 97,
                dark[i]
            );
        }
    }
}

#[test]
fn fragment_and_compute_lighting_agree() {
    let (mut renderer, mut settings) = renderer("cornell", (96, 64));
    settings.light_count = 128;
    for layout in GBufferLayout::ALL {
        let fragment = render_hdr(
            &mut renderer,
            &deferred(&settings, layout, LightingPath::Fragment),
        );
        manylights_tests::assert_lit(&format!("{layout:?} fragment"), &fragment, 0.5);
        let compute = render_hdr(
            &mut renderer,
            &deferred(&settings, layout, LightingPath::Compute),
        );
        assert_hdr_close(
            &format!("{layout:?} fragment vs compute"),
            &fragment,
            &compute,
            1e-5,
        );
    }
}

#[test]
fn gbuffer_and_cluster_debug_views_draw() {
    let (mut renderer, mut settings) = renderer("cornell", (96, 64));
    settings.light_count = 64;
    let mut images = Vec::new();
    for view in [
        DebugView::Albedo,
        DebugView::Normal,
        DebugView::Depth,
        DebugView::Position,
        DebugView::ClusterHeatmap { max_lights: 16.0 },
        DebugView::ZSlices,
    ] {
        let mut frame = deferred(&settings, GBufferLayout::Compact, LightingPath::Compute);
        frame.debug_view = view;
        renderer.render_frame(&frame).expect("debug view");
        let image = renderer.read_output().expect("image");
        let distinct: std::collections::HashSet<[u8; 4]> = image.pixels().map(|p| p.0).collect();
        assert!(
            distinct.len() > 4,
            "{view:?}: only {} colours",
            distinct.len()
        );
        images.push(image);
    }
    for i in 0..images.len() {
        for j in i + 1..images.len() {
            assert_ne!(
                images[i], images[j],
                "views {i} and {j} drew the same image"
            );
        }
    }
    // The normal view of the floor straight below is +Y: (0.5, 1.0, 0.5) before sRGB.
    let mut frame = deferred(&settings, GBufferLayout::Packed, LightingPath::Fragment);
    frame.debug_view = DebugView::Normal;
    frame.camera = Camera {
        position: Vec3::new(0.0, 2.0, 0.0),
        pitch: -std::f32::consts::FRAC_PI_2,
        ..frame.camera
    };
    renderer.render_frame(&frame).expect("normal view");
    let pixel = renderer.read_hdr().expect("hdr")[(32 * 96 + 48) as usize];
    assert!(
        (pixel[0] - 0.5).abs() < 1e-3
            && (pixel[1] - 1.0).abs() < 1e-3
            && (pixel[2] - 0.5).abs() < 1e-3,
        "{pixel:?}"
    );
}

#[test]
fn layouts_report_their_bytes_per_pixel() {
    let (renderer, _) = renderer("cornell", (8, 8));
    // Cornell has specular materials: the specular channel exists.
    assert_eq!(renderer.gbuffer_bytes_per_pixel(GBufferLayout::Full), 68);
    assert_eq!(renderer.gbuffer_bytes_per_pixel(GBufferLayout::Compact), 16);
    assert_eq!(renderer.gbuffer_bytes_per_pixel(GBufferLayout::Packed), 20);
    // Sponza's OBJ has Ks 0 everywhere: no specular channel.
    let obj = LoadedScene::load(
        manylights::assets_dir()
            .join("sponza/sponza.obj")
            .to_str()
            .expect("utf-8"),
    )
    .expect("obj");
    let renderer = Renderer::new(gpu(), obj).expect("renderer");
    assert_eq!(renderer.gbuffer_bytes_per_pixel(GBufferLayout::Full), 52);
    assert_eq!(renderer.gbuffer_bytes_per_pixel(GBufferLayout::Compact), 12);
}
