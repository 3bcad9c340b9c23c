//! Bloom (`shaders/gpu/bloom.wgsl`): the HDR frame blended toward a wide, energy-keeping
//! blur of itself, in compute, after temporal anti-aliasing and before the tonemap. The
//! result is written back into the HDR target.

use crate::binding::{CachedBindGroup, ComputePasses};
use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::shaders::{MaterialVariant, Program, SHADERS, ShaderLibrary};
use crate::targets::{HDR_FORMAT, RenderTargets, Target};
use crate::timer::{GpuTimer, PassName, timed_compute_pass};

/// The pass's program.
pub fn program() -> Program {
    Program::new("bloom", &SHADERS, "gpu/bloom.wgsl")
}

/// The passes, timed together.
pub const BLOOM_PASS: PassName = PassName::new("bloom");

/// How much of each level is the coarser levels' (`SPREAD` in `bloom.wgsl`): level k of
/// the chain weighs (1 - SPREAD) SPREAD^k in the bloom, so the light spreads mostly near
/// its source (level 0, 2 pixels, holds 30%) with a long, faint reach.
pub const BLOOM_SPREAD: f32 = 0.7;

/// The chain stops before a level's shorter side would fall under this (or at
/// [`BLOOM_MAX_LEVELS`]): coarser levels reach no further than the frame.
const BLOOM_MIN_SIDE: u32 = 8;
/// At 1920x1080: 960x540 down to 15x9, seven levels.
const BLOOM_MAX_LEVELS: u32 = 7;

/// The levels of the chain for a frame of `size`: half the size each, from half the
/// frame.
pub fn bloom_levels(size: (u32, u32)) -> Vec<(u32, u32)> {
    let mut levels = Vec::new();
    let mut level = (size.0.div_ceil(2), size.1.div_ceil(2));
    while levels.len() < BLOOM_MAX_LEVELS as usize && level.0.min(level.1) >= BLOOM_MIN_SIDE {
        levels.push(level);
        level = (level.0.div_ceil(2), level.1.div_ceil(2));
    }
    levels
}

/// Mirrors `BloomParams` in `bloom.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BloomParamsGpu {
    strength: f32,
    spread: f32,
    _pad: [f32; 2],
}

/// The chain's images at one frame size.
#[derive(Debug)]
struct Chain {
    size: (u32, u32),
    /// The down chain, D[i] (each level its own texture: a level is read by one dispatch
    /// and written by the next).
    down: Vec<Target>,
    /// The up chain, U[i] for every level but the coarsest (U of the coarsest is its D).
    up: Vec<Target>,
    /// The bloomed frame, copied into the HDR target.
    bloomed: Target,
    /// One group a dispatch, in recording order.
    groups: Vec<CachedBindGroup>,
}

impl Chain {
    fn new(context: &GpuContext, size: (u32, u32)) -> GpuResult<Self> {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING;
        let levels = bloom_levels(size);
        let down = levels
            .iter()
            .map(|level| Target::new(context, "bloom down", *level, HDR_FORMAT, usage))
            .collect::<GpuResult<Vec<_>>>()?;
        let up = levels[..levels.len().saturating_sub(1)]
            .iter()
            .map(|level| Target::new(context, "bloom up", *level, HDR_FORMAT, usage))
            .collect::<GpuResult<Vec<_>>>()?;
        let bloomed = Target::new(
            context,
            "bloomed frame",
            size,
            HDR_FORMAT,
            usage | wgpu::TextureUsages::COPY_SRC,
        )?;
        Ok(Self {
            size,
            down,
            up,
            bloomed,
            groups: Vec::new(),
        })
    }
}

/// U[i]: the up chain's level, or the down chain's for the coarsest.
fn up_level<'a>(down: &'a [Target], up: &'a [Target], level: usize) -> &'a Target {
    if level + 1 == down.len() {
        &down[level]
    } else {
        &up[level]
    }
}

