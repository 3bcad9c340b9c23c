//! Blended surfaces (glTF's `BLEND`), shaded forward from the cluster lists after the
//! opaque frame (`shaders/cluster/blended.wgsl`): Forward+ and deferred draw them with this
//! pass, as every engine shades transparency forward from the clusters its opaque frame
//! uses. Either back to front per object ([`GpuScene::blended_back_to_front`]), blended
//! over the HDR target with the "over" operator (glTF's non-premultiplied alpha), or
//! unsorted through weighted blended transparency ([`Transparency`]); depth tested against
//! the opaque frame and not written. The cluster boxes must reach the blended surfaces:
//! [`crate::GpuClusters::set_blended_bounds`].

use manylights_gpu::blended::{Transparency, WeightedComposite, record_blended};
use manylights_gpu::{
    DepthConvention, GpuContext, GpuResult, GpuScene, GpuTimer, PipelineKey, Program,
    RenderTargets, ScenePipelineDesc, ShaderLibrary, Specialized, ViewBinding, wgpu,
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

/// The blended pass's pipelines, one per blended key of the scene, light loop and
/// transparency a frame asks for, built on first use.
#[derive(Debug)]
pub struct BlendedPass {
    library: ShaderLibrary,
    depth: DepthConvention,
    pipelines: Specialized<BlendedKey, Pipelines>,
    /// Weighted transparency's targets and composite, made on its first frame.
    weighted: Option<WeightedComposite>,
}

/// What the blended pipelines are specialized for: the light loop (its shadows
/// unfiltered), how layers combine, and the targets' samples a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct BlendedKey {
    light_loop: LightLoop,
    transparency: Transparency,
    samples: u32,
}

/// A frame's blended draws, prepared: the pipelines of its loop, the draws' order, the
/// shading group they bind at group 3, and the composite of weighted transparency.
#[derive(Debug)]
pub struct PreparedBlended<'a> {
    pipelines: &'a Pipelines,
    order: Vec<usize>,
    shading_group: wgpu::BindGroup,
    weighted: Option<&'a WeightedComposite>,
}

impl BlendedPass {
    pub fn new(library: &ShaderLibrary, depth: DepthConvention) -> Self {
        Self {
            library: library.clone(),
            depth,
            pipelines: Specialized::default(),
            weighted: None,
        }
    }

    /// The frame's blended draws seen from `eye` (world space) and combined as
    /// `transparency` says, with `light_loop` (its shadows unfiltered: the filter reads the
    /// opaque surface) and the clustered shading group `shading` (its layout
    /// `shading_layout`); `None` when the scene has none, or when the loop draws a debug
    /// view (the clusters or the G-buffer alone).
    pub fn prepare(
        &mut self,
        (context, scene, view, targets): (&GpuContext, &GpuScene, &ViewBinding, &RenderTargets),
        light_loop: LightLoop,
        (shading_layout, shading): (&wgpu::BindGroupLayout, &wgpu::BindGroup),
        (eye, transparency): (glam::DVec3, Transparency),
    ) -> GpuResult<Option<PreparedBlended<'_>>> {
        let keys = scene.blended_keys();
        if keys.is_empty() || !light_loop.shades() {
            return Ok(None);
        }
        if transparency == Transparency::Weighted {
            if self.weighted.is_none() {
                self.weighted = Some(WeightedComposite::new(context, &self.library)?);
            }
            if let Some(weighted) = &mut self.weighted {
                weighted.prepare(context, targets)?;
            }
        }
        let key = BlendedKey {
            light_loop: light_loop.with_shadows(light_loop.shadows().unfiltered()),
            transparency,
            samples: targets.samples(),
        };
        let (library, depth) = (&self.library, self.depth);
        let pipelines = &*self.pipelines.get_or_build(key, |key| {
            let program = blended_program(key.light_loop);
            let color_targets = key.transparency.color_targets();
            keys.into_iter()
                .map(|material| {
                    let desc = ScenePipelineDesc {
                        label: "blended surfaces",
                        program: &program,
                        key: material,
                        view_layout: &view.layout,
                        extra_layouts: &[shading_layout],
                        vertex_entry: "vs_main",
                        fragment_entry: Some(key.transparency.fragment_entry()),
                        color_targets: &color_targets,
                        depth_write: false,
                        depth_compare: depth.nearer(),
                        pulls_vertices: false,
                        samples: key.samples,
                    };
                    Ok((material, scene.create_pipeline(context, library, &desc)?))
                })
                .collect()
        })?;
        Ok(Some(PreparedBlended {
            pipelines,
            order: scene.blended_back_to_front(eye),
            shading_group: shading.clone(),
            weighted: self
                .weighted
                .as_ref()
                .filter(|_| transparency == Transparency::Weighted),
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
        record_blended(encoder, timer, (view, targets), self.weighted, |pass| {
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
