//! Scenes with blended surfaces (glTF's `BLEND`, issue 45): the glass room, and the panes
//! and sparks hung in Sponza (`sponza-glass`, Sponza with this overlay).

use glam::{Mat4, Vec3, Vec4};

use super::MeshBuilder;
use crate::model::{AlphaMode, Instance, Material, Scene, SceneLight};

/// The panes of [`glass_room`], nearest the camera last: name, base colour and alpha,
/// and the pane's centre (each 1.6 m wide and 1.8 m tall, facing +z).
pub const GLASS_PANES: [(&str, [f32; 4], [f32; 3]); 3] = [
    ("blue glass", [0.55, 0.75, 1.0, 0.35], [-0.9, 1.1, -1.8]),
    ("green glass", [0.6, 1.0, 0.6, 0.45], [0.3, 1.0, -0.6]),
    ("amber glass", [1.0, 0.75, 0.4, 0.55], [1.3, 1.2, 0.6]),
];

/// A blended, double-sided dielectric of `base` colour and alpha.
fn blended(name: &str, base: Vec4, roughness: f32) -> Material {
    Material {
        name: name.into(),
        base_color_factor: base,
        roughness_factor: roughness,
        alpha_mode: AlphaMode::Blend,
        double_sided: true,
        ..Material::default()
    }
}

/// Adds `mesh` of `material` to `scene` as one object (its own instance).
fn push_object(scene: &mut Scene, material: Material, mesh: MeshBuilder) {
    scene.materials.push(material);
    let name = scene.materials[scene.materials.len() - 1].name.clone();
    scene
        .meshes
        .push(mesh.build(&name, scene.materials.len() - 1));
    scene.instances.push(Instance {
        mesh: scene.meshes.len() - 1,
        transform: Mat4::IDENTITY,
    });
}

/// `count` small square sparks in the box from `corner` over `extent`, from a fixed
/// linear congruential sequence (the same cloud every build), each `size` to
/// `size + growth` wide, facing +z or (`turned`) turned about the vertical at random.
fn spark_cloud(
    count: usize,
    (corner, extent): (Vec3, Vec3),
    (size, growth): (f32, f32),
    turned: bool,
) -> MeshBuilder {
    let mut state: u32 = 0x2545_f491;
    let mut unit = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut sparks = MeshBuilder::new();
    for _ in 0..count {
        let centre = corner + extent * Vec3::new(unit(), unit(), unit());
        let side = size + growth * unit();
        let across = if turned {
            let angle = unit() * std::f32::consts::PI;
            Vec3::new(angle.cos(), 0.0, angle.sin())
        } else {
            Vec3::X
        };
        sparks.grid_quad(
            centre - (across + Vec3::Y) * side * 0.5,
            across * side,
            Vec3::Y * side,
            1,
        );
    }
    sparks
}

/// Blended transparency (glTF's `BLEND`, as `assets/glass/glass.gltf` is exported): a grey
/// floor and a pale back wall (opaque), three tinted glass panes standing one behind another
/// so that they overlap from the front ([`GLASS_PANES`], double-sided, smooth dielectrics),
/// and a cloud of 400 sparks (small double-sided quads of one blended mesh, drawn as one
/// object) between them, lit by two point lights.
pub fn glass_room() -> Scene {
    let mut scene = Scene {
        name: "glass".into(),
        ..Scene::default()
    };
    let opaque = |name: &str, grey: f32| Material {
        name: name.into(),
        base_color_factor: Vec3::splat(grey).extend(1.0),
        roughness_factor: 0.8,
        ..Material::default()
    };
    let mut floor = MeshBuilder::new();
    floor.grid_quad(Vec3::new(-4.0, 0.0, -4.0), Vec3::Z * 8.0, Vec3::X * 8.0, 1);
    push_object(&mut scene, opaque("floor", 0.5), floor);
    let mut wall = MeshBuilder::new();
    wall.grid_quad(Vec3::new(-4.0, 0.0, -4.0), Vec3::X * 8.0, Vec3::Y * 4.0, 1);
    push_object(&mut scene, opaque("back wall", 0.8), wall);
    for (name, base, centre) in GLASS_PANES {
        let centre = Vec3::from_array(centre);
        let mut pane = MeshBuilder::new();
        pane.grid_quad(
            centre - Vec3::new(0.8, 0.9, 0.0),
            Vec3::X * 1.6,
            Vec3::Y * 1.8,
            1,
        );
        push_object(
            &mut scene,
            blended(name, Vec4::from_array(base), 0.05),
            pane,
        );
    }
    let cloud = (Vec3::new(-2.5, 0.3, -3.0), Vec3::new(5.0, 2.2, 4.5));
    let sparks = spark_cloud(400, cloud, (0.04, 0.06), false);
    let spark = blended("sparks", Vec4::new(1.0, 0.85, 0.6, 0.6), 0.5);
    push_object(&mut scene, spark, sparks);
    scene.lights = vec![
        SceneLight {
            name: "left lamp".into(),
            position: Vec3::new(-2.0, 2.6, 1.5),
            direction: Vec3::NEG_Y,
            cone: None,
            color: Vec3::new(1.0, 0.95, 0.9),
            intensity: 12.0,
            range: Some(8.0),
        },
        SceneLight {
            name: "right lamp".into(),
            position: Vec3::new(2.2, 1.8, -2.5),
            direction: Vec3::NEG_Y,
            cone: None,
            color: Vec3::new(0.9, 0.95, 1.0),
            intensity: 8.0,
            range: Some(8.0),
        },
    ];
    scene
}

