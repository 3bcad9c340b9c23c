//! Temporal anti-aliasing against its f64 twin, frame by frame and pixel by pixel, on
//! frames the test writes: every defining parameter of the resolve (the running mean's
//! length, the clip box's width, the history's reach and the same-surface rule, the
//! Catmull-Rom history filter) is held by a comparison whose tolerance follows from the
//! formats, and each sequence shows that the twin with a value the code does not use would
//! not match.

use glam::{DMat4, DVec2, DVec3, DVec4};
use manylights_gpu::taa::JITTER_SAMPLES;
use manylights_gpu::view::ViewUniform;

use manylights_tests::synthetic::{Image, Plane, differing, moved_since_last_frame, test_view};

use super::passes::PostBench;

/// The resolve's defining values (taa.wgsl and common/history.wgsl say why each).
#[derive(Debug, Clone, Copy)]
struct TaaDesign {
    /// The most frames the running mean averages: one cycle of the jitter.
    history_frames: f64,
    /// The clip box's half-width in the neighbourhood's standard deviations.
    clip_sigmas: f64,
    /// How far from the point, in pixels, the history's sample may lie.
    history_reach: f64,
    /// The relative change of distance that is still the same surface.
    same_surface: f64,
    /// The history filter: Catmull-Rom (else bilinear).
    catmull_rom: bool,
    /// The history's normal test: it is of another surface where the normal turned by
    /// more than 37 degrees.
    normal_cos: f64,
}

const DESIGN: TaaDesign = TaaDesign {
    history_frames: JITTER_SAMPLES as f64,
    clip_sigmas: 1.25,
    history_reach: 1.5,
    same_surface: 0.01,
    catmull_rom: true,
    normal_cos: 0.8,
};

/// What the resolve keeps of a pixel for the next frame.
#[derive(Debug, Clone, Copy, Default)]
struct Seen {
    distance: f64,
    frames: f64,
    normal: DVec2,
}

/// The twin's state: last frame's resolved image and what each pixel saw.
#[derive(Debug, Clone, Default)]
struct History {
    colour: Image,
    surface: Vec<Seen>,
}

/// One frame's inputs, as the pass reads them.
struct Frame<'a> {
    size: (usize, usize),
    current: &'a Image,
    /// Each pixel's depth, as the rasterizer wrote it.
    depth: &'a [f64],
    view: &'a ViewUniform,
}

fn mat(m: &[[f32; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)))
}

fn vec4(v: [f32; 4]) -> DVec4 {
    DVec4::from_array(v.map(f64::from))
}

fn luminance(c: DVec3) -> f64 {
    c.dot(DVec3::new(0.2126, 0.7152, 0.0722))
}

fn perceptual(radiance: DVec3) -> DVec3 {
    let x = radiance.max(DVec3::ZERO);
    let c = x / (1.0 + luminance(x));
    DVec3::new(
        0.25 * c.x + 0.5 * c.y + 0.25 * c.z,
        0.5 * c.x - 0.5 * c.z,
        -0.25 * c.x + 0.5 * c.y - 0.25 * c.z,
    )
}

fn radiance_of(ycocg: DVec3) -> DVec3 {
    let c = DVec3::new(
        ycocg.x + ycocg.y - ycocg.z,
        ycocg.x + ycocg.z,
        ycocg.x - ycocg.y - ycocg.z,
    )
    .max(DVec3::ZERO);
    c / (1.0 - luminance(c)).max(1e-3)
}

fn clip_to_box(value: DVec3, centre: DVec3, extent: DVec3) -> DVec3 {
    let offset = value - centre;
    let room = extent / offset.abs().max(DVec3::splat(1e-30));
    centre + offset * room.min_element().min(1.0)
}

fn octahedral(n: DVec3) -> DVec2 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs()).max(1e-30);
    if n.z >= 0.0 {
        DVec2::new(n.x, n.y)
    } else {
        let sign = |s: f64| if s >= 0.0 { 1.0 } else { -1.0 };
        DVec2::new((1.0 - n.y.abs()) * sign(n.x), (1.0 - n.x.abs()) * sign(n.y))
    }
}

