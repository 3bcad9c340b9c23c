//! Blended surfaces (glTF's `BLEND`) drawn over the opaque frame, in either of two ways
//! ([`Transparency`]): sorted back to front per object and blended with the "over"
//! operator, or weighted blended order-independent transparency (McGuire and Bavoil 2013)
//! into two accumulation targets that a composite pass lays over the frame
//! ([`WeightedComposite`]). Forward+ and deferred record their blended draws through
//! `cluster::BlendedPass`, naive with its own loop; both through [`record_blended`].

use crate::binding::{bind_group, depth_attachment, texture_2d_entry};
use crate::targets::{Target, multisampled_view};
use crate::{
    GpuContext, GpuResult, GpuTimer, HDR_FORMAT, MaterialVariant, PassName, Program, RenderTargets,
    ShaderLibrary, ViewBinding, shaders::SHADERS, wgpu,
};

/// The blended pass's timed name (the sorted draws, or the weighted accumulation).
pub const BLENDED_PASS: PassName = PassName::new("blended surfaces");
/// Weighted blended transparency's composite over the frame.
pub const BLENDED_COMPOSITE_PASS: PassName = PassName::new("blended composite");

/// How blended surfaces are combined with what is behind them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum Transparency {
    /// Objects sorted back to front by their box centres, each blended "over" what is
    /// drawn: exact where objects do not interleave in depth.
    #[default]
    Sorted,
    /// Weighted blended order-independent transparency: no sorting; each layer's share
    /// is weighted by its alpha and depth, exact for one layer and within
    /// `coverage * (largest - smallest layer colour)` of sorted for more.
    Weighted,
}

impl Transparency {
    pub const ALL: [Transparency; 2] = [Transparency::Sorted, Transparency::Weighted];

