//! Numerical stability at the extremes (issue 8, the cases the renderer covers so far): for
//! each case every pipeline (naive, Forward+ with and without pre-pass, deferred in every
//! layout on both lighting paths, and the G-buffer debug views) renders on the GPU at hand
//! with no NaN or infinity in the HDR output, Forward+ and the lossless deferred layout
//! match naive, and the GPU light lists equal the CPU reference.

use glam::Vec3;
use manylights::cluster::{AssignmentDesign, ClusterBoxes, ZRange, assign_lights};
use manylights::lights::{Light, RadiusMode};
use manylights::{
    Camera, ClusteringSettings, FrameSettings, GBufferChannel, GBufferLayout, LightingPath,
    LoadedScene, PipelineKind, PipelineSettings, Projection, Renderer,
};
use manylights_tests::{assert_hdr_close, fixed_lights, gpu};

fn renderer(size: (u32, u32)) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    // The reference pipeline unless a test names another.
    settings.pipeline = PipelineSettings::naive(Default::default());
    settings.view.size = size;
    settings.lights.time = 0.75;
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

fn assert_finite(label: &str, image: &[[f32; 4]]) {
    if let Some((i, texel)) = image
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|v| !v.is_finite()))
    {
        panic!("{label}: pixel {i} is {texel:?}");
    }
}

/// Renders one case with every pipeline and checks it (see the module docs). Returns the
/// total light-list length of the Forward+ frame.
fn check_case(label: &str, renderer: &mut Renderer, settings: &FrameSettings) -> usize {
    check_case_with_lists(label, renderer, settings, ClusteringSettings::default())
}

