//! The GPU assignment ([`GpuClusters`]) and its statistics ([`GpuListStatistics`]) held to
//! the CPU reference from this crate alone: a plain wgpu device, generated lights and a
//! hand-made camera, no renderer. The workspace's GPU tests check the same through the
//! facade; these run when only `cluster` changed (so `cargo mutants -p manylights-cluster`
//! sees its GPU code fail without relinking every crate above it) and show the crate used on
//! its own.
//!
//! Lists are compared exactly ([`compare_with_reference`]): the same multiset of lights as
//! [`assign_lights`] given the very spheres the GPU tested (read back), in ascending order
//! where the design promises it.

use glam::camera::rh::proj::directx;
use glam::{Mat4, Vec3};
use manylights_cluster::{
    AssignmentDesign, ClusterBoxes, ClusterFrame, ClusterGrid, ClusterSettings, ClusterStats,
    FarField, FarFieldMethod, GpuClusters, GpuListStatistics, LightLists, Rebuilt, SpotCulling,
    TileSpec, ViewSphere, ZRange, ZScheme, assign_lights, compare_with_reference,
    false_positive_ratio,
};
use manylights_gpu::{GpuContext, ShaderLibrary, ViewBinding, ViewUniform, wgpu};
use manylights_lights::{AnimationParams, GpuLights, LightSet, LightSettings, RadiusMode};
use manylights_scene::Aabb;

const NEAR: f32 = 0.1;
const FAR: f32 = 40.0;
const CAMERA: Vec3 = Vec3::new(0.5, 1.6, 7.0);
const TARGET: Vec3 = Vec3::new(0.0, 1.0, 0.0);

/// The room the lights live in (the camera stands just outside it).
fn room() -> Aabb {
    Aabb::new(Vec3::new(-4.0, 0.0, -5.0), Vec3::new(4.0, 3.0, 5.0))
}

struct Gpu {
    context: GpuContext,
    library: ShaderLibrary,
    view: ViewBinding,
}

fn gpu() -> Gpu {
    let context = GpuContext::new_headless().unwrap_or_else(|error| {
        // Without an adapter the error (GpuError::NoAdapter) says how to install lavapipe.
        panic!("these tests need a GPU: {error}")
    });
    let view = ViewBinding::new(&context);
    Gpu {
        context,
        // `MANYLIGHTS_SHADER_DIR` swaps in mutated shaders (cargo xtask mutants).
        library: ShaderLibrary::from_env(),
        view,
    }
}

/// One frame's camera, grid and lights.
struct Frame {
    projection: Mat4,
    grid: ClusterGrid,
    lights: GpuLights,
}

fn frame(
    gpu: &Gpu,
    cluster: &ClusterSettings,
    screen: (u32, u32),
    light_count: u32,
    radius: f32,
) -> Frame {
    let view = glam::camera::rh::view::look_at_mat4(CAMERA, TARGET, Vec3::Y);
    let projection = directx::perspective(
        55f32.to_radians(),
        screen.0 as f32 / screen.1 as f32,
        NEAR,
        FAR,
    );
    let mut uniform = ViewUniform::new(view, projection, CAMERA, screen, NEAR, FAR);
    // The clear depth, by which the statistics pass tells empty pixels.
    uniform.near_far[2] = 1.0;
    gpu.view.update(&gpu.context, &uniform);
    let grid = ClusterGrid::new(
        cluster,
        screen,
        projection,
        NEAR,
        FAR,
        Some(room().transformed(&view)),
    )
    .expect("valid grid");
    let lights = LightSet::generate(&LightSettings {
        count: light_count,
        seed: 7 + light_count,
        intensity: 1.0,
        radius: RadiusMode::Fixed(radius),
        saturation: 1.0,
        spots: Default::default(),
        animation: AnimationParams::in_box(room()),
        shape: manylights_lights::LightShape::Point,
    })
    .expect("valid lights");
    let lights = GpuLights::upload(&gpu.context, &lights).expect("light upload");
    Frame {
        projection,
        grid,
        lights,
    }
}

