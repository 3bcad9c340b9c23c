//! Helpers shared by the GPU tests: a context that fails loudly (with the command that
//! installs lavapipe) when no adapter exists, camera rays, and a CPU ray caster that
//! computes what a pixel must show.

pub mod synthetic;

use glam::{Mat4, Vec2, Vec3};
use manylights_gpu::GpuContext;
use manylights_scene::{AlphaMode, Scene};

/// The GPU for tests. There is no skipping: without an adapter the test fails and says
/// how to install one.
pub fn gpu() -> GpuContext {
    GpuContext::new_headless().unwrap_or_else(|error| fail_without_gpu(error))
}

/// Fails a GPU test whose device could not be made, saying how to install lavapipe.
pub fn fail_without_gpu(error: impl std::fmt::Display) -> ! {
    panic!(
        "{error:#}\nGPU tests run on any Vulkan driver; on a machine without a GPU install Mesa's \
         lavapipe: `sudo apt-get install mesa-vulkan-drivers libvulkan1` (or run `cargo xtask test` \
         as root, which installs it)"
    )
}

/// A pinhole camera for tests (right-handed, depth 0..1 like wgpu).
#[derive(Debug, Clone, Copy)]
pub struct TestCamera {
    pub position: Vec3,
    pub target: Vec3,
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
}

impl TestCamera {
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.position, self.target, Vec3::Y)
    }

    pub fn proj(&self, size: (u32, u32)) -> Mat4 {
        glam::camera::rh::proj::directx::perspective(
            self.fov_y,
            size.0 as f32 / size.1 as f32,
            self.near,
            self.far,
        )
    }

    /// World-space direction through the centre of pixel (x, y) (y down).
    pub fn ray(&self, size: (u32, u32), x: u32, y: u32) -> Vec3 {
        let ndc = Vec2::new(
            (x as f32 + 0.5) / size.0 as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / size.1 as f32 * 2.0,
        );
        let tan = (self.fov_y / 2.0).tan();
        let aspect = size.0 as f32 / size.1 as f32;
        let view_dir = Vec3::new(ndc.x * tan * aspect, ndc.y * tan, -1.0);
        self.view()
            .inverse()
            .transform_vector3(view_dir)
            .normalize()
    }
}

/// What a ray hits first: material, uv and distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub material: usize,
    pub uv: Vec2,
    pub distance: f32,
}

/// Closest hit of a ray with the scene's triangles (Moller-Trumbore), honouring back-face
/// culling of single-sided materials and alpha masks (nearest texel).
pub fn cast(scene: &Scene, origin: Vec3, direction: Vec3) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for instance in &scene.instances {
        let mesh = &scene.meshes[instance.mesh];
        let material = &scene.materials[mesh.material];
        for triangle in mesh.indices.chunks_exact(3) {
            let [i0, i1, i2] = [triangle[0], triangle[1], triangle[2]].map(|i| i as usize);
            let [a, b, c] =
                [i0, i1, i2].map(|i| instance.transform.transform_point3(mesh.positions[i]));
            let (e1, e2) = (b - a, c - a);
            let p = direction.cross(e2);
            let det = e1.dot(p);
            // det > 0: counter-clockwise seen from the ray, i.e. front face.
            if det.abs() < 1e-12 || (det < 0.0 && !material.double_sided) {
                continue;
            }
            let s = origin - a;
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = direction.dot(q) / det;
            let t = e2.dot(q) / det;
            if u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 1e-4 {
                continue;
            }
            if best.is_some_and(|hit| hit.distance <= t) {
                continue;
            }
            let uv = mesh.uvs[i0] * (1.0 - u - v) + mesh.uvs[i1] * u + mesh.uvs[i2] * v;
            if let AlphaMode::Mask { cutoff } = material.alpha_mode {
                let alpha = material.base_color_factor.w
                    * material
                        .base_color_texture
                        .map(|t| sample_nearest(&scene.textures[t], uv)[3] as f32 / 255.0)
                        .unwrap_or(1.0);
                if alpha < cutoff {
                    continue;
                }
            }
            best = Some(Hit {
                material: mesh.material,
                uv,
                distance: t,
            });
        }
    }
    best
}

