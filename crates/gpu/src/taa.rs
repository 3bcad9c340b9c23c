//! Temporal anti-aliasing (`shaders/gpu/taa.wgsl`): the projection's sub-pixel jitter,
//! and the compute pass that averages each surface point's jittered samples over frames.
//! It runs after the pipeline has shaded the HDR target and before bloom and the tonemap,
//! the same in every pipeline, and writes its result back into the HDR target, so what
//! follows (and what the lab and the tests read back) is the anti-aliased frame.

use crate::binding::{CachedBindGroup, ComputePasses};
use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::shaders::{MaterialVariant, Program, SHADERS, ShaderLibrary};
use crate::targets::{HDR_FORMAT, RenderTargets, Target};
use crate::timer::{GpuTimer, PassName, timed_compute_pass};

/// The pass's program.
pub fn program() -> Program {
    Program::new("taa", &SHADERS, "gpu/taa.wgsl")
}

/// The pass, timed.
pub const TAA_PASS: PassName = PassName::new("temporal anti-aliasing");

/// Anti-aliasing of the frame after shading (MSAA is a separate dial, `--msaa`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum AntiAliasing {
    /// One sample a pixel, at its centre.
    #[default]
    Off,
    /// Temporal anti-aliasing: a jittered sample a frame, averaged over frames.
    Taa,
}

crate::named_choice!(AntiAliasing, "anti-aliasing");

impl AntiAliasing {
    pub const ALL: [AntiAliasing; 2] = [AntiAliasing::Off, AntiAliasing::Taa];

    /// `off`, `taa`.
    pub fn name(&self) -> &'static str {
        match self {
            AntiAliasing::Off => "off",
            AntiAliasing::Taa => "taa",
        }
    }
}

/// The mip bias of material textures under temporal anti-aliasing. Its running mean
/// averages 16 samples a pixel, as a frame at 4x4 the pixels does, which samples textures
/// two mip levels finer (a bias of -2): without a bias the mean blurs textures by a whole
/// pixel more than that frame (`manylights edges`, Sponza 480x270: an edge error of 0.138
/// against 4x MSAA's 0.123; -1: 0.094; -2: 0.068). -1 is half way: each frame's own
/// samples alias textures twice as finely as without TAA, where -2 would alias them four
/// times as finely before the history averages them (the shimmer of a moving camera).
pub const TEXTURE_LOD_BIAS: f32 = -1.0;

/// The jitter sequence's length: a still camera's pixel averages this many samples.
pub const JITTER_SAMPLES: u32 = 16;

/// The `n`th element of the van der Corput sequence in `base` (the radical inverse).
fn radical_inverse(mut n: u32, base: u32) -> f32 {
    let mut inverse = 0.0;
    let mut scale = 1.0 / base as f32;
    while n > 0 {
        inverse += (n % base) as f32 * scale;
        n /= base;
        scale /= base as f32;
    }
    inverse
}

/// Frame `frame`'s sample position within the pixel, in pixels from its centre (each
/// coordinate in -0.5..0.5): the Halton (2, 3) points 1 to 16, repeating. They spread
/// over the pixel evenly at every prefix (a low-discrepancy sequence), so the running
/// mean is a good estimate of the pixel's box average long before the cycle completes.
pub fn jitter_in_pixels(frame: u32) -> (f32, f32) {
    let n = frame % JITTER_SAMPLES + 1;
    (radical_inverse(n, 2) - 0.5, radical_inverse(n, 3) - 0.5)
}

/// Frame `frame`'s jitter as the NDC translation the projection is moved by, for a
/// target of `size` pixels (NDC spans 2 across the frame; y points up).
pub fn jitter_in_ndc(frame: u32, size: (u32, u32)) -> [f32; 2] {
    let (x, y) = jitter_in_pixels(frame);
    [
        2.0 * x / size.0.max(1) as f32,
        -2.0 * y / size.1.max(1) as f32,
    ]
}

/// Mirrors `TaaParams` in `taa.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TaaParamsGpu {
    history_valid: u32,
    _pad: [u32; 3],
}

