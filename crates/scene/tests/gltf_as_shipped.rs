//! glTF as people ship it (issue 31): files the specification calls valid that the `gltf`
//! crate alone refuses, and the extensions optimized assets use. Each test builds a small
//! document in memory with one feature and checks what the loader made of it; Sponza
//! quantized and meshopt-compressed by gltfpack (`assets/sponza/sponza-*.glb`) must give
//! the original geometry within what quantization can move.

#![allow(clippy::unwrap_used)] // test helpers: a failed setup step should just fail the test

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use manylights_scene::{MemoryFiles, Scene, SceneError, load, load_from_memory};
use serde_json::{Value, json};

/// A document under construction: one binary buffer (`scene.bin`) of aligned views.
struct Doc {
    json: Value,
    bin: Vec<u8>,
}

impl Doc {
    /// A triangle in the unit square (float positions, u16 indices), no normals.
    fn triangle() -> Doc {
        let mut doc = Doc {
            json: json!({
                "asset": {"version": "2.0"},
                "scene": 0,
                "scenes": [{"nodes": [0]}],
                "nodes": [{"mesh": 0}],
                "meshes": [{"primitives": [{"attributes": {}}]}],
                "accessors": [],
                "bufferViews": [],
                "buffers": [],
            }),
            bin: Vec::new(),
        };
        let positions = doc.view(&f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]));
        let position = doc.accessor(json!({"bufferView": positions, "componentType": 5126,
            "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}));
        let indices = doc.view(&[0u8, 0, 1, 0, 2, 0]);
        let index = doc.accessor(
            json!({"bufferView": indices, "componentType": 5123, "count": 3, "type": "SCALAR"}),
        );
        doc.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(position);
        doc.json["meshes"][0]["primitives"][0]["indices"] = json!(index);
        doc
    }

    /// Appends bytes (4-aligned) as a buffer view; returns its index.
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        views.len() - 1
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        let accessors = self.json["accessors"].as_array_mut().unwrap();
        accessors.push(accessor);
        accessors.len() - 1
    }

    fn primitive(&mut self) -> &mut Value {
        &mut self.json["meshes"][0]["primitives"][0]
    }

    fn load(mut self) -> Result<Scene, SceneError> {
        self.json["buffers"] = json!([{"uri": "scene.bin", "byteLength": self.bin.len()}]);
        let mut files = MemoryFiles::new();
        files.insert("scene.bin", self.bin);
        let text = serde_json::to_vec(&self.json).unwrap();
        load_from_memory("scene.gltf", &text, &files)
    }
}

fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

#[test]
fn whole_numbers_written_as_floats_and_animations_without_a_node_load() {
    let mut doc = Doc::triangle();
    // glTF's integers are JSON numbers: 3.0 is a valid count.
    doc.json["accessors"][0]["count"] = json!(3.0);
    doc.json["scene"] = json!(0.0);
    // An animation channel whose target has no node (valid; KHR_animation_pointer uses it).
    doc.json["animations"] = json!([{"channels": [{"sampler": 0, "target": {"path": "pointer"}}],
        "samplers": [{"input": 0, "output": 0}]}]);
    let scene = doc.load().unwrap();
    assert_eq!(scene.triangle_count(), 1);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.message.contains("animation")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn an_accessor_without_a_buffer_view_is_zeros_with_sparse_values() {
    let mut doc = Doc::triangle();
    // Positions: zeros, with vertices 1 and 2 given by sparse values (u8 indices).
    let indices = doc.view(&[1u8, 2]);
    let values = doc.view(&f32_bytes(&[2.0, 0.0, 0.0, 0.0, 3.0, 0.0]));
    let position = doc.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3",
        "min": [0, 0, 0], "max": [2, 3, 0],
        "sparse": {"count": 2, "indices": {"bufferView": indices, "componentType": 5121},
                   "values": {"bufferView": values}}}));
    // A TEXCOORD_0 accessor with neither a view nor sparse data: all zeros.
    let uv = doc.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC2"}));
    doc.primitive()["attributes"] = json!({"POSITION": position, "TEXCOORD_0": uv});
    let scene = doc.load().unwrap();
    let mesh = &scene.meshes[0];
    assert_eq!(
        mesh.positions,
        [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0)
        ]
    );
    assert_eq!(mesh.uvs, [Vec2::ZERO; 3]);

    // A zero accessor with a forged count is refused, not allocated.
    let mut doc = Doc::triangle();
    let huge =
        doc.accessor(json!({"componentType": 5126, "count": 4_000_000_000u64, "type": "VEC2"}));
    doc.primitive()["attributes"]["TEXCOORD_0"] = json!(huge);
    let error = doc.load().unwrap_err();
    assert!(error.to_string().contains("no buffer view"), "{error}");
}

