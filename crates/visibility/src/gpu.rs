//! The scene's BVH on the GPU: three textures and a uniform that every program tracing
//! shadow rays binds at group 3, bindings [`FIRST_BINDING`]..+4 (`shaders/visibility/bvh.wgsl`;
//! the numbers are the lighting group's, `manylights_lights::lighting_group`).
//!
//! Textures, not storage buffers: the clustered shading passes already bind the 8 storage
//! buffers WebGPU guarantees a stage, while a stage may sample 16 textures. The nodes and
//! triangles are RGBA32F texels read with `textureLoad` ([`ROW_TEXELS`] to a row), the
//! coverage masks one R8 atlas.

use manylights_gpu::targets::Target;
use manylights_gpu::{GpuContext, ShaderDef, wgpu};

use crate::VisibilityError;
use crate::bvh::{BvhNode, BvhTriangle, SceneBvh};
use crate::masks::{ATLAS_WIDTH, MAX_MASKS, MaskRect};

/// Texels in a row of the node and triangle textures.
pub const ROW_TEXELS: u32 = 4096;

/// Largest texture side WebGPU guarantees (`maxTextureDimension2D`).
const MAX_ROWS: u32 = 8192;

/// The group-3 binding of the BVH's uniform; the nodes, triangles and atlas follow it.
pub const FIRST_BINDING: u32 = manylights_lights::lighting_group::BVH;

/// Mirrors `BvhParams` in bvh.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BvhUniform {
    /// Nodes, triangles, masks, unused.
    counts: [u32; 4],
    mask_rects: [MaskRect; MAX_MASKS],
}

/// The constants bvh.wgsl reads as shader defs.
pub fn shader_defs() -> Vec<(String, ShaderDef)> {
    [
        ("BVH_GROUP", crate::shadow_queries::MANYLIGHTS_GROUP),
        ("BVH_ROW_TEXELS", ROW_TEXELS),
        ("BVH_STACK_SIZE", crate::bvh::MAX_DEPTH + 1),
        ("MAX_COVERAGE_MASKS", MAX_MASKS as u32),
        (
            "SHADOW_OFFSET_ABSOLUTE_INVERSE",
            (1.0 / crate::bvh::SHADOW_OFFSET_ABSOLUTE).round() as u32,
        ),
        (
            "SHADOW_OFFSET_RELATIVE_INVERSE",
            (1.0 / crate::bvh::SHADOW_OFFSET_RELATIVE).round() as u32,
        ),
    ]
    .into_iter()
    .map(|(name, value)| (name.to_string(), ShaderDef::UInt(value)))
    .collect()
}

/// A scene's BVH, uploaded once.
#[derive(Debug)]
pub struct GpuSceneBvh {
    uniform: wgpu::Buffer,
    nodes: wgpu::TextureView,
    triangles: wgpu::TextureView,
    atlas: wgpu::TextureView,
    /// Bytes of GPU memory the tree takes.
    pub bytes: u64,
    /// How many nodes and triangles the tree has.
    pub node_count: u32,
    pub triangle_count: u32,
}

impl GpuSceneBvh {
    /// Uploads `bvh`. Fails when a texture would outgrow WebGPU's 8192 rows or the device.
    pub fn new(context: &GpuContext, bvh: &SceneBvh) -> Result<GpuSceneBvh, VisibilityError> {
        let masks = bvh.masks();
        let mut uniform = BvhUniform {
            counts: [
                bvh.nodes().len() as u32,
                bvh.triangles().len() as u32,
                masks.rects().len() as u32,
                0,
            ],
            mask_rects: [MaskRect {
                x: 0,
                y: 0,
                width: 0,
                height: 0,
            }; MAX_MASKS],
        };
        uniform.mask_rects[..masks.rects().len()].copy_from_slice(masks.rects());
        let buffer = manylights_gpu::binding::uniform_buffer(
            &context.device,
            "bvh params",
            std::mem::size_of::<BvhUniform>(),
        );
        context
            .queue
            .write_buffer(&buffer, 0, bytemuck::bytes_of(&uniform));
        let nodes = texel_texture(
            context,
            "bvh nodes",
            bytemuck::cast_slice::<BvhNode, [f32; 4]>(bvh.nodes()),
        )?;
        let triangles = texel_texture(
            context,
            "bvh triangles",
            bytemuck::cast_slice::<BvhTriangle, [f32; 4]>(bvh.triangles()),
        )?;
        let atlas = Target::sampled_with_data(
            context,
            "coverage atlas",
            (ATLAS_WIDTH, masks.atlas_height()),
            wgpu::TextureFormat::R8Unorm,
            masks.atlas(),
        )?;
        let bytes = std::mem::size_of::<BvhUniform>() as u64
            + texture_bytes(&nodes.texture)
            + texture_bytes(&triangles.texture)
            + texture_bytes(&atlas.texture);
        Ok(GpuSceneBvh {
            uniform: buffer,
            nodes: nodes.view,
            triangles: triangles.view,
            atlas: atlas.view,
            bytes,
            node_count: bvh.nodes().len() as u32,
            triangle_count: bvh.triangles().len() as u32,
        })
    }

