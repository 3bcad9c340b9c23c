//! The cluster grid: screen tiles x depth slices, the depth-slicing schemes, the view-space
//! bounds of every cluster, and the fragment-to-cluster index (the Rust twin of
//! `shaders/cluster/cluster_index.wgsl`).
//!
//! Clustered shading: Olsson, Billeter and Assarsson 2012, "Clustered Deferred and Forward
//! Shading"; logarithmic slicing as in Doom 2016 (Sousa, Geffroy, Ollier); a separate first
//! slice as in Bevy's and Filament's froxels.

use glam::{Mat4, UVec3, Vec3, Vec4};
use manylights_scene::Aabb;

/// How the screen is divided into tiles.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TileSpec {
    /// This many tiles across and down, whatever the resolution.
    Count { x: u32, y: u32 },
    /// Square tiles of this many pixels (the last row and column may be partial).
    PixelSize(u32),
}

/// How depth is divided into slices.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ZScheme {
    /// Slice boundaries in geometric progression from near to far (Olsson 2012, Doom
    /// 2016): clusters stay roughly cubic in view space.
    Logarithmic,
    /// Slice 0 covers near..`first_slice_far`; the rest are logarithmic from there to far
    /// (Bevy, Filament): avoids many thin slices right in front of the camera, where
    /// there is usually little geometry.
    LogarithmicWithNearSlice { first_slice_far: f32 },
    /// Equal-thickness slices: far clusters much smaller than near ones on screen.
    Linear,
}

/// The near slice's far depth (metres) of [`ZScheme::LogarithmicWithNearSlice`] where
/// none is given: the grid's default (docs/architecture/clustering.md, "Cluster defaults").
pub const DEFAULT_FIRST_SLICE_FAR: f32 = 1.0;

impl ZScheme {
    /// Every slicing by name, `log-near` with [`DEFAULT_FIRST_SLICE_FAR`].
    pub const ALL: [ZScheme; 3] = [
        ZScheme::LogarithmicWithNearSlice {
            first_slice_far: DEFAULT_FIRST_SLICE_FAR,
        },
        ZScheme::Logarithmic,
        ZScheme::Linear,
    ];

    /// The name the CLI and the lab use (`log-near`, `log`, `linear`).
    pub fn name(&self) -> &'static str {
        match self {
            ZScheme::LogarithmicWithNearSlice { .. } => "log-near",
            ZScheme::Logarithmic => "log",
            ZScheme::Linear => "linear",
        }
    }

    /// The same slicing with the near slice ending at `first_slice_far` (only `log-near`
    /// has a near slice; the others are returned as they are).
    pub fn with_first_slice_far(self, first_slice_far: f32) -> Self {
        match self {
            ZScheme::LogarithmicWithNearSlice { .. } => {
                ZScheme::LogarithmicWithNearSlice { first_slice_far }
            }
            other => other,
        }
    }

    /// `Z_SCHEME_*` in `cluster_index.wgsl` (`ClusterParams::scheme_lights_capacity.x`).
    pub(crate) const LINEAR_CODE: u32 = 0;
    pub(crate) const LOGARITHMIC_CODE: u32 = 1;
    pub(crate) const LOG_NEAR_SLICE_CODE: u32 = 2;

    pub(crate) fn shader_code(&self) -> u32 {
        match self {
            ZScheme::Linear => Self::LINEAR_CODE,
            ZScheme::Logarithmic => Self::LOGARITHMIC_CODE,
            ZScheme::LogarithmicWithNearSlice { .. } => Self::LOG_NEAR_SLICE_CODE,
        }
    }
}

/// Which depth range the slices cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum ZRange {
    /// The camera's near and far planes.
    Camera,
    /// The depth range the scene's bounds occupy in view, clamped to near/far and
    /// recomputed each frame: no slices are spent on empty depth.
    FittedToScene,
}

manylights_gpu::named_choice!(ZScheme, "depth slicing");

impl ZRange {
    pub const ALL: [ZRange; 2] = [ZRange::Camera, ZRange::FittedToScene];

