//! The CPU reference light assignment, with exactly the semantics of the GPU passes
//! (`shaders/cluster/assign.wgsl`) and usable by other engines on its own: give it a grid
//! and view-space spheres. A cluster lists, in increasing order, every light whose
//! view-space sphere intersects the cluster's box and lies in the light's candidate range
//! ([`candidate_range`]: its depth slices, and for spheres in front of the eye the tiles
//! its projection covers, each widened by one). The candidate range only removes lights
//! that cannot reach any fragment of the cluster (a cluster's fragments lie inside its
//! tile's frustum, which the box over-covers), so every light that reaches a fragment is in
//! that fragment's list; `tests/reference.rs` checks exactly that at random fragments.

use glam::{UVec3, Vec3};
use manylights_scene::Aabb;

use crate::grid::ClusterGrid;

/// A light as the assignment sees it: view-space centre and radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl ViewSphere {
    /// From the sphere half of the GPU's `ViewLight` (xyz centre, w radius).
    pub fn from_vec4(v: [f32; 4]) -> Self {
        Self {
            center: Vec3::new(v[0], v[1], v[2]),
            radius: v[3],
        }
    }
}

/// How assignment culls spot lights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum SpotCulling {
    /// By the cone: its bounding sphere chooses the candidate clusters and the cone is
    /// tested against each cluster's box (as Bevy and Filament do).
    #[default]
    Cone,
    /// By the range sphere alone, as if spots were point lights: what the cone test saves
    /// is measured against this.
    Sphere,
}

impl SpotCulling {
    pub const ALL: [SpotCulling; 2] = [SpotCulling::Cone, SpotCulling::Sphere];

    pub fn name(&self) -> &'static str {
        match self {
            SpotCulling::Cone => "cone",
            SpotCulling::Sphere => "sphere",
        }
    }

    /// `ClusterParams.culling_and_bands.x` (`SPOT_CULLING_CONE` in `bounds.wgsl`).
    pub fn shader_value(&self) -> u32 {
        match self {
            SpotCulling::Cone => 1,
            SpotCulling::Sphere => 0,
        }
    }
}

manylights_gpu::named_choice!(SpotCulling, "spot culling");

/// Relative growth of a spot's bounding sphere (`BOUNDING_SPHERE_SLACK` in WGSL).
pub const BOUNDING_SPHERE_SLACK: f32 = 1.00001;

/// A spot light's cone in view space: unit axis and the sine of its outer half-angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewCone {
    pub axis: Vec3,
    pub sin_outer: f32,
}

impl ViewCone {
    fn cos_outer(&self) -> f32 {
        (1.0 - self.sin_outer * self.sin_outer).max(0.0).sqrt()
    }
}

/// A light as the assignment tests it, in view space: its range sphere and, for a spot
/// culled by its cone, the cone. Mirrors `LightVolume` in `shaders/cluster/bounds.wgsl`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightVolume {
    pub sphere: ViewSphere,
    pub cone: Option<ViewCone>,
}

impl From<ViewSphere> for LightVolume {
    fn from(sphere: ViewSphere) -> Self {
        Self { sphere, cone: None }
    }
}

impl LightVolume {
    /// From the GPU's `ViewLight` (`bounds.wgsl`): the sphere and the cone (a negative w:
    /// no cone).
    pub fn from_vec4s(sphere: [f32; 4], cone: [f32; 4]) -> Self {
        Self {
            sphere: ViewSphere::from_vec4(sphere),
            cone: (cone[3] >= 0.0).then(|| ViewCone {
                axis: Vec3::new(cone[0], cone[1], cone[2]),
                sin_outer: cone[3],
            }),
        }
    }

    /// The smallest sphere around the lit region (for a spot, the cone cut by the range
    /// sphere): it decides the candidate clusters.
    pub fn bounding_sphere(&self) -> ViewSphere {
        let Some(cone) = self.cone else {
            return self.sphere;
        };
        let (apex, range) = (self.sphere.center, self.sphere.radius);
        let cos_outer = cone.cos_outer();
        let mut sphere = if cone.sin_outer < cos_outer {
            let half_chord = range / (2.0 * cos_outer);
            ViewSphere {
                center: apex + cone.axis * half_chord,
                radius: half_chord,
            }
        } else {
            ViewSphere {
                center: apex + cone.axis * (range * cos_outer),
                radius: range * cone.sin_outer,
            }
        };
        // The sphere passes through the apex and the rim: rounding its far centre (ranges
        // reach 1e15 m with the stochastic far field) must not leave them outside.
        sphere.radius *= BOUNDING_SPHERE_SLACK;
        sphere
    }

