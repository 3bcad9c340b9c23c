//! The committed `assets/spheres/spheres.gltf` is exactly the export of
//! `procedural::material_spheres`, and loads back with its metallic-roughness materials.

use manylights_scene::export::{ExportFormat, export};
use manylights_scene::procedural::{SPHERE_ROUGHNESS, material_spheres};
use manylights_scene::{MemoryFiles, Shading, load_from_memory};

#[test]
fn the_committed_spheres_asset_is_the_material_spheres() {
    let exported =
        export(&material_spheres(), ExportFormat::GltfEmbedded, "spheres").expect("export");
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/spheres/spheres.gltf");
    if std::env::var_os("MANYLIGHTS_WRITE_ASSETS").is_some() {
        std::fs::create_dir_all(path.parent().expect("folder")).expect("assets/spheres");
        std::fs::write(&path, exported.main_bytes()).expect("write");
    }
    let committed = std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (write it with MANYLIGHTS_WRITE_ASSETS=1 cargo test -p manylights-scene --test material_spheres)",
            path.display()
        )
    });
    assert!(
        committed == exported.main_bytes(),
        "{} is not the export of procedural::material_spheres (write it again with MANYLIGHTS_WRITE_ASSETS=1)",
        path.display()
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
