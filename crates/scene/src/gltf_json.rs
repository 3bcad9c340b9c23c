//! The glTF JSON, read the way the specification reads it before the `gltf` crate sees it.
//!
//! The `gltf` crate (1.4) is stricter than the specification in three places, each met in
//! files the Khronos validator accepts:
//! - serde refuses an integer property written as a float (`"byteStride": 12.0`): JSON has
//!   one number type, and glTF's integers are numbers with no fractional part. Every whole
//!   number is rewritten as an integer here (a float property accepts an integer).
//! - serde refuses an animation channel target without a `node` (optional in the
//!   specification, used with `KHR_animation_pointer`). manylights draws a static frame, so
//!   animations are dropped here, with a warning, before the crate parses them.
//! - serde/validation refuse application-specific vertex attributes (names starting with
//!   `_`, allowed by the specification), and the crate's attribute iterator would panic on
//!   them: they are removed here (manylights reads none of them).
//! - validation refuses an accessor with neither a `bufferView` nor `sparse` ("Missing
//!   data"), which the specification defines as zeros. [`validate`] runs the crate's
//!   validation and lets that one report through; the accessor reader
//!   (`gltf_accessor.rs`) reads such an accessor as zeros.
//!
//! It also reads the extensions the crate does not model on the objects that carry them:
//! `EXT_meshopt_compression` (and its ratified twin `KHR_meshopt_compression`) on buffer
//! views and buffers, and `KHR_texture_transform` on every texture reference of a material
//! (the crate models it on the base colour texture only), and `EXT_mesh_gpu_instancing` on
//! nodes.

use std::collections::{HashMap, HashSet};

use serde_json::Value;

/// How a buffer view's data is compressed (`EXT_meshopt_compression`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MeshoptView {
    /// The buffer holding the compressed bytes, and where in it.
    pub buffer: usize,
    pub byte_offset: usize,
    pub byte_length: usize,
    /// Bytes per decoded element.
    pub byte_stride: usize,
    /// Decoded elements.
    pub count: usize,
    pub mode: MeshoptMode,
    pub filter: MeshoptFilter,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MeshoptMode {
    Attributes,
    Triangles,
    Indices,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MeshoptFilter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
    Color,
}

/// `KHR_texture_transform` on one texture reference: uv' = offset + R(rotation) S(scale) uv,
/// with the specification's rotation (counter-clockwise in UV space, v pointing down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TextureTransform {
    pub offset: [f32; 2],
    pub rotation: f32,
    pub scale: [f32; 2],
    /// Replaces the texture reference's `texCoord` when present.
    pub tex_coord: Option<u32>,
}

impl TextureTransform {
    pub const IDENTITY: TextureTransform = TextureTransform {
        offset: [0.0, 0.0],
        rotation: 0.0,
        scale: [1.0, 1.0],
        tex_coord: None,
    };

    /// The transform applied to one UV (the specification's translation * rotation *
    /// scale matrix).
    pub fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let (sin, cos) = self.rotation.sin_cos();
        let (u, v) = (uv[0] * self.scale[0], uv[1] * self.scale[1]);
        [
            cos * u + sin * v + self.offset[0],
            -sin * u + cos * v + self.offset[1],
        ]
    }

    /// Whether two references sample with the same UVs.
    pub fn same_uvs(&self, other: &TextureTransform) -> bool {
        self.offset == other.offset && self.rotation == other.rotation && self.scale == other.scale
    }
}

/// The texture references of a material that manylights samples, in the order they take
/// precedence when they disagree on UVs (one UV set is drawn per mesh).
pub(crate) const MATERIAL_TEXTURES: [&str; 3] =
    ["baseColorTexture", "normalTexture", "emissiveTexture"];

/// What a material's extensions say, read from its JSON.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct MaterialExtensions {
    /// `KHR_texture_transform` per entry of [`MATERIAL_TEXTURES`] (`None`: the reference
    /// is absent or has no transform).
    pub texture_transforms: [Option<TextureTransform>; 3],
    /// `KHR_materials_emissive_strength` (1 without it).
    pub emissive_strength: f32,
}

/// `EXT_mesh_gpu_instancing` on a node: the accessors of its per-instance transform
/// attributes (each absent one is the identity).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct NodeInstancing {
    pub translation: Option<usize>,
    pub rotation: Option<usize>,
    pub scale: Option<usize>,
}

