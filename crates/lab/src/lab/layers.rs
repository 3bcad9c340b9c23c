//! The blended layers the f64 reference composites over a sample's opaque surface (glTF
//! `BLEND` materials, issue 45): every blended triangle of the scene in world space, in
//! f64, met by the ray from the eye to the sample and shaded as the pipelines shade it,
//! then laid "over" the surface behind it, farthest first: per fragment, the order no
//! pipeline's per-object sort can beat.

use glam::{DVec3, Vec4Swizzles};

use manylights::lights::reference::SurfacePoint;
use manylights::scene::{AlphaMode, Scene, Shading};

/// glTF's reflectance at normal incidence for dielectrics (`DIELECTRIC_F0` in WGSL).
const DIELECTRIC_F0: f64 = 0.04;

/// A blended material as the reference shades it: its factors (it has no textures).
#[derive(Debug, Clone, Copy)]
struct LayerMaterial {
    albedo: DVec3,
    specular: DVec3,
    lobe: f64,
    emission: DVec3,
    alpha: f64,
    double_sided: bool,
}

#[derive(Debug, Clone, Copy)]
struct LayerTriangle {
    vertices: [DVec3; 3],
    normals: [DVec3; 3],
    /// The scene instance it belongs to (the pipelines sort whole instances).
    object: usize,
    material: LayerMaterial,
}

/// One blended surface a ray meets: its surface, alpha, and which surface it is.
#[derive(Debug, Clone, Copy)]
pub(super) struct Layer {
    pub surface: SurfacePoint,
    pub alpha: f64,
    pub object: usize,
    /// Its object and plane (unit normal and offset, to a millionth): the same for the
    /// triangles of one flat face, different across a face's edge.
    pub face: (usize, [i64; 4]),
}

/// The scene's blended triangles, or why the reference cannot composite them.
#[derive(Debug, Clone)]
pub(super) struct BlendedLayers {
    triangles: Vec<LayerTriangle>,
    shading: Shading,
}

impl BlendedLayers {
    /// The blended triangles of `scene` shaded with `shading`; an error naming the first
    /// blended material with a texture (the reference shades factors only).
    pub fn from_scene(scene: &Scene, shading: Shading) -> Result<Self, String> {
        let mut triangles = Vec::new();
        for (object, instance) in scene.instances.iter().enumerate() {
            let mesh = &scene.meshes[instance.mesh];
            let material = &scene.materials[mesh.material];
            if material.alpha_mode != AlphaMode::Blend {
                continue;
            }
            if material.base_color_texture.is_some()
                || material.emissive_texture.is_some()
                || material.metallic_roughness_texture.is_some()
                || material.normal_texture.is_some()
            {
                return Err(format!(
                    "blended material '{}' has textures: the f64 reference composites blended layers of constant factors only",
                    material.name
                ));
            }
            let layer_material = layer_material(material, shading);
            let transform = instance.transform.as_dmat4();
            let normal_matrix = transform.inverse().transpose();
            for corners in mesh.indices.chunks_exact(3) {
                let vertex = |k: usize| {
                    let i = corners[k] as usize;
                    (
                        transform.transform_point3(mesh.positions[i].as_dvec3()),
                        normal_matrix
                            .transform_vector3(mesh.normals[i].as_dvec3())
                            .normalize_or_zero(),
                    )
                };
                let [(p0, n0), (p1, n1), (p2, n2)] = [vertex(0), vertex(1), vertex(2)];
                triangles.push(LayerTriangle {
                    vertices: [p0, p1, p2],
                    normals: [n0, n1, n2],
                    object,
                    material: layer_material,
                });
            }
        }
        Ok(Self { triangles, shading })
    }

    /// The blended surfaces strictly between `eye` and `point`, farthest first (a
    /// single-sided surface seen from behind is culled, as the pipelines cull it). Where
    /// two triangles of one object meet the ray at one point (their shared edge), once.
    pub fn between(&self, eye: DVec3, point: DVec3) -> Vec<Layer> {
        let direction = point - eye;
        let mut hits: Vec<(f64, Layer)> = Vec::new();
        for triangle in &self.triangles {
            let Some((t, barycentric)) = intersect(eye, direction, &triangle.vertices) else {
                continue;
            };
            // Strictly before the opaque surface (a pane on the surface is not in front).
            if t <= 1e-9 || t >= 1.0 - 1e-9 {
                continue;
            }
            let [v0, v1, v2] = triangle.vertices;
            let facing = (v1 - v0).cross(v2 - v0).dot(-direction);
            if facing <= 0.0 && !triangle.material.double_sided {
                continue;
            }
            if hits
                .iter()
                .any(|(other, layer)| layer.object == triangle.object && (other - t).abs() < 1e-9)
            {
                continue;
            }
            let [n0, n1, n2] = triangle.normals;
            let mut normal =
                (n0 * barycentric.x + n1 * barycentric.y + n2 * barycentric.z).normalize_or_zero();
            if facing <= 0.0 {
                normal = -normal;
            }
            let material = triangle.material;
            let surface = SurfacePoint {
                position: eye + direction * t,
                normal,
                albedo: material.albedo,
                specular: material.specular,
                lobe: material.lobe,
                shading: self.shading,
                emission: material.emission,
            };
            let plane = (v1 - v0).cross(v2 - v0).normalize_or_zero();
            let quantised = |x: f64| (x * 1e6).round() as i64;
            let face = [plane.x, plane.y, plane.z, plane.dot(v0)].map(quantised);
            hits.push((
                t,
                Layer {
                    surface,
                    alpha: material.alpha,
                    object: triangle.object,
                    face: (triangle.object, face),
                },
            ));
        }
        hits.sort_by(|a, b| b.0.total_cmp(&a.0));
        hits.into_iter().map(|(_, layer)| layer).collect()
    }
}

