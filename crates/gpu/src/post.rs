//! The post passes, shared by every pipeline: automatic exposure
//! (`shaders/gpu/exposure.wgsl`: a luminance histogram and its median, on the GPU), then
//! exposure and a tonemap curve (`shaders/gpu/tonemap.wgsl`) from the HDR target into
//! the sRGB output.

use crate::binding::ComputePasses;
use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::shader_files;
use crate::shaders::{MaterialVariant, Program, SHADERS, ShaderLibrary, ShaderModules};

/// The tonemap pass's program (`shaders/gpu/tonemap.wgsl`).
pub fn tonemap_program() -> Program {
    Program::new("tonemap", &SHADERS, "gpu/tonemap.wgsl")
}

/// Automatic exposure's program (`shaders/gpu/exposure.wgsl`).
pub fn auto_exposure_program() -> Program {
    Program::new("auto_exposure", &EXPOSURE_SHADERS, "gpu/exposure.wgsl")
}

/// Automatic exposure's WGSL, which reads the histogram's size and the tile of its
/// workgroups as constants (the crate's other modules from [`SHADERS`]).
pub static EXPOSURE_SHADERS: ShaderModules = ShaderModules {
    owner: "gpu",
    files: shader_files!["gpu/exposure.wgsl"],
    uses: &[&SHADERS],
    constants: || vec![histogram_bins_def(), exposure_tile_def()],
};
use crate::targets::{OUTPUT_STORAGE_FORMAT, RenderTargets};
use crate::timer::{GpuTimer, PassName, timed_compute_pass};

/// The automatic exposure's timed pass.
pub const AUTO_EXPOSURE_PASS: PassName = PassName::new("auto exposure");
/// The tonemap's timed pass.
pub const TONEMAP_PASS: PassName = PassName::new("tonemap");

/// How HDR radiance is scaled before the tonemap curve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Exposure {
    /// Multiply radiance by this factor (accuracy comparisons use one fixed exposure, so
    /// automatic exposure can neither hide nor create error).
    Manual(f32),
    /// Chosen on the GPU from the frame's luminance histogram: the median luminance of
    /// the lit pixels is mapped to mid-grey (0.18).
    Auto(AutoExposure),
}

impl Exposure {
    /// The factor, if it is fixed.
    pub fn manual(&self) -> Option<f32> {
        match self {
            Exposure::Manual(value) => Some(*value),
            Exposure::Auto(_) => None,
        }
    }
}

/// Settings of automatic exposure.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct AutoExposure {
    /// Stops added to the exposure that maps the median to mid-grey.
    pub compensation_ev: f32,
    /// How far (in stops) the exposure moves from its current value toward this frame's
    /// target: 1 converges in this frame (`render`), smaller values adapt smoothly (the
    /// viewer, from the frame time: see [`AutoExposure::adapting`]).
    pub adaptation: f32,
}

impl AutoExposure {
    /// Converges in one frame, no compensation.
    pub const CONVERGE_NOW: AutoExposure = AutoExposure {
        compensation_ev: 0.0,
        adaptation: 1.0,
    };

    /// The time constant the viewer (natively and in the page) adapts with: 63% of a change
    /// in half a second, as eyes and cameras adapt over about that; faster looks like
    /// flicker when lights move (`the_viewers_exposure_covers_63_percent_of_a_change_in_half_a_second`
    /// holds it).
    pub const VIEWER_TIME_CONSTANT_S: f32 = 0.5;

    /// Exponential adaptation with time constant `time_constant_s` for a frame that took
    /// `frame_time_s`: after `time_constant_s` the exposure has covered 63% of a change.
    pub fn adapting(compensation_ev: f32, frame_time_s: f32, time_constant_s: f32) -> Self {
        let adaptation = if time_constant_s > 0.0 {
            1.0 - (-frame_time_s.max(0.0) / time_constant_s).exp()
        } else {
            1.0
        };
        Self {
            compensation_ev,
            adaptation: adaptation.clamp(0.0, 1.0),
        }
    }
}

/// Log2 luminance of the darkest lit histogram bin's lower edge (about 1e-6), and the
/// stops the 255 lit bins span (to about 1e6, beyond the largest half float, 65504):
/// 0.16 stops (12%) a bin.
const HISTOGRAM_MIN_LOG2: f32 = -20.0;
const HISTOGRAM_RANGE_LOG2: f32 = 40.0;
const HISTOGRAM_BINS: u64 = 256;

