//! MSAA (issue 45): Forward+ and naive draw into multisampled colour and depth and resolve
//! it; deferred refuses it with the reason.

use manylights::lights::Falloff;
use manylights::scene::Scene;
use manylights::scene::procedural::glass_room;
use manylights::{
    Exposure, ForwardPlusSettings, FrameSettings, GBufferLayout, LightingPath, LoadedScene,
    PipelineSettings, Renderer, Shadows, Transparency,
};
use manylights_tests::{assert_hdr_close, assert_lit, f16_ulp, gpu, self_lit_glass_room};

const SIZE: (u32, u32) = (96, 72);

/// The standard sample positions within a pixel (Vulkan's, Direct3D's and WebGPU's), for
/// each count. Each lies on a regular grid of `grid` x `grid` points at `(i + 0.5) / grid`,
/// so a frame rendered `grid` times larger holds a pixel for every sample.
fn standard_samples(samples: u32) -> (u32, Vec<(f32, f32)>) {
    match samples {
        2 => (2, vec![(0.75, 0.75), (0.25, 0.25)]),
        4 => (
            4,
            vec![
                (0.375, 0.125),
                (0.875, 0.375),
                (0.125, 0.625),
                (0.625, 0.875),
            ],
        ),
        8 => (
            8,
            vec![
                (0.5625, 0.3125),
                (0.4375, 0.6875),
                (0.8125, 0.5625),
                (0.3125, 0.1875),
                (0.1875, 0.8125),
                (0.0625, 0.4375),
                (0.6875, 0.9375),
                (0.9375, 0.0625),
            ],
        ),
        _ => panic!("no standard pattern for {samples} samples"),
    }
}

/// The MSAA counts beyond 1 that this device offers; WebGPU guarantees 4.
fn multisample_counts() -> Vec<u32> {
    let counts = gpu().msaa_sample_counts();
    assert!(
        counts.contains(&4),
        "every WebGPU device offers 4x MSAA; this one offers {counts:?}"
    );
    counts.into_iter().filter(|&n| n > 1).collect()
}

/// The glass room seen by its camera at `size` with `msaa`, in `pipeline`, as `change`
/// leaves the settings.
fn frame(
    scene: Scene,
    pipeline: PipelineSettings,
    size: (u32, u32),
    msaa: u32,
    change: impl FnOnce(&mut FrameSettings),
) -> Vec<[f32; 4]> {
    let loaded = LoadedScene::from_scene("glass", scene);
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = size;
    settings.view.msaa = msaa;
    settings.lights.count = 24;
    settings.post.exposure = Exposure::Manual(1.0);
    // The self-lit room's surfaces glow without lighting one another.
    settings.lights.emissive = false;
    settings.pipeline = pipeline;
    change(&mut settings);
    let mut renderer = Renderer::new(gpu(), loaded).expect("renderer");
    renderer.render_frame(&settings).expect("frame");
    renderer.read_hdr().expect("hdr")
}

/// A frame `grid` times larger than [`SIZE`], with a pixel on every standard sample
/// position of each of [`SIZE`]'s pixels.
struct Supersampled {
    image: Vec<[f32; 4]>,
    size: (u32, u32),
    grid: u32,
    positions: Vec<(f32, f32)>,
}

impl Supersampled {
    fn at(&self, (x, y): (u32, u32)) -> [f32; 4] {
        self.image[(y * self.size.0 + x) as usize]
    }

    /// The larger frame's pixel on each sample of pixel `i`.
    fn sample_pixels(&self, i: u32) -> Vec<(u32, u32)> {
        let (x, y) = (i % SIZE.0, i / SIZE.0);
        let on_grid = |s: f32| (s * self.grid as f32 - 0.5) as u32;
        self.positions
            .iter()
            .map(|&(sx, sy)| (x * self.grid + on_grid(sx), y * self.grid + on_grid(sy)))
            .collect()
    }

    /// The mean of pixel `i`'s sample colours, and the largest channel among them.
    fn mean(&self, i: u32) -> ([f32; 3], f32) {
        let mut mean = [0.0f32; 3];
        let mut largest = 0.0f32;
        for sample in self.sample_pixels(i) {
            let colour = self.at(sample);
            for c in 0..3 {
                mean[c] += colour[c] / self.positions.len() as f32;
                largest = largest.max(colour[c]);
            }
        }
        (mean, largest)
    }