/// The glowing embers' count in [`sponza_embers`]: 10,000 emissive triangles, the issue's
/// scene size for a scene lit by its own emissive surfaces.
pub const SPONZA_EMBERS: usize = 5_000;

/// An overlay for Sponza (`assets/sponza-embers/sponza-embers.gltf`, loaded over
/// `sponza.gltf` as `--scene sponza-embers`): [`SPONZA_EMBERS`] opaque glowing quads 5 to
/// 12 cm across, one-sided, turned every way about the vertical, floating through the
/// ground floor and the gallery, each emitting an ember's orange at strength 40. Lit by
/// its embers alone (`--lights 0`), it is a scene of 10,000 emissive triangles.
pub fn sponza_embers() -> Scene {
    let mut scene = Scene {
        name: "sponza-embers".into(),
        ..Scene::default()
    };
    let atrium = (Vec3::new(-9.5, 0.3, -4.5), Vec3::new(19.0, 7.7, 9.0));
    let embers = spark_cloud(SPONZA_EMBERS, atrium, (0.05, 0.07), true);
    let ember = Material {
        name: "glowing embers".into(),
        base_color_factor: Vec4::new(0.1, 0.05, 0.02, 1.0),
        emissive_factor: Vec3::new(40.0, 18.0, 6.0),
        roughness_factor: 0.6,
        ..Material::default()
    };
    push_object(&mut scene, ember, embers);
    scene
}

/// The banners of [`sponza_glass`], in the order the reference camera (at x = -7, looking
/// down +x) sees them from nearest: name, base colour and alpha, and the x of their plane.
pub const SPONZA_BANNERS: [(&str, [f32; 4], f32); 4] = [
    ("rose banner", [1.0, 0.55, 0.6, 0.3], -3.5),
    ("teal banner", [0.45, 0.9, 0.85, 0.35], 0.0),
    ("gold banner", [1.0, 0.8, 0.35, 0.4], 3.5),
    ("violet banner", [0.7, 0.55, 1.0, 0.45], 7.0),
];

/// What `sponza-glass` adds to Sponza (`assets/sponza-glass/sponza-glass.gltf`): four
/// tinted glass banners hung across the atrium one behind another ([`SPONZA_BANNERS`],
/// 7 m wide, from 0.5 to 6.5 m high, facing down the atrium so that the reference camera
/// looks through all four), and 3,000 glowing embers (small blended quads, turned every
/// way about the vertical, one mesh) floating through the ground floor and the gallery.
/// The blended share of the frame follows the view: most of it inside, looking down the
/// atrium; little from the gallery or outside.
pub fn sponza_glass() -> Scene {
    let mut scene = Scene {
        name: "sponza-glass".into(),
        ..Scene::default()
    };
    for (name, base, x) in SPONZA_BANNERS {
        let mut banner = MeshBuilder::new();
        banner.grid_quad(Vec3::new(x, 0.5, 3.5), Vec3::NEG_Z * 7.0, Vec3::Y * 6.0, 1);
        push_object(
            &mut scene,
            blended(name, Vec4::from_array(base), 0.1),
            banner,
        );
    }
    let atrium = (Vec3::new(-9.5, 0.3, -4.5), Vec3::new(19.0, 7.7, 9.0));
    let embers = spark_cloud(3000, atrium, (0.05, 0.07), true);
    let ember = Material {
        emissive_factor: Vec3::new(1.6, 0.7, 0.25),
        ..blended("embers", Vec4::new(1.0, 0.6, 0.3, 0.7), 0.6)
    };
    push_object(&mut scene, ember, embers);
    scene
}