/// The side of the histogram pass's square workgroups: one thread a bin clears and adds
/// its workgroup's counts (`#EXPOSURE_TILE` in `exposure.wgsl`).
const EXPOSURE_TILE: u32 = 16;
const _: () = assert!((EXPOSURE_TILE * EXPOSURE_TILE) as u64 == HISTOGRAM_BINS);

pub(crate) fn exposure_tile_def() -> (String, crate::ShaderDef) {
    (
        "EXPOSURE_TILE".into(),
        crate::ShaderDef::UInt(EXPOSURE_TILE),
    )
}

/// The bin count as `exposure.wgsl` reads it (`#HISTOGRAM_BINS`).
pub(crate) fn histogram_bins_def() -> (String, crate::ShaderDef) {
    (
        "HISTOGRAM_BINS".into(),
        crate::ShaderDef::UInt(HISTOGRAM_BINS as u32),
    )
}

/// The width of one histogram bin in stops: how far an automatic exposure may be from
/// the exact median of the frame (half a bin either way, plus the median's own bin).
pub const AUTO_EXPOSURE_BIN_STOPS: f32 = HISTOGRAM_RANGE_LOG2 / (HISTOGRAM_BINS as f32 - 1.0);

/// Mirrors `ExposureParams` in `shaders/gpu/exposure.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ExposureParamsGpu {
    min_log2: f32,
    range_log2: f32,
    adaptation: f32,
    compensation_ev: f32,
}

/// Mirrors `ExposureState` in `shaders/gpu/exposure_state.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ExposureStateGpu {
    /// The exposure the last tonemap pass applied.
    pub value: f32,
    /// The median luminance of the lit pixels of the last automatically exposed frame.
    pub median_luminance: f32,
    /// Non-zero once an automatic exposure was resolved.
    pub valid: u32,
    _pad: u32,
}

/// How HDR radiance is mapped to the display.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum Tonemap {
    /// Clamp to [0, 1]: what the HDR target holds, for comparisons.
    None,
    /// x / (1 + x).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve. Default.
    #[default]
    AcesFit,
}

crate::named_choice!(Tonemap, "tonemap curve");

impl Tonemap {
    pub const ALL: [Tonemap; 3] = [Tonemap::None, Tonemap::Reinhard, Tonemap::AcesFit];

    /// The name the CLI, the lab and the viewer's script use (`none`, `reinhard`, `aces`).
    pub fn name(&self) -> &'static str {
        match self {
            Tonemap::None => "none",
            Tonemap::Reinhard => "reinhard",
            Tonemap::AcesFit => "aces",
        }
    }

    fn shader_curve(&self) -> u32 {
        match self {
            Tonemap::None => 0,
            Tonemap::Reinhard => 1,
            Tonemap::AcesFit => 2,
        }
    }
}

/// Mirrors `TonemapParams` in `shaders/gpu/tonemap.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TonemapUniform {
    curve: u32,
    _pad: [u32; 3],
}

/// The HDR target, read with `textureLoad` (binding 0 of both post programs).
fn hdr_entry() -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// `tonemap.wgsl`'s group: HDR in, curve, exposure state, the output's storage view.
fn tonemap_layout() -> [wgpu::BindGroupLayoutEntry; 4] {
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        hdr_entry(),
        crate::binding::uniform_entry(1, compute),
        crate::binding::storage_entry(2, compute, true),
        wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: compute,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: OUTPUT_STORAGE_FORMAT,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        },
    ]
}

/// `exposure.wgsl`'s group: HDR in, the histogram, the exposure state, its parameters.
fn exposure_layout() -> [wgpu::BindGroupLayoutEntry; 4] {
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        hdr_entry(),
        crate::binding::storage_entry(1, compute, false),
        crate::binding::storage_entry(2, compute, false),
        crate::binding::uniform_entry(3, compute),
    ]
}

