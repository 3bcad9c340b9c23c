//! Loader tests: the Sponza reference scene in both formats, and one test for each kind of
//! bad input (each must give a typed error naming the file, never a panic).

#![allow(clippy::unwrap_used)] // test helpers: a failed setup step should just fail the test

use std::path::{Path, PathBuf};

use base64::Engine as _;
use glam::{Vec3, Vec4};
use manylights_scene::{AlphaMode, SceneError, load};
use serde_json::{Value, json};

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

#[test]
fn sponza_gltf_and_obj_agree() {
    let gltf = load(assets().join("sponza/sponza.gltf")).expect("sponza.gltf loads");
    let obj = load(assets().join("sponza/sponza.obj")).expect("sponza.obj loads");
    assert_eq!(gltf.triangle_count(), 66_454);
    assert_eq!(obj.triangle_count(), gltf.triangle_count());
    let (a, b) = (gltf.bounds(), obj.bounds());
    assert!(
        a.min.abs_diff_eq(b.min, 1e-4) && a.max.abs_diff_eq(b.max, 1e-4),
        "{a:?} vs {b:?}"
    );
    // The documented extent: x -17.4..17.4, y -0.91..15.65, z -7.8..7.8.
    assert!(
        (a.min.x + 17.4).abs() < 0.1
            && (a.max.y - 15.65).abs() < 0.1
            && (a.max.z - 7.8).abs() < 0.1
    );
    assert!(gltf.warnings.is_empty() && obj.warnings.is_empty());
    // The flat-coloured materials agree (MTL Kd is decoded from sRGB, as the glTF was).
    for material in gltf
        .materials
        .iter()
        .filter(|m| m.base_color_texture.is_none() && m.name != "default")
    {
        let twin = obj
            .materials
            .iter()
            .find(|m| m.name == material.name)
            .expect("same material names");
        assert!(
            twin.base_color_factor
                .abs_diff_eq(material.base_color_factor, 1e-4),
            "{}",
            material.name
        );
    }
    for scene in [&gltf, &obj] {
        let features = scene.features();
        assert!(features.base_color_textures);
        assert!(!features.normal_maps && !features.vertex_tangents && !features.alpha_mask);
        // 18 textured materials, 11 distinct images.
        assert_eq!(scene.textures.len(), 11, "{}", scene.name);
        assert!(scene.meshes.iter().all(|m| m.tangents.is_none()));
    }
}

#[test]
fn incomplete_crytek_sponza_names_the_missing_bin() {
    let error = load(assets().join("sponza-crytek-incomplete/Sponza.gltf")).unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::MissingReferencedFile { kind: "buffer", .. }
        ),
        "{error}"
    );
    let message = error.to_string();
    assert!(
        message.contains("Sponza.bin") && message.contains("Sponza.gltf"),
        "{message}"
    );
}

