//! Small model types on their own: box centre and size, the metallic/roughness to
//! Blinn-Phong mapping, and the in-memory file set. Written against survivors of
//! `cargo mutants -p manylights-scene` (docs/testing.md).

use glam::Vec3;
use manylights_scene::{Aabb, Material, MemoryFiles};

#[test]
fn box_centre_and_size() {
    let b = Aabb::new(Vec3::new(-1.0, 2.0, 3.0), Vec3::new(3.0, 6.0, 4.0));
    assert_eq!(b.center(), Vec3::new(1.0, 4.0, 3.5));
    assert_eq!(b.size(), Vec3::new(4.0, 4.0, 1.0));
}

#[test]
fn metallic_roughness_maps_to_blinn_phong() {
    let base = Vec3::new(0.8, 0.4, 0.2);
    // Roughness 0.5: alpha = 0.25, exponent 2 / 0.0625 - 2 = 30.
    let (specular, shininess) = Material::blinn_phong_from_metallic_roughness(base, 0.0, 0.5);
    assert_eq!(specular, Vec3::splat(0.04));
    assert!((shininess - 30.0).abs() < 1e-4, "{shininess}");
    // Metals take the base colour; fully rough surfaces bottom out at exponent 1.
    let (specular, shininess) = Material::blinn_phong_from_metallic_roughness(base, 1.0, 1.0);
    assert_eq!(specular, base);
    assert_eq!(shininess, 1.0);
    // Half metallic: halfway between 4% and the base colour.
    let (specular, _) = Material::blinn_phong_from_metallic_roughness(base, 0.5, 0.5);
    assert!(
        (specular - (Vec3::splat(0.04) + base) * 0.5)
            .abs()
            .max_element()
            < 1e-6
    );
}

#[test]
fn memory_files_count_what_was_inserted() {
    let mut files = MemoryFiles::new();
    assert!(files.is_empty());
    assert_eq!(files.len(), 0);
    files.insert("a.gltf", vec![1, 2]);
    files.insert("b.bin", vec![3]);
    assert!(!files.is_empty());
    assert_eq!(files.len(), 2);
    assert_eq!(files.get("b.bin"), Some(&[3u8][..]));
}