/// Bloom's passes and their images.
#[derive(Debug)]
pub struct Bloom {
    first: wgpu::ComputePipeline,
    down: wgpu::ComputePipeline,
    up: wgpu::ComputePipeline,
    composite: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    sampler: wgpu::Sampler,
    chain: Option<Chain>,
}

/// Which of the four programs a dispatch runs.
#[derive(Debug, Clone, Copy)]
enum Step {
    First,
    Down,
    Up,
    Composite,
}

/// One frame's bloom, prepared: each dispatch's program, group and size.
#[derive(Debug)]
pub struct PreparedBloom<'a> {
    /// The first step's, the down steps', the up steps' and the composite's programs.
    pipelines: [&'a wgpu::ComputePipeline; 4],
    dispatches: Vec<(Step, wgpu::BindGroup, (u32, u32))>,
    bloomed: &'a wgpu::Texture,
    hdr: &'a wgpu::Texture,
}

fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 6] {
    use crate::binding::{
        sampled_texture_entry, sampler_entry, storage_entry, storage_texture_entry, uniform_entry,
    };
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        sampled_texture_entry(0, compute),
        sampled_texture_entry(1, compute),
        sampler_entry(2, compute),
        storage_texture_entry(3, HDR_FORMAT),
        uniform_entry(4, compute),
        storage_entry(5, compute, true),
    ]
}

impl Bloom {
    pub fn new(context: &GpuContext, library: &ShaderLibrary) -> GpuResult<Self> {
        let module = library.create_module(context, &program(), MaterialVariant::default())?;
        let ComputePasses {
            layout,
            pipelines: [first, down, up, composite],
        } = ComputePasses::new(
            context,
            &module,
            "bloom",
            &[],
            &layout_entries(),
            [
                "cs_downsample_first",
                "cs_downsample",
                "cs_upsample",
                "cs_composite",
            ],
        )?;
        let params = crate::binding::uniform_buffer(
            &context.device,
            "bloom params",
            std::mem::size_of::<BloomParamsGpu>(),
        );
        let sampler = crate::binding::linear_clamp_sampler(&context.device, "bloom sampler");
        Ok(Self {
            first,
            down,
            up,
            composite,
            layout,
            params,
            sampler,
            chain: None,
        })
    }

    /// Prepares bloom of `strength` (above 0) over `targets`, with `exposure` the exposure
    /// state the tonemap applies (the first step's firefly weights are of the shown
    /// image). A frame too small for one level (under 16 pixels a side) is left as it is.
    pub fn prepare<'a>(
        &'a mut self,
        context: &GpuContext,
        targets: &'a RenderTargets,
        exposure: &wgpu::Buffer,
        strength: f32,
    ) -> GpuResult<Option<PreparedBloom<'a>>> {
        if self
            .chain
            .as_ref()
            .is_none_or(|chain| chain.size != targets.size)
        {
            self.chain = Some(Chain::new(context, targets.size)?);
        }
        let Self {
            first,
            down: down_pipeline,
            up: up_pipeline,
            composite,
            layout,
            params,
            sampler,
            chain,
        } = self;
        let Some(Chain {
            down,
            up,
            bloomed,
            groups,
            ..
        }) = chain
        else {
            unreachable!("made above")
        };
        if down.is_empty() {
            return Ok(None);
        }
        let params_buffer = &*params;
        let params = BloomParamsGpu {
            strength,
            spread: BLOOM_SPREAD,
            _pad: [0.0; 2],
        };
        context
            .queue
            .write_buffer(params_buffer, 0, bytemuck::bytes_of(&params));

        let plan = dispatch_plan(&targets.hdr.view, down, up, bloomed);
        groups.resize_with(plan.len(), Default::default);
        let mut dispatches = Vec::with_capacity(plan.len());
        for (dispatch, cached) in plan.into_iter().zip(groups.iter_mut()) {
            let PlannedDispatch {
                step,
                source,
                detail,
                destination,
            } = dispatch;
            let group = cached.get(
                context,
                "bloom",
                layout,
                [
                    (0, wgpu::BindingResource::TextureView(source)),
                    (1, wgpu::BindingResource::TextureView(detail)),
                    (2, wgpu::BindingResource::Sampler(sampler)),
                    (3, wgpu::BindingResource::TextureView(&destination.view)),
                    (4, params_buffer.as_entire_binding()),
                    (5, exposure.as_entire_binding()),
                ],
            );
            let size = destination.texture.size();
            dispatches.push((step, group, (size.width, size.height)));
        }
        Ok(Some(PreparedBloom {
            pipelines: [first, down_pipeline, up_pipeline, composite],
            dispatches,
            bloomed: &bloomed.texture,
            hdr: &targets.hdr.texture,
        }))
    }
}

