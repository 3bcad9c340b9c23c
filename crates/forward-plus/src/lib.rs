//! Forward+ (clustered forward) shading (`shaders/forward_plus/forward_plus.wgsl`): after
//! the cluster assignment, each fragment finds its cluster with the shared
//! `cluster_index` and shades only that cluster's lights. An optional depth pre-pass
//! (`depth_prepass`) lays down depth first, so the shading pass (depth test LessEqual, no
//! writes) shades each pixel once. Material and alpha-mask handling is the scene's, as
//! in naive: one pipeline per `PipelineKey`, built from the scene's `MaterialVariant`.
//!
//! The cluster debug views are drawn by the same pipelines' other fragment entry points:
//! a lights-per-cluster heatmap with a legend strip, and depth-slice colouring.

use manylights_cluster::GpuClusters;
use manylights_gpu::{
    GpuContext, GpuResult, GpuScene, GpuTimer, HDR_FORMAT, PipelineKey, Program, RenderTargets,
    ScenePipelineDesc, ShaderLibrary, ViewBinding, wgpu,
};
use manylights_lights::{Falloff, GpuLights};

/// What the Forward+ pass draws.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ClusterDebugView {
    /// Normal shading.
    #[default]
    None,
    /// Lights per cluster: black (0) through blue, cyan, green, yellow, red to white
    /// (`max_lights` or more); the strip at the bottom is the legend, ticks at quarters.
    Heatmap { max_lights: f32 },
    /// Each depth slice in its own colour, tiles in a checkerboard.
    ZSlices,
}

/// Mirrors `ForwardPlusParams` in the shader.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ForwardPlusUniform {
    falloff: u32,
    heatmap_max: f32,
    _pad: [u32; 2],
}

type Pipelines = Vec<(PipelineKey, wgpu::RenderPipeline)>;

/// The Forward+ pipelines for one uploaded scene.
#[derive(Debug)]
pub struct ForwardPlusPipeline {
    depth_prepass: Pipelines,
    shade_after_prepass: Pipelines,
    shade: Pipelines,
    heatmap: Pipelines,
    slices: Pipelines,
    /// Group 3: cluster params, offsets, indices, lights, Forward+ params.
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
}

fn read_only_storage(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl ForwardPlusPipeline {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        scene: &GpuScene,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        let device = &context.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("forward+ layout"),
            entries: &[
                uniform(0),
                read_only_storage(1),
                read_only_storage(2),
                read_only_storage(3),
                uniform(4),
            ],
        });
        let hdr = [Some(HDR_FORMAT.into())];
        let build = |label: &str,
                     fragment: Option<&str>,
                     targets: &[Option<wgpu::ColorTargetState>],
                     depth_write: bool,
                     compare: wgpu::CompareFunction|
         -> GpuResult<Pipelines> {
            scene
                .pipeline_keys()
                .into_iter()
                .map(|key| {
                    // Opaque depth-only pipelines need no fragment stage at all.
                    let fragment_entry = if fragment == Some("fs_depth") && !key.alpha_mask {
                        None
                    } else {
                        fragment
                    };
                    let desc = ScenePipelineDesc {
                        label,
                        program: Program::ForwardPlus,
                        key,
                        view_layout: &view.layout,
                        extra_layouts: &[&layout],
                        vertex_entry: "vs_main",
                        fragment_entry,
                        color_targets: targets,
                        depth_write,
                        depth_compare: compare,
                    };
                    Ok((key, scene.create_pipeline(context, library, &desc)?))
                })
                .collect()
        };
        Ok(Self {
            depth_prepass: build(
                "forward+ depth pre-pass",
                Some("fs_depth"),
                &[],
                true,
                wgpu::CompareFunction::Less,
            )?,
            shade_after_prepass: build(
                "forward+ shading",
                Some("fs_main"),
                &hdr,
                false,
                wgpu::CompareFunction::LessEqual,
            )?,
            shade: build(
                "forward+ shading (no pre-pass)",
                Some("fs_main"),
                &hdr,
                true,
                wgpu::CompareFunction::Less,
            )?,
            heatmap: build(
                "forward+ heatmap",
                Some("fs_heatmap"),
                &hdr,
                true,
                wgpu::CompareFunction::Less,
            )?,
            slices: build(
                "forward+ z slices",
                Some("fs_slices"),
                &hdr,
                true,
                wgpu::CompareFunction::Less,
            )?,
            uniform: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("forward+ params"),
                size: std::mem::size_of::<ForwardPlusUniform>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            layout,
        })
    }

    /// Records the optional depth pre-pass and the shading (or debug) pass into the HDR
    /// target. The cluster assignment for this frame must already be recorded.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        view: &ViewBinding,
        clusters: &GpuClusters,
        lights: &GpuLights,
        falloff: Falloff,
        depth_prepass: bool,
        debug_view: ClusterDebugView,
        targets: &RenderTargets,
        timer: &mut GpuTimer,
    ) -> GpuResult<()> {
        let heatmap_max = match debug_view {
            ClusterDebugView::Heatmap { max_lights } => max_lights.max(1.0),
            _ => 1.0,
        };
        let params = ForwardPlusUniform {
            falloff: falloff.shader_mode(),
            heatmap_max,
            _pad: [0; 2],
        };
        context
            .queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&params));
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("forward+"),
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
            });
        let prepass = depth_prepass && debug_view == ClusterDebugView::None;
        if prepass {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("forward+ depth pre-pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(depth_attachment(targets, wgpu::LoadOp::Clear(1.0))),
                timestamp_writes: timer.render_pass("depth pre-pass"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &view.bind_group, &[]);
            pass.set_bind_group(3, &bind_group, &[]);
            for (key, pipeline) in &self.depth_prepass {
                pass.set_pipeline(pipeline);
                scene.draw(&mut pass, *key);
            }
        }
        let (pipelines, name) = match debug_view {
            ClusterDebugView::None if prepass => (&self.shade_after_prepass, "forward+ shading"),
            ClusterDebugView::None => (&self.shade, "forward+ shading"),
            ClusterDebugView::Heatmap { .. } => (&self.heatmap, "cluster heatmap"),
            ClusterDebugView::ZSlices => (&self.slices, "cluster z slices"),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &targets.hdr.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(depth_attachment(
                targets,
                if prepass {
                    wgpu::LoadOp::Load
                } else {
                    wgpu::LoadOp::Clear(1.0)
                },
            )),
            timestamp_writes: timer.render_pass(name),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &view.bind_group, &[]);
        pass.set_bind_group(3, &bind_group, &[]);
        for (key, pipeline) in pipelines {
            pass.set_pipeline(pipeline);
            scene.draw(&mut pass, *key);
        }
        Ok(())
    }
}

fn depth_attachment(
    targets: &RenderTargets,
    load: wgpu::LoadOp<f32>,
) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view: &targets.depth.view,
        depth_ops: Some(wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}
