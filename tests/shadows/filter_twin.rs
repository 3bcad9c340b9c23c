//! The shadow filter (`shaders/visibility/shadow_filter.wgsl`) against its f64 twin, on
//! inputs the test writes (the unshadowed radiance, the rays' share, the normals, a depth
//! plane): its footprint (the taps each side and the Gaussian's width), its edge rules
//! (normals, planes) and its history (the running mean's length, the light rule, the
//! margin) are each held by a comparison whose tolerance follows from the formats, and
//! each sequence shows that the twin with a value the code does not use would not match.

use glam::{DMat4, DVec3, DVec4};
use manylights::Shadows;
use manylights::gpu::targets::{RenderTargets, read_f32_rgba};
use manylights::gpu::timer::GpuTimer;
use manylights::gpu::view::{ViewBinding, ViewUniform};
use manylights::gpu::{ShaderLibrary, wgpu};
use manylights::visibility::{SHADOW_HISTORY_FRAMES, ShadowFilter};
use manylights_tests::synthetic::{
    Image, clear_depth, differing, in_half_floats, plane_depth, test_view, write_rgba16,
};

const SIZE: (usize, usize) = (40, 24);

/// The filter's defining values (shadow_filter.wgsl says why each).
#[derive(Debug, Clone, Copy)]
struct FilterDesign {
    radius: i64,
    sigma: f64,
    plane_tolerance: f64,
    normal_cos: f64,
    history_frames: f64,
    light_change: f64,
    history_margin: f64,
}

const DESIGN: FilterDesign = FilterDesign {
    radius: 6,
    sigma: 3.0,
    plane_tolerance: 0.01,
    normal_cos: 0.9,
    history_frames: SHADOW_HISTORY_FRAMES as f64,
    light_change: 0.05,
    history_margin: 0.15,
};

/// One frame's inputs: each a row-major RGBA image (the emissions' channels in w, zero).
#[derive(Clone)]
struct Inputs {
    unshadowed: Vec<[f64; 4]>,
    share: Vec<[f64; 4]>,
    normal: Vec<[f64; 4]>,
    distance: f32,
}

/// What the history keeps of a pixel.
#[derive(Debug, Clone, Copy, Default)]
struct Kept {
    share: [f64; 3],
    frames: f64,
    distance: f64,
    brightness: f64,
}

fn mat(m: &[[f32; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)))
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

fn rgb(p: [f64; 4]) -> [f64; 3] {
    [p[0], p[1], p[2]]
}

struct Twin<'a> {
    inputs: &'a Inputs,
    view: &'a ViewUniform,
    depth: f64,
    design: FilterDesign,
}

/// How close a decision came to going the other way, relative to what it decided on:
/// pixels decided within the GPU's f32 rounding of it are not compared.
const DECISION_MARGIN: f64 = 1e-4;

/// The first three components of a uniform's vector.
fn xyz(v: [f32; 4]) -> DVec3 {
    DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
}