    /// Whether pixel `i`'s samples see more than one colour (its mean is not its corner's).
    fn sees_two_colours(&self, i: u32, mean: &[f32; 3]) -> bool {
        let corner = self.at(((i % SIZE.0) * self.grid, (i / SIZE.0) * self.grid));
        (0..3).any(|c| (mean[c] - corner[c]).abs() > 1e-3 * mean[c].max(1e-3))
    }

    /// Whether `pixel` is pixel `i`'s mean with one sample's colour replaced by the colour
    /// of the larger frame's pixel next to that sample (to two half-float ulps).
    fn one_sample_flipped(&self, i: u32, pixel: &[f32; 4]) -> bool {
        let (mean, largest) = self.mean(i);
        let ulp = f16_ulp(f64::from(largest)) as f32;
        let count = self.positions.len() as f32;
        self.sample_pixels(i).into_iter().any(|(px, py)| {
            let own = self.at((px, py));
            (-1i32..=1)
                .flat_map(|dy| (-1i32..=1).map(move |dx| (px as i32 + dx, py as i32 + dy)))
                .filter(|&(nx, ny)| {
                    nx >= 0 && ny >= 0 && nx < self.size.0 as i32 && ny < self.size.1 as i32
                })
                .any(|(nx, ny)| {
                    let other = self.at((nx as u32, ny as u32));
                    (0..3).all(|c| {
                        let flipped = mean[c] + (other[c] - own[c]) / count;
                        (pixel[c] - flipped).abs() <= 2.0 * ulp
                    })
                })
        })
    }
}

/// Resolved MSAA is the mean of the samples' colours. Where every surface has one colour
/// (emission only), a sample's colour is the colour of what covers its position, so the
/// resolved pixel must equal the mean of the pixels of a frame rendered `grid` times larger
/// that lie on the standard sample positions (the panes blended per sample in both), at
/// every pixel, edges included, to the half-float rounding of the resolve and of the
/// sample colours: one ulp of the largest sample. One exception, derived from how a
/// rasterizer works: it snaps vertices to a sub-pixel grid whose step is a fixed fraction
/// of a pixel, so the larger frame's triangles are snapped four times finer and a sample
/// within a snapping step of an edge may fall on the other side. Such a pixel must still
/// be the mean with exactly one sample's colour replaced by a colour the larger frame has
/// next to that sample, and such pixels must be few (a tenth of the edge pixels). One
/// sample a pixel (no MSAA) misses the mean at most edges; a sample mask that kept one
/// sample would darken every pixel.
#[test]
fn resolved_msaa_is_the_mean_of_the_colours_at_the_sample_positions() {
    let pipelines = [
        PipelineSettings::naive(Falloff::WindowedInverseSquare),
        PipelineSettings::forward_plus(),
    ];
    for samples in multisample_counts() {
        let (grid, positions) = standard_samples(samples);
        let large = (SIZE.0 * grid, SIZE.1 * grid);
        let image = frame(self_lit_glass_room(), pipelines[0], large, 1, |s| {
            s.lights.count = 0
        });
        assert_lit("the supersampled frame", &image, 0.5);
        let supersampled = Supersampled {
            image,
            size: large,
            grid,
            positions,
        };
        let expected: Vec<([f32; 3], f32)> =
            (0..SIZE.0 * SIZE.1).map(|i| supersampled.mean(i)).collect();
        let edges = (0..SIZE.0 * SIZE.1)
            .filter(|&i| supersampled.sees_two_colours(i, &expected[i as usize].0))
            .count();
        assert!(
            edges > 100,
            "{samples}x: only {edges} pixels see two colours"
        );
        for pipeline in pipelines {
            for msaa in [samples, 1] {
                let image = frame(self_lit_glass_room(), pipeline, SIZE, msaa, |s| {
                    s.lights.count = 0
                });
                let wrong = image
                    .iter()
                    .zip(&expected)
                    .enumerate()
                    .filter(|(_, (pixel, (mean, largest)))| {
                        let ulp = f16_ulp(f64::from(*largest)) as f32;
                        (0..3).any(|c| (pixel[c] - mean[c]).abs() > ulp)
                    })
                    .map(|(i, _)| i)
                    .collect::<Vec<_>>();
                if msaa == 1 {
                    assert!(
                        wrong.len() * 2 > edges,
                        "{pipeline:?} without MSAA: only {} of {edges} edge pixels differ from the {samples}-sample mean",
                        wrong.len()
                    );
                    continue;
                }
                let explained = |i: usize| supersampled.one_sample_flipped(i as u32, &image[i]);
                if let Some(&i) = wrong.iter().find(|&&i| !explained(i)) {
                    panic!(
                        "{pipeline:?}, {samples}x: pixel {i} is {:?}, neither the mean of its samples {:?} nor that mean with one sample on the other side of an edge ({} pixels differ from the mean)",
                        image[i],
                        expected[i].0,
                        wrong.len()
                    );
                }
                eprintln!(
                    "{pipeline:?}, {samples}x: {} of {edges} edge pixels have one sample across an edge",
                    wrong.len()
                );
                assert!(
                    wrong.len() * 10 <= edges,
                    "{pipeline:?}, {samples}x: {} of {edges} edge pixels have a sample across an edge",
                    wrong.len()
                );
            }
        }
    }
}

