//! Someone else's renderer: what the engine examples share and manylights has no part in
//! (its device, scene, camera, lights, depth pre-pass, pipelines, command line and PNG), so
//! that each example shows only what it takes to use the library inside it. It names the
//! library's types only where it lends it its device (`GpuContext::from_device`), makes
//! its lights (`Light`) and times passes (`GpuTimer`). With `--scene FILE` (to time the
//! library inside this engine against manylights' own renderer on the same frame) it reads
//! the file with `manylights-scene` and generates the lab's lights for it with
//! `manylights-lights`.

use std::error::Error;

use glam::{Mat4, Vec3};
use manylights_gpu::wgpu::{self, util::DeviceExt};
use manylights_gpu::{DeviceRequirements, GpuContext, GpuTimer, GpuTimings};
use manylights_lights::Light;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The engine's WGSL that every example's shader starts with: its camera block and its
/// vertex format.
pub const ENGINE_WGSL: &str = r#"
struct Camera {
    view_proj: mat4x4<f32>,
    view: mat4x4<f32>,
    inverse_view_proj: mat4x4<f32>,
    // xyz: the eye's position.
    eye: vec4<f32>,
    // x: the lights in the buffer.
    light_count: vec4<u32>,
}
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

// The distance along the camera's view direction (right-handed: it looks down -Z).
fn view_depth(world: vec3<f32>) -> f32 {
    return -(camera.view * vec4<f32>(world, 1.0)).z;
}
"#;

/// The engine's BRDF, Lambert of albedo 0.8, as two functions its light loops call:
/// `surface_of`, what a pixel's terms share, worked out once before the loop, and
/// `reflected`, the radiance towards the eye per unit of irradiance (colour x intensity x
/// falloff) from a light at `light_position`.
pub const LAMBERT_WGSL: &str = r#"
struct Surface { world: vec3<f32>, normal: vec3<f32> }
fn surface_of(world: vec3<f32>, normal: vec3<f32>) -> Surface {
    return Surface(world, normal);
}
fn reflected(surface: Surface, light_position: vec3<f32>) -> vec3<f32> {
    let n_dot_l = max(dot(surface.normal, normalize(light_position - surface.world)), 0.0);
    return vec3<f32>(n_dot_l * 0.8 / 3.14159265);
}
"#;

/// manylights' BRDF (`manylights_lights::pbr_wgsl`, which the example adds to its shader)
/// behind the same two functions (`--brdf pbr`): a grey dielectric of roughness 0.5.
pub const OUR_BRDF_WGSL: &str = r#"
struct Surface { world: vec3<f32>, normal: vec3<f32>, view_dir: vec3<f32>, lit: manylights_LitSurface }
fn surface_of(world: vec3<f32>, normal: vec3<f32>) -> Surface {
    let view_dir = normalize(camera.eye.xyz - world);
    let lit = manylights_pbr_surface(world, normal, view_dir, vec3<f32>(0.8), 0.0, 0.5);
    return Surface(world, normal, view_dir, lit);
}
fn reflected(surface: Surface, light_position: vec3<f32>) -> vec3<f32> {
    let l = normalize(light_position - surface.world);
    return manylights_pbr_reflected(surface.lit, surface.view_dir, l);
}
"#;

/// How a pipeline tests the engine's depth (reverse-Z: nearer is greater) and whether it
/// writes it.
#[derive(Debug, Clone, Copy)]
pub struct DepthTest {
    pub compare: wgpu::CompareFunction,
    pub writes: bool,
}

impl DepthTest {
    /// A pass that lays the depth down: the nearest surface wins and is written.
    pub const LAYS_DOWN: Self = Self {
        compare: wgpu::CompareFunction::Greater,
        writes: true,
    };
    /// A pass after the depth is laid down: the surface it holds passes, nothing is written.
    pub const AFTER_DEPTH: Self = Self {
        compare: wgpu::CompareFunction::GreaterEqual,
        writes: false,
    };
}