/// Nearest texel with repeat addressing.
pub fn sample_nearest(texture: &manylights_scene::Texture, uv: Vec2) -> [u8; 4] {
    let x = ((uv.x.rem_euclid(1.0) * texture.width as f32) as u32).min(texture.width - 1);
    let y = ((uv.y.rem_euclid(1.0) * texture.height as f32) as u32).min(texture.height - 1);
    let i = ((y * texture.width + x) * 4) as usize;
    [
        texture.rgba8[i],
        texture.rgba8[i + 1],
        texture.rgba8[i + 2],
        texture.rgba8[i + 3],
    ]
}

pub use manylights_scene::color::linear_to_srgb8;

/// Mean FLIP error between two images of the same size, and the error map (magma colours).
pub fn flip_mean(reference: &image::RgbaImage, test: &image::RgbaImage) -> (f32, image::RgbImage) {
    manylights_lab::lab::flip_mean_and_map(reference, test)
}

/// Where tests write images for people to look at (`target/test-output`).
pub fn output_dir() -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/test-output");
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// Every clustered shading loop: Forward+ and deferred (in `layout`) on every lighting
/// path (the per-pixel loop in a fragment and a compute pass, the tile-shared loop).
/// Tests that must hold for each iterate over these.
pub fn clustered_variants(layout: manylights::GBufferLayout) -> [manylights::PipelineSettings; 4] {
    use manylights::{LightingPath, PipelineSettings};
    [
        PipelineSettings::forward_plus(),
        PipelineSettings::deferred(layout, LightingPath::Fragment),
        PipelineSettings::deferred(layout, LightingPath::Compute),
        PipelineSettings::deferred(layout, LightingPath::Tiles),
    ]
}

/// The golden comparison's tolerance, per pixel: 8-bit sRGB steps a channel may differ by.
/// An unchanged renderer on the same driver reproduces the golden image but for rounding
/// at a step boundary (measured: 1 of 12,288 pixels, by 1 step); another driver's
/// transcendental and texture-filtering precision move a channel by a fraction of a step.
pub const GOLDEN_STEP_TOLERANCE: u8 = 2;
/// And per image: the fraction of pixels allowed beyond [`GOLDEN_STEP_TOLERANCE`], for the
/// triangle-edge pixels whose coverage another rasteriser may decide the other way (pixel
/// centres within a sub-pixel step of an edge). A count, not a mean, so that one light's
/// pool shows: removing any light that changes at least this many pixels fails the check
/// (`golden_check_sees_any_one_missing_light`, tests/naive.rs); a mean FLIP of 0.02 let 53
/// of the 64 lights go missing one at a time.
pub const GOLDEN_CHANGED_FRACTION: f64 = 1e-3;

/// Pixels of `image` whose channels differ from `golden` by more than
/// [`GOLDEN_STEP_TOLERANCE`] steps, and how many the tolerance allows.
pub fn golden_mismatch(golden: &image::RgbaImage, image: &image::RgbaImage) -> (usize, usize) {
    let changed = channel_steps(golden, image)
        .into_iter()
        .filter(|&steps| steps > GOLDEN_STEP_TOLERANCE)
        .count();
    (changed, changed_pixels_allowed(golden.pixels().len()))
}

/// The largest difference of each pixel's colour channels, in 8-bit steps.
pub fn channel_steps(reference: &image::RgbaImage, image: &image::RgbaImage) -> Vec<u8> {
    reference
        .pixels()
        .zip(image.pixels())
        .map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0))
        .collect()
}

/// Of `pixels`, how many may differ beyond the step tolerance: the
/// [`GOLDEN_CHANGED_FRACTION`] whose centres lie within a sub-pixel step of an edge.
pub fn changed_pixels_allowed(pixels: usize) -> usize {
    (GOLDEN_CHANGED_FRACTION * pixels as f64).floor() as usize
}

/// Loads `tests/golden/<name>.png`.
pub fn load_golden(name: &str) -> image::RgbaImage {
    let path = golden_path(name);
    image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (MANYLIGHTS_UPDATE_GOLDEN=1 writes it)",
                path.display()
            )
        })
        .into_rgba8()
}

fn golden_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("golden/{name}.png"))
}

