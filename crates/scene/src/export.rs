//! Writing a [`Scene`] as glTF 2.0 (`.gltf` with data URIs, or `.glb`) or as OBJ + MTL +
//! PNG textures, so that procedural scenes can be opened in other tools and so that the
//! fuzzers start from files this project wrote itself.
//!
//! What is kept: meshes (positions, normals, UVs, tangents, `u32` indices), instances,
//! textures (as PNG), the material fields each format has, and (glTF only) the scene's
//! point and spot lights as `KHR_lights_punctual`. What is not: glTF has no
//! Blinn-Phong specular (the loader derives it from metallic/roughness again); OBJ has no
//! instancing (transforms are baked into the vertices), no metallic/roughness, and an
//! alpha mask only through `map_d` (a texture's alpha) or `d` (a factor below one).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use glam::{Mat3, Vec3};
use serde_json::{Value, json};

// MTL colours are display colours (the loader decodes them).
use crate::color::linear_to_srgb;

use crate::files::MemoryFiles;
use crate::model::{AlphaMode, Material, Mesh, Scene, SceneLight, Texture};

/// File layout to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    /// One `.gltf` file; buffers and images are base64 data URIs.
    GltfEmbedded,
    /// One `.glb` file with a binary chunk.
    Glb,
    /// `.obj` + `.mtl` + `textures/N.png`.
    Obj,
}

/// Why a scene could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("texture {index} ('{source_name}'): {message}")]
    Texture {
        index: usize,
        source_name: String,
        message: String,
    },
    #[error("{path}: cannot write: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// An exported scene: its main file and the files it references, by relative path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExportedScene {
    pub main_file: String,
    pub files: BTreeMap<String, Vec<u8>>,
}

impl ExportedScene {
    pub fn main_bytes(&self) -> &[u8] {
        &self.files[&self.main_file]
    }

    /// The referenced files (everything but the main file), for [`crate::load_from_memory`].
    pub fn referenced(&self) -> MemoryFiles {
        let mut files = MemoryFiles::new();
        for (name, bytes) in &self.files {
            if *name != self.main_file {
                files.insert(name.clone(), bytes.clone());
            }
        }
        files
    }

    /// Writes every file into `folder` (created if needed); returns the main file's path.
    pub fn write_into(&self, folder: &Path) -> Result<PathBuf, ExportError> {
        for (name, bytes) in &self.files {
            let path = folder.join(name);
            let io = |source| ExportError::Io {
                path: path.clone(),
                source,
            };
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(io)?;
            }
            std::fs::write(&path, bytes).map_err(io)?;
        }
        Ok(folder.join(&self.main_file))
    }
}

/// Writes `scene` in `format`; files are named after `name` (`name.gltf`, `name.mtl`...).
pub fn export(
    scene: &Scene,
    format: ExportFormat,
    name: &str,
) -> Result<ExportedScene, ExportError> {
    match format {
        ExportFormat::GltfEmbedded | ExportFormat::Glb => export_gltf(scene, format, name),
        ExportFormat::Obj => export_obj(scene, name),
    }
}

fn png(scene: &Scene, index: usize) -> Result<Vec<u8>, ExportError> {
    let texture = &scene.textures[index];
    encode_png(texture).map_err(|message| ExportError::Texture {
        index,
        source_name: texture.source.clone(),
        message,
    })
}

fn encode_png(texture: &Texture) -> Result<Vec<u8>, String> {
    let image = image::RgbaImage::from_raw(texture.width, texture.height, texture.rgba8.clone())
        .ok_or_else(|| {
            format!(
                "{} bytes do not hold {}x{} RGBA8 texels",
                texture.rgba8.len(),
                texture.width,
                texture.height
            )
        })?;
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Accumulates the binary buffer and the views/accessors that describe it.
#[derive(Default)]
struct GltfBuffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl GltfBuffer {
    /// Appends `data` as a new buffer view (4-byte aligned); returns the view's index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut view = json!({
            "buffer": 0,
            "byteOffset": self.bytes.len(),
            "byteLength": data.len(),
        });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Appends float vectors of `width` components; returns the accessor's index.
    fn floats(&mut self, values: &[f32], width: usize, with_bounds: bool) -> usize {
        let view = self.view(&le_bytes(values), Some(ARRAY_BUFFER));
        let kind = ["SCALAR", "VEC2", "VEC3", "VEC4"][width - 1];
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": values.len() / width,
            "type": kind,
        });
        if with_bounds {
            let mut min = vec![f32::INFINITY; width];
            let mut max = vec![f32::NEG_INFINITY; width];
            for vector in values.chunks_exact(width) {
                for (axis, &value) in vector.iter().enumerate() {
                    min[axis] = min[axis].min(value);
                    max[axis] = max[axis].max(value);
                }
            }
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn indices(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": indices.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

impl GltfBuffer {
    /// The buffer padded to 4 bytes, and its JSON: a data URI for embedded glTF, the GLB's
    /// binary chunk otherwise.
    fn finish(&mut self, format: ExportFormat) -> Value {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut buffer_json = json!({ "byteLength": self.bytes.len() });
        if format == ExportFormat::GltfEmbedded {
            buffer_json["uri"] = json!(format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&self.bytes)
            ));
        }
        buffer_json
    }
}

