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

/// What pins a scene: an exact FNV-1a hash of its integers and bytes (indices, material
/// slots, texels, instance count) and two float moments of its vertices (weighted by vertex
/// order, so moving or reordering vertices shows), compared to a relative 1e-5: the
/// generators call sin and cos, which another libm may round differently in the last bit.
fn fingerprint(scene: &manylights_scene::Scene) -> (u64, f64, f64) {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for &byte in bytes {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    let (mut weighted, mut squares) = (0.0f64, 0.0f64);
    feed(&(scene.instances.len() as u64).to_le_bytes());
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
    13_322_421_411_120_918_944,
    187_405.677_844_524_38,
    1_514.859_997_052_699_3,
);
const PILLARS: (u64, f64, f64) = (
    15_654_490_115_522_306_708,
    814_212.745_955_467_2,
    33_163.805_569_417_775,
);