/// Compares `image` with `tests/golden/<name>.png` by [`golden_mismatch`]. On failure
/// writes the image and the FLIP error map to `target/test-output/` and panics naming them.
/// Set `MANYLIGHTS_UPDATE_GOLDEN=1` to (re)write the golden instead.
pub fn assert_matches_golden(name: &str, image: &image::RgbaImage) {
    if std::env::var_os("MANYLIGHTS_UPDATE_GOLDEN").is_some() {
        let path = golden_path(name);
        image
            .save(&path)
            .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
        return;
    }
    let golden = load_golden(name);
    assert_eq!(
        golden.dimensions(),
        image.dimensions(),
        "{name}: size differs from the golden image"
    );
    let (changed, allowed) = golden_mismatch(&golden, image);
    if changed > allowed {
        let (mean, map) = flip_mean(&golden, image);
        let actual = output_dir().join(format!("{name}.actual.png"));
        let diff = output_dir().join(format!("{name}.flip.png"));
        let _ = image.save(&actual);
        let _ = map.save(&diff);
        panic!(
            "{name}: {changed} pixels differ by more than {GOLDEN_STEP_TOLERANCE} steps from {} (at most {allowed}; mean FLIP {mean:.4}); see {} and {}",
            golden_path(name).display(),
            actual.display(),
            diff.display()
        );
    }
}

pub use manylights_lab::lab::{ImageError as HdrError, image_error as hdr_error};

/// Asserts two HDR images agree to one half-float ulp (the Rgba16Float target's storage,
/// where a different summation order can round either way) plus `relative` of the value.
pub fn assert_hdr_close(
    label: &str,
    reference: &[[f32; 4]],
    test: &[[f32; 4]],
    relative: f32,
) -> f32 {
    assert_eq!(reference.len(), test.len(), "{label}: sizes differ");
    let mut worst = 0.0f32;
    for (i, (a, b)) in reference.iter().zip(test).enumerate() {
        for c in 0..3 {
            let magnitude = a[c].abs().max(b[c].abs());
            let ulp = (magnitude.max(6.1e-5).log2().floor() - 10.0).exp2();
            let difference = (a[c] - b[c]).abs();
            worst = worst.max(difference / magnitude.max(1e-6));
            assert!(
                difference <= ulp + relative * magnitude,
                "{label}: pixel {i} channel {c}: reference {} test {}",
                a[c],
                b[c]
            );
        }
    }
    worst
}

/// The scene's camera presets that look at what its lights light: all but `outside`
/// (Sponza from above its roof, the lab's outside view, mostly the unlit roof), whose few
/// lit pixels no lit-fraction floor of these tests is for.
pub fn interior_cameras(loaded: &manylights::LoadedScene) -> Vec<(String, manylights::Camera)> {
    loaded
        .presets
        .iter()
        .filter(|(name, _)| name != "outside")
        .cloned()
        .collect()
}

/// Asserts that at least `min_fraction` of `image`'s pixels are lit (any channel above 0):
/// comparisons of two black images prove nothing. Returns the lit fraction.
pub fn assert_lit(label: &str, image: &[[f32; 4]], min_fraction: f64) -> f64 {
    let lit = image
        .iter()
        .filter(|t| t[..3].iter().any(|&v| v > 0.0))
        .count();
    let fraction = lit as f64 / image.len().max(1) as f64;
    assert!(
        fraction >= min_fraction,
        "{label}: only {lit} of {} pixels are lit (at least {min_fraction} expected)",
        image.len()
    );
    fraction
}