/// What an example draws: `--size WxH`, `--lights N`, `--check` (also draw every light
/// without the lists), `--shadows` (shadow rays), `--far-field TOLERANCE` (what the
/// lights add beyond their radius, from the light tree), `--time FRAMES` (GPU time per
/// pass), `--brdf lambert|pbr|clustered-radiance` (the engine's BRDF, ours in the engine's
/// loop, or our loop and BRDF in one call), `--shapes` (lights of every shape), `--scene
/// FILE`, `--camera EX,EY,EZ,TX,TY,TZ,FOV`, `--out FILE`.
#[derive(Debug, Clone)]
pub struct Options {
    /// A glTF or OBJ file drawn instead of the engine's floor and boxes, lit by the lights
    /// `manylights render --scene` puts in it (see [`lab_lights`]).
    pub scene: Option<String>,
    /// Where the camera is, what it looks at and its vertical field of view (default:
    /// [`ENGINE_VIEW`]; for `--scene`, [`SPONZA_REFERENCE_VIEW`] in Sponza, and a view of
    /// the whole scene in any other file).
    pub camera: Option<Look>,
    pub size: (u32, u32),
    pub lights: u32,
    pub check: bool,
    pub shadows: bool,
    pub far_field: Option<f32>,
    /// Our BRDF in the example's loop instead of the engine's Lambert (`--brdf pbr`; not
    /// with `--far-field`, whose aggregates the engine lights with its Lambert).
    pub pbr: bool,
    /// The lists' loop and our BRDF in one call (`--brdf clustered-radiance`:
    /// `ListedLights::clustered_radiance_wgsl`), far field included; the frame from every
    /// light (`--check`) is the engine's loop with our BRDF.
    pub clustered_radiance: bool,
    /// Every fifth light a point, a spot, a sphere, a rectangle or a triangle (`--shapes`;
    /// only with `--brdf clustered-radiance`: the engine's own loop shades points).
    pub shapes: bool,
    /// Frames to time (`--time N`; 0: none).
    pub time: u32,
    pub out: String,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            scene: None,
            camera: None,
            size: (1280, 720),
            lights: 10_000,
            check: false,
            shadows: false,
            far_field: None,
            pbr: false,
            clustered_radiance: false,
            shapes: false,
            time: 0,
            out: String::new(),
        }
    }
}

impl Options {
    pub fn from_args(out: &str) -> Result<Self, Box<dyn Error>> {
        let mut options = Options {
            out: out.into(),
            ..Options::default()
        };
        let mut args = std::env::args().skip(1);
        while let Some(arg) = args.next() {
            let mut value = || args.next().ok_or(format!("{arg} needs a value"));
            match arg.as_str() {
                "--check" => options.check = true,
                "--shadows" => options.shadows = true,
                "--lights" => options.lights = value()?.parse()?,
                "--far-field" => options.far_field = Some(value()?.parse()?),
                "--brdf" => match value()?.as_str() {
                    "pbr" => options.pbr = true,
                    "lambert" => options.pbr = false,
                    "clustered-radiance" => options.clustered_radiance = true,
                    other => {
                        let choices = "lambert|pbr|clustered-radiance";
                        return Err(format!("--brdf {choices}, not {other}").into());
                    }
                },
                "--shapes" => options.shapes = true,
                "--time" => options.time = value()?.parse()?,
                "--out" => options.out = value()?,
                "--scene" => options.scene = Some(value()?),
                "--camera" => {
                    let numbers: Vec<f32> = (value()?.split(','))
                        .map(str::parse)
                        .collect::<Result<_, _>>()?;
                    let [ex, ey, ez, tx, ty, tz, fov] = numbers[..] else {
                        return Err("--camera EX,EY,EZ,TX,TY,TZ,FOV_DEGREES".into());
                    };
                    options.camera = Some(Look {
                        eye: Vec3::new(ex, ey, ez),
                        target: Vec3::new(tx, ty, tz),
                        fov_y: fov.to_radians(),
                    });
                }
                "--size" => {
                    let size = value()?;
                    let (w, h) = size.split_once('x').ok_or("--size WxH")?;
                    options.size = (w.parse()?, h.parse()?);
                }
                other => return Err(format!("unknown argument {other}").into()),
            }
        }
        if options.pbr && options.far_field.is_some() {
            return Err(
                "--brdf pbr lights no far field: its aggregates take the engine's Lambert".into(),
            );
        }
        if options.shapes && (!options.clustered_radiance || options.check) {
            return Err("--shapes needs --brdf clustered-radiance and no --check: the engine's own loop shades points".into());
        }
        if options.clustered_radiance && options.shadows {
            return Err(
                "--brdf clustered-radiance has no shadows: the engine's own loop traces them"
                    .into(),
            );
        }
        Ok(options)
    }