    /// The box's bounding sphere's signed distance outside the cone, minus its radius:
    /// positive means the box holds no point of the cone (`None` without a cone).
    pub fn cone_box_margin(&self, aabb: &Aabb) -> Option<f32> {
        let cone = self.cone?;
        let box_center = (aabb.min + aabb.max) * 0.5;
        let box_radius = (aabb.max - aabb.min).length() * 0.5;
        let v = box_center - self.sphere.center;
        let along = v.dot(cone.axis);
        let across = v.cross(cone.axis).length();
        Some(across * cone.cos_outer() - along * cone.sin_outer - box_radius)
    }

    /// Whether the volume meets the box (mirrors `volume_meets_bounds` in WGSL).
    pub fn meets_box(&self, aabb: &Aabb) -> bool {
        sphere_intersects_box(&self.sphere, aabb)
            && sphere_intersects_box(&self.bounding_sphere(), aabb)
            && self
                .cone_box_margin(aabb)
                .is_none_or(|margin| margin <= 0.0)
    }

    /// Whether the box lies within rounding of the volume's surface (either side may
    /// decide it differently in f32).
    fn is_borderline(&self, aabb: &Aabb) -> bool {
        let near_sphere = |sphere: &ViewSphere| {
            sphere_box_margin(sphere, aabb).abs() <= 1e-5 * sphere.radius * sphere.radius
        };
        let scale =
            (aabb.max - aabb.min).length() + self.sphere.center.length() + self.sphere.radius;
        near_sphere(&self.sphere)
            || near_sphere(&self.bounding_sphere())
            || self
                .cone_box_margin(aabb)
                .is_some_and(|margin| margin.abs() <= 1e-5 * scale)
    }
}

/// Compact light lists: cluster `c` owns `indices[offsets[c]..offsets[c + 1]]`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct LightLists {
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
}

impl LightLists {
    pub fn list(&self, cluster: usize) -> &[u32] {
        &self.indices[self.offsets[cluster] as usize..self.offsets[cluster + 1] as usize]
    }

    pub fn cluster_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn total(&self) -> usize {
        self.indices.len()
    }
}

/// Squared distance from the sphere's centre to the box, minus the squared radius:
/// negative or zero means they intersect; infinite for an empty box (a cluster no visible
/// sample falls in), which meets nothing. Mirrors `sphere_meets_bounds` in WGSL.
pub fn sphere_box_margin(sphere: &ViewSphere, aabb: &Aabb) -> f32 {
    if aabb.is_empty() {
        return f32::INFINITY;
    }
    let offset = sphere.center.clamp(aabb.min, aabb.max) - sphere.center;
    offset.dot(offset) - sphere.radius * sphere.radius
}

pub fn sphere_intersects_box(sphere: &ViewSphere, aabb: &Aabb) -> bool {
    sphere_box_margin(sphere, aabb) <= 0.0
}