    /// An empty tree (nothing blocks any ray): what programs without shadows bind.
    pub fn empty(context: &GpuContext) -> Result<GpuSceneBvh, VisibilityError> {
        Self::new(
            context,
            &SceneBvh::build(&manylights_scene::Scene::default())?,
        )
    }

    /// The layout entries of the BVH's four bindings from [`FIRST_BINDING`].
    pub fn layout_entries(visibility: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 4] {
        use manylights_gpu::binding::uniform_entry;
        let texture = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        [
            uniform_entry(FIRST_BINDING, visibility),
            texture(FIRST_BINDING + 1),
            texture(FIRST_BINDING + 2),
            texture(FIRST_BINDING + 3),
        ]
    }

    /// The resources of [`GpuSceneBvh::layout_entries`], by binding.
    pub fn bindings(&self) -> [(u32, wgpu::BindingResource<'_>); 4] {
        [
            (FIRST_BINDING, self.uniform.as_entire_binding()),
            (
                FIRST_BINDING + 1,
                wgpu::BindingResource::TextureView(&self.nodes),
            ),
            (
                FIRST_BINDING + 2,
                wgpu::BindingResource::TextureView(&self.triangles),
            ),
            (
                FIRST_BINDING + 3,
                wgpu::BindingResource::TextureView(&self.atlas),
            ),
        ]
    }
}

/// RGBA32F texels in rows of [`ROW_TEXELS`] (the last row padded).
fn texel_texture(
    context: &GpuContext,
    label: &str,
    texels: &[[f32; 4]],
) -> Result<Target, VisibilityError> {
    let rows = (texels.len() as u32).div_ceil(ROW_TEXELS).max(1);
    if rows > MAX_ROWS {
        return Err(VisibilityError::TooLarge {
            what: label.to_string(),
            texels: texels.len() as u64,
            limit: u64::from(ROW_TEXELS) * u64::from(MAX_ROWS),
        });
    }
    let mut padded = texels.to_vec();
    padded.resize((rows * ROW_TEXELS) as usize, [0.0; 4]);
    Ok(Target::sampled_with_data(
        context,
        label,
        (ROW_TEXELS, rows),
        wgpu::TextureFormat::Rgba32Float,
        bytemuck::cast_slice(&padded),
    )?)
}

fn texture_bytes(texture: &wgpu::Texture) -> u64 {
    let texel = texture.format().block_copy_size(None).unwrap_or(1);
    u64::from(texel) * u64::from(texture.width()) * u64::from(texture.height())
}

#[cfg(test)]
mod layout_tests {
    use super::BvhUniform;
    use manylights_gpu::assert_wgsl_layout;
    use manylights_gpu::shaders::Program;

    #[test]
    fn bvh_uniform_matches_wgsl() {
        let program = Program::new("bvh", &crate::SHADERS, "visibility/bvh.wgsl");
        assert_wgsl_layout!(
            program,
            "visibility/bvh.wgsl",
            BvhParams
                == BvhUniform {
                    counts: counts,
                    mask_rects: mask_rects,
                }
        );
    }
}