impl Twin<'_> {
    fn index(&self, x: i64, y: i64) -> usize {
        y as usize * SIZE.0 + x as usize
    }

    fn world(&self, x: i64, y: i64) -> DVec3 {
        let viewport = DVec4::from_array(self.view.viewport.map(f64::from));
        let u = (x as f64 + 0.5) * viewport.z;
        let v = (y as f64 + 0.5) * viewport.w;
        let ndc = DVec4::new(u * 2.0 - 1.0, 1.0 - v * 2.0, self.depth, 1.0);
        let view_h = mat(&self.view.inverse_proj) * ndc;
        let view_position = view_h.truncate() / view_h.w;
        (mat(&self.view.inverse_view) * view_position.extend(1.0)).truncate()
    }

    fn rebuilt(&self, x: i64, y: i64) -> DVec3 {
        let camera = xyz(self.view.camera_position);
        self.world(x, y) - camera
    }

    /// The share at (x, y) of `share`, filtered along `axis`; and whether a decision was
    /// close.
    fn filtered(&self, share: &[[f64; 4]], x: i64, y: i64, axis: (i64, i64)) -> ([f64; 3], bool) {
        let i = self.index(x, y);
        let own = rgb(share[i]);
        let normal = DVec3::new(
            self.inputs.normal[i][0],
            self.inputs.normal[i][1],
            self.inputs.normal[i][2],
        );
        if normal.length_squared() <= 0.25 {
            return (own, false);
        }
        let centre = self.rebuilt(x, y);
        let plane = normal.dot(centre);
        let own_light = rgb(self.inputs.unshadowed[i]);
        let mut visible = [0, 1, 2].map(|c| own[c] * own_light[c]);
        let mut all = own_light;
        let mut close = false;
        for side in [-1i64, 1] {
            for k in 1..=self.design.radius {
                let (tx, ty) = (x + axis.0 * k * side, y + axis.1 * k * side);
                if tx < 0 || ty < 0 || tx >= SIZE.0 as i64 || ty >= SIZE.1 as i64 {
                    break;
                }
                let t = self.index(tx, ty);
                let tap_normal = DVec3::new(
                    self.inputs.normal[t][0],
                    self.inputs.normal[t][1],
                    self.inputs.normal[t][2],
                );
                let facing = tap_normal.dot(normal);
                if (facing - self.design.normal_cos).abs() < DECISION_MARGIN {
                    close = true;
                }
                if tap_normal.length_squared() <= 0.25 || facing < self.design.normal_cos {
                    break;
                }
                let along = normal.dot(self.rebuilt(tx, ty));
                let off = (along - plane).abs();
                let allowed = self.design.plane_tolerance * plane.abs();
                if (off - allowed).abs() < DECISION_MARGIN * plane.abs() {
                    close = true;
                }
                if off > allowed {
                    break;
                }
                let weight =
                    (-((k * k) as f64) / (2.0 * self.design.sigma * self.design.sigma)).exp();
                let tap_light = rgb(self.inputs.unshadowed[t]);
                let tap_share = rgb(share[t]);
                for c in 0..3 {
                    visible[c] += weight * tap_light[c] * tap_share[c];
                    all[c] += weight * tap_light[c];
                }
            }
        }
        (
            [0, 1, 2].map(|c| {
                if all[c] > 0.0 {
                    visible[c] / all[c]
                } else {
                    own[c]
                }
            }),
            close,
        )
    }

    /// The frame: the HDR image, the history it writes (with `history` the last frame's,
    /// when temporal), and which pixels had a close decision.
    fn frame(&self, history: Option<&[Kept]>) -> (Image, Vec<Kept>, Vec<bool>) {
        let (w, h) = (SIZE.0 as i64, SIZE.1 as i64);
        let mut rows = vec![[0.0; 4]; SIZE.0 * SIZE.1];
        let mut close = vec![false; SIZE.0 * SIZE.1];
        for y in 0..h {
            for x in 0..w {
                let (share, c) = self.filtered(&self.inputs.share, x, y, (1, 0));
                let i = self.index(x, y);
                rows[i] = [share[0], share[1], share[2], self.inputs.share[i][3]];
                close[i] |= c;
            }
        }
        let camera = xyz(self.view.camera_position);
        let previous_camera = xyz(self.view.previous_camera_position);
        let viewport = DVec4::from_array(self.view.viewport.map(f64::from));
        let mut out = Vec::with_capacity(SIZE.0 * SIZE.1);
        let mut kept_out = Vec::with_capacity(SIZE.0 * SIZE.1);
        for y in 0..h {
            for x in 0..w {
                let i = self.index(x, y);
                let (filtered, c) = self.filtered(&rows, x, y, (0, 1));
                // Rows' neighbours' decisions feed this pixel's columns.
                close[i] |= c
                    || (-self.design.radius..=self.design.radius).any(|dy| {
                        let yy = y + dy;
                        yy >= 0 && yy < h && close[self.index(x, yy)]
                    });
                let light = rgb(self.inputs.unshadowed[i]);
                let mut accumulated = filtered;
                if let Some(history) = history {
                    let position = self.world(x, y);
                    let brightness = luminance(light);
                    let clip = mat(&self.view.previous_view_proj) * position.extend(1.0);
                    let mut frames = 0.0;
                    let mut kept = filtered;
                    if clip.w > 0.0 {
                        let ndc = clip.truncate().truncate() / clip.w;
                        let (u, v) = (ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
                        let (bx, by) = (
                            (u * viewport.x).floor() as i64,
                            (v * viewport.y).floor() as i64,
                        );
                        if bx >= 0 && by >= 0 && bx < w && by < h {
                            let previous = history[self.index(bx, by)];
                            let expected = (position - previous_camera).length();
                            let surface_kept =
                                (previous.distance - expected).abs() <= 0.01 * expected;
                            let change = (previous.brightness - brightness).abs();
                            let allowed =
                                self.design.light_change * previous.brightness.max(brightness);
                            if (change - allowed).abs() < DECISION_MARGIN * brightness.max(1e-30) {
                                close[i] = true;
                            }
                            if previous.frames > 0.0 && surface_kept && change <= allowed {
                                frames = previous.frames;
                                kept = [0, 1, 2].map(|c| {
                                    previous.share[c].clamp(
                                        filtered[c] - self.design.history_margin,
                                        filtered[c] + self.design.history_margin,
                                    )
                                });
                            }
                        }
                    }
                    let frames = (frames + 1.0f64).min(self.design.history_frames);
                    accumulated = [0, 1, 2].map(|c| kept[c] + (filtered[c] - kept[c]) / frames);
                    kept_out.push(Kept {
                        share: accumulated,
                        frames,
                        distance: (position - camera).length(),
                        brightness,
                    });
                }
                out.push([0, 1, 2].map(|c| light[c] * accumulated[c]));
            }
        }
        (out, kept_out, close)
    }
}

