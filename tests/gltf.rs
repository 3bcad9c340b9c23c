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

/// Naive against the f64 reference (which adds the captured emission): the tolerance of
/// `naive.rs` (one half-float ulp of the reference plus 1e-5 relative for f32 shading);
/// then the emission must show: at least a tenth of the image is lit mostly by it.
#[test]
fn emission_matches_the_f64_reference_in_naive() {
    let loaded = emissive_cornell();
    let mut settings = FrameSettings::for_scene(&loaded);
    // The emission as drawn: what the emissive surfaces light is tests/area_lights.rs's.
    settings.lights.emissive = false;
    settings.view.size = SIZE;
    settings.lights.time = 1.5;
    settings.lights.count = 8;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    for falloff in [Falloff::WindowedInverseSquare, Falloff::InverseSquare] {
        settings.pipeline = PipelineSettings::naive(falloff);
        renderer.render_frame(&settings).expect("frame");
        let hdr = renderer.read_hdr().expect("hdr");
        let lights: Vec<Light> = renderer.read_lights().expect("lights");
        let surface = renderer.capture_surface(&settings).expect("surface");
        let camera = settings.view.camera.position.as_dvec3();
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
                    (got - want).abs() <= manylights_tests::f16_ulp(want) + 1e-5 * want.abs(),
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
    // The emission as drawn: what the emissive surfaces light is tests/area_lights.rs's.
    settings.lights.emissive = false;
    settings.view.size = SIZE;
    settings.lights.time = 1.5;
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let emission_storage = 2f32.powi(-10);
    for light_count in [8, 0] {
        settings.lights.count = light_count;
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
    settings.view.size = SIZE;
    settings.lights.time = 1.25;
    settings.lights.count = 1000;
    settings.view.camera = original.preset("reference").unwrap_or(settings.view.camera);
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

/// A coverage mask: which pixels an image's subject covers.
struct Mask {
    width: usize,
    covered: Vec<bool>,
}

impl Mask {
    /// A reference screenshot's subject: the pixels whose colour differs from the
    /// background (the median of the border pixels) by more than `BACKGROUND_MARGIN` in
    /// some channel. Only rows from `first_row` (a fraction of the height) on are kept.
    fn from_screenshot(image: &image::RgbImage, first_row: f64) -> Self {
        const BACKGROUND_MARGIN: i32 = 32;
        let (width, height) = (image.width() as usize, image.height() as usize);
        let pixel = |x: usize, y: usize| image.get_pixel(x as u32, y as u32).0;
        let mut border: Vec<[u8; 3]> = (0..width)
            .flat_map(|x| [pixel(x, 0), pixel(x, height - 1)])
            .chain((0..height).flat_map(|y| [pixel(0, y), pixel(width - 1, y)]))
            .collect();
        let background: [i32; 3] = std::array::from_fn(|c| {
            border.sort_by_key(|p| p[c]);
            i32::from(border[border.len() / 2][c])
        });
        let distance = |p: [u8; 3]| {
            (0..3)
                .map(|c| (i32::from(p[c]) - background[c]).abs())
                .max()
                .unwrap_or(0)
        };
        // The margin means something only on a plain background.
        let noisy = border
            .iter()
            .filter(|&&p| distance(p) > BACKGROUND_MARGIN / 4)
            .count();
        assert!(
            noisy * 100 <= border.len(),
            "screenshot background is not plain ({noisy} of {} border pixels differ)",
            border.len()
        );
        let first = (first_row * height as f64) as usize;
        let covered = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| y >= first && distance(pixel(x, y)) > BACKGROUND_MARGIN)
            .collect();
        Self { width, covered }
    }

    /// Pixel-edge bounds of the covered pixels: (x0, y0, x1, y1), exclusive ends.
    fn bounds(&self) -> (usize, usize, usize, usize) {
        let mut bounds = (usize::MAX, usize::MAX, 0, 0);
        for (i, _) in self.covered.iter().enumerate().filter(|(_, c)| **c) {
            let (x, y) = (i % self.width, i / self.width);
            bounds = (
                bounds.0.min(x),
                bounds.1.min(y),
                bounds.2.max(x + 1),
                bounds.3.max(y + 1),
            );
        }
        assert!(bounds.0 < bounds.2, "the mask covers nothing");
        bounds
    }

    /// The mask over its own bounds, resampled (nearest) to `columns` x `rows` cells:
    /// framing (where the subject is and how large) taken out.
    fn normalized(&self, columns: usize, rows: usize) -> Vec<bool> {
        let (x0, y0, x1, y1) = self.bounds();
        let (w, h) = ((x1 - x0) as f64, (y1 - y0) as f64);
        (0..rows)
            .flat_map(|r| (0..columns).map(move |c| (c, r)))
            .map(|(c, r)| {
                let x = x0 + ((c as f64 + 0.5) / columns as f64 * w) as usize;
                let y = y0 + ((r as f64 + 0.5) / rows as f64 * h) as usize;
                self.covered[y * self.width + x]
            })
            .collect()
    }

    /// The larger side of the bounds, in pixels.
    fn larger_side(&self) -> f64 {
        let (x0, y0, x1, y1) = self.bounds();
        (x1 - x0).max(y1 - y0) as f64
    }
}

/// Our coverage of a model, looked at along -Z (the sample screenshots' view of these flat
/// models) with an orthographic camera fitted to its bounds, from the surface capture;
/// with the model's triangle count.
fn rendered_coverage(path: &std::path::Path) -> (Mask, usize) {
    use manylights::{Camera, Projection};
    let loaded = LoadedScene::load(path.to_str().expect("path")).expect("sample model loads");
    let bounds = loaded.scene.bounds();
    let (size, center) = (bounds.size(), bounds.center());
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let height = size.y.max(size.x / aspect) * 1.1;
    let camera = Camera {
        projection: Projection::Orthographic { height },
        ..Camera::look_at(
            center + Vec3::Z * (size.z + height),
            center,
            45.0,
            0.01 * height,
            2.0 * (size.z + height),
        )
    };
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = SIZE;
    settings.view.camera = camera;
    settings.lights.count = 0;
    let triangles = loaded.scene.triangle_count();
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    let surface = renderer.capture_surface(&settings).expect("surface");
    let covered = surface.position.iter().map(|p| p[3] == 1.0).collect();
    let mask = Mask {
        width: SIZE.0 as usize,
        covered,
    };
    (mask, triangles)
}

/// Geometry and coverage against the glTF-Sample-Assets reference screenshots (their
/// colours are PBR-shaded; only the silhouette is compared until PBR lands). Both masks
/// are cropped to their bounds and resampled to one grid, which takes out the framing the
/// screenshot's unrecorded camera chose; these models are flat and face the camera, so
/// the rest is a similarity.
///
/// Tolerance, derived: an edge may move by one pixel of the screenshot (its antialiasing
/// against the threshold) and one of ours (rasterization), and each crop edge by as much
/// again. A normalized position u = (x - x0) / (x1 - x0) then moves by at most
/// |dx| + (1 - u)|dx0| + u|dx1| = 2 pixels of each image, plus one cell for the nearest
/// resampling. A differing cell farther than that from our
/// silhouette's boundary is a geometry error (the sparse peaks missing, a morph weight not
/// applied, a mesh or strip triangle lost).
#[test]
fn sample_models_cover_what_their_reference_screenshots_show() {
    const CELLS: usize = 64;
    let samples = manylights::assets_dir().join("gltf-samples");
    // (model, first screenshot row compared, what the model exercises). MeshPrimitiveModes'
    // top rows are its POINTS and LINES meshes, which manylights does not draw: its lines
    // end at row 79 of 128 and its triangles start at row 91. SimpleMorph
    // is not here: its screenshot shows a frame of its animation, not the default weights.
    let models = [
        ("SimpleSparseAccessor", 0.0, "sparse accessor substitution"),
        ("SimpleMeshes", 0.0, "one mesh on two nodes"),
        (
            "MeshPrimitiveModes",
            85.0 / 128.0,
            "triangle strips and fans",
        ),
    ];
    for (model, first_row, what) in models {
        let folder = samples.join(model);
        let (ours, triangles) = rendered_coverage(&folder.join(format!("{model}.gltf")));
        let screenshot = image::open(folder.join("screenshot.png"))
            .expect("screenshot")
            .to_rgb8();
        let theirs = Mask::from_screenshot(&screenshot, first_row);
        let (x0, y0, x1, y1) = theirs.bounds();
        let aspect = (x1 - x0) as f64 / (y1 - y0) as f64;
        let (columns, rows) = if aspect >= 1.0 {
            (CELLS, ((CELLS as f64 / aspect).round() as usize).max(1))
        } else {
            (((CELLS as f64 * aspect).round() as usize).max(1), CELLS)
        };
        let cells_per_pixel = |mask: &Mask| CELLS as f64 / mask.larger_side();
        let reach = (2.0 * (cells_per_pixel(&theirs) + cells_per_pixel(&ours))).ceil() as i64 + 1;
        let (a, b) = (
            ours.normalized(columns, rows),
            theirs.normalized(columns, rows),
        );
        // Outside the crop is uncovered: the crop's sides are silhouette edges too.
        let at = |grid: &[bool], c: i64, r: i64| {
            let inside = (0..columns as i64).contains(&c) && (0..rows as i64).contains(&r);
            inside && grid[r as usize * columns + c as usize]
        };
        let mut differing = 0;
        let mut far = Vec::new();
        for r in 0..rows as i64 {
            for c in 0..columns as i64 {
                if at(&a, c, r) == at(&b, c, r) {
                    continue;
                }
                differing += 1;
                let near_our_edge = (-reach..=reach)
                    .any(|dr| (-reach..=reach).any(|dc| at(&a, c + dc, r + dr) != at(&a, c, r)));
                if !near_our_edge {
                    far.push((c, r));
                }
            }
        }
        let covered = a.iter().filter(|&&c| c).count();
        println!(
            "{model} ({what}): {} triangles, {columns}x{rows} cells, {covered} covered, {differing} differ, {} beyond {reach} cells of the edge",
            triangles,
            far.len()
        );
        let mut picture = image::RgbImage::new(columns as u32, rows as u32);
        for (i, (&ours, &theirs)) in a.iter().zip(&b).enumerate() {
            let colour = [255 * u8::from(ours), 255 * u8::from(theirs), 0];
            picture.put_pixel(
                (i % columns) as u32,
                (i / columns) as u32,
                image::Rgb(colour),
            );
        }
        let _ = picture.save(manylights_tests::output_dir().join(format!("coverage_{model}.png")));
        assert!(
            covered * 10 >= columns * rows,
            "{model}: our render covers under a tenth of its bounds"
        );
        assert!(
            far.is_empty(),
            "{model} ({what}): {} cells differ from the reference screenshot farther than {reach} cells from the silhouette's edge, e.g. {:?} (red: ours only, green: screenshot only, in target/test-output/coverage_{model}.png)",
            far.len(),
            &far[..far.len().min(5)]
        );
    }
}