    /// The name the CLI and the lab use (`camera`, `fitted`).
    pub fn name(&self) -> &'static str {
        match self {
            ZRange::Camera => "camera",
            ZRange::FittedToScene => "fitted",
        }
    }
}

manylights_gpu::named_choice!(ZRange, "depth range");

/// Cluster grid settings. The defaults were chosen by measurement
/// (docs/architecture/clustering.md, "Cluster defaults"): 16x9 tiles, 48 logarithmic
/// slices with a 1 m near slice, range fitted to the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct ClusterSettings {
    pub tiles: TileSpec,
    /// Depth slices. Too few: lights are listed in clusters whose depth they barely
    /// touch (more false positives); too many: more clusters to assign and store.
    pub z_slices: u32,
    pub z_scheme: ZScheme,
    pub z_range: ZRange,
}

impl Default for ClusterSettings {
    fn default() -> Self {
        Self {
            tiles: TileSpec::Count { x: 16, y: 9 },
            z_slices: 48,
            z_scheme: ZScheme::LogarithmicWithNearSlice {
                first_slice_far: DEFAULT_FIRST_SLICE_FAR,
            },
            z_range: ZRange::FittedToScene,
        }
    }
}

/// Largest number of clusters accepted: keeps the per-cluster buffers and the single
/// workgroup prefix sum (each of 256 threads scans its share sequentially) bounded.
pub const MAX_CLUSTERS: u32 = 1 << 20;

/// Relative inflation of every cluster's depth bounds. The fragment's slice is computed
/// with a logarithm on the GPU, the bounds on the CPU; at a slice boundary the two may
/// disagree by an ulp, and the inflation keeps every light that touches the fragment in
/// the fragment's cluster.
pub const DEPTH_BOUNDS_INFLATION: f32 = 1e-4;

/// Why a grid cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    #[error("cluster grid: {0}")]
    Invalid(String),
}

/// A cluster grid for one frame: everything the index function and the bounds need.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterGrid {
    /// Tiles across, tiles down, depth slices.
    pub dims: UVec3,
    /// Tile size in pixels (x, y); the last column/row may be partial.
    pub tile_size: (f32, f32),
    /// Render target size in pixels.
    pub screen: (u32, u32),
    /// The depth range the slices cover (positive view-space distances).
    pub z_near: f32,
    pub z_far: f32,
    pub scheme: ZScheme,
    /// View to clip, for the tiles' view-space bounds.
    pub projection: Mat4,
}

impl ClusterGrid {
    /// The grid for an engine's camera, as [`ViewUniform::from_matrices`] read it: its
    /// target size, projection and planes. `scene_bounds_world` (the world-space box of
    /// what is drawn) lets [`ZRange::FittedToScene`] slice only the depth the scene
    /// occupies, and is what bounds the slices of an infinite-far projection.
    ///
    /// [`ViewUniform::from_matrices`]: manylights_gpu::ViewUniform::from_matrices
    pub fn for_view(
        settings: &ClusterSettings,
        view: &manylights_gpu::ViewUniform,
        scene_bounds_world: Option<Aabb>,
    ) -> Result<Self, GridError> {
        let (near, far) = view.near_far();
        let scene_in_view =
            scene_bounds_world.map(|bounds| bounds.transformed(&view.view_matrix()));
        Self::new(
            settings,
            view.size(),
            view.projection_matrix(),
            near,
            far,
            scene_in_view,
        )
    }