fn from_octahedral(e: DVec2) -> DVec3 {
    let mut n = DVec3::new(e.x, e.y, 1.0 - e.x.abs() - e.y.abs());
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    let length_squared = n.length_squared();
    if length_squared > 0.0 {
        n / length_squared.sqrt()
    } else {
        DVec3::ZERO
    }
}

/// How close a decision of the resolve came to going the other way at one pixel (relative
/// to the quantity decided on): pixels decided within rounding of the GPU's f32 are not
/// compared.
const DECISION_MARGIN: f64 = 1e-4;

impl Frame<'_> {
    fn at(&self, image: &Image, x: i64, y: i64) -> DVec3 {
        let x = x.clamp(0, self.size.0 as i64 - 1) as usize;
        let y = y.clamp(0, self.size.1 as i64 - 1) as usize;
        DVec3::from_array(image[y * self.size.0 + x])
    }

    fn depth_at(&self, x: i64, y: i64) -> f64 {
        let x = x.clamp(0, self.size.0 as i64 - 1) as usize;
        let y = y.clamp(0, self.size.1 as i64 - 1) as usize;
        self.depth[y * self.size.0 + x]
    }

    fn scene_point(&self, x: i64, y: i64) -> DVec3 {
        let depth = self.depth_at(x, y);
        let viewport = vec4(self.view.viewport);
        let u = (x as f64 + 0.5) * viewport.z;
        let v = (y as f64 + 0.5) * viewport.w;
        let ndc = DVec4::new(u * 2.0 - 1.0, 1.0 - v * 2.0, depth, 1.0);
        let point = mat(&self.view.inverse_view) * (mat(&self.view.inverse_proj) * ndc);
        let point = if point.w < 0.0 { -point } else { point };
        point.truncate() / point.w
    }

    /// The surface's step to the neighbour ahead or behind, whichever is nearer in depth
    /// (ahead on a tie), as a tangent; none at the border, where that neighbour is the
    /// pixel itself.
    fn tangent(&self, x: i64, y: i64, step: (i64, i64), point: DVec3) -> DVec3 {
        let (w, h) = (self.size.0 as i64, self.size.1 as i64);
        let ahead = ((x + step.0).clamp(0, w - 1), (y + step.1).clamp(0, h - 1));
        let behind = ((x - step.0).clamp(0, w - 1), (y - step.1).clamp(0, h - 1));
        let here = self.depth_at(x, y);
        // f32 differences of f32 depths this close are exact, in f32 as in f64.
        let use_ahead = (self.depth_at(ahead.0, ahead.1) - here).abs()
            <= (self.depth_at(behind.0, behind.1) - here).abs();
        let neighbour = if use_ahead { ahead } else { behind };
        if neighbour == (x, y) {
            return DVec3::ZERO;
        }
        let sign = if use_ahead { 1.0 } else { -1.0 };
        (self.scene_point(neighbour.0, neighbour.1) - point) * sign
    }

    fn history_at(&self, history: &Image, uv: DVec2, catmull_rom: bool) -> DVec3 {
        let size = DVec2::new(self.size.0 as f64, self.size.1 as f64);
        let bilinear = |uv: DVec2| {
            let p = uv * size - 0.5;
            let p0 = p.floor();
            let f = p - p0;
            let (x0, y0) = (p0.x as i64, p0.y as i64);
            self.at(history, x0, y0) * (1.0 - f.x) * (1.0 - f.y)
                + self.at(history, x0 + 1, y0) * f.x * (1.0 - f.y)
                + self.at(history, x0, y0 + 1) * (1.0 - f.x) * f.y
                + self.at(history, x0 + 1, y0 + 1) * f.x * f.y
        };
        if !catmull_rom {
            return bilinear(uv).max(DVec3::ZERO);
        }
        let at = uv * size;
        let centre = (at - 0.5).floor() + 0.5;
        let f = at - centre;
        let w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
        let w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
        let w2 = f * (0.5 + f * (2.0 - 1.5 * f));
        let w3 = f * f * (-0.5 + 0.5 * f);
        let w12 = w1 + w2;
        let t0 = (centre - 1.0) / size;
        let t3 = (centre + 2.0) / size;
        let t12 = (centre + w2 / w12) / size;
        let taps = [
            (DVec2::new(t12.x, t0.y), w12.x * w0.y),
            (DVec2::new(t0.x, t12.y), w0.x * w12.y),
            (t12, w12.x * w12.y),
            (DVec2::new(t3.x, t12.y), w3.x * w12.y),
            (DVec2::new(t12.x, t3.y), w12.x * w3.y),
        ];
        let total: f64 = taps.iter().map(|(_, w)| w).sum();
        let sum = taps
            .iter()
            .fold(DVec3::ZERO, |sum, (tap, w)| sum + bilinear(*tap) * *w);
        (sum / total).max(DVec3::ZERO)
    }
}

