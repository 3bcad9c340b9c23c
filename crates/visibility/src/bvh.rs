//! The scene's bounding volume hierarchy: built once per scene from its world-space
//! triangles (the geometry is static; only lights move), traced here in f64 for the
//! accuracy reference and uploaded as is for the GPU's traversal
//! (`shaders/visibility/bvh.wgsl`), which mirrors these functions.

use glam::{DVec2, DVec3, Vec3};
use manylights_scene::Scene;
use obvhs::Boundable;
use obvhs::bvh2::{leaf_collapser, reinsertion::ReinsertionOptimizer};
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};

use crate::VisibilityError;
use crate::masks::{CoverageMasks, NO_MASK};

/// Most triangles a leaf holds: small leaves keep the GPU's any-hit loop short (each
/// triangle is 4 texel reads), large ones keep the tree shallow.
const MAX_TRIANGLES_PER_LEAF: u32 = 4;

/// Deepest tree the GPU's traversal stack holds (`BVH_STACK_SIZE` in bvh.wgsl, from this
/// constant). A PLOC tree over Sponza's 262,267 triangles is 33 deep; a scene whose tree
/// is deeper is refused with [`VisibilityError::TooDeep`] rather than traced wrongly.
pub const MAX_DEPTH: u32 = 64;

/// A node of the flattened tree, as the GPU reads it (two RGBA32F texels, `BvhNode` in
/// bvh.wgsl): its box, then either its two children (`count == 0`: at `first` and
/// `first + 1`) or its `count` triangles from `first`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

/// A triangle in world space with what an alpha test needs, as the GPU reads it (four
/// RGBA32F texels): the vertices, the index of its material's coverage mask
/// ([`NO_MASK`] for opaque materials) and the vertices' texture coordinates.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BvhTriangle {
    pub v0: [f32; 3],
    pub mask: u32,
    pub v1: [f32; 3],
    pub uv0_x: f32,
    pub v2: [f32; 3],
    pub uv0_y: f32,
    /// uv1.x, uv1.y, uv2.x, uv2.y.
    pub uv12: [f32; 4],
}

impl BvhTriangle {
    fn vertices(&self) -> [DVec3; 3] {
        [self.v0, self.v1, self.v2].map(|v| Vec3::from_array(v).as_dvec3())
    }

    fn uvs(&self) -> [DVec2; 3] {
        [
            DVec2::new(self.uv0_x as f64, self.uv0_y as f64),
            DVec2::new(self.uv12[0] as f64, self.uv12[1] as f64),
            DVec2::new(self.uv12[2] as f64, self.uv12[3] as f64),
        ]
    }
}

/// Where a ray first meets the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray in units of its direction's length.
    pub t: f64,
    /// Index into [`SceneBvh::triangles`].
    pub triangle: u32,
}

/// The scene's triangles in a BVH, with the coverage masks of its alpha-masked materials.
#[derive(Debug, Clone)]
pub struct SceneBvh {
    nodes: Vec<BvhNode>,
    triangles: Vec<BvhTriangle>,
    masks: CoverageMasks,
    depth: u32,
}

impl SceneBvh {
    /// Builds the tree over every instance's triangles (PLOC, then reinsertion and leaf
    /// collapsing, from the `obvhs` crate).
    pub fn build(scene: &Scene) -> Result<SceneBvh, VisibilityError> {
        let masks = CoverageMasks::build(scene)?;
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        for instance in &scene.instances {
            let mesh = &scene.meshes[instance.mesh];
            let mask = masks.mask_of_material(mesh.material);
            for corners in mesh.indices.chunks_exact(3) {
                let position = |k: usize| {
                    instance
                        .transform
                        .transform_point3(mesh.positions[corners[k] as usize])
                };
                let uv = |k: usize| {
                    let uv = mesh
                        .uvs
                        .get(corners[k] as usize)
                        .copied()
                        .unwrap_or_default();
                    if mask == NO_MASK {
                        [0.0; 2]
                    } else {
                        uv.to_array()
                    }
                };
                let (uv0, uv1, uv2) = (uv(0), uv(1), uv(2));
                triangles.push(BvhTriangle {
                    v0: position(0).to_array(),
                    mask,
                    v1: position(1).to_array(),
                    uv0_x: uv0[0],
                    v2: position(2).to_array(),
                    uv0_y: uv0[1],
                    uv12: [uv1[0], uv1[1], uv2[0], uv2[1]],
                });
            }
        }
        Self::over(triangles, masks)
    }