/// A one-triangle glTF document; tests edit it to make it bad in one way.
fn triangle_gltf(positions: [[f32; 3]; 3], with_normals: bool) -> (Value, Vec<u8>) {
    let mut bin = Vec::new();
    for p in positions {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    let mut attributes = json!({ "POSITION": 0 });
    // min/max are required for POSITION; the tests' triangles lie in the unit square.
    let mut accessors = vec![
        json!({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
        "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]}),
    ];
    let mut views = vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": 36})];
    if with_normals {
        for _ in 0..3 {
            for c in [0.0f32, 0.0, 1.0] {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        attributes["NORMAL"] = json!(1);
        accessors.push(json!({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}));
        views.push(json!({"buffer": 0, "byteOffset": 36, "byteLength": 36}));
    }
    let index_view = views.len();
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes()); // padded to 4 bytes
    }
    views.push(json!({"buffer": 0, "byteOffset": bin.len() - 8, "byteLength": 6}));
    accessors.push(
        json!({"bufferView": index_view, "componentType": 5123, "count": 3, "type": "SCALAR"}),
    );
    let indices = accessors.len() - 1;
    let document = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": indices}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"uri": "triangle.bin", "byteLength": bin.len()}],
    });
    (document, bin)
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn write(dir: &Path, document: &Value, bin: &[u8]) -> PathBuf {
    std::fs::write(dir.join("triangle.bin"), bin).unwrap();
    let path = dir.join("triangle.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(document).unwrap()).unwrap();
    path
}

fn load_edited(
    edit: impl FnOnce(&mut Value, &mut Vec<u8>),
) -> Result<manylights_scene::Scene, SceneError> {
    let dir = tempfile::tempdir().unwrap();
    let (mut document, mut bin) = triangle_gltf(TRIANGLE, true);
    edit(&mut document, &mut bin);
    let path = write(dir.path(), &document, &bin);
    load(path)
}

fn assert_names_file(error: &SceneError, file: &str) {
    assert!(
        error.to_string().contains(file),
        "error does not name {file}: {error}"
    );
}

#[test]
fn valid_triangle_loads() {
    let scene = load_edited(|_, _| {}).expect("valid file");
    assert_eq!(scene.name, "triangle", "named after the file");
    assert_eq!(scene.triangle_count(), 1);
    assert_eq!(scene.meshes[0].normals, vec![Vec3::Z; 3]);
}

#[test]
fn missing_file() {
    let error = load("/nonexistent/scene.gltf").unwrap_err();
    assert!(matches!(error, SceneError::FileNotFound { .. }));
    assert_names_file(&error, "/nonexistent/scene.gltf");
}

#[test]
fn unsupported_format() {
    let error = load(assets().join("sponza/kamen.jpg")).unwrap_err();
    assert!(
        matches!(error, SceneError::UnsupportedFormat { .. }),
        "{error}"
    );
}

#[test]
fn missing_buffer_file() {
    let dir = tempfile::tempdir().unwrap();
    let (document, bin) = triangle_gltf(TRIANGLE, false);
    let path = write(dir.path(), &document, &bin);
    std::fs::remove_file(dir.path().join("triangle.bin")).unwrap();
    let error = load(&path).unwrap_err();
    assert!(matches!(
        error,
        SceneError::MissingReferencedFile { kind: "buffer", .. }
    ));
    assert_names_file(&error, "triangle.bin");
    assert_names_file(&error, "triangle.gltf");
}

#[test]
fn missing_image_file() {
    let error = load_edited(|doc, _| {
        doc["images"] = json!([{"uri": "no-such-texture.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    })
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::MissingReferencedFile { kind: "image", .. }
        ),
        "{error}"
    );
    assert_names_file(&error, "no-such-texture.png");
}

#[test]
fn buffer_shorter_than_declared() {
    let error = load_edited(|_, bin| bin.truncate(20)).unwrap_err();
    assert!(
        matches!(error, SceneError::BufferTooShort { actual: 20, .. }),
        "{error}"
    );
    assert_names_file(&error, "triangle.gltf");
}

#[test]
fn invalid_json() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.gltf");
    std::fs::write(&path, b"{ \"asset\": { \"version\": \"2.0\" ").unwrap();
    let error = load(&path).unwrap_err();
    assert!(matches!(error, SceneError::InvalidGltf { .. }), "{error}");
    assert_names_file(&error, "broken.gltf");
}

#[test]
fn accessor_past_its_view() {
    let error =
        load_edited(|doc, _| doc["accessors"][0]["count"] = json!(4_000_000_000u64)).unwrap_err();
    assert!(
        matches!(error, SceneError::AccessorOutOfRange { accessor: 0, .. }),
        "{error}"
    );
}

#[test]
fn view_past_its_buffer() {
    let error =
        load_edited(|doc, _| doc["bufferViews"][0]["byteOffset"] = json!(1000)).unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::AccessorOutOfRange { .. } | SceneError::InvalidGltf { .. }
        ),
        "{error}"
    );
    assert_names_file(&error, "triangle.gltf");
}

#[test]
fn index_out_of_range() {
    let error = load_edited(|_, bin| {
        let at = bin.len() - 8;
        bin[at..at + 2].copy_from_slice(&7u16.to_le_bytes());
    })
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::IndexOutOfRange {
                index: 7,
                vertex_count: 3,
                ..
            }
        ),
        "{error}"
    );
}

#[test]
fn non_finite_position() {
    let dir = tempfile::tempdir().unwrap();
    let (document, bin) = triangle_gltf(
        [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]],
        true,
    );
    let error = load(write(dir.path(), &document, &bin)).unwrap_err();
    assert!(
        matches!(error, SceneError::NonFinitePosition { vertex: 1, .. }),
        "{error}"
    );
    let dir = tempfile::tempdir().unwrap();
    let (document, bin) = triangle_gltf(
        [[0.0, f32::INFINITY, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        true,
    );
    let error = load(write(dir.path(), &document, &bin)).unwrap_err();
    assert!(
        matches!(error, SceneError::NonFinitePosition { vertex: 0, .. }),
        "{error}"
    );
}

#[test]
fn unsupported_required_extension() {
    let error = load_edited(|doc, _| {
        doc["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
        doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    })
    .unwrap_err();
    assert!(
        matches!(error, SceneError::UnsupportedExtension { .. }),
        "{error}"
    );
    assert!(error.to_string().contains("KHR_draco_mesh_compression"));
}

#[test]
fn undecodable_texture_is_a_warning_with_fallback() {
    let dir = tempfile::tempdir().unwrap();
    let (mut document, bin) = triangle_gltf(TRIANGLE, true);
    std::fs::write(dir.path().join("garbage.png"), b"this is not a png").unwrap();
    document["images"] = json!([{"uri": "garbage.png"}]);
    document["textures"] = json!([{"source": 0}]);
    document["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    document["meshes"][0]["primitives"][0]["material"] = json!(0);
    let scene = load(write(dir.path(), &document, &bin)).expect("loads with a warning");
    assert_eq!(scene.warnings.len(), 1);
    assert!(
        scene.warnings[0].message.contains("garbage.png"),
        "{}",
        scene.warnings[0]
    );
    assert!(
        scene.warnings[0].file.ends_with("triangle.gltf"),
        "the warning names the scene file: {}",
        scene.warnings[0]
    );
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (2, 2));
}

#[test]
fn data_uri_glb_hierarchy_and_generated_normals() {
    // Positions only (no NORMAL): smooth normals are generated. The buffer is a data URI,
    // the mesh sits under a parent node with a translation and a child with a scale.
    let (mut document, bin) = triangle_gltf(TRIANGLE, false);
    let encoded = base64::engine::general_purpose::STANDARD.encode(&bin);
    document["buffers"][0]["uri"] =
        json!(format!("data:application/octet-stream;base64,{encoded}"));
    document["nodes"] = json!([
        {"translation": [10.0, 0.0, 0.0], "children": [1]},
        {"scale": [2.0, 2.0, 2.0], "mesh": 0}
    ]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("embedded.gltf");
    std::fs::write(&path, serde_json::to_vec(&document).unwrap()).unwrap();
    let scene = load(&path).expect("data URI glTF");
    assert_eq!(scene.meshes[0].normals, vec![Vec3::Z; 3]);
    let bounds = scene.bounds();
    assert_eq!(bounds.min, Vec3::new(10.0, 0.0, 0.0));
    assert_eq!(bounds.max, Vec3::new(12.0, 2.0, 0.0));

    // The same document as GLB with the buffer in the BIN chunk.
    document["buffers"][0] = json!({"byteLength": bin.len()});
    let json_bytes = serde_json::to_vec(&document).unwrap();
    let glb = manylights_scene::export::glb_container(&json_bytes, &bin);
    let glb_path = dir.path().join("embedded.glb");
    std::fs::write(&glb_path, glb).unwrap();
    let from_glb = load(&glb_path).expect("GLB");
    assert_eq!(from_glb.bounds(), bounds);
    assert_eq!(from_glb.meshes, scene.meshes);
}

/// The triangle's u runs along +X and v (down the image) along -Y: tangent +X, and the
/// bitangent -Y is opposite to cross(N, T) = +Y, so the sign is -1.
const GENERATED_TANGENT: Vec4 = Vec4::new(1.0, 0.0, 0.0, -1.0);

#[test]
fn gltf_normal_map_generates_tangents() {
    for t in normal_mapped_triangle(None) {
        assert!((t - GENERATED_TANGENT).length() < 1e-5, "tangent {t}");
    }
}

/// Zero-length TANGENT vectors in the file are degenerate: the tangents are generated
/// instead (no NaN from normalising them).
#[test]
fn degenerate_tangents_from_the_file_are_regenerated() {
    for t in normal_mapped_triangle(Some([0.0; 4])) {
        assert!((t - GENERATED_TANGENT).length() < 1e-5, "tangent {t}");
    }
}

/// Usable tangents from the file are kept (normalised), with their bitangent sign, even
/// where they differ from what MikkTSpace would generate.
#[test]
fn tangents_from_the_file_are_kept_with_their_sign() {
    // (A w of 0, which glTF does not allow, counts as +1.)
    for (w, sign) in [(-1.0f32, -1.0), (1.0, 1.0), (0.0, 1.0)] {
        for t in normal_mapped_triangle(Some([0.0, 2.0, 0.0, w])) {
            assert_eq!(t, Vec4::new(0.0, 1.0, 0.0, sign));
        }
    }
}

fn normal_mapped_triangle(tangents_in_file: Option<[f32; 4]>) -> Vec<Vec4> {
    let dir = tempfile::tempdir().unwrap();
    let (mut document, mut bin) = triangle_gltf(TRIANGLE, true);
    if let Some(tangent) = tangents_in_file {
        let offset = bin.len();
        for _ in 0..3 {
            bin.extend(tangent.iter().flat_map(|c| c.to_le_bytes()));
        }
        document["bufferViews"]
            .as_array_mut()
            .unwrap()
            .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 48}));
        let view = document["bufferViews"].as_array().unwrap().len() - 1;
        document["accessors"]
            .as_array_mut()
            .unwrap()
            .push(json!({"bufferView": view, "componentType": 5126, "count": 3, "type": "VEC4"}));
        let accessor = document["accessors"].as_array().unwrap().len() - 1;
        document["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(accessor);
    }
    // UVs: u along +X, v along -Y (glTF's v points down the image).
    let uv_offset = bin.len();
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [0.0, 0.0]] {
        for c in uv {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    document["buffers"][0]["byteLength"] = json!(bin.len());
    document["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": uv_offset, "byteLength": 24}));
    let uv_view = document["bufferViews"].as_array().unwrap().len() - 1;
    document["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": uv_view, "componentType": 5126, "count": 3, "type": "VEC2"}));
    let uv_accessor = document["accessors"].as_array().unwrap().len() - 1;
    document["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv_accessor);
    image::RgbaImage::from_pixel(4, 4, image::Rgba([128, 128, 255, 255]))
        .save(dir.path().join("normal.png"))
        .unwrap();
    document["images"] = json!([{"uri": "normal.png"}]);
    document["textures"] = json!([{"source": 0}]);
    document["materials"] = json!([{"normalTexture": {"index": 0}}]);
    document["meshes"][0]["primitives"][0]["material"] = json!(0);
    let scene = load(write(dir.path(), &document, &bin)).expect("normal-mapped triangle");
    let features = scene.features();
    assert!(features.normal_maps && features.vertex_tangents);
    assert_eq!(
        scene.textures[0].color_space,
        manylights_scene::ColorSpace::Linear
    );
    scene.meshes[0].tangents.clone().expect("tangents")
}

