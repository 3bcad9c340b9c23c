//! The library in someone else's renderer: the examples that use the crates from an
//! engine's own wgpu program run here as the examples step runs them, at the smallest size
//! that shows their claim. Forward+ in an engine (`crates/cluster/examples/
//! forward_plus_in_your_engine.rs`, its own device, reverse-Z infinite camera, depth
//! pre-pass and shader) draws the same frame through the lists as from every light, with
//! and without shadow rays through the BVH of its own triangles; deferred in an engine
//! (its own G-buffer and compute lighting) lights it the same through the lists as from
//! every light. Both examples' frames, with the engine's BRDF and with ours, are our naive
//! pipeline's frame of the same triangles, lights and camera.

// Each example is a program of its own with its own copy of the engine's module
// (`engine/mod.rs`), as cargo builds it: loaded here twice, once in each.
#![allow(clippy::duplicate_mod)]

#[allow(dead_code)]
#[path = "../crates/cluster/examples/deferred_in_your_engine.rs"]
mod deferred_in_your_engine;
#[allow(dead_code)]
#[path = "../crates/cluster/examples/forward_plus_in_your_engine.rs"]
mod forward_plus_in_your_engine;

use forward_plus_in_your_engine::engine::{differing_channels, lit_pixels};

/// 1,500 lights of 2.8 m over 400 m^2: about a hundred reach a point of the floor, so a
/// dropped or misplaced light changes many pixels. The smallest frame that still has every
/// box.
/// (Each example has its own copy of the engine's module, so of its `Options`.)
macro_rules! small {
    ($example:ident, $shadows:expr) => {
        $example::engine::Options {
            size: (96, 64),
            lights: 1_500,
            check: true,
            shadows: $shadows,
            ..Default::default()
        }
    };
}

#[test]
fn an_engines_far_field_at_tolerance_zero_is_every_lights_unbounded_frame() {
    drop(manylights_tests::gpu());
    // What the lights add beyond their radius, from the cut of the light tree, with the
    // engine's BRDF on it: exact at tolerance 0, so windowed (the lists) plus far (the cut)
    // is every light's plain inverse square, summed in another order.
    let options = forward_plus_in_your_engine::engine::Options {
        far_field: Some(0.0),
        ..small!(forward_plus_in_your_engine, false)
    };
    let frames = forward_plus_in_your_engine::render(&options).expect("the engine's frame");
    let every_light = frames.every_light.expect("drawn with check");
    assert!(lit_pixels(&every_light) > every_light.len() / 2);
    let ulps = forward_plus_in_your_engine::engine::allowed_ulps(&options).expect("exact");
    assert_eq!(differing_channels(&frames.listed, &every_light, ulps), 0);
    // The same with our loop and BRDF in one call (`--brdf clustered-radiance`), against
    // every light through our BRDF in the engine's loop.
    let ours = forward_plus_in_your_engine::engine::Options {
        clustered_radiance: true,
        ..options.clone()
    };
    let ours = forward_plus_in_your_engine::render(&ours).expect("our clustered radiance");
    let our_every_light = ours.every_light.expect("drawn with check");
    assert_eq!(differing_channels(&ours.listed, &our_every_light, ulps), 0);
    assert!(differing_channels(&our_every_light, &every_light, ulps) > every_light.len());
    // Without the far field the same frame misses what lies beyond the radius: the check
    // above can fail.
    let windowed = forward_plus_in_your_engine::render(&small!(forward_plus_in_your_engine, false))
        .expect("the frame without a far field");
    assert!(differing_channels(&windowed.listed, &every_light, ulps) > every_light.len());
}

/// The frame through the lists equals the frame from every light in every channel, and
/// has content: most of the frame is floor and boxes, lit.
fn assert_lists_drop_nothing(name: &str, listed: &[[f32; 4]], every_light: &[[f32; 4]]) {
    let pixels = listed.len();
    assert!(
        lit_pixels(every_light) > pixels / 2,
        "{name}: {} of {pixels} lit",
        lit_pixels(every_light)
    );
    assert_eq!(lit_pixels(listed), lit_pixels(every_light), "{name}");
    // Both frames sum the same nonzero terms in the same order: a light its cluster does
    // not list adds exactly zero there. 64 f32 ulps a channel allow for the compilers'
    // contractions of two pipelines; a light left out of a list is a whole term.
    assert_eq!(differing_channels(listed, every_light, 64.0), 0, "{name}");
}

