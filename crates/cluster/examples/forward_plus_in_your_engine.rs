//! Forward+ in someone else's renderer: a wgpu program with its own device, camera (a
//! reverse-Z, infinite-far projection), vertex format, depth pre-pass, render pipeline
//! and fragment shader shades 10,000 lights of its own through manylights' cluster lists.
//! Five of the library's types do it: `GpuContext` (over the engine's device),
//! `ViewUniform`/`ViewBinding` (the camera as the assignment reads it, from the engine's
//! matrices), `GpuLights` (the engine's lights), `GpuClusters` (the lists, bounded by the
//! engine's depth) and `ListedLights` (the WGSL and bind group the engine's shader uses).
//!
//! ```sh
//! cargo run --release -p manylights-cluster --example forward_plus_in_your_engine -- \
//!     --size 1280x720 --lights 10000 --check --out engine.png
//! ```
//! `--check` also draws the frame from every light (no lists) and compares the two pixel by
//! pixel: the lists must leave out nothing that reaches a pixel.

use std::error::Error;

use glam::Vec3;
use glam::camera::rh;
use manylights_cluster::{
    ClusterFrame, ClusterGrid, ClusterSettings, GpuClusters, ListedLights, VisibleDepth,
};
use manylights_gpu::wgpu::{self, util::DeviceExt};
use manylights_gpu::{DeviceRequirements, GpuContext, ShaderLibrary, ViewBinding, ViewUniform};
use manylights_lights::{GpuLights, Light};

/// What the engine draws, and how.
#[derive(Debug)]
pub struct Options {
    pub size: (u32, u32),
    pub lights: u32,
    /// Also draw every light without the lists.
    pub check: bool,
}

/// The engine's frames, HDR radiance, row by row.
#[derive(Debug)]
pub struct Frames {
    pub listed: Vec<[f32; 4]>,
    pub every_light: Option<Vec<[f32; 4]>>,
}

/// The engine's bind group index for the lists (its camera is at 0).
const LISTS_GROUP: u32 = 1;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The engine's shader: its camera, its vertex format, its Lambert BRDF, and two fragment
/// entry points, one walking the lists and one every light.
const ENGINE_WGSL: &str = r#"
struct Camera { view_proj: mat4x4<f32>, view: mat4x4<f32>, light_count: vec4<u32> }
@group(0) @binding(0) var<uniform> camera: Camera;

struct Varyings {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> Varyings {
    return Varyings(camera.view_proj * vec4<f32>(position, 1.0), position, normal);
}

// The engine's BRDF (Lambert, albedo 0.8) with the falloff the lights are listed for.
fn lambert(light: manylights_Light, world: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    let to_light = light.position - world;
    let distance_squared = dot(to_light, to_light);
    let n_dot_l = max(dot(normal, to_light) * inverseSqrt(max(distance_squared, 1e-8)), 0.0);
    let falloff = manylights_windowed_falloff(distance_squared, light.radius);
    return light.color * (light.intensity * n_dot_l * falloff * 0.8 / 3.14159265);
}

@fragment
fn fs_listed(in: Varyings) -> @location(0) vec4<f32> {
    let normal = normalize(in.normal);
    let view_depth = -(camera.view * vec4<f32>(in.world, 1.0)).z;
    let list = manylights_lights_at(in.clip.xy, view_depth);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < list.candidates; i++) {
        let index = manylights_listed_light(list, i);
        if index == manylights_NOT_LISTED {
            continue;
        }
        radiance += lambert(manylights_lights[index], in.world, normal);
    }
    return vec4<f32>(radiance, 1.0);
}

@fragment
fn fs_every_light(in: Varyings) -> @location(0) vec4<f32> {
    let normal = normalize(in.normal);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < camera.light_count.x; i++) {
        radiance += lambert(manylights_lights[i], in.world, normal);
    }
    return vec4<f32>(radiance, 1.0);
}
"#;

/// The engine's scene: a 20 x 20 m floor and a 5 x 5 grid of 1 m boxes, as (position,
/// normal) vertices and triangle indices.
fn engine_scene() -> (Vec<[f32; 6]>, Vec<u32>) {
    let (mut vertices, mut indices) = (Vec::new(), Vec::new());
    let mut quad = |corner: Vec3, u: Vec3, v: Vec3| {
        let normal = u.cross(v).normalize();
        let first = vertices.len() as u32;
        for p in [corner, corner + u, corner + u + v, corner + v] {
            vertices.push([p.x, p.y, p.z, normal.x, normal.y, normal.z]);
        }
        indices.extend([0, 1, 2, 0, 2, 3].map(|i| first + i));
    };
    quad(
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::X * 20.0,
        Vec3::NEG_Z * 20.0,
    );
    for (x, z) in (0..25).map(|i| (i % 5, i / 5)) {
        let low = Vec3::new(x as f32 * 4.0 - 8.5, 0.0, z as f32 * 4.0 - 8.5);
        let (ex, ey, ez) = (Vec3::X, Vec3::Y, Vec3::Z);
        let high = low + Vec3::ONE;
        quad(low, ey, ex); // -Z face
        quad(high, -ex, -ey); // +Z face
        quad(low, ez, ey); // -X face
        quad(high, -ey, -ez); // +X face
        quad(high, -ez, -ex); // top
    }
    (vertices, indices)
}

