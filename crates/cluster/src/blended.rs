//! Blended surfaces (glTF's `BLEND`), shaded forward from the cluster lists after the
//! opaque frame (`shaders/cluster/blended.wgsl`): Forward+ and deferred draw them with this
//! pass, as every engine shades transparency forward from the clusters its opaque frame
//! uses. Back to front per object ([`GpuScene::blended_back_to_front`]), blended over the
//! HDR target with the "over" operator (glTF's non-premultiplied alpha), depth tested
//! against the opaque frame and not written. The cluster boxes must reach the blended
//! surfaces: [`crate::GpuClusters::set_blended_bounds`].

use std::collections::HashMap;

use manylights_gpu::blended::{OVER, record_blended};
use manylights_gpu::{
    DepthConvention, GpuContext, GpuResult, GpuScene, GpuTimer, HDR_FORMAT, PipelineKey, Program,
    RenderTargets, ScenePipelineDesc, ShaderLibrary, ViewBinding, wgpu,
};

use crate::{LightLoop, SHADERS};

/// The blended pass's program running `light_loop` (composed per material variant).
pub fn blended_program(light_loop: LightLoop) -> Program {
    Program::shading_materials(
        format!("blended ({})", light_loop.label()),
        &SHADERS,
        "cluster/blended.wgsl",
    )
    .with_defs(light_loop.shader_defs())
}

type Pipelines = Vec<(PipelineKey, wgpu::RenderPipeline)>;

/// The blended pass's pipelines, one per blended key of the scene and light loop a frame
/// asks for, built on first use.
#[derive(Debug)]
pub struct BlendedPass {
    library: ShaderLibrary,
    depth: DepthConvention,
    pipelines: HashMap<LightLoop, Pipelines>,
}

/// A frame's blended draws, prepared: the pipelines of its loop, the draws' order and the
/// shading group they bind at group 3.
#[derive(Debug)]
pub struct PreparedBlended<'a> {
    pipelines: &'a Pipelines,
    order: Vec<usize>,
    shading_group: wgpu::BindGroup,
}

impl BlendedPass {
    pub fn new(library: &ShaderLibrary, depth: DepthConvention) -> Self {
        Self {
            library: library.clone(),
            depth,
            pipelines: HashMap::new(),
        }
    }

    /// The frame's blended draws seen from `eye` (world space), with `light_loop` (its
    /// shadows unfiltered: the filter reads the opaque surface) and the clustered shading
    /// group `shading` (its layout `shading_layout`); `None` when the scene has none, or
    /// when the loop draws a debug view (the clusters or the G-buffer alone).
    pub fn prepare(
        &mut self,
        (context, scene, view): (&GpuContext, &GpuScene, &ViewBinding),
        light_loop: LightLoop,
        (shading_layout, shading): (&wgpu::BindGroupLayout, &wgpu::BindGroup),
        eye: glam::DVec3,
    ) -> GpuResult<Option<PreparedBlended<'_>>> {
        let keys = scene.blended_keys();
        if keys.is_empty() || !light_loop.shades() {
            return Ok(None);
        }
        let light_loop = light_loop.with_shadows(light_loop.shadows().unfiltered());
        if !self.pipelines.contains_key(&light_loop) {
            let program = blended_program(light_loop);
            let targets = [Some(wgpu::ColorTargetState {
                format: HDR_FORMAT,
                blend: Some(OVER),
                write_mask: wgpu::ColorWrites::ALL,
            })];
            let built = keys
                .into_iter()
                .map(|key| {
                    let desc = ScenePipelineDesc {
                        label: "blended surfaces",
                        program: &program,
                        key,
                        view_layout: &view.layout,
                        extra_layouts: &[shading_layout],
                        vertex_entry: "vs_main",
                        fragment_entry: Some("fs_blended"),
                        color_targets: &targets,
                        depth_write: false,
                        depth_compare: self.depth.nearer(),
                        pulls_vertices: false,
                    };
                    Ok((key, scene.create_pipeline(context, &self.library, &desc)?))
                })
                .collect::<GpuResult<Pipelines>>()?;
            self.pipelines.insert(light_loop, built);
        }
        Ok(Some(PreparedBlended {
            pipelines: &self.pipelines[&light_loop],
            order: scene.blended_back_to_front(eye),
            shading_group: shading.clone(),
        }))
    }
}

impl PreparedBlended<'_> {
    /// The blended pass over the HDR target, after everything that writes it.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        (scene, view, targets): (&GpuScene, &ViewBinding, &RenderTargets),
    ) {
        record_blended(encoder, timer, (view, targets), |pass| {
            pass.set_bind_group(3, &self.shading_group, &[]);
            scene.draw_blended(pass, &self.order, |key| {
                self.pipelines
                    .iter()
                    .find(|(k, _)| *k == key)
                    .map(|(_, pipeline)| pipeline)
            });
        });
    }
}