    /// Whether the engine's loop shades with our BRDF: `--brdf pbr`, and the frame from
    /// every light that `--brdf clustered-radiance` is checked against.
    pub fn our_brdf(&self) -> bool {
        self.pbr || self.clustered_radiance
    }
}

/// The engine's device, made by the engine with what the library needs merged into its
/// descriptor, then lent to the library.
pub fn device(needs: &DeviceRequirements) -> Result<GpuContext, Box<dyn Error>> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let mut descriptor = wgpu::DeviceDescriptor::default();
    needs.merge_into(&mut descriptor, &adapter);
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))?;
    Ok(GpuContext::from_device(
        instance, adapter, device, queue, needs,
    )?)
}

/// Where a camera is, what it looks at, and its vertical field of view in radians.
#[derive(Debug, Clone, Copy)]
pub struct Look {
    pub eye: Vec3,
    pub target: Vec3,
    pub fov_y: f32,
}

/// The engine's view of its floor and boxes.
pub const ENGINE_VIEW: Look = Look {
    eye: Vec3::new(0.0, 7.0, 13.0),
    target: Vec3::new(0.0, 0.0, 1.0),
    fov_y: 0.9,
};

/// manylights' `reference` camera of Sponza (`manylights render --camera reference`).
pub const SPONZA_REFERENCE_VIEW: Look = Look {
    eye: Vec3::new(-7.0, 2.0, 0.0),
    target: Vec3::new(10.0, 2.0, 0.0),
    fov_y: std::f32::consts::PI / 4.0,
};

/// The engine's camera: right-handed, reverse-Z with an infinite far plane, near 0.1 m.
pub fn camera(size: (u32, u32), look: Look) -> (Mat4, Mat4) {
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(look.eye, look.target, Vec3::Y);
    let aspect = size.0 as f32 / size.1 as f32;
    let projection = rh::proj::directx::perspective_infinite_reverse(look.fov_y, aspect, 0.1);
    (view, projection)
}

/// What the engine draws: its triangles, its lights and its camera's matrices.
#[derive(Debug)]
pub struct World {
    pub scene: Scene,
    pub lights: Vec<Light>,
    pub view: Mat4,
    pub projection: Mat4,
}

/// The engine's floor, boxes and lights, or (`--scene`) a file's triangles and the lab's
/// lights for it.
pub fn world(options: &Options) -> Result<World, Box<dyn Error>> {
    let (scene, lights, look) = match &options.scene {
        None => (scene(), lights(options.lights), ENGINE_VIEW),
        Some(path) => {
            let scene = scene_file(path)?;
            let lights = lab_lights(path, &scene, options.lights)?;
            let look = match is_sponza(path) {
                true => SPONZA_REFERENCE_VIEW,
                false => framing(&scene),
            };
            (scene, lights, look)
        }
    };
    let (view, projection) = camera(options.size, options.camera.unwrap_or(look));
    Ok(World {
        scene,
        lights: match options.shapes {
            true => of_every_shape(lights),
            false => lights,
        },
        view,
        projection,
    })
}

/// The engine's triangles, as (position, normal) vertices and triangle indices, and the
/// box they lie in.
#[derive(Debug)]
pub struct Scene {
    pub vertices: Vec<[f32; 6]>,
    pub indices: Vec<u32>,
    pub bounds: (Vec3, Vec3),
}

