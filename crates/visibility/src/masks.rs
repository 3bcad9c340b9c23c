//! Coverage masks: what an alpha-masked material hides from a shadow ray. The GPU's
//! primary visibility discards a fragment whose alpha (the base colour factor's times the
//! texture's) is below the material's cutoff; a shadow ray passes through the same texels.
//! Each masked material's test is baked once into one byte per texel (covered or not) and
//! all masks are packed into one atlas that the GPU samples by `textureLoad` (nearest
//! texel of level 0, UVs repeated) and the f64 reference reads the same way: the two
//! agree texel for texel. (Primary visibility samples mip levels with filtering, so at a
//! leaf's edge a shadow may differ from the leaf's image by up to a texel of level 0.)
//! Blend materials block like opaque ones (a stated approximation: no coloured or partial
//! shadows).

use glam::DVec2;
use manylights_scene::{AlphaMode, Scene, Texture};

use crate::VisibilityError;

/// The mask index of a triangle no alpha test can cut (opaque and blend materials).
pub const NO_MASK: u32 = u32::MAX;

/// Most masks one scene may have (the uniform array of rectangles in bvh.wgsl,
/// `MAX_COVERAGE_MASKS`): Sponza has 3.
pub const MAX_MASKS: usize = 256;

/// The atlas's width in texels.
pub const ATLAS_WIDTH: u32 = 4096;

/// Largest side of one mask: larger textures are subsampled (every 2nd, 4th... texel).
pub const MAX_MASK_SIDE: u32 = 2048;

/// WebGPU's guaranteed largest 2D texture side: the atlas may not grow past it.
const MAX_ATLAS_HEIGHT: u32 = 8192;

/// Where one mask lies in the atlas.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaskRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// The masks of a scene's alpha-masked materials, packed in rows (shelves) into one
/// R8 atlas: 255 where a texel blocks light, 0 where it lets it through.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageMasks {
    rects: Vec<MaskRect>,
    /// Each material's mask, or [`NO_MASK`].
    material_masks: Vec<u32>,
    atlas: Vec<u8>,
    atlas_height: u32,
}

/// A masked material's coverage (width, height, a byte a texel) at the size it is stored:
/// its base colour texture's alpha times `factor` against `cutoff`, the texture's side cut
/// to at most [`MAX_MASK_SIDE`]; one texel of `factor` alone without a texture.
fn baked_coverage(texture: Option<&Texture>, factor: f32, cutoff: f32) -> (u32, u32, Vec<u8>) {
    let Some(texture) = texture else {
        return (1, 1, vec![covered_byte(factor, cutoff)]);
    };
    let step = (texture.width.max(texture.height))
        .div_ceil(MAX_MASK_SIDE)
        .max(1);
    let (width, height) = (texture.width.div_ceil(step), texture.height.div_ceil(step));
    let mut coverage = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let source = ((y * step) * texture.width + x * step) as usize * 4;
            let alpha = f32::from(texture.rgba8[source + 3]) / 255.0;
            coverage.push(covered_byte(factor * alpha, cutoff));
        }
    }
    (width, height, coverage)
}

impl CoverageMasks {
    /// Bakes the masks of every masked material of `scene` (one per material, even when
    /// two share a texture: their cutoffs or factors may differ).
    pub fn build(scene: &Scene) -> Result<CoverageMasks, VisibilityError> {
        // Each masked material's coverage, at the size it is stored.
        let mut baked: Vec<(u32, u32, Vec<u8>)> = Vec::new();
        let mut material_masks = vec![NO_MASK; scene.materials.len()];
        for (index, material) in scene.materials.iter().enumerate() {
            let AlphaMode::Mask { cutoff } = material.alpha_mode else {
                continue;
            };
            let texture = material
                .base_color_texture
                .and_then(|t| scene.textures.get(t))
                .filter(|t| t.width > 0 && t.height > 0);
            material_masks[index] = baked.len() as u32;
            baked.push(baked_coverage(
                texture,
                material.base_color_factor.w,
                cutoff,
            ));
        }
        if baked.len() > MAX_MASKS {
            return Err(VisibilityError::TooManyMasks {
                masks: baked.len(),
                limit: MAX_MASKS,
            });
        }
        // Shelves, tallest masks first.
        let mut order: Vec<usize> = (0..baked.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(baked[i].1));
        let mut rects = vec![
            MaskRect {
                x: 0,
                y: 0,
                width: 0,
                height: 0
            };
            baked.len()
        ];
        let (mut x, mut shelf_y, mut shelf_height) = (0u32, 0u32, 0u32);
        for &i in &order {
            let (width, height, _) = &baked[i];
            if x + width > ATLAS_WIDTH {
                shelf_y += shelf_height;
                x = 0;
                shelf_height = 0;
            }
            rects[i] = MaskRect {
                x,
                y: shelf_y,
                width: *width,
                height: *height,
            };
            x += width;
            shelf_height = shelf_height.max(*height);
        }
        let atlas_height = (shelf_y + shelf_height).max(1);
        if atlas_height > MAX_ATLAS_HEIGHT {
            return Err(VisibilityError::AtlasFull {
                height: atlas_height,
                limit: MAX_ATLAS_HEIGHT,
            });
        }
        let mut atlas = vec![0u8; (ATLAS_WIDTH * atlas_height) as usize];
        for (rect, (width, _, coverage)) in rects.iter().zip(&baked) {
            for (row, texels) in coverage.chunks_exact(*width as usize).enumerate() {
                let start = ((rect.y + row as u32) * ATLAS_WIDTH + rect.x) as usize;
                atlas[start..start + texels.len()].copy_from_slice(texels);
            }
        }
        Ok(CoverageMasks {
            rects,
            material_masks,
            atlas,
            atlas_height,
        })
    }

    /// The mask of material `material`, or [`NO_MASK`].
    pub fn mask_of_material(&self, material: usize) -> u32 {
        self.material_masks
            .get(material)
            .copied()
            .unwrap_or(NO_MASK)
    }

    pub fn rects(&self) -> &[MaskRect] {
        &self.rects
    }

    /// The atlas: [`ATLAS_WIDTH`] x [`CoverageMasks::atlas_height`] bytes, row-major.
    pub fn atlas(&self) -> &[u8] {
        &self.atlas
    }

    pub fn atlas_height(&self) -> u32 {
        self.atlas_height
    }

    /// Whether mask `mask` blocks light at `uv` (repeated outside [0, 1), the nearest
    /// texel): `mask_covered` in bvh.wgsl.
    pub fn covered(&self, mask: u32, uv: DVec2) -> bool {
        let rect = self.rects[mask as usize];
        let wrapped = uv - uv.floor();
        let x = ((wrapped.x * rect.width as f64) as u32).min(rect.width - 1);
        let y = ((wrapped.y * rect.height as f64) as u32).min(rect.height - 1);
        self.atlas[((rect.y + y) * ATLAS_WIDTH + rect.x + x) as usize] > 127
    }
}

/// A texel's coverage: blocked (255) unless the GPU's alpha test would discard it.
fn covered_byte(alpha: f32, cutoff: f32) -> u8 {
    if alpha < cutoff { 0 } else { 255 }
}
