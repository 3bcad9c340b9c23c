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
    /// From the GPU's `view_lights` layout (xyz centre, w radius).
    pub fn from_vec4(v: [f32; 4]) -> Self {
        Self {
            center: Vec3::new(v[0], v[1], v[2]),
            radius: v[3],
        }
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
    let clusters = grid.cluster_count() as usize;
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); clusters];
    // As the GPU's mark pass: each tile's first and last slice with a non-empty box, so a
    // light tests only those (empty boxes meet nothing: the lists are the same).
    let occupied = occupied_slices(grid, bounds);
    for (index, sphere) in spheres.iter().enumerate() {
        let Some((lo, hi)) = candidate_range(grid, sphere) else {
            continue;
        };
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let Some((first, last)) = occupied[(y * grid.dims.x + x) as usize] else {
                    continue;
                };
                for z in lo.z.max(first)..=hi.z.min(last) {
                    let cluster = grid.flat_index(UVec3::new(x, y, z)) as usize;
                    if sphere_intersects_box(sphere, &bounds[cluster]) {
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
            let sphere = spheres[light as usize];
            let margin = sphere_box_margin(&sphere, cluster_bounds);
            if margin.abs() > 1e-5 * sphere.radius * sphere.radius {
                return Err(format!(
                    "cluster {cluster}: light {light} ({sphere:?}, margin {margin}) listed by one side only: {sorted:?}, reference {expected:?}"
                ));
            }
            borderline += 1;
        }
    }
    Ok(borderline)
}

/// World-space lights to view-space spheres (what the GPU's count pass computes).
pub fn view_spheres(
    view: &glam::Mat4,
    lights: &[manylights_lights::PointLight],
) -> Vec<ViewSphere> {
    lights
        .iter()
        .map(|light| ViewSphere {
            center: (*view * Vec3::from_array(light.position).extend(1.0)).truncate(),
            radius: light.radius,
        })
        .collect()
}
