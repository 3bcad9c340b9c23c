//! The grid's CPU contracts on their own (the GPU twins are held to these by
//! tests/forward_plus.rs): flat indices, slices, fragment-to-cluster, the cluster boxes
//! against an independent computation from the projection, candidate ranges against brute
//! force, and the false-positive ratio on hand-made cases. Written against the survivors of
//! `cargo mutants -p manylights-cluster` (docs/testing.md).

use glam::camera::rh::proj::directx;
use glam::{Mat4, UVec3, Vec3};
use manylights_cluster::{
    ClusterGrid, ClusterSettings, DEPTH_BOUNDS_INFLATION, LightLists, TileSpec, ViewSphere, ZRange,
    ZScheme, candidate_range, false_positive_ratio, view_spheres,
};

const SCREEN: (u32, u32) = (100, 60);
const NEAR: f32 = 0.1;
const FAR: f32 = 100.0;

fn grid(scheme: ZScheme, projection: Mat4, tiles: (u32, u32), slices: u32) -> ClusterGrid {
    let settings = ClusterSettings {
        tiles: TileSpec::Count {
            x: tiles.0,
            y: tiles.1,
        },
        z_slices: slices,
        z_scheme: scheme,
        z_range: ZRange::Camera,
    };
    ClusterGrid::new(&settings, SCREEN, projection, NEAR, FAR, None).expect("valid grid")
}

fn perspective() -> Mat4 {
    directx::perspective(
        60f32.to_radians(),
        SCREEN.0 as f32 / SCREEN.1 as f32,
        NEAR,
        FAR,
    )
}

const SCHEMES: [ZScheme; 3] = [
    ZScheme::Linear,
    ZScheme::Logarithmic,
    ZScheme::LogarithmicWithNearSlice {
        first_slice_far: 1.0,
    },
];

#[test]
fn flat_indices_round_trip() {
    let g = grid(ZScheme::Linear, perspective(), (5, 3), 4);
    for index in 0..g.cluster_count() {
        let cluster = g.cluster_of_flat(index);
        assert!(cluster.cmplt(g.dims).all(), "{index}: {cluster}");
        assert_eq!(g.flat_index(cluster), index);
    }
    assert_eq!(g.cluster_of_flat(5 * 3 + 5 + 2), UVec3::new(2, 1, 1));
}

#[test]
fn each_slice_holds_the_depths_between_its_boundaries() {
    for scheme in SCHEMES {
        let g = grid(scheme, perspective(), (4, 3), 16);
        for slice in 0..16 {
            let (near, far) = (g.slice_near_depth(slice), g.slice_near_depth(slice + 1));
            assert!(near < far, "{scheme:?} slice {slice}: {near} .. {far}");
            for depth in [near * 1.001 + 1e-6, 0.5 * (near + far), far * 0.999] {
                assert_eq!(g.slice_of_depth(depth), slice, "{scheme:?} depth {depth}");
            }
        }
        assert_eq!(
            g.slice_near_depth(16),
            FAR,
            "{scheme:?}: the last boundary is far"
        );
        // Clamped at both ends; at or behind the eye is slice 0.
        assert_eq!(g.slice_of_depth(FAR * 10.0), 15);
        for depth in [0.0, -1.0, NEAR * 0.5] {
            assert_eq!(g.slice_of_depth(depth), 0, "{scheme:?} depth {depth}");
        }
    }
    // The near slice ends at first_slice_far exactly.
    let g = grid(SCHEMES[2], perspective(), (4, 3), 16);
    assert_eq!(g.slice_of_depth(0.999), 0);
    assert_eq!(g.slice_of_depth(1.001), 1);
}

#[test]
fn fragments_land_in_their_tile() {
    // 100x60 in 4x3 tiles of 25x20 pixels.
    let g = grid(ZScheme::Linear, perspective(), (4, 3), 8);
    assert_eq!(
        g.cluster_of_fragment(24.5, 19.5, 1.0).truncate(),
        glam::UVec2::new(0, 0)
    );
    assert_eq!(
        g.cluster_of_fragment(25.5, 20.5, 1.0).truncate(),
        glam::UVec2::new(1, 1)
    );
    assert_eq!(
        g.cluster_of_fragment(99.5, 59.5, 1.0).truncate(),
        glam::UVec2::new(3, 2)
    );
    assert_eq!(
        g.cluster_of_fragment(50.5, 0.5, 1.0).truncate(),
        glam::UVec2::new(2, 0)
    );
}