    /// Builds the tree over an engine's own opaque triangles: world-space `positions` and
    /// `indices`, three a triangle (nothing alpha-tested: every triangle blocks light).
    /// Refused with the problem named: an index count not a multiple of three, an index
    /// past the positions, a position that is not finite.
    pub fn from_triangles(
        positions: &[Vec3],
        indices: &[u32],
    ) -> Result<SceneBvh, VisibilityError> {
        if !indices.len().is_multiple_of(3) {
            return Err(VisibilityError::BadTriangles(format!(
                "{} indices is not three a triangle",
                indices.len()
            )));
        }
        if let Some((at, index)) = indices
            .iter()
            .enumerate()
            .find(|(_, index)| **index as usize >= positions.len())
        {
            return Err(VisibilityError::BadTriangles(format!(
                "index {at} is {index}, past the {} positions",
                positions.len()
            )));
        }
        let triangles = indices
            .chunks_exact(3)
            .map(|corners| {
                let corner = |k: usize| positions[corners[k] as usize].to_array();
                BvhTriangle {
                    v0: corner(0),
                    mask: NO_MASK,
                    v1: corner(1),
                    uv0_x: 0.0,
                    v2: corner(2),
                    uv0_y: 0.0,
                    uv12: [0.0; 4],
                }
            })
            .collect();
        Self::over(triangles, CoverageMasks::build(&Scene::default())?)
    }

    /// The tree over `triangles` (world space), whose masks are in `masks`.
    fn over(
        triangles: Vec<BvhTriangle>,
        masks: CoverageMasks,
    ) -> Result<SceneBvh, VisibilityError> {
        if let Some(bad) = triangles
            .iter()
            .position(|t| !(t.v0.iter().chain(&t.v1).chain(&t.v2)).all(|c| c.is_finite()))
        {
            return Err(VisibilityError::NonFinite { triangle: bad });
        }
        if triangles.is_empty() {
            return Ok(SceneBvh {
                nodes: Vec::new(),
                triangles,
                masks,
                depth: 0,
            });
        }
        let primitives: Vec<BoxedTriangle> = triangles.iter().map(BoxedTriangle::of).collect();
        let mut bvh = PlocBuilder::with_capacity(primitives.len()).build(
            PlocSearchDistance::Medium,
            &primitives,
            (0..primitives.len() as u32).collect(),
            SortPrecision::U64,
            2,
        );
        let mut reinsertion = ReinsertionOptimizer::default();
        reinsertion.run(&mut bvh, 0.05, None);
        leaf_collapser::collapse(&mut bvh, MAX_TRIANGLES_PER_LEAF, 3.0);
        reinsertion.run(&mut bvh, 0.1, None);

        // Leaves index the triangles directly: lay them out in the tree's order.
        let triangles: Vec<BvhTriangle> = bvh
            .primitive_indices
            .iter()
            .map(|&i| triangles[i as usize])
            .collect();
        let nodes: Vec<BvhNode> = bvh
            .nodes
            .iter()
            .map(|node| BvhNode {
                min: node.aabb.min.to_array(),
                first: node.first_index,
                max: node.aabb.max.to_array(),
                count: node.prim_count,
            })
            .collect();
        let depth = tree_depth(&nodes);
        if depth > MAX_DEPTH {
            return Err(VisibilityError::TooDeep { depth });
        }
        Ok(SceneBvh {
            nodes,
            triangles,
            masks,
            depth,
        })
    }

    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// The triangles in the tree's order.
    pub fn triangles(&self) -> &[BvhTriangle] {
        &self.triangles
    }

    pub fn masks(&self) -> &CoverageMasks {
        &self.masks
    }

    /// Levels from the root to the deepest leaf (1: the root is a leaf).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The nearest surface the ray `origin + t * direction`, `t_min < t < t_max`, meets
    /// (alpha-masked surfaces only where their coverage mask is set).
    pub fn closest_hit(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
    ) -> Option<Hit> {
        let mut nearest = None;
        let mut t_far = t_max;
        self.traverse(origin, direction, t_min, &mut t_far, |hit| {
            nearest = Some(hit);
            false
        });
        nearest
    }