    /// The grid for a frame. `scene_bounds_view` is the scene's AABB in view space (for
    /// [`ZRange::FittedToScene`]).
    pub fn new(
        settings: &ClusterSettings,
        screen: (u32, u32),
        projection: Mat4,
        camera_near: f32,
        camera_far: f32,
        scene_bounds_view: Option<Aabb>,
    ) -> Result<Self, GridError> {
        let invalid = |m: String| Err(GridError::Invalid(m));
        if screen.0 == 0 || screen.1 == 0 {
            return invalid(format!("screen {}x{} is empty", screen.0, screen.1));
        }
        let (tiles_x, tiles_y) = match settings.tiles {
            TileSpec::Count { x, y } => (x.clamp(1, screen.0), y.clamp(1, screen.1)),
            TileSpec::PixelSize(0) => {
                return invalid("tile size must be at least one pixel".into());
            }
            TileSpec::PixelSize(px) => (screen.0.div_ceil(px), screen.1.div_ceil(px)),
        };
        if settings.z_slices == 0 {
            return invalid("at least one depth slice is needed".into());
        }
        let count = tiles_x as u64 * tiles_y as u64 * settings.z_slices as u64;
        if count > MAX_CLUSTERS as u64 {
            return invalid(format!(
                "{tiles_x}x{tiles_y}x{} = {count} clusters is over the limit of {MAX_CLUSTERS}",
                settings.z_slices
            ));
        }
        let orthographic = projection.z_axis.w == 0.0 && projection.w_axis.w == 1.0;
        let near_ok = if orthographic {
            camera_near >= 0.0
        } else {
            camera_near > 0.0
        };
        if !(near_ok && camera_near.is_finite() && camera_far > camera_near) {
            return invalid(format!(
                "needs 0 < near < far (near {camera_near}, far {camera_far})"
            ));
        }
        let (z_near, z_far) = match sliced_depth_range(
            settings.z_range,
            scene_bounds_view,
            camera_near,
            camera_far,
        ) {
            Ok(range) => range,
            Err(message) => return invalid(message),
        };
        let scheme = match settings.z_scheme {
            ZScheme::LogarithmicWithNearSlice { first_slice_far }
                if !(first_slice_far > z_near && first_slice_far < z_far)
                    || settings.z_slices < 2 =>
            {
                // The near slice would be empty or everything: plain logarithmic.
                ZScheme::Logarithmic
            }
            other => other,
        };
        let tile_size = match settings.tiles {
            TileSpec::PixelSize(px) => (px as f32, px as f32),
            TileSpec::Count { .. } => (
                screen.0 as f32 / tiles_x as f32,
                screen.1 as f32 / tiles_y as f32,
            ),
        };
        Ok(Self {
            dims: UVec3::new(tiles_x, tiles_y, settings.z_slices),
            tile_size,
            screen,
            z_near,
            z_far,
            scheme,
            projection,
        })
    }

    pub fn cluster_count(&self) -> u32 {
        self.dims.x * self.dims.y * self.dims.z
    }

    /// Flat index of cluster (x, y, z): x fastest, then y, then z.
    pub fn flat_index(&self, cluster: UVec3) -> u32 {
        (cluster.z * self.dims.y + cluster.y) * self.dims.x + cluster.x
    }

    pub fn cluster_of_flat(&self, index: u32) -> UVec3 {
        UVec3::new(
            index % self.dims.x,
            (index / self.dims.x) % self.dims.y,
            index / (self.dims.x * self.dims.y),
        )
    }

    /// The slice holding view depth `depth` (positive distance), clamped to the grid.
    /// Mirrors `cluster_slice` in `shaders/cluster/cluster_index.wgsl`.
    pub fn slice_of_depth(&self, depth: f32) -> u32 {
        let slices = self.dims.z as f32;
        let slice = match self.scheme {
            ZScheme::Linear => (depth - self.z_near) / (self.z_far - self.z_near) * slices,
            ZScheme::Logarithmic => {
                (depth / self.z_near).ln() / (self.z_far / self.z_near).ln() * slices
            }
            ZScheme::LogarithmicWithNearSlice { first_slice_far } => {
                if depth < first_slice_far {
                    0.0
                } else {
                    1.0 + (depth / first_slice_far).ln() / (self.z_far / first_slice_far).ln()
                        * (slices - 1.0)
                }
            }
        };
        // NaN (depth 0 or negative) lands in slice 0.
        if slice.is_nan() {
            0
        } else {
            (slice.max(0.0) as u32).min(self.dims.z - 1)
        }
    }