#[test]
fn an_engines_forward_plus_frame_through_the_lists_equals_every_lights() {
    // Fails with how to install lavapipe where there is no adapter.
    drop(manylights_tests::gpu());
    let frames = forward_plus_in_your_engine::render(&small!(forward_plus_in_your_engine, false))
        .expect("the engine's frame");
    let every_light = frames.every_light.expect("drawn with check");
    assert_lists_drop_nothing("Forward+", &frames.listed, &every_light);

    // Shadow rays from the engine's shader, through the BVH of its own triangles: the
    // same through the lists, and darker than unshadowed where a box hides a light.
    let shadowed = forward_plus_in_your_engine::render(&small!(forward_plus_in_your_engine, true))
        .expect("shadowed frame");
    let shadowed_every_light = shadowed.every_light.expect("drawn with check");
    assert_lists_drop_nothing(
        "Forward+ with shadows",
        &shadowed.listed,
        &shadowed_every_light,
    );
    let darker = (shadowed.listed.iter().zip(&frames.listed))
        .filter(|(shadowed, unshadowed)| {
            shadowed[0] + shadowed[1] + shadowed[2]
                < 0.99 * (unshadowed[0] + unshadowed[1] + unshadowed[2])
        })
        .count();
    let brighter = (shadowed.listed.iter().zip(&frames.listed))
        .filter(|(shadowed, unshadowed)| (0..3).any(|c| shadowed[c] > unshadowed[c]))
        .count();
    println!(
        "{darker} of {} pixels darker with shadows",
        frames.listed.len()
    );
    assert!(
        darker > frames.listed.len() / 50,
        "{darker} pixels darker with shadows"
    );
    assert_eq!(brighter, 0, "a shadow ray only ever takes light away");
}

#[test]
fn an_engines_deferred_lighting_through_the_lists_equals_every_lights() {
    drop(manylights_tests::gpu());
    let frames = deferred_in_your_engine::render(&small!(deferred_in_your_engine, false))
        .expect("the engine's frame");
    let every_light = frames.every_light.expect("lit with check");
    assert_lists_drop_nothing("deferred", &frames.listed, &every_light);
    // With our BRDF in the engine's loop (`--brdf pbr`): the same lists, another frame.
    let options = deferred_in_your_engine::engine::Options {
        pbr: true,
        ..small!(deferred_in_your_engine, false)
    };
    let pbr = deferred_in_your_engine::render(&options).expect("the engine's frame, our BRDF");
    let pbr_every_light = pbr.every_light.expect("lit with check");
    assert_lists_drop_nothing("deferred, our BRDF", &pbr.listed, &pbr_every_light);
    assert!(differing_channels(&pbr.listed, &frames.listed, 64.0) > every_light.len());
}

#[test]
fn an_engines_lights_are_uploaded_and_rewritten_and_bad_ones_refused_by_index() {
    use glam::Vec3;
    use manylights_lights::{GpuLights, Light};
    let context = manylights_tests::gpu();
    let light = |x: f32| Light::point(Vec3::new(x, 1.0, 0.0), 2.0, Vec3::ONE, 0.5);
    let mut lights: Vec<Light> = (0..4).map(|i| light(i as f32)).collect();
    let mut uploaded = GpuLights::new(&context, &lights).expect("four valid lights");
    assert_eq!(
        (uploaded.count, uploaded.animated),
        (4, 0),
        "no animation of ours moves them"
    );
    assert!(!uploaded.kinds.shaped);

    // A per-frame update of the range that changed.
    let spot = Light::spot(
        Vec3::ZERO,
        3.0,
        Vec3::ONE,
        1.0,
        Vec3::NEG_Y,
        manylights_lights::SpotCone {
            inner: 0.2,
            outer: 0.4,
        },
    );
    uploaded.write(&context, 2, &[spot]).expect("a valid spot");
    lights[2] = spot;
    assert_eq!(uploaded.read(&context).expect("read back"), lights);
    assert!(
        uploaded.kinds.shaped,
        "the next frame's programs include the cone"
    );

    // Refused with the light's index in the whole array and the field; nothing written.
    let mut nan = light(0.0);
    nan.position[1] = f32::NAN;
    let mut negative = light(0.0);
    negative.radius = -1.0;
    let refusals = [
        (
            GpuLights::new(&context, &[light(0.0), light(1.0), nan]).err(),
            "light 2: position",
        ),
        (
            uploaded.write(&context, 1, &[negative]).err(),
            "light 1: radius",
        ),
        (
            uploaded.write(&context, 3, &[nan]).err(),
            "light 3: position",
        ),
        (
            uploaded.write(&context, 3, &[light(0.0), light(1.0)]).err(),
            "past the 4 lights",
        ),
    ];
    for (error, expected) in refusals {
        let error = error.map(|e| e.to_string()).unwrap_or_default();
        assert!(error.contains(expected), "{expected:?} in {error:?}");
    }
    assert_eq!(
        uploaded.read(&context).expect("read back"),
        lights,
        "nothing written"
    );
}

