//! Bloom against its f64 twin, pixel by pixel: every defining parameter of the chain (the
//! first step's firefly weighting, the down chain's 13-tap filter, the up chain's tent and
//! spread, the blend by strength) is held by one comparison, since the twin computes each
//! from the design's own values and a change to any of them moves pixels far beyond the
//! tolerance. The test also shows that, for the values the code does not use, the twin
//! would not match.

use manylights_gpu::bloom::{BLOOM_SPREAD, bloom_levels};

use manylights_tests::synthetic::{Image, differing};

use super::passes::PostBench;

/// The design's values (docs/architecture/post.md): Karis's average on the first step,
/// how much of each level is the coarser levels'.
#[derive(Debug, Clone, Copy)]
struct BloomDesign {
    karis: bool,
    spread: f64,
    /// The down chain's 13 taps as five 2x2 boxes: the centre box's weight (each corner
    /// box has a quarter of the rest).
    centre_box: f64,
}

const DESIGN: BloomDesign = BloomDesign {
    karis: true,
    spread: 0.7,
    centre_box: 0.5,
};

/// An image of `size` and its values, sampled as the GPU's linear-clamp sampler does
/// (exactly here: every tap of the chain falls on a texel's corner, centre or quarter at
/// the even sizes the test uses, which 8 bits of sub-texel precision represent exactly).
struct Level {
    size: (usize, usize),
    texels: Image,
}

impl Level {
    fn texel(&self, x: i64, y: i64) -> [f64; 3] {
        let x = x.clamp(0, self.size.0 as i64 - 1) as usize;
        let y = y.clamp(0, self.size.1 as i64 - 1) as usize;
        self.texels[y * self.size.0 + x]
    }

    /// Bilinear sample at texture coordinate `uv`.
    fn sample(&self, u: f64, v: f64) -> [f64; 3] {
        let x = u * self.size.0 as f64 - 0.5;
        let y = v * self.size.1 as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let mut out = [0.0; 3];
        for (dx, dy, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let t = self.texel(x0 + dx, y0 + dy);
            for c in 0..3 {
                out[c] += w * t[c];
            }
        }
        out
    }

    /// `self` sampled at `uv` moved by `offset` of its texels.
    fn tap(&self, u: f64, v: f64, offset: (f64, f64)) -> [f64; 3] {
        self.sample(
            u + offset.0 / self.size.0 as f64,
            v + offset.1 / self.size.1 as f64,
        )
    }
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

fn mean(values: &[[f64; 3]]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for v in values {
        for c in 0..3 {
            out[c] += v[c] / values.len() as f64;
        }
    }
    out
}

/// A level of `size` whose texel (x, y) is `f` of its centre's texture coordinate.
fn level_from(size: (usize, usize), f: impl Fn(f64, f64) -> [f64; 3]) -> Level {
    let mut texels = Vec::with_capacity(size.0 * size.1);
    for y in 0..size.1 {
        for x in 0..size.0 {
            texels.push(f(
                (x as f64 + 0.5) / size.0 as f64,
                (y as f64 + 0.5) / size.1 as f64,
            ));
        }
    }
    Level { size, texels }
}

/// The 13-tap downsample of `source` at `uv` (bloom.wgsl's `downsample`).
fn downsample(source: &Level, u: f64, v: f64, karis: bool, design: BloomDesign) -> [f64; 3] {
    let t = |x: f64, y: f64| source.tap(u, v, (x, y));
    let (a, b, c) = (t(-2.0, -2.0), t(0.0, -2.0), t(2.0, -2.0));
    let (d, e, f) = (t(-2.0, 0.0), t(0.0, 0.0), t(2.0, 0.0));
    let (g, h, i) = (t(-2.0, 2.0), t(0.0, 2.0), t(2.0, 2.0));
    let (j, k, l, m) = (t(-1.0, -1.0), t(1.0, -1.0), t(-1.0, 1.0), t(1.0, 1.0));
    let boxes = [
        mean(&[j, k, l, m]),
        mean(&[a, b, d, e]),
        mean(&[b, c, e, f]),
        mean(&[d, e, g, h]),
        mean(&[e, f, h, i]),
    ];
    let mut sum = [0.0; 3];
    let mut total = 0.0;
    for (n, bx) in boxes.iter().enumerate() {
        let mut weight = if n == 0 {
            design.centre_box
        } else {
            (1.0 - design.centre_box) / 4.0
        };
        if karis {
            // Exposure 1 (the bench's exposure state).
            weight /= 1.0 + luminance(*bx);
        }
        for c in 0..3 {
            sum[c] += bx[c] * weight;
        }
        total += weight;
    }
    sum.map(|s| s / total)
}

/// The 3x3 tent of `source` around `uv`.
fn tent(source: &Level, u: f64, v: f64) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for dy in -1i32..=1 {
        for dx in -1i32..=1 {
            let weight = f64::from((2 - dx.abs()) * (2 - dy.abs()));
            let t = source.tap(u, v, (f64::from(dx), f64::from(dy)));
            for c in 0..3 {
                sum[c] += t[c] * weight / 16.0;
            }
        }
    }
    sum
}

/// `own + amount * (other - own)` per channel.
fn blend(own: [f64; 3], other: [f64; 3], amount: f64) -> [f64; 3] {
    [0, 1, 2].map(|c| own[c] + amount * (other[c] - own[c]))
}