    /// Near boundary (view depth) of `slice`; `slice == dims.z` gives the far boundary.
    pub fn slice_near_depth(&self, slice: u32) -> f32 {
        let slices = self.dims.z as f32;
        let k = slice as f32;
        match self.scheme {
            ZScheme::Linear => self.z_near + (self.z_far - self.z_near) * k / slices,
            ZScheme::Logarithmic => self.z_near * (self.z_far / self.z_near).powf(k / slices),
            ZScheme::LogarithmicWithNearSlice { first_slice_far } => {
                if slice == 0 {
                    self.z_near
                } else {
                    first_slice_far
                        * (self.z_far / first_slice_far).powf((k - 1.0) / (slices - 1.0))
                }
            }
        }
    }

    /// The cluster a fragment at pixel coordinates (`frag_x`, `frag_y`, pixel centres at
    /// .5) and view depth `depth` belongs to. Mirrors `cluster_index` in WGSL.
    pub fn cluster_of_fragment(&self, frag_x: f32, frag_y: f32, depth: f32) -> UVec3 {
        let x = ((frag_x / self.tile_size.0) as u32).min(self.dims.x - 1);
        let y = ((frag_y / self.tile_size.1) as u32).min(self.dims.y - 1);
        UVec3::new(x, y, self.slice_of_depth(depth))
    }

    /// The view-space line of the points a screen position (in pixels) shows, as
    /// (point at view depth 0, step per unit of depth): for a perspective projection a ray
    /// from the eye, for an orthographic one a line parallel to -Z. Found by unprojecting
    /// two depths, so it holds for both (and for infinite far planes).
    fn view_line(&self, pixel_x: f32, pixel_y: f32, inverse_projection: &Mat4) -> (Vec3, Vec3) {
        let ndc_x = pixel_x / self.screen.0 as f32 * 2.0 - 1.0;
        let ndc_y = 1.0 - pixel_y / self.screen.1 as f32 * 2.0;
        let unproject = |z: f32| {
            let p = *inverse_projection * Vec4::new(ndc_x, ndc_y, z, 1.0);
            p.truncate() / p.w
        };
        // Depths 0.25 and 0.75 are finite for every convention (0 or 1 may be an
        // infinite far plane).
        let (a, b) = (unproject(0.25), unproject(0.75));
        let step = (b - a) / (a.z - b.z);
        (a + step * a.z, step)
    }

    /// Whether the projection is orthographic (no perspective divide).
    pub fn is_orthographic(&self) -> bool {
        self.projection.z_axis.w == 0.0 && self.projection.w_axis.w == 1.0
    }

