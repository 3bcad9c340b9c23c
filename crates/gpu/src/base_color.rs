//! Unlit base colour drawing (`shaders/gpu/base_color.wgsl`): the material colour of
//! every surface with no lighting. The GPU round-trip test checks uploads with it, and
//! the renderer uses it as the albedo debug view.

use crate::context::GpuContext;
use crate::depth::DepthConvention;
use crate::error::GpuResult;
use crate::shaders::{Program, SHADERS, ShaderLibrary};

/// The unlit base colour's program (`shaders/gpu/base_color.wgsl`).
pub fn program() -> Program {
    Program::shading_materials("base_color", &SHADERS, "gpu/base_color.wgsl")
}
use crate::upload::{GpuScene, PipelineKey, ScenePipelineDesc};
use crate::view::ViewBinding;

/// One pipeline per pipeline key the scene uses.
#[derive(Debug)]
pub struct BaseColorPass {
    pipelines: Vec<(PipelineKey, wgpu::RenderPipeline)>,
    depth: DepthConvention,
}

/// Where a pass draws: a colour view cleared to `clear`, and a depth view.
#[derive(Debug, Clone, Copy)]
pub struct DrawTarget<'a> {
    pub color: &'a wgpu::TextureView,
    pub depth: &'a wgpu::TextureView,
    pub clear: wgpu::Color,
}

impl BaseColorPass {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        scene: &GpuScene,
        view: &ViewBinding,
        target_format: wgpu::TextureFormat,
        depth: DepthConvention,
    ) -> GpuResult<Self> {
        let targets = [Some(target_format.into())];
        let program = program();
        let pipelines = scene
            .pipeline_keys()
            .into_iter()
            .map(|key| {
                let pipeline = scene.create_pipeline(
                    context,
                    library,
                    &ScenePipelineDesc {
                        label: "base colour",
                        program: &program,
                        key,
                        view_layout: &view.layout,
                        extra_layouts: &[],
                        vertex_entry: "vs_main",
                        fragment_entry: Some("fs_main"),
                        color_targets: &targets,
                        depth_write: true,
                        depth_compare: depth.nearer(),
                        pulls_vertices: false,
                        samples: 1,
                    },
                )?;
                Ok((key, pipeline))
            })
            .collect::<GpuResult<_>>()?;
        Ok(Self { pipelines, depth })
    }

    /// Clears the target's colour to its clear colour and depth to the far value, then
    /// draws the scene.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        view: &ViewBinding,
        target: &DrawTarget,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let DrawTarget {
            color,
            depth,
            clear,
        } = *target;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("base colour"),
            color_attachments: &[crate::binding::cleared_color(color, clear)],
            depth_stencil_attachment: Some(crate::binding::depth_attachment(
                depth,
                wgpu::LoadOp::Clear(self.depth.clear_value()),
            )),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &view.bind_group, &[]);
        for (key, pipeline) in &self.pipelines {
            pass.set_pipeline(pipeline);
            scene.draw(&mut pass, *key);
        }
    }
}