fn write_obj(dir: &Path, obj: &str, mtl: &str) -> PathBuf {
    std::fs::write(dir.join("test.mtl"), mtl).unwrap();
    let path = dir.join("test.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

const QUAD_OBJ: &str = "mtllib test.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n";

#[test]
fn obj_quad_is_triangulated_with_materials() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 0, 0, 255]))
        .save(dir.path().join("kd.png"))
        .unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([0, 0, 0, 255]))
        .save(dir.path().join("mask.png"))
        .unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([128, 128, 255, 255]))
        .save(dir.path().join("bump.png"))
        .unwrap();
    let mtl = "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd kd.png\nmap_d mask.png\nmap_Bump bump.png\n";
    let scene = load(write_obj(dir.path(), QUAD_OBJ, mtl)).expect("obj loads");
    assert_eq!(scene.name, "test", "named after the file");
    assert_eq!(scene.triangle_count(), 2);
    let mesh = &scene.meshes[0];
    assert!(mesh.tangents.is_some(), "map_Bump needs tangents");
    // v flipped: OBJ vt (0,0) is the image's bottom-left, glTF-style (0,1).
    assert_eq!(mesh.uvs[0], glam::Vec2::new(0.0, 1.0));
    assert_eq!(mesh.uvs[2], glam::Vec2::new(1.0, 0.0));
    let material = &scene.materials[mesh.material];
    assert!(matches!(material.alpha_mode, AlphaMode::Mask { .. }));
    let texture = &scene.textures[material.base_color_texture.unwrap()];
    assert_eq!(
        &texture.rgba8[..4],
        &[255, 0, 0, 0],
        "map_d baked into alpha"
    );
    assert!(material.normal_texture.is_some());
    // The normals are generated (the OBJ has none) and face +Z for this CCW quad.
    assert!(mesh.normals.iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));

    let scene = load(write_obj(
        dir.path(),
        QUAD_OBJ,
        "newmtl m\nKd 0.2 0.4 0.6\nd 0.5\n",
    ))
    .unwrap();
    let material = &scene.materials[scene.meshes[0].material];
    assert!(matches!(material.alpha_mode, AlphaMode::Mask { .. }));
    // Kd is sRGB-encoded: 0.2, 0.4, 0.6 decode to 0.0331, 0.1329, 0.3185.
    let expected = glam::Vec4::new(0.0331, 0.1329, 0.3185, 0.5);
    assert!(
        material.base_color_factor.abs_diff_eq(expected, 1e-4),
        "{}",
        material.base_color_factor
    );
}

