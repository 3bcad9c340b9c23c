//! GPU round trip on whatever adapter is present (lavapipe in CI): upload `cornell` and
//! Sponza, draw the unlit base colour into a 128x96 target, read it back, and check it
//! against what the CPU says each pixel must show.

use glam::Vec3;
use manylights_gpu::targets::read_rgba8;
use manylights_gpu::{
    BaseColorPass, GpuContext, GpuScene, OUTPUT_FORMAT, RenderTargets, ShaderLibrary, ViewBinding,
    ViewUniform,
};
use manylights_scene::{Scene, procedural};
use manylights_tests::{TestCamera, cast, gpu, linear_to_srgb8};

const SIZE: (u32, u32) = (128, 96);
/// The clear colour: magenta, which no test scene contains.
const CLEAR: [u8; 4] = [255, 0, 255, 255];

fn render_base_color(context: &GpuContext, scene: &Scene, camera: &TestCamera) -> image::RgbaImage {
    let library = ShaderLibrary::from_env();
    let gpu_scene = GpuScene::upload(context, scene, &library).expect("scene upload");
    let view = ViewBinding::new(context);
    view.update(
        context,
        &ViewUniform::new(
            camera.view(),
            camera.proj(SIZE),
            camera.position,
            SIZE,
            camera.near,
            camera.far,
        ),
    );
    let targets = RenderTargets::new(context, SIZE).expect("targets");
    let pass = BaseColorPass::new(
        context,
        &library,
        &gpu_scene,
        &view,
        OUTPUT_FORMAT,
        manylights_gpu::DepthConvention::Standard,
    )
    .expect("pipelines");
    context
        .scoped("drawing base colour", || {
            let mut encoder = context.device.create_command_encoder(&Default::default());
            let clear = wgpu_color(CLEAR);
            pass.record(
                &mut encoder,
                &gpu_scene,
                &view,
                &manylights_gpu::DrawTarget {
                    color: &targets.output.view,
                    depth: &targets.depth.view,
                    clear,
                },
                None,
            );
            context.queue.submit([encoder.finish()]);
        })
        .expect("no wgpu errors while drawing");
    read_rgba8(context, &targets.output.texture).expect("readback")
}

fn wgpu_color(srgb: [u8; 4]) -> manylights_gpu::wgpu::Color {
    // The output is sRGB: clear values are linear.
    let linear = |c: u8| {
        f64::from(manylights_scene::color::srgb_to_linear(
            f32::from(c) / 255.0,
        ))
    };
    manylights_gpu::wgpu::Color {
        r: linear(srgb[0]),
        g: linear(srgb[1]),
        b: linear(srgb[2]),
        a: 1.0,
    }
}

/// The darkest and lightest texel (per channel) within `radius` (in UV units) plus one
/// texel of `uv`, with the texture repeating.
fn texel_range(
    texture: &manylights_scene::Texture,
    uv: glam::Vec2,
    radius: f32,
) -> ([u8; 3], [u8; 3]) {
    let (w, h) = (texture.width as i64, texture.height as i64);
    let centre = (
        (uv.x * w as f32 - 0.5).floor() as i64,
        (uv.y * h as f32 - 0.5).floor() as i64,
    );
    let reach = (
        (radius * w as f32).ceil() as i64 + 1,
        (radius * h as f32).ceil() as i64 + 1,
    );
    let (mut lo, mut hi) = ([255u8; 3], [0u8; 3]);
    for ty in centre.1 - reach.1..=centre.1 + 1 + reach.1 {
        for tx in centre.0 - reach.0..=centre.0 + 1 + reach.0 {
            let i = (ty.rem_euclid(h) * w + tx.rem_euclid(w)) as usize * 4;
            for c in 0..3 {
                lo[c] = lo[c].min(texture.rgba8[i + c]);
                hi[c] = hi[c].max(texture.rgba8[i + c]);
            }
        }
    }
    (lo, hi)
}

fn uncleared(image: &image::RgbaImage) -> usize {
    image.pixels().filter(|p| p.0 == CLEAR).count()
}