/// Where and what the resolve looks for in the surface history: the history texel the
/// point reprojects to, its distance from last frame's camera, the slack the history's
/// reach allows, and its normal now.
struct SurfaceQuery {
    texel: (i64, i64),
    expected: f64,
    slack: f64,
    normal: DVec3,
}

/// The frames the history averaged for the surface `query` describes, if one of the 3x3
/// history texels around its texel saw it (0 if none did), and whether a rule decided
/// within [`DECISION_MARGIN`] (taa.wgsl's `history_of_surface`).
fn history_of_surface(
    history: &History,
    size: (usize, usize),
    query: &SurfaceQuery,
    design: TaaDesign,
) -> (f64, bool) {
    let (w, h) = (size.0 as i64, size.1 as i64);
    let mut frames: f64 = 0.0;
    let mut close = false;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let at_x = (query.texel.0 + dx).clamp(0, w - 1);
            let at_y = (query.texel.1 + dy).clamp(0, h - 1);
            let seen = history.surface[(at_y * w + at_x) as usize];
            let has_normal = seen.normal.x <= 1.5;
            let facing = query.normal.dot(from_octahedral(seen.normal));
            close |= has_normal && (facing - design.normal_cos).abs() < DECISION_MARGIN;
            let normal_kept =
                query.normal.length_squared() == 0.0 || !has_normal || facing >= design.normal_cos;
            let threshold = design.same_surface * query.expected + query.slack;
            let off = (seen.distance - query.expected).abs();
            close |= (off - threshold).abs() <= DECISION_MARGIN * query.expected;
            if seen.frames > 0.0 && off <= threshold && normal_kept {
                frames = frames.max(seen.frames);
            }
        }
    }
    (frames, close)
}

/// One resolve of `frame` over `history` (None: no history, a first frame) with `design`:
/// the resolved image, what it saw, and which pixels were decided within
/// [`DECISION_MARGIN`].
fn taa_twin(frame: &Frame, history: Option<&History>, design: TaaDesign) -> (History, Vec<bool>) {
    let (w, h) = (frame.size.0 as i64, frame.size.1 as i64);
    let view = frame.view;
    let camera = vec4(view.camera_position).truncate();
    let previous_camera = vec4(view.previous_camera_position).truncate();
    let jitter = vec4(view.jitter);
    let viewport = vec4(view.viewport);
    let mut out = History::default();
    let mut close = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let sample = frame.at(frame.current, x, y);
            let mut sum = DVec3::ZERO;
            let mut sum_squares = DVec3::ZERO;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let p = perceptual(frame.at(frame.current, x + dx, y + dy));
                    sum += p;
                    sum_squares += p * p;
                }
            }
            let mean = sum / 9.0;
            let spread = (sum_squares / 9.0 - mean * mean).max(DVec3::ZERO).sqrt();
            let point = frame.scene_point(x, y);
            let along_x = frame.tangent(x, y, (1, 0), point);
            let along_y = frame.tangent(x, y, (0, 1), point);
            let across = along_x.cross(along_y);
            let mut normal = across.normalize_or_zero();
            if normal.dot(camera - point) < 0.0 {
                normal = -normal;
            }
            let mut kept = sample;
            let mut frames = 0.0;
            let mut decided_close = false;
            let previous_clip = mat(&view.previous_view_proj) * point.extend(1.0);
            if let Some(history) = history.filter(|_| previous_clip.w > 0.0) {
                let ndc = previous_clip.truncate().truncate() / previous_clip.w
                    - DVec2::new(jitter.z, jitter.w)
                    + DVec2::new(jitter.x, jitter.y);
                let uv = DVec2::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
                let inside = uv.cmpge(DVec2::ZERO).all() && uv.cmplt(DVec2::ONE).all();
                if inside {
                    let from_camera = point - previous_camera;
                    let expected = from_camera.length();
                    let ray = from_camera / expected.max(1e-30);
                    let slack =
                        design.history_reach * along_x.dot(ray).abs().max(along_y.dot(ray).abs());
                    let texel = (uv * DVec2::new(viewport.x, viewport.y)).floor();
                    let surface = SurfaceQuery {
                        texel: (texel.x as i64, texel.y as i64),
                        expected,
                        slack,
                        normal,
                    };
                    let (seen_frames, close_here) =
                        history_of_surface(history, frame.size, &surface, design);
                    decided_close |= close_here;
                    if seen_frames > 0.0 {
                        frames = seen_frames;
                        let clipped = clip_to_box(
                            perceptual(frame.history_at(&history.colour, uv, design.catmull_rom)),
                            mean,
                            design.clip_sigmas * spread,
                        );
                        kept = radiance_of(clipped);
                    }
                }
            }
            let frames = (frames + 1.0).min(design.history_frames);
            let accumulated = kept + (sample - kept) / frames;
            out.colour.push(accumulated.to_array());
            out.surface.push(Seen {
                distance: (point - camera).length(),
                frames,
                normal: if normal.length_squared() > 0.0 {
                    octahedral(normal)
                } else {
                    DVec2::splat(2.0)
                },
            });
            close.push(decided_close);
        }
    }
    (out, close)
}