#[test]
fn orthographic_projections_are_recognised() {
    let ortho = directx::orthographic(-5.0, 5.0, -3.0, 3.0, NEAR, FAR);
    assert!(grid(ZScheme::Linear, ortho, (4, 3), 8).is_orthographic());
    assert!(!grid(ZScheme::Linear, perspective(), (4, 3), 8).is_orthographic());
    let reverse = directx::perspective_infinite_reverse(1.0, 1.6, NEAR);
    let settings = ClusterSettings {
        z_range: ZRange::Camera,
        ..ClusterSettings::default()
    };
    let g = ClusterGrid::new(&settings, SCREEN, reverse, NEAR, f32::INFINITY, None);
    // An infinite far plane is refused or clamped, never orthographic.
    if let Ok(g) = g {
        assert!(!g.is_orthographic());
    }
}

/// The view-space point a pixel position shows at view depth `depth` under a symmetric
/// perspective projection: the pixel's NDC scaled by depth over the focal terms.
fn perspective_point(projection: &Mat4, pixel: (f32, f32), depth: f32) -> Vec3 {
    let ndc_x = pixel.0 / SCREEN.0 as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - pixel.1 / SCREEN.1 as f32 * 2.0;
    Vec3::new(
        ndc_x * depth / projection.x_axis.x,
        ndc_y * depth / projection.y_axis.y,
        -depth,
    )
}

#[test]
fn cluster_boxes_are_the_tile_corners_at_the_slice_depths() {
    let projection = perspective();
    for scheme in SCHEMES {
        let g = grid(scheme, projection, (4, 3), 8);
        let bounds = g.cluster_bounds();
        assert_eq!(bounds.len(), g.cluster_count() as usize);
        for (index, aabb) in bounds.iter().enumerate() {
            let c = g.cluster_of_flat(index as u32);
            let mut near = g.slice_near_depth(c.z) * (1.0 - DEPTH_BOUNDS_INFLATION);
            let mut far = g.slice_near_depth(c.z + 1) * (1.0 + DEPTH_BOUNDS_INFLATION);
            // The first and last slices also hold fragments clamped into them.
            if c.z == 0 {
                near = near.min(NEAR * 0.5);
            }
            if c.z == 7 {
                far = far.max(FAR * 2.0);
            }
            let (x0, x1) = (c.x as f32 * 25.0, (c.x + 1) as f32 * 25.0);
            let (y0, y1) = (c.y as f32 * 20.0, (c.y + 1) as f32 * 20.0);
            let mut expected_min = Vec3::splat(f32::INFINITY);
            let mut expected_max = Vec3::splat(f32::NEG_INFINITY);
            for pixel in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                for depth in [near, far] {
                    let p = perspective_point(&projection, pixel, depth);
                    expected_min = expected_min.min(p);
                    expected_max = expected_max.max(p);
                }
            }
            let scale = expected_max.abs().max(expected_min.abs()).max_element();
            let tolerance = 1e-5 * scale.max(1.0);
            assert!(
                (aabb.min - expected_min).abs().max_element() <= tolerance
                    && (aabb.max - expected_max).abs().max_element() <= tolerance,
                "{scheme:?} cluster {c}: {aabb:?}, expected {expected_min} .. {expected_max}"
            );
        }
    }
}

#[test]
fn orthographic_first_slices_start_at_the_eye() {
    let ortho = directx::orthographic(-5.0, 5.0, -3.0, 3.0, NEAR, FAR);
    let g = grid(ZScheme::Linear, ortho, (4, 3), 8);
    let bounds = g.cluster_bounds();
    // Slice 0 reaches depth 0 (z = 0); an orthographic box is as wide as its tile.
    assert_eq!(bounds[0].max.z, 0.0);
    assert!(
        (bounds[0].max.x - bounds[0].min.x - 2.5).abs() < 1e-4,
        "{:?}",
        bounds[0]
    );
}

/// A deterministic stream of numbers in [0, 1) (a 32-bit LCG).
fn stream(seed: u32) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / 16_777_216.0
    }
}