#[test]
fn bad_input_from_an_engine_is_refused_and_its_own_error_callback_never_called() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    use manylights_cluster::{ClusterFrame, ClusterGrid, GpuClusters, VisibleDepth};
    use manylights_gpu::{
        DeviceRequirements, GpuContext, ShaderLibrary, ViewBinding, ViewUniform, wgpu,
    };
    use manylights_lights::{GpuLights, Light};

    drop(manylights_tests::gpu());
    // The engine's device, with its own uncaptured-error callback.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&Default::default())).expect("an adapter");
    let needs = DeviceRequirements::minimum();
    let mut descriptor = wgpu::DeviceDescriptor::default();
    needs.merge_into(&mut descriptor, &adapter);
    let (device, queue) =
        pollster::block_on(adapter.request_device(&descriptor)).expect("the engine's device");
    let engine_errors = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&engine_errors);
    device.on_uncaptured_error(Arc::new(move |_| {
        counter.fetch_add(1, Ordering::SeqCst);
    }));
    let context = GpuContext::from_device(instance, adapter, device.clone(), queue, &needs)
        .expect("a device with the requirements merged in");

    // A light with a NaN position: refused by index, nothing created.
    let mut lights = vec![Light::point(glam::Vec3::ONE, 1.0, glam::Vec3::ONE, 1.0); 3];
    lights[1].position[0] = f32::NAN;
    let error = GpuLights::new(&context, &lights).expect_err("a NaN position");
    assert!(error.to_string().contains("light 1: position"), "{error}");
    lights[1].position[0] = 0.0;
    let lights = GpuLights::new(&context, &lights).expect("three valid lights");

    // Depth of another size than the grid's: refused with both sizes.
    let (view, projection) = forward_plus_in_your_engine::engine::camera(
        (64, 32),
        forward_plus_in_your_engine::engine::ENGINE_VIEW,
    );
    let camera = ViewUniform::from_matrices(view, projection, (64, 32)).expect("the camera");
    let view_binding = ViewBinding::new(&context);
    let grid = ClusterGrid::for_view(
        &Default::default(),
        &camera,
        Some(manylights_scene::Aabb::new(
            glam::Vec3::splat(-5.0),
            glam::Vec3::splat(5.0),
        )),
    )
    .expect("the grid");
    let mut clusters =
        GpuClusters::new(&context, &ShaderLibrary::from_env(), &view_binding).expect("clusters");
    let depth = forward_plus_in_your_engine::engine::texture(
        &device,
        (32, 32),
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let depth_view = depth.create_view(&Default::default());
    let error = clusters
        .prepare(
            &context,
            &ClusterFrame::new(grid),
            &lights,
            Some(VisibleDepth::of(&depth, &depth_view)),
        )
        .expect_err("depth of another size");
    assert!(
        error.to_string().contains("32x32") && error.to_string().contains("64x32"),
        "{error}"
    );

    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("the device idles");
    assert_eq!(
        engine_errors.load(Ordering::SeqCst),
        0,
        "the engine's callback saw nothing of ours"
    );
}

/// The WGSL of an engine's shader that asks our BRDF (`manylights_lights::pbr_wgsl`) at
/// each sample: normal, view and light directions, base colour, metallic and roughness.
const BRDF_PROBE_WGSL: &str = r#"
struct Sample { normal: vec4<f32>, view_dir: vec4<f32>, l: vec4<f32>, base_metallic: vec4<f32> }
@group(0) @binding(0) var<storage, read> samples: array<Sample>;
@group(0) @binding(1) var<storage, read_write> reflected: array<vec4<f32>>;

