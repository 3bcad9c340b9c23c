//! glTF as people ship it, on the GPU (issue 31): emissive surfaces in every pipeline
//! against the f64 reference, and Sponza as gltfpack writes it (quantized, and
//! meshopt-compressed) rendering as the original does.

use glam::Vec3;
use manylights::lights::reference::{SurfacePoint, shade};
use manylights::lights::{Falloff, Light};
use manylights::{FrameSettings, GBufferLayout, LoadedScene, PipelineSettings, Renderer};
use manylights_scene::{ColorSpace, Texture};
use manylights_tests::{assert_hdr_close, assert_lit, clustered_variants, gpu, relative_errors};

const SIZE: (u32, u32) = (128, 96);

/// The cornell room with emission: the back wall's material glows a warm colour at
/// strength 3 (HDR: above 1), another material through a 2x2 texture.
fn emissive_cornell() -> LoadedScene {
    let mut loaded = LoadedScene::load("cornell").expect("cornell");
    let scene = &mut loaded.scene;
    scene.textures.push(Texture {
        source: "test checker".into(),
        width: 2,
        height: 2,
        color_space: ColorSpace::Srgb,
        rgba8: [
            [255, 0, 0, 255],
            [0, 255, 0, 255],
            [0, 0, 255, 255],
            [255, 255, 255, 255],
        ]
        .concat(),
    });
    let checker = scene.textures.len() - 1;
    scene.materials[0].emissive_factor = Vec3::new(1.0, 0.6, 0.3) * 3.0;
    let last = scene.materials.len() - 1;
    scene.materials[last.min(1)].emissive_factor = Vec3::splat(0.05);
    scene.materials[last.min(1)].emissive_texture = Some(checker);
    assert!(scene.features().emissive);
    loaded
}

/// Half-float spacing around `x` (the HDR target's storage).
fn f16_ulp(x: f64) -> f64 {
    let magnitude = x.abs().max(2f64.powi(-14));
    2f64.powi(magnitude.log2().floor() as i32 - 10)
}

/// Naive against the f64 reference (which adds the captured emission): the tolerance of
/// `naive.rs` (one half-float ulp of the reference plus 1e-5 relative for f32 shading);
/// then the emission must show: at least a tenth of the image is lit mostly by it.
#[test]
fn emission_matches_the_f64_reference_in_naive() {
    let loaded = emissive_cornell();
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = SIZE;
    settings.time = 1.5;
    settings.light_count = 8;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    for falloff in [Falloff::WindowedInverseSquare, Falloff::InverseSquare] {
        settings.pipeline = PipelineSettings::naive(falloff);
        renderer.render_frame(&settings).expect("frame");
        let hdr = renderer.read_hdr().expect("hdr");
        let lights: Vec<Light> = renderer.read_lights().expect("lights");
        let surface = renderer.capture_surface(&settings).expect("surface");
        let camera = settings.camera.position.as_dvec3();
        let mut emission_dominated = 0;
        for (i, gpu) in hdr.iter().enumerate() {
            if surface.position[i][3] != 1.0 {
                continue;
            }
            let point = SurfacePoint::from_capture(&surface, i);
            let reference = shade(&point, camera, &lights, falloff);
            if point.emission.element_sum() > 0.5 * reference.element_sum() {
                emission_dominated += 1;
            }
            for c in 0..3 {
                let (want, got) = (reference[c], f64::from(gpu[c]));
                assert!(
                    (got - want).abs() <= f16_ulp(want) + 1e-5 * want.abs(),
                    "{falloff:?}: pixel {i} channel {c}: GPU {got}, f64 reference {want}"
                );
            }
        }
        assert!(
            emission_dominated >= hdr.len() / 10,
            "{falloff:?}: only {emission_dominated} pixels are lit mostly by emission"
        );
    }
}

