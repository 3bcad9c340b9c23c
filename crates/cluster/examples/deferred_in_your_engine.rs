//! Deferred shading in someone else's renderer: the engine of `engine/mod.rs` lays down its
//! own G-buffer (its layout: a normal target and its reverse-Z depth), manylights lists the
//! lights of what that depth shows, and the engine's own compute lighting pass walks the
//! lists from each pixel's position rebuilt from depth. The library's types are the Forward+
//! example's five: `GpuContext`, `ViewUniform`/`ViewBinding`, `GpuLights`, `GpuClusters`
//! and `ListedLights` (here bound in a compute pass).
//!
//! ```sh
//! cargo run --release -p manylights-cluster --example deferred_in_your_engine -- --check
//! ```
//! `--check` also lights the G-buffer from every light and compares the two pixel by pixel;
//! `--brdf pbr` runs our BRDF (`manylights_lights::pbr_wgsl`) in the engine's loop instead
//! of its Lambert, its one table (`SpecularTables`) bound in the engine's G-buffer group.

pub mod engine;

use std::error::Error;

use engine::{Frames, Options};
use manylights_cluster::{
    ClusterFrame, ClusterGrid, ClusterSettings, GpuClusters, ListedLights, VisibleDepth,
};
use manylights_gpu::wgpu;
use manylights_gpu::{
    DeviceRequirements, GpuTimer, PassName, ShaderLibrary, ViewBinding, ViewUniform,
};
use manylights_lights::{GpuLights, SpecularTables};

/// The engine's bind groups: its camera (0), the lists (1), its G-buffer (2).
const LISTS_GROUP: u32 = 1;
const GBUFFER_GROUP: u32 = 2;
const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The engine's own passes, as `--time` names them beside the library's.
const GBUFFER_PASS: PassName = PassName::new("engine: g-buffer");
const LIGHTING_PASS: PassName = PassName::new("engine: compute lighting");

/// The engine's G-buffer pass and its compute lighting, through the lists or from every
/// light.
const DEFERRED_WGSL: &str = r#"
@fragment
fn fs_gbuffer(in: Varyings) -> @location(0) vec4<f32> {
    return vec4<f32>(normalize(in.normal), 1.0);
}

@group(2) @binding(0) var gbuffer_normals: texture_2d<f32>;
@group(2) @binding(1) var gbuffer_depth: texture_depth_2d;
@group(2) @binding(2) var lit: texture_storage_2d<rgba32float, write>;

struct Pixel { world: vec3<f32>, normal: vec3<f32>, covered: bool }

// The pixel's surface, its position rebuilt from reverse-Z depth (0: nothing drawn).
fn pixel_surface(at: vec2<u32>) -> Pixel {
    let depth = textureLoad(gbuffer_depth, at, 0);
    let uv = (vec2<f32>(at) + 0.5) / vec2<f32>(textureDimensions(gbuffer_depth));
    let clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let world = camera.inverse_view_proj * clip;
    let normal = normalize(textureLoad(gbuffer_normals, at, 0).xyz);
    return Pixel(world.xyz / world.w, normal, depth > 0.0);
}

fn shade(light: manylights_Light, surface: Surface) -> vec3<f32> {
    let to_light = light.position - surface.world;
    let falloff = manylights_windowed_falloff(dot(to_light, to_light), light.radius);
    return light.color * light.intensity * falloff * reflected(surface, light.position);
}

@compute @workgroup_size(8, 8)
fn cs_listed(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(lit)) {
        return;
    }
    let pixel = pixel_surface(id.xy);
    var radiance = vec3<f32>(0.0);
    if pixel.covered {
        let surface = surface_of(pixel.world, pixel.normal);
        let list = manylights_lights_at(vec2<f32>(id.xy) + 0.5, view_depth(pixel.world));
        for (var i = 0u; i < list.candidates; i++) {
            let index = manylights_listed_light(list, i);
            if index != manylights_NOT_LISTED {
                radiance += shade(manylights_lights[index], surface);
            }
        }
    }
    textureStore(lit, id.xy, vec4<f32>(radiance, 1.0));
}

@compute @workgroup_size(8, 8)
fn cs_every_light(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(lit)) {
        return;
    }
    let pixel = pixel_surface(id.xy);
    var radiance = vec3<f32>(0.0);
    if pixel.covered {
        let surface = surface_of(pixel.world, pixel.normal);
        for (var i = 0u; i < camera.light_count.x; i++) {
            radiance += shade(manylights_lights[i], surface);
        }
    }
    textureStore(lit, id.xy, vec4<f32>(radiance, 1.0));
}
"#;