/// Every point of a sphere that the camera sees (in front of the eye, on screen) lies in a
/// cluster of the sphere's candidate range. (Not every cluster whose box the sphere meets:
/// a box is larger than its frustum cell, and those extra meetings are false positives the
/// range may leave out, on the CPU and the GPU alike.)
#[test]
fn candidate_ranges_hold_every_cluster_a_sphere_reaches() {
    let mut next = stream(7);
    let projection = perspective();
    for scheme in SCHEMES {
        let g = grid(scheme, projection, (5, 4), 12);
        let mut seen_points = 0;
        for _ in 0..400 {
            let sphere = ViewSphere {
                center: Vec3::new(
                    next() * 20.0 - 10.0,
                    next() * 12.0 - 6.0,
                    next() * -30.0 + 2.0,
                ),
                radius: 0.05 + next() * 3.0,
            };
            let range = candidate_range(&g, &sphere);
            for _ in 0..64 {
                let offset = Vec3::new(next(), next(), next()) * 2.0 - 1.0;
                if offset.length_squared() > 1.0 {
                    continue;
                }
                let point = sphere.center + offset * sphere.radius;
                let clip = projection * point.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                if point.z >= 0.0 || ndc.x.abs() >= 1.0 || ndc.y.abs() >= 1.0 {
                    continue;
                }
                seen_points += 1;
                let pixel = (
                    (ndc.x + 1.0) * 0.5 * SCREEN.0 as f32,
                    (1.0 - ndc.y) * 0.5 * SCREEN.1 as f32,
                );
                let c = g.cluster_of_fragment(pixel.0, pixel.1, -point.z);
                let Some((lo, hi)) = range else {
                    panic!("{scheme:?} {sphere:?} reaches cluster {c} but has no range");
                };
                assert!(
                    c.cmpge(lo).all() && c.cmple(hi).all(),
                    "{scheme:?} {sphere:?} reaches cluster {c} outside {lo}..{hi}"
                );
            }
        }
        assert!(
            seen_points > 1000,
            "{scheme:?}: only {seen_points} points tested"
        );
    }
    let g = grid(ZScheme::Linear, perspective(), (5, 4), 12);
    // Entirely behind the eye; entirely left of the frustum; entirely above it.
    for center in [
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(-50.0, 0.0, -10.0),
        Vec3::new(0.0, 50.0, -10.0),
    ] {
        let sphere = ViewSphere {
            center,
            radius: 1.0,
        };
        assert_eq!(candidate_range(&g, &sphere), None, "{center}");
    }
    // A small sphere in front of the eye: a few tiles, not the whole screen.
    let (lo, hi) = candidate_range(
        &g,
        &ViewSphere {
            center: Vec3::new(0.0, 0.0, -10.0),
            radius: 0.1,
        },
    )
    .expect("visible");
    assert!(
        (hi - lo).truncate().cmple(glam::UVec2::splat(3)).all(),
        "{lo}..{hi}"
    );
}

/// A tiny grid for hand-made cases: `tiles` across and down, one linear slice over the
/// camera's range, a `screen` of a few pixels.
fn one_slice_grid(tiles: (u32, u32), screen: (u32, u32)) -> ClusterGrid {
    let settings = ClusterSettings {
        tiles: TileSpec::Count {
            x: tiles.0,
            y: tiles.1,
        },
        z_slices: 1,
        z_scheme: ZScheme::Linear,
        z_range: ZRange::Camera,
    };
    let aspect = screen.0 as f32 / screen.1 as f32;
    let projection = directx::perspective(1.0, aspect, NEAR, FAR);
    ClusterGrid::new(&settings, screen, projection, NEAR, FAR, None).expect("grid")
}

#[test]
fn false_positives_are_listed_lights_that_reach_no_pixel_of_their_cluster() {
    // Two tiles of one pixel each, one slice.
    let g = one_slice_grid((2, 1), (2, 1));
    let pixels = [
        Some(Vec3::new(-1.0, 0.0, -5.0)),
        Some(Vec3::new(1.0, 0.0, -5.0)),
    ];
    let spheres = [
        ViewSphere {
            center: Vec3::new(-1.0, 0.0, -5.0),
            radius: 0.5,
        },
        ViewSphere {
            center: Vec3::new(1.0, 0.0, -5.0),
            radius: 0.5,
        },
    ];
    // Cluster 0 lists light 0 (reaches its pixel); cluster 1 lists 0 (does not) and 1.
    let lists = LightLists {
        offsets: vec![0, 1, 3],
        indices: vec![0, 0, 1],
    };
    assert_eq!(lists.total(), 3);
    let ratio = false_positive_ratio(&g, &lists, &spheres, &pixels);
    assert!((ratio - 1.0 / 3.0).abs() < 1e-12, "{ratio}");
    // Background pixels hold nothing: no entries, ratio 0.
    assert_eq!(
        false_positive_ratio(&g, &lists, &spheres, &[None, None]),
        0.0
    );
}