impl Scene {
    /// The vertices' positions.
    pub fn positions(&self) -> Vec<Vec3> {
        self.vertices
            .iter()
            .map(|v| Vec3::new(v[0], v[1], v[2]))
            .collect()
    }

    /// The vertices' normals.
    pub fn normals(&self) -> Vec<Vec3> {
        self.vertices
            .iter()
            .map(|v| Vec3::new(v[3], v[4], v[5]))
            .collect()
    }
}

/// The engine's own scene: a 20 x 20 m floor and a 5 x 5 grid of 1 m boxes.
pub fn scene() -> Scene {
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
    Scene {
        vertices,
        indices,
        bounds: (Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 2.0, 10.0)),
    }
}

/// A scene file's triangles, read with `manylights-scene`, every instance moved into the
/// world. All of them are drawn opaque, from the front (manylights' renderer cuts alpha-masked
/// texels out, and draws double-sided materials from both sides).
pub fn scene_file(path: &str) -> Result<Scene, Box<dyn Error>> {
    let file = manylights_scene::load(path)?;
    let (mut vertices, mut indices) = (Vec::new(), Vec::new());
    for instance in &file.instances {
        let mesh = &file.meshes[instance.mesh];
        let normals_to_world = glam::Mat3::from_mat4(instance.transform)
            .inverse()
            .transpose();
        let first = vertices.len() as u32;
        for (position, normal) in mesh.positions.iter().zip(&mesh.normals) {
            let p = instance.transform.transform_point3(*position);
            let n = (normals_to_world * *normal).normalize_or_zero();
            vertices.push([p.x, p.y, p.z, n.x, n.y, n.z]);
        }
        indices.extend(mesh.indices.iter().map(|index| first + index));
    }
    let bounds = file.bounds();
    Ok(Scene {
        vertices,
        indices,
        bounds: (bounds.min, bounds.max),
    })
}

/// Whether a scene file is Sponza (the lab's light box and cameras are Sponza's).
fn is_sponza(path: &str) -> bool {
    std::path::Path::new(path).file_stem() == Some("sponza".as_ref())
}

/// A camera that sees the whole of `scene`, from above its front: its bounding sphere fits
/// the vertical field of view of [`ENGINE_VIEW`].
fn framing(scene: &Scene) -> Look {
    let (low, high) = scene.bounds;
    let (centre, radius) = ((low + high) * 0.5, (high - low).length() * 0.5);
    let distance = radius / (ENGINE_VIEW.fov_y * 0.5).sin();
    Look {
        eye: centre + Vec3::new(0.0, 0.5, 1.0).normalize() * distance,
        target: centre,
        ..ENGINE_VIEW
    }
}

/// The lights `manylights render --scene FILE --lights N` puts in a file at time 0: its
/// generator with the lab's defaults (seed 1, intensity 0.2, radius 2 m from the luminance
/// threshold 0.05, random hues), in Sponza's light box for a file named `sponza`, inside
/// the bounds for any other.
pub fn lab_lights(path: &str, scene: &Scene, count: u32) -> Result<Vec<Light>, Box<dyn Error>> {
    use manylights_lights as lights;
    let light_box = match is_sponza(path) {
        true => lights::SPONZA_LIGHT_BOX,
        false => lights::interior_box(&manylights_scene::Aabb::new(scene.bounds.0, scene.bounds.1)),
    };
    let settings = lights::LightSettings {
        count,
        seed: 1,
        intensity: 0.2,
        radius: lights::RadiusMode::LuminanceThreshold(0.05),
        saturation: lights::DEFAULT_SATURATION,
        animation: lights::AnimationParams::in_box(light_box),
        spots: Default::default(),
        shape: lights::LightShape::Point,
    };
    Ok(lights::LightSet::generate(&settings)?.lights)
}