#[test]
fn quantized_attributes_of_every_allowed_type_dequantize_by_the_specification() {
    // KHR_mesh_quantization: positions as SHORT (scaled by the node), normals as
    // normalized BYTE, UVs as normalized UNSIGNED_SHORT and as unnormalized BYTE.
    let mut doc = Doc::triangle();
    doc.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    doc.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let shorts: Vec<u8> = [0i16, 0, 0, 0, 1000, 0, 0, 0, 0, 0, -1000, 0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    // Stride 8: three shorts and padding per vertex.
    let positions = doc.view(&shorts);
    doc.json["bufferViews"][positions]["byteStride"] = json!(8);
    let position = doc.accessor(json!({"bufferView": positions, "componentType": 5122,
        "count": 3, "type": "VEC3", "min": [0, 0, -1000], "max": [1000, 0, 0]}));
    let normals = doc.view(&[0u8, 127, 0, 0, 0, 0, 127, 0, 0x81, 0, 0, 0]);
    let normal = doc.accessor(
        json!({"bufferView": normals, "byteOffset": 0, "componentType": 5120,
        "normalized": true, "count": 3, "type": "VEC3"}),
    );
    doc.json["bufferViews"][normals]["byteStride"] = json!(4);
    let uv_bytes: Vec<u8> = [0u16, 0, 65535, 0, 0, 32768]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let uvs = doc.view(&uv_bytes);
    let uv = doc.accessor(
        json!({"bufferView": uvs, "componentType": 5123, "normalized": true,
        "count": 3, "type": "VEC2"}),
    );
    let signed_uvs = doc.view(&[0u8, 0, 2, 0, 0, 0xfe]);
    let signed_uv = doc.accessor(json!({"bufferView": signed_uvs, "componentType": 5120,
        "count": 3, "type": "VEC2"}));
    doc.primitive()["attributes"] =
        json!({"POSITION": position, "NORMAL": normal, "TEXCOORD_0": uv, "TEXCOORD_1": signed_uv});
    // gltfpack's dequantization: the node scales the integers back to metres.
    doc.json["nodes"][0]["scale"] = json!([0.001, 0.001, 0.001]);
    let scene = doc.load().unwrap();
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.positions[1], Vec3::new(1000.0, 0.0, 0.0));
    assert_eq!(mesh.positions[2], Vec3::new(0.0, 0.0, -1000.0));
    let world = scene.bounds();
    assert!(
        world.max.abs_diff_eq(Vec3::new(1.0, 0.0, 0.0), 1e-6),
        "{world:?}"
    );
    assert_eq!(mesh.normals[0], Vec3::Y);
    assert_eq!(mesh.normals[1], Vec3::Z);
    assert_eq!(mesh.normals[2], Vec3::NEG_X, "-127/127 = -1");
    assert_eq!(mesh.uvs[1], Vec2::new(1.0, 0.0));
    assert!((mesh.uvs[2].y - 32768.0 / 65535.0).abs() < 1e-7);

    // Storage glTF does not allow stays an error naming the accessor.
    let mut doc = Doc::triangle();
    let normals = doc.view(&[0u8; 12]);
    let normal = doc.accessor(json!({"bufferView": normals, "componentType": 5121,
        "normalized": true, "count": 3, "type": "VEC3"}));
    doc.primitive()["attributes"]["NORMAL"] = json!(normal);
    let error = doc.load().unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("NORMAL accessor") && message.contains("UNSIGNED_BYTE"),
        "{message}"
    );
}