/// What pins a scene: an exact FNV-1a hash of its integers, bytes and literal constants
/// (name, materials, indices, material slots, texels, instance count and meshes) and two
/// float moments of its vertices and instance transforms (weighted by order, so moving or
/// reordering shows), compared to a relative 1e-5: the generators call sin and cos, which
/// another libm may round differently in the last bit.
fn fingerprint(scene: &manylights_scene::Scene) -> (u64, f64, f64) {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for &byte in bytes {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    let (mut weighted, mut squares) = (0.0f64, 0.0f64);
    feed(scene.name.as_bytes());
    // Materials are literals (no libm): their printed form is exact on every machine.
    for material in &scene.materials {
        feed(format!("{material:?}").as_bytes());
    }
    feed(&(scene.instances.len() as u64).to_le_bytes());
    for (i, instance) in scene.instances.iter().enumerate() {
        feed(&(instance.mesh as u64).to_le_bytes());
        for (j, element) in instance.transform.to_cols_array().iter().enumerate() {
            weighted += ((i * 16 + j) % 89 + 1) as f64 * f64::from(*element);
        }
    }
    for mesh in &scene.meshes {
        feed(&(mesh.material as u64).to_le_bytes());
        for index in &mesh.indices {
            feed(&index.to_le_bytes());
        }
        for (i, ((p, n), uv)) in mesh
            .positions
            .iter()
            .zip(&mesh.normals)
            .zip(&mesh.uvs)
            .enumerate()
        {
            let w = ((i % 97) + 1) as f64;
            let value = p.dot(Vec3::new(1.0, 2.0, 3.0))
                + n.dot(Vec3::new(5.0, 7.0, 11.0))
                + uv.x * 13.0
                + uv.y * 17.0;
            weighted += w * f64::from(value);
            squares += f64::from(p.length_squared());
        }
    }
    for texture in &scene.textures {
        feed(&texture.width.to_le_bytes());
        feed(&texture.height.to_le_bytes());
        feed(&texture.rgba8);
    }
    (hash, weighted, squares)
}

fn assert_fingerprint(name: &str, actual: (u64, f64, f64), expected: (u64, f64, f64)) {
    println!("{name}: {actual:?}");
    assert_eq!(
        actual.0, expected.0,
        "{name}: indices, slots or texels changed"
    );
    for (what, a, e) in [
        ("weighted", actual.1, expected.1),
        ("squares", actual.2, expected.2),
    ] {
        assert!(
            (a - e).abs() <= 1e-5 * e.abs().max(1.0),
            "{name}: {what} moment {a} instead of {e}"
        );
    }
}

/// The procedural scenes are the tests' fixtures (the golden image, the f64 reference, the
/// soak): their content is pinned, so a change to their geometry or textures is a
/// deliberate one (update the fingerprints here and the golden images with it).
#[test]
fn procedural_scenes_are_pinned() {
    use manylights_scene::procedural::{PillarsParams, cornell, pillars};
    assert_fingerprint("cornell", fingerprint(&cornell()), CORNELL);
    assert_fingerprint(
        "pillars",
        fingerprint(&pillars(PillarsParams::default())),
        PILLARS,
    );
}

const CORNELL: (u64, f64, f64) = (
    10_991_417_358_272_214_403,
    188_467.477_844_238_28,
    1_514.859_997_052_699_3,
);
const PILLARS: (u64, f64, f64) = (
    12_829_089_754_062_756_687,
    844_997.584_232_112_4,
    33_163.805_569_417_775,
);

/// `with_triangles` picks the smallest tessellation reaching the count: exactly a
/// tessellation's own count gives that tessellation, one more gives the next.
#[test]
fn pillars_tessellation_is_the_smallest_that_reaches_the_count() {
    use manylights_scene::procedural::PillarsParams;
    let ten = PillarsParams {
        grid: 2,
        segments: 10,
    };
    let exact = ten.triangle_count();
    assert_eq!(PillarsParams::with_triangles(2, exact).segments, 10);
    assert_eq!(PillarsParams::with_triangles(2, exact + 1).segments, 11);
    assert_eq!(PillarsParams::with_triangles(2, 0).segments, 3);
    assert_eq!(PillarsParams::with_triangles(2, usize::MAX).segments, 1024);
    let scene = manylights_scene::procedural::pillars(ten);
    assert_eq!(scene.triangle_count(), exact);
}

fn triangle_mesh(material: usize, tangents: bool) -> manylights_scene::Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    manylights_scene::Mesh {
        name: format!("triangle {material}"),
        normals: vec![Vec3::Z; 3],
        uvs: vec![glam::Vec2::ZERO; 3],
        tangents: tangents.then(|| vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 3]),
        indices: vec![0, 1, 2],
        material,
        bounds: manylights_scene::bounds_of(&positions),
        positions,
    }
}

/// Each feature is reported when one instanced mesh uses it (even after a mesh that does
/// not), and never for a mesh no instance draws.
#[test]
fn features_come_from_instanced_meshes_only() {
    use manylights_scene::{AlphaMode, Instance, Scene, SceneFeatures};
    let plain = Material {
        specular_color: Vec3::ZERO,
        ..Material::default()
    };
    let rich = Material {
        base_color_texture: Some(0),
        normal_texture: Some(0),
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        double_sided: true,
        specular_color: Vec3::splat(0.04),
        emissive_factor: Vec3::new(0.0, 2.0, 0.0),
        metallic_roughness_texture: Some(0),
        ..Material::default()
    };
    let blend = Material {
        alpha_mode: AlphaMode::Blend,
        ..plain.clone()
    };
    let instance = |mesh| Instance {
        mesh,
        transform: glam::Mat4::IDENTITY,
    };
    let mut scene = Scene {
        materials: vec![plain, rich, blend],
        meshes: vec![
            triangle_mesh(0, false),
            triangle_mesh(1, true),
            triangle_mesh(2, false),
        ],
        ..Scene::default()
    };
    assert_eq!(scene.vertex_count(), 9, "stored vertices, instanced or not");
    scene.instances = vec![instance(0)];
    assert_eq!(scene.features(), SceneFeatures::default());
    // The plain mesh first: a later feature must not be masked by an earlier absence.
    scene.instances = vec![instance(0), instance(1), instance(0)];
    assert_eq!(
        scene.features(),
        SceneFeatures {
            base_color_textures: true,
            normal_maps: true,
            alpha_mask: true,
            alpha_blend: false,
            double_sided: true,
            vertex_tangents: true,
            specular: true,
            metallic_roughness_textures: true,
            emissive: true,
        }
    );
    scene.instances = vec![instance(0), instance(2)];
    assert_eq!(
        scene.features(),
        SceneFeatures {
            alpha_blend: true,
            ..SceneFeatures::default()
        }
    );
    assert_eq!(scene.triangle_count(), 2);
}