#[test]
fn view_spheres_move_lights_into_view_space() {
    let light = manylights_lights::Light::point(Vec3::new(1.0, 2.0, 3.0), 0.5, Vec3::ONE, 1.0);
    let view = Mat4::from_translation(Vec3::new(0.0, 0.0, -10.0));
    let spheres = view_spheres(&view, &[light, light]);
    assert_eq!(spheres.len(), 2);
    assert_eq!(spheres[1].center, Vec3::new(1.0, 2.0, -7.0));
    assert_eq!(spheres[1].radius, 0.5);
}

#[test]
fn sphere_box_margins_by_hand() {
    use manylights_cluster::{sphere_box_margin, sphere_intersects_box};
    let unit = manylights_scene::Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let apart = ViewSphere {
        center: Vec3::new(3.0, 0.0, 0.0),
        radius: 1.0,
    };
    let touching = ViewSphere {
        center: Vec3::new(1.5, 0.0, 0.0),
        radius: 1.0,
    };
    // Squared distance to the box minus the squared radius: 4 - 1 and 0.25 - 1.
    assert_eq!(sphere_box_margin(&apart, &unit), 3.0);
    assert_eq!(sphere_box_margin(&touching, &unit), -0.75);
    assert!(!sphere_intersects_box(&apart, &unit));
    assert!(sphere_intersects_box(&touching, &unit));
}

#[test]
fn the_near_slice_ends_exactly_at_its_far_depth() {
    let g = grid(SCHEMES[2], perspective(), (4, 3), 16);
    assert_eq!(g.slice_of_depth(1.0), 1);
}

#[test]
fn statistics_print_their_numbers() {
    let mut stats = manylights_cluster::ClusterStats::from_offsets(&[0, 2, 5]);
    assert_eq!(
        stats.to_string(),
        "2 clusters, 5 list entries, lights per cluster mean 2.50 max 3"
    );
    stats.false_positive_ratio = Some(0.25);
    assert!(stats.to_string().ends_with(", false positives 25.0%"));
}

/// Rows of pixels must land in their own tile row, and "reaches" means strictly inside
/// the radius (squared): light 1 reaches row 1's pixels (0.8 m away, radius 0.9 m) but not
/// row 0's (1.2 m away; 1.2^2 = 1.44 would be inside r + r = 1.8).
#[test]
fn false_positives_follow_pixel_rows_and_the_squared_radius() {
    let g = one_slice_grid((1, 2), (2, 2));
    let row0 = Some(Vec3::new(0.0, 1.0, -5.0));
    let row1 = Some(Vec3::new(0.0, -1.0, -5.0));
    let pixels = [row0, row0, row1, row1];
    let spheres = [
        ViewSphere {
            center: Vec3::new(0.0, 1.0, -5.0),
            radius: 0.5,
        },
        ViewSphere {
            center: Vec3::new(0.0, -0.2, -5.0),
            radius: 0.9,
        },
    ];
    // Row 0's cluster lists both lights (light 1 a false positive), row 1's lists light 1.
    let lists = LightLists {
        offsets: vec![0, 2, 3],
        indices: vec![0, 1, 1],
    };
    let ratio = false_positive_ratio(&g, &lists, &spheres, &pixels);
    assert!((ratio - 1.0 / 3.0).abs() < 1e-12, "{ratio}");
}

/// The same by pixel column: column 1's pixels must land in tile column 1.
#[test]
fn false_positives_follow_pixel_columns() {
    let g = one_slice_grid((2, 1), (2, 2));
    let column0 = Some(Vec3::new(1.0, 0.0, -5.0));
    let column1 = Some(Vec3::new(-1.0, 0.0, -5.0));
    let pixels = [column0, column1, column0, column1];
    let spheres = [
        ViewSphere {
            center: Vec3::new(1.0, 0.0, -5.0),
            radius: 0.5,
        },
        ViewSphere {
            center: Vec3::new(-1.0, 0.0, -5.0),
            radius: 0.5,
        },
    ];
    // Column 0's cluster lists both lights (light 1 a false positive), column 1's light 1.
    let lists = LightLists {
        offsets: vec![0, 2, 3],
        indices: vec![0, 1, 1],
    };
    let ratio = false_positive_ratio(&g, &lists, &spheres, &pixels);
    assert!((ratio - 1.0 / 3.0).abs() < 1e-12, "{ratio}");
}