fn material_with_texture(extension: Value) -> Doc {
    let mut doc = Doc::triangle();
    let uvs = doc.view(&f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]));
    let uv = doc.accessor(json!({"bufferView": uvs, "componentType": 5126, "count": 3,
        "type": "VEC2"}));
    doc.primitive()["attributes"]["TEXCOORD_0"] = json!(uv);
    doc.primitive()["material"] = json!(0);
    // A 1x1 PNG as a data URI.
    let png = {
        let mut bytes = Vec::new();
        image::RgbaImage::from_pixel(1, 1, image::Rgba([255, 128, 0, 255]))
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .unwrap();
        use base64::Engine as _;
        format!(
            "data:image/png;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(bytes)
        )
    };
    doc.json["images"] = json!([{"uri": png}]);
    doc.json["textures"] = json!([{"source": 0}]);
    doc.json["materials"] = json!([{
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": extension}},
        "emissiveFactor": [1.0, 0.5, 0.25],
        "emissiveTexture": {"index": 0, "extensions": extension},
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
    }]);
    doc.json["extensionsUsed"] =
        json!(["KHR_texture_transform", "KHR_materials_emissive_strength"]);
    doc.json["extensionsRequired"] = json!(["KHR_texture_transform"]);
    doc
}

#[test]
fn texture_transforms_are_baked_into_the_uvs_and_emissive_strength_scales_emission() {
    let transform = json!({"KHR_texture_transform": {"offset": [0.5, 0.25],
        "rotation": std::f32::consts::FRAC_PI_2, "scale": [2.0, 3.0]}});
    let scene = material_with_texture(transform).load().unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let uvs = &scene.meshes[0].uvs;
    // uv' = offset + R S uv with R = [[cos, sin], [-sin, cos]] (the extension's rotation):
    // (1, 0) -> scale (2, 0) -> rotate 90 degrees (0, -2) -> + offset (0.5, -1.75).
    assert!(uvs[0].abs_diff_eq(Vec2::new(0.5, 0.25), 1e-6), "{uvs:?}");
    assert!(uvs[1].abs_diff_eq(Vec2::new(0.5, -1.75), 1e-6), "{uvs:?}");
    assert!(uvs[2].abs_diff_eq(Vec2::new(3.5, 0.25), 1e-6), "{uvs:?}");
    let material = &scene.materials[0];
    assert_eq!(material.emissive_factor, Vec3::new(4.0, 2.0, 1.0));
    assert!(material.emissive_texture.is_some());
    assert!(scene.features().emissive);

    // Textures of one material asking for different UVs: the base colour's win, warned.
    let mut doc = material_with_texture(json!({"KHR_texture_transform": {"offset": [0.5, 0.0]}}));
    doc.json["materials"][0]["emissiveTexture"]["extensions"] = json!({});
    let scene = doc.load().unwrap();
    assert!(scene.meshes[0].uvs[0].abs_diff_eq(Vec2::new(0.5, 0.0), 1e-6));
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.message.contains("UV mapping")),
        "{:?}",
        scene.warnings
    );
    // A negative emissive strength is an error naming the material's extension.
    let mut doc = material_with_texture(json!({}));
    doc.json["materials"][0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] =
        json!(-1.0);
    let error = doc.load().unwrap_err();
    assert!(error.to_string().contains("emissiveStrength"), "{error}");
}