/// Exposure (fixed or automatic) and tonemapping.
#[derive(Debug)]
pub struct TonemapPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    histogram_pipeline: wgpu::ComputePipeline,
    resolve_pipeline: wgpu::ComputePipeline,
    exposure_layout: wgpu::BindGroupLayout,
    exposure_params: wgpu::Buffer,
    histogram: wgpu::Buffer,
    /// The exposure the tonemap pass applies: written by the CPU for a fixed exposure,
    /// by `resolve_exposure` for an automatic one (and kept between frames to adapt).
    state: wgpu::Buffer,
    tonemap_group: crate::binding::CachedBindGroup,
    exposure_group: crate::binding::CachedBindGroup,
}

/// One frame's post passes, prepared: an automatic exposure's histogram and resolve (with
/// its group), then the tonemap into the output.
#[derive(Debug)]
pub struct PreparedTonemap<'a> {
    pass: &'a TonemapPass,
    tonemap_group: wgpu::BindGroup,
    exposure_group: Option<wgpu::BindGroup>,
    size: (u32, u32),
}

impl TonemapPass {
    pub fn new(context: &GpuContext, library: &ShaderLibrary) -> GpuResult<Self> {
        let device = &context.device;
        let module =
            library.create_module(context, &tonemap_program(), MaterialVariant::default())?;
        let ComputePasses {
            layout,
            pipelines: [pipeline],
        } = ComputePasses::new(
            context,
            &module,
            "tonemap",
            &[],
            &tonemap_layout(),
            ["cs_tonemap"],
        )?;
        let uniform = crate::binding::uniform_buffer(
            device,
            "tonemap params",
            std::mem::size_of::<TonemapUniform>(),
        );
        let exposure_module = library.create_module(
            context,
            &auto_exposure_program(),
            MaterialVariant::default(),
        )?;
        let ComputePasses {
            layout: exposure_layout,
            pipelines: [histogram_pipeline, resolve_pipeline],
        } = ComputePasses::new(
            context,
            &exposure_module,
            "auto exposure",
            &[],
            &exposure_layout(),
            ["build_histogram", "resolve_exposure"],
        )?;
        let exposure_params = crate::binding::uniform_buffer(
            device,
            "auto exposure params",
            std::mem::size_of::<ExposureParamsGpu>(),
        );
        let storage = |label: &str, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        // Zeroed at creation: an empty histogram and no valid exposure yet.
        let histogram = storage("luminance histogram", HISTOGRAM_BINS * 4);
        let state = storage(
            "exposure state",
            std::mem::size_of::<ExposureStateGpu>() as u64,
        );
        Ok(Self {
            pipeline,
            layout,
            uniform,
            histogram_pipeline,
            resolve_pipeline,
            exposure_layout,
            exposure_params,
            histogram,
            state,
            tonemap_group: Default::default(),
            exposure_group: Default::default(),
        })
    }

    /// The exposure state as the GPU has it after the last submitted frame (waits for the
    /// GPU: for tests and reports, not for every frame).
    pub fn read_state(&self, context: &GpuContext) -> GpuResult<ExposureStateGpu> {
        let values: Vec<ExposureStateGpu> = crate::targets::read_buffer(context, &self.state)?;
        Ok(values[0])
    }

    /// Prepares the post passes of a frame with `exposure` (a fixed one is written to the
    /// state now; an automatic one is resolved on the GPU) and `curve`.
    pub fn prepare(
        &mut self,
        context: &GpuContext,
        targets: &RenderTargets,
        exposure: Exposure,
        curve: Tonemap,
    ) -> PreparedTonemap<'_> {
        let exposure_group = match exposure {
            Exposure::Manual(value) => {
                // `valid` 0: switching to automatic exposure converges at once.
                let state = ExposureStateGpu {
                    value,
                    median_luminance: 0.0,
                    valid: 0,
                    _pad: 0,
                };
                context
                    .queue
                    .write_buffer(&self.state, 0, bytemuck::bytes_of(&state));
                None
            }
            Exposure::Auto(auto) => {
                let params = ExposureParamsGpu {
                    min_log2: HISTOGRAM_MIN_LOG2,
                    range_log2: HISTOGRAM_RANGE_LOG2,
                    adaptation: auto.adaptation.clamp(0.0, 1.0),
                    compensation_ev: auto.compensation_ev,
                };
                context
                    .queue
                    .write_buffer(&self.exposure_params, 0, bytemuck::bytes_of(&params));
                Some(self.exposure_group.get(
                    context,
                    "auto exposure",
                    &self.exposure_layout,
                    [
                        (0, wgpu::BindingResource::TextureView(&targets.hdr.view)),
                        (1, self.histogram.as_entire_binding()),
                        (2, self.state.as_entire_binding()),
                        (3, self.exposure_params.as_entire_binding()),
                    ],
                ))
            }
        };
        let uniform = TonemapUniform {
            curve: curve.shader_curve(),
            _pad: [0; 3],
        };
        context
            .queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let tonemap_group = self.tonemap_group.get(
            context,
            "tonemap",
            &self.layout,
            [
                (0, wgpu::BindingResource::TextureView(&targets.hdr.view)),
                (1, self.uniform.as_entire_binding()),
                (2, self.state.as_entire_binding()),
                (
                    3,
                    wgpu::BindingResource::TextureView(&targets.output_storage),
                ),
            ],
        );
        PreparedTonemap {
            pass: self,
            tonemap_group,
            exposure_group,
            size: targets.size,
        }
    }
}

