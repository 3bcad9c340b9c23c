//! The blotch measure: the part of a frame's error that is neither a pixel's noise nor a
//! seam of the cluster grid, but low-frequency structure a few tens of pixels wide (a
//! shadow filter spreading one ray's noise into patches, a history cut short, a far
//! field's cut wrong over a wall). A mean error cannot tell a frame of fine grain from one
//! of patches of the same energy; FLIP sees both as error; the seam measure sees only
//! steps along cluster boundaries.
//!
//! The luminance error against the full-frame reference is averaged over boxes of
//! [`BLOTCH_SCALES`] pixels on smooth surfaces, relative to the box's mean luminance. If
//! every pixel's error were independent of its neighbours' (noise, the reference's
//! included), a box's mean would have the expected square `sum(e^2) / n^2`; what the
//! boxes' means hold beyond that (and beyond twice its chance deviation) is structure at
//! that scale. The measure is the root of that excess at the worst scale: a relative
//! luminance error, 0 for a frame whose error is only noise (a noise-free exact method
//! against its exact reference is at the floor), 0.03 for patches 3% too bright or too
//! dark. The frame's relative bias is taken out first: a uniform bias is the mean error's
//! business, not a blotch.

use super::image_metrics::{SurfaceGeometry, luminance};

/// The box widths, in pixels, over which the error is averaged: from the 8x8 tiles the
/// lighting shares lists in to the 64-pixel patches the shadowed frames show.
pub const BLOTCH_SCALES: [u32; 4] = [8, 16, 32, 64];

/// A box darker than this (mean luminance) is not judged: an error relative to nothing
/// means nothing (the background, unlit corners).
const DARK_LUMINANCE: f64 = 1e-6;

/// The fewest judged pixels a box needs, as a fraction of its area, to be counted: a box
/// at a silhouette holding a handful of pixels would say more of them than of the frame.
const LEAST_BOX_COVER: f64 = 0.25;

/// A frame's blotch measure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlotchMeasure {
    /// The root of the error's box-mean energy beyond what independent per-pixel error
    /// leaves (and beyond twice that excess's chance deviation), at the worst of
    /// [`BLOTCH_SCALES`] (relative luminance).
    pub blotch: f64,
    /// The box width that worst scale is.
    pub scale: u32,
    /// Per scale of [`BLOTCH_SCALES`]: (the boxes' mean square, what independent error of
    /// the same per-pixel size would give).
    pub energies: [(f64, f64); 4],
}

/// Sums over any rectangle of a grid of values, from one pass (a summed-area table).
struct BoxSums {
    width: usize,
    table: Vec<f64>,
}

impl BoxSums {
    fn new(values: &[f64], (width, height): (usize, usize)) -> Self {
        let stride = width + 1;
        let mut table = vec![0.0; stride * (height + 1)];
        for y in 0..height {
            let mut row = 0.0;
            for x in 0..width {
                row += values[y * width + x];
                table[(y + 1) * stride + x + 1] = table[y * stride + x + 1] + row;
            }
        }
        Self { width, table }
    }

    /// The sum over columns `x0..x1` and rows `y0..y1`.
    fn sum(&self, (x0, x1): (usize, usize), (y0, y1): (usize, usize)) -> f64 {
        let stride = self.width + 1;
        let at = |x: usize, y: usize| self.table[y * stride + x];
        at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0)
    }
}

/// The boxes' energy beyond what independent error leaves, less twice the chance
/// deviation of that excess: with `boxes` independent boxes (the judged pixels over a
/// box's area), the mean of their squares strays from its expectation by about
/// `sqrt(2 / boxes)` of it (a chi-square's spread). Without this a small or very noisy
/// frame (one unfiltered ray a pixel at 128x96) would measure its own sampling error as a
/// blotch at the largest boxes, of which it holds only a few.
fn excess_beyond_chance((boxed, independent): (f64, f64), boxes: f64) -> f64 {
    if boxes <= 0.0 {
        return 0.0;
    }
    boxed - independent - 2.0 * independent * (2.0 / boxes).sqrt()
}