/// Prepares, records and submits one assignment by `design`, with wgpu's validation
/// captured.
fn assign(gpu: &Gpu, clusters: &mut GpuClusters, frame: &Frame, design: AssignmentDesign) {
    assign_seeing(gpu, clusters, frame, design, None);
}

/// A depth view of the grid's size with one sample a pixel, as the assignment reads it.
fn single_sampled<'a>(
    view: &'a wgpu::TextureView,
    grid: &ClusterGrid,
) -> manylights_cluster::VisibleDepth<'a> {
    manylights_cluster::VisibleDepth {
        view,
        samples: 1,
        size: grid.screen,
    }
}

/// As [`assign`], given the frame's depth (clusters then bounded by their visible samples).
fn assign_seeing(
    gpu: &Gpu,
    clusters: &mut GpuClusters,
    frame: &Frame,
    design: AssignmentDesign,
    visible_depth: Option<&wgpu::TextureView>,
) -> Rebuilt {
    let cluster_frame = ClusterFrame {
        design,
        ..ClusterFrame::new(frame.grid)
    };
    let rebuilt = clusters
        .prepare(
            &gpu.context,
            &cluster_frame,
            &frame.lights,
            visible_depth.map(|view| single_sampled(view, &frame.grid)),
        )
        .expect("prepare");
    gpu.context
        .scoped("recording the assignment", || {
            let mut encoder = gpu
                .context
                .device
                .create_command_encoder(&Default::default());
            let _lists =
                clusters
                    .assignment()
                    .expect("prepared")
                    .record(&mut encoder, &gpu.view, None);
            gpu.context.queue.submit([encoder.finish()]);
        })
        .expect("the assignment passes wgpu's validation");
    clusters.after_submit();
    rebuilt
}

/// The GPU lists against the CPU reference on the spheres the GPU tested: exact multisets,
/// ascending where `design` promises order. Returns the lists and the spheres.
fn check_lists(
    gpu: &Gpu,
    clusters: &GpuClusters,
    frame: &Frame,
    design: AssignmentDesign,
) -> Result<(LightLists, Vec<ViewSphere>), String> {
    let lists = clusters
        .read_lists(&gpu.context)
        .map_err(|e| e.to_string())?;
    let spheres = clusters
        .read_view_lights(&gpu.context, frame.lights.count)
        .map_err(|e| e.to_string())?;
    // The boxes the GPU tested (the grid's, or its visible samples').
    let bounds = clusters
        .read_bounds(&gpu.context)
        .map_err(|e| e.to_string())?;
    if clusters.boxes_used() == ClusterBoxes::Grid && bounds != frame.grid.cluster_bounds() {
        return Err("the grid's boxes were not the ones uploaded".into());
    }
    let reference = assign_lights(&frame.grid, &bounds, &spheres);
    compare_with_reference(
        &lists,
        &reference,
        &bounds,
        &spheres,
        design.sorted_list_limit(),
    )?;
    Ok((lists, spheres))
}

fn grid_settings(
    tiles: (u32, u32),
    slices: u32,
    scheme: ZScheme,
    range: ZRange,
) -> ClusterSettings {
    ClusterSettings {
        tiles: TileSpec::Count {
            x: tiles.0,
            y: tiles.1,
        },
        z_slices: slices,
        z_scheme: scheme,
        z_range: range,
    }
}

/// Grids of every slicing scheme and range, several tile and slice counts (more slices
/// than one tile walk's 8 and than one visible-bounds group's 64, and fewer), on an even
/// and an odd screen.
fn grids() -> Vec<(ClusterSettings, (u32, u32))> {
    let near_slice = ZScheme::LogarithmicWithNearSlice {
        first_slice_far: 2.0,
    };
    vec![
        (
            grid_settings((8, 6), 24, near_slice, ZRange::FittedToScene),
            (64, 48),
        ),
        (
            grid_settings((5, 3), 7, ZScheme::Linear, ZRange::Camera),
            (37, 23),
        ),
        (
            grid_settings((1, 1), 1, ZScheme::Logarithmic, ZRange::Camera),
            (64, 48),
        ),
        (
            grid_settings((13, 9), 17, ZScheme::Logarithmic, ZRange::FittedToScene),
            (37, 23),
        ),
        // More slices than one workgroup of the visible-bounds pass bounds (64).
        (
            grid_settings((6, 4), 100, ZScheme::Linear, ZRange::FittedToScene),
            (64, 48),
        ),
    ]
}