/// [`check_case`], the clustered pipelines building their lists with `lists`.
fn check_case_with_lists(
    label: &str,
    renderer: &mut Renderer,
    settings: &FrameSettings,
    lists: ClusteringSettings,
) -> usize {
    let mut naive_settings = settings.clone();
    naive_settings.pipeline = PipelineSettings::naive(Default::default());
    renderer
        .render_frame(&naive_settings)
        .unwrap_or_else(|e| panic!("{label}: naive: {e}"));
    let naive = renderer.read_hdr().expect("hdr");
    assert_finite(&format!("{label} naive"), &naive);
    // Every case looks at the scene: a camera that rasterised nothing would make every
    // comparison below pass on two empty images.
    let covered = renderer.covered_pixels().expect("coverage");
    assert!(covered > 0, "{label}: the camera drew no geometry");

    let mut entries = 0;
    for prepass in [true, false] {
        let mut fp = settings.clone();
        fp.pipeline = PipelineSettings::ForwardPlus(manylights::ForwardPlusSettings {
            depth_prepass: prepass,
            clustering: lists,
            ..Default::default()
        });
        // The image of the first frame, even where the lists overflowed (shaded from all
        // lights there); the lists of a frame that held them whole.
        renderer
            .render_frame(&fp)
            .unwrap_or_else(|e| panic!("{label}: Forward+: {e}"));
        let image = renderer.read_hdr().expect("hdr");
        assert_finite(&format!("{label} Forward+"), &image);
        assert_hdr_close(
            &format!("{label} Forward+ (pre-pass {prepass})"),
            &naive,
            &image,
            1e-4,
        );
        // Lists: GPU equals CPU (as sets) for every cluster.
        manylights_tests::render_with_whole_lists(renderer, &fp)
            .unwrap_or_else(|e| panic!("{label}: Forward+: {e}"));
        let gpu_lists = renderer.read_light_lists().expect("lists");
        let spheres = renderer.read_view_lights().expect("view lights");
        let grid = renderer.cluster_grid(&fp).expect("grid");
        // The boxes the frame tested: its visible samples' with the pre-pass, else the grid's.
        let bounds = renderer.read_cluster_bounds().expect("bounds");
        let cpu_lists = assign_lights(&grid, &bounds, &spheres);
        for cluster in 0..cpu_lists.cluster_count() {
            let mut gpu_list = gpu_lists.list(cluster).to_vec();
            gpu_list.sort_unstable();
            assert_eq!(
                gpu_list,
                cpu_lists.list(cluster),
                "{label}: cluster {cluster}"
            );
        }
        entries = cpu_lists.total();
    }
    for layout in GBufferLayout::ALL {
        for path in LightingPath::ALL {
            let mut deferred = settings.clone();
            deferred.pipeline = PipelineSettings::deferred(layout, path).with_clustering(lists);
            renderer
                .render_frame(&deferred)
                .unwrap_or_else(|e| panic!("{label}: deferred {layout:?}/{path:?}: {e}"));
            let image = renderer.read_hdr().expect("hdr");
            assert_finite(&format!("{label} deferred {layout:?}/{path:?}"), &image);
            if layout == GBufferLayout::Full {
                assert_hdr_close(
                    &format!("{label} deferred full/{path:?}"),
                    &naive,
                    &image,
                    1e-4,
                );
            } else {
                // The lossy layouts: within what 8-bit sRGB albedo can change, with the
                // same outlier allowance as on Sponza (tests/deferred.rs), relative to each
                // pixel rather than to the image's brightest value.
                let errors = manylights_tests::relative_errors(&naive, &image);
                let bound = manylights_tests::lossy_relative_bound();
                let outliers = errors.iter().filter(|&&e| e > bound).count();
                assert!(
                    outliers as f64
                        <= manylights_tests::LOSSY_OUTLIER_FRACTION * errors.len() as f64,
                    "{label} deferred {layout:?}/{path:?}: {outliers} of {} lit channels beyond {bound:.3} relative (worst {:?})",
                    errors.len(),
                    errors.last()
                );
            }
        }
        // The G-buffer itself: every channel finite, in the default layout. The other
        // layouts' channels are proved through their lit images above: a pixel reading a
        // non-finite channel is non-finite (their debug views are drawn in
        // tests/deferred.rs). The sweep over all four layouts was 12 of a case's 40 frames.
        if layout != GBufferLayout::default() {
            continue;
        }
        for view in GBufferChannel::ALL {
            let mut debug = settings.clone();
            debug.pipeline = PipelineSettings::Deferred(manylights::DeferredSettings {
                layout,
                debug_view: Some(manylights::DeferredView::GBuffer(view)),
                ..Default::default()
            });
            renderer
                .render_frame(&debug)
                .unwrap_or_else(|e| panic!("{label}: {view:?}: {e}"));
            assert_finite(
                &format!("{label} {layout:?} {view:?}"),
                &renderer.read_hdr().expect("hdr"),
            );
        }
    }
    entries
}

#[test]
fn near_far_ratios_from_1_to_10_up_to_1e_minus_4_to_1e7_and_infinite() {
    let (mut renderer, mut settings) = renderer((48, 32));
    settings.lights.count = 48;
    for (near, far) in [(0.1, 1.0), (0.1, 100.0), (1e-3, 1e4), (1e-4, 1e7)] {
        settings.view.camera.near = near;
        settings.view.camera.far = far;
        check_case(&format!("near {near} far {far}"), &mut renderer, &settings);
    }
    // An infinite far plane, with the depth range fitted to the scene and with the camera's
    // range (which then falls back to the scene's extent).
    settings.view.camera.near = 0.05;
    settings.view.camera.far = f32::INFINITY;
    for range in [ZRange::FittedToScene, ZRange::Camera] {
        let mut lists = ClusteringSettings::default();
        lists.grid.z_range = range;
        check_case_with_lists(
            &format!("infinite far, {range:?}"),
            &mut renderer,
            &settings,
            lists,
        );
    }
}