/// The JSON parsed into the crate's model, plus what the crate does not read.
#[derive(Debug)]
pub(crate) struct PreparedJson {
    pub root: gltf::json::Root,
    /// Compressed buffer views by index.
    pub meshopt_views: HashMap<usize, MeshoptView>,
    /// Buffers marked `fallback`: placeholders (often without data) for compressed views.
    pub meshopt_fallback_buffers: HashSet<usize>,
    /// Per material, in the file's order.
    pub materials: Vec<MaterialExtensions>,
    /// Instanced nodes by index.
    pub node_instancing: HashMap<usize, NodeInstancing>,
    /// Non-fatal findings (dropped animations), for the scene's warnings.
    pub warnings: Vec<String>,
}

/// Extension names that compress buffer views with meshoptimizer's codecs.
pub(crate) const MESHOPT_EXTENSIONS: [&str; 2] =
    ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// Parses a glTF JSON document. Errors are messages for `SceneError::InvalidGltf`.
pub(crate) fn prepare(json_bytes: &[u8]) -> Result<PreparedJson, String> {
    let mut value: Value = serde_json::from_slice(json_bytes).map_err(|e| e.to_string())?;
    if !value.is_object() {
        return Err("the document is not a JSON object".into());
    }
    whole_numbers_as_integers(&mut value);
    let mut warnings = Vec::new();
    if let Some(animations) = value
        .as_object_mut()
        .and_then(|root| root.remove("animations"))
        && let Some(count) = animations.as_array().map(Vec::len).filter(|&n| n > 0)
    {
        warnings.push(format!(
            "{count} animation(s) ignored: manylights draws the scene as the nodes place it"
        ));
    }
    remove_application_attributes(&mut value);
    let meshopt_views = meshopt_views(&value)?;
    let meshopt_fallback_buffers = meshopt_fallback_buffers(&value);
    let materials = material_extensions(&value)?;
    let node_instancing = node_instancing(&value)?;
    let root: gltf::json::Root = serde_json::from_value(value).map_err(|e| e.to_string())?;
    Ok(PreparedJson {
        root,
        meshopt_views,
        meshopt_fallback_buffers,
        materials,
        node_instancing,
        warnings,
    })
}

/// The crate's validation, less its rule the specification does not have (an accessor
/// with neither `bufferView` nor `sparse` is zeros, not an error) and less its check of
/// `extensionsRequired` against the extensions the crate models (the loader checks them
/// against the ones manylights implements, which include some the crate does not model).
pub(crate) fn validate(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::{Error, Validate};
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path().to_string();
        let zeros_accessor = matches!(error, Error::Missing)
            && path.starts_with("accessors[")
            && path.ends_with("].bufferView");
        let required_extension = path.starts_with("extensionsRequired[");
        if !zeros_accessor && !required_extension {
            errors.push(format!("{path}: {error}"));
        }
    });
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors.join(", "))
    }
}

/// Rewrites every number with no fractional part (and within f64's exact integers) as an
/// integer, in place.
fn whole_numbers_as_integers(value: &mut Value) {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    match value {
        Value::Number(number) if number.is_f64() => {
            let float = number.as_f64().unwrap_or(f64::NAN);
            if float.fract() == 0.0 && float.abs() <= EXACT {
                *value = if float >= 0.0 {
                    Value::from(float as u64)
                } else {
                    Value::from(float as i64)
                };
            }
        }
        Value::Array(items) => items.iter_mut().for_each(whole_numbers_as_integers),
        Value::Object(fields) => fields.values_mut().for_each(whole_numbers_as_integers),
        _ => {}
    }
}

/// Removes vertex attributes whose names start with `_` (application-specific) from
/// every primitive and morph target.
fn remove_application_attributes(root: &mut Value) {
    let Some(meshes) = root.get_mut("meshes").and_then(Value::as_array_mut) else {
        return;
    };
    let primitives = meshes
        .iter_mut()
        .filter_map(|mesh| mesh.get_mut("primitives").and_then(Value::as_array_mut))
        .flatten();
    for primitive in primitives {
        if let Some(attributes) = primitive
            .get_mut("attributes")
            .and_then(Value::as_object_mut)
        {
            attributes.retain(|name, _| !name.starts_with('_'));
        }
        if let Some(targets) = primitive.get_mut("targets").and_then(Value::as_array_mut) {
            for target in targets.iter_mut().filter_map(Value::as_object_mut) {
                target.retain(|name, _| !name.starts_with('_'));
            }
        }
    }
}