@compute @workgroup_size(64)
fn cs_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&samples) {
        return;
    }
    let s = samples[id.x];
    let surface = manylights_pbr_surface(vec3<f32>(0.0), s.normal.xyz, s.view_dir.xyz, s.base_metallic.xyz, s.base_metallic.w, s.normal.w);
    reflected[id.x] = vec4<f32>(manylights_pbr_reflected(surface, s.view_dir.xyz, s.l.xyz), 1.0);
}
"#;

#[test]
fn our_brdf_in_an_engines_shader_is_the_f64_references() {
    use glam::DVec3;
    use manylights_gpu::wgpu::{self, util::DeviceExt as _};
    use manylights_lights::reference::{SurfacePoint, brdf};
    let context = manylights_tests::gpu();
    let device = &context.device;
    // Samples over the whole lit hemisphere's useful range: n.v and n.l from 0.1 (the
    // visibility term's grazing ends are the loops' own tests), every base colour,
    // metallic 0 to 1, roughness 0.1 to 1 (below, GGX's peak needs f32's last digits).
    let mut state = 7u32;
    let mut unit = move || {
        state = state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        f64::from(state >> 8) / f64::from(1u32 << 24)
    };
    let direction_around = |n: DVec3, min_cos: f64, unit: &mut dyn FnMut() -> f64| loop {
        let d = DVec3::new(unit() * 2.0 - 1.0, unit() * 2.0 - 1.0, unit() * 2.0 - 1.0);
        if d.length_squared() > 1e-3 && d.length_squared() <= 1.0 && d.normalize().dot(n) >= min_cos
        {
            return d.normalize();
        }
    };
    let mut points = Vec::new();
    let mut gpu_samples: Vec<[f32; 16]> = Vec::new();
    for _ in 0..2048 {
        let normal = direction_around(DVec3::Z, -1.0, &mut unit);
        let view_dir = direction_around(normal, 0.1, &mut unit);
        let l = direction_around(normal, 0.1, &mut unit);
        let base = DVec3::new(unit(), unit(), unit());
        let (metallic, roughness) = (unit(), 0.1 + 0.9 * unit());
        let point = SurfacePoint {
            position: DVec3::ZERO,
            normal,
            albedo: base * (1.0 - metallic),
            specular: DVec3::splat(0.04).lerp(base, metallic),
            lobe: roughness,
            shading: manylights_lights::Shading::Pbr,
            emission: DVec3::ZERO,
        };
        points.push((point, view_dir, l));
        let v = |d: DVec3, w: f64| [d.x as f32, d.y as f32, d.z as f32, w as f32];
        let s = [
            v(normal, roughness),
            v(view_dir, 0.0),
            v(l, 0.0),
            v(base, metallic),
        ];
        gpu_samples.push(bytemuck::cast(s));
    }
    // The engine's shader: our BRDF's source, then its own.
    let library = manylights_gpu::ShaderLibrary::from_env();
    let source =
        manylights_lights::pbr_wgsl(&library, 0).expect("our BRDF's WGSL") + BRDF_PROBE_WGSL;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("engine's BRDF probe"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let storage = |read_only| wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    };
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[
            entry(0, storage(true)),
            entry(1, storage(false)),
            manylights_lights::SpecularTables::layout_entry(wgpu::ShaderStages::COMPUTE),
        ],
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: Some(
            &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            }),
        ),
        module: &module,
        entry_point: Some("cs_probe"),
        compilation_options: Default::default(),
        cache: None,
    });
    let samples = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&gpu_samples),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let reflected = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (points.len() * 16) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let tables = manylights_lights::SpecularTables::new(&context).expect("the tables");
    let (table_binding, table_view) = tables.binding();
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: samples.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: reflected.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: table_binding,
                resource: table_view,
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
    }
    context.queue.submit([encoder.finish()]);
    let on_gpu: Vec<[f32; 4]> =
        manylights_gpu::targets::read_buffer(&context, &reflected).expect("the engine's samples");
    // The tolerance: the same formulas and the same fitted coefficients in f32 against
    // f64. About a hundred roundings lie on any path (2^-24 each), amplified at most tenfold
    // here (n.l, n.v >= 0.1, alpha^2 >= 1e-4 with D free of cancellation), and the fit's
    // coefficients rounded to f32 lose up to tenfold more where its terms cancel:
    // 100 x 10 x 10 x 6e-8 = 6e-4 of the value, held to 1e-3.
    let relative = 1e-3;
    let mut lambert_misses = 0;
    for (i, ((point, view_dir, l), gpu)) in points.iter().zip(&on_gpu).enumerate() {
        let expected = brdf(point, *view_dir, *l) * point.normal.dot(*l);
        let got = DVec3::new(gpu[0].into(), gpu[1].into(), gpu[2].into());
        let error = (got - expected).abs().max_element();
        assert!(
            error <= relative * expected.max_element() + 1e-9,
            "sample {i}: our BRDF in the engine gives {got}, the f64 reference {expected}"
        );
        let lambert = point.albedo / std::f64::consts::PI * point.normal.dot(*l);
        if (lambert - expected).abs().max_element() > 100.0 * relative * expected.max_element() {
            lambert_misses += 1;
        }
    }
    // The reference has content: Lambert alone misses it on most samples by a hundred
    // times the tolerance, so the check above can fail.
    assert!(lambert_misses > points.len() / 2, "{lambert_misses}");
}

