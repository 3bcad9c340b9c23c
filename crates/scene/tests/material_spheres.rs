//! The committed `assets/spheres/spheres.gltf` is exactly the export of
//! `procedural::material_spheres`, and loads back with its metallic-roughness materials.

use manylights_scene::procedural::{SPHERE_ROUGHNESS, material_spheres};
use manylights_scene::{MemoryFiles, Shading, load_from_memory};

mod common;

#[test]
fn the_committed_spheres_asset_is_the_material_spheres() {
    let committed = common::assert_committed_asset_is_export(
        &material_spheres(),
        "spheres",
        "material_spheres",
    );
    let loaded = load_from_memory("spheres.gltf", &committed, &MemoryFiles::new()).expect("loads");
    assert_eq!(loaded.shading, Shading::Pbr, "a glTF scene is PBR");
    for (metallic, row) in [(0.0, 0), (1.0, 1)] {
        for (column, roughness) in SPHERE_ROUGHNESS.into_iter().enumerate() {
            let material = &loaded.materials[row * SPHERE_ROUGHNESS.len() + column];
            assert_eq!(
                (material.metallic_factor, material.roughness_factor),
                (metallic, roughness),
                "{}",
                material.name
            );
        }
    }
}