/// The lit frame, through the lists and (with `--check`) from every light.
pub fn render(options: &Options) -> Result<Frames, Box<dyn Error>> {
    let context = engine::device(&DeviceRequirements::minimum())?;
    let device = &context.device;
    let world = engine::world(options)?;
    let renderer = engine::Renderer::new(device, options.size, &world);
    let normals = engine::texture(
        device,
        options.size,
        NORMAL_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let normals_view = normals.create_view(&Default::default());

    // The library, as in the Forward+ example.
    let library = ShaderLibrary::from_env();
    let camera = ViewUniform::from_matrices(world.view, world.projection, options.size)?;
    let view_binding = ViewBinding::new(&context);
    view_binding.update(&context, &camera);
    let gpu_lights = GpuLights::new(&context, &world.lights)?;
    // An infinite far plane: the slices cover the depth the engine's scene occupies.
    let (low, high) = world.scene.bounds;
    let scene = manylights_scene::Aabb::new(low, high);
    let grid = ClusterGrid::for_view(&ClusterSettings::default(), &camera, Some(scene))?;
    let mut clusters = GpuClusters::new(&context, &library, &view_binding)?;
    let listed = ListedLights::new(&context, LISTS_GROUP);

    // The engine's G-buffer pipeline and its compute lighting, on its own layouts, with
    // its BRDF or ours (`--brdf pbr`: its one table in the engine's G-buffer group).
    let (brdf, brdf_hooks) = match options.pbr {
        true => (
            manylights_lights::pbr_wgsl(&library, GBUFFER_GROUP)?,
            engine::OUR_BRDF_WGSL,
        ),
        false => (String::new(), engine::LAMBERT_WGSL),
    };
    let lists = listed.wgsl(&library)?;
    let parts = [
        &lists,
        &brdf,
        engine::ENGINE_WGSL,
        brdf_hooks,
        DEFERRED_WGSL,
    ];
    let module = engine::shader(device, "engine deferred shader", &parts);
    let compute = wgpu::ShaderStages::COMPUTE;
    let texture = |binding, sample_type| engine::texture_entry(binding, compute, sample_type);
    let view = wgpu::BindingResource::TextureView;
    let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
    let mut gbuffer_entries = vec![
        (texture(0, Some(unfilterable)), view(&normals_view)),
        (
            texture(1, Some(wgpu::TextureSampleType::Depth)),
            view(&renderer.depth_view),
        ),
        (texture(2, None), view(&renderer.color_view)),
    ];
    let tables = SpecularTables::new(&context)?;
    if options.pbr {
        gbuffer_entries.push((SpecularTables::layout_entry(compute), tables.binding().1));
    }
    let (gbuffer_layout, gbuffer_group) = engine::bind_group(device, "g-buffer", &gbuffer_entries);
    let gbuffer_pass = renderer.pipeline(
        device,
        &module,
        Some("fs_gbuffer"),
        &[Some(&renderer.camera_layout)],
        &[Some(NORMAL_FORMAT.into())],
        engine::DepthTest::LAYS_DOWN,
    );
    let groups = [
        Some(&renderer.camera_layout),
        Some(listed.layout()),
        Some(&gbuffer_layout),
    ];
    let lighting = |entry| engine::compute_pipeline(device, &groups, &module, entry);
    let (light_listed, light_every) = (lighting("cs_listed"), lighting("cs_every_light"));

    // A frame: the G-buffer, the lists of what its depth shows, the lighting; timed per
    // pass with `timer`, read back with `read_back`.
    let mut frame = |lighting: &wgpu::ComputePipeline,
                     mut timer: Option<&mut GpuTimer>,
                     read_back: bool|
     -> Result<Option<Vec<[f32; 4]>>, Box<dyn Error>> {
        loop {
            let depth = VisibleDepth::of(&renderer.depth, &renderer.depth_view);
            clusters.prepare(&context, &ClusterFrame::new(grid), &gpu_lights, Some(depth))?;
            let lists = listed.bind_group(&context, &clusters, &gpu_lights)?;
            let mut encoder = device.create_command_encoder(&Default::default());
            if let Some(timer) = timer.as_deref_mut() {
                timer.begin_frame();
            }
            let gbuffer_times = timer
                .as_deref_mut()
                .and_then(|t| t.render_pass(GBUFFER_PASS));
            let normals = [&normals_view];
            renderer.draw(
                &mut encoder,
                &gbuffer_pass,
                &normals,
                true,
                &[],
                gbuffer_times,
            );
            let _built =
                (clusters.assignment()?).record(&mut encoder, &view_binding, timer.as_deref_mut());
            {
                let timestamp_writes = timer
                    .as_deref_mut()
                    .and_then(|t| t.compute_pass(LIGHTING_PASS));
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("engine lighting"),
                    timestamp_writes,
                });
                pass.set_pipeline(lighting);
                pass.set_bind_group(0, &renderer.camera_group, &[]);
                pass.set_bind_group(LISTS_GROUP, &lists, &[]);
                pass.set_bind_group(GBUFFER_GROUP, &gbuffer_group, &[]);
                pass.dispatch_workgroups(options.size.0.div_ceil(8), options.size.1.div_ceil(8), 1);
            }
            if let Some(timer) = timer.as_deref_mut() {
                timer.resolve(&mut encoder);
            }
            context.queue.submit([encoder.finish()]);
            clusters.after_submit();
            if let Some(timer) = timer.as_deref_mut() {
                timer.after_submit();
            }
            if clusters.wait_and_grow(&context)?.is_none() {
                let color = &renderer.color;
                return Ok(read_back
                    .then(|| manylights_gpu::targets::read_f32_rgba(&context, color))
                    .transpose()?);
            }
        }
    };
    let listed_frame = frame(&light_listed, None, true)?.unwrap_or_default();
    let every_light = match options.check {
        true => frame(&light_every, None, true)?,
        false => None,
    };
    let timings = engine::time_passes(&context, options.time, |timer| {
        frame(&light_listed, Some(timer), false).map(drop)
    })?;
    Ok(Frames {
        listed: listed_frame,
        every_light,
        timings,
    })
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn Error>> {
    let options = Options::from_args("deferred_in_your_engine.png")?;
    if options.shadows || options.far_field.is_some() || options.clustered_radiance {
        let flags = "--shadows, --far-field and --brdf clustered-radiance";
        return Err(format!("{flags} are the Forward+ example's").into());
    }
    let frames = render(&options)?;
    engine::report(&options, &frames)
}
