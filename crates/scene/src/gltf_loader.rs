//! glTF 2.0 loading (`.gltf` + external or data-URI buffers, and `.glb`) through the
//! `gltf` crate's JSON model.
//!
//! `gltf_json.rs` reads the JSON as the specification does (where the crate is stricter)
//! and the extensions the crate does not model; this module loads buffers and images itself
//! so that every failure names the file involved, decodes compressed buffer views
//! (`gltf_meshopt.rs`), and reads accessors with `gltf_accessor.rs`, which checks every
//! element against its data before reading it.
//!
//! Extensions read: `KHR_lights_punctual`, `KHR_mesh_quantization`, `KHR_texture_transform`
//! (baked into the mesh's UVs), `KHR_materials_emissive_strength`, `EXT_meshopt_compression`
//! and `KHR_meshopt_compression`, and `EXT_mesh_gpu_instancing` (each instance baked as a
//! scene instance). Skins are drawn unskinned, morph targets at the mesh's default weights,
//! animations not at all, points and lines not at all (each with a warning); triangle
//! strips and fans become triangle lists. Every other extension a file uses is named in
//! a warning (the file is drawn without it).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

use crate::error::{Result, SceneError};
use crate::files::FileSource;
use crate::gltf_accessor::{ReadError, ViewData, check_attribute, read_indices, read_vectors};
use crate::gltf_json::{self, NodeInstancing, PreparedJson, TextureTransform};
use crate::gltf_meshopt;
use crate::mesh_builder::RawMesh;
use crate::model::{ColorSpace, Instance, LoadWarning, Scene, SceneLight, SpotCone};

mod materials;

/// The extensions manylights reads. A file that requires any other is refused with
/// [`SceneError::UnsupportedExtension`] rather than rendered wrongly; one that only uses
/// another is drawn without it, with a warning naming it.
const READ_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_mesh_gpu_instancing",
];

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
    let prepared = gltf_json::prepare(&json_bytes).map_err(invalid)?;
    check_before_validation(&prepared.root).map_err(invalid)?;
    for extension in &prepared.root.extensions_required {
        check_required_extension(file, extension)?;
    }
    gltf_json::validate(&prepared.root).map_err(invalid)?;
    let PreparedJson {
        root,
        meshopt_views,
        meshopt_fallback_buffers,
        materials: material_extensions,
        node_instancing,
        mut warnings,
    } = prepared;
    warnings.extend(unread_extensions_warning(&root));
    let document = gltf::Document::from_json_without_validation(root);
    let base_dir = file.parent().unwrap_or(Path::new("."));
    let buffers = load_buffers(
        file,
        base_dir,
        &document,
        glb_bin,
        &meshopt_fallback_buffers,
        files,
    )?;
    let views = decode_compressed_views(file, buffers, &meshopt_views)?;

    let mut loader = GltfLoader {
        file,
        document: &document,
        base_dir,
        views,
        scene: Scene {
            name: file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            warnings: warnings
                .into_iter()
                .map(|message| LoadWarning {
                    file: file.display().to_string(),
                    message,
                })
                .collect(),
            ..Scene::default()
        },
        texture_slots: HashMap::new(),
        files,
        mesh_slots: HashMap::new(),
        material_uvs: Vec::new(),
        node_instancing,
        skipped_triangles: 0,
    };
    loader.load_materials(&document, &material_extensions)?;
    loader.visit_scene()?;
    if loader.skipped_triangles > 0 {
        let skipped = loader.skipped_triangles;
        loader.warn(format!(
            "{skipped} degenerate triangle(s) (two equal indices) skipped"
        ));
    }
    Ok(loader.scene)
}

/// The warning naming the extensions a file uses that manylights does not read (the file
/// is drawn without them), if there are any.
fn unread_extensions_warning(root: &gltf::json::Root) -> Option<String> {
    let unread: Vec<&str> = root
        .extensions_used
        .iter()
        .map(String::as_str)
        .filter(|name| !READ_EXTENSIONS.contains(name))
        .collect();
    (!unread.is_empty()).then(|| {
        format!(
            "extension(s) used but not read, drawn without them: {}",
            unread.join(", ")
        )
    })
}