/// Largest relative change of a linear colour channel that half an 8-bit sRGB step can
/// make, for channels at or above sRGB value `srgb` (0..1): the sRGB curve's relative slope
/// there is 2.4 / (srgb + 0.055), times half a step (0.5 / 255).
pub fn srgb8_half_step_relative(srgb: f64) -> f64 {
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
pub fn lossy_relative_bound() -> f64 {
    srgb8_half_step_relative(0.04)
}

/// Pixel-channels beyond `lossy_relative_bound` may be at most this fraction of the lit
/// ones (Sponza's textures have few texels darker than sRGB 0.04; a test that wrote
/// garbage to the G-buffer would fail nearly every pixel).
pub const LOSSY_OUTLIER_FRACTION: f64 = 0.01;

/// Channels darker than this fraction of the image's median lit channel are left out: an
/// absolute error there that no exposure showing the median could reveal becomes a large
/// relative one (f16 storage alone is 2^-11 of the value).
pub const DARK_FRACTION_OF_MEDIAN: f64 = 0.01;

/// The dark floor of `image`: [`DARK_FRACTION_OF_MEDIAN`] of its median lit channel;
/// `None` for a black image.
pub fn dark_floor(image: &[[f32; 4]]) -> Option<f64> {
    let mut lit: Vec<f64> = image
        .iter()
        .flat_map(|t| t[..3].iter().map(|&v| f64::from(v)))
        .filter(|&v| v > 0.0)
        .collect();
    if lit.is_empty() {
        return None;
    }
    lit.sort_by(f64::total_cmp);
    Some(lit[lit.len() / 2] * DARK_FRACTION_OF_MEDIAN)
}

/// The spacing of half floats around `x` (the HDR target's storage; 2^-24 below the
/// smallest normal, 2^-14).
pub fn f16_ulp(x: f64) -> f64 {
    let magnitude = x.abs().max(2f64.powi(-14));
    2f64.powi(magnitude.log2().floor() as i32 - 10)
}

/// Per-channel relative errors of `image` against `reference` over lit channels (above the
/// dark floor), sorted; empty for a black reference.
pub fn relative_errors(reference: &[[f32; 4]], image: &[[f32; 4]]) -> Vec<f64> {
    let Some(floor) = dark_floor(reference) else {
        return Vec::new();
    };
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

/// Renders a frame whose light lists are to be read back: waits for it, and if its lists
/// outgrew the index buffer (the frame was shaded from all lights where they were cut
/// short, and the buffer has grown since), renders it once more so the lists are whole.
pub fn render_with_whole_lists(
    renderer: &mut manylights::Renderer,
    settings: &manylights::FrameSettings,
) -> Result<manylights::FrameStats, manylights::RenderError> {
    let stats = renderer.render_frame_timed(settings)?;
    if stats.list_capacity_grown_to.is_none() {
        return Ok(stats);
    }
    let again = renderer.render_frame_timed(settings)?;
    Ok(manylights::FrameStats {
        list_capacity_grown_to: stats.list_capacity_grown_to,
        ..again
    })
}

/// Fixed lights from (position, radius, intensity), all of one warm white: the extremes'
/// placements.
pub fn fixed_lights(lights: &[(Vec3, f32, f32)]) -> manylights::lights::LightSet {
    manylights::lights::LightSet {
        lights: lights
            .iter()
            .map(|&(position, radius, intensity)| {
                manylights::lights::Light::point(
                    position,
                    radius,
                    glam::Vec3::new(1.0, 0.9, 0.8),
                    intensity,
                )
            })
            .collect(),
    }
}

/// The cornell room with glossy and rough dielectrics and metals for its materials, in
/// turn: roughness from 0.05 (a highlight 0.1 degrees wide) to 1, metallic 0 and 1, shaded
/// with PBR.
pub fn metal_and_dielectric_cornell() -> manylights::LoadedScene {
    let mut loaded = manylights::LoadedScene::load("cornell").expect("scene");
    for (i, material) in loaded.scene.materials.iter_mut().enumerate() {
        material.metallic_factor = (i % 2) as f32;
        material.roughness_factor = [0.05, 0.3, 0.6, 1.0][i % 4];
    }
    loaded.scene.shading = manylights_scene::Shading::Pbr;
    loaded
}

/// The light lists' settings of a frame's clustered pipeline (a test's frame that must
/// cluster: naive has none, and panics here).
pub fn clustering(settings: &manylights::FrameSettings) -> &manylights::ClusteringSettings {
    settings
        .pipeline
        .clustering()
        .expect("a clustered pipeline (Forward+ or deferred)")
}

/// [`clustering`], to change.
pub fn clustering_mut(
    settings: &mut manylights::FrameSettings,
) -> &mut manylights::ClusteringSettings {
    settings
        .pipeline
        .clustering_mut()
        .expect("a clustered pipeline (Forward+ or deferred)")
}

/// The glass room lit by its emission only: every surface one colour of its own (no
/// lights, no reflection), the panes and sparks still blended over the rest. A pixel's
/// value depends only on which surfaces cover it, so a frame's differences are all at
/// edges.
pub fn self_lit_glass_room() -> Scene {
    let mut scene = manylights_scene::procedural::glass_room();
    scene.lights.clear();
    let count = scene.materials.len() as f32;
    for (i, material) in scene.materials.iter_mut().enumerate() {
        let hue = i as f32 / count;
        material.emissive_factor = Vec3::new(0.2 + hue, 1.2 - hue, 0.3 + 0.5 * (hue * 7.0).fract());
        material.base_color_factor = Vec3::ZERO.extend(material.base_color_factor.w);
    }
    scene
}