#[test]
fn gpu_lists_equal_the_cpu_reference_on_every_design_and_grid() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let mut checked = 0;
    for design in AssignmentDesign::ALL {
        for (settings, screen) in grids() {
            for (count, radius) in [(0, 1.0), (1, 2.0), (40, 0.4), (300, 1.5)] {
                let frame = frame(&gpu, &settings, screen, count, radius);
                assign(&gpu, &mut clusters, &frame, design);
                assert_eq!(
                    clusters.wait_and_grow(&gpu.context).expect("list total"),
                    None,
                    "{design}: the initial capacity holds a few thousand entries"
                );
                let (lists, _) = check_lists(&gpu, &clusters, &frame, design).unwrap_or_else(|e| {
                    panic!("{design}, {settings:?} on {screen:?}, {count} lights: {e}")
                });
                if count >= 40 {
                    // The lights lie in view: an empty result would prove nothing.
                    assert!(
                        lists.total() >= count as usize,
                        "{design}, {settings:?}: only {} entries for {count} lights",
                        lists.total()
                    );
                }
                if count == 0 {
                    assert_eq!(lists.total(), 0, "{design}: entries without lights");
                }
                assert_eq!(
                    clusters.read_offsets(&gpu.context).expect("offsets"),
                    lists.offsets
                );
                checked += lists.total();
            }
        }
    }
    println!("{checked} list entries checked");
}

#[test]
fn a_list_buffer_too_small_grows_and_the_next_frame_drops_nothing() {
    let gpu = gpu();
    for design in AssignmentDesign::ALL {
        let mut clusters = GpuClusters::with_capacity(&gpu.context, &gpu.library, &gpu.view, 16)
            .expect("clusters");
        let (settings, screen) = grids().remove(0);
        let frame = frame(&gpu, &settings, screen, 300, 1.5);
        assign(&gpu, &mut clusters, &frame, design);
        assert!(
            clusters.read_lists(&gpu.context).is_err(),
            "{design}: lists cut short are refused, not returned"
        );
        let grown = clusters.wait_and_grow(&gpu.context).expect("list total");
        assert!(
            grown.is_some_and(|capacity| capacity > 16),
            "{design}: 300 lights need more than 16 entries ({grown:?})"
        );
        assert!(clusters.capacity() > 16);
        assign(&gpu, &mut clusters, &frame, design);
        assert_eq!(
            clusters.wait_and_grow(&gpu.context).expect("list total"),
            None,
            "{design}: one growth is enough"
        );
        let (lists, _) = check_lists(&gpu, &clusters, &frame, design)
            .unwrap_or_else(|e| panic!("{design} after growth: {e}"));
        assert!(lists.total() > 16 && lists.total() <= clusters.capacity() as usize);
        assert!(
            clusters.capacity() as usize <= 2 * lists.total(),
            "{design}: grows to the next power of two of the total"
        );
    }
}

#[test]
fn asking_for_the_passes_before_prepare_is_an_error() {
    let gpu = gpu();
    let clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let (settings, screen) = grids().remove(0);
    let frame = frame(&gpu, &settings, screen, 4, 1.0);
    assert!(clusters.assignment().is_err());
    assert!(clusters.read_lists(&gpu.context).is_err());
    assert!(clusters.grid().is_none());
    assert_eq!(clusters.frame(), None);
    drop(frame);
}

