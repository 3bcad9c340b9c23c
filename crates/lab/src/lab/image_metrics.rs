//! Whole-frame metrics that see what a mean over sampled pixels cannot: where the error
//! sits (an error map) and whether it jumps along the cluster grid (the seam measure);
//! the blotch measure, of the error's low-frequency structure, is in `blotch.rs`.
//!
//! Both read the frame's relative luminance error against a full-frame reference (the
//! GPU reference or naive), pixel by pixel.

use glam::{DVec3, Vec3};

/// Luminance below which a reference pixel is left out of relative errors: the
/// background and unlit corners, where a relative error means nothing.
const DARK_LUMINANCE: f64 = 1e-6;

/// Rec. 709 luminance of linear RGB.
pub(super) fn luminance(rgb: [f32; 4]) -> f64 {
    0.2126 * f64::from(rgb[0]) + 0.7152 * f64::from(rgb[1]) + 0.0722 * f64::from(rgb[2])
}

/// The signed relative luminance error of `image` against `reference` at each pixel,
/// `None` where the reference is dark (or not a number).
pub fn relative_luminance_errors(reference: &[[f32; 4]], image: &[[f32; 4]]) -> Vec<Option<f64>> {
    reference
        .iter()
        .zip(image)
        .map(|(want, got)| {
            let want = luminance(*want);
            let error = (luminance(*got) - want) / want;
            (want > DARK_LUMINANCE && error.is_finite()).then_some(error)
        })
        .collect()
}

/// The signed luminance error of `image` against `reference` at each pixel, and the
/// reference's mean luminance: absolute errors, for measures that must not blow up in
/// the dark corners a relative error divides by nearly nothing.
pub fn luminance_errors(reference: &[[f32; 4]], image: &[[f32; 4]]) -> (Vec<f64>, f64) {
    let errors = reference
        .iter()
        .zip(image)
        .map(|(want, got)| luminance(*got) - luminance(*want))
        .collect();
    let mean = reference.iter().map(|c| luminance(*c)).sum::<f64>() / reference.len().max(1) as f64;
    (errors, mean)
}

/// What surface each pixel shows: whether it shows one, its view depth and unit normal
/// (from the reference's surface capture), to judge error only where a surface is smooth.
#[derive(Debug, Clone)]
pub struct SurfaceGeometry {
    pub size: (u32, u32),
    /// Per pixel: whether a surface covers it (not the background).
    pub covered: Vec<bool>,
    pub depth: Vec<f32>,
    pub normal: Vec<Vec3>,
}

impl SurfaceGeometry {
    /// The geometry of a surface capture seen from `camera`.
    pub fn from_surface(
        surface: &manylights::gpu::SurfaceImage,
        camera: &manylights::Camera,
    ) -> Self {
        let forward = camera.forward().as_dvec3();
        let eye = camera.position.as_dvec3();
        let covered = surface.position.iter().map(|p| p[3] == 1.0).collect();
        let depth = (surface.position.iter())
            .map(|position| {
                let world = surface.origin
                    + DVec3::new(position[0].into(), position[1].into(), position[2].into());
                (world - eye).dot(forward) as f32
            })
            .collect();
        let normal = (surface.normal_lobe.iter())
            .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero())
            .collect();
        Self {
            size: surface.size,
            covered,
            depth,
            normal,
        }
    }

    /// Whether pixels `a` and `b` show one smooth surface: depths within 2% and normals
    /// within about 18 degrees. Pairs across a geometric edge step in any image, seams or
    /// not, and depth slices change more often there: they would count as seams.
    fn same_surface(&self, a: usize, b: usize) -> bool {
        let (da, db) = (self.depth[a], self.depth[b]);
        self.covered[a]
            && self.covered[b]
            && (da - db).abs() <= 0.02 * da.abs().max(db.abs())
            && self.normal[a].dot(self.normal[b]) >= 0.95
    }

    /// Per pixel: whether it is covered and one smooth surface with its covered
    /// neighbours to the right and below (not at a geometric edge).
    pub fn smooth_pixels(&self) -> Vec<bool> {
        let (width, height) = (self.size.0 as usize, self.size.1 as usize);
        (0..width * height)
            .map(|i| {
                let (x, y) = (i % width, i / width);
                let smooth_to = |j: usize| !self.covered[j] || self.same_surface(i, j);
                self.covered[i]
                    && (x + 1 == width || smooth_to(i + 1))
                    && (y + 1 == height || smooth_to(i + width))
            })
            .collect()
    }
}