/// A smooth pattern with features a few pixels wide (so the neighbourhood has a spread
/// everywhere), of the position `(x, y)` in pixels: colour, positive.
fn pattern(x: f64, y: f64) -> [f64; 3] {
    let a = (0.9 * x + 0.3 * y).sin();
    let b = (0.4 * x - 1.1 * y).cos();
    [
        0.35 + 0.25 * a,
        0.3 + 0.15 * b + 0.1 * a,
        0.25 + 0.2 * (a * b),
    ]
}

fn image(size: (usize, usize), f: impl Fn(f64, f64) -> [f64; 3]) -> Image {
    let mut out = Vec::with_capacity(size.0 * size.1);
    for y in 0..size.1 {
        for x in 0..size.0 {
            // As the GPU is given it: in half floats.
            let v = f(x as f64, y as f64).map(|c| half::f16::from_f64(c).to_f64());
            out.push(v);
        }
    }
    out
}

/// One frame of a test sequence: the image, the plane's distance, and how far (in
/// pixels, x right and y down) the image's content moved since the frame before.
struct Step {
    current: Image,
    plane: Plane,
    moved: (f64, f64),
}

/// The plane `distance` ahead, facing the camera.
fn facing(distance: f32) -> Plane {
    Plane {
        distance,
        tilt_degrees: 0.0,
    }
}

/// The tolerance of a sequence's frame at a pixel whose twin value is `value`, `frames`
/// frames after the sequence began.
///
/// Each frame's resolve is stored in half floats (2^-10 of the value where a device
/// truncates) and read back by the next: its error is carried at a weight of at most
/// (1 - 1/N) a frame into the running mean, so the errors of all frames before sum to at
/// most N units (N the running mean's length), of the largest value the history is read
/// from, times the Catmull-Rom filter's largest gain (its five weights' absolute sum over
/// their sum, at most 1.3). The history's filter taps are placed to the sampler's
/// sub-texel precision, 8 bits on every device we know (Vulkan's minimum is 4; lavapipe,
/// SwiftShader, NVIDIA, AMD, Intel and Apple have 8): each bilinear weight within 2^-9,
/// times the values' range (under 1 here).
fn tolerance(largest: f64, moving: bool) -> f64 {
    let filter_gain = if moving { 1.3 } else { 1.0 };
    let rounding = DESIGN.history_frames * 2f64.powi(-10) * filter_gain * largest;
    let placement = if moving {
        filter_gain * 2.0 * 2f64.powi(-9)
    } else {
        0.0
    };
    rounding + placement
}

