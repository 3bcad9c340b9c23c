//! Clustered deferred on the GPU (lavapipe in CI): the lossless `full` layout matches naive
//! within Forward+'s tolerance on both lighting paths; `compact` and `packed` stay within
//! the error their encodings can cause on Sponza; fragment and compute lighting agree; the
//! tile-shared light loop gives the per-pixel loop's image; the G-buffer debug views draw;
//! the visibility buffer rebuilds the G-buffer pass's surfaces.

use glam::Vec3;
use manylights::{
    Camera, DeferredSettings, DeferredView, FrameSettings, GBufferChannel, GBufferLayout,
    LightingPath, LoadedScene, PipelineSettings, Renderer,
};
use manylights_tests::{assert_hdr_close, clustering_mut, gpu};

fn renderer(scene: &str, size: (u32, u32)) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load(scene).expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = size;
    settings.lights.time = 1.25;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

fn render_hdr(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f32; 4]> {
    renderer.render_frame(settings).expect("frame");
    renderer.read_hdr().expect("hdr")
}

/// `settings` on deferred in `layout` and on `path`, keeping the light lists' settings
/// where `settings` has them.
fn deferred(settings: &FrameSettings, layout: GBufferLayout, path: LightingPath) -> FrameSettings {
    let mut pipeline = PipelineSettings::deferred(layout, path);
    if let Some(lists) = settings.pipeline.clustering() {
        pipeline = pipeline.with_clustering(*lists);
    }
    FrameSettings {
        pipeline,
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
        settings.lights.radius = manylights::lights::RadiusMode::Fixed(6.0);
        let cameras: Vec<Camera> = manylights_tests::interior_cameras(renderer.scene())
            .into_iter()
            .map(|(_, c)| c)
            .collect();
        for camera in cameras {
            for count in [16, 300] {
                settings.view.camera = camera;
                settings.lights.count = count;
                settings.pipeline = PipelineSettings::naive(Default::default());
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

#[test]
fn compact_and_packed_stay_within_their_derived_error() {
    let (mut renderer, mut settings) = renderer("sponza", (160, 90));
    settings.lights.count = 500;
    let bound = manylights_tests::lossy_relative_bound();
    let cameras: Vec<(String, Camera)> = manylights_tests::interior_cameras(renderer.scene());
    for (name, camera) in cameras {
        settings.view.camera = camera;
        settings.pipeline = PipelineSettings::naive(Default::default());
        let naive = render_hdr(&mut renderer, &settings);
        for layout in [
            GBufferLayout::Compact,
            GBufferLayout::Packed,
            GBufferLayout::Visibility,
        ] {
            let image = render_hdr(
                &mut renderer,
                &deferred(&settings, layout, LightingPath::Compute),
            );
            let errors = manylights_tests::relative_errors(&naive, &image);
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
                outliers as f64 <= manylights_tests::LOSSY_OUTLIER_FRACTION * errors.len() as f64,
                "sponza {name}, {layout:?}: {outliers} of {} lit channels beyond the {bound:.3} relative error 8-bit sRGB albedo can cause (at most {} allowed)",
                errors.len(),
                manylights_tests::LOSSY_OUTLIER_FRACTION
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
    settings.lights.count = 64;
    settings.pipeline = PipelineSettings::naive(Default::default());
    let naive = settings.pipeline;
    for pipeline in
        std::iter::once(naive).chain(manylights_tests::clustered_variants(GBufferLayout::Compact))
    {
        let lit = render_hdr(&mut renderer, &settings);
        // Cornell is closed: naive lights every pixel.
        manylights_tests::assert_lit("cornell, naive", &lit, 1.0);
        let dark = render_hdr(
            &mut renderer,
            &FrameSettings {
                pipeline,
                lights: manylights::FrameLights {
                    count: 0,
                    ..settings.lights.clone()
                },
                ..settings.clone()
            },
        );
        if let Some(i) = dark.iter().position(|t| t[..3].iter().any(|&v| v != 0.0)) {
            panic!(
                "{}: pixel ({}, {}) kept {:?} from the frame before",
                pipeline.describe(),
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
    settings.lights.count = 128;
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
    settings.lights.count = 64;
    let mut images = Vec::new();
    for view in ["albedo", "normal", "depth", "position", "heatmap", "slices"] {
        let mut frame = deferred(&settings, GBufferLayout::Compact, LightingPath::Compute);
        frame.pipeline = frame
            .pipeline
            .with_debug_view_named(view)
            .expect("a deferred view")
            .with_heatmap_max(16.0);
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
    frame.pipeline = frame
        .pipeline
        .with_debug_view_named("normal")
        .expect("a deferred view");
    frame.view.camera = Camera {
        position: Vec3::new(0.0, 2.0, 0.0),
        pitch: -std::f32::consts::FRAC_PI_2,
        ..frame.view.camera
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

/// The tiles path (a tile's pixels share each cluster's lights through workgroup memory,
/// culled to the box around their surfaces) sums the same terms as the per-pixel compute
/// loop in the same order: a light is dropped only where its term is exactly zero. So the
/// images agree to one half-float ulp: each f32 sum of positive terms may differ by the
/// compiler's contraction choices, a few f32 ulps per term, which for these light counts
/// (at most a few hundred terms, under 2^-13 relative) is less than the 2^-11 of the
/// Rgba16Float target, so at most one rounding step there. Checked with spots, both far
/// fields and clusters whose tiles are not multiples of the 8x8 compute tile (a tile of
/// pixels then spans several clusters across as well as in depth), at a size whose edge
/// tiles are partial.
#[test]
fn the_tile_shared_loop_renders_the_per_pixel_loops_image() {
    use manylights::cluster::{FarField, FarFieldMethod, TileSpec};
    use manylights::lights::{Falloff, SpotSettings};
    let (mut renderer, mut settings) = renderer("sponza", (150, 90));
    settings.lights.count = 400;
    settings.lights.radius = manylights::lights::RadiusMode::Fixed(3.0);
    let cameras: Vec<(String, Camera)> = manylights_tests::interior_cameras(renderer.scene());
    let far_fields = [
        None,
        Some(FarField::with_tolerance(FarFieldMethod::Tree, 0.3)),
        Some(FarField {
            seed: 1,
            ..FarField::with_tolerance(FarFieldMethod::Stochastic, 0.3)
        }),
    ];
    let mut identical = 0usize;
    let mut compared = 0usize;
    for (name, camera) in cameras {
        settings.view.camera = camera;
        // Half the lights spots: both kinds share each list (a frame of points alone only
        // takes the branch this one takes for its points).
        {
            let spots = 0.5;
            settings.lights.spots = SpotSettings {
                fraction: spots,
                ..SpotSettings::default()
            };
            for tiles in [TileSpec::PixelSize(16), TileSpec::Count { x: 7, y: 5 }] {
                clustering_mut(&mut settings).grid.tiles = tiles;
                for far_field in far_fields {
                    let falloff = if far_field.is_some() {
                        Falloff::InverseSquare
                    } else {
                        Falloff::WindowedInverseSquare
                    };
                    let label = format!("sponza {name}, spots {spots}, {tiles:?}, {far_field:?}");
                    let mut frame =
                        deferred(&settings, GBufferLayout::Compact, LightingPath::Compute);
                    frame.set_falloff(falloff, far_field).expect("settings");
                    let per_pixel = render_hdr(&mut renderer, &frame);
                    manylights_tests::assert_lit(&label, &per_pixel, 0.2);
                    frame = deferred(&frame, GBufferLayout::Compact, LightingPath::Tiles);
                    let tiled = render_hdr(&mut renderer, &frame);
                    assert_hdr_close(&label, &per_pixel, &tiled, 0.0);
                    identical += per_pixel
                        .iter()
                        .zip(&tiled)
                        .filter(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
                        .count();
                    compared += per_pixel.len();
                }
            }
        }
    }
    println!("tiles against per-pixel: {identical} of {compared} pixels bit-identical");
}

/// One G-buffer channel as the lighting pass decodes it.
fn channel(
    renderer: &mut Renderer,
    settings: &FrameSettings,
    layout: GBufferLayout,
    channel: GBufferChannel,
) -> Vec<[f32; 4]> {
    let pipeline = PipelineSettings::Deferred(DeferredSettings {
        layout,
        lighting: LightingPath::Compute,
        debug_view: Some(DeferredView::GBuffer(channel)),
        ..Default::default()
    });
    render_hdr(
        renderer,
        &FrameSettings {
            pipeline,
            ..settings.clone()
        },
    )
}

/// The largest difference between two images' colour channels at each pixel.
fn channel_differences(a: &[[f32; 4]], b: &[[f32; 4]]) -> Vec<f32> {
    a.iter()
        .zip(b)
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max))
        .collect()
}

/// `loaded` with every triangle's winding reversed and every material double-sided: the
/// same image, but every face is a back face.
fn inside_out(mut loaded: LoadedScene) -> LoadedScene {
    for mesh in &mut loaded.scene.meshes {
        for triangle in mesh.indices.chunks_exact_mut(3) {
            triangle.swap(1, 2);
        }
    }
    for material in &mut loaded.scene.materials {
        material.double_sided = true;
    }
    loaded
}

/// One half-float ulp in [0.5, 1): the debug views' Rgba16Float target's step where the
/// normal view (0.5 + 0.5 n) puts most values.
const HALF_ULP_BELOW_ONE: f32 = 1.0 / 2048.0;

/// The visibility buffer rebuilds the surfaces the G-buffer pass writes, checked channel by
/// channel against `packed` (which its resolve writes, so encodings cancel):
/// - depth: the raster transforms the same f32 vertices with the same `scene_vertex`, and
///   alpha-masked materials discard on the same interpolated UV, so coverage and depth are
///   the same. A compiler may contract the transform's multiply-adds differently in the two
///   programs, moving a vertex by an ulp: only a pixel whose centre lies within that of an
///   edge could change, a handful in a frame; at most 0.1% of pixels are allowed, while
///   ignoring the masks changes several percent of Sponza's views;
/// - normal: the perspective-correct barycentrics are the rasteriser's interpolation up to
///   f32 rounding (relative 1e-6), far below the 16-bit octahedral code (3e-5), so the
///   decoded normals differ by at most a rounding step of the view's half floats, 2 ulps;
/// - albedo: the mip level comes from analytic gradients taken as a 2x2 quad takes them,
///   coarsely (the quad's top row and left column, as llvmpipe does: there, measured, at
///   most 6 of Sponza's 14,400 pixels are more than an 8-bit step apart). Vulkan lets a
///   device difference each row and column instead: that is a fraction of a mip level
///   apart where the UV's rate changes across the quad, moving a trilinear sample by a
///   fraction of the difference between adjacent mips; on average under one 8-bit step
///   (1/255), the bound asserted. Lit images stay within the lossy-layout bound against
///   naive (`compact_and_packed_stay_within_their_derived_error`).
///
/// Both rasters: the indexed one with the primitive index (the adapter's device, where it
/// has the feature) and the one that fetches its vertices (a WebGPU-core device).
#[test]
fn the_visibility_buffer_rebuilds_the_gbuffer_passes_surfaces() {
    use manylights::gpu::{AdapterRequest, DeviceLimits, GpuContext, wgpu};
    let devices = [DeviceLimits::Adapter, DeviceLimits::WebGpuDefaults];
    // Sponza: textures, normal maps, alpha masks, double-sided materials; Cornell: flat;
    // Cornell inside out: every face seen from behind, so double-sided materials must turn
    // their normals to the viewer.
    for (limits, scene) in devices
        .into_iter()
        .flat_map(|limits| ["sponza", "cornell", "cornell inside out"].map(|scene| (limits, scene)))
    {
        let request = AdapterRequest {
            limits,
            ..AdapterRequest::from_env()
        };
        let context = GpuContext::new_headless_with(&request)
            .unwrap_or_else(|e| manylights_tests::fail_without_gpu(e));
        let indexed = context
            .device
            .features()
            .contains(wgpu::Features::PRIMITIVE_INDEX);
        if limits == DeviceLimits::WebGpuDefaults {
            assert!(
                !indexed,
                "a WebGPU-core device must not have the primitive index"
            );
        }
        let raster = if indexed { "indexed" } else { "pulled" };
        let loaded = match scene {
            "cornell inside out" => inside_out(LoadedScene::load("cornell").expect("cornell")),
            _ => LoadedScene::load(scene).expect("scene"),
        };
        let mut settings = FrameSettings::for_scene(&loaded);
        settings.view.size = (160, 90);
        settings.lights.time = 1.25;
        let mut renderer = Renderer::new(context, loaded).expect("renderer");
        let scene = format!("{scene} ({raster} raster)");
        let cameras: Vec<(String, Camera)> = manylights_tests::interior_cameras(renderer.scene());
        for (name, camera) in cameras {
            settings.view.camera = camera;
            let views = [
                GBufferChannel::Depth,
                GBufferChannel::Normal,
                GBufferChannel::Albedo,
            ]
            .map(|view| {
                let packed = channel(&mut renderer, &settings, GBufferLayout::Packed, view);
                let visibility = channel(&mut renderer, &settings, GBufferLayout::Visibility, view);
                (packed, visibility)
            });
            let [depth, normal, albedo] = &views;
            manylights_tests::assert_lit(&format!("{scene} {name} albedo"), &albedo.0, 0.5);
            let pixels = depth.0.len();
            let moved = channel_differences(&depth.0, &depth.1)
                .iter()
                .filter(|&&d| d > 0.0)
                .count();
            assert!(
                moved * 1000 <= pixels,
                "{scene} {name}: the visibility buffer's depth differs at {moved} of {pixels} pixels"
            );
            let normal_worst = channel_differences(&normal.0, &normal.1)
                .into_iter()
                .fold(0.0, f32::max);
            assert!(
                normal_worst <= 2.0 * HALF_ULP_BELOW_ONE,
                "{scene} {name}: normals differ by {normal_worst:.2e}, above 2 half-float ulps"
            );
            let albedo_differences = channel_differences(&albedo.0, &albedo.1);
            let albedo_mean = albedo_differences
                .iter()
                .map(|&d| f64::from(d))
                .sum::<f64>()
                / pixels as f64;
            println!(
                "{scene} {name}: depth moved at {moved} pixels, normals within {normal_worst:.2e}, albedo mean difference {albedo_mean:.2e}"
            );
            assert!(
                albedo_mean <= 1.0 / 255.0,
                "{scene} {name}: albedo differs by {albedo_mean:.2e} on average, above one 8-bit step"
            );
        }
    }
}

/// Glossy and rough metals and dielectrics under PBR (`metal_and_dielectric_cornell`:
/// roughness 0.05 to 1), point and spot lights: every clustered loop (Forward+ and
/// deferred's fragment, compute and tile paths) in the lossless layout equals naive to
/// Forward+'s tolerance, and in the lossy layouts (compact, packed, and the visibility
/// buffer's resolve into packed) every lit channel stays within a bound derived at that
/// pixel from what the layout quantizes (`quantization_bound`). A glossy highlight is
/// where a wrong roughness or normal code shows: D's peak at roughness 0.05 moves by 12%
/// per half 8-bit step of roughness.
#[test]
fn pbr_metals_and_dielectrics_match_naive_in_every_layout() {
    let loaded = manylights_tests::metal_and_dielectric_cornell();
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (96, 64);
    settings.lights.time = 1.25;
    settings.lights.count = 64;
    settings.lights.spots.fraction = 0.5;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    settings.pipeline = PipelineSettings::naive(Default::default());
    let naive = render_hdr(&mut renderer, &settings);
    manylights_tests::assert_lit("cornell PBR", &naive, 0.5);
    let bounds = quantization_bound(&mut renderer, &settings);

    let floor = manylights_tests::dark_floor(&naive).expect("a lit image");
    for layout in GBufferLayout::ALL {
        for pipeline in manylights_tests::clustered_variants(layout) {
            if layout != GBufferLayout::Full && !matches!(pipeline, PipelineSettings::Deferred(_)) {
                continue; // Forward+ has no layout: compared once, with `full`.
            }
            let label = format!("cornell PBR {pipeline:?}");
            let image = render_hdr(
                &mut renderer,
                &FrameSettings {
                    pipeline,
                    ..settings.clone()
                },
            );
            if layout == GBufferLayout::Full {
                let worst = assert_hdr_close(&label, &naive, &image, FULL_LAYOUT_RELATIVE);
                println!("{label}: largest relative difference {worst:.2e}");
                continue;
            }
            let mut worst_share: f64 = 0.0;
            for (i, (want, got)) in naive.iter().zip(&image).enumerate() {
                for c in 0..3 {
                    let (want, got) = (f64::from(want[c]), f64::from(got[c]));
                    if want <= floor {
                        continue;
                    }
                    let allowed = bounds[i][c] * want + manylights_tests::f16_ulp(want);
                    worst_share = worst_share.max((got - want).abs() / allowed);
                    assert!(
                        (got - want).abs() <= allowed,
                        "{label}: pixel ({}, {}) channel {c}: naive {want}, {got}; the layout's quantization allows {allowed:.3e} ({:.2e} relative)",
                        i % 96,
                        i / 96,
                        bounds[i][c]
                    );
                }
            }
            println!("{label}: the largest difference is {worst_share:.2} of its pixel's bound");
        }
    }
}

/// Per pixel and channel, the relative change of the f64 twin's radiance that the lossy
/// layouts' codes can cause, from each quantized quantity moved alone by its largest
/// coding error, both ways, summed (first order), with a quarter more for the products of
/// changes the sum leaves out:
/// - the lobe's 8-bit code: roughness by half a step, 0.5 / 255;
/// - albedo and F0 in 8-bit sRGB: each channel by a whole step at its value (twice
///   `srgb8_half_step_relative`): half a step from rounding to the nearest code, and as
///   much again for the driver's sRGB conversion, which need not be exact (lavapipe
///   decodes sRGB 0.2 as 0.2023, 0.3 of a step above the nearest code's 0.2016);
/// - the normal in 2 x 16-bit octahedral coordinates: tilted by 1e-4 rad (the codec's bound,
///   `deferred::codecs`' tests) about two tangent axes.
///
/// Position from 32-bit depth moves 1/d^2 by under 1e-6 and is left out.
fn quantization_bound(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f64; 3]> {
    use glam::DVec3;
    use manylights::lights::reference::{SurfacePoint, shade};
    let lights = renderer.read_lights().expect("lights");
    let surface = renderer.capture_surface(settings).expect("surface");
    let camera = settings.view.camera.position.as_dvec3();
    let falloff = settings.pipeline.falloff();
    let srgb_step = |linear: DVec3| {
        linear.map(|c| {
            let srgb = if c <= 0.0031308 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            2.0 * manylights_tests::srgb8_half_step_relative(srgb)
        })
    };
    (0..surface.position.len())
        .map(|i| {
            let point = SurfacePoint::from_capture(&surface, i);
            let radiance = shade(&point, camera, &lights, falloff);
            let tangent = point.normal.any_orthonormal_vector();
            let bitangent = point.normal.cross(tangent);
            let mut moved = Vec::new();
            for sign in [-1.0, 1.0] {
                let half_step = 0.5 / 255.0;
                moved.push(SurfacePoint {
                    lobe: (point.lobe + sign * half_step).clamp(0.0, 1.0),
                    ..point
                });
                moved.push(SurfacePoint {
                    albedo: point.albedo * (DVec3::ONE + sign * srgb_step(point.albedo)),
                    ..point
                });
                moved.push(SurfacePoint {
                    specular: point.specular * (DVec3::ONE + sign * srgb_step(point.specular)),
                    ..point
                });
                for axis in [tangent, bitangent] {
                    moved.push(SurfacePoint {
                        normal: (point.normal + sign * 1e-4 * axis).normalize(),
                        ..point
                    });
                }
            }
            // Each quantity's larger change of its two (moved come in [-, +] halves).
            let changes: Vec<DVec3> = moved
                .iter()
                .map(|m| (shade(m, camera, &lights, falloff) - radiance).abs())
                .collect();
            let (minus, plus) = changes.split_at(changes.len() / 2);
            let total = minus
                .iter()
                .zip(plus)
                .fold(DVec3::ZERO, |sum, (a, b)| sum + a.max(*b));
            let relative = 1.25 * total / radiance.max(DVec3::splat(1e-30));

            relative.to_array()
        })
        .collect()
}