/// Which surface and which cluster each pixel shows: what the seam measure splits pixel
/// pairs by.
#[derive(Debug, Clone)]
pub struct PixelClusters {
    /// Per pixel: the flat cluster index, or `None` over the background.
    pub cluster: Vec<Option<u32>>,
    /// Per pixel: the surface, to leave out pairs across a geometric edge.
    pub geometry: SurfaceGeometry,
}

impl PixelClusters {
    /// The clusters of `geometry`'s pixels under `grid`.
    pub fn new(geometry: SurfaceGeometry, grid: &manylights::cluster::ClusterGrid) -> Self {
        let width = geometry.size.0;
        let cluster = (geometry.covered.iter().zip(&geometry.depth).enumerate())
            .map(|(i, (covered, depth))| {
                let (x, y) = (
                    (i as u32 % width) as f32 + 0.5,
                    (i as u32 / width) as f32 + 0.5,
                );
                covered.then(|| grid.flat_index(grid.cluster_of_fragment(x, y, *depth)))
            })
            .collect();
        Self { cluster, geometry }
    }
}

/// The seam measure of a frame: the mean step of the relative luminance error between
/// neighbouring pixels in different clusters (across a tile or a depth-slice boundary),
/// over the mean step of the pairs beside them, just before and just after the boundary
/// in the same direction, each within one cluster. 1.0: the error does not care where
/// clusters end; a frame whose clusters disagree shows blocks, and the ratio grows with
/// their steps. Beside, not anywhere: depth slices end more often where depth changes
/// fast (grazing surfaces), where the error's gradient is steep too, so a step anywhere
/// else would call a smooth gradient a seam. Every pair lies on one smooth surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeamMeasure {
    pub ratio: f64,
    /// Mean |step| across cluster boundaries, and beside them within clusters.
    pub across: f64,
    pub beside: f64,
    /// Boundary crossings counted.
    pub crossings: usize,
}

/// The seam measure of `errors` ([`relative_luminance_errors`]) over `clusters`; `None`
/// without a crossing or without any step beside them.
pub fn seam_measure(errors: &[Option<f64>], clusters: &PixelClusters) -> Option<SeamMeasure> {
    let (width, height) = (
        clusters.geometry.size.0 as usize,
        clusters.geometry.size.1 as usize,
    );
    // The error step from pixel a to b, if both are judged and on one smooth surface,
    // and whether they lie in one cluster.
    let step = |a: usize, b: usize| -> Option<(f64, bool)> {
        let (ea, eb) = (errors[a]?, errors[b]?);
        let (ca, cb) = (clusters.cluster[a]?, clusters.cluster[b]?);
        clusters
            .geometry
            .same_surface(a, b)
            .then(|| ((ea - eb).abs(), ca == cb))
    };
    let (mut across, mut beside, mut crossings) = (0.0, 0.0, 0usize);
    // Four pixels in a row along x or y: b | c is the crossing, a | b and c | d beside it.
    let mut crossing = |a: usize, b: usize, c: usize, d: usize| {
        let (Some((middle, false)), Some((before, true)), Some((after, true))) =
            (step(b, c), step(a, b), step(c, d))
        else {
            return;
        };
        across += middle;
        beside += 0.5 * (before + after);
        crossings += 1;
    };
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            if x >= 1 && x + 2 < width {
                crossing(i - 1, i, i + 1, i + 2);
            }
            if y >= 1 && y + 2 < height {
                crossing(i - width, i, i + width, i + 2 * width);
            }
        }
    }
    if crossings == 0 || beside == 0.0 {
        return None;
    }
    Some(SeamMeasure {
        ratio: across / beside,
        across: across / crossings as f64,
        beside: beside / crossings as f64,
        crossings,
    })
}

/// The relative error a map's colours saturate at: 10% too bright is full red, 10% too
/// dark full blue.
pub const ERROR_MAP_FULL_SCALE: f64 = 0.1;

/// An error map of `errors` ([`relative_luminance_errors`]): white where the frame equals
/// the reference, red where it is brighter, blue where darker, full at
/// [`ERROR_MAP_FULL_SCALE`]; grey where the reference is dark (not judged).
pub fn error_map(errors: &[Option<f64>], size: (u32, u32)) -> image::RgbImage {
    image::RgbImage::from_fn(size.0, size.1, |x, y| {
        let Some(error) = errors[(y * size.0 + x) as usize] else {
            return image::Rgb([96, 96, 96]);
        };
        let strength = (error.abs() / ERROR_MAP_FULL_SCALE).min(1.0);
        let fade = (255.0 * (1.0 - strength)).round() as u8;
        if error >= 0.0 {
            image::Rgb([255, fade, fade])
        } else {
            image::Rgb([fade, fade, 255])
        }
    })
}

