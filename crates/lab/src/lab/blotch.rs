//! The blotch measure: the part of a frame's error that is neither a pixel's noise nor a
//! seam of the cluster grid, but low-frequency structure a few tens of pixels wide (a
//! shadow filter spreading one ray's noise into patches, a history cut short, a far
//! field's cut wrong over a wall). A mean error cannot tell a frame of fine grain from one
//! of patches of the same energy; FLIP sees both as error; the seam measure sees only
//! steps along cluster boundaries.
//!
//! The error (relative luminance, against the full-frame reference) is averaged over
//! boxes of [`BLOTCH_SCALES`] pixels on smooth surfaces. If every pixel's error were
//! independent of its neighbours' (noise, the reference's included), a box's mean would
//! have the expected square `sum(e^2) / n^2`; what the boxes' means hold beyond that is
//! structure at that scale. The measure is the root of that excess at the worst scale: a
//! relative luminance error, 0 for a frame whose error is only noise (a noise-free exact
//! method against its exact reference is at the floor), 0.03 for patches 3% too bright or
//! too dark. The frame's mean error is taken out first: a uniform bias is the mean error's
//! business, not a blotch.

use super::image_metrics::SurfaceGeometry;

/// The box widths, in pixels, over which the error is averaged: from the 8x8 tiles the
/// lighting shares lists in to the 64-pixel patches the shadowed frames show.
pub const BLOTCH_SCALES: [u32; 4] = [8, 16, 32, 64];

/// The largest relative error a pixel counts with: a pixel off by more than its own value
/// is wrong whatever its size, and one near-black pixel must not outweigh a wall.
const LARGEST_COUNTED_ERROR: f64 = 1.0;

/// The fewest judged pixels a box needs, as a fraction of its area, to be counted: a box
/// at a silhouette holding a handful of pixels would say more of them than of the frame.
const LEAST_BOX_COVER: f64 = 0.25;

/// A frame's blotch measure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlotchMeasure {
    /// The root of the error's box-mean energy beyond what independent per-pixel error
    /// leaves, at the worst of [`BLOTCH_SCALES`] (relative luminance).
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

