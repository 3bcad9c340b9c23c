//! The WGSL traversal (`shaders/visibility/bvh.wgsl`, run through `bvh_probe.wgsl`)
//! against the f64 one, ray by ray: the same hit or miss for every ray, the same distance
//! within the f32 rounding bound derived below, the same shadow-ray answer.

use glam::{DVec3, Mat4, Vec3};
use manylights_gpu::wgpu::util::DeviceExt as _;
use manylights_gpu::{GpuContext, MaterialVariant, ShaderLibrary, wgpu};
use manylights_scene::Scene;
use manylights_visibility::test_scenes::{
    closed_box, half_masked, merged, mesh_scene, plane, sphere,
};
use manylights_visibility::{GpuSceneBvh, SceneBvh, probe_program};

/// Mirrors `ProbeRay` in bvh_probe.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeRay {
    origin: [f32; 4],
    direction: [f32; 4],
    normal: [f32; 4],
}

/// Mirrors `ProbeResult` in bvh_probe.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeResult {
    closest_hit: u32,
    closest_t: f32,
    any_hit: u32,
    visible: u32,
    closest_triangle: u32,
}

impl ProbeRay {
    fn new(origin: Vec3, direction: Vec3, t_max: f32, normal: Vec3) -> Self {
        Self {
            origin: origin.extend(0.0).to_array(),
            direction: direction.extend(t_max).to_array(),
            normal: normal.extend(0.0).to_array(),
        }
    }
    fn origin(&self) -> DVec3 {
        Vec3::from_slice(&self.origin[..3]).as_dvec3()
    }
    fn direction(&self) -> DVec3 {
        Vec3::from_slice(&self.direction[..3]).as_dvec3()
    }
}

fn probe(bvh: &SceneBvh, rays: &[ProbeRay]) -> Vec<ProbeResult> {
    let context = GpuContext::new_headless()
        .unwrap_or_else(|error| panic!("these tests need a GPU: {error}"));
    let gpu_bvh = context
        .scoped("uploading the BVH", || GpuSceneBvh::new(&context, bvh))
        .expect("uploads without wgpu errors")
        .expect("fits WebGPU's textures");
    let module = ShaderLibrary::from_env()
        .create_module(&context, &probe_program(), MaterialVariant::default())
        .expect("the probe composes");
    let device = &context.device;
    let ray_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe rays"),
        contents: bytemuck::cast_slice(rays),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let result_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe results"),
        size: (rays.len() * std::mem::size_of::<ProbeResult>()) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let compute = wgpu::ShaderStages::COMPUTE;
    let mut entries = vec![
        manylights_gpu::binding::storage_entry(0, compute, true),
        manylights_gpu::binding::storage_entry(1, compute, false),
    ];
    entries.extend(GpuSceneBvh::layout_entries(compute));
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("bvh probe"),
        entries: &entries,
    });
    let empty = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("empty"),
        entries: &[],
    });
    let [pipeline] = manylights_gpu::binding::compute_pipelines(
        &context,
        "bvh probe",
        &[&empty, &empty, &empty, &layout],
        &module,
        ["probe"],
    );
    let mut group_entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: ray_buffer.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: result_buffer.as_entire_binding(),
        },
    ];
    group_entries.extend(
        gpu_bvh
            .bindings()
            .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource }),
    );
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("bvh probe"),
        layout: &layout,
        entries: &group_entries,
    });
    let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("empty"),
        layout: &empty,
        entries: &[],
    });
    context
        .scoped("running the bvh probe", || {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                for group in 0..3 {
                    pass.set_bind_group(group, &empty_group, &[]);
                }
                pass.set_bind_group(3, &bind_group, &[]);
                pass.dispatch_workgroups((rays.len() as u32).div_ceil(64), 1, 1);
            }
            context.queue.submit([encoder.finish()]);
        })
        .expect("the probe passes wgpu's validation");
    manylights_gpu::targets::read_buffer(&context, &result_buffer).expect("readback")
}

