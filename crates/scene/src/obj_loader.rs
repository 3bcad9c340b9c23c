//! OBJ + MTL loading through `tobj`: triangulated, one index per vertex.
//!
//! Conventions (documented in the crate docs): OBJ texture coordinates have v = 0 at the
//! bottom, so v is flipped to match glTF; `Kd` and `Ks` are display (sRGB-encoded)
//! colours, as MTL files are authored by eye (Sponza's glTF conversion linearises the same
//! 3DS colours), and are decoded to linear; when `map_Kd` is present it replaces `Kd` (as in
//! most real-time OBJ viewers, and as Sponza's glTF conversion does); `map_Bump`/`bump`/
//! `norm` is a tangent-space normal map; `d` < 1 or a `map_d` turns the material into an
//! alpha-masked one (cutoff 0.5), with `map_d`'s luminance baked into the base colour
//! texture's alpha channel.

use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use crate::error::{Result, SceneError};
use crate::files::FileSource;
use crate::mesh_builder::RawMesh;
use crate::model::{AlphaMode, ColorSpace, Instance, Material, Scene, Shading, Texture};
use crate::texture::decode_or_fallback;

/// Alpha cutoff for materials whose MTL asks for dissolve (`d`, `map_d`).
const OBJ_ALPHA_CUTOFF: f32 = 0.5;

pub(crate) fn load_obj(file: &Path, bytes: &[u8], files: FileSource) -> Result<Scene> {
    let base_dir = file.parent().unwrap_or(Path::new(".")).to_path_buf();
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // The callback is `Fn`, so it reports through a RefCell.
    let mtl_error: std::cell::RefCell<Option<SceneError>> = std::cell::RefCell::new(None);
    // Each library is read once: a file repeating `mtllib` (the fuzzer made one with 144)
    // would otherwise multiply its materials.
    let libraries_read = std::cell::RefCell::new(std::collections::HashSet::new());
    let read_material_library =
        |mtl_path: &Path| match files.read(file, &base_dir, mtl_path, "material library") {
            Ok(mtl) => {
                let report = |message: String| {
                    mtl_error
                        .borrow_mut()
                        .get_or_insert(SceneError::InvalidObj {
                            file: base_dir.join(mtl_path),
                            message,
                        });
                };
                if let Err(message) = check_mtl_colours(&mtl) {
                    report(message);
                    return Err(tobj::LoadError::MaterialParseError);
                }
                tobj::load_mtl_buf(&mut BufReader::new(mtl.as_slice()))
                    .inspect_err(|e| report(e.to_string()))
            }
            Err(error) => {
                mtl_error.borrow_mut().get_or_insert(error);
                Err(tobj::LoadError::OpenFileFailed)
            }
        };
    let (models, materials) =
        tobj::load_obj_buf(&mut BufReader::new(bytes), &options, |mtl_path| {
            if !libraries_read.borrow_mut().insert(mtl_path.to_path_buf()) {
                return Ok((Vec::new(), Default::default()));
            }
            read_material_library(mtl_path)
        })
        .map_err(|e| SceneError::InvalidObj {
            file: file.to_path_buf(),
            message: e.to_string(),
        })?;
    if let Some(error) = mtl_error.into_inner() {
        return Err(error);
    }
    // A failure not reported through the callback (e.g. no mtllib at all) leaves no materials.
    let obj_materials = materials.unwrap_or_default();

    let mut loader = ObjLoader {
        file,
        base_dir: &base_dir,
        scene: Scene {
            name: file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            shading: Shading::BlinnPhong,
            ..Scene::default()
        },
        textures: HashMap::new(),
        files,
    };
    for material in &obj_materials {
        let converted = loader.material(material)?;
        loader.scene.materials.push(converted);
    }
    let default_material = loader.scene.materials.len();
    loader.scene.materials.push(Material::default());

    for model in models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = mesh
            .material_id
            .filter(|&id| id < obj_materials.len())
            .unwrap_or(default_material);
        let needs_tangents = loader.scene.materials[material].normal_texture.is_some();
        let raw = RawMesh {
            name: model.name.clone(),
            positions: mesh
                .positions
                .chunks_exact(3)
                .map(Vec3::from_slice)
                .collect(),
            normals: (!mesh.normals.is_empty())
                .then(|| mesh.normals.chunks_exact(3).map(Vec3::from_slice).collect()),
            uvs: (!mesh.texcoords.is_empty()).then(|| {
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|uv| Vec2::new(uv[0], 1.0 - uv[1]))
                    .collect()
            }),
            tangents: None,
            indices: mesh.indices.clone(),
            material,
        };
        let mesh = raw.finish(file, needs_tangents)?;
        loader.scene.meshes.push(mesh);
        loader.scene.instances.push(Instance {
            mesh: loader.scene.meshes.len() - 1,
            transform: glam::Mat4::IDENTITY,
        });
    }
    Ok(loader.scene)
}

struct ObjLoader<'a> {
    file: &'a Path,
    base_dir: &'a Path,
    /// Where referenced files come from.
    files: FileSource<'a>,
    scene: Scene,
    /// (diffuse map, dissolve map, colour space) -> index in `scene.textures`.
    textures: HashMap<(Option<String>, Option<String>, ColorSpace), usize>,
}

