//! glTF 2.0 loading (`.gltf` + external or data-URI buffers, and `.glb`) through the
//! `gltf` crate.
//!
//! The crate parses and validates the JSON; this module loads buffers and images itself so
//! that every failure names the file involved, and checks every accessor against the data
//! it reads before reading it (the crate's reader would panic on short data).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::error::{Result, SceneError};
use crate::files::FileSource;
use crate::mesh_builder::RawMesh;
use crate::model::{
    AlphaMode, ColorSpace, Instance, LoadWarning, Material, Scene, SceneLight, SpotCone, Texture,
};
use crate::texture::decode_or_fallback;

/// Required extensions we implement; a file that requires any other is refused with
/// [`SceneError::UnsupportedExtension`] rather than rendered wrongly.
const SUPPORTED_REQUIRED_EXTENSIONS: &[&str] = &["KHR_lights_punctual"];

/// Ranges from here on are read as "no range": 3.4e38 (f32::MAX) is some exporters' way
/// of writing an infinite range, and any range past 1e10 m reaches every scene anyway
/// (while its square, 1e20, would overflow what the culling computes in f32).
pub const UNBOUNDED_RANGE: f32 = 1e10;

/// Deepest node hierarchy accepted. Real scenes are a few levels deep; the limit turns a
/// (invalid) cyclic hierarchy into an error instead of endless recursion.
const MAX_NODE_DEPTH: usize = 256;

