//! Round trips through the exporter: what is written loads back (from memory and from
//! disk) as the same scene, within the precision each format keeps.

use manylights_scene::export::{ExportFormat, ExportedScene, export};
use manylights_scene::procedural::{PillarsParams, cornell, pillars};
use manylights_scene::{LoadOptions, Scene, Texture, load_from_memory, load_with};

fn textured_cornell() -> Scene {
    manylights_scene::fuzz_harness::seed_scene()
}

/// Loads an exported scene from memory, with the files it references.
fn load_back(exported: &ExportedScene) -> manylights_scene::Result<Scene> {
    load_from_memory(
        &exported.main_file,
        exported.main_bytes(),
        &exported.referenced(),
    )
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
    // Texture coordinates summed over every drawn triangle corner (formats may re-index
    // vertices or flatten instances, never move a corner's coordinates).
    let corner_uvs = |scene: &Scene| -> glam::DVec2 {
        scene
            .instances
            .iter()
            .map(|instance| &scene.meshes[instance.mesh])
            .flat_map(|mesh| {
                mesh.indices
                    .iter()
                    .map(|&i| mesh.uvs[i as usize].as_dvec2())
            })
            .sum()
    };
    let (a, b) = (corner_uvs(original), corner_uvs(loaded));
    assert!(
        a.length() > 1.0 && (a - b).abs().max_element() < 1e-3 * a.length(),
        "{format:?}: corner texture coordinates sum to {a} before and {b} after"
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
            let loaded = load_back(&exported).unwrap_or_else(|e| panic!("{format:?}: {e}"));
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
        let loaded = load_back(&exported).expect("load");
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
    let loaded = load_back(&exported).expect("load");
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

/// Colours on the sRGB curve's linear segment (below 0.0031308) survive the OBJ round trip
/// as well as the bright ones.
#[test]
fn obj_keeps_dark_colours() {
    let mut scene = textured_cornell();
    scene.materials[1].base_color_factor = glam::Vec4::new(0.001, 0.003, 0.2, 1.0);
    let exported = export(&scene, ExportFormat::Obj, "dark").expect("export");
    let loaded = load_back(&exported).expect("load");
    let (a, b) = (
        scene.materials[1].base_color_factor,
        loaded.materials[1].base_color_factor,
    );
    assert!((a - b).abs().max_element() < 1e-6, "{a} became {b}");
}

/// The containers follow the glTF spec's layout rules (which other tools rely on even
/// where this loader does not): buffer views start 4-byte aligned, the buffer's length is
/// a multiple of 4, and the GLB header's total and chunk lengths are the real ones.
#[test]
fn exported_containers_are_aligned_and_sized() {
    let scene = textured_cornell();
    let glb = export(&scene, ExportFormat::Glb, "scene").expect("export");
    let bytes = glb.main_bytes();
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(word(8), bytes.len(), "GLB total length");
    let json_length = word(12);
    assert_eq!(json_length % 4, 0, "JSON chunk padded to 4 bytes");
    assert_eq!(&bytes[16..20], b"JSON");
    let bin_at = 20 + json_length;
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(word(bin_at) % 4, 0, "binary chunk padded to 4 bytes");
    assert_eq!(bin_at + 8 + word(bin_at), bytes.len(), "chunk lengths");
    let document: serde_json::Value =
        serde_json::from_slice(&bytes[20..bin_at]).expect("JSON chunk");
    let buffer_length = document["buffers"][0]["byteLength"].as_u64().unwrap();
    assert_eq!(buffer_length % 4, 0, "buffer length {buffer_length}");
    let views = document["bufferViews"].as_array().unwrap();
    assert!(views.len() > 3);
    for view in views {
        let offset = view["byteOffset"].as_u64().unwrap_or(0);
        assert_eq!(offset % 4, 0, "view at {offset}");
    }
}