/// The engine's lights: `count` points 0.1-2 m above the floor in random saturated
/// colours, as bright together and reaching as many of each other at any count: at
/// 10,000, radius 1.5 m and intensity 0.06; the radius falls with the cube root of the
/// count, the intensity with the count (a million lights: 0.32 m, 0.0006).
pub fn lights(count: u32) -> Vec<Light> {
    let density = 10_000.0 / count.max(1) as f32;
    let (radius, intensity) = (1.5 * density.cbrt(), 0.06 * density);
    let mut state = 0x9e37_79b9u32;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    (0..count)
        .map(|_| {
            let (x, y, z) = (random(), random(), random());
            let position = Vec3::new(x * 20.0 - 10.0, 0.1 + y * 1.9, z * 20.0 - 10.0);
            let hue = Vec3::new(random(), random(), random()).powf(3.0);
            Light::point(position, radius, hue / hue.max_element(), intensity)
        })
        .collect()
}

/// `lights` made every shape in turn (point, spot, sphere, rectangle, triangle), each of
/// the light's colour, power and reach: the spots point down, the areas are 20 cm across
/// and the flat ones face down.
pub fn of_every_shape(lights: Vec<Light>) -> Vec<Light> {
    let (across, along) = (Vec3::X * 0.1, Vec3::Z * 0.1);
    let cone = manylights_lights::SpotCone {
        inner: 0.5,
        outer: 0.9,
    };
    (lights.into_iter().enumerate())
        .map(|(i, light)| {
            let (at, color) = (Vec3::from(light.position), Vec3::from(light.color));
            let (radius, intensity) = (light.radius, light.intensity);
            match i % 5 {
                0 => light,
                1 => Light::spot(at, radius, color, intensity, Vec3::NEG_Y, cone),
                2 => Light::sphere(at, radius, color, intensity, 0.1),
                3 => Light::rect(at, radius, color, intensity, (across, along)),
                _ => {
                    // Counter-clockwise seen from below; the intensity along its normal.
                    let corners = [at - across, at + across, at + along];
                    let triangle = Light::triangle(corners, radius, color, 1.0);
                    Light {
                        intensity,
                        ..triangle
                    }
                }
            }
        })
        .collect()
}

/// The engine's GPU side of the scene: its buffers, its camera's group (0), its depth and
/// colour targets, and its pipelines' common state.
#[derive(Debug)]
pub struct Renderer {
    pub size: (u32, u32),
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    pub camera_layout: wgpu::BindGroupLayout,
    pub camera_group: wgpu::BindGroup,
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
}

impl Renderer {
    pub fn new(device: &wgpu::Device, size: (u32, u32), world: &World) -> Self {
        let (view, projection) = (world.view, world.projection);
        let light_count = world.lights.len() as u32;
        #[repr(C)]
        #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        struct CameraBlock {
            view_proj: [[f32; 4]; 4],
            view: [[f32; 4]; 4],
            inverse_view_proj: [[f32; 4]; 4],
            eye: [f32; 4],
            light_count: [u32; 4],
        }
        let block = CameraBlock {
            view_proj: (projection * view).to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            inverse_view_proj: (projection * view).inverse().to_cols_array_2d(),
            eye: view.inverse().w_axis.to_array(),
            light_count: [light_count, 0, 0, 0],
        };
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let uniform = wgpu::BufferUsages::UNIFORM;
        let camera_buffer = buffer("camera", bytemuck::bytes_of(&block), uniform);
        let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::all(),
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
        let scene = &world.scene;
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let depth = texture(
            device,
            size,
            DEPTH_FORMAT,
            attachment | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let color = texture(
            device,
            size,
            COLOR_FORMAT,
            attachment | wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        Self {
            size,
            vertices: buffer(
                "vertices",
                bytemuck::cast_slice(&scene.vertices),
                wgpu::BufferUsages::VERTEX,
            ),
            indices: buffer(
                "indices",
                bytemuck::cast_slice(&scene.indices),
                wgpu::BufferUsages::INDEX,
            ),
            index_count: scene.indices.len() as u32,
            camera_layout,
            camera_group,
            depth_view: depth.create_view(&Default::default()),
            depth,
            color_view: color.create_view(&Default::default()),
            color,
        }
    }

    /// A pipeline of the engine's vertex format drawing into its depth (reverse-Z: nearer is
    /// greater) as `depth` says and, with a `fragment` entry of `module`, into `targets`.
    pub fn pipeline(
        &self,
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        fragment: Option<&str>,
        groups: &[Option<&wgpu::BindGroupLayout>],
        targets: &[Option<wgpu::ColorTargetState>],
        depth: DepthTest,
    ) -> wgpu::RenderPipeline {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: groups,
            immediate_size: 0,
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: fragment,
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
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
                depth_write_enabled: Some(depth.writes),
                depth_compare: Some(depth.compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: fragment.map(|entry| wgpu::FragmentState {
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// Draws the scene with `pipeline` in a render pass into `colors` (cleared) and the
    /// depth (cleared to the far value 0, or kept), with the camera at group 0 and `groups`
    /// after it.
    pub fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        colors: &[&wgpu::TextureView],
        clear_depth: bool,
        groups: &[(u32, &wgpu::BindGroup)],
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) {
        let color_attachments: Vec<_> = colors
            .iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let load = if clear_depth {
            wgpu::LoadOp::Clear(0.0)
        } else {
            wgpu::LoadOp::Load
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &color_attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes,
            ..Default::default()
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.camera_group, &[]);
        for (index, group) in groups {
            pass.set_bind_group(*index, *group, &[]);
        }
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.index_count, 0, 0..1);
    }
}

/// The engine's shader module, from its parts' WGSL in order.
pub fn shader(device: &wgpu::Device, label: &str, parts: &[&str]) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(parts.join("\n").into()),
    })
}