/// Runs `steps` through the GPU and the twin with `DESIGN`, compares every frame from
/// `compare_from` on, and checks that the twin with each of `others` differs from the
/// GPU somewhere in the sequence; `what` names the sequence.
fn check_sequence(what: &str, steps: &[Step], compare_from: usize, others: &[(&str, TaaDesign)]) {
    let size = (32usize, 24usize);
    let mut bench = PostBench::new((size.0 as u32, size.1 as u32));
    let base = test_view((size.0 as u32, size.1 as u32));
    let designs: Vec<TaaDesign> = std::iter::once(DESIGN)
        .chain(others.iter().map(|(_, d)| *d))
        .collect();
    let mut histories: Vec<Option<History>> = vec![None; designs.len()];
    let mut far_apart = vec![0usize; designs.len()];
    let mut compared = 0;
    for (n, step) in steps.iter().enumerate() {
        // Last frame's camera saw this frame's point `moved` pixels back.
        let view = moved_since_last_frame(&base, step.moved);
        let depth = bench.write_frame_on(&step.current, &view, step.plane);
        assert!(
            depth.iter().all(|&d| d > 0.0 && d < 1.0),
            "{what}, frame {n}: the plane must cover the frame"
        );
        let gpu = bench.taa_frame(&view);
        let frame = Frame {
            size,
            current: &step.current,
            depth: &depth,
            view: &view,
        };
        let moving = step.moved != (0.0, 0.0);
        let largest = step
            .current
            .iter()
            .flatten()
            .chain(histories[0].iter().flat_map(|h| h.colour.iter().flatten()))
            .fold(0.0f64, |a, &b| a.max(b));
        let bound = tolerance(largest, moving);
        for (d, design) in designs.iter().enumerate() {
            let (resolved, close) = taa_twin(&frame, histories[d].as_ref(), *design);
            if n >= compare_from {
                let (count, examples) = differing(
                    &gpu,
                    &resolved.colour,
                    |i, _| if close[i] { f64::INFINITY } else { bound },
                    6,
                );
                if d == 0 {
                    let decided_close = close.iter().filter(|c| **c).count();
                    assert!(
                        decided_close * 20 <= close.len(),
                        "{what}, frame {n}: {decided_close} pixels decided within rounding"
                    );
                    assert_eq!(
                        count, 0,
                        "{what}, frame {n}: {count} channels differ from the twin beyond \
                         {bound:.2e}: {examples:#?}"
                    );
                    compared += 1;
                } else {
                    far_apart[d] += count;
                }
            }
            histories[d] = Some(resolved);
        }
    }
    assert!(compared > 0, "{what}: no frame compared");
    for ((name, _), apart) in others.iter().zip(&far_apart[1..]) {
        assert!(
            *apart > 20,
            "{what}: the twin with {name} matches the GPU within the tolerance at all but \
             {apart} channels: the sequence would not see that change"
        );
    }
}

/// A still camera, a steady image, then a step within the clip box: the running mean
/// converges as 1/1, 1/2, ... 1/N, then 1/N a frame.
#[test]
fn taa_running_mean_matches_its_twin_frame_by_frame() {
    let size = (32, 24);
    let mut steps = Vec::new();
    for n in 0..30 {
        // Three small steps of brightness, each inside the neighbourhood's box.
        let lift = if n < 6 {
            0.0
        } else if n < 14 {
            0.04
        } else {
            -0.03
        };
        steps.push(Step {
            current: image(size, |x, y| pattern(x, y).map(|c| c + lift)),
            plane: facing(4.0),
            moved: (0.0, 0.0),
        });
    }
    let others = [
        (
            "a running mean of 8 frames",
            TaaDesign {
                history_frames: 8.0,
                ..DESIGN
            },
        ),
        (
            "a running mean of 32 frames",
            TaaDesign {
                history_frames: 32.0,
                ..DESIGN
            },
        ),
    ];
    check_sequence("the running mean", &steps, 0, &others);
}

