//! [`BlendedPass`]: blended surfaces (glTF's `BLEND`), shaded forward after the opaque
//! frame with the pipeline's light loop over the frame's lighting binding. Every pipeline
//! draws them with this pass, so sorting, the two ways layers combine
//! ([`Transparency`]) and the pipelines' cache live once: either back to front per object
//! ([`GpuScene::blended_back_to_front`]), blended over the HDR target with the "over"
//! operator (glTF's non-premultiplied alpha), or unsorted through weighted blended
//! transparency; depth tested against the opaque frame and not written. A pipeline gives
//! only its loop's key and the program that runs it: the cluster loop for Forward+ and
//! deferred (`cluster/blended.wgsl`), every light for naive (`naive/naive.wgsl`).

use std::hash::Hash;

use manylights_gpu::blended::{Transparency, WeightedComposite, record_blended};
use manylights_gpu::{
    DepthConvention, GpuResult, PipelineKey, Program, ScenePipelineDesc, ShaderLibrary,
    Specialized, wgpu,
};

use crate::{FrameInputs, FrameRecorder, LIGHTING_GROUP};

type Pipelines = Vec<(PipelineKey, wgpu::RenderPipeline)>;

/// The blended pass's pipelines, one per blended key of the scene, light loop `L` and
/// transparency a frame asks for, built on first use.
#[derive(Debug)]
pub struct BlendedPass<L> {
    library: ShaderLibrary,
    depth: DepthConvention,
    pipelines: Specialized<BlendedKey<L>, Pipelines>,
    /// Weighted transparency's targets and composite, made on its first frame.
    weighted: Option<WeightedComposite>,
}

/// What the blended pipelines are specialized for: the pipeline's light loop (its shadows
/// unfiltered: the shadow filter reads the opaque surface), how layers combine, and the
/// targets' samples a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct BlendedKey<L> {
    light_loop: L,
    transparency: Transparency,
    samples: u32,
}

/// A frame's blended draws, prepared: the pipelines of its loop, the draws' order, the
/// lighting group they bind, and the composite of weighted transparency.
#[derive(Debug)]
pub struct PreparedBlended<'a> {
    pipelines: &'a Pipelines,
    order: Vec<usize>,
    lighting: wgpu::BindGroup,
    weighted: Option<&'a WeightedComposite>,
}

impl<L: Copy + Eq + Hash> BlendedPass<L> {
    pub fn new(library: &ShaderLibrary, depth: DepthConvention) -> Self {
        Self {
            library: library.clone(),
            depth,
            pipelines: Specialized::default(),
            weighted: None,
        }
    }

    /// The frame's blended draws with `light_loop`, run by `program` (its fragment
    /// entries are [`Transparency::fragment_entry`]'s), built on the lighting layout; seen
    /// from the frame's eye and combined as its transparency says. `None` when the scene
    /// has no blended surfaces.
    pub fn prepare(
        &mut self,
        frame: &FrameInputs,
        lighting_layout: &wgpu::BindGroupLayout,
        light_loop: L,
        program: impl FnOnce(L) -> Program,
    ) -> GpuResult<Option<PreparedBlended<'_>>> {
        let (context, scene, targets) = (frame.gpu, frame.scene, frame.targets);
        let keys = scene.blended_keys();
        if keys.is_empty() {
            return Ok(None);
        }
        let transparency = frame.transparency;
        if transparency == Transparency::Weighted {
            if self.weighted.is_none() {
                self.weighted = Some(WeightedComposite::new(context, &self.library)?);
            }
            if let Some(weighted) = &mut self.weighted {
                weighted.prepare(context, targets)?;
            }
        }
        let key = BlendedKey {
            light_loop,
            transparency,
            samples: targets.samples(),
        };
        let (library, depth, view) = (&self.library, self.depth, frame.view);
        let pipelines = &*self.pipelines.get_or_build(key, |key| {
            let program = program(key.light_loop);
            let color_targets = key.transparency.color_targets();
            keys.into_iter()
                .map(|material| {
                    let desc = ScenePipelineDesc {
                        label: "blended surfaces",
                        program: &program,
                        key: material,
                        view_layout: &view.layout,
                        extra_layouts: &[lighting_layout],
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
            order: scene.blended_back_to_front(frame.eye),
            lighting: frame.lighting.group.clone(),
            weighted: self
                .weighted
                .as_ref()
                .filter(|_| transparency == Transparency::Weighted),
        }))
    }
}

impl PreparedBlended<'_> {
    /// The blended pass over the HDR target, after everything that writes it.
    pub fn record(&self, frame: &mut FrameRecorder) {
        let (scene, view, targets) = (frame.scene, frame.view, frame.targets);
        let (encoder, timer) = (&mut *frame.encoder, &mut *frame.timer);
        record_blended(encoder, timer, view, targets, self.weighted, |pass| {
            pass.set_bind_group(LIGHTING_GROUP, &self.lighting, &[]);
            scene.draw_blended(pass, &self.order, |key| {
                self.pipelines
                    .iter()
                    .find(|(k, _)| *k == key)
                    .map(|(_, pipeline)| pipeline)
            });
        });
    }
}