    pub fn name(&self) -> &'static str {
        match self {
            Transparency::Sorted => "sorted",
            Transparency::Weighted => "weighted",
        }
    }

    /// The blended fragment entry point of this way (every blended program has both).
    pub fn fragment_entry(&self) -> &'static str {
        match self {
            Transparency::Sorted => "fs_blended",
            Transparency::Weighted => "fs_blended_weighted",
        }
    }

    /// The colour targets the blended draws write.
    pub fn color_targets(&self) -> Vec<Option<wgpu::ColorTargetState>> {
        match self {
            Transparency::Sorted => vec![Some(wgpu::ColorTargetState {
                format: HDR_FORMAT,
                blend: Some(OVER),
                write_mask: wgpu::ColorWrites::ALL,
            })],
            Transparency::Weighted => vec![
                Some(wgpu::ColorTargetState {
                    format: ACCUMULATION_FORMAT,
                    blend: Some(wgpu::BlendState {
                        color: ADD,
                        alpha: ADD,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                }),
                Some(wgpu::ColorTargetState {
                    format: REVEALAGE_FORMAT,
                    blend: Some(wgpu::BlendState {
                        color: KEEP_UNCOVERED,
                        alpha: KEEP_UNCOVERED,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                }),
            ],
        }
    }
}

crate::named_choice!(Transparency, "transparency");

/// The "over" operator on the HDR target: colour by the surface's alpha over what is
/// behind it; the target's alpha kept.
pub const OVER: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::SrcAlpha,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Zero,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};

/// Sums (the weighted colours and weights).
const ADD: wgpu::BlendComponent = wgpu::BlendComponent {
    src_factor: wgpu::BlendFactor::One,
    dst_factor: wgpu::BlendFactor::One,
    operation: wgpu::BlendOperation::Add,
};

/// Multiplies the target by one minus the fragment's value (the revealage by 1 - alpha).
const KEEP_UNCOVERED: wgpu::BlendComponent = wgpu::BlendComponent {
    src_factor: wgpu::BlendFactor::Zero,
    dst_factor: wgpu::BlendFactor::OneMinusSrc,
    operation: wgpu::BlendOperation::Add,
};

/// The weighted colours and weights, summed: half floats, blendable everywhere (WebGPU
/// included); the weights are scaled so that the sums fit (`weighted_blended.wgsl`).
pub const ACCUMULATION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The product of (1 - alpha) over the layers.
pub const REVEALAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// The weight of a blended fragment of `alpha`, `view_depth` metres before the camera, in
/// weighted blended transparency: `weighted_blended_weight` in
/// `shaders/gpu/weighted_blended.wgsl`, here for the tests that hold the GPU to it (the
/// paper's equation 9, scaled by 1/300 so that sums of HDR colours fit half floats).
pub fn weighted_blended_weight(alpha: f32, view_depth: f32) -> f32 {
    let d = view_depth.max(0.0);
    let falloff = 10.0 / (1e-5 + (d / 5.0).powi(2) + (d / 200.0).powi(6));
    alpha * falloff.clamp(1e-2, 3e3) / 300.0
}

/// Weighted blended transparency's composite program (`shaders/gpu/weighted_composite.wgsl`).
pub fn composite_program() -> Program {
    Program::new(
        "weighted_composite",
        &SHADERS,
        "gpu/weighted_composite.wgsl",
    )
}

/// Weighted blended transparency's accumulation targets (sized to the frame on
/// [`WeightedComposite::prepare`]) and the pass composing them over the HDR target.
#[derive(Debug)]
pub struct WeightedComposite {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    targets: Option<AccumulationTargets>,
}

#[derive(Debug)]
struct AccumulationTargets {
    size: (u32, u32),
    accumulation: Target,
    revealage: Target,
    /// Under MSAA: the multisampled accumulation and revealage the blended draws write
    /// (beside the multisampled depth), resolved into the two above.
    multisampled: Option<[wgpu::TextureView; 2]>,
    samples: u32,
    bind_group: wgpu::BindGroup,
}

impl AccumulationTargets {
    /// The two colour attachments, cleared to no layer (sums 0, revealage 1).
    fn attachments(&self) -> [Option<wgpu::RenderPassColorAttachment<'_>>; 2] {
        let resolved = [&self.accumulation.view, &self.revealage.view];
        let clears = [wgpu::Color::TRANSPARENT, wgpu::Color::WHITE];
        std::array::from_fn(|i| {
            let (view, resolve_target) = match &self.multisampled {
                Some(multisampled) => (&multisampled[i], Some(resolved[i])),
                None => (resolved[i], None),
            };
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clears[i]),
                    store: wgpu::StoreOp::Store,
                },
            })
        })
    }
}

impl WeightedComposite {
    pub fn new(context: &GpuContext, library: &ShaderLibrary) -> GpuResult<Self> {
        let module =
            library.create_module(context, &composite_program(), MaterialVariant::default())?;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let unfiltered = wgpu::TextureSampleType::Float { filterable: false };
        let layout = context
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("weighted composite layout"),
                entries: &[
                    texture_2d_entry(0, fragment, unfiltered),
                    texture_2d_entry(1, fragment, unfiltered),
                ],
            });
        let pipeline_layout =
            context
                .device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("weighted composite"),
                    bind_group_layouts: &[Some(&layout)],
                    immediate_size: 0,
                });
        let pipeline = context.scoped("creating the weighted composite pipeline", || {
            crate::binding::fullscreen_pipeline(
                context,
                "weighted composite",
                &pipeline_layout,
                &module,
                "fs_composite",
                wgpu::ColorTargetState {
                    format: HDR_FORMAT,
                    blend: Some(OVER),
                    write_mask: wgpu::ColorWrites::ALL,
                },
                Default::default(),
            )
        })?;
        Ok(Self {
            layout,
            pipeline,
            targets: None,
        })
    }

    /// Sizes the accumulation targets to `targets` and their samples a pixel (made anew
    /// only when either changes).
    pub fn prepare(&mut self, context: &GpuContext, targets: &RenderTargets) -> GpuResult<()> {
        let samples = targets.samples();
        if self.targets.as_ref().map(|t| (t.size, t.samples)) == Some((targets.size, samples)) {
            return Ok(());
        }
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let accumulation = Target::new(
            context,
            "weighted accumulation",
            targets.size,
            ACCUMULATION_FORMAT,
            usage,
        )?;
        let revealage = Target::new(
            context,
            "weighted revealage",
            targets.size,
            REVEALAGE_FORMAT,
            usage,
        )?;
        let bind_group = bind_group(
            context,
            "weighted composite",
            &self.layout,
            [
                (0, wgpu::BindingResource::TextureView(&accumulation.view)),
                (1, wgpu::BindingResource::TextureView(&revealage.view)),
            ],
        );
        let multisampled = if samples > 1 {
            let view =
                |label, format| multisampled_view(context, label, targets.size, format, samples);
            Some([
                view("multisampled weighted accumulation", ACCUMULATION_FORMAT)?,
                view("multisampled weighted revealage", REVEALAGE_FORMAT)?,
            ])
        } else {
            None
        };
        self.targets = Some(AccumulationTargets {
            size: targets.size,
            accumulation,
            revealage,
            multisampled,
            samples,
            bind_group,
        });
        Ok(())
    }
}