/// The filter on a device, over targets of [`SIZE`].
struct FilterBench {
    context: manylights::gpu::GpuContext,
    targets: RenderTargets,
    view: ViewBinding,
    filter: ShadowFilter,
}

impl FilterBench {
    fn new() -> FilterBench {
        let context = manylights_tests::gpu();
        let library = ShaderLibrary::from_env();
        let targets =
            RenderTargets::new(&context, (SIZE.0 as u32, SIZE.1 as u32)).expect("targets");
        let view = ViewBinding::new(&context);
        let filter = ShadowFilter::new(&context, &library, &view).expect("shadow filter");
        FilterBench {
            context,
            targets,
            view,
            filter,
        }
    }

    /// One frame of the filter (`mode`: spatial, or spatial and temporal) over `inputs`.
    fn frame(&mut self, inputs: &Inputs, view: &ViewUniform, mode: Shadows) -> Image {
        let size = self.targets.size;
        self.view.update(&self.context, view);
        clear_depth(
            &self.context,
            &self.targets.depth.view,
            plane_depth(view, inputs.distance),
        );
        self.filter
            .prepare(
                &self.context,
                &self.targets,
                manylights::visibility::FrameShadows {
                    shadows: mode,
                    follows_own_frame: true,
                },
            )
            .expect("filter prepared");
        let prepared = self.filter.prepared().expect("filter targets");
        let [unshadowed, share, normal] = prepared.inputs();
        write_rgba16(&self.context, unshadowed, size, &inputs.unshadowed);
        write_rgba16(&self.context, share, size, &inputs.share);
        write_rgba16(&self.context, normal, size, &inputs.normal);
        let mut encoder = self
            .context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let mut timer = GpuTimer::new(&self.context);
        self.context
            .scoped("a test's shadow filter frame", || {
                self.filter
                    .record(&mut encoder, &mut timer, &self.view, prepared);
            })
            .expect("the filter's passes are valid");
        self.context.queue.submit([encoder.finish()]);
        read_f32_rgba(&self.context, &self.targets.hdr.texture)
            .expect("hdr")
            .into_iter()
            .map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])])
            .collect()
    }
}