#[test]
fn cornell_base_color_matches_cpu_ray_casting() {
    let context = gpu();
    let scene = procedural::cornell();
    let camera = TestCamera {
        position: Vec3::new(0.0, 1.5, 1.9),
        target: Vec3::new(0.0, 1.2, -2.0),
        fov_y: 60f32.to_radians(),
        near: 0.05,
        far: 20.0,
    };
    let image = render_base_color(&context, &scene, &camera);
    assert_eq!(uncleared(&image), 0, "the closed room covers every pixel");

    // What every pixel centre sees, on the CPU.
    let rays: Vec<Option<manylights_tests::Hit>> = (0..SIZE.1)
        .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
        .map(|(x, y)| cast(&scene, camera.position, camera.ray(SIZE, x, y)))
        .collect();
    let hits: Vec<Option<usize>> = rays
        .iter()
        .map(|h| h.as_ref().map(|h| h.material))
        .collect();
    let uv_at = |x: i64, y: i64| {
        rays[(y.clamp(0, SIZE.1 as i64 - 1) * SIZE.0 as i64 + x.clamp(0, SIZE.0 as i64 - 1))
            as usize]
            .as_ref()
            .map(|hit| hit.uv)
    };
    let material_at = |x: i64, y: i64| {
        hits[(y.clamp(0, SIZE.1 as i64 - 1) * SIZE.0 as i64 + x.clamp(0, SIZE.0 as i64 - 1))
            as usize]
    };
    let mut checked = 0;
    let mut failures = Vec::new();
    for y in 0..SIZE.1 as i64 {
        for x in 0..SIZE.0 as i64 {
            let here = material_at(x, y).expect("every ray hits the closed room");
            // Skip pixels within 2 of an edge between materials: rasterisation and the
            // alpha test's bilinear filtering may fall either way there.
            let interior =
                (-2..=2).all(|dy| (-2..=2).all(|dx| material_at(x + dx, y + dy) == Some(here)));
            if !interior {
                continue;
            }
            checked += 1;
            let material = &scene.materials[here];
            let got = image.get_pixel(x as u32, y as u32).0;
            let ok = match material.base_color_texture {
                None => {
                    let want = material
                        .base_color_factor
                        .truncate()
                        .to_array()
                        .map(linear_to_srgb8);
                    (0..3).all(|c| got[c].abs_diff(want[c]) <= 1)
                }
                Some(texture) => {
                    // Filtered texels lie between the darkest and lightest texel of the
                    // pixel's footprint around the ray's UV: the UV step to the neighbouring
                    // pixels (what mip selection and bilinear filtering reach), plus one
                    // texel. Wrong UVs land on other texels and fail.
                    let texture = &scene.textures[texture];
                    let uv = uv_at(x, y).expect("hit");
                    let step = [
                        uv_at(x + 1, y),
                        uv_at(x, y + 1),
                        uv_at(x - 1, y),
                        uv_at(x, y - 1),
                    ]
                    .into_iter()
                    .flatten()
                    .map(|n| (n - uv).abs().max_element())
                    .fold(0.0f32, f32::max);
                    let (lo, hi) = texel_range(texture, uv, step);
                    (0..3).all(|c| got[c] + 2 >= lo[c] && got[c] <= hi[c].saturating_add(2))
                }
            };
            if !ok {
                failures.push(format!("({x},{y}) {}: got {got:?}", material.name));
            }
        }
    }
    let total = (SIZE.0 * SIZE.1) as usize;
    assert!(
        checked * 2 > total,
        "only {checked} of {total} pixels were away from edges"
    );
    assert!(
        failures.is_empty(),
        "{} of {checked} pixels differ: {:?}",
        failures.len(),
        &failures[..failures.len().min(10)]
    );
    // The coloured walls and the grille are in view.
    for name in ["red", "green", "grille", "glossy block"] {
        let material = scene
            .materials
            .iter()
            .position(|m| m.name == name)
            .expect("material");
        assert!(hits.contains(&Some(material)), "{name} not in view");
    }
}

#[test]
fn sponza_gltf_and_obj_render_alike_and_cover_the_view() {
    let context = gpu();
    let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/sponza");
    // The reference projects' camera, pitched down a little so the open roof is out of view.
    let camera = TestCamera {
        position: Vec3::new(-7.0, 2.0, 0.0),
        target: Vec3::new(3.0, 0.5, 0.0),
        fov_y: 45f32.to_radians(),
        near: 0.1,
        far: 1000.0,
    };
    let gltf = render_base_color(
        &context,
        &manylights_scene::load(assets.join("sponza.gltf")).expect("gltf"),
        &camera,
    );
    let obj = render_base_color(
        &context,
        &manylights_scene::load(assets.join("sponza.obj")).expect("obj"),
        &camera,
    );
    for (name, image) in [("gltf", &gltf), ("obj", &obj)] {
        assert_eq!(
            uncleared(image),
            0,
            "{name}: background visible where Sponza covers the view"
        );
        let distinct: std::collections::HashSet<[u8; 4]> = image.pixels().map(|p| p.0).collect();
        assert!(
            distinct.len() > 500,
            "{name}: only {} distinct colours: textures missing?",
            distinct.len()
        );
    }
    // Same geometry, same textures, same UVs (OBJ's v flipped on load): same image, up to
    // rasterisation of coincident triangles.
    let differences: Vec<u32> = gltf
        .pixels()
        .zip(obj.pixels())
        .map(|(a, b)| {
            (0..3)
                .map(|c| a.0[c].abs_diff(b.0[c]) as u32)
                .max()
                .unwrap_or(0)
        })
        .collect();
    if let Ok(dir) = std::env::var("MANYLIGHTS_TEST_OUT") {
        let _ = gltf.save(format!("{dir}/sponza_gltf.png"));
        let _ = obj.save(format!("{dir}/sponza_obj.png"));
    }
    let mean = differences.iter().sum::<u32>() as f64 / differences.len() as f64;
    let within = differences.iter().filter(|&&d| d <= 4).count() as f64 / differences.len() as f64;
    assert!(
        mean < 1.0 && within > 0.99,
        "glTF vs OBJ: mean difference {mean:.3}, {:.2}% within 4/255",
        within * 100.0
    );
}