/// Reads an optional vertex attribute of `N` float components, converted by `convert`.
fn read_attribute<const N: usize, T>(
    views: &ViewData,
    accessor: Option<gltf::Accessor>,
    convert: impl Fn([f32; N]) -> T,
) -> std::result::Result<Option<Vec<T>>, ReadError> {
    accessor
        .map(|accessor| {
            Ok(read_vectors::<N>(views, &accessor)?
                .into_iter()
                .map(convert)
                .collect())
        })
        .transpose()
}

/// Refuses a required extension manylights does not implement, saying what to do about
/// the common ones.
fn check_required_extension(file: &Path, extension: &str) -> Result<()> {
    if READ_EXTENSIONS.contains(&extension) {
        return Ok(());
    }
    let hint = match extension {
        "KHR_draco_mesh_compression" => {
            ": no maintained Draco decoder exists for Rust; convert the file with gltfpack (`npx gltfpack -i in.glb -o out.glb -cc` writes meshopt compression, which manylights reads)"
        }
        "KHR_texture_basisu" | "EXT_texture_webp" | "EXT_texture_avif" => {
            ": manylights decodes PNG and JPEG textures; re-export the textures as PNG or JPEG (e.g. `npx gltf-transform png in.glb out.glb`)"
        }
        _ => "",
    };
    Err(SceneError::UnsupportedExtension {
        file: file.to_path_buf(),
        extension: extension.to_string(),
        hint: hint.to_string(),
    })
}