    /// The view-space AABB of every cluster, in flat order: the tile's four corner rays
    /// cut at the slice's near and far depths (inflated by [`DEPTH_BOUNDS_INFLATION`]).
    /// Computed once, here, and uploaded: CPU and GPU assignment test the same boxes.
    pub fn cluster_bounds(&self) -> Vec<Aabb> {
        let inverse_projection = self.projection.inverse();
        let mut tile_rays = Vec::with_capacity((self.dims.x * self.dims.y) as usize);
        for y in 0..self.dims.y {
            for x in 0..self.dims.x {
                let (x0, x1) = (
                    x as f32 * self.tile_size.0,
                    ((x + 1) as f32 * self.tile_size.0).min(self.screen.0 as f32),
                );
                let (y0, y1) = (
                    y as f32 * self.tile_size.1,
                    ((y + 1) as f32 * self.tile_size.1).min(self.screen.1 as f32),
                );
                tile_rays.push(
                    [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
                        .map(|(px, py)| self.view_line(px, py, &inverse_projection)),
                );
            }
        }
        let mut bounds = Vec::with_capacity(self.cluster_count() as usize);
        for z in 0..self.dims.z {
            let near = self.slice_near_depth(z) * (1.0 - DEPTH_BOUNDS_INFLATION);
            let far = self.slice_near_depth(z + 1) * (1.0 + DEPTH_BOUNDS_INFLATION);
            // The first and last slices also hold fragments clamped into them.
            // (An orthographic camera can see from depth 0.)
            let near = match (z, self.is_orthographic()) {
                (0, true) => 0.0,
                (0, false) => near.min(self.z_near * 0.5),
                _ => near,
            };
            let far = if z == self.dims.z - 1 {
                far.max(self.z_far * 2.0)
            } else {
                far
            };
            for rays in &tile_rays {
                let mut aabb = Aabb::EMPTY;
                for (origin, step) in rays {
                    aabb.grow(*origin + *step * near);
                    aabb.grow(*origin + *step * far);
                }
                bounds.push(aabb);
            }
        }
        bounds
    }
}

/// The depth range the slices cover: the camera's (`near`, `far`), or with
/// [`ZRange::FittedToScene`] the part of it the scene's view-space `bounds` occupy; a
/// near plane at 0 (orthographic) moved to a positive start, and an infinite far plane cut
/// to the scene's farthest depth (refused without bounds).
fn sliced_depth_range(
    z_range: ZRange,
    bounds: Option<Aabb>,
    near: f32,
    far: f32,
) -> Result<(f32, f32), String> {
    let (mut z_near, mut z_far) = (near, far);
    if let (ZRange::FittedToScene, Some(bounds)) = (z_range, bounds)
        && !bounds.is_empty()
    {
        // View space looks down -Z: depth = -z.
        let nearest = (-bounds.max.z).max(near);
        let farthest = (-bounds.min.z).min(far);
        if farthest > nearest {
            z_near = nearest;
            z_far = farthest;
        }
    }
    if z_near <= 0.0 {
        // An orthographic camera with near 0: logarithmic slicing needs a positive start;
        // depths below it fall into slice 0, whose box reaches depth 0.
        z_near = (z_far * 1e-4).min(1e-3);
    }
    if !z_far.is_finite() {
        // An infinite far plane: slices can only cover the depth the scene occupies.
        match bounds.filter(|b| !b.is_empty()) {
            Some(bounds) => z_far = (-bounds.min.z).max(z_near * 2.0),
            None => {
                return Err(
                    "an infinite far plane needs the scene's bounds to fit the depth range to"
                        .into(),
                );
            }
        }
    }
    Ok((z_near, z_far))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn projection() -> Mat4 {
        glam::camera::rh::proj::directx::perspective(60f32.to_radians(), 16.0 / 9.0, 0.1, 100.0)
    }

    fn grid(scheme: ZScheme) -> ClusterGrid {
        let settings = ClusterSettings {
            tiles: TileSpec::Count { x: 16, y: 9 },
            z_slices: 24,
            z_scheme: scheme,
            z_range: ZRange::Camera,
        };
        ClusterGrid::new(&settings, (1280, 720), projection(), 0.1, 100.0, None).expect("grid")
    }

    #[test]
    fn z_range_names_round_trip() {
        for range in ZRange::ALL {
            assert_eq!(range.to_string().parse::<ZRange>(), Ok(range));
        }
        assert_eq!("fitted".parse::<ZRange>(), Ok(ZRange::FittedToScene));
        assert!("scene".parse::<ZRange>().is_err());
    }

    #[test]
    fn slice_of_depth_inverts_slice_boundaries() {
        for scheme in [
            ZScheme::Linear,
            ZScheme::Logarithmic,
            ZScheme::LogarithmicWithNearSlice {
                first_slice_far: 2.0,
            },
        ] {
            let grid = grid(scheme);
            for slice in 0..grid.dims.z {
                let (near, far) = (
                    grid.slice_near_depth(slice),
                    grid.slice_near_depth(slice + 1),
                );
                assert!(far > near, "{scheme:?} slice {slice}");
                let middle = (near + far) / 2.0;
                assert_eq!(
                    grid.slice_of_depth(middle),
                    slice,
                    "{scheme:?}: depth {middle}"
                );
            }
            assert!((grid.slice_near_depth(grid.dims.z) - 100.0).abs() < 1e-3);
            assert_eq!(grid.slice_of_depth(0.0), 0);
            assert_eq!(grid.slice_of_depth(-5.0), 0);
            assert_eq!(grid.slice_of_depth(1e9), grid.dims.z - 1);
        }
    }

    #[test]
    fn every_fragment_lies_in_its_cluster_bounds() {
        for scheme in [
            ZScheme::Linear,
            ZScheme::Logarithmic,
            ZScheme::LogarithmicWithNearSlice {
                first_slice_far: 2.0,
            },
        ] {
            let grid = grid(scheme);
            let bounds = grid.cluster_bounds();
            let inverse = grid.projection.inverse();
            for (px, py) in [
                (0.5, 0.5),
                (640.0, 360.0),
                (1279.5, 719.5),
                (80.0, 80.0),
                (1000.25, 3.75),
            ] {
                for depth in [0.1, 0.15, 0.5, 1.0, 2.0, 2.0001, 7.3, 50.0, 99.9] {
                    let (origin, step) = grid.view_line(px, py, &inverse);
                    let position = origin + step * depth;
                    let cluster = grid.cluster_of_fragment(px, py, depth);
                    let aabb = bounds[grid.flat_index(cluster) as usize];
                    let slack = Vec3::splat(1e-4 * depth);
                    assert!(
                        position.cmpge(aabb.min - slack).all()
                            && position.cmple(aabb.max + slack).all(),
                        "{scheme:?}: pixel ({px},{py}) depth {depth} at {position} outside cluster {cluster} {aabb:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn fitted_range_follows_the_scene() {
        let settings = ClusterSettings {
            z_range: ZRange::FittedToScene,
            ..ClusterSettings::default()
        };
        let scene = Aabb::new(Vec3::new(-5.0, -5.0, -30.0), Vec3::new(5.0, 5.0, -4.0));
        let grid = ClusterGrid::new(
            &settings,
            (640, 360),
            projection(),
            0.1,
            1000.0,
            Some(scene),
        )
        .expect("grid");
        assert_eq!((grid.z_near, grid.z_far), (4.0, 30.0));
        // A scene around the camera clamps to the near plane.
        let around = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        let grid = ClusterGrid::new(
            &settings,
            (640, 360),
            projection(),
            0.1,
            1000.0,
            Some(around),
        )
        .expect("grid");
        assert_eq!((grid.z_near, grid.z_far), (0.1, 10.0));
    }

    #[test]
    fn an_infinite_far_plane_slices_the_scene_depth() {
        let projection = glam::camera::rh::proj::directx::perspective_infinite(
            60f32.to_radians(),
            16.0 / 9.0,
            0.1,
        );
        let scene = Aabb::new(Vec3::new(-5.0, -5.0, -40.0), Vec3::new(5.0, 5.0, -2.0));
        for z_range in [ZRange::Camera, ZRange::FittedToScene] {
            let settings = ClusterSettings {
                z_range,
                ..ClusterSettings::default()
            };
            let grid = ClusterGrid::new(
                &settings,
                (640, 360),
                projection,
                0.1,
                f32::INFINITY,
                Some(scene),
            )
            .expect("grid");
            assert!(
                grid.z_far.is_finite() && grid.z_far >= 40.0 - 1e-3,
                "{z_range:?}: {}",
                grid.z_far
            );
            assert!(
                grid.cluster_bounds()
                    .iter()
                    .all(|b| b.min.is_finite() && b.max.is_finite())
            );
        }
        let error = ClusterGrid::new(
            &ClusterSettings::default(),
            (640, 360),
            projection,
            0.1,
            f32::INFINITY,
            None,
        )
        .expect_err("no bounds");
        assert!(error.to_string().contains("infinite far plane"), "{error}");
    }

    #[test]
    fn tiles_by_pixel_size_cover_odd_resolutions() {
        let settings = ClusterSettings {
            tiles: TileSpec::PixelSize(64),
            ..ClusterSettings::default()
        };
        let grid =
            ClusterGrid::new(&settings, (1921, 1), projection(), 0.1, 10.0, None).expect("grid");
        assert_eq!((grid.dims.x, grid.dims.y), (31, 1));
        assert_eq!(grid.cluster_of_fragment(1920.5, 0.5, 1.0).x, 30);
        assert!(
            ClusterGrid::new(
                &ClusterSettings {
                    tiles: TileSpec::PixelSize(0),
                    ..settings
                },
                (8, 8),
                projection(),
                0.1,
                10.0,
                None
            )
            .is_err()
        );
    }
}