#[test]
fn steep_pitch_roll_and_a_camera_inside_a_light() {
    let (mut renderer, mut settings) = renderer((48, 32));
    for pitch in [90.0f32, -90.0] {
        settings.view.camera = Camera {
            position: Vec3::new(0.3, 1.5, -0.2),
            yaw: 0.7,
            pitch: pitch.to_radians(),
            ..settings.view.camera
        };
        renderer.use_generated_lights();
        settings.lights.count = 32;
        check_case(&format!("pitch {pitch}"), &mut renderer, &settings);
    }
    // Roll about the view direction, including the image turned on its side.
    for roll in [45.0f32, 90.0, 180.0] {
        settings.view.camera = Camera {
            roll: roll.to_radians(),
            ..Camera::look_at(
                Vec3::new(0.2, 1.4, 1.8),
                Vec3::new(-0.3, 1.0, -2.0),
                70.0,
                0.05,
                20.0,
            )
        };
        check_case(&format!("roll {roll}"), &mut renderer, &settings);
    }
    // The camera sits inside a light's sphere (and a second light just behind it).
    settings.view.camera = Camera::look_at(
        Vec3::new(0.0, 1.5, 1.0),
        Vec3::new(0.0, 1.0, -2.0),
        60.0,
        0.05,
        20.0,
    );
    renderer
        .set_fixed_lights(&fixed_lights(&[
            (Vec3::new(0.0, 1.5, 0.9), 1.5, 0.5),
            (Vec3::new(0.0, 1.4, 1.6), 2.0, 0.5),
        ]))
        .expect("lights");
    check_case("camera inside a light", &mut renderer, &settings);
}

#[test]
fn reverse_z_everywhere() {
    let (mut renderer, mut settings) = renderer((48, 32));
    settings.lights.count = 40;
    settings.view.camera.reverse_z = true;
    for (near, far) in [(0.1, 100.0), (1e-4, 1e7), (0.05, f32::INFINITY)] {
        settings.view.camera.near = near;
        settings.view.camera.far = far;
        check_case(
            &format!("reverse-Z, near {near} far {far}"),
            &mut renderer,
            &settings,
        );
    }
    settings.view.camera = Camera {
        projection: Projection::Orthographic { height: 3.0 },
        reverse_z: true,
        ..Camera::look_at(
            Vec3::new(0.0, 1.5, 1.95),
            Vec3::new(0.0, 1.5, -2.0),
            60.0,
            0.0,
            10.0,
        )
    };
    check_case("reverse-Z orthographic, near 0", &mut renderer, &settings);
}

/// Largest and median relative error of the view depth reconstructed from the depth
/// buffer, against the f32 world positions the rasteriser interpolated.
fn depth_error(renderer: &mut Renderer, settings: &FrameSettings) -> (f64, f64) {
    renderer.render_frame(settings).expect("frame");
    let from_depth = renderer.view_positions(settings).expect("depth");
    let surface = renderer.capture_surface(settings).expect("surface");
    let view = settings.view.camera.view_matrix_relative().as_dmat4();
    let mut errors: Vec<f64> = from_depth
        .iter()
        .zip(&surface.position)
        .filter_map(|(reconstructed, world)| {
            let reconstructed = (*reconstructed)?;
            let truth = view.transform_point3(glam::DVec3::new(
                world[0] as f64,
                world[1] as f64,
                world[2] as f64,
            ));
            Some(((reconstructed.z as f64) - truth.z).abs() / truth.z.abs())
        })
        .collect();
    errors.sort_by(f64::total_cmp);
    (
        errors.last().copied().unwrap_or(0.0),
        errors[errors.len() / 2],
    )
}