/// Render passes over the opaque frame (the HDR target and the depth buffer, depth tested
/// and not written) with `draw` recording the blended draws (group 0 set): `weighted`
/// `None` blends them "over" the HDR target as they come (sorted by the caller); a
/// prepared [`WeightedComposite`] accumulates them and composites the sums.
pub fn record_blended(
    encoder: &mut wgpu::CommandEncoder,
    timer: &mut GpuTimer,
    view: &ViewBinding,
    targets: &RenderTargets,
    weighted: Option<&WeightedComposite>,
    draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
) {
    let accumulation = weighted.and_then(|w| w.targets.as_ref());
    let loaded_hdr = [targets.hdr_attachment(wgpu::LoadOp::Load)];
    let sums;
    let color_attachments: &[_] = match accumulation {
        Some(accumulation) => {
            sums = accumulation.attachments();
            &sums
        }
        None => &loaded_hdr,
    };
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(BLENDED_PASS.as_str()),
        color_attachments,
        depth_stencil_attachment: Some(depth_attachment(targets.depth_view(), wgpu::LoadOp::Load)),
        timestamp_writes: timer.render_pass(BLENDED_PASS),
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_bind_group(0, &view.bind_group, &[]);
    draw(&mut pass);
    drop(pass);
    if let (Some(weighted), Some(accumulation)) = (weighted, accumulation) {
        // Over the resolved frame, at one sample a pixel: the sums are resolved too.
        let resolved_hdr = [Some(wgpu::RenderPassColorAttachment {
            view: &targets.hdr.view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })];
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(BLENDED_COMPOSITE_PASS.as_str()),
            color_attachments: &resolved_hdr,
            depth_stencil_attachment: None,
            timestamp_writes: timer.render_pass(BLENDED_COMPOSITE_PASS),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&weighted.pipeline);
        pass.set_bind_group(0, &accumulation.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::Transparency;

    #[test]
    fn transparency_names_round_trip() {
        for way in Transparency::ALL {
            assert_eq!(way.name().parse::<Transparency>(), Ok(way));
        }
        assert!("depth-peeling".parse::<Transparency>().is_err());
    }

    /// Nearer layers weigh more, at every depth the clamp leaves free, and the weights
    /// stay within what half-float sums of HDR colours need (at most 10).
    #[test]
    fn nearer_layers_weigh_more() {
        let mut last = f32::INFINITY;
        for depth in [0.6, 1.0, 2.0, 5.0, 10.0, 50.0, 150.0] {
            let weight = super::weighted_blended_weight(1.0, depth);
            assert!(
                weight < last,
                "{depth} m weighs {weight}, not less than nearer"
            );
            assert!(weight <= 10.0);
            last = weight;
        }
        assert_eq!(
            super::weighted_blended_weight(0.5, 3.0),
            0.5 * super::weighted_blended_weight(1.0, 3.0)
        );
    }
}
