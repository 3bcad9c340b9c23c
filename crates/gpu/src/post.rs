//! The post pass (`shaders/post/tonemap.wgsl`): exposure, then a tonemap curve, from the
//! HDR target into the sRGB output. Shared by every pipeline.

use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::shaders::{MaterialVariant, Program, ShaderLibrary};
use crate::targets::{OUTPUT_FORMAT, RenderTargets};

/// How HDR radiance is mapped to the display.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Tonemap {
    /// Clamp to [0, 1]: what the HDR target holds, for comparisons.
    None,
    /// x / (1 + x).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve. Default.
    #[default]
    AcesFit,
}

impl Tonemap {
    fn shader_curve(&self) -> u32 {
        match self {
            Tonemap::None => 0,
            Tonemap::Reinhard => 1,
            Tonemap::AcesFit => 2,
        }
    }
}

/// Mirrors `TonemapParams` in `shaders/post/tonemap.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TonemapUniform {
    exposure: f32,
    curve: u32,
    _pad: [u32; 2],
}

#[derive(Debug)]
pub struct TonemapPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
}

impl TonemapPass {
    pub fn new(context: &GpuContext, library: &ShaderLibrary) -> GpuResult<Self> {
        let device = &context.device;
        let module =
            library.create_module(context, Program::Tonemap, MaterialVariant::default())?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                crate::binding::uniform_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let pipeline = context.scoped("creating the tonemap pipeline", || {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("tonemap"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            crate::binding::fullscreen_pipeline(
                device,
                "tonemap",
                &pipeline_layout,
                &module,
                "fs_tonemap",
                OUTPUT_FORMAT,
                Default::default(),
            )
        })?;
        let uniform = crate::binding::uniform_buffer(
            device,
            "tonemap params",
            std::mem::size_of::<TonemapUniform>(),
        );
        Ok(Self {
            pipeline,
            layout,
            uniform,
        })
    }

    /// Records HDR -> output with `exposure` and `curve`.
    pub fn record(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        targets: &RenderTargets,
        exposure: f32,
        curve: Tonemap,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let uniform = TonemapUniform {
            exposure,
            curve: curve.shader_curve(),
            _pad: [0; 2],
        };
        context
            .queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("tonemap"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&targets.hdr.view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: self.uniform.as_entire_binding(),
                    },
                ],
            });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tonemap"),
            color_attachments: &[crate::binding::cleared_color(
                &targets.output.view,
                wgpu::Color::BLACK,
            )],
            depth_stencil_attachment: None,
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