/// The first of `names` present in an object's `extensions`.
fn extension<'a>(object: &'a Value, names: &[&'a str]) -> Option<(&'a str, &'a Value)> {
    let extensions = object.get("extensions")?;
    names
        .iter()
        .find_map(|&name| extensions.get(name).map(|value| (name, value)))
}

fn index_field(object: &Value, field: &str, context: &str) -> Result<usize, String> {
    object
        .get(field)
        .and_then(Value::as_u64)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| format!("{context}: '{field}' must be a non-negative integer"))
}

fn optional_index_field(object: &Value, field: &str, context: &str) -> Result<usize, String> {
    match object.get(field) {
        None => Ok(0),
        Some(_) => index_field(object, field, context),
    }
}

fn meshopt_views(root: &Value) -> Result<HashMap<usize, MeshoptView>, String> {
    let mut views = HashMap::new();
    let Some(list) = root.get("bufferViews").and_then(Value::as_array) else {
        return Ok(views);
    };
    for (index, view) in list.iter().enumerate() {
        let Some((name, compression)) = extension(view, &MESHOPT_EXTENSIONS) else {
            continue;
        };
        let context = format!("bufferViews[{index}].extensions.{name}");
        let mode = match compression.get("mode").and_then(Value::as_str) {
            Some("ATTRIBUTES") => MeshoptMode::Attributes,
            Some("TRIANGLES") => MeshoptMode::Triangles,
            Some("INDICES") => MeshoptMode::Indices,
            other => {
                return Err(format!(
                    "{context}: mode must be ATTRIBUTES, TRIANGLES or INDICES, got {other:?}"
                ));
            }
        };
        let filter = match compression.get("filter").and_then(Value::as_str) {
            None | Some("NONE") => MeshoptFilter::None,
            Some("OCTAHEDRAL") => MeshoptFilter::Octahedral,
            Some("QUATERNION") => MeshoptFilter::Quaternion,
            Some("EXPONENTIAL") => MeshoptFilter::Exponential,
            Some("COLOR") => MeshoptFilter::Color,
            Some(other) => return Err(format!("{context}: unknown filter '{other}'")),
        };
        views.insert(
            index,
            MeshoptView {
                buffer: index_field(compression, "buffer", &context)?,
                byte_offset: optional_index_field(compression, "byteOffset", &context)?,
                byte_length: index_field(compression, "byteLength", &context)?,
                byte_stride: index_field(compression, "byteStride", &context)?,
                count: index_field(compression, "count", &context)?,
                mode,
                filter,
            },
        );
    }
    Ok(views)
}

fn meshopt_fallback_buffers(root: &Value) -> HashSet<usize> {
    let Some(list) = root.get("buffers").and_then(Value::as_array) else {
        return HashSet::new();
    };
    list.iter()
        .enumerate()
        .filter(|(_, buffer)| {
            extension(buffer, &MESHOPT_EXTENSIONS)
                .is_some_and(|(_, ext)| ext.get("fallback").and_then(Value::as_bool) == Some(true))
        })
        .map(|(index, _)| index)
        .collect()
}

fn material_extensions(root: &Value) -> Result<Vec<MaterialExtensions>, String> {
    let Some(list) = root.get("materials").and_then(Value::as_array) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::with_capacity(list.len());
    for (index, material) in list.iter().enumerate() {
        let mut extensions = MaterialExtensions {
            emissive_strength: 1.0,
            ..Default::default()
        };
        if let Some((_, strength)) = extension(material, &["KHR_materials_emissive_strength"]) {
            let value = match strength.get("emissiveStrength") {
                None => 1.0,
                Some(value) => value.as_f64().unwrap_or(f64::NAN) as f32,
            };
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!(
                    "materials[{index}].extensions.KHR_materials_emissive_strength: emissiveStrength must be a finite number >= 0, got {value}"
                ));
            }
            extensions.emissive_strength = value;
        }
        for (slot, texture) in MATERIAL_TEXTURES.iter().enumerate() {
            let reference = match *texture {
                "baseColorTexture" => material
                    .get("pbrMetallicRoughness")
                    .and_then(|pbr| pbr.get(texture)),
                _ => material.get(texture),
            };
            let Some((_, transform)) =
                reference.and_then(|reference| extension(reference, &["KHR_texture_transform"]))
            else {
                continue;
            };
            let context = format!("materials[{index}].{texture}.extensions.KHR_texture_transform");
            extensions.texture_transforms[slot] = Some(texture_transform(transform, &context)?);
        }
        out.push(extensions);
    }
    Ok(out)
}

