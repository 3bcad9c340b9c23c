//! Which pixels the f64 reference samples: evenly spread over the pixels showing an opaque
//! surface, less those it cannot judge. Next to a blended face's edge the rasterizer and
//! the reference's ray may decide the edge differently; under blended materials it cannot
//! shade (textured ones) it has no layers at all; and with MSAA in the matrix, at any edge
//! a resolved pixel mixes surfaces that a point sample does not see.

use std::sync::Arc;

use glam::DVec3;

use manylights::gpu::SurfaceImage;
use manylights::lights::reference::SurfacePoint;
use manylights::visibility::SceneBvh;

use super::layers::BlendedLayers;

/// What a frame's blended surfaces let the reference do.
pub(super) enum BlendedReference {
    /// No blended surfaces.
    None,
    /// Their layers, composited over each sample.
    Layers(BlendedLayers),
    /// Not composited (why), with the scene's BVH that finds the pixels under them.
    LeftOut(String, Arc<SceneBvh>),
}

impl BlendedReference {
    pub fn layers(&self) -> Option<&BlendedLayers> {
        match self {
            BlendedReference::Layers(layers) => Some(layers),
            _ => None,
        }
    }
}

/// The capture the samples are chosen from, seen from `camera`.
pub(super) struct SamplePixels<'a> {
    pub surface: &'a SurfaceImage,
    pub camera: DVec3,
    pub blended: &'a BlendedReference,
    /// Interior pixels only (MSAA in the matrix).
    pub interior_only: bool,
}

impl SamplePixels<'_> {
    fn size(&self) -> (usize, usize) {
        (self.surface.size.0 as usize, self.surface.size.1 as usize)
    }

    fn covered(&self, j: usize) -> bool {
        self.surface.position.get(j).is_some_and(|p| p[3] == 1.0)
    }

    fn point(&self, j: usize) -> SurfacePoint {
        SurfacePoint::from_capture(self.surface, j)
    }

    /// Every pixel showing an opaque surface.
    pub fn covered_pixels(&self) -> Vec<usize> {
        (0..self.surface.position.len())
            .filter(|&i| self.covered(i))
            .collect()
    }

    /// Up to `count` pixels, every `step`-th of `covered` that the reference can judge.
    pub fn chosen(&self, covered: &[usize], step: usize, count: usize) -> Vec<usize> {
        covered
            .iter()
            .step_by(step)
            .copied()
            .filter(|&i| self.seen_clearly(i) && (!self.interior_only || self.interior(i)))
            .take(count)
            .collect()
    }

    /// The share of every `step`-th of `covered` with a blended surface in front.
    pub fn blended_coverage(&self, covered: &[usize], step: usize) -> Option<f64> {
        let layers = self.blended.layers()?;
        let spread: Vec<usize> = covered.iter().step_by(step).copied().collect();
        let under = spread
            .iter()
            .filter(|&&i| {
                !layers
                    .between(self.camera, self.point(i).position)
                    .is_empty()
            })
            .count();
        Some(under as f64 / spread.len().max(1) as f64)
    }

    /// The pixel and its neighbours in its row and column that show an opaque surface.
    fn neighbourhood(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (width, _) = self.size();
        let column = i % width;
        let left = i.checked_sub(1).filter(|_| column > 0);
        let right = Some(i + 1).filter(|_| column + 1 < width);
        [Some(i), left, right, i.checked_sub(width), Some(i + width)]
            .into_iter()
            .flatten()
            .filter(|&j| self.covered(j))
    }

    /// Whether the pixel's neighbours meet the blended faces it meets (or, where the
    /// layers are not composited, no blended surface at all).
    fn seen_clearly(&self, i: usize) -> bool {
        match self.blended {
            BlendedReference::None => true,
            BlendedReference::Layers(layers) => {
                let faces = |j: usize| -> Vec<(usize, [i64; 4])> {
                    layers
                        .between(self.camera, self.point(j).position)
                        .iter()
                        .map(|layer| layer.face)
                        .collect()
                };
                let own = faces(i);
                self.neighbourhood(i).all(|j| faces(j) == own)
            }
            BlendedReference::LeftOut(_, tree) => self.neighbourhood(i).all(|j| {
                let point = self.point(j);
                tree.light_visible(point.position, point.normal, self.camera)
            }),
        }
    }

    /// Whether the pixel and its eight neighbours show one smooth surface (normals within
    /// 2.6 degrees, on the pixel's tangent plane to a thousandth of its distance): every
    /// MSAA sample of the pixel then sees that surface, and the resolved pixel is the
    /// one-sample pixel.
    fn interior(&self, i: usize) -> bool {
        let (width, height) = self.size();
        let point = self.point(i);
        let scale = 1e-3 * (point.position - self.camera).length();
        let (x, y) = ((i % width) as i64, (i / width) as i64);
        (-1..=1i64)
            .flat_map(|dy| (-1..=1i64).map(move |dx| (x + dx, y + dy)))
            .all(|(nx, ny)| {
                if nx < 0 || ny < 0 || nx >= width as i64 || ny >= height as i64 {
                    return false;
                }
                let j = ny as usize * width + nx as usize;
                if !self.covered(j) {
                    return false;
                }
                let other = self.point(j);
                other.normal.dot(point.normal) > 0.999
                    && (other.position - point.position).dot(point.normal).abs() <= scale
            })
    }
}
