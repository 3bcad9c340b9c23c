//! A glTF's materials and textures for the loader: metallic-roughness and its textures,
//! the UV set and `KHR_texture_transform` each material's textures read, and images decoded
//! once per colour space.

use glam::{Vec3, Vec4};

use super::{GltfLoader, MaterialUvs, read_uri};
use crate::error::{Result, SceneError};
use crate::gltf_json::{self, MaterialExtensions, TextureTransform};
use crate::model::{AlphaMode, ColorSpace, Material, Texture};
use crate::texture::decode_or_fallback;

impl GltfLoader<'_> {
    /// A material's base colour, normal, emissive and metallic-roughness textures, as
    /// indices into the scene's textures (each loaded on first use).
    pub(super) fn material_textures(
        &mut self,
        material: &gltf::Material,
    ) -> Result<[Option<usize>; 4]> {
        let pbr = material.pbr_metallic_roughness();
        let wanted = [
            (
                pbr.base_color_texture().map(|i| i.texture()),
                ColorSpace::Srgb,
            ),
            (
                material.normal_texture().map(|n| n.texture()),
                ColorSpace::Linear,
            ),
            (
                material.emissive_texture().map(|i| i.texture()),
                ColorSpace::Srgb,
            ),
            (
                pbr.metallic_roughness_texture().map(|i| i.texture()),
                ColorSpace::Linear,
            ),
        ];
        let mut indices = [None; 4];
        for (index, (texture, color_space)) in indices.iter_mut().zip(wanted) {
            *index = texture
                .map(|texture| self.texture(texture, color_space))
                .transpose()?;
        }
        Ok(indices)
    }

    pub(super) fn load_materials(
        &mut self,
        document: &gltf::Document,
        extensions: &[MaterialExtensions],
    ) -> Result<()> {
        for material in document.materials() {
            let pbr = material.pbr_metallic_roughness();
            let base_color_factor = Vec4::from_array(pbr.base_color_factor());
            let [
                base_color_texture,
                normal_texture,
                emissive_texture,
                metallic_roughness_texture,
            ] = self.material_textures(&material)?;
            let material_extensions = extensions
                .get(material.index().unwrap_or(usize::MAX))
                .cloned()
                .unwrap_or(MaterialExtensions {
                    emissive_strength: 1.0,
                    ..Default::default()
                });
            let emissive_factor = Vec3::from_array(material.emissive_factor())
                * material_extensions.emissive_strength;
            let name = material.name().unwrap_or("unnamed").to_string();
            if !emissive_factor.is_finite() || emissive_factor.min_element() < 0.0 {
                return Err(SceneError::InvalidGltf {
                    file: self.file.to_path_buf(),
                    message: format!(
                        "material '{name}': emissive {emissive_factor} must be finite and non-negative"
                    ),
                });
            }
            let tex_coords = [
                pbr.base_color_texture().map(|info| info.tex_coord()),
                material.normal_texture().map(|info| info.tex_coord()),
                material.emissive_texture().map(|info| info.tex_coord()),
            ];
            let uvs = self.material_uvs(&name, tex_coords, &material_extensions);
            self.material_uvs.push(uvs);
            let (specular_color, shininess) = Material::blinn_phong_from_metallic_roughness(
                base_color_factor.truncate(),
                pbr.metallic_factor(),
                pbr.roughness_factor(),
            );
            self.scene.materials.push(Material {
                name,
                base_color_factor,
                base_color_texture,
                normal_texture,
                emissive_factor,
                emissive_texture,
                metallic_factor: pbr.metallic_factor(),
                roughness_factor: pbr.roughness_factor(),
                metallic_roughness_texture,
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
        self.material_uvs.push(MaterialUvs {
            tex_coord: 0,
            transform: TextureTransform::IDENTITY,
        });
        Ok(())
    }

    /// The UV set and transform a material's textures are drawn with. manylights draws
    /// one UV mapping per mesh: when the base colour, normal and emissive textures ask for
    /// different ones, the first present in that order wins, with a warning.
    pub(super) fn material_uvs(
        &mut self,
        name: &str,
        tex_coords: [Option<u32>; 3],
        extensions: &MaterialExtensions,
    ) -> MaterialUvs {
        let mappings: Vec<(usize, MaterialUvs)> = tex_coords
            .iter()
            .enumerate()
            .filter_map(|(slot, tex_coord)| {
                let transform = extensions.texture_transforms[slot];
                let tex_coord = transform
                    .and_then(|transform| transform.tex_coord)
                    .or(*tex_coord)?;
                Some((
                    slot,
                    MaterialUvs {
                        tex_coord,
                        transform: transform.unwrap_or(TextureTransform::IDENTITY),
                    },
                ))
            })
            .collect();
        let Some(&(_, chosen)) = mappings.first() else {
            return MaterialUvs {
                tex_coord: 0,
                transform: TextureTransform::IDENTITY,
            };
        };
        for (slot, other) in &mappings[1..] {
            if other.tex_coord != chosen.tex_coord || !other.transform.same_uvs(&chosen.transform) {
                self.warn(format!(
                    "material '{name}': its {} uses other UVs than its {} (texCoord or KHR_texture_transform); manylights draws one UV mapping per material and uses the latter's",
                    gltf_json::MATERIAL_TEXTURES[*slot],
                    gltf_json::MATERIAL_TEXTURES[mappings[0].0],
                ));
            }
        }
        chosen
    }

    pub(super) fn texture(
        &mut self,
        texture: gltf::Texture,
        color_space: ColorSpace,
    ) -> Result<usize> {
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
                let bytes = self
                    .views
                    .bytes(&view)
                    .map_err(|message| SceneError::InvalidGltf {
                        file: self.file.to_path_buf(),
                        message: format!("image {}: {message}", image.index()),
                    })?
                    .to_vec();
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
}