#[test]
fn depth_of_another_size_than_the_grid_is_refused_with_both_sizes() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let (settings, screen) = grids().remove(0);
    let frame = frame(&gpu, &settings, screen, 20, 1.0);
    let (depth, _) = plane_depth(&gpu, &frame, 6.0);
    let view = depth.create_view(&Default::default());
    let wrong = (screen.0 + 1, screen.1);
    let error = clusters
        .prepare(
            &gpu.context,
            &ClusterFrame::new(frame.grid),
            &frame.lights,
            Some(manylights_cluster::VisibleDepth {
                view: &view,
                samples: 1,
                size: wrong,
            }),
        )
        .expect_err("depth of another size is refused")
        .to_string();
    let (given, expected) = (
        format!("{}x{}", wrong.0, wrong.1),
        format!("{}x{}", screen.0, screen.1),
    );
    assert!(
        error.contains("depth texture") && error.contains(&given) && error.contains(&expected),
        "{error}"
    );
    // The texture's own size, through `VisibleDepth::of`, is the grid's: accepted.
    let right = manylights_cluster::VisibleDepth::of(&depth, &view);
    assert_eq!((right.size, right.samples), (screen, 1));
    clusters
        .prepare(
            &gpu.context,
            &ClusterFrame::new(frame.grid),
            &frame.lights,
            Some(right),
        )
        .expect("depth of the grid's size");
}

/// A depth buffer holding one plane facing the camera at `distance`, and the view-space
/// positions of its pixels (the CPU's input for the false-positive ratio).
fn plane_depth(gpu: &Gpu, frame: &Frame, distance: f32) -> (wgpu::Texture, Vec<Option<Vec3>>) {
    let (width, height) = frame.grid.screen;
    let clip = frame.projection * Vec3::new(0.0, 0.0, -distance).extend(1.0);
    let depth = clip.z / clip.w;
    let texture = gpu.context.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("plane depth"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: manylights_gpu::DEPTH_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let mut encoder = gpu
        .context
        .device
        .create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear to the plane"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &texture.create_view(&Default::default()),
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(depth),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    gpu.context.queue.submit([encoder.finish()]);
    let inverse = frame.projection.inverse();
    let positions = (0..width * height)
        .map(|i| {
            let (x, y) = ((i % width) as f32 + 0.5, (i / width) as f32 + 0.5);
            let ndc = glam::Vec4::new(
                x / width as f32 * 2.0 - 1.0,
                1.0 - y / height as f32 * 2.0,
                depth,
                1.0,
            );
            let unprojected = inverse * ndc;
            Some(unprojected.truncate() / unprojected.w)
        })
        .collect();
    (texture, positions)
}

#[test]
fn gpu_statistics_equal_the_cpu_reference() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let mut statistics =
        GpuListStatistics::new(&gpu.context, &gpu.library, &gpu.view).expect("statistics");
    // Ascending cluster counts (1, 105, 1152, 1989): the bit sets must grow.
    let grids = grids();
    for (settings, screen) in [2, 1, 0, 3].map(|i| grids[i]) {
        let frame = frame(&gpu, &settings, screen, 200, 1.5);
        assign(&gpu, &mut clusters, &frame, AssignmentDesign::default());
        let (lists, spheres) = check_lists(&gpu, &clusters, &frame, AssignmentDesign::default())
            .unwrap_or_else(|e| panic!("{settings:?}: {e}"));
        let (depth, positions) = plane_depth(&gpu, &frame, 6.0);
        let depth_view = depth.create_view(&Default::default());
        for with_depth in [false, true] {
            gpu.context
                .scoped("recording the statistics", || {
                    let mut encoder = gpu
                        .context
                        .device
                        .create_command_encoder(&Default::default());
                    statistics
                        .prepare(&gpu.context, &clusters, with_depth.then_some(&depth_view))
                        .expect("prepare statistics")
                        .expect("the clusters have a grid")
                        .record(&mut encoder, &gpu.view, None);
                    gpu.context.queue.submit([encoder.finish()]);
                })
                .expect("the statistics pass wgpu's validation");
            statistics.after_submit();
            let mut measured = statistics
                .wait(&gpu.context)
                .expect("statistics")
                .expect("the frame's statistics arrive");
            let mut expected = ClusterStats::from_offsets(&lists.offsets);
            assert!(expected.total_entries > 0, "{settings:?}: nothing listed");
            if with_depth {
                let gpu_ratio = measured.false_positive_ratio.take().expect("GPU ratio");
                let cpu_ratio = false_positive_ratio(&frame.grid, &lists, &spheres, &positions);
                // The GPU unprojects each pixel and tests its distance in f32 as the CPU
                // does, but may round a pixel on a slice boundary or a sphere's surface the
                // other way: one entry in a hundred.
                assert!(
                    (gpu_ratio - cpu_ratio).abs() <= 0.01,
                    "{settings:?}: false positives GPU {gpu_ratio}, CPU {cpu_ratio}"
                );
                assert!(
                    cpu_ratio > 0.0 && cpu_ratio < 1.0,
                    "{settings:?}: a plane through lit space has both kinds of entries ({cpu_ratio})"
                );
            } else {
                assert_eq!(measured.false_positive_ratio, None);
            }
            expected.false_positive_ratio = None;
            assert_eq!(measured, expected, "{settings:?}, depth {with_depth}");
        }
    }
}