/// The engine's floor and boxes as a manylights scene: one mesh of its triangles, one
/// untextured grey material as the engine shades it. PBR: a dielectric of base colour 0.8
/// and roughness 0.5. Blinn-Phong without specular is Lambert, its diffuse BRDF its albedo
/// (the OBJ files' convention): the engine's 0.8 / pi.
fn the_engines_scene_for_us(shading: manylights_scene::Shading) -> manylights::LoadedScene {
    let triangles = forward_plus_in_your_engine::engine::scene();
    let positions = triangles.positions();
    let mesh = manylights_scene::Mesh {
        name: "the engine's".into(),
        normals: triangles.normals(),
        uvs: vec![glam::Vec2::ZERO; positions.len()],
        tangents: None,
        indices: triangles.indices,
        material: 0,
        bounds: manylights_scene::bounds_of(&positions),
        positions,
    };
    let albedo = match shading {
        manylights_scene::Shading::Pbr => 0.8,
        manylights_scene::Shading::BlinnPhong => 0.8 / std::f32::consts::PI,
    };
    let material = manylights_scene::Material {
        base_color_factor: glam::Vec3::splat(albedo).extend(1.0),
        metallic_factor: 0.0,
        roughness_factor: 0.5,
        specular_color: glam::Vec3::ZERO,
        ..Default::default()
    };
    let scene = manylights_scene::Scene {
        meshes: vec![mesh],
        materials: vec![material],
        instances: vec![manylights_scene::Instance {
            mesh: 0,
            transform: glam::Mat4::IDENTITY,
        }],
        shading,
        ..Default::default()
    };
    manylights::LoadedScene::from_scene("the engine's", scene)
}

/// Our naive pipeline's HDR frame of the engine's scene, lights and camera, and the
/// nearest any light comes to a pixel's surface (metres) within its radius.
fn our_naive_frame(
    shading: manylights_scene::Shading,
    size: (u32, u32),
    lights: Vec<manylights::lights::Light>,
) -> (Vec<[f32; 4]>, f64) {
    let loaded = the_engines_scene_for_us(shading);
    let mut settings = manylights::FrameSettings::for_scene(&loaded);
    settings.pipeline = manylights::PipelineSettings::naive(Default::default());
    settings.view.size = size;
    let look = forward_plus_in_your_engine::engine::ENGINE_VIEW;
    let mut camera = manylights::Camera::look_at(
        look.eye,
        look.target,
        look.fov_y.to_degrees(),
        0.1,
        f32::INFINITY,
    );
    camera.reverse_z = true;
    settings.view.camera = camera;
    let mut renderer =
        manylights::Renderer::new(manylights_tests::gpu(), loaded).expect("renderer");
    let in_reach = lights.clone();
    (renderer.set_fixed_lights(&manylights::lights::LightSet { lights }))
        .expect("the engine's lights");
    renderer.render_frame(&settings).expect("our frame");
    let surface = renderer.capture_surface(&settings).expect("our surfaces");
    let mut nearest = f64::INFINITY;
    for (i, position) in surface.position.iter().enumerate() {
        if position[3] != 1.0 {
            continue;
        }
        let at = manylights::lights::reference::SurfacePoint::from_capture(&surface, i).position;
        for light in &in_reach {
            let distance = at.distance(glam::Vec3::from(light.position).as_dvec3());
            if distance < f64::from(light.radius) {
                nearest = nearest.min(distance);
            }
        }
    }
    (renderer.read_hdr().expect("our HDR frame"), nearest)
}