/// The blotch measure of `image` against `reference` (linear RGB) over the pixels
/// `geometry` shows on a smooth surface; `None` where no box is covered enough to judge.
///
/// Each box's error is relative to the box's own mean luminance (the mean of the frame's
/// luminance error over the mean of the reference's), not a mean of each pixel's relative
/// error: a pixel's relative error under one shadow ray is +-1 or more where the light is
/// partly hidden, and any bound on it would turn noise into a bias that follows the
/// shadows' shape, a structure the measure would count.
pub fn blotch_measure(
    reference: &[[f32; 4]],
    image: &[[f32; 4]],
    geometry: &SurfaceGeometry,
) -> Option<BlotchMeasure> {
    let (width, height) = (geometry.size.0 as usize, geometry.size.1 as usize);
    let smooth = geometry.smooth_pixels();
    // Per judged pixel: the reference's luminance and the frame's error from it.
    let judged: Vec<Option<(f64, f64)>> = (reference.iter().zip(image).zip(&smooth))
        .map(|((want, got), smooth)| {
            let (want, got) = (luminance(*want), luminance(*got));
            (*smooth && want.is_finite() && got.is_finite()).then_some((want, got - want))
        })
        .collect();
    let (reference_sum, error_sum) = judged
        .iter()
        .flatten()
        .fold((0.0, 0.0), |(r, e), (want, error)| (r + want, e + error));
    if reference_sum <= 0.0 {
        return None;
    }
    // The frame's relative bias, taken out: it is the mean error's business.
    let bias = error_sum / reference_sum;
    let size = (width, height);
    let sums_of = |value: fn((f64, f64), f64) -> f64| {
        let values: Vec<f64> = (judged.iter())
            .map(|pixel| pixel.map_or(0.0, |pixel| value(pixel, bias)))
            .collect();
        BoxSums::new(&values, size)
    };
    let cover_sums = sums_of(|_, _| 1.0);
    let reference_sums = sums_of(|(want, _), _| want);
    let error_sums = sums_of(|(want, error), bias| error - bias * want);
    let square_sums = sums_of(|(want, error), bias| (error - bias * want).powi(2));
    let mut energies = [(0.0, 0.0); 4];
    let mut excesses = Vec::with_capacity(BLOTCH_SCALES.len());
    let mut counted_boxes = 0;
    for (energy, scale) in energies.iter_mut().zip(BLOTCH_SCALES) {
        let half = scale as usize / 2;
        let least = LEAST_BOX_COVER * f64::from(scale * scale);
        let (mut boxed, mut independent, mut boxes) = (0.0, 0.0, 0usize);
        for (i, pixel) in judged.iter().enumerate() {
            if pixel.is_none() {
                continue;
            }
            let (x, y) = (i % width, i / width);
            let columns = (x.saturating_sub(half), (x + half).min(width));
            let rows = (y.saturating_sub(half), (y + half).min(height));
            let n = cover_sums.sum(columns, rows);
            let brightness = reference_sums.sum(columns, rows) / n;
            if n < least || brightness <= DARK_LUMINANCE {
                continue;
            }
            let box_error = error_sums.sum(columns, rows) / n / brightness;
            boxed += box_error * box_error;
            independent += square_sums.sum(columns, rows) / (n * n) / (brightness * brightness);
            boxes += 1;
        }
        if boxes > 0 {
            *energy = (boxed / boxes as f64, independent / boxes as f64);
        }
        counted_boxes += boxes;
        excesses.push(excess_beyond_chance(
            *energy,
            boxes as f64 / f64::from(scale * scale),
        ));
    }
    if counted_boxes == 0 {
        return None;
    }
    let (worst, excess) = excesses
        .iter()
        .enumerate()
        .max_by(|(_, a), (_, b)| a.total_cmp(b))?;
    Some(BlotchMeasure {
        blotch: excess.max(0.0).sqrt(),
        scale: BLOTCH_SCALES[worst],
        energies,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use manylights::lights::animation::pcg_hash;

    const SIZE: (u32, u32) = (160, 96);

    /// One flat surface facing the camera over the whole frame.
    fn wall() -> SurfaceGeometry {
        let pixels = (SIZE.0 * SIZE.1) as usize;
        SurfaceGeometry {
            size: SIZE,
            covered: vec![true; pixels],
            depth: vec![5.0; pixels],
            normal: vec![Vec3::Z; pixels],
        }
    }

    /// A uniform random number in [-0.5, 0.5) from a pixel's index and a seed.
    fn noise(i: usize, seed: u32) -> f64 {
        let hash = pcg_hash(pcg_hash(i as u32) ^ seed);
        f64::from(hash >> 8) / f64::from(1u32 << 24) - 0.5
    }

    /// A reference with a gradient, and a frame off it by `grain` of independent noise and
    /// `blotch` of a pattern 40 pixels across (relative), with `bias` besides.
    fn frames(grain: f64, blotch: f64, bias: f64) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        let (reference, image) = (0..(SIZE.0 * SIZE.1) as usize)
            .map(|i| {
                let (x, y) = ((i % SIZE.0 as usize) as f64, (i / SIZE.0 as usize) as f64);
                let pattern = (x * std::f64::consts::TAU / 40.0).sin()
                    * (y * std::f64::consts::TAU / 40.0).cos();
                let want = 1.0 + 0.01 * x + 0.02 * y;
                let got = want * (1.0 + grain * noise(i, 7) + blotch * pattern + bias);
                ([want as f32; 4], [got as f32; 4])
            })
            .unzip();
        (reference, image)
    }

    fn measure((reference, image): (Vec<[f32; 4]>, Vec<[f32; 4]>)) -> BlotchMeasure {
        blotch_measure(&reference, &image, &wall()).expect("a judged frame")
    }

    #[test]
    fn an_exact_frame_and_a_frame_of_grain_are_at_the_floor() {
        let exact = measure(frames(0.0, 0.0, 0.0));
        assert_eq!(exact.blotch, 0.0, "{exact:?}");
        // 10% grain (std 2.9%): its box means are what independent error leaves, up to
        // their sampling error (~sqrt(2 / boxes) of the energy, boxes ~ 15,000 pixels).
        let grain = measure(frames(0.1, 0.0, 0.0));
        assert!(grain.blotch < 0.003, "{grain:?}");
    }

    #[test]
    fn a_blotch_is_measured_at_its_size_whatever_the_grain() {
        for grain in [0.0, 0.1] {
            // A pattern of amplitude 3%: its box means at 8 pixels keep most of it (rms of
            // sin x cos is half the amplitude: 1.5%).
            let measure = measure(frames(grain, 0.03, 0.0));
            assert!(
                (0.010..=0.016).contains(&measure.blotch),
                "grain {grain}: {measure:?}"
            );
            assert!(measure.scale <= 16, "{measure:?}");
        }
        // A uniform bias is not a blotch.
        assert!(measure(frames(0.1, 0.0, 0.05)).blotch < 0.003);
    }

    #[test]
    fn only_smooth_judged_pixels_count() {
        let mut geometry = wall();
        // The right half a surface far behind, left uncovered: pixels at the step are left
        // out, and a blotch only on the left half is still seen.
        for (i, depth) in geometry.depth.iter_mut().enumerate() {
            if i % SIZE.0 as usize >= SIZE.0 as usize / 2 {
                *depth = 50.0;
                geometry.covered[i] = false;
            }
        }
        let (reference, mut image) = frames(0.05, 0.0, 0.0);
        for (i, pixel) in image.iter_mut().enumerate() {
            if i % SIZE.0 as usize >= SIZE.0 as usize / 2 {
                *pixel = [f32::NAN; 4];
            } else if (i / SIZE.0 as usize / 24).is_multiple_of(2) {
                *pixel = pixel.map(|c| c * 1.04);
            }
        }
        let measured = blotch_measure(&reference, &image, &geometry).unwrap();
        assert!(measured.blotch > 0.01, "{measured:?}");
        let dark = vec![[0.0; 4]; reference.len()];
        assert_eq!(blotch_measure(&dark, &dark, &geometry), None);
    }
}