const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// glTF buffers are little-endian.
fn le_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// `scene` as one glTF document (and, for GLB, its binary chunk) named `name`: the meshes
/// and images written into one buffer, then the materials, the nodes and the lights.
fn export_gltf(
    scene: &Scene,
    format: ExportFormat,
    name: &str,
) -> Result<ExportedScene, ExportError> {
    let mut buffer = GltfBuffer::default();
    let meshes: Vec<Value> = (scene.meshes.iter())
        .map(|mesh| mesh_json(mesh, &mut buffer))
        .collect();
    let images = (0..scene.textures.len())
        .map(|index| Ok(image_json(&png(scene, index)?, format, &mut buffer)))
        .collect::<Result<Vec<Value>, ExportError>>()?;
    let materials: Vec<Value> = scene.materials.iter().map(material_json).collect();
    let uses_emissive_strength = materials
        .iter()
        .any(|material| material.get("extensions").is_some());
    let mut nodes: Vec<Value> = (scene.instances.iter())
        .map(|instance| json!({ "mesh": instance.mesh, "matrix": instance.transform.to_cols_array() }))
        .collect();
    // The scene's lights (KHR_lights_punctual), each on its own node.
    let lights: Vec<Value> = scene.lights.iter().map(light_json).collect();
    nodes.extend(scene.lights.iter().enumerate().map(light_node_json));

    let buffer_json = buffer.finish(format);
    let mut document = json!({
        "asset": { "version": "2.0", "generator": "manylights-scene export" },
        "scene": 0,
        "scenes": [{ "name": scene.name, "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "buffers": [buffer_json],
        "bufferViews": buffer.views,
        "accessors": buffer.accessors,
    });
    let mut extensions_used = Vec::new();
    if !lights.is_empty() {
        extensions_used.push("KHR_lights_punctual");
        document["extensions"] = json!({ "KHR_lights_punctual": { "lights": lights } });
    }
    if uses_emissive_strength {
        extensions_used.push("KHR_materials_emissive_strength");
    }
    if !extensions_used.is_empty() {
        document["extensionsUsed"] = json!(extensions_used);
    }
    if !images.is_empty() {
        let textures: Vec<Value> = (0..images.len())
            .map(|index| json!({ "source": index }))
            .collect();
        document["images"] = json!(images);
        document["textures"] = json!(textures);
        document["samplers"] = json!([{}]);
    }
    sort_keys(&mut document);
    let json_bytes = document.to_string().into_bytes();

    let (main_file, bytes) = match format {
        ExportFormat::Glb => (
            format!("{name}.glb"),
            glb_container(&json_bytes, &buffer.bytes),
        ),
        _ => (format!("{name}.gltf"), json_bytes),
    };
    Ok(ExportedScene {
        files: BTreeMap::from([(main_file.clone(), bytes)]),
        main_file,
    })
}

/// A mesh with its one primitive, its attributes and indices written into `buffer`.
fn mesh_json(mesh: &Mesh, buffer: &mut GltfBuffer) -> Value {
    let positions: Vec<f32> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    let normals: Vec<f32> = mesh.normals.iter().flat_map(|n| n.to_array()).collect();
    let mut attributes = json!({
        "POSITION": buffer.floats(&positions, 3, true),
        "NORMAL": buffer.floats(&normals, 3, false),
    });
    if mesh.uvs.len() == mesh.positions.len() {
        let uvs: Vec<f32> = mesh.uvs.iter().flat_map(|uv| uv.to_array()).collect();
        attributes["TEXCOORD_0"] = json!(buffer.floats(&uvs, 2, false));
    }
    if let Some(tangents) = &mesh.tangents {
        let tangents: Vec<f32> = tangents.iter().flat_map(|t| t.to_array()).collect();
        attributes["TANGENT"] = json!(buffer.floats(&tangents, 4, false));
    }
    json!({
        "name": mesh.name,
        "primitives": [{
            "attributes": attributes,
            "indices": buffer.indices(&mesh.indices),
            "material": mesh.material,
        }],
    })
}

/// A PNG image: in the binary chunk for GLB, a data URI otherwise.
fn image_json(png: &[u8], format: ExportFormat, buffer: &mut GltfBuffer) -> Value {
    match format {
        ExportFormat::Glb => json!({
            "bufferView": buffer.view(png, None),
            "mimeType": "image/png",
        }),
        _ => json!({
            "uri": format!(
                "data:image/png;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(png)
            ),
        }),
    }
}

/// A metallic-roughness material; an emission brighter than glTF's unit factor is a unit
/// factor times KHR_materials_emissive_strength (the material's only extension).
fn material_json(material: &Material) -> Value {
    let mut pbr = json!({
        "baseColorFactor": material.base_color_factor.to_array(),
        "metallicFactor": material.metallic_factor,
        "roughnessFactor": material.roughness_factor,
    });
    if let Some(texture) = material.base_color_texture {
        pbr["baseColorTexture"] = json!({ "index": texture });
    }
    if let Some(texture) = material.metallic_roughness_texture {
        pbr["metallicRoughnessTexture"] = json!({ "index": texture });
    }
    let mut out = json!({
        "name": material.name,
        "pbrMetallicRoughness": pbr,
        "doubleSided": material.double_sided,
    });
    if let Some(texture) = material.normal_texture {
        out["normalTexture"] = json!({ "index": texture });
    }
    let brightest = material.emissive_factor.max_element();
    if brightest > 0.0 {
        let strength = brightest.max(1.0);
        out["emissiveFactor"] = json!((material.emissive_factor / strength).to_array());
        if strength > 1.0 {
            out["extensions"] = json!({
                "KHR_materials_emissive_strength": { "emissiveStrength": strength }
            });
        }
    }
    if let Some(texture) = material.emissive_texture {
        out["emissiveTexture"] = json!({ "index": texture });
    }
    match material.alpha_mode {
        AlphaMode::Opaque => {}
        AlphaMode::Mask { cutoff } => {
            out["alphaMode"] = json!("MASK");
            out["alphaCutoff"] = json!(cutoff);
        }
        AlphaMode::Blend => out["alphaMode"] = json!("BLEND"),
    }
    out
}

/// A KHR_lights_punctual light: a point, or a spot with its cone.
fn light_json(light: &SceneLight) -> Value {
    let mut out = json!({
        "name": light.name,
        "color": light.color.to_array(),
        "intensity": light.intensity,
    });
    if let Some(range) = light.range {
        out["range"] = json!(range);
    }
    match light.cone {
        Some(cone) => {
            out["type"] = json!("spot");
            out["spot"] = json!({ "innerConeAngle": cone.inner, "outerConeAngle": cone.outer });
        }
        None => out["type"] = json!("point"),
    }
    out
}

/// The node that places light `index`: a spot points along its node's -Z, so the node
/// turns -Z onto the light's direction.
fn light_node_json((index, light): (usize, &SceneLight)) -> Value {
    let rotation = glam::Quat::from_rotation_arc(Vec3::NEG_Z, light.direction.normalize());
    json!({
        "name": light.name,
        "translation": light.position.to_array(),
        "rotation": rotation.to_array(),
        "extensions": { "KHR_lights_punctual": { "light": index } },
    })
}

/// The GLB container: a 12-byte header, the JSON chunk (space-padded to 4 bytes) and the
/// BIN chunk (zero-padded).
pub fn glb_container(json_bytes: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |bytes: &[u8], fill: u8| {
        let mut padded = bytes.to_vec();
        while !padded.len().is_multiple_of(4) {
            padded.push(fill);
        }
        padded
    };
    let (json_chunk, bin_chunk) = (pad(json_bytes, b' '), pad(bin, 0));
    let total = 12 + 8 + json_chunk.len() + 8 + bin_chunk.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_chunk.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_chunk);
    out.extend_from_slice(&(bin_chunk.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin_chunk);
    out
}

/// The OBJ file: every instance's mesh in world space, with its material's name.
fn obj_geometry(scene: &Scene, name: &str) -> String {
    let mut obj = format!("# manylights-scene export\nmtllib {name}.mtl\n");
    // OBJ indices are global and 1-based.
    let mut first_vertex = 1usize;
    for (index, instance) in scene.instances.iter().enumerate() {
        let mesh = &scene.meshes[instance.mesh];
        let normal_matrix = Mat3::from_mat4(instance.transform).inverse().transpose();
        obj += &format!(
            "o {}_{index}\nusemtl material{}\n",
            mesh.name, mesh.material
        );
        for position in &mesh.positions {
            let p = instance.transform.transform_point3(*position);
            obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        for vertex in 0..mesh.positions.len() {
            let uv = mesh.uvs.get(vertex).copied().unwrap_or_default();
            obj += &format!("vt {} {}\n", uv.x, 1.0 - uv.y);
        }
        for normal in &mesh.normals {
            let n = (normal_matrix * *normal).try_normalize().unwrap_or(Vec3::Y);
            obj += &format!("vn {} {} {}\n", n.x, n.y, n.z);
        }
        for triangle in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| triangle[k] as usize + first_vertex);
            obj += &format!("f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n");
        }
        first_vertex += mesh.positions.len();
    }
    obj
}

fn export_obj(scene: &Scene, name: &str) -> Result<ExportedScene, ExportError> {
    let mut files = BTreeMap::new();
    let texture_file = |index: usize| format!("textures/{index}.png");
    for index in 0..scene.textures.len() {
        files.insert(texture_file(index), png(scene, index)?);
    }

    let mut mtl = String::new();
    for (index, material) in scene.materials.iter().enumerate() {
        let rgb = material
            .base_color_factor
            .truncate()
            .to_array()
            .map(linear_to_srgb);
        mtl += &format!("newmtl material{index}\n");
        mtl += &format!("Kd {} {} {}\n", rgb[0], rgb[1], rgb[2]);
        let specular = material.specular_color;
        mtl += &format!("Ks {} {} {}\n", specular.x, specular.y, specular.z);
        mtl += &format!("Ns {}\n", material.shininess);
        if let Some(texture) = material.base_color_texture {
            mtl += &format!("map_Kd {}\n", texture_file(texture));
            if matches!(material.alpha_mode, AlphaMode::Mask { .. }) {
                // map_d's luminance is the mask: write the texture's alpha as grey.
                let source = &scene.textures[texture];
                let alpha = Texture {
                    rgba8: source
                        .rgba8
                        .chunks_exact(4)
                        .flat_map(|texel| [texel[3], texel[3], texel[3], 255])
                        .collect(),
                    ..source.clone()
                };
                let alpha_file = format!("textures/{texture}_alpha.png");
                let png = encode_png(&alpha).map_err(|message| ExportError::Texture {
                    index: texture,
                    source_name: source.source.clone(),
                    message,
                })?;
                files.insert(alpha_file.clone(), png);
                mtl += &format!("map_d {alpha_file}\n");
            }
        } else if matches!(material.alpha_mode, AlphaMode::Mask { .. }) {
            mtl += &format!("d {}\n", material.base_color_factor.w.min(0.999));
        }
        if let Some(texture) = material.normal_texture {
            mtl += &format!("map_Bump {}\n", texture_file(texture));
        }
    }

    let obj = obj_geometry(scene, name);

    let main_file = format!("{name}.obj");
    files.insert(main_file.clone(), obj.into_bytes());
    files.insert(format!("{name}.mtl"), mtl.into_bytes());
    Ok(ExportedScene { main_file, files })
}

/// Every object's keys in alphabetical order, at every depth: the document's bytes do not
/// depend on the order the exporter inserts keys in (serde_json keeps insertion order
/// where the workspace asks it to, for settings as data), so an unchanged scene exports
/// to the same bytes and the committed assets stay the exports of their scenes.
fn sort_keys(value: &mut Value) {
    match value {
        Value::Object(fields) => {
            fields.sort_keys();
            fields.values_mut().for_each(sort_keys);
        }
        Value::Array(items) => items.iter_mut().for_each(sort_keys),
        _ => {}
    }
}
