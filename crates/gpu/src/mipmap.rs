//! Texture upload with a full mip chain generated on the GPU (`shaders/gpu/mipmap.wgsl`):
//! each level is drawn from the previous one with a linear filter.

use std::collections::HashMap;

use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::shaders::{MaterialVariant, Program, SHADERS, ShaderLibrary};

/// Mip generation's program (`shaders/gpu/mipmap.wgsl`).
pub fn program() -> Program {
    Program::new("mipmap", &SHADERS, "gpu/mipmap.wgsl")
}

/// Pipelines and sampler for mip generation, created once per scene upload.
#[derive(Debug)]
pub struct MipmapGenerator {
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

/// The formats textures are uploaded in.
const FORMATS: [wgpu::TextureFormat; 2] = [
    wgpu::TextureFormat::Rgba8UnormSrgb,
    wgpu::TextureFormat::Rgba8Unorm,
];

/// Number of levels in a full mip chain for a texture of this size.
pub fn mip_level_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

impl MipmapGenerator {
    pub fn new(context: &GpuContext, library: &ShaderLibrary) -> GpuResult<Self> {
        let device = &context.device;
        let module = library.create_module(context, &program(), MaterialVariant::default())?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mipmap layout"),
            entries: &[
                crate::binding::sampled_texture_entry(0, wgpu::ShaderStages::FRAGMENT),
                crate::binding::sampler_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let sampler = crate::binding::linear_clamp_sampler(device, "mipmap sampler");
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mipmap"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipelines = context.scoped("creating mipmap pipelines", || {
            FORMATS
                .iter()
                .map(|&format| {
                    let pipeline = crate::binding::fullscreen_pipeline(
                        context,
                        &format!("mipmap {format:?}"),
                        &pipeline_layout,
                        &module,
                        "fs_downsample",
                        format,
                        Default::default(),
                    );
                    (format, pipeline)
                })
                .collect()
        })?;
        Ok(Self {
            layout,
            sampler,
            pipelines,
        })
    }

    /// Creates a texture from tightly packed RGBA8 texels and fills its mip chain.
    pub fn upload(
        &self,
        context: &GpuContext,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        rgba8: &[u8],
    ) -> GpuResult<wgpu::Texture> {
        context.check_texture_size(label, size.0, size.1)?;
        let mip_count = mip_level_count(size.0, size.1);
        let device = &context.device;
        context.scoped(&format!("uploading texture {label}"), || {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.0,
                    height: size.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: mip_count,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            });
            context.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                rgba8,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * size.0),
                    rows_per_image: Some(size.1),
                },
                texture.size(),
            );
            if mip_count > 1 {
                self.generate(context, &texture, format, mip_count);
            }
            texture
        })
    }

    fn generate(
        &self,
        context: &GpuContext,
        texture: &wgpu::Texture,
        format: wgpu::TextureFormat,
        mip_count: u32,
    ) {
        let Some(pipeline) = self.pipelines.get(&format) else {
            log::error!("no mipmap pipeline for {format:?}");
            return;
        };
        let level_view = |level| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("mip level"),
                base_mip_level: level,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("mipmaps"),
            });
        for level in 1..mip_count {
            let source = level_view(level - 1);
            let target = level_view(level);
            let bind_group = crate::binding::bind_group(
                context,
                "mip source",
                &self.layout,
                [
                    (0, wgpu::BindingResource::TextureView(&source)),
                    (1, wgpu::BindingResource::Sampler(&self.sampler)),
                ],
            );
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("mip level"),
                color_attachments: &[crate::binding::cleared_color(&target, wgpu::Color::BLACK)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        context.queue.submit([encoder.finish()]);
    }
}

#[cfg(test)]
mod tests {
    use super::mip_level_count;

    #[test]
    fn full_chain_lengths() {
        assert_eq!(mip_level_count(1, 1), 1);
        assert_eq!(mip_level_count(2, 1), 2);
        assert_eq!(mip_level_count(1024, 512), 11);
        assert_eq!(mip_level_count(1000, 3), 10);
    }
}