/// One `GpuClusters` through a sequence of frames where one thing changes at a time (the
/// slicing with the same dimensions, the slice count with the same tiles, the tiles with
/// the same cluster count, the light count up and down, the design): every frame's lists
/// stay exact, so each change reaches the buffers and the uploaded bounds it must.
#[test]
fn lists_follow_every_change_of_grid_lights_and_design() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let screen = (64, 48);
    let near_slice = ZScheme::LogarithmicWithNearSlice {
        first_slice_far: 2.0,
    };
    let steps: [(&str, ClusterSettings, u32, AssignmentDesign); 7] = [
        (
            "first frame",
            grid_settings((8, 6), 24, near_slice, ZRange::FittedToScene),
            40,
            AssignmentDesign::TileMasks,
        ),
        (
            "same dimensions, other slicing and range",
            grid_settings((8, 6), 24, ZScheme::Linear, ZRange::Camera),
            40,
            AssignmentDesign::TileMasks,
        ),
        (
            "more slices, same tiles",
            grid_settings((8, 6), 32, ZScheme::Linear, ZRange::Camera),
            40,
            AssignmentDesign::TileMasks,
        ),
        (
            "other tiles, same cluster count",
            grid_settings((16, 6), 16, ZScheme::Linear, ZRange::Camera),
            40,
            AssignmentDesign::TileMasks,
        ),
        (
            "more lights",
            grid_settings((16, 6), 16, ZScheme::Linear, ZRange::Camera),
            300,
            AssignmentDesign::TileMasks,
        ),
        (
            "fewer lights",
            grid_settings((16, 6), 16, ZScheme::Linear, ZRange::Camera),
            20,
            AssignmentDesign::TileMasks,
        ),
        (
            "the other design alone",
            grid_settings((16, 6), 16, ZScheme::Linear, ZRange::Camera),
            20,
            AssignmentDesign::AtomicFill,
        ),
    ];
    for (step, settings, count, design) in steps {
        let frame = frame(&gpu, &settings, screen, count, 1.5);
        let rebuilt = assign_seeing(&gpu, &mut clusters, &frame, design, None);
        assert_ne!(
            rebuilt,
            Rebuilt::default(),
            "{step}: a change rebuilds something"
        );
        assert_eq!(clusters.grid(), Some(&frame.grid), "{step}");
        assert_eq!(clusters.frame().map(|f| f.design), Some(design), "{step}");
        let (lists, _) =
            check_lists(&gpu, &clusters, &frame, design).unwrap_or_else(|e| panic!("{step}: {e}"));
        assert!(
            lists.total() >= count as usize,
            "{step}: {} entries",
            lists.total()
        );
        // The same frame again reuses every buffer (allocation only on change).
        let buffers = |c: &GpuClusters| {
            [
                c.indices_buffer().expect("indices").clone(),
                c.offsets_buffer().expect("offsets").clone(),
                c.view_lights_buffer().expect("view lights").clone(),
            ]
        };
        let before = buffers(&clusters);
        assert_eq!(
            assign_seeing(&gpu, &mut clusters, &frame, design, None),
            Rebuilt::default(),
            "{step}: the same frame again rebuilds nothing"
        );
        assert!(
            before == buffers(&clusters),
            "{step}: buffers reallocated for the same frame"
        );
    }
}