impl<'a> PreparedTonemap<'a> {
    /// The exposure this frame's tonemap applies (a fixed one already written), which the
    /// passes before it read to work in the shown image's brightness.
    pub fn exposure_state(&self) -> &'a wgpu::Buffer {
        &self.pass.state
    }

    /// Records HDR -> output (an automatic exposure first records its own compute pass,
    /// timed as "auto exposure").
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        let (width, height) = self.size;
        if let Some(exposure_group) = &self.exposure_group {
            let mut pass = timed_compute_pass(encoder, Some(&mut *timer), AUTO_EXPOSURE_PASS);
            pass.set_bind_group(0, exposure_group, &[]);
            pass.set_pipeline(&self.pass.histogram_pipeline);
            pass.dispatch_workgroups(
                width.div_ceil(EXPOSURE_TILE),
                height.div_ceil(EXPOSURE_TILE),
                1,
            );
            pass.set_pipeline(&self.pass.resolve_pipeline);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let mut pass = timed_compute_pass(encoder, Some(timer), TONEMAP_PASS);
        pass.set_pipeline(&self.pass.pipeline);
        pass.set_bind_group(0, &self.tonemap_group, &[]);
        pass.dispatch_workgroups(
            width.div_ceil(crate::SCREEN_TILE),
            height.div_ceil(crate::SCREEN_TILE),
            1,
        );
    }
}

#[cfg(test)]
mod layout_tests {
    use super::{
        ExposureParamsGpu, ExposureStateGpu, TonemapUniform, auto_exposure_program, tonemap_program,
    };
    use crate::assert_wgsl_layout;

    #[test]
    fn exposure_and_tonemap_uniforms_match_wgsl() {
        assert_wgsl_layout!(
            auto_exposure_program(),
            "gpu/exposure.wgsl",
            ExposureParams
                == ExposureParamsGpu {
                    min_log2: min_log2,
                    range_log2: range_log2,
                    adaptation: adaptation,
                    compensation_ev: compensation_ev,
                }
        );
        for program in [auto_exposure_program(), tonemap_program()] {
            assert_wgsl_layout!(
                program,
                "gpu/exposure_state.wgsl",
                ExposureState
                    == ExposureStateGpu {
                        value: value,
                        median_luminance: median_luminance,
                        valid: valid,
                        _pad: _pad,
                    }
            );
        }
        assert_wgsl_layout!(
            tonemap_program(),
            "gpu/tonemap.wgsl",
            TonemapParams
                == TonemapUniform {
                    curve: curve,
                    _pad0: _pad,
                    _pad1: _pad + 4,
                    _pad2: _pad + 8,
                }
        );
    }
}

#[cfg(test)]
mod name_tests {
    use super::Tonemap;

    #[test]
    fn tonemap_names_round_trip() {
        for curve in Tonemap::ALL {
            assert_eq!(curve.to_string().parse::<Tonemap>(), Ok(curve));
        }
        assert_eq!("aces".parse::<Tonemap>(), Ok(Tonemap::AcesFit));
        let error = "filmic".parse::<Tonemap>().unwrap_err();
        assert!(error.contains("none, reinhard, aces"), "{error}");
    }
}