/// The mean of `values` (0 for none).
pub(super) fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat frame of 4x3 tiles of 8x8 pixels, one depth slice, one surface.
    fn tiled_clusters() -> PixelClusters {
        let size = (32, 24);
        let pixels = (size.0 * size.1) as usize;
        PixelClusters {
            cluster: (0..pixels as u32)
                .map(|i| Some((i / size.0 / 8) * 4 + (i % size.0) / 8))
                .collect(),
            geometry: SurfaceGeometry {
                size,
                covered: vec![true; pixels],
                depth: vec![5.0; pixels],
                normal: vec![Vec3::Z; pixels],
            },
        }
    }

    /// A smooth reference, and a frame off it by a noise of 1% plus, with `seam`, a
    /// brightness of its own per tile (up to `seam`).
    fn frames(seam: f64) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        let clusters = tiled_clusters();
        let (width, height) = clusters.geometry.size;
        let reference: Vec<[f32; 4]> = (0..width * height)
            .map(|i| {
                let (x, y) = ((i % width) as f32, (i / width) as f32);
                let v = 1.0 + 0.01 * x + 0.02 * y;
                [v, v, v, 1.0]
            })
            .collect();
        let image = reference
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let noise = ((i as u32).wrapping_mul(2654435761) >> 16) as f64 / 65536.0 - 0.5;
                let tile = clusters.cluster[i].unwrap_or(0);
                let block = seam * f64::from(tile % 5) / 4.0;
                let scale = (1.0 + 0.02 * noise + block) as f32;
                [r[0] * scale, r[1] * scale, r[2] * scale, 1.0]
            })
            .collect();
        (reference, image)
    }

    #[test]
    fn a_frame_without_seams_measures_about_one() {
        let (reference, image) = frames(0.0);
        let seams = seam_measure(
            &relative_luminance_errors(&reference, &image),
            &tiled_clusters(),
        )
        .unwrap();
        // Independent noise: steps across and beside alike, up to the sampling error of
        // ~150 crossings (a few percent).
        assert!((seams.ratio - 1.0).abs() < 0.15, "{seams:?}");
    }

    #[test]
    fn tile_blocks_are_caught_by_the_seam_measure() {
        let (reference, image) = frames(0.1);
        let seams = seam_measure(
            &relative_luminance_errors(&reference, &image),
            &tiled_clusters(),
        )
        .unwrap();
        // Neighbouring blocks 2.5% or 10% apart against a 2% noise (mean step 0.0067).
        assert!(seams.ratio > 2.5, "{seams:?}");
    }

    /// The boundaries must be where the clusters change: a map shifted by one pixel puts
    /// the block steps inside "clusters" and measures no seam.
    #[test]
    fn boundaries_one_pixel_off_do_not_see_the_seams() {
        let (reference, image) = frames(0.1);
        let mut shifted = tiled_clusters();
        // Each pixel given the cluster of the pixel one up and one left of it.
        let width = shifted.geometry.size.0 as usize;
        shifted.cluster.rotate_right(width + 1);
        let seams = seam_measure(&relative_luminance_errors(&reference, &image), &shifted).unwrap();
        assert!(seams.ratio < 1.5, "{seams:?}");
    }

    #[test]
    fn pairs_across_a_geometric_edge_are_left_out() {
        let (reference, image) = frames(0.05);
        let mut clusters = tiled_clusters();
        // Every tile its own depth: each boundary pair is across a step in depth.
        for (i, depth) in clusters.geometry.depth.iter_mut().enumerate() {
            *depth = 5.0 + clusters.cluster[i].unwrap() as f32;
        }
        let errors = relative_luminance_errors(&reference, &image);
        assert!(seam_measure(&errors, &clusters).is_none());
    }

    #[test]
    fn error_map_colours_by_sign_and_saturates() {
        let errors = [Some(0.0), Some(0.2), Some(-0.05), None];
        let map = error_map(&errors, (4, 1));
        assert_eq!(map.get_pixel(0, 0).0, [255, 255, 255]);
        assert_eq!(map.get_pixel(1, 0).0, [255, 0, 0]);
        assert_eq!(map.get_pixel(2, 0).0, [128, 128, 255]);
        assert_eq!(map.get_pixel(3, 0).0, [96, 96, 96]);
    }
}
