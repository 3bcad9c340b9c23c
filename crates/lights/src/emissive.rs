//! Emissive surfaces as lights: every triangle of a material that emits (glTF's
//! `emissiveFactor` times `KHR_materials_emissive_strength`, times its emissive texture)
//! becomes a triangle light of the radiance it shows, so a lamp shade or a screen lights
//! the room as well as glowing itself.

use glam::{Mat4, Vec2, Vec3};
use manylights_scene::{Scene, color::srgb_to_linear};

use crate::light::{Light, RadiusMode};

/// A scene's emissive triangles as lights, and what was left out and why.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EmissiveLights {
    pub lights: Vec<Light>,
    /// Triangles of no area (or so thin their normal is undefined in f32): they emit
    /// nothing, and are left out.
    pub degenerate: usize,
    /// Triangles whose material's emissive texture failed to load (the loader's warning
    /// names it): their glow is drawn with the fallback texture, but they light nothing.
    pub failed_texture: usize,
    /// Triangles whose radiance is black over the whole triangle (a texture dark there).
    pub black: usize,
}

impl EmissiveLights {
    /// A line for the render output and the viewer, `None` when the scene emits nothing.
    pub fn describe(&self) -> Option<String> {
        let skipped = self.degenerate + self.failed_texture + self.black;
        if self.lights.is_empty() && skipped == 0 {
            return None;
        }
        let mut text = format!("emissive triangles as lights: {}", self.lights.len());
        if skipped > 0 {
            text.push_str(&format!(
                " (left out: {} of no area, {} with a texture that failed to load, {} black)",
                self.degenerate, self.failed_texture, self.black
            ));
        }
        Some(text)
    }
}

/// The square of the smallest cross product of two edges a triangle light may have: below
/// it, f32 cannot hold its normal's direction.
const MIN_DOUBLE_AREA_SQUARED: f32 = 1e-20;

/// Samples a triangle's texture mean takes (a 4 x 4 grid, mapped onto the triangle area
/// for area).
const TEXTURE_SAMPLES: u32 = 4;

/// Every emissive triangle of `scene`'s instances as a triangle light: its corners in world
/// space, emitting the material's emissive factor times the mean of its emissive texture
/// over the triangle (sampled at 16 points spread evenly over its area, nearest texel),
/// towards its front face (both faces for double-sided materials: two lights), reaching
/// `radius`'s range of its intensity beyond its farthest corner.
pub fn emissive_lights(scene: &Scene, radius: RadiusMode) -> EmissiveLights {
    let mut out = EmissiveLights::default();
    for instance in &scene.instances {
        let mesh = &scene.meshes[instance.mesh];
        let Some(material) = scene.materials.get(mesh.material) else {
            continue;
        };
        if material.emissive_factor.max_element() <= 0.0 {
            continue;
        }
        let texture = material
            .emissive_texture
            .and_then(|t| scene.textures.get(t));
        let failed = texture.is_some_and(|t| texture_failed(scene, &t.source));
        // A mirroring transform turns the winding, and with it the front face.
        let mirrored = instance.transform.determinant() < 0.0;
        for triangle in mesh.indices.chunks_exact(3) {
            let index = |k: usize| triangle[k] as usize;
            let mut corners =
                [0, 1, 2].map(|k| world(&instance.transform, mesh.positions[index(k)]));
            let mut uvs = [0, 1, 2].map(|k| mesh.uvs.get(index(k)).copied().unwrap_or(Vec2::ZERO));
            if mirrored {
                corners.swap(1, 2);
                uvs.swap(1, 2);
            }
            let facing = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            if !facing.is_finite() || facing.length_squared() <= MIN_DOUBLE_AREA_SQUARED {
                out.degenerate += 1;
                continue;
            }
            if failed {
                out.failed_texture += 1;
                continue;
            }
            let texture_mean = texture.map_or(Vec3::ONE, |t| mean_over_triangle(t, uvs));
            let radiance = material.emissive_factor * texture_mean;
            let brightest = radiance.max_element();
            // Not above 0 (NaN too: the loader refuses non-finite factors, a texel is finite).
            if brightest.is_nan() || brightest <= 0.0 {
                out.black += 1;
                continue;
            }
            let color = radiance / brightest;
            let make = |corners: [Vec3; 3]| {
                let light = Light::triangle(corners, 1.0, color, brightest);
                light.reaching(radius.radius(light.intensity))
            };
            out.lights.push(make(corners));
            if material.double_sided {
                out.lights.push(make([corners[0], corners[2], corners[1]]));
            }
        }
    }
    out
}

fn world(transform: &Mat4, position: Vec3) -> Vec3 {
    transform.transform_point3(position)
}

/// Whether the loader replaced the texture from `source` with its fallback (it says so in
/// a warning naming it).
fn texture_failed(scene: &Scene, source: &str) -> bool {
    let named = format!("'{source}'");
    scene
        .warnings
        .iter()
        .any(|warning| warning.message.contains(&named) && warning.message.contains("fallback"))
}

/// The mean linear colour of `texture` over the triangle of texture coordinates `uvs`:
/// 16 nearest-texel samples at the centres of a 4 x 4 grid mapped onto the triangle area
/// for area, coordinates wrapped (glTF's default repeat).
fn mean_over_triangle(texture: &manylights_scene::Texture, uvs: [Vec2; 3]) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for i in 0..TEXTURE_SAMPLES {
        for j in 0..TEXTURE_SAMPLES {
            let s = (i as f32 + 0.5) / TEXTURE_SAMPLES as f32;
            let t = (j as f32 + 0.5) / TEXTURE_SAMPLES as f32;
            let root = s.sqrt();
            let uv = uvs[0] * (1.0 - root) + uvs[1] * (root * (1.0 - t)) + uvs[2] * (root * t);
            sum += texel(texture, uv);
        }
    }
    sum / (TEXTURE_SAMPLES * TEXTURE_SAMPLES) as f32
}

fn texel(texture: &manylights_scene::Texture, uv: Vec2) -> Vec3 {
    let wrap = |x: f32, size: u32| {
        let x = x - x.floor();
        ((x * size as f32) as u32).min(size.saturating_sub(1))
    };
    if texture.width == 0 || texture.height == 0 {
        return Vec3::ONE;
    }
    let x = wrap(uv.x, texture.width);
    let y = wrap(uv.y, texture.height);
    let offset = ((y * texture.width + x) * 4) as usize;
    let channel = |c: usize| {
        let encoded = f32::from(texture.rgba8.get(offset + c).copied().unwrap_or(255)) / 255.0;
        match texture.color_space {
            manylights_scene::ColorSpace::Srgb => srgb_to_linear(encoded),
            manylights_scene::ColorSpace::Linear => encoded,
        }
    };
    Vec3::new(channel(0), channel(1), channel(2))
}