#[test]
fn morph_targets_apply_at_the_default_weights_and_skins_are_ignored_with_a_warning() {
    let mut doc = Doc::triangle();
    let deltas = doc.view(&f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]));
    let delta = doc.accessor(
        json!({"bufferView": deltas, "componentType": 5126, "count": 3,
        "type": "VEC3", "min": [0, 0, 1], "max": [0, 0, 1]}),
    );
    doc.primitive()["targets"] = json!([{"POSITION": delta}]);
    doc.json["meshes"][0]["weights"] = json!([0.5]);
    let joints = doc.accessor(json!({"componentType": 5126, "count": 1, "type": "MAT4"}));
    doc.json["skins"] = json!([{"joints": [0], "inverseBindMatrices": joints}]);
    doc.json["nodes"][0]["skin"] = json!(0);
    let scene = doc.load().unwrap();
    assert!(
        scene.meshes[0].positions.iter().all(|p| p.z == 0.5),
        "{:?}",
        scene.meshes[0].positions
    );
    assert!(
        scene.warnings.iter().any(|w| w.message.contains("skin")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn degenerate_triangles_are_skipped_and_a_file_without_a_scene_draws_its_root_nodes() {
    let mut doc = Doc::triangle();
    let indices = doc.view(&[0u8, 0, 1, 0, 2, 0, 0, 0, 0, 0, 1, 0]);
    let index = doc.accessor(
        json!({"bufferView": indices, "componentType": 5123, "count": 6, "type": "SCALAR"}),
    );
    doc.primitive()["indices"] = json!(index);
    let object = doc.json.as_object_mut().unwrap();
    object.remove("scene");
    object.remove("scenes");
    let scene = doc.load().unwrap();
    assert_eq!(scene.triangle_count(), 1);
    assert_eq!(scene.instances.len(), 1);
    let messages: Vec<&str> = scene.warnings.iter().map(|w| w.message.as_str()).collect();
    assert!(
        messages.iter().any(|m| m.contains("degenerate")),
        "{messages:?}"
    );
    assert!(
        messages.iter().any(|m| m.contains("no scene")),
        "{messages:?}"
    );
}

#[test]
fn application_specific_attributes_are_ignored() {
    let mut doc = Doc::triangle();
    let ids = doc.view(&f32_bytes(&[1.0, 2.0, 3.0]));
    let id = doc.accessor(json!({"bufferView": ids, "componentType": 5126, "count": 3,
        "type": "SCALAR"}));
    doc.primitive()["attributes"]["_FEATURE_ID_0"] = json!(id);
    assert_eq!(doc.load().unwrap().triangle_count(), 1);
}

#[test]
fn draco_and_unknown_required_extensions_are_refused_saying_what_to_do() {
    let mut doc = Doc::triangle();
    doc.json["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    doc.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let error = doc.load().unwrap_err();
    let message = error.to_string();
    assert!(
        matches!(error, SceneError::UnsupportedExtension { .. })
            && message.contains("KHR_draco_mesh_compression")
            && message.contains("gltfpack")
            && message.contains("scene.gltf"),
        "{message}"
    );
    // Used but not required: the uncompressed data is there, and it loads.
    let mut doc = Doc::triangle();
    doc.json["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    assert!(doc.load().is_ok());
}

#[test]
fn meshopt_compressed_views_decode_and_bad_streams_are_errors() {
    let positions: Vec<[f32; 3]> = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let encoded = meshopt::encode_vertex_buffer(&positions).unwrap();
    let build = |encoded: &[u8], count: usize| {
        let mut doc = Doc::triangle();
        doc.json["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
        doc.json["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
        let compressed = doc.view(encoded);
        let offset = doc.json["bufferViews"][compressed]["byteOffset"].clone();
        // The decoded view lives in a fallback buffer that has no data.
        doc.json["bufferViews"].as_array_mut().unwrap().push(json!({
            "buffer": 1, "byteLength": 36, "byteStride": 12,
            "extensions": {"EXT_meshopt_compression": {"buffer": 0,
                "byteOffset": offset,
                "byteLength": encoded.len(), "byteStride": 12, "count": count,
                "mode": "ATTRIBUTES"}}}));
        let view = doc.json["bufferViews"].as_array().unwrap().len() - 1;
        doc.json["accessors"][0]["bufferView"] = json!(view);
        doc
    };
    let finish = |doc: Doc| {
        let mut doc = doc;
        let bin_len = doc.bin.len();
        doc.json["buffers"] = json!([{"uri": "scene.bin", "byteLength": bin_len},
            {"byteLength": 36, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}]);
        let mut files = MemoryFiles::new();
        files.insert("scene.bin", doc.bin);
        load_from_memory(
            "scene.gltf",
            &serde_json::to_vec(&doc.json).unwrap(),
            &files,
        )
    };
    let scene = finish(build(&encoded, 3)).unwrap();
    assert_eq!(scene.meshes[0].positions[1], Vec3::X);
    assert_eq!(scene.meshes[0].positions[2], Vec3::Y);
    let garbage = vec![0xa0u8; encoded.len()];
    let error = finish(build(&garbage, 3)).unwrap_err();
    assert!(
        error.to_string().contains("meshopt-compressed buffer view"),
        "{error}"
    );
}

/// gltfpack's output for Sponza (`-vt 16`: 14-bit positions, 8-bit normals, 16-bit UVs;
/// and the same with meshopt compression, `-cc`) holds the original's geometry: the same
/// bounds to within one position quantization step, and the same triangle count.
#[test]
fn gltfpack_sponza_quantized_and_meshopt_match_the_original() {
    let original = load(assets().join("sponza/sponza.gltf")).unwrap();
    let bounds = original.bounds();
    // 14-bit positions over the largest extent: the step gltfpack rounds to, half of it
    // the largest error.
    let step = bounds.size().max_element() / ((1 << 14) - 1) as f32;
    for file in ["sponza-quantized.glb", "sponza-meshopt.glb"] {
        let packed = load(assets().join("sponza").join(file)).unwrap();
        assert!(packed.warnings.is_empty(), "{file}: {:?}", packed.warnings);
        assert_eq!(packed.triangle_count(), original.triangle_count(), "{file}");
        let b = packed.bounds();
        assert!(
            b.min.abs_diff_eq(bounds.min, step) && b.max.abs_diff_eq(bounds.max, step),
            "{file}: {b:?} vs {bounds:?} (step {step})"
        );
        assert_eq!(packed.textures.len(), original.textures.len(), "{file}");
    }
}

/// Khronos's SimpleInstancing (CC0, `assets/gltf-samples`): one unit cube on a node with
/// `EXT_mesh_gpu_instancing`, 125 instances; by its README the first is the unmodified
/// cube and the last sits at (10, 10, 10), scaled 2, turned 90 degrees about each axis:
/// x to y, y to z, z to x, which is 120 degrees about (1, 1, 1).
#[test]
fn gpu_instancing_bakes_every_instance() {
    use glam::{Mat4, Quat};
    let scene = load(assets().join("gltf-samples/SimpleInstancing/SimpleInstancing.glb")).unwrap();
    assert_eq!(scene.instances.len(), 125);
    assert_eq!(scene.triangle_count(), 125 * 12);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let close = |a: Mat4, b: Mat4| a.abs_diff_eq(b, 1e-5);
    assert!(close(scene.instances[0].transform, Mat4::IDENTITY));
    let last = Mat4::from_scale_rotation_translation(
        Vec3::splat(2.0),
        Quat::from_axis_angle(Vec3::ONE.normalize(), 120f32.to_radians()),
        Vec3::splat(10.0),
    );
    assert!(
        close(scene.instances[124].transform, last),
        "{}",
        scene.instances[124].transform
    );
}

/// Instancing attributes are checked: counts must agree, accessors must exist, and a
/// zero quaternion is an error naming the node, never a NaN transform.
#[test]
fn bad_instancing_attributes_are_errors_naming_the_node() {
    let instanced = |translations: &[f32], rotation: Option<&[f32]>| {
        let mut doc = Doc::triangle();
        let view = doc.view(&f32_bytes(translations));
        let translation = doc.accessor(json!({"bufferView": view, "componentType": 5126,
            "count": translations.len() / 3, "type": "VEC3"}));
        let mut attributes = json!({"TRANSLATION": translation});
        if let Some(rotation) = rotation {
            let view = doc.view(&f32_bytes(rotation));
            attributes["ROTATION"] = json!(doc.accessor(json!({"bufferView": view,
                "componentType": 5126, "count": rotation.len() / 4, "type": "VEC4"})));
        }
        doc.json["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing"]);
        doc.json["nodes"][0]["extensions"] =
            json!({"EXT_mesh_gpu_instancing": {"attributes": attributes}});
        doc
    };
    let two = instanced(&[0.0, 0.0, 0.0, 5.0, 0.0, 0.0], None)
        .load()
        .unwrap();
    assert_eq!(two.instances.len(), 2);
    assert_eq!(two.bounds().max.x, 6.0);

    let mismatched = instanced(&[0.0; 6], Some(&[0.0, 0.0, 0.0, 1.0])).load();
    let message = mismatched.unwrap_err().to_string();
    assert!(
        message.contains("node 0") && message.contains("different counts"),
        "{message}"
    );

    let zero = instanced(&[0.0; 3], Some(&[0.0; 4])).load();
    let message = zero.unwrap_err().to_string();
    assert!(
        message.contains("instance 0") && message.contains("not a transform"),
        "{message}"
    );

    let mut missing = instanced(&[0.0; 3], None);
    missing.json["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] =
        json!(99);
    let message = missing.load().unwrap_err().to_string();
    assert!(message.contains("accessor 99 does not exist"), "{message}");
}

/// An extension the file uses but manylights does not read is named in a warning (the
/// file is drawn without it), never dropped silently.
#[test]
fn used_extensions_that_are_not_read_are_named_in_a_warning() {
    let mut doc = Doc::triangle();
    doc.json["extensionsUsed"] = json!(["KHR_materials_sheen", "KHR_texture_transform"]);
    let scene = doc.load().unwrap();
    let warnings: Vec<&str> = scene.warnings.iter().map(|w| w.message.as_str()).collect();
    assert_eq!(
        warnings,
        ["extension(s) used but not read, drawn without them: KHR_materials_sheen"]
    );
}
