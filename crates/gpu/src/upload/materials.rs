//! The scene's materials on the GPU: textures with their mip chains and 1x1 stand-ins,
//! the material bind group's layout (only the textures the scene uses) and its groups, the
//! sampler, and the flags the shaders read.

use manylights_scene::{AlphaMode, ColorSpace, Material, Scene, SceneFeatures};
use wgpu::util::DeviceExt as _;

use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::mipmap::MipmapGenerator;
use crate::shaders::ShaderLibrary;

use super::GpuMaterialUniform;

const WHITE: [u8; 4] = [255, 255, 255, 255];
const FLAT_NORMAL: [u8; 4] = [128, 128, 255, 255];

/// The scene's textures on the GPU with their mip chains, and the 1x1 stand-ins bound where
/// a material has no texture.
pub(super) struct SceneTextures {
    /// Kept alive for the bind groups: the scene's, then white and the flat normal.
    pub(super) textures: Vec<wgpu::Texture>,
    pub(super) views: Vec<wgpu::TextureView>,
    pub(super) white_view: wgpu::TextureView,
    pub(super) flat_normal_view: wgpu::TextureView,
}

impl SceneTextures {
    pub(super) fn upload(
        context: &GpuContext,
        library: &ShaderLibrary,
        scene: &Scene,
    ) -> GpuResult<Self> {
        let mipmaps = MipmapGenerator::new(context, library)?;
        let mut textures = Vec::with_capacity(scene.textures.len() + 2);
        let mut views = Vec::with_capacity(scene.textures.len());
        for texture in &scene.textures {
            let format = match texture.color_space {
                ColorSpace::Srgb => wgpu::TextureFormat::Rgba8UnormSrgb,
                ColorSpace::Linear => wgpu::TextureFormat::Rgba8Unorm,
            };
            let uploaded = mipmaps.upload(
                context,
                &texture.source,
                (texture.width, texture.height),
                format,
                &texture.rgba8,
            )?;
            views.push(uploaded.create_view(&wgpu::TextureViewDescriptor::default()));
            textures.push(uploaded);
        }
        let white = mipmaps.upload(
            context,
            "white",
            (1, 1),
            wgpu::TextureFormat::Rgba8UnormSrgb,
            &WHITE,
        )?;
        let flat_normal = mipmaps.upload(
            context,
            "flat normal",
            (1, 1),
            wgpu::TextureFormat::Rgba8Unorm,
            &FLAT_NORMAL,
        )?;
        let white_view = white.create_view(&wgpu::TextureViewDescriptor::default());
        let flat_normal_view = flat_normal.create_view(&wgpu::TextureViewDescriptor::default());
        textures.push(white);
        textures.push(flat_normal);

        Ok(Self {
            textures,
            views,
            white_view,
            flat_normal_view,
        })
    }
}

/// Materials are read by fragment shaders and by the visibility buffer's compute resolve.
pub(super) const MATERIAL_STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

/// Group 2's layout: the material uniform and sampler, and the textures the scene's
/// material variant samples.
pub(super) fn material_layout(
    device: &wgpu::Device,
    features: SceneFeatures,
) -> wgpu::BindGroupLayout {
    let texture_entry = |binding| crate::binding::sampled_texture_entry(binding, MATERIAL_STAGES);
    let mut layout_entries = vec![
        crate::binding::uniform_entry(0, MATERIAL_STAGES),
        crate::binding::sampler_entry(1, MATERIAL_STAGES),
    ];
    if features.base_color_textures {
        layout_entries.push(texture_entry(2));
    }
    if features.normal_maps {
        layout_entries.push(texture_entry(3));
    }
    if features.emissive {
        layout_entries.push(texture_entry(4));
    }
    if features.metallic_roughness_textures {
        layout_entries.push(texture_entry(5));
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("material layout"),
        entries: &layout_entries,
    })
}

/// One material's bind group (group 2): its uniform, the sampler and its textures.
pub(super) fn material_bind_group(
    context: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    textures: &SceneTextures,
    sampler: &wgpu::Sampler,
    material: &Material,
    features: SceneFeatures,
) -> wgpu::BindGroup {
    let (cutoff, double_sided) = material_flags(material);
    let uniform = GpuMaterialUniform {
        base_color_factor: material.base_color_factor.to_array(),
        specular_shininess: material
            .specular_color
            .extend(material.shininess)
            .to_array(),
        alpha_cutoff_double_sided: [cutoff, if double_sided { 1.0 } else { 0.0 }, 0.0, 0.0],
        emissive: material.emissive_factor.extend(0.0).to_array(),
        metallic_roughness: [
            material.metallic_factor,
            material.roughness_factor,
            0.0,
            0.0,
        ],
    };
    let buffer = context
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(&format!("material {}", material.name)),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
    let base_view = material
        .base_color_texture
        .map(|t| &textures.views[t])
        .unwrap_or(&textures.white_view);
    let normal_view = material
        .normal_texture
        .map(|t| &textures.views[t])
        .unwrap_or(&textures.flat_normal_view);
    let emissive_view = material
        .emissive_texture
        .map(|t| &textures.views[t])
        .unwrap_or(&textures.white_view);
    // White is 1 in sRGB as in linear: the factors alone.
    let metallic_roughness_view = material
        .metallic_roughness_texture
        .map(|t| &textures.views[t])
        .unwrap_or(&textures.white_view);
    // Textures only where the scene's material variant samples them.
    let textures = [
        (2, features.base_color_textures, base_view),
        (3, features.normal_maps, normal_view),
        (4, features.emissive, emissive_view),
        (
            5,
            features.metallic_roughness_textures,
            metallic_roughness_view,
        ),
    ]
    .into_iter()
    .filter(|&(_, used, _)| used)
    .map(|(binding, _, view)| (binding, wgpu::BindingResource::TextureView(view)));
    let resources = [
        (0, buffer.as_entire_binding()),
        (1, wgpu::BindingResource::Sampler(sampler)),
    ]
    .into_iter()
    .chain(textures);
    crate::binding::bind_group(
        context,
        &format!("material {}", material.name),
        layout,
        resources,
    )
}

/// The materials' sampler: repeating, trilinear.
pub(super) fn material_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("material sampler"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

/// (alpha cutoff, double-sided) as the shaders see them. Blend materials have no cutoff:
/// their alpha is composited by the blended passes (`crate::blended`), not tested.
pub(super) fn material_flags(material: &manylights_scene::Material) -> (f32, bool) {
    let cutoff = match material.alpha_mode {
        AlphaMode::Mask { cutoff } => cutoff,
        AlphaMode::Opaque | AlphaMode::Blend => 0.0,
    };
    (cutoff, material.double_sided)
}