/// Measures depth precision on the GPU: standard Z against reverse-Z at near/far 1e-4:1e7
/// and 0.1:1000 (numbers recorded in docs/design-history.md).
#[test]
fn depth_precision_standard_against_reverse_z() {
    let (mut renderer, mut settings) = renderer((96, 64));
    settings.lights.count = 1;
    let mut results = Vec::new();
    for (near, far) in [(0.1, 1000.0), (1e-4, 1e7)] {
        for reverse_z in [false, true] {
            settings.view.camera.near = near;
            settings.view.camera.far = far;
            settings.view.camera.reverse_z = reverse_z;
            let (max, median) = depth_error(&mut renderer, &settings);
            println!(
                "near {near} far {far}, reverse-Z {reverse_z}: depth error max {max:.2e}, median {median:.2e} (relative)"
            );
            results.push((near, reverse_z, max));
        }
    }
    let error = |near: f32, reverse: bool| {
        results
            .iter()
            .find(|r| r.0 == near && r.1 == reverse)
            .map(|r| r.2)
            .unwrap_or(f64::NAN)
    };
    // Reverse-Z keeps the error relative and tiny whatever the near plane.
    assert!(error(1e-4, true) < 1e-5, "{results:?}");
    assert!(error(0.1, true) < 1e-5, "{results:?}");
    // Standard Z with a 1e-4 near plane is orders of magnitude worse: why the option exists.
    assert!(
        error(1e-4, false) > 100.0 * error(1e-4, true),
        "{results:?}"
    );
}

/// Cornell moved 1e5 m from the world origin (x and z), with its presets and light box.
fn far_away_cornell(offset: Vec3) -> LoadedScene {
    let mut loaded = LoadedScene::load("cornell").expect("cornell");
    for instance in &mut loaded.scene.instances {
        instance.transform = glam::Mat4::from_translation(offset) * instance.transform;
    }
    loaded.light_box =
        manylights::scene::Aabb::new(loaded.light_box.min + offset, loaded.light_box.max + offset);
    for (_, camera) in &mut loaded.presets {
        camera.position += offset;
    }
    loaded
}

/// Geometry 1e5 m from the origin with the camera near it: camera-relative rendering
/// gives the image the same scene gives at the origin; world-space f32 (one ulp is 7.8 mm
/// there) does not. Light and camera positions are multiples of 2^-7 so that they are
/// exact in f32 at both places and only the renderer's precision is compared.
#[test]
fn geometry_far_from_the_origin() {
    let offset = Vec3::new(1e5, 0.0, 1e5);
    let lights = [
        (Vec3::new(0.5, 1.5, -0.25), 2.0, 0.4),
        (Vec3::new(-1.0, 2.25, 0.75), 2.5, 0.4),
        (Vec3::new(1.25, 0.5, 1.0), 1.5, 0.4),
    ];
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.5, 1.875),
        Vec3::new(0.0, 1.25, -2.0),
        60.0,
        0.05,
        20.0,
    );

    // The reference: the far scene's own (f32) instance transforms moved back in f64, so
    // both hold the very same relative placement and only the renderer differs.
    let far_scene = far_away_cornell(offset);
    let mut near_scene = LoadedScene::load("cornell").expect("cornell");
    for (near, far) in near_scene
        .scene
        .instances
        .iter_mut()
        .zip(&far_scene.scene.instances)
    {
        near.transform = (glam::DMat4::from_translation(-offset.as_dvec3())
            * far.transform.as_dmat4())
        .as_mat4();
    }
    let mut settings = FrameSettings::for_scene(&near_scene);
    settings.pipeline = PipelineSettings::naive(Default::default());
    settings.view.size = (64, 48);
    settings.lights.time = 0.75;
    let mut at_origin = Renderer::new(gpu(), near_scene).expect("renderer");
    at_origin
        .set_fixed_lights(&fixed_lights(&lights))
        .expect("lights");
    settings.view.camera = camera;
    let mut far = Renderer::new(gpu(), far_scene).expect("renderer");
    let shifted: Vec<(Vec3, f32, f32)> =
        lights.iter().map(|&(p, r, i)| (p + offset, r, i)).collect();
    far.set_fixed_lights(&fixed_lights(&shifted))
        .expect("lights");
    let mut far_settings = settings.clone();
    far_settings.view.camera.position += offset;

    for kind in PipelineKind::ALL {
        let pipeline = PipelineSettings::of_kind(kind);
        settings.pipeline = pipeline;
        far_settings.pipeline = pipeline;
        at_origin
            .render_frame(&settings)
            .expect("frame at the origin");
        let reference = at_origin.read_hdr().expect("hdr");
        far_settings.view.camera_relative = true;
        far.render_frame(&far_settings).expect("far frame");
        let relative = far.read_hdr().expect("hdr");
        assert_finite("far, camera-relative", &relative);
        let relative_error = manylights_tests::hdr_error(&reference, &relative);
        far_settings.view.camera_relative = false;
        far.render_frame(&far_settings)
            .expect("far frame, world space");
        let world = far.read_hdr().expect("hdr");
        let world_error = manylights_tests::hdr_error(&reference, &world);
        println!(
            "{pipeline:?} 1e5 m from the origin: camera-relative {relative_error}; world space {world_error}"
        );
        // Camera-relative: the same image up to rounding (one half-float ulp + 1e-4).
        assert_hdr_close(
            &format!("{pipeline:?} far from the origin, camera-relative"),
            &reference,
            &relative,
            1e-4,
        );
        // World space visibly differs: the difference camera-relative rendering makes.
        assert!(
            world_error.mean_abs > 10.0 * relative_error.mean_abs.max(1e-6),
            "{world_error} vs {relative_error}"
        );
    }
}