/// The engine's lights: `count` points 0.1-2 m above the floor, 1.5 m radius, random
/// saturated colours.
fn engine_lights(count: u32) -> Vec<Light> {
    let mut state = 0x9e37_79b9u32;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    (0..count)
        .map(|_| {
            let position = Vec3::new(
                random() * 20.0 - 10.0,
                0.1 + random() * 1.9,
                random() * 20.0 - 10.0,
            );
            let hue = Vec3::new(random(), random(), random()).powf(3.0);
            Light::point(position, 1.5, hue / hue.max_element(), 0.06)
        })
        .collect()
}

/// The engine's device, made by the engine with what the library needs merged in.
fn engine_device() -> Result<GpuContext, Box<dyn Error>> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let needs = DeviceRequirements::minimum();
    let mut descriptor = wgpu::DeviceDescriptor::default();
    needs.merge_into(&mut descriptor, &adapter);
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))?;
    Ok(GpuContext::from_device(
        instance, adapter, device, queue, &needs,
    )?)
}

pub fn render(options: &Options) -> Result<Frames, Box<dyn Error>> {
    let context = engine_device()?;
    let device = &context.device;
    let (width, height) = options.size;
    // The engine's camera: right-handed, reverse-Z with an infinite far plane.
    let eye = Vec3::new(0.0, 7.0, 13.0);
    let view = rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, 1.0), Vec3::Y);
    let aspect = width as f32 / height as f32;
    let projection = rh::proj::directx::perspective_infinite_reverse(0.9, aspect, 0.1);
    let lights = engine_lights(options.lights);
    #[repr(C)]
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct Camera {
        view_proj: [[f32; 4]; 4],
        view: [[f32; 4]; 4],
        light_count: [u32; 4],
    }
    let camera = Camera {
        view_proj: (projection * view).to_cols_array_2d(),
        view: view.to_cols_array_2d(),
        light_count: [lights.len() as u32, 0, 0, 0],
    };
    let buffer = |label, contents: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    };
    let camera_buffer = buffer(
        "camera",
        bytemuck::bytes_of(&camera),
        wgpu::BufferUsages::UNIFORM,
    );
    let (vertices, indices) = engine_scene();
    let vertex_buffer = buffer(
        "vertices",
        bytemuck::cast_slice(&vertices),
        wgpu::BufferUsages::VERTEX,
    );
    let index_buffer = buffer(
        "indices",
        bytemuck::cast_slice(&indices),
        wgpu::BufferUsages::INDEX,
    );
    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let depth = texture(
        "depth",
        DEPTH_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let depth_view = depth.create_view(&Default::default());
    let color = texture(
        "color",
        COLOR_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let color_view = color.create_view(&Default::default());

    // The library: the camera from the engine's matrices, its lights, the lists.
    let library = ShaderLibrary::from_env();
    let uniform = ViewUniform::from_matrices(view, projection, options.size)?;
    let view_binding = ViewBinding::new(&context);
    view_binding.update(&context, &uniform);
    let gpu_lights = GpuLights::new(&context, &lights)?;
    let scene_bounds =
        manylights_scene::Aabb::new(Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 2.0, 10.0));
    let grid = ClusterGrid::for_view(&ClusterSettings::default(), &uniform, Some(scene_bounds))?;
    let mut clusters = GpuClusters::new(&context, &library, &view_binding)?;
    let listed = ListedLights::new(&context, LISTS_GROUP);

    // The engine's pipelines: a depth pre-pass and the shading pass, with the lists' WGSL
    // put before its own and their layout at LISTS_GROUP.
    let source = format!("{}\n{ENGINE_WGSL}", listed.wgsl(&library)?);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("engine shader"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("camera"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let camera_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("camera"),
        layout: &camera_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: camera_buffer.as_entire_binding(),
        }],
    });
    let layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: groups,
            immediate_size: 0,
        })
    };
    // The depth pre-pass binds the camera alone, the shading pass the lists beside it.
    let depth_layout = layout(&[Some(&camera_layout)]);
    let shading_layout = layout(&[Some(&camera_layout), Some(listed.layout())]);
    let color_targets = [Some(wgpu::ColorTargetState::from(COLOR_FORMAT))];
    let pipeline = |fragment: Option<&str>, compare, writes_depth| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: fragment,
            layout: Some(if fragment.is_some() {
                &shading_layout
            } else {
                &depth_layout
            }),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: Some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(writes_depth),
                depth_compare: Some(compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: fragment.map(|entry| wgpu::FragmentState {
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: &color_targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    // Reverse-Z: nearer is greater.
    let depth_pass = pipeline(None, wgpu::CompareFunction::Greater, true);
    let shade = |entry| pipeline(Some(entry), wgpu::CompareFunction::GreaterEqual, false);
    let (shade_listed, shade_every_light) = (shade("fs_listed"), shade("fs_every_light"));
    let draw = |pass: &mut wgpu::RenderPass,
                pipeline: &wgpu::RenderPipeline,
                lists: Option<&wgpu::BindGroup>| {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &camera_group, &[]);
        if let Some(lists) = lists {
            pass.set_bind_group(LISTS_GROUP, lists, &[]);
        }
        pass.set_vertex_buffer(0, vertex_buffer.slice(..));
        pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..indices.len() as u32, 0, 0..1);
    };

    // One frame: depth pre-pass, the lists from the seen depth, then shading.
    let mut frame = |shading: &wgpu::RenderPipeline| -> Result<Vec<[f32; 4]>, Box<dyn Error>> {
        loop {
            clusters.prepare(
                &context,
                &ClusterFrame::new(grid),
                &gpu_lights,
                Some(VisibleDepth::of(&depth, &depth_view)),
            )?;
            let lists_group = listed.bind_group(&context, &clusters, &gpu_lights)?;
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("depth pre-pass"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(0.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
                draw(&mut pass, &depth_pass, None);
            }
            let _lists = clusters
                .assignment()?
                .record(&mut encoder, &view_binding, None);
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shading"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &color_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
                draw(&mut pass, shading, Some(&lists_group));
            }
            context.queue.submit([encoder.finish()]);
            clusters.after_submit();
            // A list buffer too small for the frame grows; an engine learns it a frame
            // later without waiting (`grow_for_earlier_frames`), this example waits.
            if clusters.wait_and_grow(&context)?.is_none() {
                return Ok(manylights_gpu::targets::read_f32_rgba(&context, &color)?);
            }
        }
    };
    let listed_frame = frame(&shade_listed)?;
    let every_light = options
        .check
        .then(|| frame(&shade_every_light))
        .transpose()?;
    Ok(Frames {
        listed: listed_frame,
        every_light,
    })
}

