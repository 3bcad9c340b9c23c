//! The spatial filter of the shadow rays' visible share (`Shadows::RaysSpatial`): the
//! compute lighting paths write the unshadowed radiance, the rays' share and the normal
//! (each with a channel of the emission) instead of the HDR target; two compute passes
//! filter the share along rows, then along columns, and write the HDR target: the emission
//! plus the unshadowed radiance times the filtered share
//! (`shaders/deferred/shadow_filter.wgsl`). With temporal accumulation
//! (`Shadows::RaysTemporal`) the columns pass also blends the share with its history, kept
//! in two pairs of textures that swap roles each frame.

use manylights_gpu::{
    GpuContext, GpuResult, HDR_FORMAT, PassName, Program, RenderTargets, SCREEN_TILE,
    ShaderLibrary, Target, ViewBinding, timed_compute_pass, wgpu,
};
use manylights_pipeline::FrameRecorder;

use manylights_gpu::binding::texture_2d_entry;

use crate::SHADERS;
use crate::visibility::storage_texture_entry;

/// The filter's passes' timed names.
pub const SHADOW_FILTER_ROWS_PASS: PassName = PassName::new("shadow filter (rows)");
pub const SHADOW_FILTER_COLUMNS_PASS: PassName = PassName::new("shadow filter (columns)");
pub const SHADOW_FILTER_TEMPORAL_PASS: PassName =
    PassName::new("shadow filter (columns and history)");

/// The unshadowed radiance, the shares and the normals: half floats (the radiance as the
/// HDR target holds it; shares within [0, 1] to 2^-11; normals to 2^-11 a component).
const FILTER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The history's share and frame count: f32, as a sixteenth of a step below half a
/// half-float ulp would be lost and the history stop short of the share.
const HISTORY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The history's surface: its distance from its camera and its unshadowed luminance.
const HISTORY_SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;

/// The filter's program: `cs_rows` and `cs_columns`.
pub fn filter_program() -> Program {
    Program::new("shadow_filter", &SHADERS, "deferred/shadow_filter.wgsl")
}

/// The filter's layouts and pipelines, and its targets at the frame's size.
#[derive(Debug)]
pub(crate) struct ShadowFilter {
    /// Group 2 of a compute lighting pass with the filter: the unshadowed radiance, the
    /// rays' share and the normal, as storage textures (bindings 1 to 3).
    pub(crate) output_layout: wgpu::BindGroupLayout,
    /// The filter passes' group 1: the unshadowed radiance, a share, the normals, depth,
    /// and the output.
    read_layout: wgpu::BindGroupLayout,
    /// The temporal columns pass's group 1: the read layout's bindings, last frame's
    /// history (5, 6) and this frame's (7, 8).
    temporal_layout: wgpu::BindGroupLayout,
    rows: wgpu::ComputePipeline,
    columns: wgpu::ComputePipeline,
    columns_temporal: wgpu::ComputePipeline,
    targets: Option<FilterTargets>,
}

/// The filter's textures for one frame size, and the groups that bind them.
#[derive(Debug)]
pub(crate) struct FilterTargets {
    size: (u32, u32),
    /// The frame's targets these groups bind (rebuilt when the renderer replaces them).
    hdr: wgpu::Texture,
    depth: wgpu::Texture,
    unshadowed: Target,
    _share: Target,
    normal: Target,
    /// The share filtered along rows: the columns pass's input.
    rows_share: Target,
    /// The depth buffer's depth aspect, which the filter's passes read.
    depth_view: wgpu::TextureView,
    pub(crate) output_group: wgpu::BindGroup,
    rows_group: wgpu::BindGroup,
    columns_group: wgpu::BindGroup,
    /// The history, while frames accumulate (dropped by a frame that does not, so the
    /// next starts afresh).
    history: Option<FilterHistory>,
}

/// Two frames of history: the frame reading pair `read` writes the other.
#[derive(Debug)]
struct FilterHistory {
    _textures: [(Target, Target); 2],
    /// `groups[i]` reads pair i and writes the other.
    groups: [wgpu::BindGroup; 2],
    read: usize,
}

/// `target`'s view, bound.
fn view(target: &Target) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::TextureView(&target.view)
}

/// The filter's bind group layouts.
struct FilterLayouts {
    output: wgpu::BindGroupLayout,
    read: wgpu::BindGroupLayout,
    temporal: wgpu::BindGroupLayout,
}