#[test]
fn orthographic_cameras_including_near_zero() {
    let (mut renderer, mut settings) = renderer((48, 32));
    settings.lights.count = 40;
    for (label, camera) in [
        (
            "orthographic, near 0",
            Camera::look_at(
                Vec3::new(0.0, 1.5, 1.95),
                Vec3::new(0.0, 1.5, -2.0),
                60.0,
                0.0,
                10.0,
            ),
        ),
        (
            "orthographic, near 0.1",
            Camera::look_at(
                Vec3::new(0.5, 1.2, 1.9),
                Vec3::new(-0.5, 1.0, -2.0),
                60.0,
                0.1,
                10.0,
            ),
        ),
        (
            "orthographic, straight down",
            Camera {
                pitch: -std::f32::consts::FRAC_PI_2,
                ..Camera::look_at(
                    Vec3::new(0.0, 2.9, 0.0),
                    Vec3::new(0.0, 0.0, -1.0),
                    60.0,
                    0.0,
                    5.0,
                )
            },
        ),
    ] {
        settings.view.camera = Camera {
            projection: Projection::Orthographic { height: 3.0 },
            ..camera
        };
        check_case(label, &mut renderer, &settings);
    }
    // The fitted and the camera's depth range both work with near 0.
    let mut lists = ClusteringSettings::default();
    lists.grid.z_range = ZRange::Camera;
    check_case_with_lists(
        "orthographic, camera range",
        &mut renderer,
        &settings,
        lists,
    );
}

#[test]
fn tiny_odd_and_huge_resolutions() {
    for size in [(1, 1), (3, 7)] {
        let (mut renderer, mut settings) = renderer(size);
        settings.lights.count = 16;
        check_case(&format!("{}x{}", size.0, size.1), &mut renderer, &settings);
    }
    // The largest size in one dimension renders; one more is a clear error.
    let (mut renderer, mut settings) = renderer((8, 8));
    let max = renderer.context().device.limits().max_texture_dimension_2d;
    settings.view.size = (max, 1);
    settings.lights.count = 4;
    settings.pipeline = PipelineSettings::default();
    renderer
        .render_frame(&settings)
        .expect("the largest width renders");
    settings.view.size = (max + 1, 1);
    let error = renderer
        .render_frame(&settings)
        .expect_err("over the limit")
        .to_string();
    assert!(error.contains("max_texture_dimension_2d"), "{error}");
}

