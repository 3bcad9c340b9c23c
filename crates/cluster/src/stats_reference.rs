//! Per-frame statistics of light lists: lights per cluster (mean, max, histogram), total
//! list length, and (debug) the false-positive ratio.

use glam::{UVec3, Vec3};

use crate::assign_reference::{LightLists, ViewSphere};
use crate::grid::ClusterGrid;

/// Lights-per-cluster statistics of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterStats {
    pub clusters: u32,
    /// Sum of all list lengths.
    pub total_entries: u64,
    pub mean_lights: f64,
    pub max_lights: u32,
    /// Clusters with 0, 1, 2-3, 4-7, 8-15, ... lights: `histogram[0]` counts empty
    /// clusters, `histogram[k]` those with 2^(k-1) to 2^k - 1 lights.
    pub histogram: Vec<u32>,
    /// Listed lights that reach no pixel of their cluster, over all entries of clusters
    /// that have pixels (debug mode only; see [`false_positive_ratio`]).
    pub false_positive_ratio: Option<f64>,
}

impl ClusterStats {
    /// From list offsets (`offsets[c + 1] - offsets[c]` lights in cluster `c`).
    pub fn from_offsets(offsets: &[u32]) -> Self {
        let clusters = offsets.len().saturating_sub(1) as u32;
        let mut histogram = vec![0u32; 2];
        let mut max_lights = 0;
        for pair in offsets.windows(2) {
            let count = pair[1].saturating_sub(pair[0]);
            max_lights = max_lights.max(count);
            let bucket = if count == 0 {
                0
            } else {
                32 - count.leading_zeros() as usize
            };
            if histogram.len() <= bucket {
                histogram.resize(bucket + 1, 0);
            }
            histogram[bucket] += 1;
        }
        let total_entries = offsets.last().copied().unwrap_or(0) as u64;
        Self {
            clusters,
            total_entries,
            mean_lights: if clusters == 0 {
                0.0
            } else {
                total_entries as f64 / clusters as f64
            },
            max_lights,
            histogram,
            false_positive_ratio: None,
        }
    }
}

impl std::fmt::Display for ClusterStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} clusters, {} list entries, lights per cluster mean {:.2} max {}",
            self.clusters, self.total_entries, self.mean_lights, self.max_lights
        )?;
        if let Some(ratio) = self.false_positive_ratio {
            write!(f, ", false positives {:.1}%", ratio * 100.0)?;
        }
        Ok(())
    }
}

/// The fraction of list entries (in clusters that contain at least one visible pixel)
/// whose light reaches no visible pixel of that cluster: the cost of testing against boxes
/// rather than the geometry actually there. `view_positions` are the view-space positions
/// of the frame's pixels (row-major, `None` for background), e.g. from the depth buffer.
pub fn false_positive_ratio(
    grid: &ClusterGrid,
    lists: &LightLists,
    spheres: &[ViewSphere],
    view_positions: &[Option<Vec3>],
) -> f64 {
    let clusters = grid.cluster_count() as usize;
    let mut pixels_of: Vec<Vec<Vec3>> = vec![Vec::new(); clusters];
    let width = grid.screen.0 as usize;
    for (i, position) in view_positions.iter().enumerate() {
        if let Some(p) = position {
            let (x, y) = ((i % width) as f32 + 0.5, (i / width) as f32 + 0.5);
            let cluster: UVec3 = grid.cluster_of_fragment(x, y, -p.z);
            pixels_of[grid.flat_index(cluster) as usize].push(*p);
        }
    }
    let (mut entries, mut useless) = (0u64, 0u64);
    for (cluster, pixels) in pixels_of.iter().enumerate() {
        if pixels.is_empty() {
            continue;
        }
        for &light in lists.list(cluster) {
            let sphere = spheres[light as usize];
            entries += 1;
            let reaches = pixels
                .iter()
                .any(|p| p.distance_squared(sphere.center) < sphere.radius * sphere.radius);
            useless += u64::from(!reaches);
        }
    }
    if entries == 0 {
        0.0
    } else {
        useless as f64 / entries as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_buckets_by_powers_of_two() {
        // Counts 0, 1, 3, 4, 9.
        let stats = ClusterStats::from_offsets(&[0, 0, 1, 4, 8, 17]);
        assert_eq!(stats.clusters, 5);
        assert_eq!(stats.total_entries, 17);
        assert_eq!(stats.max_lights, 9);
        assert_eq!(stats.histogram, vec![1, 1, 1, 1, 1]);
        assert!((stats.mean_lights - 3.4).abs() < 1e-12);
    }
}