/// Statistics arrive without waiting (`poll`, after `after_submit`), and with frames in
/// flight the newest one's, decoded with its own cluster count.
#[test]
fn statistics_arrive_by_polling_and_the_newest_frame_wins() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let mut statistics =
        GpuListStatistics::new(&gpu.context, &gpu.library, &gpu.view).expect("statistics");
    let mut record = |clusters: &mut GpuClusters, frame: &Frame| {
        assign(&gpu, clusters, frame, AssignmentDesign::default());
        let mut encoder = gpu
            .context
            .device
            .create_command_encoder(&Default::default());
        statistics
            .prepare(&gpu.context, clusters, None)
            .expect("prepare statistics")
            .expect("the clusters have a grid")
            .record(&mut encoder, &gpu.view, None);
        gpu.context.queue.submit([encoder.finish()]);
        statistics.after_submit();
        let lists = clusters.read_lists(&gpu.context).expect("lists");
        ClusterStats::from_offsets(&lists.offsets)
    };
    let grids = grids();
    let first = frame(&gpu, &grids[0].0, grids[0].1, 100, 1.0);
    let second = frame(&gpu, &grids[3].0, grids[3].1, 60, 2.0);
    record(&mut clusters, &first);
    let expected = record(&mut clusters, &second);
    assert_ne!(expected.clusters, grids[0].0.z_slices * 48);
    let mut polled = None;
    for _ in 0..1000 {
        if let Some(stats) = statistics.poll(&gpu.context).expect("poll") {
            polled = Some(stats);
            // The first frame's copy may finish first; keep polling for the second.
            if polled.as_ref() == Some(&expected) {
                break;
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    assert_eq!(
        polled,
        Some(expected),
        "the second frame's statistics by polling"
    );
}

#[test]
fn design_names_round_trip() {
    for design in AssignmentDesign::ALL {
        assert_eq!(design.to_string(), design.name());
        assert_eq!(design.name().parse::<AssignmentDesign>(), Ok(design));
    }
    assert_eq!(AssignmentDesign::TileMasks.name(), "tile-masks");
    assert_eq!(AssignmentDesign::AtomicFill.name(), "atomic-fill");
    let error = "bitonic".parse::<AssignmentDesign>().unwrap_err();
    assert!(
        error.contains("bitonic") && error.contains("tile-masks"),
        "{error}"
    );
    // Tile masks promise order for every list, the atomic fill up to its sort limit.
    assert_eq!(AssignmentDesign::TileMasks.sorted_list_limit(), usize::MAX);
    assert_eq!(
        AssignmentDesign::AtomicFill.sorted_list_limit(),
        manylights_cluster::SORTED_LIST_LIMIT
    );
    assert_eq!(AssignmentDesign::default(), AssignmentDesign::TileMasks);
}

/// Given the frame's depth (here a plane facing the camera), each cluster's box is the box of
/// its visible samples: it holds every sample's view position, clusters no sample falls in
/// are empty and list nothing, and the lists still equal the CPU reference on those boxes.
/// Fewer entries than the grid's boxes give, and never a light that reaches a sample missed.
#[test]
fn visible_sample_boxes_hold_every_sample_and_list_only_what_is_seen() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let mut totals = (0, 0);
    for (settings, screen) in grids() {
        let frame = frame(&gpu, &settings, screen, 300, 1.5);
        let (depth, positions) = plane_depth(&gpu, &frame, 6.0);
        let depth_view = depth.create_view(&Default::default());
        for design in AssignmentDesign::ALL {
            assign(&gpu, &mut clusters, &frame, design);
            let grid_entries = clusters.read_lists(&gpu.context).expect("lists").total();

            assign_seeing(&gpu, &mut clusters, &frame, design, Some(&depth_view));
            assert_eq!(clusters.boxes_used(), ClusterBoxes::VisibleSamples);
            let (lists, spheres) = check_lists(&gpu, &clusters, &frame, design)
                .unwrap_or_else(|e| panic!("{design}, {settings:?}: {e}"));
            let bounds = clusters.read_bounds(&gpu.context).expect("bounds");
            let (width, _) = frame.grid.screen;
            let mut seen = vec![false; bounds.len()];
            for (i, position) in positions.iter().enumerate() {
                let position = position.expect("the plane covers every pixel");
                let cluster = frame.grid.flat_index(frame.grid.cluster_of_fragment(
                    (i as u32 % width) as f32 + 0.5,
                    (i as u32 / width) as f32 + 0.5,
                    -position.z,
                )) as usize;
                seen[cluster] = true;
                let aabb = bounds[cluster];
                assert!(
                    position.cmpge(aabb.min).all() && position.cmple(aabb.max).all(),
                    "{settings:?}: pixel {i} at {position} outside its cluster's box {aabb:?}"
                );
                // Every light that reaches the sample is in its cluster's list.
                for (light, sphere) in spheres.iter().enumerate() {
                    if sphere.center.distance_squared(position)
                        < sphere.radius * sphere.radius * (1.0 - 1e-5)
                    {
                        assert!(
                            lists.list(cluster).contains(&(light as u32)),
                            "{settings:?}: light {light} reaches pixel {i} but is not listed"
                        );
                    }
                }
            }
            for (cluster, aabb) in bounds.iter().enumerate() {
                if !seen[cluster] {
                    // Samples widened by a few depth steps may reach a neighbouring slice;
                    // a cluster no sample touches at all is empty.
                    assert!(
                        aabb.is_empty()
                            || seen_in_a_neighbouring_slice(&frame.grid, &seen, cluster),
                        "{settings:?}: cluster {cluster} has a box {aabb:?} but no sample"
                    );
                }
                if aabb.is_empty() {
                    assert!(
                        lists.list(cluster).is_empty(),
                        "{settings:?}: cluster {cluster}"
                    );
                }
            }
            assert!(
                lists.total() <= grid_entries,
                "{design}, {settings:?}: {} entries with visible boxes, {grid_entries} with the grid's",
                lists.total()
            );
            totals.0 += lists.total();
            totals.1 += grid_entries;
        }
    }
    println!(
        "list entries: {} with visible-sample boxes, {} with the grid's",
        totals.0, totals.1
    );
    // One plane in a room of lights: most clusters see nothing.
    assert!(totals.0 > 0 && totals.0 * 2 < totals.1, "{totals:?}");
}

fn seen_in_a_neighbouring_slice(grid: &ClusterGrid, seen: &[bool], cluster: usize) -> bool {
    let at = grid.cluster_of_flat(cluster as u32);
    [at.z.wrapping_sub(1), at.z + 1]
        .into_iter()
        .filter(|&z| z < grid.dims.z)
        .any(|z| seen[grid.flat_index(glam::UVec3::new(at.x, at.y, z)) as usize])
}

/// Walk groups share a mask when one per group would pass the memory budget: with a budget
/// of one byte every tile has a single mask, and the lists stay exact, with few lights and
/// with enough to fill several of the walk's windows (some of them skipped as empty).
#[test]
fn walk_groups_sharing_masks_under_a_small_budget_give_the_same_lists() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let mut shared = false;
    for budget in [1, manylights_cluster::TILE_MASK_BUDGET_BYTES] {
        clusters.set_mask_budget(budget);
        // 20,000 lights span three windows of the walk (8,192 lights each).
        for ((settings, screen), (count, radius)) in grids()
            .into_iter()
            .flat_map(|grid| [(grid, (300, 1.5)), (grid, (20_000, 0.3))])
        {
            let frame = frame(&gpu, &settings, screen, count, radius);
            assign(&gpu, &mut clusters, &frame, AssignmentDesign::TileMasks);
            if clusters
                .wait_and_grow(&gpu.context)
                .expect("total")
                .is_some()
            {
                // The lists outgrew the buffer: assign again into the grown one.
                assign(&gpu, &mut clusters, &frame, AssignmentDesign::TileMasks);
            }
            let layout = clusters.mask_layout().expect("prepared");
            shared |= layout.walk_groups_per_mask > 1;
            check_lists(&gpu, &clusters, &frame, AssignmentDesign::TileMasks)
                .unwrap_or_else(|e| panic!("budget {budget}, {settings:?} ({layout:?}): {e}"));
        }
    }
    assert!(shared, "some budget made walk groups share a mask");
}