    /// Whether any surface blocks the open segment `t_min < t < t_max` of the ray.
    pub fn any_hit(&self, origin: DVec3, direction: DVec3, t_min: f64, t_max: f64) -> bool {
        let mut blocked = false;
        let mut t_far = t_max;
        self.traverse(origin, direction, t_min, &mut t_far, |_| {
            blocked = true;
            true
        });
        blocked
    }

    /// Whether the light at `light` reaches the surface point `point` with unit normal
    /// `normal`: the shadow ray of [`shadow_ray`] meets nothing.
    pub fn light_visible(&self, point: DVec3, normal: DVec3, light: DVec3) -> bool {
        let ray = shadow_ray(point, normal, light);
        !self.any_hit(ray.origin, ray.direction, 0.0, 1.0)
    }

    /// Depth-first traversal; `on_hit` sees each accepted hit nearer than `t_far` (which
    /// then shrinks to it) and returns whether to stop.
    fn traverse(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_far: &mut f64,
        mut on_hit: impl FnMut(Hit) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inverse = direction.recip();
        // A stack on the stack, as in bvh.wgsl: expanding a node of level L leaves at most
        // L + 1 entries, and `build` refuses trees deeper than MAX_DEPTH.
        let mut stack = [0u32; MAX_DEPTH as usize + 1];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = &self.nodes[stack[depth] as usize];
            if !box_hit(node, origin, inverse, t_min, *t_far) {
                continue;
            }
            if node.count == 0 {
                stack[depth] = node.first + 1;
                stack[depth + 1] = node.first;
                depth += 2;
                continue;
            }
            for triangle in node.first..node.first + node.count {
                let Some(t) = self.triangle_hit(triangle, origin, direction, t_min, *t_far) else {
                    continue;
                };
                *t_far = t;
                if on_hit(Hit { t, triangle }) {
                    return;
                }
            }
        }
    }

    /// The watertight ray-triangle test of Woop, Benthin and Wald (JCGT 2013) in f64: a ray
    /// through a shared edge or vertex meets at least one of the triangles around it.
    /// Degenerate (zero-area) triangles are never met; masked ones only where covered.
    fn triangle_hit(
        &self,
        index: u32,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
    ) -> Option<f64> {
        let triangle = &self.triangles[index as usize];
        let hit = watertight_hit(triangle.vertices(), origin, direction)?;
        if !(hit.t > t_min && hit.t < t_max) {
            return None;
        }
        if triangle.mask != NO_MASK {
            let [uv0, uv1, uv2] = triangle.uvs();
            let uv = (uv0 * hit.u + uv1 * hit.v + uv2 * hit.w) / hit.det;
            if !self.masks.covered(triangle.mask, uv) {
                return None;
            }
        }
        Some(hit.t)
    }
}

/// A triangle's box, for obvhs's builder.
struct BoxedTriangle(obvhs::aabb::Aabb);

impl BoxedTriangle {
    fn of(triangle: &BvhTriangle) -> Self {
        let [a, b, c] = [triangle.v0, triangle.v1, triangle.v2].map(Vec3::from_array);
        let (min, max) = (a.min(b).min(c), a.max(b).max(c));
        // obvhs's Aabb is two 16-byte vectors (glam 0.33's Vec3A, padded).
        Self(bytemuck::cast([
            min.x, min.y, min.z, 0.0, max.x, max.y, max.z, 0.0,
        ]))
    }
}

impl Boundable for BoxedTriangle {
    fn aabb(&self) -> obvhs::aabb::Aabb {
        self.0
    }
}

fn tree_depth(nodes: &[BvhNode]) -> u32 {
    let mut deepest = 0;
    let mut stack = vec![(0u32, 1u32)];
    while let Some((index, depth)) = stack.pop() {
        deepest = deepest.max(depth);
        let node = &nodes[index as usize];
        if node.count == 0 {
            stack.push((node.first, depth + 1));
            stack.push((node.first + 1, depth + 1));
        }
    }
    deepest
}

