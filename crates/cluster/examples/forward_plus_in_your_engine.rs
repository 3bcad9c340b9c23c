//! Forward+ in someone else's renderer: a wgpu program with its own device, camera (a
//! reverse-Z, infinite-far projection), vertex format, depth pre-pass, render pipeline and
//! fragment shader (`engine/mod.rs`, which knows nothing of manylights) shades 10,000
//! lights of its own through manylights' cluster lists, its own BRDF inside the lists'
//! loop. Five of the library's types do it: `GpuContext` (over the engine's device),
//! `ViewUniform`/`ViewBinding` (the camera as the assignment reads it, from the engine's
//! matrices), `GpuLights` (the engine's lights), `GpuClusters` (the lists, bounded by the
//! engine's depth) and `ListedLights` (the WGSL and bind group the engine's shader uses).
//!
//! ```sh
//! cargo run --release -p manylights-cluster --example forward_plus_in_your_engine -- \
//!     --size 1280x720 --lights 10000 --check --out engine.png
//! ```
//! `--check` also draws the frame from every light (no lists) and compares the two pixel by
//! pixel: the lists must leave out nothing that reaches a pixel. `--shadows` adds shadow
//! rays through the BVH of the engine's triangles, `--far-field 1` what the lights add
//! beyond their radius, `--brdf pbr` our BRDF in the loop (its table in a group of the
//! engine's), `--brdf clustered-radiance` our loop and BRDF in one call
//! (`ListedLights::clustered_radiance_wgsl`; `--shapes` gives it lights of every shape), `--scene FILE` a glTF or OBJ file with our lab's lights (to time the library
//! here against our renderer on the same frame), `--time N` the GPU time per pass.

pub mod engine;

use std::error::Error;

use engine::{Frames, Options};
use manylights_cluster::{
    ClusterFrame, ClusterGrid, ClusterSettings, FarField, FarFieldMethod, GpuClusters,
    ListedLights, VisibleDepth,
};
use manylights_gpu::wgpu;
use manylights_gpu::{
    DeviceRequirements, GpuTimer, PassName, ShaderLibrary, ViewBinding, ViewUniform,
};
use manylights_lights::{GpuLights, SpecularTables};
use manylights_visibility::{GpuSceneBvh, SceneBvh, ShadowQueries};

/// The engine's bind group indices for the lists, the shadow queries (`--shadows`) and our
/// BRDF's table (`--brdf pbr`); its camera is at 0.
const LISTS_GROUP: u32 = 1;
const SHADOWS_GROUP: u32 = 2;
const BRDF_GROUP: u32 = 3;

/// The engine's own passes, as `--time` names them beside the library's.
const DEPTH_PRE_PASS: PassName = PassName::new("engine: depth pre-pass");
const SHADING_PASS: PassName = PassName::new("engine: shading");

/// How the engine's shader keeps a light's radiance: as it is, or (`--shadows`) where a
/// shadow ray through the scene's BVH reaches the light.
const UNSHADOWED_WGSL: &str = "fn visible(radiance: vec3<f32>, world: vec3<f32>, normal: vec3<f32>, light: vec3<f32>) -> vec3<f32> { return radiance; }";
const SHADOWED_WGSL: &str = "fn visible(radiance: vec3<f32>, world: vec3<f32>, normal: vec3<f32>, light: vec3<f32>) -> vec3<f32> { return manylights_shadows_unless_shadowed(radiance, world, normal, 0.0, light); }";

/// Without a far field a light ends at its radius; the engine's frame from every light
/// then uses the falloff the lists are made for.
const NO_FAR_FIELD_WGSL: &str = r#"
fn far_radiance(cluster: u32, surface: Surface) -> vec3<f32> {
    return vec3<f32>(0.0);
}
fn every_light_falloff(distance_squared: f32, radius: f32) -> f32 {
    return manylights_windowed_falloff(distance_squared, radius);
}
"#;

/// With the far field (`--far-field`), what the lights add beyond their radius: the
/// cluster's cut of the light tree, the engine's BRDF on each aggregate's term and on
/// each light of an exact entry. Windowed plus far is the plain inverse square, which the
/// frame from every light then uses.
const FAR_FIELD_WGSL: &str = r#"
fn far_radiance(cluster: u32, surface: Surface) -> vec3<f32> {
    let world = surface.world;
    let normal = surface.normal;
    var radiance = vec3<f32>(0.0);
    let cut = manylights_far_cut(cluster);
    for (var k = 0u; k < cut.entries; k++) {
        let entry = manylights_far_entry(cut, k);
        if entry.aggregate {
            let term = manylights_aggregate_term(entry.node, entry.node.centroid - world, normal);
            radiance += visible(term.incoming * (0.8 / 3.14159265), world, normal, entry.node.centroid);
            continue;
        }
        for (var i = entry.node.first; i < entry.node.first + entry.node.count; i++) {
            let light = manylights_lights[manylights_far_light(i)];
            let to_light = light.position - world;
            radiance += shade(light, manylights_far_falloff(dot(to_light, to_light), light.radius), surface);
        }
    }
    return radiance;
}
fn every_light_falloff(distance_squared: f32, radius: f32) -> f32 {
    return 1.0 / max(distance_squared, 1e-4);
}
"#;