/// Channels of `a` and `b` that differ by more than 64 f32 ulps of the larger: both
/// frames sum the same nonzero terms in the same order (a light the lists leave out adds
/// exactly zero where it is left out), so only the compilers' contractions of two
/// pipelines differ.
pub fn differing_channels(a: &[[f32; 4]], b: &[[f32; 4]]) -> usize {
    let tolerance = 64.0 * f32::EPSILON;
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .filter(|(x, y)| (*x - *y).abs() > tolerance * x.abs().max(y.abs()).max(f32::MIN_POSITIVE))
        .count()
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn Error>> {
    let mut options = Options {
        size: (1280, 720),
        lights: 10_000,
        check: false,
    };
    let mut out = String::from("forward_plus_in_your_engine.png");
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--check" => options.check = true,
            "--size" => {
                let size = args.next().ok_or("--size WxH")?;
                let (w, h) = size.split_once('x').ok_or("--size WxH")?;
                options.size = (w.parse()?, h.parse()?);
            }
            "--lights" => options.lights = args.next().ok_or("--lights N")?.parse()?,
            "--out" => out = args.next().ok_or("--out FILE")?,
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let frames = render(&options)?;
    let lit = frames
        .listed
        .iter()
        .filter(|p| p[0] + p[1] + p[2] > 0.0)
        .count();
    println!(
        "{} lights, {}x{}: {lit} of {} pixels lit",
        options.lights,
        options.size.0,
        options.size.1,
        frames.listed.len()
    );
    if let Some(every_light) = &frames.every_light {
        let differing = differing_channels(&frames.listed, every_light);
        println!("against every light: {differing} channels differ by more than 64 ulps");
        if differing > 0 {
            return Err("the lists left out light that reaches a pixel".into());
        }
    }
    // Tone mapped for the PNG (Reinhard, sRGB encoded by `image`'s 8-bit write).
    let image = image::RgbaImage::from_fn(options.size.0, options.size.1, |x, y| {
        let p = frames.listed[(y * options.size.0 + x) as usize];
        let map = |c: f32| ((c / (1.0 + c)).powf(1.0 / 2.2) * 255.0).round() as u8;
        image::Rgba([map(p[0]), map(p[1]), map(p[2]), 255])
    });
    image.save(&out)?;
    println!("wrote {out}");
    Ok(())
}