/// Slab test against `node`'s box. The far distance is widened by 4 ulps of f32 (more
/// than the rounding of the slab products, Ize 2013), so a ray along a box's face is
/// never lost: a box test may only ever say yes too often.
fn box_hit(node: &BvhNode, origin: DVec3, inverse: DVec3, t_min: f64, t_max: f64) -> bool {
    let min = Vec3::from_array(node.min).as_dvec3();
    let max = Vec3::from_array(node.max).as_dvec3();
    let t0 = (min - origin) * inverse;
    let t1 = (max - origin) * inverse;
    // f64::max/min ignore a NaN (0 x infinity, a ray in a slab's plane).
    let near = t0.min(t1).max_element().max(t_min);
    let far = t0.max(t1).min_element().min(t_max) * (1.0 + 4.0 * f32::EPSILON as f64);
    near <= far
}

/// A watertight hit: distance and the unnormalized barycentric weights of v0, v1, v2
/// (divide by `det`).
struct TriangleHit {
    t: f64,
    u: f64,
    v: f64,
    w: f64,
    det: f64,
}

fn watertight_hit(vertices: [DVec3; 3], origin: DVec3, direction: DVec3) -> Option<TriangleHit> {
    // The axis the ray runs most along becomes z; x and y keep the winding.
    let abs = direction.abs();
    let kz = if abs.x > abs.y && abs.x > abs.z {
        0
    } else if abs.y > abs.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if direction[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let shear_x = direction[kx] / direction[kz];
    let shear_y = direction[ky] / direction[kz];
    let shear_z = 1.0 / direction[kz];
    let [a, b, c] = vertices.map(|v| v - origin);
    let project = |p: DVec3| (p[kx] - shear_x * p[kz], p[ky] - shear_y * p[kz]);
    let (ax, ay) = project(a);
    let (bx, by) = project(b);
    let (cx, cy) = project(c);
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let t = (u * a[kz] + v * b[kz] + w * c[kz]) * shear_z / det;
    t.is_finite().then_some(TriangleHit { t, u, v, w, det })
}

/// A shadow ray: from `origin` to `origin + direction` (`0 < t < 1`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowRay {
    pub origin: DVec3,
    pub direction: DVec3,
}

/// Absolute part of the shadow ray's offset, in metres (0.1 mm).
pub const SHADOW_OFFSET_ABSOLUTE: f64 = 1e-4;
/// Relative part of the shadow ray's offset: times the largest coordinate of the point
/// (2^-17, 64 to 128 f32 ulps of it: the GPU's surface position carries the rasterizer's
/// interpolation and the camera-relative rounding, each a few ulps of the coordinates).
/// 0.23 mm at Sponza's 30 m, 2.3 cm 3 km from the world's origin.
pub const SHADOW_OFFSET_RELATIVE: f64 = 1.0 / 131072.0;

/// The shadow ray from a surface point towards a light. It starts `offset` along the
/// normal (off the surface the point lies on, so the surface does not shadow itself) and
/// stops `offset` short of the light (a light resting on a surface is not hidden by it);
/// `offset` = [`SHADOW_OFFSET_ABSOLUTE`] + [`SHADOW_OFFSET_RELATIVE`] x the point's
/// largest coordinate. The same rule is `shadow_ray` in bvh.wgsl.
pub fn shadow_ray(point: DVec3, normal: DVec3, light: DVec3) -> ShadowRay {
    let offset = shadow_offset(point);
    let origin = point + normal * offset;
    let to_light = light - origin;
    let length = to_light.length();
    let end = if length > offset {
        light - to_light * (offset / length)
    } else {
        origin
    };
    ShadowRay {
        origin,
        direction: end - origin,
    }
}

/// The shadow ray's offset at `point` (see [`shadow_ray`]).
pub fn shadow_offset(point: DVec3) -> f64 {
    SHADOW_OFFSET_ABSOLUTE + SHADOW_OFFSET_RELATIVE * point.abs().max_element()
}

#[cfg(test)]
mod texel_layout_tests {
    use super::{BvhNode, BvhTriangle};
    use std::mem::{offset_of, size_of};