#[test]
fn light_counts_placements_and_radii() {
    let (mut renderer, mut settings) = renderer((48, 32));
    settings.lights.count = 0;
    check_case("0 lights", &mut renderer, &settings);
    settings.lights.count = 1;
    check_case("1 light", &mut renderer, &settings);
    let floor = Vec3::new(0.3, 0.0, -0.4);
    for (label, lights) in [
        (
            "a light exactly on the floor (d = 0)",
            fixed_lights(&[(floor, 1.0, 0.5)]),
        ),
        (
            "a light 1e-7 above the floor",
            fixed_lights(&[(floor + Vec3::Y * 1e-7, 1.0, 0.5)]),
        ),
        (
            "radius 1e-6",
            fixed_lights(&[(Vec3::new(0.0, 1.0, 0.0), 1e-6, 0.5)]),
        ),
        (
            "radius 1e6",
            fixed_lights(&[(Vec3::new(0.0, 1.0, 0.0), 1e6, 0.5)]),
        ),
        // 30 m behind the camera (which looks down -Z from z = 1.9): its sphere reaches in.
        (
            "a light far behind the camera",
            fixed_lights(&[(Vec3::new(0.0, 1.5, 31.0), 32.0, 0.5)]),
        ),
    ] {
        renderer.set_fixed_lights(&lights).expect("lights");
        check_case(label, &mut renderer, &settings);
    }
}

#[test]
fn one_hundred_thousand_lights_in_one_spot() {
    let (mut renderer, settings) = renderer((48, 32));
    let spot = Vec3::new(0.0, 1.0, 0.0);
    let lights: Vec<(Vec3, f32, f32)> = (0..100_000)
        .map(|i| (spot + Vec3::splat((i % 7) as f32 * 1e-4), 0.3, 1e-3))
        .collect();
    renderer
        .set_fixed_lights(&fixed_lights(&lights))
        .expect("lights");
    // Both assignment designs: the atomic fill writes long lists in atomic order, tile
    // masks in ascending order.
    for design in AssignmentDesign::ALL {
        let mut fp = settings.clone();
        // The grid's boxes: the spot floats in the air, and the test is about lists that
        // long (visible-sample boxes would list it only in the few clusters it lights).
        fp.pipeline = PipelineSettings::forward_plus().with_clustering(ClusteringSettings {
            assignment: design,
            boxes: ClusterBoxes::Grid,
            ..ClusteringSettings::default()
        });
        let stats = manylights_tests::render_with_whole_lists(&mut renderer, &fp).expect("frame");
        let lists = renderer.read_light_lists().expect("lists");
        // Nothing dropped: the GPU lists hold exactly the CPU reference's entries, and the
        // clusters around the spot list every one of the 100,000 lights.
        let spheres = renderer.read_view_lights().expect("view lights");
        let grid = renderer.cluster_grid(&fp).expect("grid");
        let cpu = assign_lights(&grid, &grid.cluster_bounds(), &spheres);
        assert_eq!(renderer.cluster_boxes_used(), ClusterBoxes::Grid);
        assert_eq!(lists.total(), cpu.total(), "{design}");
        // The indices themselves, not only the counts: every list holds exactly the CPU
        // reference's lights (as a multiset beyond the design's sort limit).
        for cluster in 0..lists.cluster_count() {
            let listed = lists.list(cluster);
            let mut sorted = listed.to_vec();
            sorted.sort_unstable();
            assert_eq!(sorted, cpu.list(cluster), "{design}: cluster {cluster}");
            if listed.len() <= design.sorted_list_limit() {
                assert_eq!(listed, sorted, "{design}: cluster {cluster} out of order");
            }
        }
        let full = (0..lists.cluster_count())
            .filter(|&c| lists.list(c).len() == 100_000)
            .count();
        assert!(full > 0, "{design}: no cluster lists all 100,000 lights");
        // Memory stays bounded by what the frame needs: the list buffer is the next power
        // of two.
        assert!(renderer.light_list_capacity() as usize <= 2 * lists.total().max(1 << 16));
        println!(
            "100,000 lights in one spot, {design}: {} clusters list them all, {} entries ({} MiB of list), list buffer grown to {:?}",
            full,
            lists.total(),
            lists.total() * 4 / (1 << 20),
            stats.list_capacity_grown_to
        );
    }
    let hdr = renderer.read_hdr().expect("hdr");
    assert_finite("100,000 lights in one spot", &hdr);
    // And naive's frame of them is finite and lit. The two images are not compared:
    // lavapipe ends any loop after 65,536 lights (docs/testing.md), so both would be cut.
    let mut naive_settings = settings.clone();
    naive_settings.pipeline = PipelineSettings::naive(Default::default());
    renderer.render_frame(&naive_settings).expect("naive");
    let naive = renderer.read_hdr().expect("hdr");
    // The spot lights a few pixels of this small frame: at least one.
    manylights_tests::assert_lit("100,000 lights in one spot", &naive, 1e-9);
    assert_hdr_close("100,000 lights in one spot", &naive, &hdr, 1e-4);
}