#[test]
fn obj_syntax_error() {
    let dir = tempfile::tempdir().unwrap();
    let error = load(write_obj(dir.path(), "v 0 0 zero\nf 1 1 1\n", "")).unwrap_err();
    assert!(matches!(error, SceneError::InvalidObj { .. }), "{error}");
    assert_names_file(&error, "test.obj");
}

/// Found by the `obj_mtl` fuzzer: tobj 4.0.5 panics on a colour with fewer than three
/// values; the loader refuses it first, naming the MTL file and line.
#[test]
fn mtl_colour_with_too_few_values() {
    let dir = tempfile::tempdir().unwrap();
    let error = load(write_obj(dir.path(), QUAD_OBJ, "newmtl m\nKd 0.5 0.5\n")).unwrap_err();
    assert!(matches!(error, SceneError::InvalidObj { .. }), "{error}");
    assert_names_file(&error, "test.mtl");
    assert!(
        error
            .to_string()
            .contains("line 2: 'Kd' needs three numbers, found 2"),
        "{error}"
    );
}

/// Found by the `obj_mtl` fuzzer: an OBJ repeating `mtllib` read the library (and added its
/// materials) once per line.
#[test]
fn repeated_material_library_is_read_once() {
    let dir = tempfile::tempdir().unwrap();
    let obj = format!("{}{QUAD_OBJ}", "mtllib test.mtl\n".repeat(100));
    let scene = load(write_obj(dir.path(), &obj, "newmtl m\nKd 1 0 0\n")).unwrap();
    // The library's material and the default one.
    assert_eq!(scene.materials.len(), 2, "{:?}", scene.materials);
}