/// The tolerance at a pixel of unshadowed radiance `light` and output `value` (one
/// channel). The rows pass stores its share in half floats (within 2^-11 of a share in
/// [0, 1], where a device truncates: the largest half-float step below 1); the columns
/// pass's weighted mean keeps that bound, and the history (f32) and its clamp do not grow
/// it; the output, the unshadowed radiance times that share, is stored in half floats
/// again (2^-10 of the value); the inputs are given to both in half floats.
fn tolerance(light: f64, value: f64) -> f64 {
    light * 2f64.powi(-11) + value.abs() * 2f64.powi(-10) + 1e-6
}

/// The scene both sides are given: a shadow edge (and a soft band) across a floor facing
/// the camera, under unshadowed light that varies in colour, with four bands of normals,
/// one above another: facing the camera, turned 22 degrees (within the normal rule's 25
/// of the first band), -10 degrees (32 from the second: beyond it) and 3.4 degrees (its
/// plane leaves the depth plane by 0.29% of the distance a pixel, so the plane rule of 1%
/// ends a walk along rows between the third tap and the fourth, with room either side).
fn floor_inputs(frame: u32, distance: f32) -> Inputs {
    let (w, h) = SIZE;
    let mut unshadowed = Vec::new();
    let mut share = Vec::new();
    let mut normal = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f64, y as f64);
            unshadowed.push([
                0.6 + 0.3 * (0.3 * fx).sin(),
                0.5 + 0.2 * (0.2 * fy).cos(),
                0.4 + 0.01 * fx,
                0.0,
            ]);
            // Noise from frame to frame, as one ray a pixel gives, on a shadow edge.
            let noise = (((x * 7 + y * 13 + frame as usize * 29) % 17) as f64 / 16.0 - 0.5) * 0.3;
            let base = if x < 14 {
                0.1
            } else if x < 20 {
                0.5
            } else {
                0.9
            };
            let s = (base + noise).clamp(0.0, 1.0);
            share.push([s, (s * 0.9 + 0.05).min(1.0), s, 0.0]);
            let tilt: f64 = match y {
                0..=5 => 0.0,
                6..=11 => 22.0,
                12..=17 => -10.0,
                _ => 3.4,
            };
            let (sin, cos) = tilt.to_radians().sin_cos();
            normal.push([sin, 0.0, cos, 0.0]);
        }
    }
    Inputs {
        unshadowed: in_half_floats(&unshadowed),
        share: in_half_floats(&share),
        normal: in_half_floats(&normal),
        distance,
    }
}

/// Runs `frames` through the GPU's filter and the twin, compares every pixel, and checks
/// that the twin with each of `others` differs from the GPU somewhere.
fn check(what: &str, mode: Shadows, frames: &[Inputs], others: &[(&str, FilterDesign)]) {
    let mut bench = FilterBench::new();
    let view = test_view((SIZE.0 as u32, SIZE.1 as u32));
    let designs: Vec<FilterDesign> = std::iter::once(DESIGN)
        .chain(others.iter().map(|(_, d)| *d))
        .collect();
    let temporal = mode.temporally_accumulated();
    let mut histories: Vec<Option<Vec<Kept>>> =
        vec![temporal.then(|| vec![Kept::default(); SIZE.0 * SIZE.1]); designs.len()];
    let mut apart = vec![0usize; designs.len()];
    for (n, inputs) in frames.iter().enumerate() {
        let gpu = bench.frame(inputs, &view, mode);
        let depth = f64::from(plane_depth(&view, inputs.distance));
        for (d, design) in designs.iter().enumerate() {
            let twin = Twin {
                inputs,
                view: &view,
                depth,
                design: *design,
            };
            let (image, kept, close) = twin.frame(histories[d].as_deref());
            let bound = |i: usize, c: usize| {
                if close[i] {
                    f64::INFINITY
                } else {
                    tolerance(inputs.unshadowed[i][c], image[i][c])
                }
            };
            let (count, examples) = differing(&gpu, &image, bound, 6);
            if d == 0 {
                let closes = close.iter().filter(|c| **c).count();
                assert!(
                    closes * 10 <= close.len(),
                    "{what}, frame {n}: {closes} pixels decided within rounding"
                );
                assert_eq!(
                    count, 0,
                    "{what}, frame {n}: {count} channels differ from the twin: {examples:#?}"
                );
            } else {
                apart[d] += count;
            }
            if temporal {
                histories[d] = Some(kept);
            }
        }
    }
    for ((name, _), apart) in others.iter().zip(&apart[1..]) {
        assert!(
            *apart > 20,
            "{what}: the twin with {name} matches the GPU at all but {apart} channels: the test would not see it"
        );
    }
}