/// The bloomed frame, as the chain computes it with `design`'s values.
fn bloom_twin(frame: &Level, strength: f64, design: BloomDesign) -> Image {
    let levels = bloom_levels((frame.size.0 as u32, frame.size.1 as u32));
    let mut down: Vec<Level> = Vec::new();
    for (n, &(w, h)) in levels.iter().enumerate() {
        let source = if n == 0 { frame } else { &down[n - 1] };
        let level = level_from((w as usize, h as usize), |u, v| {
            downsample(source, u, v, n == 0 && design.karis, design)
        });
        down.push(level);
    }
    // U of the coarsest level is its D; each finer U blends its D toward the coarser U.
    let mut up = down.pop().expect("at least one level");
    while let Some(own) = down.pop() {
        up = level_from(own.size, |u, v| {
            let x = ((u * own.size.0 as f64) as usize).min(own.size.0 - 1);
            let y = ((v * own.size.1 as f64) as usize).min(own.size.1 - 1);
            blend(
                own.texels[y * own.size.0 + x],
                tent(&up, u, v),
                design.spread,
            )
        });
    }
    level_from(frame.size, |u, v| {
        let x = ((u * frame.size.0 as f64) as usize).min(frame.size.0 - 1);
        let y = ((v * frame.size.1 as f64) as usize).min(frame.size.1 - 1);
        blend(
            frame.texels[y * frame.size.0 + x],
            tent(&up, u, v),
            strength,
        )
    })
    .texels
}

/// The tolerance at a pixel whose twin value is `value`. Every weight of the chain is
/// positive and every value non-negative, so an error relative to a texel's value stays
/// relative through each weighted mean; each of the chain's steps (the first, two more
/// down, two up, the composite at 128x64) adds its store's rounding to half floats, at
/// most one unit in the last place (2^-10 of the value where a device truncates), and the
/// firefly weighting's weights move by at most the same relative amount, which doubles the
/// first step's. Seven units in all, plus the smallest half-float step for texels of zero.
fn tolerance(value: [f64; 3]) -> f64 {
    let largest = value.into_iter().fold(0.0, f64::max);
    7.0 * 2f64.powi(-10) * largest + 2f64.powi(-24)
}

/// The test frame: a dim, coloured gradient with two fireflies (single bright texels, one
/// far brighter than the other, as TAA's jitter leaves them) and a bright bar.
fn test_frame(size: (usize, usize)) -> Level {
    let mut frame = level_from(size, |u, v| {
        [0.05 + 0.2 * u, 0.1 + 0.1 * v, 0.15 * (1.0 - u) * v]
    });
    let (w, _) = size;
    frame.texels[20 * w + 37] = [500.0, 400.0, 300.0];
    frame.texels[41 * w + 90] = [8.0, 16.0, 4.0];
    for x in 60..76 {
        frame.texels[10 * w + x] = [3.0, 2.0, 1.0];
    }
    frame
}

#[test]
fn bloom_matches_its_f64_twin_at_every_pixel_and_no_other_design_does() {
    let size = (128usize, 64usize);
    let mut bench = PostBench::new((size.0 as u32, size.1 as u32));
    let mut frame = test_frame(size);
    // What the GPU is given: the frame rounded to half floats.
    for texel in &mut frame.texels {
        *texel = texel.map(|c| half::f16::from_f64(c).to_f64());
    }
    for strength in [1.0, 0.5] {
        bench.write_frame(&frame.texels, 1.0);
        let gpu = bench.bloom_frame(strength as f32);
        let twin = bloom_twin(&frame, strength, DESIGN);
        let bloomed = gpu
            .iter()
            .zip(&frame.texels)
            .filter(|(a, b)| (a[1] - b[1]).abs() > tolerance(**b))
            .count();
        assert!(
            bloomed > gpu.len() / 2,
            "bloom {strength} moved only {bloomed} pixels: the frame does not test it"
        );
        let (count, examples) = differing(&gpu, &twin, |i, _| tolerance(twin[i]), 8);
        assert_eq!(
            count, 0,
            "bloom {strength}: {count} channels differ from the f64 twin: {examples:#?}"
        );
        // The firefly, by the design's weighting: the bloom around it (beyond its own
        // texel) holds far less than the firefly's light, which an unweighted chain would
        // spread whole.
        let others = [
            (
                "no firefly weighting",
                BloomDesign {
                    karis: false,
                    ..DESIGN
                },
            ),
            (
                "spread 0.6",
                BloomDesign {
                    spread: 0.6,
                    ..DESIGN
                },
            ),
            (
                "spread 0.8",
                BloomDesign {
                    spread: 0.8,
                    ..DESIGN
                },
            ),
            (
                "a down filter of equal boxes",
                BloomDesign {
                    centre_box: 0.2,
                    ..DESIGN
                },
            ),
        ];
        for (what, design) in others {
            let other = bloom_twin(&frame, strength, design);
            let (count, _) = differing(&gpu, &other, |i, _| tolerance(twin[i]), 0);
            assert!(
                count > 100,
                "bloom {strength}: a chain with {what} is within the tolerance of the GPU's \
                 at all but {count} channels: the test would not see that change"
            );
        }
        let other_strength = bloom_twin(&frame, strength * 1.1, DESIGN);
        let (count, _) = differing(&gpu, &other_strength, |i, _| tolerance(twin[i]), 0);
        assert!(
            count > 100,
            "bloom {strength}: strength {} is within the tolerance at all but {count} channels",
            strength * 1.1
        );
    }
    assert!((f64::from(BLOOM_SPREAD) - DESIGN.spread).abs() < 1e-6);
}