/// The blotch measure of `errors` ([`super::image_metrics::relative_luminance_errors`])
/// over the pixels `geometry` shows on a smooth surface; `None` where no box is covered
/// enough to judge.
pub fn blotch_measure(errors: &[Option<f64>], geometry: &SurfaceGeometry) -> Option<BlotchMeasure> {
    let (width, height) = (geometry.size.0 as usize, geometry.size.1 as usize);
    let smooth = geometry.smooth_pixels();
    let judged: Vec<Option<f64>> = errors
        .iter()
        .zip(&smooth)
        .map(|(error, smooth)| {
            error
                .filter(|_| *smooth)
                .map(|e| e.clamp(-LARGEST_COUNTED_ERROR, LARGEST_COUNTED_ERROR))
        })
        .collect();
    let count = judged.iter().flatten().count();
    if count == 0 {
        return None;
    }
    let mean = judged.iter().flatten().sum::<f64>() / count as f64;
    let cover: Vec<f64> = judged
        .iter()
        .map(|e| f64::from(u8::from(e.is_some())))
        .collect();
    let centred: Vec<f64> = judged.iter().map(|e| e.map_or(0.0, |e| e - mean)).collect();
    let squares: Vec<f64> = centred.iter().map(|e| e * e).collect();
    let size = (width, height);
    let (cover_sums, error_sums, square_sums) = (
        BoxSums::new(&cover, size),
        BoxSums::new(&centred, size),
        BoxSums::new(&squares, size),
    );
    let mut energies = [(0.0, 0.0); 4];
    let mut counted_boxes = 0;
    for (energy, scale) in energies.iter_mut().zip(BLOTCH_SCALES) {
        let half = scale as usize / 2;
        let least = LEAST_BOX_COVER * f64::from(scale * scale);
        let (mut boxed, mut independent, mut boxes) = (0.0, 0.0, 0usize);
        for (i, error) in judged.iter().enumerate() {
            if error.is_none() {
                continue;
            }
            let (x, y) = (i % width, i / width);
            let columns = (x.saturating_sub(half), (x + half).min(width));
            let rows = (y.saturating_sub(half), (y + half).min(height));
            let n = cover_sums.sum(columns, rows);
            if n < least {
                continue;
            }
            let box_mean = error_sums.sum(columns, rows) / n;
            boxed += box_mean * box_mean;
            independent += square_sums.sum(columns, rows) / (n * n);
            boxes += 1;
        }
        if boxes > 0 {
            *energy = (boxed / boxes as f64, independent / boxes as f64);
        }
        counted_boxes += boxes;
    }
    if counted_boxes == 0 {
        return None;
    }
    let (worst, &(boxed, independent)) = energies
        .iter()
        .enumerate()
        .max_by(|(_, a), (_, b)| (a.0 - a.1).total_cmp(&(b.0 - b.1)))?;
    Some(BlotchMeasure {
        blotch: (boxed - independent).max(0.0).sqrt(),
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

    /// A reference with a gradient, and frames off it by `grain` of independent noise and
    /// `blotch` of a pattern 40 pixels across.
    fn errors(grain: f64, blotch: f64) -> Vec<Option<f64>> {
        (0..(SIZE.0 * SIZE.1) as usize)
            .map(|i| {
                let (x, y) = ((i % SIZE.0 as usize) as f64, (i / SIZE.0 as usize) as f64);
                let pattern = (x * std::f64::consts::TAU / 40.0).sin()
                    * (y * std::f64::consts::TAU / 40.0).cos();
                Some(grain * noise(i, 7) + blotch * pattern)
            })
            .collect()
    }

    #[test]
    fn an_exact_frame_and_a_frame_of_grain_are_at_the_floor() {
        let exact = blotch_measure(&errors(0.0, 0.0), &wall()).unwrap();
        assert_eq!(exact.blotch, 0.0, "{exact:?}");
        // 10% grain (std 2.9%): its box means are what independent error leaves, up to
        // their sampling error (~sqrt(2 / boxes) of the energy, boxes ~ 15,000 pixels).
        let grain = blotch_measure(&errors(0.1, 0.0), &wall()).unwrap();
        assert!(grain.blotch < 0.003, "{grain:?}");
    }

    #[test]
    fn a_blotch_is_measured_at_its_size_whatever_the_grain() {
        for grain in [0.0, 0.1] {
            // A pattern of amplitude 3%: its box means at 8 pixels keep most of it (rms of
            // sin x cos is half the amplitude: 1.5%).
            let measure = blotch_measure(&errors(grain, 0.03), &wall()).unwrap();
            assert!(
                (0.010..=0.016).contains(&measure.blotch),
                "grain {grain}: {measure:?}"
            );
            assert!(measure.scale <= 16, "{measure:?}");
        }
        // A uniform bias is not a blotch.
        let biased: Vec<Option<f64>> = errors(0.1, 0.0)
            .into_iter()
            .map(|e| e.map(|e| e + 0.05))
            .collect();
        assert!(blotch_measure(&biased, &wall()).unwrap().blotch < 0.003);
    }

    #[test]
    fn only_smooth_judged_pixels_count() {
        let mut geometry = wall();
        // The right half a surface far behind: pixels at the step are left out, and a
        // blotch only on the left half is still seen.
        for (i, depth) in geometry.depth.iter_mut().enumerate() {
            if i % SIZE.0 as usize >= SIZE.0 as usize / 2 {
                *depth = 50.0;
            }
        }
        let mut frame = errors(0.05, 0.0);
        for (i, error) in frame.iter_mut().enumerate() {
            if i % SIZE.0 as usize >= SIZE.0 as usize / 2 {
                *error = None;
            } else if (i / SIZE.0 as usize / 24).is_multiple_of(2) {
                *error = error.map(|e| e + 0.04);
            }
        }
        let measure = blotch_measure(&frame, &geometry).unwrap();
        assert!(measure.blotch > 0.01, "{measure:?}");
        let nothing = vec![None; frame.len()];
        assert_eq!(blotch_measure(&nothing, &geometry), None);
    }
}