/// History that the frame no longer shows is clipped to the neighbourhood's box of
/// 1.25 standard deviations, exactly.
#[test]
fn taa_clips_history_to_its_box_as_its_twin_does() {
    let size = (32, 24);
    let mut steps = Vec::new();
    for n in 0..12 {
        // The image changes beyond the box twice: brighter, then another pattern.
        let current = if n < 4 {
            image(size, pattern)
        } else if n < 8 {
            image(size, |x, y| pattern(x, y).map(|c| c * 1.6 + 0.05))
        } else {
            image(size, |x, y| pattern(y * 0.7, x * 1.3))
        };
        steps.push(Step {
            current,
            plane: facing(4.0),
            moved: (0.0, 0.0),
        });
    }
    let others = [
        (
            "a box of 2.5 standard deviations",
            TaaDesign {
                clip_sigmas: 2.5,
                ..DESIGN
            },
        ),
        (
            "a box of 0.6 standard deviations",
            TaaDesign {
                clip_sigmas: 0.6,
                ..DESIGN
            },
        ),
    ];
    check_sequence("clipping", &steps, 0, &others);
}

/// A camera that moves a fraction of a pixel a frame reads its history between texels,
/// through the Catmull-Rom filter.
#[test]
fn taa_reads_moving_history_through_catmull_rom_as_its_twin_does() {
    let size = (32, 24);
    let velocity = (0.3, 0.2);
    let steps: Vec<Step> = (0..8)
        .map(|n| {
            let (dx, dy) = (velocity.0 * n as f64, velocity.1 * n as f64);
            Step {
                current: image(size, |x, y| pattern(x - dx, y - dy)),
                plane: facing(4.0),
                moved: if n == 0 { (0.0, 0.0) } else { velocity },
            }
        })
        .collect();
    let others = [(
        "a bilinear history filter",
        TaaDesign {
            catmull_rom: false,
            ..DESIGN
        },
    )];
    check_sequence("a moving camera", &steps, 0, &others);
}

/// The surface moved 3% further from the camera: the history is of another surface at
/// the frame's middle (the distance rule's 1%, plus a pixel and a half of the surface's
/// change across a pixel, which is little where the plane faces the view) and of the
/// same one toward the frame's corners, where a pixel spans more distance.
#[test]
fn taa_keeps_history_of_the_same_surface_only_as_its_twin_does() {
    let size = (32, 24);
    let mut steps = Vec::new();
    for n in 0..8 {
        let near = n < 5;
        steps.push(Step {
            current: image(size, |x, y| {
                pattern(x, y).map(|c| if near { c } else { c + 0.05 })
            }),
            plane: facing(if near { 4.0 } else { 4.12 }),
            moved: (0.0, 0.0),
        });
    }
    let others = [
        (
            "a distance rule of 2%",
            TaaDesign {
                same_surface: 0.02,
                ..DESIGN
            },
        ),
        (
            "a distance rule of 0.5%",
            TaaDesign {
                same_surface: 0.005,
                ..DESIGN
            },
        ),
        (
            "a reach of 3 pixels",
            TaaDesign {
                history_reach: 3.0,
                ..DESIGN
            },
        ),
        (
            "a reach of 0.75 pixels",
            TaaDesign {
                history_reach: 0.75,
                ..DESIGN
            },
        ),
    ];
    check_sequence("the same surface", &steps, 0, &others);
}

/// The surface turns about the frame's middle column: by 30 degrees (within the normal
/// rule's 37: the history is kept where the distance rule keeps it, near the axis), then
/// by 45 (beyond it: the history is of another surface even where the distance is the
/// same).
#[test]
fn taa_keeps_history_only_where_the_normal_turned_less_than_its_rule_as_its_twin_does() {
    let size = (32, 24);
    let mut steps = Vec::new();
    for n in 0..10 {
        let tilt = match n {
            0..=3 => 0.0,
            4..=6 => 30.0,
            _ => -15.0,
        };
        steps.push(Step {
            current: image(size, |x, y| pattern(x, y).map(|c| c + 0.01 * n as f64)),
            plane: Plane {
                distance: 4.0,
                tilt_degrees: tilt,
            },
            moved: (0.0, 0.0),
        });
    }
    let others = [
        (
            "a normal rule of 53 degrees",
            TaaDesign {
                normal_cos: 0.6,
                ..DESIGN
            },
        ),
        (
            "a normal rule of 26 degrees",
            TaaDesign {
                normal_cos: 0.9,
                ..DESIGN
            },
        ),
    ];
    check_sequence("a turning surface", &steps, 0, &others);
}
