//! What the fuzz targets (`fuzz/`) feed to the loaders, in one place so that the
//! regression tests (`tests/fuzz_regressions.rs`) replay crash inputs exactly as the
//! fuzzer ran them, without the fuzzer.
//!
//! Each entry point loads the input from memory and, when the load succeeds, checks the
//! invariants every pipeline relies on (indices inside their mesh, finite positions, valid
//! material/texture/mesh references, texel data matching the declared size), panicking on
//! a violation so that the fuzzer reports it as a crash. Loader errors are fine: they are
//! the expected answer to a bad file.

use crate::{MemoryFiles, Scene, export, load_from_memory, procedural};

/// Separates the OBJ part of an `obj_mtl` input from the MTL part.
pub const MTL_SEPARATOR: &[u8] = b"\n%%MTL%%\n";

/// Name under which the MTL part is offered (`mtllib scene.mtl`).
pub const MTL_NAME: &str = "scene.mtl";

/// The files every input may reference besides what it carries itself: a small binary
/// buffer and the textures of the exported seed scene.
fn referenced_files() -> &'static MemoryFiles {
    static FILES: std::sync::OnceLock<MemoryFiles> = std::sync::OnceLock::new();
    FILES.get_or_init(make_referenced_files)
}

fn make_referenced_files() -> MemoryFiles {
    let mut files = MemoryFiles::new();
    files.insert("scene.bin", (0..=255u8).cycle().take(4096).collect());
    if let Ok(exported) = export::export(&seed_scene(), export::ExportFormat::Obj, "seed") {
        for (name, bytes) in exported.files {
            if name.ends_with(".png") {
                files.insert(name, bytes);
            }
        }
    }
    files
}

/// A glTF JSON document (`.gltf`).
pub fn gltf_json(data: &[u8]) -> crate::Result<Scene> {
    check("fuzz.gltf", data, referenced_files())
}

/// A binary glTF (`.glb`).
pub fn glb(data: &[u8]) -> crate::Result<Scene> {
    check("fuzz.glb", data, referenced_files())
}

/// An OBJ file, optionally followed by [`MTL_SEPARATOR`] and the MTL file it names as
/// [`MTL_NAME`].
pub fn obj_mtl(data: &[u8]) -> crate::Result<Scene> {
    let mut files = referenced_files().clone();
    let obj = match find(data, MTL_SEPARATOR) {
        Some(at) => {
            let (obj, separator_and_mtl) = data.split_at(at);
            let mtl = separator_and_mtl
                .strip_prefix(MTL_SEPARATOR)
                .unwrap_or_default();
            files.insert(MTL_NAME, mtl.to_vec());
            obj
        }
        None => data,
    };
    check("fuzz.obj", obj, &files)
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack
        .windows(needle.len())
        .position(|window| window == needle)
}

/// The load's outcome (returned so that tests can tell a loaded input from a refused one;
/// the fuzz targets ignore it).
fn check(name: &str, data: &[u8], files: &MemoryFiles) -> crate::Result<Scene> {
    let scene = load_from_memory(name, data, files)?;
    assert_scene_invariants(&scene);
    Ok(scene)
}

/// Panics when `scene` breaks an invariant the renderers rely on.
pub fn assert_scene_invariants(scene: &Scene) {
    for (index, mesh) in scene.meshes.iter().enumerate() {
        let vertices = mesh.positions.len();
        assert!(
            mesh.indices.len().is_multiple_of(3),
            "mesh {index}: index count"
        );
        assert!(
            mesh.indices.iter().all(|&i| (i as usize) < vertices),
            "mesh {index}: index past the vertices"
        );
        assert_eq!(mesh.normals.len(), vertices, "mesh {index}: normals");
        assert_eq!(mesh.uvs.len(), vertices, "mesh {index}: uvs");
        if let Some(tangents) = &mesh.tangents {
            assert_eq!(tangents.len(), vertices, "mesh {index}: tangents");
            assert!(
                tangents.iter().all(|t| t.is_finite()),
                "mesh {index}: tangents"
            );
        }
        assert!(
            mesh.positions.iter().all(|p| p.is_finite()),
            "mesh {index}: non-finite position"
        );
        assert!(
            mesh.normals.iter().all(|n| n.is_finite()),
            "mesh {index}: non-finite normal"
        );
        assert!(
            mesh.material < scene.materials.len(),
            "mesh {index}: material"
        );
    }
    for instance in &scene.instances {
        assert!(instance.mesh < scene.meshes.len(), "instance mesh");
    }
    for (index, material) in scene.materials.iter().enumerate() {
        for texture in [material.base_color_texture, material.normal_texture]
            .into_iter()
            .flatten()
        {
            assert!(texture < scene.textures.len(), "material {index}: texture");
        }
    }
    for (index, texture) in scene.textures.iter().enumerate() {
        assert!(
            texture.width > 0 && texture.height > 0,
            "texture {index}: size"
        );
        assert_eq!(
            texture.rgba8.len() as u64,
            u64::from(texture.width) * u64::from(texture.height) * 4,
            "texture {index}: texel data"
        );
    }
}