#[test]
fn boxes_are_empty_only_when_inverted() {
    assert!(Aabb::EMPTY.is_empty());
    assert!(!Aabb::new(Vec3::ZERO, Vec3::ZERO).is_empty(), "a point");
    assert!(!Aabb::new(Vec3::ZERO, Vec3::ONE).is_empty());
    assert!(Aabb::new(Vec3::ZERO, Vec3::new(1.0, -1.0, 1.0)).is_empty());
}

/// Area-weighted, in the winding's direction: a counter-clockwise triangle in the xy plane
/// faces +z; a vertex shared by a large and a small face leans toward the large one.
#[test]
fn smooth_normals_follow_winding_and_area() {
    use manylights_scene::smooth_normals;
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 0.1)];
    let normals = smooth_normals(&positions, &[0, 1, 2]);
    assert_eq!(normals[0], Vec3::Z);
    assert_eq!(normals[3], Vec3::Y, "unused vertices get the fallback");
    // Triangle (0, 1, 2) has area 0.5 facing +z; (0, 3, 1) has area 0.05 facing +y.
    let normals = smooth_normals(&positions, &[0, 1, 2, 0, 3, 1]);
    let expected = (Vec3::Z * 0.5 + Vec3::Y * 0.05).normalize();
    assert!((normals[0] - expected).length() < 1e-6, "{}", normals[0]);
    assert!((normals[2] - Vec3::Z).length() < 1e-6);
}

#[test]
fn warnings_print_their_file_and_message() {
    let warning = manylights_scene::LoadWarning {
        file: "room.gltf".into(),
        message: "texture 3 could not be decoded".into(),
    };
    assert_eq!(
        warning.to_string(),
        "room.gltf: texture 3 could not be decoded"
    );
}

/// MikkTSpace's tangent is the UV gradient made perpendicular to the vertex normal: with
/// the normal tilted 45 degrees toward +X, the +X gradient becomes (1, 0, -1) / sqrt 2.
/// Mirrored UVs flip the bitangent sign.
#[test]
fn generated_tangents_are_perpendicular_to_the_normals() {
    use manylights_scene::generate_tangents;
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
    let uvs = [
        glam::Vec2::new(0.0, 0.0),
        glam::Vec2::new(1.0, 0.0),
        glam::Vec2::new(0.0, 1.0),
    ];
    let tangents = generate_tangents(&positions, &[tilted; 3], &uvs, &[0, 1, 2]);
    let expected = Vec3::new(1.0, 0.0, -1.0).normalize();
    for t in &tangents {
        assert!((t.truncate() - expected).length() < 1e-5, "{t}");
        assert_eq!(t.w, 1.0, "v along +Y: bitangent = cross(N, T) side");
    }
    // No UV gradient at all: a unit vector perpendicular to the normal, sign +1.
    for t in generate_tangents(
        &positions,
        &[Vec3::Z; 3],
        &[glam::Vec2::ZERO; 3],
        &[0, 1, 2],
    ) {
        assert!(t.truncate().is_normalized() && t.truncate().dot(Vec3::Z).abs() < 1e-6);
        assert_eq!(t.w, 1.0, "{t}");
    }
    let mirrored = uvs.map(|uv| glam::Vec2::new(uv.x, -uv.y));
    for t in generate_tangents(&positions, &[Vec3::Z; 3], &mirrored, &[0, 1, 2]) {
        assert_eq!(t.w, -1.0, "{t}");
    }
}