/// A conservative range of clusters `sphere` may touch (inclusive), or `None` when it is
/// entirely behind the eye. Mirrors `candidate_range` in WGSL: the depth range widened by
/// one slice, and, for spheres entirely in front of the eye, the tiles covered by the
/// projected corners of the sphere's box widened by one tile.
pub fn candidate_range(grid: &ClusterGrid, sphere: &ViewSphere) -> Option<(UVec3, UVec3)> {
    let depth_min = -sphere.center.z - sphere.radius;
    let depth_max = -sphere.center.z + sphere.radius;
    if depth_max <= 0.0 {
        return None;
    }
    let last = grid.dims - UVec3::ONE;
    let slice_lo = grid.slice_of_depth(depth_min.max(0.0)).saturating_sub(1);
    let slice_hi = (grid.slice_of_depth(depth_max) + 1).min(last.z);
    let mut lo = UVec3::new(0, 0, slice_lo);
    let mut hi = UVec3::new(last.x, last.y, slice_hi);
    if depth_min > 0.0 {
        let (mut pixel_min, mut pixel_max) = (glam::Vec2::splat(1e30), glam::Vec2::splat(-1e30));
        for corner in 0..8u32 {
            let sign = Vec3::new(
                (corner & 1) as f32,
                ((corner >> 1) & 1) as f32,
                ((corner >> 2) & 1) as f32,
            ) * 2.0
                - 1.0;
            let clip = grid.projection * (sphere.center + sign * sphere.radius).extend(1.0);
            let ndc = clip.truncate().truncate() / clip.w;
            let pixel = glam::Vec2::new(ndc.x + 1.0, 1.0 - ndc.y)
                * 0.5
                * glam::Vec2::new(grid.screen.0 as f32, grid.screen.1 as f32);
            pixel_min = pixel_min.min(pixel);
            pixel_max = pixel_max.max(pixel);
        }
        let tile = glam::Vec2::new(grid.tile_size.0, grid.tile_size.1);
        let tile_min = (pixel_min / tile).floor() - 1.0;
        let tile_max = (pixel_max / tile).floor() + 1.0;
        let limit = glam::Vec2::new(last.x as f32, last.y as f32);
        if tile_max.cmplt(glam::Vec2::ZERO).any() || tile_min.cmpgt(limit).any() {
            return None;
        }
        let (a, b) = (
            tile_min.clamp(glam::Vec2::ZERO, limit),
            tile_max.clamp(glam::Vec2::ZERO, limit),
        );
        lo = UVec3::new(a.x as u32, a.y as u32, lo.z);
        hi = UVec3::new(b.x as u32, b.y as u32, hi.z);
    }
    Some((lo, hi))
}

/// Assigns lights to clusters on the CPU. `bounds` are the clusters' boxes: the grid's
/// ([`ClusterGrid::cluster_bounds`]) or a frame's visible-sample boxes
/// ([`crate::GpuClusters::read_bounds`], empty where nothing is seen). Lists are in
/// increasing light order (like the GPU's sorted lists).
pub fn assign_lights(grid: &ClusterGrid, bounds: &[Aabb], spheres: &[ViewSphere]) -> LightLists {
    let volumes: Vec<LightVolume> = spheres.iter().map(|&sphere| sphere.into()).collect();
    assign_light_volumes(grid, bounds, &volumes)
}

/// [`assign_lights`] for light volumes: spots with their cones ([`LightVolume`]), as the
/// GPU assigns them. The candidate range comes from each volume's bounding sphere.
pub fn assign_light_volumes(
    grid: &ClusterGrid,
    bounds: &[Aabb],
    volumes: &[LightVolume],
) -> LightLists {
    let clusters = grid.cluster_count() as usize;
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); clusters];
    // As the GPU's mark pass: each tile's first and last slice with a non-empty box, so a
    // light tests only those (empty boxes meet nothing: the lists are the same).
    let occupied = occupied_slices(grid, bounds);
    for (index, volume) in volumes.iter().enumerate() {
        let Some((lo, hi)) = candidate_range(grid, &volume.bounding_sphere()) else {
            continue;
        };
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let Some((first, last)) = occupied[(y * grid.dims.x + x) as usize] else {
                    continue;
                };
                for z in lo.z.max(first)..=hi.z.min(last) {
                    let cluster = grid.flat_index(UVec3::new(x, y, z)) as usize;
                    if volume.meets_box(&bounds[cluster]) {
                        lists[cluster].push(index as u32);
                    }
                }
            }
        }
    }
    let mut out = LightLists {
        offsets: Vec::with_capacity(clusters + 1),
        indices: Vec::new(),
    };
    out.offsets.push(0);
    for list in lists {
        out.indices.extend_from_slice(&list);
        out.offsets.push(out.indices.len() as u32);
    }
    out
}

/// For each tile, the first and last slice whose box is not empty (`None`: all are).
fn occupied_slices(grid: &ClusterGrid, bounds: &[Aabb]) -> Vec<Option<(u32, u32)>> {
    let mut occupied = vec![None; (grid.dims.x * grid.dims.y) as usize];
    for (cluster, aabb) in bounds.iter().enumerate() {
        if aabb.is_empty() {
            continue;
        }
        let at = grid.cluster_of_flat(cluster as u32);
        let range: &mut Option<(u32, u32)> = &mut occupied[(at.y * grid.dims.x + at.x) as usize];
        *range = Some(range.map_or((at.z, at.z), |(first, last)| {
            (first.min(at.z), last.max(at.z))
        }));
    }
    occupied
}