/// A compute pipeline of `module`'s `entry` over these groups' layouts.
pub fn compute_pipeline(
    device: &wgpu::Device,
    groups: &[Option<&wgpu::BindGroupLayout>],
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(entry),
        bind_group_layouts: groups,
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(&layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A 2D texture's layout entry: sampled of `sample_type`, or (`None`) a write-only
/// storage texture of the engine's colour format.
pub fn texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    sample_type: Option<wgpu::TextureSampleType>,
) -> wgpu::BindGroupLayoutEntry {
    let view_dimension = wgpu::TextureViewDimension::D2;
    let ty = match sample_type {
        Some(sample_type) => wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        None => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: COLOR_FORMAT,
            view_dimension,
        },
    };
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    }
}

/// A bind group's layout and the group, from its entries' layouts and resources.
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    entries: &[(wgpu::BindGroupLayoutEntry, wgpu::BindingResource)],
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries.iter().map(|(entry, _)| *entry).collect::<Vec<_>>(),
    });
    let entries: Vec<_> = (entries.iter())
        .map(|(entry, resource)| wgpu::BindGroupEntry {
            binding: entry.binding,
            resource: resource.clone(),
        })
        .collect();
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &layout,
        entries: &entries,
    });
    (layout, group)
}

/// A 2D texture of the engine's.
pub fn texture(
    device: &wgpu::Device,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: None,
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
}

/// An example's frames, HDR radiance row by row: through the lists, and (with `--check`)
/// from every light.
#[derive(Debug)]
pub struct Frames {
    pub listed: Vec<[f32; 4]>,
    pub every_light: Option<Vec<[f32; 4]>>,
    /// GPU milliseconds per pass (with `--time`), in the order the frame runs them.
    pub timings: Vec<(String, f64)>,
}

/// Channels of `a` and `b` that differ by more than `ulps` f32 ulps of the larger.
pub fn differing_channels(a: &[[f32; 4]], b: &[[f32; 4]], ulps: f32) -> usize {
    let tolerance = ulps * f32::EPSILON;
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .filter(|(x, y)| {
            let larger = x.abs().max(y.abs()).max(f32::MIN_POSITIVE);
            (*x - *y).abs() > tolerance * larger
        })
        .count()
}