/// What `fragment_surface` (`shaders/common/material.wgsl`) makes of a material without
/// textures.
fn layer_material(material: &manylights::scene::Material, shading: Shading) -> LayerMaterial {
    let base = material.base_color_factor.as_dvec4();
    let (albedo, specular, lobe) = match shading {
        Shading::Pbr => {
            let metallic = f64::from(material.metallic_factor).clamp(0.0, 1.0);
            (
                base.xyz() * (1.0 - metallic),
                DVec3::splat(DIELECTRIC_F0).lerp(base.xyz(), metallic),
                f64::from(material.roughness_factor).clamp(0.0, 1.0),
            )
        }
        Shading::BlinnPhong => (
            base.xyz(),
            material.specular_color.as_dvec3(),
            f64::from(material.shininess),
        ),
    };
    LayerMaterial {
        albedo,
        specular,
        lobe,
        emission: material.emissive_factor.as_dvec3(),
        alpha: base.w,
        double_sided: material.double_sided,
    }
}

/// Where the ray `origin + t * direction` meets the triangle (Möller and Trumbore): `t`
/// and the barycentric weights of its three vertices.
fn intersect(origin: DVec3, direction: DVec3, [v0, v1, v2]: &[DVec3; 3]) -> Option<(f64, DVec3)> {
    let (edge1, edge2) = (*v1 - *v0, *v2 - *v0);
    let p = direction.cross(edge2);
    let determinant = edge1.dot(p);
    if determinant.abs() < 1e-300 {
        return None;
    }
    let inverse = 1.0 / determinant;
    let s = origin - *v0;
    let u = s.dot(p) * inverse;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(edge1);
    let v = direction.dot(q) * inverse;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some((edge2.dot(q) * inverse, DVec3::new(1.0 - u - v, u, v)))
}

/// `opaque` radiance with `layers` (farthest first, each shaded to its radiance by
/// `shade`) laid over it: each layer's alpha of its own radiance over (1 - alpha) of
/// what is behind. Also the weight each input ends with, for combining standard errors:
/// the opaque surface's first, then the layers'.
pub(super) fn composite(
    opaque: DVec3,
    layers: &[Layer],
    mut shade: impl FnMut(&SurfacePoint) -> DVec3,
) -> (DVec3, Vec<f64>) {
    let mut radiance = opaque;
    let mut weights = vec![1.0];
    for layer in layers {
        let alpha = layer.alpha;
        radiance = alpha * shade(&layer.surface) + (1.0 - alpha) * radiance;
        for weight in &mut weights {
            *weight *= 1.0 - alpha;
        }
        weights.push(alpha);
    }
    (radiance, weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two panes over a surface composite back to front whatever order the triangles come
    /// in, and a single-sided pane seen from behind is culled.
    #[test]
    fn layers_composite_farthest_first() {
        let mut scene = manylights::scene::procedural::glass_room();
        scene.lights.clear();
        let layers = BlendedLayers::from_scene(&scene, Shading::Pbr).expect("layers");
        // Straight through the panes' centres from far in front: every pane the ray meets
        // is met once, farthest first.
        let eye = DVec3::new(0.0, 1.0, 8.0);
        let point = DVec3::new(0.0, 1.0, -3.0);
        let met = layers.between(eye, point);
        assert!(!met.is_empty(), "the ray meets no pane");
        let distances: Vec<f64> = met
            .iter()
            .map(|layer| (layer.surface.position - eye).length())
            .collect();
        assert!(
            distances.windows(2).all(|pair| pair[0] > pair[1]),
            "{distances:?}"
        );
        let (radiance, weights) = composite(DVec3::ONE, &met, |_| DVec3::ZERO);
        let revealed: f64 = met.iter().map(|layer| 1.0 - layer.alpha).product();
        assert!((radiance - DVec3::splat(revealed)).abs().max_element() < 1e-12);
        assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