/// The engine's fragment shader with our loop and BRDF in one call (`--brdf
/// clustered-radiance`): a grey dielectric of roughness 0.5, as `OUR_BRDF_WGSL`'s.
const CLUSTERED_RADIANCE_WGSL: &str = r#"
@fragment
fn fs_clustered_radiance(in: Varyings) -> @location(0) vec4<f32> {
    let normal = normalize(in.normal);
    let view_dir = normalize(camera.eye.xyz - in.world);
    let radiance = manylights_clustered_radiance(in.clip.xy, view_depth(in.world), in.world, normal, view_dir, vec3<f32>(0.8), 0.0, 0.5);
    return vec4<f32>(radiance, 1.0);
}
"#;

/// The engine's fragment shaders: one walking the lists (and the far field's cut), one
/// every light.
const FRAGMENT_WGSL: &str = r#"
fn shade(light: manylights_Light, falloff: f32, surface: Surface) -> vec3<f32> {
    let radiance = light.color * light.intensity * falloff * reflected(surface, light.position);
    return visible(radiance, surface.world, surface.normal, light.position);
}

@fragment
fn fs_listed(in: Varyings) -> @location(0) vec4<f32> {
    let surface = surface_of(in.world, normalize(in.normal));
    let list = manylights_lights_at(in.clip.xy, view_depth(in.world));
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < list.candidates; i++) {
        let index = manylights_listed_light(list, i);
        if index == manylights_NOT_LISTED {
            continue;
        }
        let light = manylights_lights[index];
        let to_light = light.position - in.world;
        radiance += shade(light, manylights_windowed_falloff(dot(to_light, to_light), light.radius), surface);
    }
    radiance += far_radiance(list.cluster, surface);
    return vec4<f32>(radiance, 1.0);
}

@fragment
fn fs_every_light(in: Varyings) -> @location(0) vec4<f32> {
    let surface = surface_of(in.world, normalize(in.normal));
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < camera.light_count.x; i++) {
        let light = manylights_lights[i];
        let to_light = light.position - in.world;
        radiance += shade(light, every_light_falloff(dot(to_light, to_light), light.radius), surface);
    }
    return vec4<f32>(radiance, 1.0);
}
"#;