/// The shared test numbers in f32.
struct Numbers(manylights_visibility::test_scenes::Numbers);

impl Numbers {
    fn new(seed: u64) -> Self {
        Self(manylights_visibility::test_scenes::Numbers(seed))
    }

    fn next(&mut self) -> f32 {
        self.0.uniform() as f32
    }

    fn in_box(&mut self, min: Vec3, max: Vec3) -> Vec3 {
        self.0.in_box(min.as_dvec3(), max.as_dvec3()).as_vec3()
    }
}

/// How far the GPU's f32 distance may be from the f64 one, in units of the ray's length.
/// The watertight test shears the vertices (relative to the origin, each within R of it)
/// so that the ray runs along z: the sheared x and y are within 2R. Its edge functions
/// u, v, w are differences of products of those, each off by at most 2 roundings of
/// 2^-24 of (2R)^2 = 8 eps R^2 (eps = 2^-24, a few more for the shear: 16 eps R^2). The
/// distance is sum(u_i z_i) / sum(u_i) with every z_i within R, so an error in the u_i
/// moves it by at most 3 x 16 eps R^2 x R / det, where det = u + v + w is twice the
/// triangle's area projected along the ray, A |cos theta| / |d_z| >= A |cos theta|. The
/// final products and division add a few eps of the distance itself.
fn distance_tolerance(bvh: &SceneBvh, ray: &ProbeRay, triangle: u32) -> f64 {
    let eps = f64::from(f32::EPSILON) / 2.0;
    let t = &bvh.triangles()[triangle as usize];
    let vertices = [t.v0, t.v1, t.v2].map(|v| Vec3::from_array(v).as_dvec3());
    let origin = ray.origin();
    let reach = vertices
        .iter()
        .map(|v| (*v - origin).length())
        .fold(0.0, f64::max);
    let cross = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
    let area = cross.length() / 2.0;
    let direction = ray.direction();
    let cosine = (cross.normalize_or_zero().dot(direction.normalize())).abs();
    let from_edge_functions = 48.0 * eps * reach.powi(3) / (2.0 * area * cosine).max(1e-30);
    (from_edge_functions + 8.0 * eps * reach) / direction.length()
}

/// Every ray: the GPU's nearest hit and any hit agree with the f64 traversal, distances
/// within [`distance_tolerance`], and `light_visible` agrees. Returns the rays that hit.
fn assert_gpu_matches(name: &str, bvh: &SceneBvh, rays: &[ProbeRay]) -> usize {
    let results = probe(bvh, rays);
    let mut hits = 0;
    for (k, (ray, gpu)) in rays.iter().zip(&results).enumerate() {
        let (origin, direction) = (ray.origin(), ray.direction());
        let (t_min, t_max) = (f64::from(ray.origin[3]), f64::from(ray.direction[3]));
        let cpu = bvh.closest_hit(origin, direction, t_min, t_max);
        assert_eq!(
            gpu.closest_hit == 1,
            cpu.is_some(),
            "{name} ray {k} {ray:?}: GPU {gpu:?}, f64 {cpu:?}"
        );
        assert_eq!(gpu.any_hit == 1, cpu.is_some(), "{name} ray {k}: any hit");
        if let Some(hit) = cpu {
            hits += 1;
            // Through a shared edge the GPU may meet the other triangle: its rounding counts.
            let tolerance = distance_tolerance(bvh, ray, hit.triangle).max(distance_tolerance(
                bvh,
                ray,
                gpu.closest_triangle,
            ));
            assert!(
                (f64::from(gpu.closest_t) - hit.t).abs() <= tolerance,
                "{name} ray {k}: GPU t {} against f64 {} (tolerance {tolerance:e})",
                gpu.closest_t,
                hit.t
            );
        }
        let normal = Vec3::from_slice(&ray.normal[..3]).as_dvec3();
        let visible = bvh.light_visible(origin, normal, origin + direction);
        assert_eq!(
            gpu.visible == 1,
            visible,
            "{name} ray {k}: shadow ray {ray:?}"
        );
    }
    hits
}