/// One dispatch of the chain: its step, what it reads (`source`, and the finer level it
/// adds back, `detail`) and what it writes.
struct PlannedDispatch<'a> {
    step: Step,
    source: &'a wgpu::TextureView,
    detail: &'a wgpu::TextureView,
    destination: &'a Target,
}

/// The chain's dispatches in recording order: the first step from `hdr` into the finest
/// level, down the `down` levels, up through the `up` levels, then the composite of the
/// finest up level over `hdr` into `bloomed`.
fn dispatch_plan<'a>(
    hdr: &'a wgpu::TextureView,
    down: &'a [Target],
    up: &'a [Target],
    bloomed: &'a Target,
) -> Vec<PlannedDispatch<'a>> {
    let dispatch = |step, source, detail, destination| PlannedDispatch {
        step,
        source,
        detail,
        destination,
    };
    let levels = down.len();
    let mut plan = vec![dispatch(Step::First, hdr, hdr, &down[0])];
    for level in 1..levels {
        let finer = &down[level - 1].view;
        plan.push(dispatch(Step::Down, finer, finer, &down[level]));
    }
    for level in (0..levels - 1).rev() {
        let coarser = &up_level(down, up, level + 1).view;
        plan.push(dispatch(Step::Up, coarser, &down[level].view, &up[level]));
    }
    let finest = &up_level(down, up, 0).view;
    plan.push(dispatch(Step::Composite, finest, hdr, bloomed));
    plan
}

impl PreparedBloom<'_> {
    /// Records the chain and the composite, then copies the bloomed frame into the HDR
    /// target.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        {
            let mut pass = timed_compute_pass(encoder, Some(timer), BLOOM_PASS);
            for (step, group, (width, height)) in &self.dispatches {
                pass.set_pipeline(self.pipelines[*step as usize]);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(
                    width.div_ceil(crate::SCREEN_TILE),
                    height.div_ceil(crate::SCREEN_TILE),
                    1,
                );
            }
        }
        crate::targets::copy_whole_texture(encoder, self.bloomed, self.hdr);
    }
}

#[cfg(test)]
mod tests {
    use super::{BloomParamsGpu, bloom_levels, program};
    use crate::assert_wgsl_layout;

    #[test]
    fn bloom_params_match_wgsl() {
        assert_wgsl_layout!(
            program(),
            "gpu/bloom.wgsl",
            BloomParams
                == BloomParamsGpu {
                    strength: strength,
                    spread: spread,
                    _pad0: _pad,
                    _pad1: _pad + 4,
                }
        );
    }

    #[test]
    fn the_chain_halves_down_to_eight_pixels() {
        assert_eq!(
            bloom_levels((1920, 1080)),
            vec![
                (960, 540),
                (480, 270),
                (240, 135),
                (120, 68),
                (60, 34),
                (30, 17),
                (15, 9)
            ]
        );
        assert_eq!(bloom_levels((64, 48)), vec![(32, 24), (16, 12)]);
        assert!(bloom_levels((14, 200)).is_empty());
    }
}