pub fn render(options: &Options) -> Result<Frames, Box<dyn Error>> {
    let context = engine::device(&DeviceRequirements::minimum())?;
    let device = &context.device;
    let world = engine::world(options)?;
    let renderer = engine::Renderer::new(device, options.size, &world);

    // The library: the camera from the engine's matrices, its lights, the lists.
    let library = ShaderLibrary::from_env();
    let camera = ViewUniform::from_matrices(world.view, world.projection, options.size)?;
    let view_binding = ViewBinding::new(&context);
    view_binding.update(&context, &camera);
    let gpu_lights = GpuLights::new(&context, &world.lights)?;
    let (low, high) = world.scene.bounds;
    let scene = manylights_scene::Aabb::new(low, high);
    let grid = ClusterGrid::for_view(&ClusterSettings::default(), &camera, Some(scene))?;
    let mut clusters = GpuClusters::new(&context, &library, &view_binding)?;
    let (listed, frame_settings) = match options.far_field {
        None => (
            ListedLights::new(&context, LISTS_GROUP),
            ClusterFrame::new(grid),
        ),
        Some(tolerance) => {
            let tree = FarField {
                tolerance,
                ..FarField::new(FarFieldMethod::Tree)
            };
            let frame = ClusterFrame {
                far_field: Some(tree),
                ..ClusterFrame::new(grid)
            };
            (ListedLights::with_far_field(&context, LISTS_GROUP), frame)
        }
    };

    // Shadows as a service: the BVH of the engine's own triangles, and its queries' WGSL.
    let bvh = SceneBvh::from_triangles(&world.scene.positions(), &world.scene.indices)?;
    let bvh = GpuSceneBvh::new(&context, &bvh)?;
    let shadows = ShadowQueries::new(&context, SHADOWS_GROUP);
    let shadow_group = shadows.bind_group(&context, &bvh)?;

    // The engine's BRDF, or ours (`--brdf pbr`) with its one table in a group of its own.
    let tables = SpecularTables::new(&context)?;
    let table = (
        SpecularTables::layout_entry(wgpu::ShaderStages::FRAGMENT),
        tables.binding().1,
    );
    let (tables_layout, tables_group) = engine::bind_group(device, "our BRDF", &[table]);

    // The engine's pipelines: the library's WGSL before its own, the lists' layout at
    // LISTS_GROUP, the shadow queries' at SHADOWS_GROUP and our BRDF's at BRDF_GROUP.
    let mut source = vec![listed.wgsl(&library)?, engine::ENGINE_WGSL.into()];
    match options.our_brdf() {
        true => source.extend([
            manylights_lights::pbr_wgsl(&library, BRDF_GROUP)?,
            engine::OUR_BRDF_WGSL.into(),
        ]),
        false => source.push(engine::LAMBERT_WGSL.into()),
    }
    match options.shadows {
        true => source.extend([shadows.wgsl(&library)?, SHADOWED_WGSL.into()]),
        false => source.push(UNSHADOWED_WGSL.into()),
    }
    source.push(match options.far_field {
        Some(_) => FAR_FIELD_WGSL.into(),
        None => NO_FAR_FIELD_WGSL.into(),
    });
    source.push(FRAGMENT_WGSL.into());
    let parts: Vec<&str> = source.iter().map(String::as_str).collect();
    let module = engine::shader(device, "engine shader", &parts);
    let camera_only = [Some(&renderer.camera_layout)];
    // Every group in every pipeline (a shader need not read all of its layout's groups).
    let with_lists = [
        Some(&renderer.camera_layout),
        Some(listed.layout()),
        Some(shadows.layout()),
        Some(&tables_layout),
    ];
    let targets = [Some(engine::COLOR_FORMAT.into())];
    let (lays_down, after_depth) = (engine::DepthTest::LAYS_DOWN, engine::DepthTest::AFTER_DEPTH);
    let pre_pass = renderer.pipeline(device, &module, None, &camera_only, &[], lays_down);
    let shading = |entry| {
        renderer.pipeline(
            device,
            &module,
            Some(entry),
            &with_lists,
            &targets,
            after_depth,
        )
    };
    let (mut shade_listed, shade_every_light) = (shading("fs_listed"), shading("fs_every_light"));
    if options.clustered_radiance {
        let parts = [
            &listed.clustered_radiance_wgsl(&library, BRDF_GROUP)?,
            engine::ENGINE_WGSL,
            CLUSTERED_RADIANCE_WGSL,
        ];
        let module = engine::shader(device, "engine shader, our clustered radiance", &parts);
        let entry = Some("fs_clustered_radiance");
        shade_listed =
            renderer.pipeline(device, &module, entry, &with_lists, &targets, after_depth);
    }

    // A frame: the depth pre-pass, the lists of what it left seen, the shading; timed per
    // pass with `timer`, read back with `read_back`.
    let mut frame = |shading: &wgpu::RenderPipeline,
                     mut timer: Option<&mut GpuTimer>,
                     read_back: bool|
     -> Result<Option<Vec<[f32; 4]>>, Box<dyn Error>> {
        loop {
            let depth = VisibleDepth::of(&renderer.depth, &renderer.depth_view);
            clusters.prepare(&context, &frame_settings, &gpu_lights, Some(depth))?;
            let lists = listed.bind_group(&context, &clusters, &gpu_lights)?;
            let mut encoder = device.create_command_encoder(&Default::default());
            if let Some(timer) = timer.as_deref_mut() {
                timer.begin_frame();
            }
            let pre_pass_times = timer
                .as_deref_mut()
                .and_then(|t| t.render_pass(DEPTH_PRE_PASS));
            renderer.draw(&mut encoder, &pre_pass, &[], true, &[], pre_pass_times);
            // Recorded after the pre-pass: only what it left seen is listed.
            let _built =
                (clusters.assignment()?).record(&mut encoder, &view_binding, timer.as_deref_mut());
            let groups = [
                (LISTS_GROUP, &lists),
                (SHADOWS_GROUP, &shadow_group),
                (BRDF_GROUP, &tables_group),
            ];
            let shading_times = timer
                .as_deref_mut()
                .and_then(|t| t.render_pass(SHADING_PASS));
            renderer.draw(
                &mut encoder,
                shading,
                &[&renderer.color_view],
                false,
                &groups,
                shading_times,
            );
            if let Some(timer) = timer.as_deref_mut() {
                timer.resolve(&mut encoder);
            }
            context.queue.submit([encoder.finish()]);
            clusters.after_submit();
            if let Some(timer) = timer.as_deref_mut() {
                timer.after_submit();
            }
            // A list buffer too small for the frame grows; an engine learns it a frame
            // later without waiting (`grow_for_earlier_frames`), this example waits.
            if clusters.wait_and_grow(&context)?.is_none() {
                let color = &renderer.color;
                return Ok(read_back
                    .then(|| manylights_gpu::targets::read_f32_rgba(&context, color))
                    .transpose()?);
            }
        }
    };
    let listed_frame = frame(&shade_listed, None, true)?.unwrap_or_default();
    let every_light = match options.check {
        true => frame(&shade_every_light, None, true)?,
        false => None,
    };
    let timings = engine::time_passes(&context, options.time, |timer| {
        frame(&shade_listed, Some(timer), false).map(drop)
    })?;
    Ok(Frames {
        listed: listed_frame,
        every_light,
        timings,
    })
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn Error>> {
    let options = Options::from_args("forward_plus_in_your_engine.png")?;
    let frames = render(&options)?;
    engine::report(&options, &frames)
}
