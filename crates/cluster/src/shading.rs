//! The group-3 resources of every clustered shading pass (`shaders/cluster/cluster_lights.wgsl`):
//! grid, list offsets, light indices, lights, and the shading parameters. Forward+ and the
//! deferred lighting passes share this layout and the function that shades a cluster.

use manylights_gpu::{DebugView, GpuContext, GpuResult, wgpu};
use manylights_lights::{Falloff, GpuLights};

use crate::gpu::GpuClusters;

/// Mirrors `ClusteredShadingParams` in the shader.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ClusteredShadingUniform {
    falloff: u32,
    heatmap_max: f32,
    debug_view: u32,
    _pad: u32,
}

/// Layout and parameter buffer of the clustered shading bind group (group 3).
#[derive(Debug)]
pub struct ClusteredShading {
    pub layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
}

impl ClusteredShading {
    pub fn new(context: &GpuContext, visibility: wgpu::ShaderStages) -> Self {
        use manylights_gpu::binding::{storage_entry, uniform_entry};
        let layout = context
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("clustered shading layout"),
                entries: &[
                    uniform_entry(0, visibility),
                    storage_entry(1, visibility, true),
                    storage_entry(2, visibility, true),
                    storage_entry(3, visibility, true),
                    uniform_entry(4, visibility),
                ],
            });
        let uniform = manylights_gpu::binding::uniform_buffer(
            &context.device,
            "clustered shading params",
            std::mem::size_of::<ClusteredShadingUniform>(),
        );
        Self { layout, uniform }
    }

    /// Uploads this frame's parameters and binds the frame's lists and lights.
    pub fn bind_group(
        &self,
        context: &GpuContext,
        clusters: &GpuClusters,
        lights: &GpuLights,
        falloff: Falloff,
        debug_view: DebugView,
    ) -> GpuResult<wgpu::BindGroup> {
        let params = ClusteredShadingUniform {
            falloff: falloff.shader_mode(),
            heatmap_max: debug_view.heatmap_max(),
            debug_view: debug_view.shader_code(),
            _pad: 0,
        };
        context
            .queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&params));
        Ok(context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("clustered shading"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: clusters.params_buffer().as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: clusters.offsets_buffer()?.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: clusters.indices_buffer()?.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: lights.buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: self.uniform.as_entire_binding(),
                    },
                ],
            }))
    }
}