#[test]
fn obj_face_index_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let error = load(write_obj(
        dir.path(),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
        "",
    ))
    .unwrap_err();
    assert!(matches!(error, SceneError::InvalidObj { .. }), "{error}");
    assert!(error.to_string().contains("out of bounds"), "{error}");
}

#[test]
fn obj_missing_texture_and_mtl() {
    let dir = tempfile::tempdir().unwrap();
    let error = load(write_obj(
        dir.path(),
        QUAD_OBJ,
        "newmtl m\nmap_Kd absent.jpg\n",
    ))
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::MissingReferencedFile {
                kind: "texture",
                ..
            }
        ),
        "{error}"
    );
    assert_names_file(&error, "absent.jpg");
    let path = dir.path().join("nomtl.obj");
    std::fs::write(&path, QUAD_OBJ.replace("test.mtl", "missing.mtl")).unwrap();
    let error = load(&path).unwrap_err();
    assert!(
        matches!(error, SceneError::MissingReferencedFile { .. }),
        "{error}"
    );
    assert_names_file(&error, "missing.mtl");
}

#[test]
fn obj_non_finite_position() {
    let dir = tempfile::tempdir().unwrap();
    let error = load(write_obj(
        dir.path(),
        "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n",
        "",
    ))
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::NonFinitePosition { .. } | SceneError::InvalidObj { .. }
        ),
        "{error}"
    );
}

#[test]
fn degenerate_normals_from_the_file_are_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n";
    let scene = load(write_obj(dir.path(), obj, "")).unwrap();
    assert!(
        scene.meshes[0]
            .normals
            .iter()
            .all(|n| n.abs_diff_eq(Vec3::Z, 1e-6))
    );
}

// Hostile scenes (issue 9's part that the loaders own): references outside the folder,
// absurd hierarchies and textures. Each is a clear error or a warning, never a panic or an
// unbounded allocation.

