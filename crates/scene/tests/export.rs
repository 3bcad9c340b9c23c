//! Round trips through the exporter: what is written loads back (from memory and from
//! disk) as the same scene, within the precision each format keeps.

use manylights_scene::export::{ExportFormat, export};
use manylights_scene::procedural::{PillarsParams, cornell, pillars};
use manylights_scene::{LoadOptions, Scene, Texture, load_from_memory, load_with};

fn textured_cornell() -> Scene {
    manylights_scene::fuzz_harness::seed_scene()
}

fn assert_same_geometry(original: &Scene, loaded: &Scene, format: ExportFormat) {
    assert_eq!(
        original.triangle_count(),
        loaded.triangle_count(),
        "{format:?}: triangles"
    );
    let (a, b) = (original.bounds(), loaded.bounds());
    assert!(
        (a.min - b.min).abs().max_element() < 1e-4 && (a.max - b.max).abs().max_element() < 1e-4,
        "{format:?}: bounds {a:?} vs {b:?}"
    );
    assert!(
        loaded.warnings.is_empty(),
        "{format:?}: {:?}",
        loaded.warnings
    );
    assert_eq!(
        original.features().alpha_mask,
        loaded.features().alpha_mask,
        "{format:?}"
    );
    assert_eq!(
        original.features().normal_maps,
        loaded.features().normal_maps,
        "{format:?}"
    );
    assert_eq!(
        original.features().base_color_textures,
        loaded.features().base_color_textures,
        "{format:?}"
    );
}

#[test]
fn gltf_glb_and_obj_round_trip() {
    let formats = [
        ExportFormat::GltfEmbedded,
        ExportFormat::Glb,
        ExportFormat::Obj,
    ];
    let scenes = [
        textured_cornell(),
        pillars(PillarsParams::with_triangles(4, 2_000)),
    ];
    for original in &scenes {
        for format in formats {
            let exported = export(original, format, "exported").expect("export");
            let loaded = load_from_memory(
                &exported.main_file,
                exported.main_bytes(),
                &exported.referenced(),
            )
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
            assert_same_geometry(original, &loaded, format);

            let folder = tempfile::tempdir().expect("temp dir");
            let path = exported.write_into(folder.path()).expect("write");
            let from_disk = load_with(&path, &LoadOptions::default()).expect("load from disk");
            assert_eq!(
                loaded.meshes, from_disk.meshes,
                "{format:?}: memory vs disk"
            );
            assert_eq!(loaded.textures.len(), from_disk.textures.len());
        }
    }
}

#[test]
fn gltf_keeps_materials_and_textures_exactly() {
    let original = textured_cornell();
    for format in [ExportFormat::GltfEmbedded, ExportFormat::Glb] {
        let exported = export(&original, format, "exported").expect("export");
        let loaded = load_from_memory(
            &exported.main_file,
            exported.main_bytes(),
            &exported.referenced(),
        )
        .expect("load");
        for (a, b) in original.materials.iter().zip(&loaded.materials) {
            assert_eq!(a.base_color_factor, b.base_color_factor, "{format:?}");
            assert_eq!(a.alpha_mode, b.alpha_mode, "{format:?}");
        }
        assert_eq!(
            loaded.textures[0].rgba8, original.textures[0].rgba8,
            "{format:?}"
        );
    }
}

#[test]
fn obj_keeps_colours_within_rounding() {
    let original = textured_cornell();
    let exported = export(&original, ExportFormat::Obj, "exported").expect("export");
    let loaded = load_from_memory(
        &exported.main_file,
        exported.main_bytes(),
        &exported.referenced(),
    )
    .expect("load");
    for (a, b) in original.materials.iter().zip(&loaded.materials).skip(1) {
        let error = (a.base_color_factor - b.base_color_factor)
            .abs()
            .max_element();
        assert!(error < 1e-5, "{}: {error}", a.name);
    }
    // The mask came back through map_d: alpha equals the original texture's.
    let alpha = |t: &Texture| t.rgba8.chunks_exact(4).map(|x| x[3]).collect::<Vec<_>>();
    assert_eq!(alpha(&loaded.textures[0]), alpha(&original.textures[0]));
}

#[test]
fn memory_scenes_cannot_reach_outside_their_folder() {
    let exported = export(&cornell(), ExportFormat::Obj, "exported").expect("export");
    let obj = String::from_utf8(exported.main_bytes().to_vec())
        .expect("utf-8")
        .replace("mtllib exported.mtl", "mtllib ../exported.mtl");
    let error = load_from_memory("exported.obj", obj.as_bytes(), &exported.referenced())
        .expect_err("outside reference");
    assert!(
        error.to_string().contains("outside the scene's folder"),
        "{error}"
    );
}
