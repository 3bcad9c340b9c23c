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