/// Checks lists built elsewhere (the GPU) against `reference`, [`assign_lights`] on the
/// very spheres they were built from (`bounds` are the grid's cluster boxes): the same multiset of lights per cluster (a light listed twice is
/// an error: it would be shaded twice), in ascending order for lists up to
/// `sorted_list_limit` long. The one leeway: a light whose sphere touches a cluster's box
/// within rounding (|margin| <= 1e-5 r^2, the distance computed in f32 on either side) may
/// be listed by one side only. Returns how many such borderline entries there were.
pub fn compare_with_reference(
    lists: &LightLists,
    reference: &LightLists,
    bounds: &[Aabb],
    spheres: &[ViewSphere],
    sorted_list_limit: usize,
) -> Result<usize, String> {
    let volumes: Vec<LightVolume> = spheres.iter().map(|&sphere| sphere.into()).collect();
    compare_volumes_with_reference(lists, reference, bounds, &volumes, sorted_list_limit)
}

/// [`compare_with_reference`] for light volumes (spots with cones): the leeway also
/// covers boxes within rounding of a cone's side.
pub fn compare_volumes_with_reference(
    lists: &LightLists,
    reference: &LightLists,
    bounds: &[Aabb],
    volumes: &[LightVolume],
    sorted_list_limit: usize,
) -> Result<usize, String> {
    if lists.cluster_count() != reference.cluster_count() {
        return Err(format!(
            "{} clusters listed, {} in the grid",
            lists.cluster_count(),
            reference.cluster_count()
        ));
    }
    if lists.offsets[0] != 0 {
        return Err(format!("the first list starts at {}", lists.offsets[0]));
    }
    let mut borderline = 0;
    for (cluster, cluster_bounds) in bounds.iter().enumerate() {
        let listed = lists.list(cluster);
        let mut sorted = listed.to_vec();
        sorted.sort_unstable();
        if let Some(pair) = sorted.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(format!(
                "cluster {cluster}: light {} listed twice: {listed:?}",
                pair[0]
            ));
        }
        if listed.len() <= sorted_list_limit && listed != sorted {
            return Err(format!(
                "cluster {cluster}: lights not in ascending order: {listed:?}"
            ));
        }
        let expected = reference.list(cluster);
        let one_side = sorted
            .iter()
            .filter(|light| !expected.contains(light))
            .chain(expected.iter().filter(|light| !sorted.contains(light)));
        for &light in one_side {
            let volume = volumes[light as usize];
            if !volume.is_borderline(cluster_bounds) {
                return Err(format!(
                    "cluster {cluster}: light {light} ({volume:?}) listed by one side only: {sorted:?}, reference {expected:?}"
                ));
            }
            borderline += 1;
        }
    }
    Ok(borderline)
}

/// World-space lights to view-space spheres (what the GPU's count pass computes).
pub fn view_spheres(view: &glam::Mat4, lights: &[manylights_lights::Light]) -> Vec<ViewSphere> {
    lights
        .iter()
        .map(|light| ViewSphere {
            center: (*view * Vec3::from_array(light.position).extend(1.0)).truncate(),
            radius: light.radius,
        })
        .collect()
}

/// World-space lights to the volumes the GPU's assignment tests (spots with their cones
/// unless `spot_culling` is [`SpotCulling::Sphere`]).
pub fn view_volumes(
    view: &glam::Mat4,
    lights: &[manylights_lights::Light],
    spot_culling: SpotCulling,
) -> Vec<LightVolume> {
    view_spheres(view, lights)
        .into_iter()
        .zip(lights)
        .map(|(sphere, light)| LightVolume {
            sphere,
            cone: (light.is_spot() && spot_culling == SpotCulling::Cone).then(|| ViewCone {
                axis: view
                    .transform_vector3(Vec3::from_array(light.direction))
                    .normalize(),
                sin_outer: light.sin2_outer.sqrt(),
            }),
        })
        .collect()
}