/// The scene the seed corpus is exported from: Cornell with a masked texture and a normal
/// map, so that seeds touch every loader path.
pub fn seed_scene() -> Scene {
    let mut scene = procedural::cornell();
    // Cornell's own 64x64 textures would make every seed large (slow to mutate): all
    // textured materials use one 4x4 texture instead.
    scene.textures.clear();
    for material in &mut scene.materials {
        if material.base_color_texture.is_some() {
            material.base_color_texture = Some(0);
        }
    }
    let texels: Vec<u8> = (0..16u8)
        .flat_map(|i| [i * 16, 255 - i * 16, 128, if i % 2 == 0 { 255 } else { 0 }])
        .collect();
    scene.textures.push(crate::Texture {
        source: "checker".into(),
        width: 4,
        height: 4,
        color_space: crate::ColorSpace::Srgb,
        rgba8: texels,
    });
    scene.textures.push(crate::Texture {
        source: "flat normal".into(),
        width: 1,
        height: 1,
        color_space: crate::ColorSpace::Linear,
        rgba8: vec![128, 128, 255, 255],
    });
    scene.materials[0].base_color_texture = Some(0);
    scene.materials[0].base_color_factor = glam::Vec4::ONE;
    scene.materials[0].alpha_mode = crate::AlphaMode::Mask { cutoff: 0.5 };
    scene.materials[1].normal_texture = Some(1);
    scene
}

/// Seed inputs for each target, as `(target, file name, bytes)`: the seed scene exported
/// in each format plus a one-triangle scene, so the corpus is small and fast to mutate.
pub fn seeds() -> Vec<(&'static str, String, Vec<u8>)> {
    let mut out = Vec::new();
    let triangle = procedural_triangle();
    for (label, scene) in [("cornell", seed_scene()), ("triangle", triangle)] {
        use export::ExportFormat::*;
        for (target, format) in [("gltf_json", GltfEmbedded), ("glb", Glb), ("obj_mtl", Obj)] {
            let Ok(exported) = export::export(&scene, format, "scene") else {
                continue;
            };
            let mut bytes = exported.main_bytes().to_vec();
            if format == Obj {
                bytes.extend_from_slice(MTL_SEPARATOR);
                bytes.extend_from_slice(&exported.files[MTL_NAME]);
            }
            out.push((target, label.to_string(), bytes));
        }
    }
    out.push(("gltf_json", "optimized".into(), optimized_seed()));
    out
}

/// A triangle as optimizers write it, so the fuzzers start inside the newer paths:
/// `KHR_mesh_quantization` positions (SHORT) in an `EXT_meshopt_compression` view whose
/// fallback buffer has no data, a zero accessor with sparse values, emissive strength, a
/// triangle strip, and two `EXT_mesh_gpu_instancing` instances (zero translations).
fn optimized_seed() -> Vec<u8> {
    use base64::Engine as _;
    let positions: Vec<[i16; 4]> = vec![[0, 0, 0, 0], [1000, 0, 0, 0], [0, 1000, 0, 0]];
    let compressed = meshopt::encode_vertex_buffer(&positions).unwrap_or_default();
    let mut bin = compressed.clone();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let sparse_at = bin.len();
    bin.extend_from_slice(&[2, 0, 0, 0]);
    for value in [0.5f32, 0.5] {
        bin.extend_from_slice(&value.to_le_bytes());
    }
    let document = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_mesh_quantization", "EXT_meshopt_compression",
            "KHR_materials_emissive_strength", "EXT_mesh_gpu_instancing"],
        "extensionsRequired": ["KHR_mesh_quantization", "EXT_meshopt_compression"],
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "scale": [0.001, 0.001, 0.001],
            "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 2}}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
            "material": 0, "mode": 5}]}],
        "materials": [{"emissiveFactor": [1.0, 0.5, 0.0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}}],
        "accessors": [
            {"bufferView": 1, "componentType": 5122, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1000, 1000, 0]},
            {"componentType": 5126, "count": 3, "type": "VEC2",
             "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5121},
                        "values": {"bufferView": 2, "byteOffset": 4}}},
            {"componentType": 5126, "count": 2, "type": "VEC3"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": compressed.len()},
            {"buffer": 1, "byteLength": 24, "byteStride": 8,
             "extensions": {"EXT_meshopt_compression": {"buffer": 0, "byteLength": compressed.len(),
                 "byteStride": 8, "count": 3, "mode": "ATTRIBUTES"}}},
            {"buffer": 0, "byteOffset": sparse_at, "byteLength": 12},
        ],
        "buffers": [
            {"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&bin))},
            {"byteLength": 24, "extensions": {"EXT_meshopt_compression": {"fallback": true}}},
        ],
    });
    serde_json::to_vec(&document).unwrap_or_default()
}

/// One textured triangle: the smallest input that reaches every stage of a loader.
fn procedural_triangle() -> Scene {
    let mut scene = seed_scene();
    let mesh = &mut scene.meshes[0];
    mesh.positions.truncate(3);
    mesh.normals.truncate(3);
    mesh.uvs.truncate(3);
    mesh.indices = vec![0, 1, 2];
    mesh.tangents = None;
    mesh.bounds = crate::bounds_of(&mesh.positions);
    scene.meshes.truncate(1);
    scene.instances.retain(|instance| instance.mesh == 0);
    scene.instances.truncate(1);
    scene.materials.truncate(2);
    scene
}