    /// bvh.wgsl reads nodes as two RGBA32F texels and triangles as four: each u32 must be a
    /// texel's w (offset 12 within its 16 bytes), each vertex a texel's xyz.
    #[test]
    fn nodes_and_triangles_are_whole_texels() {
        assert_eq!(size_of::<BvhNode>(), 2 * 16);
        assert_eq!(offset_of!(BvhNode, first), 12);
        assert_eq!(offset_of!(BvhNode, max), 16);
        assert_eq!(offset_of!(BvhNode, count), 16 + 12);
        assert_eq!(size_of::<BvhTriangle>(), 4 * 16);
        assert_eq!(offset_of!(BvhTriangle, mask), 12);
        assert_eq!(offset_of!(BvhTriangle, v1), 16);
        assert_eq!(offset_of!(BvhTriangle, uv0_x), 16 + 12);
        assert_eq!(offset_of!(BvhTriangle, v2), 32);
        assert_eq!(offset_of!(BvhTriangle, uv0_y), 32 + 12);
        assert_eq!(offset_of!(BvhTriangle, uv12), 48);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scenes::{Numbers, closed_box, half_masked, merged, plane, sphere};
    use glam::Mat4;

    fn brute_force(bvh: &SceneBvh, origin: DVec3, direction: DVec3, t_max: f64) -> Option<f64> {
        (0..bvh.triangles.len() as u32)
            .filter_map(|i| bvh.triangle_hit(i, origin, direction, 0.0, t_max))
            .min_by(f64::total_cmp)
    }

    fn procedural() -> Scene {
        let pillars =
            manylights_scene::procedural::pillars(manylights_scene::procedural::PillarsParams {
                grid: 3,
                segments: 12,
            });
        merged([
            pillars,
            manylights_scene::procedural::cornell(),
            half_masked(
                plane(2.0, Mat4::from_translation(Vec3::new(0.0, 3.0, 0.0))),
                8,
            ),
        ])
    }

    #[test]
    fn the_tree_finds_what_testing_every_triangle_finds() {
        let scene = procedural();
        let bvh = SceneBvh::build(&scene).expect("builds");
        assert!(bvh.nodes.len() > 1 && bvh.depth() <= MAX_DEPTH);
        let bounds = scene.bounds();
        let (min, max) = (bounds.min.as_dvec3() - 1.0, bounds.max.as_dvec3() + 1.0);
        let mut numbers = Numbers(7);
        let mut hits = 0;
        for _ in 0..4000 {
            let origin = numbers.in_box(min, max);
            let direction = numbers.in_box(min, max) - origin;
            let want = brute_force(&bvh, origin, direction, 1.0);
            let got = bvh
                .closest_hit(origin, direction, 0.0, 1.0)
                .map(|hit| hit.t);
            assert_eq!(got, want, "ray {origin} + t {direction}");
            assert_eq!(bvh.any_hit(origin, direction, 0.0, 1.0), want.is_some());
            hits += usize::from(want.is_some());
        }
        assert!(
            hits > 400 && hits < 3600,
            "{hits} of 4000 rays hit: a test with content"
        );
    }

    #[test]
    fn a_ray_through_a_shared_edge_or_vertex_hits() {
        // The plane's two triangles share the diagonal from (-1, 0, -1) to (1, 0, 1).
        let bvh = SceneBvh::build(&plane(1.0, Mat4::IDENTITY)).expect("builds");
        // The diagonal's ends are the plane's corners (silhouette vertices): not shared.
        for k in 1..100 {
            let s = -1.0 + 2.0 * k as f64 / 100.0;
            let on_edge = DVec3::new(s, 0.0, s);
            for from in [DVec3::new(0.3, 1.0, -0.2), DVec3::new(-2.0, 0.5, 1.7)] {
                let hit = bvh.closest_hit(from, (on_edge - from) * 2.0, 0.0, 1.0);
                assert!(
                    hit.is_some_and(|h| (h.t - 0.5).abs() < 1e-12),
                    "{on_edge} from {from}: {hit:?}"
                );
            }
        }
    }

    #[test]
    fn degenerate_triangles_block_nothing() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::Z, Vec3::Z];
        let scene = crate::test_scenes::mesh_scene(
            "degenerate",
            positions,
            vec![0, 1, 2, 0, 3, 4, 0, 0, 0],
            Mat4::IDENTITY,
        );
        let bvh = SceneBvh::build(&scene).expect("zero-area triangles build");
        let mut numbers = Numbers(3);
        for _ in 0..1000 {
            let target = numbers.in_box(DVec3::new(-0.5, 0.0, -0.5), DVec3::new(2.5, 0.0, 1.5));
            let from = DVec3::new(0.4, 1.0, 0.3);
            assert!(
                !bvh.any_hit(from, (target - from) * 2.0, 0.0, 1.0),
                "{target}"
            );
        }
    }

    #[test]
    fn a_mask_lets_light_through_where_the_alpha_test_cuts() {
        // Left half of the texture (u < 0.5) covered; the plane's u is x.
        let bvh = SceneBvh::build(&half_masked(plane(0.5, Mat4::IDENTITY), 8)).expect("builds");
        let down = DVec3::new(0.0, -2.0, 0.0);
        // u = x repeats: x in [0, 0.5) and [-1, -0.5) are covered; [-0.5, 0) is not.
        assert!(bvh.any_hit(DVec3::new(0.25, 1.0, 0.1), down, 0.0, 1.0));
        assert!(!bvh.any_hit(DVec3::new(-0.25, 1.0, 0.1), down, 0.0, 1.0));
        // From below too: a mask has no side.
        assert!(bvh.any_hit(DVec3::new(0.1, -1.0, 0.1), -down, 0.0, 1.0));
    }

    /// Points on surfaces see lights on their side: flat (far from the origin, where the
    /// offset's relative part matters), curved (the shading normal is not the face's) and
    /// grazing (lights a tenth of a degree above the plane).
    #[test]
    fn no_surface_shadows_itself() {
        let far = Vec3::new(300.0, -20.0, 150.0);
        let flat = SceneBvh::build(&plane(50.0, Mat4::from_translation(far))).expect("builds");
        let curved =
            SceneBvh::build(&sphere(1.0, 48, Mat4::from_translation(far))).expect("builds");
        let mut numbers = Numbers(11);
        for _ in 0..2000 {
            let point = far.as_dvec3()
                + DVec3::new(
                    numbers.uniform() * 80.0 - 40.0,
                    0.0,
                    numbers.uniform() * 80.0 - 40.0,
                );
            let elevation = (0.1 + numbers.uniform() * 89.9).to_radians();
            let azimuth = numbers.uniform() * std::f64::consts::TAU;
            let distance = 0.01 + numbers.uniform() * 10.0;
            let light = point
                + distance
                    * DVec3::new(
                        elevation.cos() * azimuth.cos(),
                        elevation.sin(),
                        elevation.cos() * azimuth.sin(),
                    );
            assert!(
                flat.light_visible(point, DVec3::Y, light),
                "flat: {point} -> {light}"
            );
        }
        let center = far.as_dvec3();
        for (t, triangle) in curved.triangles().iter().enumerate() {
            let [a, b, c] = triangle.vertices();
            let face = (b - a).cross(c - a);
            if face.length() < 1e-9 {
                continue;
            }
            let face = face.normalize();
            let (s, r) = (numbers.uniform(), numbers.uniform());
            let (s, r) = if s + r > 1.0 {
                (1.0 - s, 1.0 - r)
            } else {
                (s, r)
            };
            let point = a + (b - a) * s + (c - a) * r;
            let shading = (point - center).normalize();
            // A light on the face's outer side: a convex solid cannot block it.
            let mut direction = numbers.in_box(DVec3::splat(-1.0), DVec3::ONE).normalize();
            if direction.dot(face) < 0.05 {
                direction = (face + direction * 0.5).normalize();
            }
            if direction.dot(face) <= 0.0 {
                continue;
            }
            let light = point + direction * (0.05 + numbers.uniform() * 5.0);
            for normal in [face, shading] {
                assert!(
                    curved.light_visible(point, normal, light),
                    "sphere triangle {t}: {point} -> {light}"
                );
            }
        }
    }

    #[test]
    fn a_closed_box_keeps_its_light_inside() {
        let bvh = SceneBvh::build(&closed_box(DVec3::ZERO.as_vec3(), Vec3::ONE)).expect("builds");
        let light = DVec3::splat(0.5);
        let mut numbers = Numbers(5);
        for _ in 0..1000 {
            let outside = numbers.in_box(DVec3::splat(-3.0), DVec3::splat(4.0));
            if (0.0..=1.0).contains(&outside.x)
                && (0.0..=1.0).contains(&outside.y)
                && (0.0..=1.0).contains(&outside.z)
            {
                continue;
            }
            assert!(
                !bvh.light_visible(outside, (light - outside).normalize(), light),
                "{outside}"
            );
        }
    }
}