/// The spatial filter: its taps each side, its Gaussian, its normal and plane rules.
#[test]
fn the_spatial_filter_matches_its_twin_at_every_pixel() {
    let others = [
        (
            "3 taps each side",
            FilterDesign {
                radius: 3,
                ..DESIGN
            },
        ),
        (
            "9 taps each side",
            FilterDesign {
                radius: 9,
                ..DESIGN
            },
        ),
        (
            "a Gaussian of 2 pixels",
            FilterDesign {
                sigma: 2.0,
                ..DESIGN
            },
        ),
        (
            "a Gaussian of 4.5 pixels",
            FilterDesign {
                sigma: 4.5,
                ..DESIGN
            },
        ),
        (
            "normals within 37 degrees",
            FilterDesign {
                normal_cos: 0.8,
                ..DESIGN
            },
        ),
        (
            "normals within 18 degrees",
            FilterDesign {
                normal_cos: 0.95,
                ..DESIGN
            },
        ),
        (
            "planes within 0.5%",
            FilterDesign {
                plane_tolerance: 0.005,
                ..DESIGN
            },
        ),
        (
            "planes within 2%",
            FilterDesign {
                plane_tolerance: 0.02,
                ..DESIGN
            },
        ),
    ];
    check(
        "the spatial filter",
        Shadows::RaysSpatial(1),
        &[floor_inputs(0, 3.0)],
        &others,
    );
}

/// The history: a running mean of 16 frames' shares, dropped where the unshadowed light
/// changed by more than 5%, held within 0.15 of this frame's share.
#[test]
fn the_shadow_history_matches_its_twin_frame_by_frame() {
    let mut frames: Vec<Inputs> = (0..24).map(|n| floor_inputs(n, 3.0)).collect();
    // Frames 10 to 13: the light changes by 3% in the left third (kept) and by 8% in the
    // right third (dropped); frame 18 on, the share jumps by 0.1 in the top half (within
    // the margin) and by 0.4 in the bottom half (beyond it).
    for (n, frame) in frames.iter_mut().enumerate() {
        for y in 0..SIZE.1 {
            for x in 0..SIZE.0 {
                let i = y * SIZE.0 + x;
                if (10..14).contains(&n) {
                    let scale = if x < 13 {
                        1.03
                    } else if x >= 27 {
                        1.08
                    } else {
                        1.0
                    };
                    frame.unshadowed[i] = frame.unshadowed[i].map(|c| c * scale);
                }
                if n >= 18 {
                    let jump = if y < SIZE.1 / 2 { 0.1 } else { -0.4 };
                    for c in 0..3 {
                        frame.share[i][c] = (frame.share[i][c] + jump).clamp(0.0, 1.0);
                    }
                }
            }
        }
        let rounded = in_half_floats(&frame.unshadowed);
        frame.unshadowed = rounded;
        let rounded = in_half_floats(&frame.share);
        frame.share = rounded;
    }
    let others = [
        (
            "a running mean of 8 frames",
            FilterDesign {
                history_frames: 8.0,
                ..DESIGN
            },
        ),
        (
            "a running mean of 32 frames",
            FilterDesign {
                history_frames: 32.0,
                ..DESIGN
            },
        ),
        (
            "a light rule of 2%",
            FilterDesign {
                light_change: 0.02,
                ..DESIGN
            },
        ),
        (
            "a light rule of 10%",
            FilterDesign {
                light_change: 0.10,
                ..DESIGN
            },
        ),
        (
            "a margin of 0.05",
            FilterDesign {
                history_margin: 0.05,
                ..DESIGN
            },
        ),
        (
            "a margin of 0.5",
            FilterDesign {
                history_margin: 0.5,
                ..DESIGN
            },
        ),
    ];
    check("the history", Shadows::RaysTemporal(1), &frames, &others);
}