#[test]
fn references_outside_the_scene_folder_are_refused() {
    for uri in [
        "../../etc/passwd",
        "/etc/passwd",
        "textures/../../secret.bin",
    ] {
        let error = load_edited(|doc, _| doc["buffers"][0]["uri"] = json!(uri)).unwrap_err();
        assert!(
            matches!(error, SceneError::OutsideSceneFolder { kind: "buffer", .. }),
            "{uri}: {error}"
        );
        assert!(error.to_string().contains(uri), "{error}");
    }
    // Allowed explicitly, the same file is read (and then found wanting as a buffer).
    let dir = tempfile::tempdir().unwrap();
    let (mut document, bin) = triangle_gltf(TRIANGLE, false);
    document["buffers"][0]["uri"] = json!("/etc/hostname");
    let path = write(dir.path(), &document, &bin);
    let options = manylights_scene::LoadOptions {
        allow_outside_folder: true,
    };
    let error = manylights_scene::load_with(&path, &options).unwrap_err();
    assert!(
        !matches!(error, SceneError::OutsideSceneFolder { .. }),
        "{error}"
    );
    // OBJ textures and material libraries too.
    let error = load(write_obj(
        dir.path(),
        QUAD_OBJ,
        "newmtl m\nmap_Kd ../outside.png\n",
    ))
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::OutsideSceneFolder {
                kind: "texture",
                ..
            }
        ),
        "{error}"
    );
    let obj = dir.path().join("escape.obj");
    std::fs::write(&obj, QUAD_OBJ.replace("test.mtl", "../../etc/passwd")).unwrap();
    let error = load(&obj).unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::OutsideSceneFolder {
                kind: "material library",
                ..
            }
        ),
        "{error}"
    );
}

#[test]
fn deep_and_cyclic_node_hierarchies_are_errors() {
    let deep = load_edited(|doc, _| {
        let mut nodes: Vec<Value> = (0..300).map(|i| json!({"children": [i + 1]})).collect();
        nodes.push(json!({"mesh": 0}));
        doc["nodes"] = json!(nodes);
    })
    .unwrap_err();
    assert!(deep.to_string().contains("deeper than"), "{deep}");
    let cyclic = load_edited(|doc, _| {
        doc["nodes"] = json!([{"children": [1], "mesh": 0}, {"children": [0]}])
    })
    .unwrap_err();
    assert!(matches!(cyclic, SceneError::InvalidGltf { .. }), "{cyclic}");
}

/// CRC-32 (IEEE) for hand-made PNG chunks.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= byte as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn a_100000_by_100000_texture_is_refused_with_a_warning() {
    // A PNG header claiming 100,000 x 100,000 RGBA pixels (40 GB decoded), and no data.
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    png.extend_from_slice(&13u32.to_be_bytes());
    png.extend_from_slice(&ihdr);
    png.extend_from_slice(&crc32(&ihdr).to_be_bytes());
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("huge.png"), &png).unwrap();
    let (mut document, bin) = triangle_gltf(TRIANGLE, true);
    document["images"] = json!([{"uri": "huge.png"}]);
    document["textures"] = json!([{"source": 0}]);
    document["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    document["meshes"][0]["primitives"][0]["material"] = json!(0);
    let scene = load(write(dir.path(), &document, &bin)).expect("loads with a fallback texture");
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(scene.warnings[0].message.contains("huge.png"));
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (2, 2));
}

/// Appends `data` to the buffer as a new view; returns the view's index.
fn push_view(document: &mut Value, bin: &mut Vec<u8>, data: &[u8]) -> usize {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let offset = bin.len();
    bin.extend_from_slice(data);
    document["buffers"][0]["byteLength"] = json!(bin.len());
    let views = document["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": data.len()}));
    views.len() - 1
}

/// Gives the triangle's POSITION accessor sparse values: `indices` (as `component_type`:
/// 5121 u8, 5123 u16, 5125 u32) replaced by `values`.
fn sparse_positions(
    component_type: u32,
    indices: &[u32],
    values: &[[f32; 3]],
    count: usize,
) -> Result<manylights_scene::Scene, SceneError> {
    let indices = indices.to_vec();
    let values = values.to_vec();
    load_edited(move |document, bin| {
        let index_bytes: Vec<u8> = indices
            .iter()
            .flat_map(|&i| match component_type {
                5121 => vec![i as u8],
                5123 => (i as u16).to_le_bytes().to_vec(),
                _ => i.to_le_bytes().to_vec(),
            })
            .collect();
        let value_bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let index_view = push_view(document, bin, &index_bytes);
        let value_view = push_view(document, bin, &value_bytes);
        document["accessors"][0]["sparse"] = json!({
            "count": count,
            "indices": {"bufferView": index_view, "componentType": component_type},
            "values": {"bufferView": value_view},
        });
        // min/max must still hold the replaced positions.
        document["accessors"][0]["min"] = json!([-1.0, -1.0, -1.0]);
        document["accessors"][0]["max"] = json!([2.0, 2.0, 2.0]);
    })
}