pub(crate) fn load_gltf(file: &Path, bytes: &[u8], files: FileSource) -> Result<Scene> {
    let invalid = |message: String| SceneError::InvalidGltf {
        file: file.to_path_buf(),
        message,
    };
    let (json_bytes, glb_bin) = if bytes.starts_with(b"glTF") {
        let glb =
            gltf::Glb::from_slice(bytes).map_err(|e| invalid(format!("bad GLB container: {e}")))?;
        (glb.json.into_owned(), glb.bin.map(|bin| bin.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    let root = gltf::json::Root::from_slice(&json_bytes).map_err(|e| invalid(format!("{e}")))?;
    check_before_validation(&root).map_err(invalid)?;
    for extension in &root.extensions_required {
        if !SUPPORTED_REQUIRED_EXTENSIONS.contains(&extension.as_str()) {
            return Err(SceneError::UnsupportedExtension {
                file: file.to_path_buf(),
                extension: extension.clone(),
            });
        }
    }
    let document = gltf::Document::from_json(root).map_err(|e| {
        invalid(
            e.to_string()
                .trim_start_matches("invalid glTF: ")
                .to_string(),
        )
    })?;
    let base_dir = file.parent().unwrap_or(Path::new("."));
    let buffers = load_buffers(file, base_dir, &document, glb_bin, files)?;

    let mut loader = GltfLoader {
        file,
        base_dir,
        buffers,
        scene: Scene {
            name: file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            ..Scene::default()
        },
        texture_slots: HashMap::new(),
        files,
        mesh_slots: HashMap::new(),
    };
    loader.load_materials(&document)?;
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| invalid("the file has no scene".into()))?;
    for node in scene.nodes() {
        loader.visit_node(&node, Mat4::IDENTITY, 0)?;
    }
    Ok(loader.scene)
}

/// What the gltf crates (1.4.1) panic on instead of reporting, refused here first (each
/// found by the fuzzers): gltf-json's validation looks up each primitive's POSITION
/// accessor without a bounds check, and `Image::source` unwraps a missing `mimeType` (for
/// an image in a buffer view) or a missing `uri` (for an image with neither).
fn check_before_validation(root: &gltf::json::Root) -> std::result::Result<(), String> {
    for (index, image) in root.images.iter().enumerate() {
        match (&image.buffer_view, &image.mime_type, &image.uri) {
            (Some(_), None, _) => {
                return Err(format!(
                    "image {index} is in a buffer view but has no mimeType"
                ));
            }
            (None, _, None) => {
                return Err(format!("image {index} has neither a uri nor a bufferView"));
            }
            _ => {}
        }
    }
    // `Node::light` unwraps the light it names.
    let light_count = root
        .extensions
        .as_ref()
        .and_then(|extensions| extensions.khr_lights_punctual.as_ref())
        .map_or(0, |lights| lights.lights.len());
    for (index, node) in root.nodes.iter().enumerate() {
        if let Some(light) = node
            .extensions
            .as_ref()
            .and_then(|extensions| extensions.khr_lights_punctual.as_ref())
            && light.light.value() >= light_count
        {
            return Err(format!(
                "node {index} refers to KHR_lights_punctual light {} but the file has {light_count}",
                light.light.value()
            ));
        }
    }
    use gltf::json::validation::Checked;
    let positions = Checked::Valid(gltf::json::mesh::Semantic::Positions);
    for (mesh_index, mesh) in root.meshes.iter().enumerate() {
        for (primitive_index, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(accessor) = primitive.attributes.get(&positions)
                && accessor.value() >= root.accessors.len()
            {
                return Err(format!(
                    "mesh {mesh_index} primitive {primitive_index}: POSITION refers to accessor {} but the file has {}",
                    accessor.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// The component types and shapes this loader reads for each attribute; the gltf crate's
/// readers hit `unreachable!` (or slice past their data) on any other (found by the `glb`
/// fuzzer), so a mismatch is refused first. The names are glTF's.
fn check_accessor_format(
    semantic: &str,
    accessor: &gltf::Accessor,
) -> std::result::Result<(), String> {
    use gltf::accessor::{DataType::*, Dimensions::*};
    let (data_type, dimensions) = (accessor.data_type(), accessor.dimensions());
    let accepted = match semantic {
        "POSITION" | "NORMAL" => matches!((data_type, dimensions), (F32, Vec3)),
        "TANGENT" => matches!((data_type, dimensions), (F32, Vec4)),
        "TEXCOORD_0" => matches!((data_type, dimensions), (F32 | U8 | U16, Vec2)),
        "indices" => matches!((data_type, dimensions), (U8 | U16 | U32, Scalar)),
        _ => true, // not read
    };
    if !accepted {
        return Err(format!(
            "{semantic} accessor {} has {data_type:?} {dimensions:?} elements, which glTF does not allow there",
            accessor.index()
        ));
    }
    if accessor.count() == 0 {
        return Err(format!(
            "{semantic} accessor {} has no elements (glTF requires count >= 1)",
            accessor.index()
        ));
    }
    Ok(())
}

fn load_buffers(
    file: &Path,
    base_dir: &Path,
    document: &gltf::Document,
    mut glb_bin: Option<Vec<u8>>,
    files: FileSource,
) -> Result<Vec<Vec<u8>>> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => glb_bin.take().ok_or_else(|| SceneError::InvalidGltf {
                file: file.to_path_buf(),
                message: format!(
                    "buffer {} refers to a GLB BIN chunk that is not there",
                    buffer.index()
                ),
            })?,
            gltf::buffer::Source::Uri(uri) => read_uri(file, base_dir, uri, "buffer", files)?,
        };
        if data.len() < buffer.length() {
            return Err(SceneError::BufferTooShort {
                file: file.to_path_buf(),
                buffer: buffer.index(),
                declared: buffer.length(),
                actual: data.len(),
            });
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Reads a `data:` URI or a file relative to the glTF's folder.
fn read_uri(
    file: &Path,
    base_dir: &Path,
    uri: &str,
    kind: &'static str,
    files: FileSource,
) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or_else(|| SceneError::InvalidGltf {
                file: file.to_path_buf(),
                message: format!("{kind} data URI is not base64"),
            })?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| SceneError::InvalidGltf {
                file: file.to_path_buf(),
                message: format!("{kind} data URI: {e}"),
            });
    }
    files.read(file, base_dir, &percent_decode(uri), kind)
}

/// URIs in glTF are percent-encoded (`my%20texture.png`).
fn percent_decode(uri: &str) -> PathBuf {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(hi), Some(lo)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((hi * 16 + lo) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    PathBuf::from(String::from_utf8_lossy(&out).into_owned())
}

struct GltfLoader<'a> {
    file: &'a Path,
    base_dir: &'a Path,
    /// Where referenced files come from.
    files: FileSource<'a>,
    buffers: Vec<Vec<u8>>,
    scene: Scene,
    /// (glTF texture index, colour space) -> index in `scene.textures`.
    texture_slots: HashMap<(usize, ColorSpace), usize>,
    /// glTF (mesh, primitive) -> index in `scene.meshes`.
    mesh_slots: HashMap<(usize, usize), Option<usize>>,
}

impl GltfLoader<'_> {
    fn file_name(&self) -> String {
        self.file.display().to_string()
    }

    fn load_materials(&mut self, document: &gltf::Document) -> Result<()> {
        for material in document.materials() {
            let pbr = material.pbr_metallic_roughness();
            let base_color_factor = Vec4::from_array(pbr.base_color_factor());
            let base_color_texture = match pbr.base_color_texture() {
                Some(info) => Some(self.texture(info.texture(), ColorSpace::Srgb)?),
                None => None,
            };
            let normal_texture = match material.normal_texture() {
                Some(normal) => Some(self.texture(normal.texture(), ColorSpace::Linear)?),
                None => None,
            };
            let (specular_color, shininess) = Material::blinn_phong_from_metallic_roughness(
                base_color_factor.truncate(),
                pbr.metallic_factor(),
                pbr.roughness_factor(),
            );
            self.scene.materials.push(Material {
                name: material.name().unwrap_or("unnamed").to_string(),
                base_color_factor,
                base_color_texture,
                normal_texture,
                metallic_factor: pbr.metallic_factor(),
                roughness_factor: pbr.roughness_factor(),
                specular_color,
                shininess,
                alpha_mode: match material.alpha_mode() {
                    gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                    gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                        cutoff: material.alpha_cutoff().unwrap_or(0.5),
                    },
                    gltf::material::AlphaMode::Blend => AlphaMode::Blend,
                },
                double_sided: material.double_sided(),
            });
        }
        // Primitives without a material use the glTF default material, stored last.
        self.scene.materials.push(Material::default());
        Ok(())
    }

    fn texture(&mut self, texture: gltf::Texture, color_space: ColorSpace) -> Result<usize> {
        if let Some(&slot) = self.texture_slots.get(&(texture.index(), color_space)) {
            return Ok(slot);
        }
        let image = texture.source();
        let (bytes, source) = match image.source() {
            gltf::image::Source::Uri { uri, .. } => {
                let source = if uri.starts_with("data:") {
                    format!("{}#image[{}]", self.file_name(), image.index())
                } else {
                    uri.to_string()
                };
                (
                    read_uri(self.file, self.base_dir, uri, "image", self.files)?,
                    source,
                )
            }
            gltf::image::Source::View { view, .. } => {
                let bytes = self.view_bytes(&view, None)?.to_vec();
                (
                    bytes,
                    format!("{}#image[{}]", self.file_name(), image.index()),
                )
            }
        };
        let file_name = self.file_name();
        let decoded: Texture = decode_or_fallback(
            &bytes,
            source,
            color_space,
            &file_name,
            &mut self.scene.warnings,
        );
        self.scene.textures.push(decoded);
        let slot = self.scene.textures.len() - 1;
        self.texture_slots
            .insert((texture.index(), color_space), slot);
        Ok(slot)
    }

    /// The bytes of a buffer view, checked against the loaded buffer.
    fn view_bytes(&self, view: &gltf::buffer::View, accessor: Option<usize>) -> Result<&[u8]> {
        let data = &self.buffers[view.buffer().index()];
        let end = view.offset().checked_add(view.length());
        match end {
            Some(end) if end <= data.len() => Ok(&data[view.offset()..end]),
            _ => Err(SceneError::AccessorOutOfRange {
                file: self.file.to_path_buf(),
                accessor: accessor.unwrap_or(usize::MAX),
                message: format!(
                    "buffer view {} (offset {}, length {}) ends past buffer {} ({} bytes)",
                    view.index(),
                    view.offset(),
                    view.length(),
                    view.buffer().index(),
                    data.len()
                ),
            }),
        }
    }

    /// Checks that every element of an accessor (and of its sparse substitution) lies
    /// inside its buffer view, so that reading it can neither panic nor over-allocate.
    fn check_accessor(&self, accessor: &gltf::Accessor) -> Result<()> {
        let out_of_range = |message: String| SceneError::AccessorOutOfRange {
            file: self.file.to_path_buf(),
            accessor: accessor.index(),
            message,
        };
        let element = accessor.size();
        let count = accessor.count();
        if let Some(view) = accessor.view() {
            let view_bytes = self.view_bytes(&view, Some(accessor.index()))?;
            let stride = view.stride().unwrap_or(element);
            let needed = if count == 0 {
                Some(0)
            } else {
                stride
                    .checked_mul(count - 1)
                    .and_then(|n| n.checked_add(element))
                    .and_then(|n| n.checked_add(accessor.offset()))
            };
            match needed {
                Some(needed) if needed <= view_bytes.len() => {}
                _ => {
                    return Err(out_of_range(format!(
                        "{count} elements of {element} bytes (stride {stride}, offset {}) need more than the {} bytes of buffer view {}",
                        accessor.offset(),
                        view_bytes.len(),
                        view.index()
                    )));
                }
            }
        }
        if let Some(sparse) = accessor.sparse() {
            let sparse_count = sparse.count();
            if sparse_count > count {
                return Err(out_of_range(format!(
                    "{sparse_count} sparse values for {count} elements"
                )));
            }
            let index_size = match sparse.indices().index_type() {
                gltf::accessor::sparse::IndexType::U8 => 1,
                gltf::accessor::sparse::IndexType::U16 => 2,
                gltf::accessor::sparse::IndexType::U32 => 4,
            };
            for (view, offset, size) in [
                (
                    sparse.indices().view(),
                    sparse.indices().offset(),
                    index_size,
                ),
                (sparse.values().view(), sparse.values().offset(), element),
            ] {
                let bytes = self.view_bytes(&view, Some(accessor.index()))?;
                let needed = size
                    .checked_mul(sparse_count)
                    .and_then(|n| n.checked_add(offset));
                if !matches!(needed, Some(needed) if needed <= bytes.len()) {
                    return Err(out_of_range(format!(
                        "sparse data needs more than the {} bytes of buffer view {}",
                        bytes.len(),
                        view.index()
                    )));
                }
            }
            // Sparse indices must address elements of the accessor.
            let indices_view = sparse.indices().view();
            let bytes = &self.view_bytes(&indices_view, Some(accessor.index()))?
                [sparse.indices().offset()..];
            for i in 0..sparse_count {
                let chunk = &bytes[i * index_size..(i + 1) * index_size];
                let index = match index_size {
                    1 => chunk[0] as usize,
                    2 => u16::from_le_bytes([chunk[0], chunk[1]]) as usize,
                    _ => u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]) as usize,
                };
                if index >= count {
                    return Err(out_of_range(format!(
                        "sparse index {index} >= count {count}"
                    )));
                }
            }
        }
        Ok(())
    }

    fn visit_node(&mut self, node: &gltf::Node, parent: Mat4, depth: usize) -> Result<()> {
        if depth > MAX_NODE_DEPTH {
            return Err(SceneError::InvalidGltf {
                file: self.file.to_path_buf(),
                message: format!(
                    "node hierarchy deeper than {MAX_NODE_DEPTH} levels at node {} (cyclic?)",
                    node.index()
                ),
            });
        }
        let transform = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                if let Some(mesh_index) = self.primitive(&mesh, &primitive)? {
                    self.scene.instances.push(Instance {
                        mesh: mesh_index,
                        transform,
                    });
                }
            }
        }
        if let Some(light) = node.light() {
            self.light(node, &light, transform)?;
        }
        for child in node.children() {
            self.visit_node(&child, transform, depth + 1)?;
        }
        Ok(())
    }

    /// A `KHR_lights_punctual` light on a node, checked: every bad value is an error naming
    /// the light (never a silent zero), except an "infinite" range (3.4e38, as some
    /// exporters write), which is read as no range, with a warning.
    fn light(
        &mut self,
        node: &gltf::Node,
        light: &gltf::khr_lights_punctual::Light,
        transform: Mat4,
    ) -> Result<()> {
        use gltf::khr_lights_punctual::Kind;
        let name = light
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("light {}", light.index()));
        let invalid = |message: String| SceneError::InvalidGltf {
            file: self.file.to_path_buf(),
            message: format!(
                "KHR_lights_punctual light '{name}' (on node {}): {message}",
                node.index()
            ),
        };
        let cone = match light.kind() {
            Kind::Directional => {
                self.scene.warnings.push(LoadWarning {
                    file: self.file.display().to_string(),
                    message: format!(
                        "directional light '{name}' ignored: manylights renders point and spot lights"
                    ),
                });
                return Ok(());
            }
            Kind::Point => None,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let cone = SpotCone {
                    inner: inner_cone_angle,
                    outer: outer_cone_angle,
                };
                cone.validate().map_err(invalid)?;
                Some(cone)
            }
        };
        let intensity = light.intensity();
        if !intensity.is_finite() || intensity < 0.0 {
            return Err(invalid(format!(
                "intensity {intensity}: it must be a finite, non-negative number of candela"
            )));
        }
        let color = Vec3::from_array(light.color());
        if !color.is_finite() || color.min_element() < 0.0 {
            return Err(invalid(format!(
                "color {color}: each channel must be a finite, non-negative number"
            )));
        }
        let range = match light.range() {
            None => None,
            Some(range) if range >= UNBOUNDED_RANGE => {
                self.scene.warnings.push(LoadWarning {
                    file: self.file.display().to_string(),
                    message: format!(
                        "light '{name}': range {range:e} m read as no range (unbounded)"
                    ),
                });
                None
            }
            Some(range) if range.is_finite() && range > 0.0 => Some(range),
            Some(range) => {
                return Err(invalid(format!(
                    "range {range}: it must be a positive number of metres (leave it out for an unbounded light)"
                )));
            }
        };
        let position = transform.transform_point3(Vec3::ZERO);
        let direction = transform.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        if !position.is_finite() || direction == Vec3::ZERO {
            return Err(invalid(format!(
                "its node's transform gives position {position} and direction {direction}"
            )));
        }
        self.scene.lights.push(SceneLight {
            name,
            position,
            direction,
            cone,
            color,
            intensity,
            range,
        });
        Ok(())
    }

    /// Loads a primitive once (instanced meshes are shared); `None` for primitives that are
    /// not triangles, which are skipped with a warning.
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> Result<Option<usize>> {
        let key = (mesh.index(), primitive.index());
        if let Some(&slot) = self.mesh_slots.get(&key) {
            return Ok(slot);
        }
        let name = match mesh.name() {
            Some(name) => format!("{name}[{}]", primitive.index()),
            None => format!("mesh{}[{}]", mesh.index(), primitive.index()),
        };
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            self.scene.warnings.push(LoadWarning {
                file: self.file_name(),
                message: format!(
                    "mesh '{name}': {:?} primitives are not supported; skipped",
                    primitive.mode()
                ),
            });
            self.mesh_slots.insert(key, None);
            return Ok(None);
        }
        let invalid_mesh = |message: String| SceneError::InvalidMesh {
            file: self.file.to_path_buf(),
            mesh: name.clone(),
            message,
        };
        for (semantic, accessor) in primitive.attributes() {
            check_accessor_format(&semantic.to_string(), &accessor).map_err(invalid_mesh)?;
            self.check_accessor(&accessor)?;
        }
        if let Some(indices) = primitive.indices() {
            check_accessor_format("indices", &indices).map_err(invalid_mesh)?;
            self.check_accessor(&indices)?;
        }
        let material = primitive
            .material()
            .index()
            .unwrap_or(self.scene.materials.len() - 1);
        let needs_tangents = self.scene.materials[material].normal_texture.is_some();

        let buffers = &self.buffers;
        let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(Vec::as_slice));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| SceneError::InvalidMesh {
                file: self.file.to_path_buf(),
                mesh: name.clone(),
                message: "no POSITION attribute".into(),
            })?
            .map(Vec3::from_array)
            .collect();
        let raw = RawMesh {
            normals: reader
                .read_normals()
                .map(|n| n.map(Vec3::from_array).collect()),
            uvs: reader
                .read_tex_coords(0)
                .map(|uvs| uvs.into_f32().map(Vec2::from_array).collect()),
            tangents: reader
                .read_tangents()
                .map(|t| t.map(Vec4::from_array).collect()),
            indices: match reader.read_indices() {
                Some(indices) => indices.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            },
            positions,
            name,
            material,
        };
        let mesh = raw.finish(self.file, needs_tangents)?;
        self.scene.meshes.push(mesh);
        let slot = self.scene.meshes.len() - 1;
        self.mesh_slots.insert(key, Some(slot));
        Ok(Some(slot))
    }
}

#[cfg(test)]
mod tests {
    use super::percent_decode;
    use std::path::PathBuf;

    #[test]
    fn percent_escapes_decode_and_malformed_ones_stay() {
        assert_eq!(
            percent_decode("my%20tex%2Fture.png"),
            PathBuf::from("my tex/ture.png")
        );
        assert_eq!(percent_decode("a%41%7a.png"), PathBuf::from("aAz.png"));
        // Not hex, or cut short at the end: kept as written.
        assert_eq!(percent_decode("%zz%4"), PathBuf::from("%zz%4"));
        assert_eq!(percent_decode("end%20"), PathBuf::from("end "));
    }
}