/// How far a frame through the lists may be from the frame from every light, in f32 ulps
/// of a channel. Without a far field both sum the same nonzero terms in the same order (a
/// light its cluster does not list adds exactly zero there): 64 ulps allow for the
/// compilers' contractions of two pipelines. With an exact far field (tolerance 0) each
/// light's term is split into its windowed part (the lists) and its complement (the cut),
/// and the terms, all positive, are summed in another order: each of the `lights` terms
/// moves the sum by at most an ulp of it, plus the split's few roundings.
pub fn allowed_ulps(options: &Options) -> Option<f32> {
    match options.far_field {
        None => Some(64.0),
        Some(0.0) => Some(options.lights as f32 + 64.0),
        // An approximation: reported, not compared.
        Some(_) => None,
    }
}

/// The mean of |a - b| over the mean of b, over every channel.
pub fn mean_relative_error(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let (mut error, mut total) = (0.0, 0.0);
    for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
        error += f64::from((x - y).abs());
        total += f64::from(y.abs());
    }
    error / total.max(f64::MIN_POSITIVE)
}

/// GPU milliseconds per pass (timestamp queries) of `frames` frames drawn by `frame`: the
/// mean of the second half, after the first half has warmed the GPU's clock up, in the
/// order the frame runs its passes.
pub fn time_passes(
    context: &GpuContext,
    frames: u32,
    mut frame: impl FnMut(&mut GpuTimer) -> Result<(), Box<dyn Error>>,
) -> Result<Vec<(String, f64)>, Box<dyn Error>> {
    let mut timer = GpuTimer::new(context);
    let mut sums: Vec<(String, f64)> = Vec::new();
    for number in 0..frames {
        frame(&mut timer)?;
        let GpuTimings::Measured(passes) = timer.wait_latest(context)? else {
            return Err("the adapter has no timestamp queries".into());
        };
        if number < frames / 2 {
            continue;
        }
        for pass in passes {
            match sums.iter_mut().find(|(name, _)| name == pass.name.as_str()) {
                Some((_, sum)) => *sum += pass.milliseconds,
                None => sums.push((pass.name.as_str().to_string(), pass.milliseconds)),
            }
        }
    }
    let timed = f64::from((frames - frames / 2).max(1));
    Ok(sums
        .into_iter()
        .map(|(name, sum)| (name, sum / timed))
        .collect())
}

/// Pixels with any light.
pub fn lit_pixels(frame: &[[f32; 4]]) -> usize {
    frame.iter().filter(|p| p[0] + p[1] + p[2] > 0.0).count()
}

/// What an example's `main` ends with: the frame's numbers, its comparison with every
/// light's (an error where they differ) and the PNG (Reinhard, then sRGB's 2.2 gamma).
pub fn report(options: &Options, frames: &Frames) -> Result<(), Box<dyn Error>> {
    let (frame, every_light) = (&frames.listed, frames.every_light.as_deref());
    let (width, height) = options.size;
    println!(
        "{} lights, {width}x{height}: {} of {} pixels lit",
        options.lights,
        lit_pixels(frame),
        frame.len()
    );
    if let Some(every_light) = every_light {
        let error = mean_relative_error(frame, every_light);
        println!("against every light: mean relative error {error:.2e}");
        if let Some(ulps) = allowed_ulps(options) {
            let differing = differing_channels(frame, every_light, ulps);
            println!("{differing} channels differ by more than {ulps} ulps");
            if differing > 0 {
                return Err("the lists left out light that reaches a pixel".into());
            }
        }
    }
    for (pass, milliseconds) in &frames.timings {
        println!("{pass:<32} {milliseconds:8.3} ms");
    }
    if !frames.timings.is_empty() {
        let total: f64 = frames.timings.iter().map(|(_, ms)| ms).sum();
        println!("{:<32} {total:8.3} ms", "in all");
    }
    let image = image::RgbaImage::from_fn(width, height, |x, y| {
        let p = frame[(y * width + x) as usize];
        let map = |c: f32| ((c / (1.0 + c)).powf(1.0 / 2.2) * 255.0).round() as u8;
        image::Rgba([map(p[0]), map(p[1]), map(p[2]), 255])
    });
    image.save(&options.out)?;
    println!("wrote {}", options.out);
    Ok(())
}