impl FilterLayouts {
    fn new(device: &wgpu::Device) -> Self {
        let storage = storage_texture_entry;
        let texture = |binding, sample_type| {
            texture_2d_entry(binding, wgpu::ShaderStages::COMPUTE, sample_type)
        };
        let float = wgpu::TextureSampleType::Float { filterable: false };
        // The lighting pass's inputs to the filter, the filter passes' own, and the
        // history's after them.
        let read_entries = [
            texture(0, float),
            texture(1, float),
            texture(2, float),
            texture(3, wgpu::TextureSampleType::Depth),
            // The rows' share and the HDR target are both half floats.
            storage(4, HDR_FORMAT),
        ];
        let history_entries = [
            texture(5, float),
            texture(6, float),
            storage(7, HISTORY_FORMAT),
            storage(8, HISTORY_SURFACE_FORMAT),
        ];
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        Self {
            output: layout(
                "deferred lighting output with the shadow filter's inputs",
                &[
                    storage(1, FILTER_FORMAT),
                    storage(2, FILTER_FORMAT),
                    storage(3, FILTER_FORMAT),
                ],
            ),
            read: layout("shadow filter read", &read_entries),
            temporal: layout(
                "shadow filter read with history",
                &[read_entries.as_slice(), history_entries.as_slice()].concat(),
            ),
        }
    }
}