/// Under MSAA the Forward+ lists reach every surface a sample of a pixel sees: the
/// cluster boxes are bounded by every sample's depth over the pixel's footprint, and a
/// partly covered fragment is shaded at a point it covers. Forward+ (with and without its
/// depth pre-pass) equals naive, lossless (1e-4), with the panes blended sorted and
/// weighted, and with exact shadows traced in the shading pass.
#[test]
fn msaa_forward_plus_equals_naive() {
    let naive = PipelineSettings::naive(Falloff::WindowedInverseSquare);
    let forward = [
        PipelineSettings::forward_plus(),
        PipelineSettings::ForwardPlus(ForwardPlusSettings {
            depth_prepass: false,
            ..ForwardPlusSettings::default()
        }),
    ];
    let settings = [
        (Transparency::Sorted, Shadows::Off),
        (Transparency::Weighted, Shadows::Off),
        (Transparency::Sorted, Shadows::Exact),
    ];
    for (transparency, shadows) in settings {
        let change = |s: &mut FrameSettings| {
            s.transparency = transparency;
            s.shadows.mode = shadows;
        };
        let reference = frame(glass_room(), naive, SIZE, 4, change);
        assert_lit("naive", &reference, 0.3);
        for pipeline in forward {
            let image = frame(glass_room(), pipeline, SIZE, 4, change);
            let label = format!("{pipeline:?}, {transparency}, shadows {shadows}, 4x");
            assert_hdr_close(&label, &reference, &image, 1e-4);
        }
    }
}

/// Deferred refuses MSAA and says why (one G-buffer surface a pixel) and what it would
/// cost; the forward shadow pass refuses it too; a count outside 1, 2, 4, 8 is refused.
/// The renderer keeps working after each refusal.
#[test]
fn msaa_refusals_say_why() {
    let loaded = LoadedScene::from_scene("glass", glass_room());
    let mut renderer = Renderer::new(gpu(), loaded.clone()).expect("renderer");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = (32, 24);
    settings.view.msaa = 4;
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Tiles);
    let error = renderer
        .render_frame(&settings)
        .expect_err("deferred")
        .to_string();
    assert!(error.contains("G-buffer per sample"), "{error}");
    settings.pipeline = PipelineSettings::forward_plus();
    settings.shadows.mode = Shadows::RaysTemporal(1);
    let error = renderer
        .render_frame(&settings)
        .expect_err("shadow pass")
        .to_string();
    assert!(error.contains("shadow pass"), "{error}");
    settings.shadows.mode = Shadows::Off;
    settings.view.msaa = 3;
    let error = renderer
        .render_frame(&settings)
        .expect_err("3x")
        .to_string();
    assert!(error.contains("1 (off), 2, 4 or 8"), "{error}");
    settings.view.msaa = 4;
    renderer
        .render_frame(&settings)
        .expect("4x Forward+ after the refusals");
}