impl ObjLoader<'_> {
    fn material(&mut self, material: &tobj::Material) -> Result<Material> {
        let diffuse = material.diffuse.map(srgb_to_linear).unwrap_or(Vec3::ONE);
        let dissolve = material.dissolve.unwrap_or(1.0);
        let masked = dissolve < 1.0 || material.dissolve_texture.is_some();
        let base_color_texture =
            if material.diffuse_texture.is_some() || material.dissolve_texture.is_some() {
                Some(self.texture(
                    material.diffuse_texture.clone(),
                    material.dissolve_texture.clone(),
                    ColorSpace::Srgb,
                )?)
            } else {
                None
            };
        let normal_texture = match &material.normal_texture {
            Some(path) => Some(self.texture(Some(path.clone()), None, ColorSpace::Linear)?),
            None => None,
        };
        let base_rgb = if material.diffuse_texture.is_some() {
            Vec3::ONE
        } else {
            diffuse
        };
        let shininess = material.shininess.unwrap_or(1.0).max(1.0);
        Ok(Material {
            name: material.name.clone(),
            base_color_factor: base_rgb.extend(dissolve),
            base_color_texture,
            normal_texture,
            emissive_factor: Vec3::ZERO,
            emissive_texture: None,
            metallic_factor: 0.0,
            roughness_factor: Material::roughness_from_shininess(shininess),
            metallic_roughness_texture: None,
            specular_color: material
                .specular
                .map(Vec3::from_array)
                .unwrap_or(Vec3::ZERO),
            shininess,
            alpha_mode: if masked {
                AlphaMode::Mask {
                    cutoff: OBJ_ALPHA_CUTOFF,
                }
            } else {
                AlphaMode::Opaque
            },
            double_sided: false,
        })
    }

    fn read_texture_file(&self, name: &str) -> Result<(Vec<u8>, String)> {
        // MTL files written on Windows use backslashes.
        let relative = PathBuf::from(name.replace('\\', "/"));
        let bytes = self
            .files
            .read(self.file, self.base_dir, &relative, "texture")?;
        Ok((bytes, relative.display().to_string()))
    }

    fn decode(&mut self, name: &str, color_space: ColorSpace) -> Result<Texture> {
        let (bytes, source) = self.read_texture_file(name)?;
        let file = self.file.display().to_string();
        Ok(decode_or_fallback(
            &bytes,
            source,
            color_space,
            &file,
            &mut self.scene.warnings,
        ))
    }

    fn texture(
        &mut self,
        color: Option<String>,
        alpha: Option<String>,
        color_space: ColorSpace,
    ) -> Result<usize> {
        let key = (color.clone(), alpha.clone(), color_space);
        if let Some(&slot) = self.textures.get(&key) {
            return Ok(slot);
        }
        let mut texture = match &color {
            Some(name) => self.decode(name, color_space)?,
            None => Texture {
                source: "white".into(),
                width: 1,
                height: 1,
                color_space,
                rgba8: vec![255; 4],
            },
        };
        if let Some(alpha_name) = &alpha {
            let mask = self.decode(alpha_name, ColorSpace::Linear)?;
            bake_alpha(&mut texture, &mask);
            texture.source = format!("{} + alpha {}", texture.source, mask.source);
        }
        self.scene.textures.push(texture);
        let slot = self.scene.textures.len() - 1;
        self.textures.insert(key, slot);
        Ok(slot)
    }
}

/// Colour statements tobj reads as exactly three numbers.
const MTL_COLOUR_KEYWORDS: [&str; 4] = ["Ka", "Kd", "Ks", "Ke"];

/// tobj 4.0.5 panics on a colour line with fewer than three values (`Kd 0.5`; found by
/// the `obj_mtl` fuzzer): such a file is refused here first, naming the line.
fn check_mtl_colours(mtl: &[u8]) -> std::result::Result<(), String> {
    for (number, line) in mtl.split(|&b| b == b'\n').enumerate() {
        let Ok(line) = std::str::from_utf8(line) else {
            continue; // tobj reports text that is not UTF-8 itself.
        };
        let mut words = line.split_whitespace();
        if let Some(keyword) = words.next().filter(|k| MTL_COLOUR_KEYWORDS.contains(k)) {
            let values = words.count();
            if values < 3 {
                return Err(format!(
                    "line {}: '{keyword}' needs three numbers, found {values}",
                    number + 1
                ));
            }
        }
    }
    Ok(())
}

/// Decodes an sRGB-encoded colour to linear.
fn srgb_to_linear(rgb: [f32; 3]) -> Vec3 {
    Vec3::from_array(rgb.map(crate::color::srgb_to_linear))
}

/// Writes the luminance of `mask` (nearest sample, any size) into `texture`'s alpha.
fn bake_alpha(texture: &mut Texture, mask: &Texture) {
    let (w, h) = (texture.width as usize, texture.height as usize);
    for y in 0..h {
        for x in 0..w {
            let mx = x * mask.width as usize / w;
            let my = y * mask.height as usize / h;
            let m = &mask.rgba8[(my * mask.width as usize + mx) * 4..][..3];
            let luminance = 0.2126 * m[0] as f32 + 0.7152 * m[1] as f32 + 0.0722 * m[2] as f32;
            texture.rgba8[(y * w + x) * 4 + 3] = luminance.round().clamp(0.0, 255.0) as u8;
        }
    }
}