/// Channels of the engine's frame (f32) farther from ours (Rgba16Float) than our target's
/// storage and two programs' f32 shading allow: one half-float ulp of the value (lavapipe
/// converts by truncation), 1e-7 absolute (a light's term at the edge of its window), and
/// a share of the value for where each program puts the sample. The engine interpolates
/// world positions and we camera-relative ones, each within four ulps of 16 m (`delta`,
/// 7.6e-6 m). A light `nearest` metres away moves its inverse square by 2 delta / nearest
/// of itself, and its GGX lobe (alpha 0.25: the log of D changes by at most 7.8 a radian of
/// the half vector, which turns by at most delta / nearest) by 7.8 delta / nearest: 10
/// delta / nearest of the value bounds both models. The deferred example's normals pass
/// through its Rgba16Float G-buffer; this scene's are axis-aligned, exact in half floats.
fn channels_beyond_storage(
    engine: &[[f32; 4]],
    ours: &[[f32; 4]],
    nearest: f64,
) -> Vec<(usize, f32, f32)> {
    assert_eq!(engine.len(), ours.len(), "frames of one size");
    let delta = 4.0 * 16.0 * f64::from(f32::EPSILON);
    let relative = 10.0 * delta / nearest;
    assert!(
        relative < 1e-2,
        "a light {nearest} m from a surface leaves the test no teeth"
    );
    let mut beyond = Vec::new();
    for (i, (a, b)) in engine.iter().zip(ours).enumerate() {
        for c in 0..3 {
            let value = f64::from(a[c]);
            let allowed = manylights_tests::f16_ulp(value) + relative * value.abs() + 1e-7;
            if f64::from((a[c] - b[c]).abs()) > allowed {
                beyond.push((i, a[c], b[c]));
            }
        }
    }
    beyond
}

#[test]
fn the_engines_frames_are_our_naive_pipelines_frame() {
    drop(manylights_tests::gpu());
    use manylights_scene::Shading;
    let small = small!(forward_plus_in_your_engine, false);
    let lights = forward_plus_in_your_engine::engine::lights(small.lights);
    for (pbr, shading) in [(false, Shading::BlinnPhong), (true, Shading::Pbr)] {
        let (ours, nearest) = our_naive_frame(shading, small.size, lights.clone());
        println!("the nearest light to a pixel's surface: {nearest:.4} m");
        manylights_tests::assert_lit("our naive frame", &ours, 0.5);
        let forward_plus =
            forward_plus_in_your_engine::render(&forward_plus_in_your_engine::engine::Options {
                pbr,
                check: false,
                ..small.clone()
            })
            .expect("Forward+");
        let deferred = deferred_in_your_engine::render(&deferred_in_your_engine::engine::Options {
            pbr,
            check: false,
            size: small.size,
            lights: small.lights,
            ..Default::default()
        })
        .expect("deferred");
        for (example, frame) in [
            ("Forward+", &forward_plus.listed),
            ("deferred", &deferred.listed),
        ] {
            let beyond = channels_beyond_storage(frame, &ours, nearest);
            assert!(
                beyond.is_empty(),
                "{example}, our BRDF {pbr}: {} channels differ from our naive frame, (pixel, the engine's, ours) {:?}",
                beyond.len(),
                &beyond[..beyond.len().min(8)]
            );
        }
    }
}

