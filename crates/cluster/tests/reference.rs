//! The CPU reference assignment against what shading needs, for random grids, cameras and
//! spheres (including spheres behind the eye, straddling the near plane and partly outside
//! the frustum): at random fragments, every light whose sphere contains the fragment is in
//! the fragment's cluster list; and every listed light intersects its cluster's box.

use glam::Vec3;
use manylights_cluster::{
    ClusterGrid, ClusterSettings, TileSpec, ViewSphere, ZRange, ZScheme, assign_lights,
    sphere_intersects_box,
};
use proptest::prelude::*;

fn scheme() -> impl Strategy<Value = ZScheme> {
    prop_oneof![
        Just(ZScheme::Linear),
        Just(ZScheme::Logarithmic),
        (0.2f32..5.0)
            .prop_map(|first_slice_far| ZScheme::LogarithmicWithNearSlice { first_slice_far }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn every_fragment_sees_every_light_that_reaches_it(
        tiles_x in 1u32..12, tiles_y in 1u32..8, slices in 1u32..20, z_scheme in scheme(),
        width in 1u32..400, height in 1u32..300, fov in 20f32..120.0, near in 0.01f32..1.0, depth_ratio in 2f32..1e4,
        spheres in proptest::collection::vec((-30f32..30.0, -30f32..30.0, -60f32..10.0, 0.001f32..8.0), 0..60),
        fragments in proptest::collection::vec((0f32..1.0, 0f32..1.0, 0f32..1.0), 200),
    ) {
        let settings = ClusterSettings { tiles: TileSpec::Count { x: tiles_x, y: tiles_y }, z_slices: slices, z_scheme, z_range: ZRange::Camera };
        let far = near * depth_ratio;
        let projection = glam::camera::rh::proj::directx::perspective(fov.to_radians(), width as f32 / height as f32, near, far);
        let grid = ClusterGrid::new(&settings, (width, height), projection, near, far, None).expect("grid");
        let bounds = grid.cluster_bounds();
        let spheres: Vec<ViewSphere> = spheres.iter().map(|&(x, y, z, radius)| ViewSphere { center: Vec3::new(x, y, z), radius }).collect();
        let lists = assign_lights(&grid, &bounds, &spheres);
        for (cluster, aabb) in bounds.iter().enumerate() {
            for &light in lists.list(cluster) {
                prop_assert!(sphere_intersects_box(&spheres[light as usize], aabb), "light {} listed in cluster {} without touching it", light, cluster);
            }
        }
        let inverse = projection.inverse();
        for (u, v, w) in fragments {
            let (px, py) = (u * width as f32, v * height as f32);
            // Depth spread logarithmically over the whole range, like real scenes.
            let depth = near * (far / near).powf(w);
            let ndc = glam::Vec4::new(px / width as f32 * 2.0 - 1.0, 1.0 - py / height as f32 * 2.0, 0.0, 1.0);
            let on_near = inverse * ndc;
            let ray = on_near.truncate() / on_near.w;
            let position = ray * (depth / -ray.z);
            let cluster = grid.flat_index(grid.cluster_of_fragment(px, py, depth)) as usize;
            for (light, sphere) in spheres.iter().enumerate() {
                // Lights reaching the fragment by a clear margin (f32 rounding aside).
                if position.distance(sphere.center) < sphere.radius * 0.999 {
                    prop_assert!(lists.list(cluster).contains(&(light as u32)),
                        "fragment at pixel ({}, {}) depth {} (cluster {}) misses light {} {:?}", px, py, depth, cluster, light, sphere);
                }
            }
        }
    }
}

#[test]
fn lights_at_the_edges_of_the_view() {
    let settings = ClusterSettings {
        tiles: TileSpec::Count { x: 8, y: 6 },
        z_slices: 16,
        z_scheme: ZScheme::Logarithmic,
        z_range: ZRange::Camera,
    };
    let projection =
        glam::camera::rh::proj::directx::perspective(60f32.to_radians(), 4.0 / 3.0, 0.1, 100.0);
    let grid = ClusterGrid::new(&settings, (128, 96), projection, 0.1, 100.0, None).expect("grid");
    let bounds = grid.cluster_bounds();
    let spheres = [
        // Behind the eye, but its sphere reaches 1 m into the view.
        ViewSphere {
            center: Vec3::new(0.0, 0.0, 1.0),
            radius: 2.0,
        },
        // Entirely behind the eye.
        ViewSphere {
            center: Vec3::new(0.0, 0.0, 3.0),
            radius: 2.0,
        },
        // Touching the near plane from in front.
        ViewSphere {
            center: Vec3::new(0.0, 0.0, -0.15),
            radius: 0.05,
        },
        // Mostly outside the frustum on the right.
        ViewSphere {
            center: Vec3::new(12.0, 0.0, -10.0),
            radius: 5.0,
        },
        // Far outside the frustum: in no cluster.
        ViewSphere {
            center: Vec3::new(100.0, 0.0, -10.0),
            radius: 5.0,
        },
        // Beyond the far plane, reaching back into the last slice.
        ViewSphere {
            center: Vec3::new(0.0, 0.0, -101.0),
            radius: 2.0,
        },
    ];
    let lists = assign_lights(&grid, &bounds, &spheres);
    let clusters_of = |light: u32| {
        (0..lists.cluster_count())
            .filter(|&c| lists.list(c).contains(&light))
            .count()
    };
    assert!(
        clusters_of(0) > 0,
        "a light behind the eye that reaches the view is listed"
    );
    assert_eq!(clusters_of(1), 0);
    assert!(clusters_of(2) > 0, "a light at the near plane is listed");
    assert!(
        clusters_of(3) > 0,
        "a light partly in the frustum is listed"
    );
    assert_eq!(clusters_of(4), 0);
    assert!(
        clusters_of(5) > 0,
        "a light beyond far that reaches the last slice is listed"
    );
}