/// Sparse accessors replace the listed elements, with indices of every width; the sparse
/// data must fit its views and address elements of the accessor.
#[test]
fn sparse_positions_replace_their_elements() {
    for component_type in [5121, 5123, 5125] {
        let scene = sparse_positions(
            component_type,
            &[0, 2],
            &[[-1.0, -1.0, 0.0], [0.5, 2.0, 0.0]],
            2,
        )
        .unwrap_or_else(|e| panic!("component type {component_type}: {e}"));
        assert_eq!(
            scene.meshes[0].positions,
            vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::X,
                Vec3::new(0.5, 2.0, 0.0)
            ],
            "component type {component_type}"
        );
    }
    // As many sparse values as elements: every one replaced.
    let moved = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
    let scene = sparse_positions(5121, &[0, 1, 2], &moved, 3).expect("a full replacement");
    assert_eq!(
        scene.meshes[0].positions,
        moved.map(Vec3::from_array).to_vec()
    );
    // Index 3 is past the triangle's 3 elements; index 2 (above) is the last one.
    let error = sparse_positions(5123, &[3], &[[0.0; 3]], 1).unwrap_err();
    assert!(error.to_string().contains("sparse index 3"), "{error}");
    // Four sparse values for a three-element accessor.
    let error = sparse_positions(5123, &[0, 1, 2, 0], &[[0.0; 3]; 4], 4).unwrap_err();
    assert!(error.to_string().contains("4 sparse values"), "{error}");
    // The declared count needs more data than the views hold.
    let error = sparse_positions(5125, &[0], &[[0.0; 3]], 2).unwrap_err();
    assert!(error.to_string().contains("sparse data"), "{error}");
}

/// Attributes in a shape or component type glTF does not allow are refused before the
/// gltf crate's readers see them (they panic on some).
#[test]
fn attributes_of_the_wrong_format_are_refused() {
    let cases: [(&str, Value, &str); 4] = [
        (
            "TANGENT",
            json!({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}),
            "TANGENT accessor",
        ),
        (
            "POSITION",
            // UNSIGNED_INT positions: not even KHR_mesh_quantization allows them.
            json!({"bufferView": 0, "componentType": 5125, "count": 3, "type": "VEC3",
            "min": [0, 0, 0], "max": [1, 1, 0]}),
            "POSITION accessor",
        ),
        (
            "NORMAL",
            json!({"bufferView": 1, "componentType": 5123, "count": 3, "type": "VEC3"}),
            "NORMAL accessor",
        ),
        (
            "TEXCOORD_0",
            json!({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}),
            "TEXCOORD_0 accessor",
        ),
    ];
    for (semantic, accessor, expected) in cases {
        let error = load_edited(|document, _| {
            let accessors = document["accessors"].as_array_mut().unwrap();
            accessors.push(accessor);
            let index = accessors.len() - 1;
            document["meshes"][0]["primitives"][0]["attributes"][semantic] = json!(index);
        })
        .unwrap_err();
        assert!(error.to_string().contains(expected), "{semantic}: {error}");
        assert_names_file(&error, "triangle.gltf");
    }
}

/// An image in a buffer view needs a mimeType (the gltf crate unwraps it).
#[test]
fn an_image_in_a_buffer_view_without_a_mime_type_is_refused() {
    let error = load_edited(|document, _| {
        document["images"] = json!([{"bufferView": 0}]);
    })
    .unwrap_err();
    assert!(error.to_string().contains("no mimeType"), "{error}");
}