/// Our loop and BRDF in one call in the engine's shader (`--brdf clustered-radiance`) is
/// our naive pipeline's PBR frame, lights of every shape included (`--shapes`: each
/// spot through its cone, each sphere, rectangle and triangle by its shape).
#[test]
fn the_clustered_radiance_in_an_engines_shader_is_our_naive_pipelines_frame() {
    drop(manylights_tests::gpu());
    use forward_plus_in_your_engine::engine;
    let small = small!(forward_plus_in_your_engine, false);
    for shapes in [false, true] {
        let options = engine::Options {
            clustered_radiance: true,
            shapes,
            check: false,
            ..small.clone()
        };
        let lights = engine::world(&options).expect("the engine's world").lights;
        let areas = lights.iter().filter(|light| light.is_area()).count();
        assert_eq!(areas > 0, shapes);
        let as_points = (lights.iter())
            .map(|l| match l.is_area() {
                true => manylights::lights::Light::point(
                    l.position.into(),
                    l.radius,
                    l.color.into(),
                    l.intensity,
                ),
                false => *l,
            })
            .collect();
        let pbr = manylights_scene::Shading::Pbr;
        let (points, _) = our_naive_frame(pbr, small.size, as_points);
        let (ours, nearest) = our_naive_frame(pbr, small.size, lights);
        manylights_tests::assert_lit("our naive frame", &ours, 0.5);
        let frame = forward_plus_in_your_engine::render(&options).expect("the engine's frame");
        let beyond = channels_beyond_storage(&frame.listed, &ours, nearest);
        assert!(
            beyond.is_empty(),
            "shapes {shapes}: {} channels differ from our naive frame, (pixel, the engine's, ours) {:?}",
            beyond.len(),
            &beyond[..beyond.len().min(8)]
        );
        // With the areas shaded as points, the same lights' frame is another: the check
        // above can fail, for the areas' sizes.
        let as_points = channels_beyond_storage(&frame.listed, &points, nearest).len();
        println!("shapes {shapes}: {as_points} channels differ from the areas as points");
        assert_eq!(as_points > ours.len() / 10, shapes, "{as_points}");
    }
}

/// An empty pixel, at its convention's clear depth, is nothing seen, whichever convention
/// the engine's projection has: with no pixel drawn, a standard projection's depth cleared
/// to 1 and the engine's reverse-Z infinite one's cleared to 0, no cluster gets a box of
/// visible samples. Read the other convention's way, the empty pixels would be surfaces on
/// the far plane, or at infinity (the frames would not show it: nothing is lit there).
#[test]
fn empty_pixels_are_nothing_seen_under_either_depth_convention() {
    use forward_plus_in_your_engine::engine;
    use manylights_cluster::{ClusterFrame, ClusterGrid, GpuClusters, VisibleDepth};
    use manylights_gpu::{ShaderLibrary, ViewBinding, ViewUniform, wgpu};

    let context = manylights_tests::gpu();
    let size = (64, 32);
    let (view, reverse_z) = engine::camera(size, engine::ENGINE_VIEW);
    let aspect = size.0 as f32 / size.1 as f32;
    let fov_y = engine::ENGINE_VIEW.fov_y;
    let standard = glam::camera::rh::proj::directx::perspective(fov_y, aspect, 0.1, 100.0);
    let lights: Vec<_> = engine::lights(1_500);
    let lights = manylights_lights::GpuLights::new(&context, &lights).expect("lights");
    let view_binding = ViewBinding::new(&context);
    let mut clusters =
        GpuClusters::new(&context, &ShaderLibrary::from_env(), &view_binding).expect("clusters");
    for (name, projection, clear) in [("standard", standard, 1.0), ("reverse-Z", reverse_z, 0.0)] {
        let camera = ViewUniform::from_matrices(view, projection, size).expect("the camera");
        assert_eq!(
            camera.near_far[2], clear,
            "{name}: the clear depth read off the matrix"
        );
        view_binding.update(&context, &camera);
        let (low, high) = engine::scene().bounds;
        let scene = manylights_scene::Aabb::new(low, high);
        let grid = ClusterGrid::for_view(&Default::default(), &camera, Some(scene)).expect("grid");
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let depth = engine::texture(&context.device, size, engine::DEPTH_FORMAT, usage);
        let depth_view = depth.create_view(&Default::default());
        let mut encoder = context.device.create_command_encoder(&Default::default());
        drop(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        }));
        let visible = VisibleDepth::of(&depth, &depth_view);
        clusters
            .prepare(&context, &ClusterFrame::new(grid), &lights, Some(visible))
            .expect("prepared");
        let _lists =
            (clusters.assignment().expect("prepared")).record(&mut encoder, &view_binding, None);
        context.queue.submit([encoder.finish()]);
        clusters.after_submit();
        let bounds = clusters.read_bounds(&context).expect("the boxes");
        let seen = bounds.iter().filter(|aabb| !aabb.is_empty()).count();
        assert_eq!(
            seen,
            0,
            "{name}: {seen} of {} clusters see an empty frame",
            bounds.len()
        );
        let entries = clusters.read_lists(&context).expect("the lists").total();
        assert_eq!(entries, 0, "{name}: lights listed where nothing is seen");
    }
}