/// Random segments between random points of the scene's box (and a margin around it).
fn random_rays(scene: &Scene, count: usize, seed: u64) -> Vec<ProbeRay> {
    let bounds = scene.bounds();
    let margin = (bounds.max - bounds.min) * 0.1;
    let (min, max) = (bounds.min - margin, bounds.max + margin);
    let mut numbers = Numbers::new(seed);
    (0..count)
        .map(|_| {
            let origin = numbers.in_box(min, max);
            let target = numbers.in_box(min, max);
            let normal = numbers
                .in_box(Vec3::splat(-1.0), Vec3::ONE)
                .normalize_or(Vec3::Y);
            ProbeRay::new(origin, target - origin, 1.0, normal)
        })
        .collect()
}

/// Rays aimed exactly at points of edges two triangles of non-zero area share, from random
/// origins on the side where the edge is not a silhouette (the two triangles face the ray
/// alike, so they lie on either side of it): a watertight test hits one of the two, even
/// after the roundings of f32. Their shadow rays have no normal to step along, so they too
/// pass through the edge.
fn grazing_rays(bvh: &SceneBvh, count: usize, seed: u64) -> Vec<ProbeRay> {
    use std::collections::HashMap;
    let mut edges: HashMap<[[u32; 3]; 2], Vec<Vec3>> = HashMap::new();
    let key = |v: [f32; 3]| v.map(f32::to_bits);
    for t in bvh.triangles() {
        let [a, b, c] = [t.v0, t.v1, t.v2].map(Vec3::from_array);
        let normal = (b - a).cross(c - a);
        if normal == Vec3::ZERO {
            continue;
        }
        for (a, b) in [(t.v0, t.v1), (t.v1, t.v2), (t.v2, t.v0)] {
            let mut edge = [key(a), key(b)];
            edge.sort();
            edges.entry(edge).or_default().push(normal);
        }
    }
    let mut shared: Vec<([[u32; 3]; 2], Vec<Vec3>)> = edges
        .into_iter()
        .filter(|(_, normals)| normals.len() == 2)
        .collect();
    shared.sort_by_key(|(edge, _)| *edge);
    assert!(!shared.is_empty());
    let mut numbers = Numbers::new(seed);
    let point = |bits: [u32; 3]| Vec3::from_array(bits.map(f32::from_bits));
    let mut rays = Vec::new();
    while rays.len() < count {
        let k = rays.len();
        let (edge, normals) =
            &shared[(numbers.next() * shared.len() as f32) as usize % shared.len()];
        let (a, b) = (point(edge[0]), point(edge[1]));
        // Half the rays at the edge's midpoint, half anywhere along it.
        let s = if k % 2 == 0 {
            0.5
        } else {
            0.05 + 0.9 * numbers.next()
        };
        let target = a.lerp(b, s);
        let origin = target + numbers.in_box(Vec3::splat(-2.0), Vec3::splat(2.0));
        let direction = target - origin;
        let facing = normals
            .iter()
            .map(|n| n.dot(direction).signum())
            .collect::<Vec<_>>();
        if facing[0] == facing[1] && facing[0] != 0.0 {
            rays.push(ProbeRay::new(origin, direction * 2.0, 1.0, Vec3::ZERO));
        }
    }
    rays
}

fn sponza() -> Scene {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../assets/sponza/sponza.gltf"
    );
    manylights_scene::load(path).unwrap_or_else(|error| panic!("{path}: {error}"))
}

#[test]
fn sponza_rays_agree_with_the_f64_traversal() {
    let scene = sponza();
    let bvh = SceneBvh::build(&scene).expect("Sponza's BVH builds");
    let mut rays = random_rays(&scene, 4096, 1);
    rays.extend(grazing_rays(&bvh, 1024, 2));
    let hits = assert_gpu_matches("sponza", &bvh, &rays);
    assert!(
        hits > rays.len() / 4 && hits < rays.len(),
        "{hits} of {} rays hit",
        rays.len()
    );
}