/// What the surface history stores: distance, frames and an octahedral normal, in f32
/// (a distance in half floats would end at 65,504 m).
const SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The two frames of history, read one frame and written the next.
#[derive(Debug)]
struct History {
    size: (u32, u32),
    /// The resolved radiance (HDR format).
    colour: [Target; 2],
    /// What each pixel saw (`SURFACE_FORMAT`).
    surface: [Target; 2],
    /// The pair the next frame reads.
    read: usize,
    /// Whether `read` holds a frame of this history (false on a first frame, after a
    /// resize, and after [`TemporalAntiAliasing::forget_history`]).
    valid: bool,
}

impl History {
    fn new(context: &GpuContext, size: (u32, u32)) -> GpuResult<Self> {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING;
        let colour = |label| {
            Target::new(
                context,
                label,
                size,
                HDR_FORMAT,
                usage | wgpu::TextureUsages::COPY_SRC,
            )
        };
        let surface = |label| Target::new(context, label, size, SURFACE_FORMAT, usage);
        Ok(Self {
            size,
            colour: [colour("taa history 0")?, colour("taa history 1")?],
            surface: [
                surface("taa surface history 0")?,
                surface("taa surface history 1")?,
            ],
            read: 0,
            valid: false,
        })
    }
}

/// Temporal anti-aliasing's pass and its history.
#[derive(Debug)]
pub struct TemporalAntiAliasing {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    sampler: wgpu::Sampler,
    history: Option<History>,
    /// One group for each direction the history flows.
    groups: [CachedBindGroup; 2],
}

/// One frame's pass, prepared.
#[derive(Debug)]
pub struct PreparedTaa<'a> {
    pipeline: &'a wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    resolved: &'a wgpu::Texture,
    hdr: &'a wgpu::Texture,
    size: (u32, u32),
}

fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 9] {
    use crate::binding::{
        depth_texture_entry, sampled_texture_entry, sampler_entry, storage_entry,
        storage_texture_entry, texture_2d_entry, uniform_entry,
    };
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        sampled_texture_entry(0, compute),
        depth_texture_entry(1, compute),
        sampled_texture_entry(2, compute),
        texture_2d_entry(
            3,
            compute,
            wgpu::TextureSampleType::Float { filterable: false },
        ),
        sampler_entry(4, compute),
        uniform_entry(5, compute),
        storage_entry(6, compute, true),
        storage_texture_entry(7, HDR_FORMAT),
        storage_texture_entry(8, SURFACE_FORMAT),
    ]
}