/// Decodes every compressed buffer view (`EXT_meshopt_compression`) once, up front.
fn decode_compressed_views(
    file: &Path,
    buffers: Vec<Vec<u8>>,
    meshopt_views: &HashMap<usize, gltf_json::MeshoptView>,
) -> Result<ViewData> {
    let mut views = ViewData {
        buffers,
        decoded: HashMap::new(),
    };
    let mut indices: Vec<_> = meshopt_views.keys().copied().collect();
    indices.sort_unstable();
    for index in indices {
        let view = &meshopt_views[&index];
        let buffer = views.buffers.get(view.buffer).ok_or_else(|| SceneError::InvalidGltf {
            file: file.to_path_buf(),
            message: format!(
                "meshopt-compressed buffer view {index} refers to buffer {} but the file has {}",
                view.buffer,
                views.buffers.len()
            ),
        })?;
        let decoded = gltf_meshopt::decode(index, view, buffer).map_err(|message| {
            SceneError::InvalidGltf {
                file: file.to_path_buf(),
                message,
            }
        })?;
        views.decoded.insert(index, decoded);
    }
    Ok(views)
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

fn load_buffers(
    file: &Path,
    base_dir: &Path,
    document: &gltf::Document,
    mut glb_bin: Option<Vec<u8>>,
    meshopt_fallback_buffers: &std::collections::HashSet<usize>,
    files: FileSource,
) -> Result<Vec<Vec<u8>>> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        // A meshopt fallback buffer without data is a placeholder: the views that use
        // it are decoded from elsewhere, and reading it directly is an error later.
        if meshopt_fallback_buffers.contains(&buffer.index())
            && matches!(buffer.source(), gltf::buffer::Source::Bin)
            && (buffer.index() != 0 || glb_bin.is_none())
        {
            buffers.push(Vec::new());
            continue;
        }
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
pub(crate) fn percent_decode(uri: &str) -> PathBuf {
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
    document: &'a gltf::Document,
    base_dir: &'a Path,
    /// Where referenced files come from.
    files: FileSource<'a>,
    /// The bytes of every buffer view (compressed ones decoded).
    views: ViewData,
    scene: Scene,
    /// (glTF texture index, colour space) -> index in `scene.textures`.
    texture_slots: HashMap<(usize, ColorSpace), usize>,
    /// glTF (mesh, primitive) -> index in `scene.meshes`.
    mesh_slots: HashMap<(usize, usize), Option<usize>>,
    /// Per entry of `scene.materials`: the UV set its textures read and the
    /// `KHR_texture_transform` baked into the meshes that use it.
    material_uvs: Vec<MaterialUvs>,
    /// `EXT_mesh_gpu_instancing` by node index.
    node_instancing: HashMap<usize, NodeInstancing>,
    /// Triangles with two equal indices, dropped.
    skipped_triangles: usize,
}

/// The one UV mapping a material's textures are drawn with.
#[derive(Debug, Clone, Copy)]
struct MaterialUvs {
    tex_coord: u32,
    transform: TextureTransform,
}

impl GltfLoader<'_> {
    fn file_name(&self) -> String {
        self.file.display().to_string()
    }

    /// The scene error for an accessor of mesh `name` that could not be read.
    fn read_error(&self, name: &str, error: ReadError) -> SceneError {
        match error {
            ReadError::OutOfRange { accessor, message } => SceneError::AccessorOutOfRange {
                file: self.file.to_path_buf(),
                accessor,
                message,
            },
            ReadError::Invalid(message) => SceneError::InvalidMesh {
                file: self.file.to_path_buf(),
                mesh: name.to_string(),
                message,
            },
        }
    }

    fn warn(&mut self, message: String) {
        self.scene.warnings.push(LoadWarning {
            file: self.file_name(),
            message,
        });
    }

    /// Visits the nodes of the document's scene: the default one, else the first. glTF lets a
    /// file have no scene ("nothing to render" is the application's call); a file with nodes
    /// is then drawn as if one scene held every root node.
    fn visit_scene(&mut self) -> Result<()> {
        let document = self.document;
        match document
            .default_scene()
            .or_else(|| document.scenes().next())
        {
            Some(scene) => {
                for node in scene.nodes() {
                    self.visit_node(&node, Mat4::IDENTITY, 0)?;
                }
            }
            None => {
                let children: std::collections::HashSet<usize> = document
                    .nodes()
                    .flat_map(|node| node.children().map(|child| child.index()))
                    .collect();
                let roots: Vec<_> = document
                    .nodes()
                    .filter(|node| !children.contains(&node.index()))
                    .collect();
                if roots.is_empty() {
                    return Err(SceneError::InvalidGltf {
                        file: self.file.to_path_buf(),
                        message: "the file has no scene and no nodes to draw".into(),
                    });
                }
                self.warn(format!(
                    "the file has no scene: drawing its {} root node(s)",
                    roots.len()
                ));
                for node in roots {
                    self.visit_node(&node, Mat4::IDENTITY, 0)?;
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
            if node.skin().is_some() {
                self.warn(format!(
                    "node {}: skin ignored: its mesh is drawn unskinned, placed by the node",
                    node.index()
                ));
            }
            if let Some(weights) = node.weights()
                && Some(weights) != mesh.weights()
            {
                self.warn(format!(
                    "node {}: its morph weights are ignored; the mesh's default weights are drawn",
                    node.index()
                ));
            }
            let instances = match self.node_instancing.get(&node.index()) {
                Some(&instancing) => self.instance_transforms(node, instancing)?,
                None => vec![Mat4::IDENTITY],
            };
            for primitive in mesh.primitives() {
                if let Some(mesh_index) = self.primitive(&mesh, &primitive)? {
                    for &instance in &instances {
                        self.scene.instances.push(Instance {
                            mesh: mesh_index,
                            transform: transform * instance,
                        });
                    }
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

    /// The per-instance transforms of an `EXT_mesh_gpu_instancing` node (applied before
    /// the node's own): translation, rotation (a quaternion, normalized integers allowed)
    /// and scale, each attribute the same count.
    fn instance_transforms(
        &self,
        node: &gltf::Node,
        instancing: NodeInstancing,
    ) -> Result<Vec<Mat4>> {
        let name = format!("node {} (EXT_mesh_gpu_instancing)", node.index());
        let read_error = |error: ReadError| self.read_error(&name, error);
        let invalid = |message: String| read_error(ReadError::Invalid(message));
        let accessor = |index: Option<usize>| -> Result<Option<gltf::Accessor>> {
            index
                .map(|index| {
                    self.document.accessors().nth(index).ok_or_else(|| {
                        invalid(format!(
                            "attribute accessor {index} does not exist (the file has {})",
                            self.document.accessors().len()
                        ))
                    })
                })
                .transpose()
        };
        let views = &self.views;
        let translations =
            read_attribute(views, accessor(instancing.translation)?, Vec3::from_array)
                .map_err(read_error)?;
        let rotations = read_attribute(views, accessor(instancing.rotation)?, Quat::from_array)
            .map_err(read_error)?;
        let scales = read_attribute(views, accessor(instancing.scale)?, Vec3::from_array)
            .map_err(read_error)?;
        let counts: Vec<usize> = [
            translations.as_ref().map(Vec::len),
            rotations.as_ref().map(Vec::len),
            scales.as_ref().map(Vec::len),
        ]
        .into_iter()
        .flatten()
        .collect();
        let Some(&count) = counts.first() else {
            return Err(invalid(
                "no TRANSLATION, ROTATION or SCALE attribute".into(),
            ));
        };
        if counts.iter().any(|&other| other != count) {
            return Err(invalid(format!(
                "its attributes have different counts {counts:?}"
            )));
        }
        (0..count)
            .map(|i| {
                let translation = translations.as_ref().map_or(Vec3::ZERO, |t| t[i]);
                let rotation = rotations.as_ref().map_or(Quat::IDENTITY, |r| r[i]);
                let scale = scales.as_ref().map_or(Vec3::ONE, |s| s[i]);
                let length = rotation.length();
                if !(translation.is_finite() && scale.is_finite() && length.is_finite())
                    || length == 0.0
                {
                    return Err(invalid(format!(
                        "instance {i}: translation {translation}, rotation {rotation}, scale {scale} is not a transform"
                    )));
                }
                Ok(Mat4::from_scale_rotation_translation(
                    scale,
                    rotation / length,
                    translation,
                ))
            })
            .collect()
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
        let (intensity, color) = checked_emission(light).map_err(invalid)?;
        let warnings = &mut self.scene.warnings;
        let range = light_range(warnings, self.file, &name, light.range()).map_err(invalid)?;
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

    /// Loads a primitive once (instanced meshes are shared); `None` for points and lines,
    /// which are skipped with a warning (strips and fans become triangle lists).
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
        use gltf::mesh::Mode;
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.warn(format!(
                "mesh '{name}': {mode:?} primitives are not drawn (manylights draws triangles); skipped"
            ));
            self.mesh_slots.insert(key, None);
            return Ok(None);
        }
        let material = primitive
            .material()
            .index()
            .unwrap_or(self.scene.materials.len() - 1);
        let needs_tangents = self.scene.materials[material].normal_texture.is_some();
        let mut raw = self.read_raw_mesh(primitive, mode, name, material)?;
        self.apply_morph_targets(
            mesh,
            primitive,
            &raw.name,
            &mut raw.positions,
            &mut raw.normals,
            &mut raw.tangents,
        )?;
        self.skipped_triangles += drop_degenerate_triangles(&mut raw.indices);
        let mesh = raw.finish(self.file, needs_tangents)?;
        self.scene.meshes.push(mesh);
        let slot = self.scene.meshes.len() - 1;
        self.mesh_slots.insert(key, Some(slot));
        Ok(Some(slot))
    }

    /// Reads a triangle primitive's vertex attributes (each checked against what glTF and
    /// `KHR_mesh_quantization` allow; UVs in the material's one mapping) and its indices,
    /// as a triangle list.
    fn read_raw_mesh(
        &self,
        primitive: &gltf::Primitive,
        mode: gltf::mesh::Mode,
        name: String,
        material: usize,
    ) -> Result<RawMesh> {
        let invalid_mesh = |error: ReadError| self.read_error(&name, error);
        for (semantic, accessor) in primitive.attributes() {
            check_attribute(&semantic.to_string(), &accessor)
                .map_err(|message| invalid_mesh(message.into()))?;
        }
        let uv_mapping = self.material_uvs[material];
        let views = &self.views;
        let attribute = |semantic: gltf::Semantic| primitive.get(&semantic);
        let positions = read_attribute(
            views,
            attribute(gltf::Semantic::Positions),
            Vec3::from_array,
        )
        .map_err(invalid_mesh)?
        .ok_or_else(|| invalid_mesh(ReadError::Invalid("no POSITION attribute".into())))?;
        let normals = read_attribute(views, attribute(gltf::Semantic::Normals), Vec3::from_array)
            .map_err(invalid_mesh)?;
        let tangents = read_attribute(views, attribute(gltf::Semantic::Tangents), Vec4::from_array)
            .map_err(invalid_mesh)?;
        let uvs = read_attribute(
            views,
            attribute(gltf::Semantic::TexCoords(uv_mapping.tex_coord)),
            |uv| Vec2::from_array(uv_mapping.transform.apply(uv)),
        )
        .map_err(invalid_mesh)?;
        let indices = triangle_list(
            mode,
            match primitive.indices() {
                Some(accessor) => read_indices(views, &accessor).map_err(invalid_mesh)?,
                None => (0..positions.len() as u32).collect(),
            },
        );
        Ok(RawMesh {
            normals,
            uvs,
            tangents,
            indices,
            positions,
            name,
            material,
        })
    }

    /// Adds the morph targets' displacements at the mesh's default weights (glTF's
    /// `mesh.weights`; none: all zero, the base shape).
    fn apply_morph_targets(
        &self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        name: &str,
        positions: &mut [Vec3],
        normals: &mut Option<Vec<Vec3>>,
        tangents: &mut Option<Vec<Vec4>>,
    ) -> Result<()> {
        let weights = mesh.weights().unwrap_or_default();
        let invalid_mesh = |error: ReadError| self.read_error(name, error);
        for (target_index, target) in primitive.morph_targets().enumerate() {
            let weight = weights.get(target_index).copied().unwrap_or(0.0);
            if weight == 0.0 {
                continue;
            }
            if !weight.is_finite() {
                return Err(invalid_mesh(ReadError::Invalid(format!(
                    "morph weight {target_index} is {weight}"
                ))));
            }
            let displace = |accessor: Option<gltf::Accessor>,
                            what: &str,
                            count: usize|
             -> Result<Option<Vec<Vec3>>> {
                let Some(accessor) = accessor else {
                    return Ok(None);
                };
                let deltas = read_vectors::<3>(&self.views, &accessor).map_err(&invalid_mesh)?;
                if deltas.len() != count {
                    return Err(invalid_mesh(ReadError::Invalid(format!(
                        "morph target {target_index}: {} {what} displacements for {count} vertices",
                        deltas.len()
                    ))));
                }
                Ok(Some(
                    deltas
                        .into_iter()
                        .map(|d| Vec3::from_array(d) * weight)
                        .collect(),
                ))
            };
            if let Some(deltas) = displace(target.positions(), "position", positions.len())? {
                positions.iter_mut().zip(deltas).for_each(|(p, d)| *p += d);
            }
            if let Some(normals) = normals.as_mut()
                && let Some(deltas) = displace(target.normals(), "normal", normals.len())?
            {
                normals.iter_mut().zip(deltas).for_each(|(n, d)| *n += d);
            }
            if let Some(tangents) = tangents.as_mut()
                && let Some(deltas) = displace(target.tangents(), "tangent", tangents.len())?
            {
                tangents
                    .iter_mut()
                    .zip(deltas)
                    .for_each(|(t, d)| *t += d.extend(0.0));
            }
        }
        Ok(())
    }
}

/// Drops the triangles that name a vertex twice (they cover nothing; dropping them keeps
/// them out of normal generation and every later pass) and returns how many. A list whose
/// length is not a multiple of 3 is left for the mesh builder to refuse.
fn drop_degenerate_triangles(indices: &mut Vec<u32>) -> usize {
    if !indices.len().is_multiple_of(3) {
        return 0;
    }
    let before = indices.len();
    *indices = indices
        .chunks_exact(3)
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .flatten()
        .copied()
        .collect();
    (before - indices.len()) / 3
}

/// A primitive's vertex order as a triangle list, by the specification's definitions:
/// strip triangle i is (v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]) (every other one flipped
/// so all keep the first's winding), fan triangle i is (v[i + 1], v[i + 2], v[0]).
fn triangle_list(mode: gltf::mesh::Mode, vertices: Vec<u32>) -> Vec<u32> {
    use gltf::mesh::Mode;
    let triangles = vertices.len().saturating_sub(2);
    match mode {
        Mode::TriangleStrip => (0..triangles)
            .flat_map(|i| {
                let odd = i % 2;
                [vertices[i], vertices[i + 1 + odd], vertices[i + 2 - odd]]
            })
            .collect(),
        Mode::TriangleFan => (0..triangles)
            .flat_map(|i| [vertices[i + 1], vertices[i + 2], vertices[0]])
            .collect(),
        _ => vertices,
    }
}

/// Light `name`'s range in `file`, checked: an "infinite" one (at least
/// [`UNBOUNDED_RANGE`]) is read as none, with a warning in `warnings`.
fn light_range(
    warnings: &mut Vec<LoadWarning>,
    file: &Path,
    name: &str,
    range: Option<f32>,
) -> std::result::Result<Option<f32>, String> {
    match range {
        None => Ok(None),
        Some(range) if range >= UNBOUNDED_RANGE => {
            warnings.push(LoadWarning {
                file: file.display().to_string(),
                message: format!("light '{name}': range {range:e} m read as no range (unbounded)"),
            });
            Ok(None)
        }
        Some(range) if range.is_finite() && range > 0.0 => Ok(Some(range)),
        Some(range) => Err(format!(
            "range {range}: it must be a positive number of metres (leave it out for an \
             unbounded light)"
        )),
    }
}

/// A light's intensity (candela) and colour, checked: finite and non-negative.
fn checked_emission(
    light: &gltf::khr_lights_punctual::Light,
) -> std::result::Result<(f32, Vec3), String> {
    let intensity = light.intensity();
    if !intensity.is_finite() || intensity < 0.0 {
        return Err(format!(
            "intensity {intensity}: it must be a finite, non-negative number of candela"
        ));
    }
    let color = Vec3::from_array(light.color());
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(format!(
            "color {color}: each channel must be a finite, non-negative number"
        ));
    }
    Ok((intensity, color))
}

#[cfg(test)]
mod tests {
    use super::{percent_decode, triangle_list};
    use gltf::mesh::Mode;
    use std::path::PathBuf;

    #[test]
    fn strips_and_fans_become_triangle_lists_with_one_winding() {
        let vertices: Vec<u32> = (10..15).collect();
        assert_eq!(
            triangle_list(Mode::TriangleStrip, vertices.clone()),
            [10, 11, 12, 11, 13, 12, 12, 13, 14]
        );
        assert_eq!(
            triangle_list(Mode::TriangleFan, vertices.clone()),
            [11, 12, 10, 12, 13, 10, 13, 14, 10]
        );
        assert_eq!(triangle_list(Mode::Triangles, vertices.clone()), vertices);
        // Too few vertices for a triangle: nothing, not a panic.
        assert!(triangle_list(Mode::TriangleStrip, vec![1, 2]).is_empty());
        assert!(triangle_list(Mode::TriangleFan, vec![]).is_empty());
    }

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