#[test]
fn procedural_rays_agree_with_the_f64_traversal() {
    let far = Mat4::from_translation(Vec3::new(120.0, 3.0, -40.0));
    let scene = merged([
        manylights_scene::procedural::cornell(),
        manylights_scene::procedural::pillars(manylights_scene::procedural::PillarsParams {
            grid: 2,
            segments: 16,
        }),
        sphere(1.0, 24, far),
        half_masked(
            plane(2.0, Mat4::from_translation(Vec3::new(0.0, 2.5, 0.0))),
            16,
        ),
        // Degenerate triangles: a sliver of zero area and a point.
        mesh_scene(
            "degenerate",
            vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::Y],
            vec![0, 1, 2, 3, 3, 3],
            Mat4::from_translation(Vec3::new(0.2, 0.5, 0.1)),
        ),
    ]);
    let bvh = SceneBvh::build(&scene).expect("builds");
    let mut rays = random_rays(&scene, 4096, 3);
    rays.extend(grazing_rays(&bvh, 1024, 4));
    // From inside closed geometry: the sphere's centre, outwards in every direction.
    let mut numbers = Numbers::new(5);
    let centre = far.transform_point3(Vec3::ZERO);
    for _ in 0..256 {
        let direction = numbers
            .in_box(Vec3::splat(-1.0), Vec3::ONE)
            .normalize_or(Vec3::X)
            * 3.0;
        rays.push(ProbeRay::new(centre, direction, 1.0, Vec3::Y));
    }
    // At the sphere's vertices (every one but the poles is inside the closed mesh).
    let ball = &scene.meshes[2];
    for vertex in &ball.positions {
        if vertex.y.abs() < 0.999 {
            let target = far.transform_point3(*vertex);
            let origin = target + *vertex * 2.0 + numbers.in_box(Vec3::splat(-1.0), Vec3::ONE);
            rays.push(ProbeRay::new(
                origin,
                (target - origin) * 2.0,
                1.0,
                Vec3::ZERO,
            ));
        }
    }
    let hits = assert_gpu_matches("procedural", &bvh, &rays);
    assert!(
        hits > rays.len() / 8 && hits < rays.len(),
        "{hits} of {} rays hit",
        rays.len()
    );
}

#[test]
fn a_closed_box_keeps_its_light_inside_on_the_gpu() {
    let bvh = SceneBvh::build(&closed_box(Vec3::ZERO, Vec3::ONE)).expect("builds");
    let light = Vec3::splat(0.5);
    let mut numbers = Numbers::new(9);
    let rays: Vec<ProbeRay> = (0..512)
        .map(|_| {
            let mut outside = numbers.in_box(Vec3::splat(-3.0), Vec3::splat(4.0));
            if outside.cmpge(Vec3::ZERO).all() && outside.cmple(Vec3::ONE).all() {
                outside.y += 2.0;
            }
            ProbeRay::new(outside, light - outside, 1.0, (light - outside).normalize())
        })
        .collect();
    let results = probe(&bvh, &rays);
    assert!(
        results.iter().all(|r| r.visible == 0),
        "a light inside a closed box lit a point outside it"
    );
    assert_gpu_matches("box", &bvh, &rays);
}

#[test]
fn probe_structs_match_wgsl() {
    use manylights_gpu::assert_wgsl_layout;
    assert_wgsl_layout!(
        probe_program(),
        "visibility/bvh_probe.wgsl",
        ProbeRay
            == ProbeRay {
                origin: origin,
                direction: direction,
                normal: normal,
            }
    );
    assert_wgsl_layout!(
        probe_program(),
        "visibility/bvh_probe.wgsl",
        ProbeResult
            == ProbeResult {
                closest_hit: closest_hit,
                closest_t: closest_t,
                any_hit: any_hit,
                visible: visible,
                closest_triangle: closest_triangle,
            }
    );
}