impl TemporalAntiAliasing {
    /// The pass's pipeline, on the view's layout (group 0).
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view_layout: &wgpu::BindGroupLayout,
    ) -> GpuResult<Self> {
        let module = library.create_module(context, &program(), MaterialVariant::default())?;
        let ComputePasses {
            layout,
            pipelines: [pipeline],
        } = ComputePasses::new(
            context,
            &module,
            "temporal anti-aliasing",
            &[view_layout],
            &layout_entries(),
            ["cs_resolve"],
        )?;
        let params = crate::binding::uniform_buffer(
            &context.device,
            "taa params",
            std::mem::size_of::<TaaParamsGpu>(),
        );
        let sampler = crate::binding::linear_clamp_sampler(&context.device, "taa history sampler");
        Ok(Self {
            pipeline,
            layout,
            params,
            sampler,
            history: None,
            groups: Default::default(),
        })
    }

    /// Drops the history: the next frame starts the running mean afresh (a new pipeline,
    /// scene or BRDF: the frame before was not of this image).
    pub fn forget_history(&mut self) {
        if let Some(history) = &mut self.history {
            history.valid = false;
        }
    }

    /// Prepares this frame's pass over `targets` (the history is made, or remade at a new
    /// size, here), with `exposure` the exposure state the tonemap applies.
    pub fn prepare<'a>(
        &'a mut self,
        context: &GpuContext,
        targets: &'a RenderTargets,
        exposure: &wgpu::Buffer,
    ) -> GpuResult<PreparedTaa<'a>> {
        if self
            .history
            .as_ref()
            .is_none_or(|history| history.size != targets.size)
        {
            self.history = Some(History::new(context, targets.size)?);
        }
        let Some(history) = &mut self.history else {
            unreachable!("made above")
        };
        let params = TaaParamsGpu {
            history_valid: u32::from(history.valid),
            _pad: [0; 3],
        };
        context
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let (read, write) = (history.read, 1 - history.read);
        let group = self.groups[read].get(
            context,
            "temporal anti-aliasing",
            &self.layout,
            [
                (0, wgpu::BindingResource::TextureView(&targets.hdr.view)),
                (1, wgpu::BindingResource::TextureView(&targets.depth.view)),
                (
                    2,
                    wgpu::BindingResource::TextureView(&history.colour[read].view),
                ),
                (
                    3,
                    wgpu::BindingResource::TextureView(&history.surface[read].view),
                ),
                (4, wgpu::BindingResource::Sampler(&self.sampler)),
                (5, self.params.as_entire_binding()),
                (6, exposure.as_entire_binding()),
                (
                    7,
                    wgpu::BindingResource::TextureView(&history.colour[write].view),
                ),
                (
                    8,
                    wgpu::BindingResource::TextureView(&history.surface[write].view),
                ),
            ],
        );
        history.read = write;
        history.valid = true;
        Ok(PreparedTaa {
            pipeline: &self.pipeline,
            group,
            resolved: &history.colour[write].texture,
            hdr: &targets.hdr.texture,
            size: targets.size,
        })
    }
}

impl PreparedTaa<'_> {
    /// Records the resolve (with the view at group 0) and copies its result into the HDR
    /// target.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view_group: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        let (width, height) = self.size;
        {
            let mut pass = timed_compute_pass(encoder, Some(timer), TAA_PASS);
            pass.set_pipeline(self.pipeline);
            pass.set_bind_group(0, view_group, &[]);
            pass.set_bind_group(1, &self.group, &[]);
            pass.dispatch_workgroups(
                width.div_ceil(crate::SCREEN_TILE),
                height.div_ceil(crate::SCREEN_TILE),
                1,
            );
        }
        crate::targets::copy_whole_texture(encoder, self.resolved, self.hdr);
    }
}

#[cfg(test)]
mod tests {
    use super::{TaaParamsGpu, jitter_in_pixels, program};
    use crate::assert_wgsl_layout;

    #[test]
    fn taa_params_match_wgsl() {
        assert_wgsl_layout!(
            program(),
            "gpu/taa.wgsl",
            TaaParams
                == TaaParamsGpu {
                    history_valid: history_valid,
                    _pad0: _pad,
                    _pad1: _pad + 4,
                    _pad2: _pad + 8,
                }
        );
    }

    /// The jitter stays inside the pixel, never repeats within a cycle, and its mean is
    /// near the pixel's centre (the points are spread evenly).
    #[test]
    fn jitter_covers_the_pixel_evenly() {
        let points: Vec<(f32, f32)> = (0..super::JITTER_SAMPLES).map(jitter_in_pixels).collect();
        for (i, a) in points.iter().enumerate() {
            assert!(
                a.0.abs() < 0.5 && a.1.abs() < 0.5,
                "{a:?} outside the pixel"
            );
            for b in &points[i + 1..] {
                assert_ne!(a, b, "a point repeats within the cycle");
            }
        }
        let n = points.len() as f32;
        let mean = points
            .iter()
            .fold((0.0, 0.0), |m, p| (m.0 + p.0 / n, m.1 + p.1 / n));
        // Halton points 1..16: the mean's offset is at most about 1/16 per axis.
        assert!(mean.0.abs() < 0.07 && mean.1.abs() < 0.07, "mean {mean:?}");
        assert_eq!(
            jitter_in_pixels(3),
            jitter_in_pixels(3 + super::JITTER_SAMPLES)
        );
    }
}