fn node_instancing(root: &Value) -> Result<HashMap<usize, NodeInstancing>, String> {
    let Some(list) = root.get("nodes").and_then(Value::as_array) else {
        return Ok(HashMap::new());
    };
    let mut out = HashMap::new();
    for (index, node) in list.iter().enumerate() {
        let Some((_, instancing)) = extension(node, &["EXT_mesh_gpu_instancing"]) else {
            continue;
        };
        let context = format!("nodes[{index}].extensions.EXT_mesh_gpu_instancing.attributes");
        let Some(attributes) = instancing.get("attributes") else {
            return Err(format!("{context}: missing"));
        };
        let attribute = |name: &str| match attributes.get(name) {
            None => Ok(None),
            Some(_) => index_field(attributes, name, &context).map(Some),
        };
        out.insert(
            index,
            NodeInstancing {
                translation: attribute("TRANSLATION")?,
                rotation: attribute("ROTATION")?,
                scale: attribute("SCALE")?,
            },
        );
    }
    Ok(out)
}

fn texture_transform(value: &Value, context: &str) -> Result<TextureTransform, String> {
    let pair = |field: &str, default: [f32; 2]| -> Result<[f32; 2], String> {
        match value.get(field) {
            None => Ok(default),
            Some(Value::Array(items)) if items.len() == 2 => {
                let a = items[0].as_f64().unwrap_or(f64::NAN) as f32;
                let b = items[1].as_f64().unwrap_or(f64::NAN) as f32;
                if a.is_finite() && b.is_finite() {
                    Ok([a, b])
                } else {
                    Err(format!("{context}: {field} must be two finite numbers"))
                }
            }
            Some(_) => Err(format!("{context}: {field} must be two finite numbers")),
        }
    };
    let rotation = match value.get("rotation") {
        None => 0.0,
        Some(rotation) => rotation.as_f64().unwrap_or(f64::NAN) as f32,
    };
    if !rotation.is_finite() {
        return Err(format!(
            "{context}: rotation must be a finite number of radians"
        ));
    }
    let tex_coord = match value.get("texCoord") {
        None => None,
        Some(_) => Some(
            u32::try_from(index_field(value, "texCoord", context)?)
                .map_err(|_| format!("{context}: texCoord is out of range"))?,
        ),
    };
    Ok(TextureTransform {
        offset: pair("offset", [0.0, 0.0])?,
        rotation,
        scale: pair("scale", [1.0, 1.0])?,
        tex_coord,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_floats_become_integers_and_fractions_stay() {
        let mut value: Value =
            serde_json::from_str(r#"{"a": 12.0, "b": [1.5, -3.0, 1e300], "c": 4}"#).unwrap();
        whole_numbers_as_integers(&mut value);
        assert_eq!(value["a"], Value::from(12u64));
        assert_eq!(value["b"][0], Value::from(1.5));
        assert_eq!(value["b"][1], Value::from(-3i64));
        // Past 2^53 a float is not an exact integer: left alone.
        assert!(value["b"][2].is_f64());
        assert_eq!(value["c"], Value::from(4u64));
    }

    #[test]
    fn texture_transform_follows_the_specification() {
        // The extension's example: rotating by 90 degrees maps u to -v.
        let transform = TextureTransform {
            offset: [0.5, 0.0],
            rotation: std::f32::consts::FRAC_PI_2,
            scale: [2.0, 1.0],
            tex_coord: None,
        };
        let [u, v] = transform.apply([1.0, 0.0]);
        assert!((u - 0.5).abs() < 1e-6, "{u}");
        assert!((v + 2.0).abs() < 1e-6, "{v}");
        assert_eq!(TextureTransform::IDENTITY.apply([0.25, 0.75]), [0.25, 0.75]);
    }
}