/// `prepare` compares the frame with the one before and rebuilds exactly what the change
/// needs (the dirty flags it returns), and the lists it then builds stay exact.
#[test]
fn prepare_rebuilds_only_what_a_change_needs() {
    let gpu = gpu();
    let mut clusters = GpuClusters::new(&gpu.context, &gpu.library, &gpu.view).expect("clusters");
    let screen = (64, 48);
    let settings = grid_settings((8, 6), 24, ZScheme::Logarithmic, ZRange::Camera);
    let frame = frame(&gpu, &settings, screen, 200, 1.5);
    let (depth, _) = plane_depth(&gpu, &frame, 6.0);
    let depth_view = depth.create_view(&Default::default());
    // The same tiles and slices, sliced linearly: other boxes, the same buffers.
    let relinear = ClusterGrid::new(
        &grid_settings((8, 6), 24, ZScheme::Linear, ZRange::Camera),
        screen,
        frame.projection,
        NEAR,
        FAR,
        None,
    )
    .expect("grid");
    let base = ClusterFrame::new(frame.grid);
    let only = |set: fn(&mut Rebuilt)| {
        let mut rebuilt = Rebuilt::default();
        set(&mut rebuilt);
        rebuilt
    };
    let everything = Rebuilt {
        buffers: true,
        grid_boxes: true,
        params: true,
        bind_groups: true,
    };
    let sphere = ClusterFrame {
        spot_culling: SpotCulling::Sphere,
        ..base
    };
    let grid_boxes = ClusterFrame {
        boxes: ClusterBoxes::Grid,
        ..sphere
    };
    let steps: [(&str, ClusterFrame, Option<&wgpu::TextureView>, Rebuilt); 8] = [
        ("the first frame", base, None, everything),
        ("the same frame", base, None, Rebuilt::default()),
        (
            "spots culled by sphere",
            sphere,
            None,
            only(|r| r.params = true),
        ),
        (
            "the frame's depth",
            sphere,
            Some(&depth_view),
            only(|r| r.bind_groups = true),
        ),
        (
            "the grid's boxes, depth given",
            grid_boxes,
            Some(&depth_view),
            only(|r| r.bind_groups = true),
        ),
        (
            "a far field",
            ClusterFrame {
                far_field: Some(FarField::new(FarFieldMethod::Tree)),
                ..grid_boxes
            },
            Some(&depth_view),
            only(|r| r.bind_groups = true),
        ),
        (
            "another slicing",
            ClusterFrame {
                grid: relinear,
                ..grid_boxes
            },
            Some(&depth_view),
            // The far field is gone again: its bind groups too.
            Rebuilt {
                grid_boxes: true,
                params: true,
                bind_groups: true,
                ..Rebuilt::default()
            },
        ),
        (
            "the other design",
            ClusterFrame {
                grid: relinear,
                design: AssignmentDesign::AtomicFill,
                ..grid_boxes
            },
            Some(&depth_view),
            everything,
        ),
    ];
    for (step, cluster_frame, depth, expected) in steps {
        let rebuilt = clusters
            .prepare(
                &gpu.context,
                &cluster_frame,
                &frame.lights,
                depth.map(|view| single_sampled(view, &cluster_frame.grid)),
            )
            .expect("prepare");
        assert_eq!(rebuilt, expected, "{step}");
    }
    // What was prepared last is what a frame records: exact lists on the new grid.
    let frame = Frame {
        grid: relinear,
        ..frame
    };
    assign_seeing(
        &gpu,
        &mut clusters,
        &frame,
        AssignmentDesign::AtomicFill,
        None,
    );
    check_lists(&gpu, &clusters, &frame, AssignmentDesign::AtomicFill).expect("exact lists");
}