#[test]
fn a_million_lights() {
    let (mut renderer, mut settings) = renderer((32, 24));
    settings.lights.count = 1_000_000;
    settings.lights.radius = RadiusMode::Fixed(0.05);
    // 1,000,000 lights need 32 MB of lights and 16 MB of view-space spheres: a device whose
    // storage-buffer limit holds that must render them; only a smaller one may refuse, and
    // then with the limit named.
    let needed = 1_000_000u64 * std::mem::size_of::<Light>() as u64;
    let limit = renderer
        .context()
        .device
        .limits()
        .max_storage_buffer_binding_size;
    for pipeline in [
        PipelineSettings::forward_plus(),
        PipelineSettings::default(),
    ] {
        settings.pipeline = pipeline;
        match renderer.render_frame(&settings) {
            Ok(stats) => {
                assert_eq!(stats.light_count, 1_000_000);
                assert_finite("1,000,000 lights", &renderer.read_hdr().expect("hdr"));
            }
            Err(error) => assert!(
                needed > limit && error.to_string().contains("limit"),
                "{pipeline:?}: refused 1,000,000 lights ({needed} bytes) under a {limit}-byte limit: {error}"
            ),
        }
    }
}

#[test]
fn light_sums_beyond_half_float_range_are_clamped_not_infinite() {
    let (mut renderer, settings) = renderer((48, 32));
    let lights: Vec<(Vec3, f32, f32)> = (0..1000)
        .map(|i| (Vec3::new(0.0, 0.05 + i as f32 * 1e-5, 0.0), 3.0, 1e4))
        .collect();
    renderer
        .set_fixed_lights(&fixed_lights(&lights))
        .expect("lights");
    check_case("HDR overflow", &mut renderer, &settings);
    renderer.render_frame(&settings).expect("frame");
    let hdr = renderer.read_hdr().expect("hdr");
    assert!(
        hdr.iter().any(|t| t[0] == 65504.0),
        "the brightest pixels are clamped to the largest half float"
    );
}

#[test]
fn non_finite_lights_are_refused() {
    let (mut renderer, _) = renderer((8, 8));
    for (label, light) in [
        ("position", (Vec3::new(f32::NAN, 1.0, 0.0), 1.0, 1.0)),
        ("radius", (Vec3::ONE, f32::INFINITY, 1.0)),
        ("intensity", (Vec3::ONE, 1.0, f32::NAN)),
        ("negative radius", (Vec3::ONE, -1.0, 1.0)),
    ] {
        let error = renderer
            .set_fixed_lights(&fixed_lights(&[light]))
            .expect_err(label)
            .to_string();
        assert!(error.contains("light 0"), "{label}: {error}");
    }
    let mut colour = fixed_lights(&[(Vec3::ONE, 1.0, 1.0)]);
    colour.lights[0].color[1] = f32::INFINITY;
    assert!(
        renderer
            .set_fixed_lights(&colour)
            .expect_err("colour")
            .to_string()
            .contains("color")
    );
}