/// The hierarchy limit is exact: 256 levels below the root load, 257 do not.
#[test]
fn node_hierarchies_load_up_to_the_depth_limit() {
    let chain = |levels: usize| {
        load_edited(move |document, _| {
            let mut nodes: Vec<Value> = (0..levels).map(|i| json!({"children": [i + 1]})).collect();
            nodes.push(json!({"mesh": 0}));
            document["nodes"] = json!(nodes);
        })
    };
    chain(256).expect("256 levels below the root");
    let error = chain(257).unwrap_err();
    assert!(error.to_string().contains("deeper than 256"), "{error}");
}

/// Texture decoding may use up to 1 GiB (a 16384^2 RGBA image): a 4200^2 texture (70 MB)
/// decodes, not falls back.
#[test]
fn large_textures_decode_within_the_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(4200, 4200, image::Rgba([10, 20, 30, 255]))
        .save(dir.path().join("large.png"))
        .unwrap();
    let (mut document, bin) = triangle_gltf(TRIANGLE, true);
    document["images"] = json!([{"uri": "large.png"}]);
    document["textures"] = json!([{"source": 0}]);
    document["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    document["meshes"][0]["primitives"][0]["material"] = json!(0);
    let scene = load(write(dir.path(), &document, &bin)).expect("loads");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(
        (scene.textures[0].width, scene.textures[0].height),
        (4200, 4200)
    );
}

/// map_d is sampled nearest into the base colour's alpha whatever its size, as the
/// luminance 0.2126 R + 0.7152 G + 0.0722 B; MTL colours decode from sRGB on both sides of
/// the linear segment.
#[test]
fn obj_masks_are_resampled_and_colours_decoded() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([255, 255, 255, 255]))
        .save(dir.path().join("kd.png"))
        .unwrap();
    let mask = image::RgbaImage::from_fn(2, 2, |x, y| match (x, y) {
        (0, 0) => image::Rgba([100, 50, 200, 255]),
        (1, 0) => image::Rgba([0, 0, 255, 255]),
        (0, 1) => image::Rgba([255, 0, 0, 255]),
        _ => image::Rgba([0, 255, 0, 255]),
    });
    mask.save(dir.path().join("mask.png")).unwrap();
    let mtl = "newmtl m\nmap_Kd kd.png\nmap_d mask.png\n";
    let scene = load(write_obj(dir.path(), QUAD_OBJ, mtl)).expect("obj loads");
    let material = &scene.materials[scene.meshes[0].material];
    let texture = &scene.textures[material.base_color_texture.unwrap()];
    // 100, 50, 200 -> 71.46; blue 255 -> 18.41; red -> 54.21; green -> 182.38.
    let quadrant = [[71u8, 18], [54, 182]];
    for y in 0..4 {
        for x in 0..4 {
            assert_eq!(
                texture.rgba8[(y * 4 + x) * 4 + 3],
                quadrant[y / 2][x / 2],
                "alpha at ({x}, {y})"
            );
        }
    }
    // Without map_Kd, Kd is the colour: 0.02 is on the linear segment (0.02 / 12.92),
    // 0.5 and 1.0 on the power curve.
    let scene = load(write_obj(
        dir.path(),
        QUAD_OBJ,
        "newmtl m\nKd 0.02 0.5 1.0\n",
    ))
    .unwrap();
    let material = &scene.materials[scene.meshes[0].material];
    let expected = Vec3::new(0.02 / 12.92, 0.214_041, 1.0);
    assert!(
        material
            .base_color_factor
            .truncate()
            .abs_diff_eq(expected, 1e-5),
        "{}",
        material.base_color_factor
    );
}

/// Scene files over 2 GiB are refused before they are read: a sparse file on disk (no data
/// written) and a zero-filled buffer in memory (pages never touched). (Exactly 2 GiB is
/// allowed; a test of that would read or parse all of it.)
#[test]
fn scene_files_over_the_size_limit_are_refused_unread() {
    let limit = manylights_scene::MAX_SCENE_FILE_BYTES;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.gltf");
    std::fs::File::create(&path)
        .unwrap()
        .set_len(limit + 1)
        .unwrap();
    let error = load(&path).unwrap_err();
    assert!(matches!(error, SceneError::LimitExceeded { .. }), "{error}");
    assert_names_file(&error, "huge.gltf");
    let files = manylights_scene::MemoryFiles::new();
    let over = vec![0u8; limit as usize + 1];
    let error = manylights_scene::load_from_memory("huge.gltf", &over, &files).unwrap_err();
    assert!(matches!(error, SceneError::LimitExceeded { .. }), "{error}");
}