/// Forward+ and deferred (every layout, both lighting paths) against naive. Deferred stores
/// emission in an Rgba16Float target before adding it, so its bound is naive's one ulp plus
/// one more ulp (2^-10 relative) for that storage; Forward+ adds it in f32 like naive. Full
/// layout with lights; every layout without lights (emission alone: the lossy layouts'
/// 8-bit albedo then plays no part).
#[test]
fn emission_is_the_same_in_every_pipeline() {
    let loaded = emissive_cornell();
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.size = SIZE;
    settings.time = 1.5;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let emission_storage = 2f32.powi(-10);
    for light_count in [8, 0] {
        settings.light_count = light_count;
        settings.pipeline = PipelineSettings::naive(Falloff::default());
        renderer.render_frame(&settings).expect("naive");
        let naive = renderer.read_hdr().expect("hdr");
        assert_lit(&format!("naive, {light_count} lights"), &naive, 0.3);
        let layouts: &[GBufferLayout] = if light_count == 0 {
            &GBufferLayout::ALL
        } else {
            &[GBufferLayout::Full]
        };
        for &layout in layouts {
            for pipeline in clustered_variants(layout) {
                settings.pipeline = pipeline;
                renderer.render_frame(&settings).expect("frame");
                let image = renderer.read_hdr().expect("hdr");
                assert_hdr_close(
                    &format!("{light_count} lights: {pipeline:?}"),
                    &naive,
                    &image,
                    emission_storage + 1e-4,
                );
            }
        }
    }
}

/// Sponza as gltfpack writes it (`assets/sponza/sponza-quantized.glb`: 14-bit positions,
/// 8-bit normals, 16-bit UVs; `sponza-meshopt.glb`: the same, meshopt-compressed) renders
/// as the original in the same pipeline, on the same camera and lights.
///
/// The tolerance, from what quantization moves (not fitted):
/// - normals in 8 bits: each component within 1/254 of the original, the direction within
///   sqrt(3)/254 = 0.0068 rad, so n.l moves by at most 0.0068 (absolute): under 2^-6
///   relative wherever n.l >= 0.44;
/// - positions in 14 bits over 35 m: within 1.1 mm, so 1/d^2 moves by under 2^-8 relative
///   for lights further than 0.6 m, and a pixel whose centre lies within 1.1 mm of a
///   triangle's edge can see the other triangle;
/// - UVs in 16 bits: within 1/65535 of the UV range, a fraction of a texel.
///
/// So the median channel (lit at n.l of any kind) is held to 2^-6, and the channels beyond
/// 2^-6 (grazing light, silhouettes, texel edges) to a quarter of the lit ones: a renderer
/// that misread any attribute (a wrong scale, swapped normals, unnormalised UVs) changes
/// most pixels by far more.
#[test]
fn gltfpack_sponza_renders_as_the_original() {
    let original = LoadedScene::load("sponza").expect("sponza");
    let mut settings = FrameSettings::for_scene(&original);
    settings.size = SIZE;
    settings.time = 1.25;
    settings.light_count = 1000;
    settings.camera = original.preset("reference").unwrap_or(settings.camera);
    settings.pipeline =
        PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Compute);
    let render = |loaded: LoadedScene| {
        let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
        renderer.render_frame(&settings).expect("frame");
        renderer.read_hdr().expect("hdr")
    };
    let reference = render(original.clone());
    let lit = assert_lit("original sponza", &reference, 0.3);
    println!("original: {:.0}% of pixels lit", lit * 100.0);
    for file in ["sponza-quantized.glb", "sponza-meshopt.glb"] {
        let path = manylights::assets_dir().join("sponza").join(file);
        let packed = manylights_scene::load(&path).expect("packed sponza");
        // Sponza's cameras and light box, the packed file's geometry.
        let image = render(LoadedScene {
            scene: packed,
            ..original.clone()
        });
        let errors = relative_errors(&reference, &image);
        assert!(!errors.is_empty());
        let median = errors[errors.len() / 2];
        let beyond = errors.iter().filter(|&&e| e > 2f64.powi(-6)).count();
        println!(
            "{file}: median relative error {median:.2e}, {beyond} of {} lit channels beyond 2^-6, 99th percentile {:.2e}",
            errors.len(),
            errors[errors.len() * 99 / 100]
        );
        assert!(median <= 2f64.powi(-6), "{file}: median {median}");
        assert!(
            beyond * 4 <= errors.len(),
            "{file}: {beyond} of {} channels beyond 2^-6",
            errors.len()
        );
    }
}