impl ShadowFilter {
    pub(crate) fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        let device = &context.device;
        let FilterLayouts {
            output: output_layout,
            read: read_layout,
            temporal: temporal_layout,
        } = FilterLayouts::new(device);
        let module = library.create_module(context, &filter_program(), Default::default())?;
        let (rows, columns, columns_temporal) =
            context.scoped("creating the shadow filter", || {
                let layout = |group: &wgpu::BindGroupLayout| {
                    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some("shadow filter"),
                        bind_group_layouts: &[Some(&view.layout), Some(group)],
                        immediate_size: 0,
                    })
                };
                let (plain, with_history) = (layout(&read_layout), layout(&temporal_layout));
                let pipeline = |label: &str, entry: &str, layout: &wgpu::PipelineLayout| {
                    context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(label),
                        layout: Some(layout),
                        module: &module,
                        entry_point: Some(entry),
                        compilation_options: Default::default(),
                        cache: None,
                    })
                };
                (
                    pipeline("shadow filter (rows)", "cs_rows", &plain),
                    pipeline("shadow filter (columns)", "cs_columns", &plain),
                    pipeline(
                        "shadow filter (columns and history)",
                        "cs_columns_temporal",
                        &with_history,
                    ),
                )
            })?;
        Ok(Self {
            output_layout,
            read_layout,
            temporal_layout,
            rows,
            columns,
            columns_temporal,
            targets: None,
        })
    }

    /// The filter's targets for `targets` (made again when their size or textures change,
    /// which starts the history afresh), with history if the frame is `temporal`: the
    /// pair last frame wrote becomes the one this frame reads.
    pub(crate) fn prepare(
        &mut self,
        context: &GpuContext,
        targets: &RenderTargets,
        temporal: bool,
    ) -> GpuResult<()> {
        let current = self.targets.as_ref().is_some_and(|t| {
            t.size == targets.size
                && t.hdr == targets.hdr.texture
                && t.depth == targets.depth.texture
        });
        if !current {
            self.targets = Some(self.make_targets(context, targets)?);
        }
        let Some(filter_targets) = self.targets.as_mut() else {
            return Err(manylights_gpu::GpuError::Unsupported(
                "shadow filter targets missing".into(),
            ));
        };
        match (&mut filter_targets.history, temporal) {
            (Some(history), true) => history.read = 1 - history.read,
            (None, true) => {
                let history =
                    Self::make_history(context, &self.temporal_layout, targets, filter_targets)?;
                filter_targets.history = Some(history);
            }
            (_, false) => filter_targets.history = None,
        }
        Ok(())
    }

    /// Drops the history: a frame without temporal accumulation ran, and the next that
    /// accumulates starts afresh.
    pub(crate) fn forget_history(&mut self) {
        if let Some(targets) = &mut self.targets {
            targets.history = None;
        }
    }

    /// The targets `prepare` made last.
    pub(crate) fn prepared(&self) -> Option<&FilterTargets> {
        self.targets.as_ref()
    }

    fn make_targets(
        &self,
        context: &GpuContext,
        targets: &RenderTargets,
    ) -> GpuResult<FilterTargets> {
        let size = targets.size;
        let written = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING;
        let make = |label: &str, usage| Target::new(context, label, size, FILTER_FORMAT, usage);
        let unshadowed = make("shadow filter: unshadowed radiance", written)?;
        let share = make("shadow filter: visible share", written)?;
        let normal = make("shadow filter: normal", written)?;
        let rows = make("shadow filter: share along rows", written)?;
        let depth_view = targets
            .depth
            .texture
            .create_view(&wgpu::TextureViewDescriptor {
                aspect: wgpu::TextureAspect::DepthOnly,
                ..Default::default()
            });
        let (output_group, rows_group, columns_group) =
            context.scoped("binding the shadow filter", || {
                // Consecutive bindings from `first`.
                let bind = |label, layout, first: u32, resources: Vec<wgpu::BindingResource>| {
                    manylights_gpu::binding::bind_group(
                        context,
                        label,
                        layout,
                        (first..).zip(resources),
                    )
                };
                (
                    bind(
                        "deferred lighting output with the shadow filter's inputs",
                        &self.output_layout,
                        1,
                        vec![view(&unshadowed), view(&share), view(&normal)],
                    ),
                    bind(
                        "shadow filter (rows)",
                        &self.read_layout,
                        0,
                        vec![
                            view(&unshadowed),
                            view(&share),
                            view(&normal),
                            wgpu::BindingResource::TextureView(&depth_view),
                            view(&rows),
                        ],
                    ),
                    bind(
                        "shadow filter (columns)",
                        &self.read_layout,
                        0,
                        vec![
                            view(&unshadowed),
                            view(&rows),
                            view(&normal),
                            wgpu::BindingResource::TextureView(&depth_view),
                            view(&targets.hdr),
                        ],
                    ),
                )
            })?;
        Ok(FilterTargets {
            size,
            hdr: targets.hdr.texture.clone(),
            depth: targets.depth.texture.clone(),
            unshadowed,
            _share: share,
            normal,
            rows_share: rows,
            depth_view,
            output_group,
            rows_group,
            columns_group,
            history: None,
        })
    }

    /// Two pairs of history textures (zero: no frames yet), and the columns pass's groups
    /// that read one pair and write the other.
    fn make_history(
        context: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        targets: &RenderTargets,
        filter: &FilterTargets,
    ) -> GpuResult<FilterHistory> {
        let written = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING;
        let pair = |i: usize| -> GpuResult<(Target, Target)> {
            Ok((
                Target::new(
                    context,
                    &format!("shadow history {i}: share and frames"),
                    filter.size,
                    HISTORY_FORMAT,
                    written,
                )?,
                Target::new(
                    context,
                    &format!("shadow history {i}: surface"),
                    filter.size,
                    HISTORY_SURFACE_FORMAT,
                    written,
                )?,
            ))
        };
        let textures = [pair(0)?, pair(1)?];
        let group = |read: usize| {
            let (previous, next) = (&textures[read], &textures[1 - read]);
            context.scoped("binding the shadow history", || {
                manylights_gpu::binding::bind_group(
                    context,
                    "shadow filter (columns and history)",
                    layout,
                    (0..).zip([
                        view(&filter.unshadowed),
                        view(&filter.rows_share),
                        view(&filter.normal),
                        wgpu::BindingResource::TextureView(&filter.depth_view),
                        view(&targets.hdr),
                        view(&previous.0),
                        view(&previous.1),
                        view(&next.0),
                        view(&next.1),
                    ]),
                )
            })
        };
        let groups = [group(0)?, group(1)?];
        Ok(FilterHistory {
            _textures: textures,
            groups,
            read: 0,
        })
    }

    /// The two passes, after the lighting pass wrote their inputs.
    pub(crate) fn record(&self, frame: &mut FrameRecorder, targets: &FilterTargets) {
        let columns = match &targets.history {
            // Present exactly when the frame prepared last accumulates over frames.
            Some(history) => (
                &self.columns_temporal,
                &history.groups[history.read],
                SHADOW_FILTER_TEMPORAL_PASS,
            ),
            _ => (
                &self.columns,
                &targets.columns_group,
                SHADOW_FILTER_COLUMNS_PASS,
            ),
        };
        let passes = [
            (&self.rows, &targets.rows_group, SHADOW_FILTER_ROWS_PASS),
            columns,
        ];
        let (width, height) = targets.size;
        for (pipeline, group, name) in passes {
            let mut pass = timed_compute_pass(frame.encoder, Some(&mut *frame.timer), name);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &frame.view.bind_group, &[]);
            pass.set_bind_group(1, group, &[]);
            pass.dispatch_workgroups(width.div_ceil(SCREEN_TILE), height.div_ceil(SCREEN_TILE), 1);
        }
    }
}
