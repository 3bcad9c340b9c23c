//! The shadow rays' visible share after shading: its spatial filter
//! (`Shadows::RaysSpatial`), its history (`Shadows::RaysTemporal`), and the forward
//! pipelines' shadow pass (`shaders/visibility/shadow_filter.wgsl`, `shadow_trace.wgsl`).
//!
//! - Deferred's compute lighting paths write the unshadowed radiance, the rays' share and
//!   the normal (each with a channel of the emission) instead of the HDR target.
//! - Forward+ and naive, with one ray a pixel, write the unshadowed radiance, the normal and
//!   the ray's light as colour targets ([`FORWARD_TARGETS`]), and a compute pass
//!   (`cs_trace`) traces the ray from the position rebuilt from depth and writes the share:
//!   their rays run at compute speed, not in the fragment shader.
//! - Two compute passes filter the share along rows, then along columns, and write the HDR
//!   target: the emission plus the unshadowed radiance times the filtered share. With
//!   temporal accumulation the columns pass also blends the share with its history, kept
//!   in two pairs of textures that swap roles each frame. Unfiltered, one pass
//!   (`cs_compose`) writes the HDR target from the traced share.

use manylights_gpu::binding::{CachedBindGroup, storage_texture_entry, texture_2d_entry};
use manylights_gpu::{
    GpuContext, GpuResult, GpuTimer, HDR_FORMAT, PassName, Program, RenderTargets, SCREEN_TILE,
    ShaderLibrary, Target, ViewBinding, timed_compute_pass, wgpu,
};

use crate::{GpuSceneBvh, SHADERS, Shadows};

/// The filter's passes' timed names.
pub const SHADOW_FILTER_ROWS_PASS: PassName = PassName::new("shadow filter (rows)");
pub const SHADOW_FILTER_COLUMNS_PASS: PassName = PassName::new("shadow filter (columns)");
pub const SHADOW_FILTER_TEMPORAL_PASS: PassName =
    PassName::new("shadow filter (columns and history)");
/// The forward pipelines' shadow pass: one ray a pixel, traced in compute.
pub const SHADOW_TRACE_PASS: PassName = PassName::new("shadow rays");
/// The forward pipelines' unfiltered shadows: the HDR target from the traced share.
pub const SHADOW_COMPOSE_PASS: PassName = PassName::new("shadow compose");

/// The unshadowed radiance, the shares and the normals: half floats (the radiance as the
/// HDR target holds it; shares within [0, 1] to 2^-11; normals to 2^-11 a component).
pub const FILTER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The history's share and frame count: f32, as a sixteenth of a step below half a
/// half-float ulp would be lost and the history stop short of the share.
const HISTORY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The history's surface: its distance from its camera and its unshadowed luminance.
const HISTORY_SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;

/// The forward pipelines' ray: the kept light's position in scene coordinates (x
/// `NO_SHADOW_RAY` where no term was kept), the emission's green in w. f32: a light's
/// position to the precision the fragment shader has it.
const RAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The colour targets a forward pipeline's shading pass writes for the shadow pass, in
/// order: the unshadowed radiance (emission's red in w), the normal (emission's blue) and
/// the ray (emission's green). 32 bytes a sample: all WebGPU guarantees
/// (`maxColorAttachmentBytesPerSample`), hence one ray a pixel.
pub const FORWARD_TARGETS: [wgpu::TextureFormat; 3] = [FILTER_FORMAT, FILTER_FORMAT, RAY_FORMAT];

/// The filter's program: `cs_rows`, `cs_columns`, `cs_columns_temporal` and `cs_compose`.
pub fn filter_program() -> Program {
    Program::new("shadow_filter", &SHADERS, "visibility/shadow_filter.wgsl")
}

/// The forward pipelines' shadow pass: `cs_trace`.
pub fn trace_program() -> Program {
    Program::new("shadow_trace", &SHADERS, "visibility/shadow_trace.wgsl")
}

/// The filter's layouts and pipelines, and its targets at the frame's size.
#[derive(Debug)]
pub struct ShadowFilter {
    /// Group 2 of a compute lighting pass with the filter: the unshadowed radiance, the
    /// rays' share and the normal, as storage textures (bindings 1 to 3).
    pub output_layout: wgpu::BindGroupLayout,
    /// The filter passes' group 1: the unshadowed radiance, a share, the normals, depth,
    /// and the output.
    read_layout: wgpu::BindGroupLayout,
    /// The temporal columns pass's group 1: the read layout's bindings, last frame's
    /// history (5, 6) and this frame's (7, 8).
    temporal_layout: wgpu::BindGroupLayout,
    rows: wgpu::ComputePipeline,
    columns: wgpu::ComputePipeline,
    columns_temporal: wgpu::ComputePipeline,
    /// The unfiltered HDR target from the share (`cs_compose`, the read layout).
    compose: wgpu::ComputePipeline,
    /// The forward pipelines' shadow pass, made when one first asks.
    trace: Option<ShadowTrace>,
    targets: Option<FilterTargets>,
    /// Whether the frame prepared last filters its share (or composes it unfiltered).
    filtered: bool,
}

/// The forward pipelines' shadow pass: its group 3 (the normals, the rays, depth, the share
/// written; the scene's BVH from [`crate::FIRST_BINDING`]) and pipeline.
#[derive(Debug)]
struct ShadowTrace {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    group: CachedBindGroup,
    /// The group for the frame prepared last.
    prepared: Option<wgpu::BindGroup>,
}

/// The filter's textures for one frame size, and the groups that bind them.
#[derive(Debug)]
pub struct FilterTargets {
    size: (u32, u32),
    /// The frame's targets these groups bind (rebuilt when the renderer replaces them).
    hdr: wgpu::Texture,
    depth: wgpu::Texture,
    unshadowed: Target,
    share: Target,
    normal: Target,
    /// The forward pipelines' rays (made with the shadow pass).
    rays: Option<Target>,
    /// The share filtered along rows: the columns pass's input.
    rows_share: Target,
    /// The depth buffer's depth aspect, which the filter's passes read.
    depth_view: wgpu::TextureView,
    pub output_group: wgpu::BindGroup,
    rows_group: wgpu::BindGroup,
    columns_group: wgpu::BindGroup,
    /// `cs_compose`'s: the columns group reading the traced share.
    compose_group: wgpu::BindGroup,
    /// The history, while frames accumulate (dropped by a frame that does not, so the
    /// next starts afresh).
    history: Option<FilterHistory>,
}

impl FilterTargets {
    /// The filter's inputs, which a lighting pass writes through [`FilterTargets::output_group`]
    /// (or a caller copies in, `COPY_DST`), each [`FILTER_FORMAT`]: the unshadowed radiance
    /// (the emission's red in w), the visible share (its green in w) and the surface's unit
    /// normal (zero where no surface covers the pixel; the emission's blue in w).
    pub fn inputs(&self) -> [&wgpu::Texture; 3] {
        [
            &self.unshadowed.texture,
            &self.share.texture,
            &self.normal.texture,
        ]
    }
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
fn view_of(target: &Target) -> wgpu::BindingResource<'_> {
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
    pub fn new(
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
        let (rows, columns, columns_temporal, compose) =
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
                    pipeline("shadow compose", "cs_compose", &plain),
                )
            })?;
        Ok(Self {
            output_layout,
            read_layout,
            temporal_layout,
            rows,
            columns,
            columns_temporal,
            compose,
            trace: None,
            targets: None,
            filtered: true,
        })
    }

    /// The filter's targets for `targets` (made again when their size or textures change,
    /// which starts the history afresh), with history if the frame's shadows accumulate
    /// over frames: the pair last frame wrote becomes the one this frame reads, if last
    /// frame was this pipeline's ([`FrameShadows::follows_own_frame`]); otherwise the
    /// history starts afresh.
    pub fn prepare(
        &mut self,
        context: &GpuContext,
        targets: &RenderTargets,
        frame: FrameShadows,
    ) -> GpuResult<()> {
        let FrameShadows {
            shadows,
            follows_own_frame,
        } = frame;
        if !follows_own_frame {
            self.forget_history();
        }
        let temporal = shadows.temporally_accumulated();
        self.filtered = shadows.spatially_filtered();
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
    pub fn forget_history(&mut self) {
        if let Some(targets) = &mut self.targets {
            targets.history = None;
        }
    }

    /// The targets `prepare` made last.
    pub fn prepared(&self) -> Option<&FilterTargets> {
        self.targets.as_ref()
    }

    fn make_targets(
        &self,
        context: &GpuContext,
        targets: &RenderTargets,
    ) -> GpuResult<FilterTargets> {
        let size = targets.size;
        let written = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING;
        // The forward pipelines draw the unshadowed radiance and the normals; a caller
        // with inputs of its own may copy them in ([`FilterTargets::inputs`]).
        let drawn =
            written | wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST;
        let written_inputs = written | wgpu::TextureUsages::COPY_DST;
        let make = |label: &str, usage| Target::new(context, label, size, FILTER_FORMAT, usage);
        let unshadowed = make("shadow filter: unshadowed radiance", drawn)?;
        let share = make("shadow filter: visible share", written_inputs)?;
        let normal = make("shadow filter: normal", drawn)?;
        let rows = make("shadow filter: share along rows", written)?;
        let depth_view = manylights_gpu::targets::depth_only_view(&targets.depth.texture);
        let (output_group, [rows_group, columns_group, compose_group]) =
            context.scoped("binding the shadow filter", || {
                let output = manylights_gpu::binding::bind_group(
                    context,
                    "deferred lighting output with the shadow filter's inputs",
                    &self.output_layout,
                    (1..).zip([view_of(&unshadowed), view_of(&share), view_of(&normal)]),
                );
                // A filter pass reading `input` (a share) and writing `output`.
                let read = |label, input: &Target, output: &Target| {
                    manylights_gpu::binding::bind_group(
                        context,
                        label,
                        &self.read_layout,
                        (0..).zip([
                            view_of(&unshadowed),
                            view_of(input),
                            view_of(&normal),
                            wgpu::BindingResource::TextureView(&depth_view),
                            view_of(output),
                        ]),
                    )
                };
                (
                    output,
                    [
                        read("shadow filter (rows)", &share, &rows),
                        read("shadow filter (columns)", &rows, &targets.hdr),
                        read("shadow compose", &share, &targets.hdr),
                    ],
                )
            })?;
        Ok(FilterTargets {
            size,
            hdr: targets.hdr.texture.clone(),
            depth: targets.depth.texture.clone(),
            unshadowed,
            share,
            normal,
            rays: None,
            rows_share: rows,
            depth_view,
            output_group,
            rows_group,
            columns_group,
            compose_group,
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
                        view_of(&filter.unshadowed),
                        view_of(&filter.rows_share),
                        view_of(&filter.normal),
                        wgpu::BindingResource::TextureView(&filter.depth_view),
                        view_of(&targets.hdr),
                        view_of(&previous.0),
                        view_of(&previous.1),
                        view_of(&next.0),
                        view_of(&next.1),
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

    /// The filter's two passes (or, unfiltered, the compose pass), after the lighting pass
    /// or the shadow pass wrote their inputs.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        view: &ViewBinding,
        targets: &FilterTargets,
    ) {
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
        let filter = [
            (&self.rows, &targets.rows_group, SHADOW_FILTER_ROWS_PASS),
            columns,
        ];
        let compose = [(&self.compose, &targets.compose_group, SHADOW_COMPOSE_PASS)];
        let passes: &[_] = if self.filtered { &filter } else { &compose };
        for &(pipeline, group, name) in passes {
            let mut pass = timed_compute_pass(encoder, Some(&mut *timer), name);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &view.bind_group, &[]);
            pass.set_bind_group(1, group, &[]);
            let (width, height) = targets.size;
            pass.dispatch_workgroups(width.div_ceil(SCREEN_TILE), height.div_ceil(SCREEN_TILE), 1);
        }
    }
}

/// A frame's shadows as the filter keeps them: how they are traced, filtered and
/// accumulated, and whether the history the filter holds is the last frame's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameShadows {
    pub shadows: Shadows,
    /// The last frame was drawn by the same pipeline: its history carries over.
    pub follows_own_frame: bool,
}

/// What a forward pipeline's frame gives its shadow pass.
#[derive(Debug, Clone, Copy)]
pub struct ShadowPassInputs<'a> {
    pub context: &'a GpuContext,
    pub library: &'a ShaderLibrary,
    pub view: &'a ViewBinding,
    /// The targets the pipeline's shading pass draws (one sample a pixel).
    pub targets: &'a RenderTargets,
    pub shadows: FrameShadows,
    /// The scene's BVH the rays are traced through.
    pub bvh: &'a GpuSceneBvh,
}

/// The forward pipelines' shadow pass.
impl ShadowFilter {
    /// A forward pipeline's filter `slot` for a frame: made on first use and prepared
    /// ([`ShadowFilter::prepare_traced`]) when the frame `traced` its rays in the shadow
    /// pass; otherwise its history is dropped, so the next frame that traces starts afresh.
    /// The pass traces from one surface a pixel: multisampled targets are refused.
    pub fn prepare_slot(
        slot: &mut Option<ShadowFilter>,
        traced: bool,
        inputs: ShadowPassInputs,
    ) -> GpuResult<()> {
        if !traced {
            if let Some(filter) = slot {
                filter.forget_history();
            }
            return Ok(());
        }
        let samples = inputs.targets.samples();
        if samples > 1 {
            return Err(manylights_gpu::GpuError::Unsupported(format!(
                "the shadow pass traces from one surface a pixel, not with {samples}x MSAA"
            )));
        }
        let filter = match slot.take() {
            Some(filter) => filter,
            None => ShadowFilter::new(inputs.context, inputs.library, inputs.view)?,
        };
        slot.insert(filter).prepare_traced(inputs)
    }

    /// The targets, the history and the shadow pass's group for a forward pipeline's frame
    /// tracing its shadows (one ray a pixel; the history as [`ShadowFilter::prepare`])
    /// through its BVH; the pass is made on first use.
    pub fn prepare_traced(&mut self, inputs: ShadowPassInputs) -> GpuResult<()> {
        let ShadowPassInputs {
            context,
            library,
            view,
            targets,
            shadows,
            bvh,
        } = inputs;
        self.prepare(context, targets, shadows)?;
        if self.trace.is_none() {
            self.trace = Some(ShadowTrace::new(context, library, view)?);
        }
        let (Some(trace), Some(filter_targets)) = (self.trace.as_mut(), self.targets.as_mut())
        else {
            return Err(manylights_gpu::GpuError::Unsupported(
                "shadow pass targets missing".into(),
            ));
        };
        let rays = match filter_targets.rays.take() {
            Some(rays) => rays,
            None => Target::new(
                context,
                "shadow pass: rays",
                filter_targets.size,
                RAY_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            )?,
        };
        let rays = &*filter_targets.rays.insert(rays);
        let group = context.scoped("binding the shadow pass", || {
            trace.group.get(
                context,
                "shadow rays",
                &trace.layout,
                [
                    (0, view_of(&filter_targets.normal)),
                    (1, view_of(rays)),
                    (
                        2,
                        wgpu::BindingResource::TextureView(&filter_targets.depth_view),
                    ),
                    (3, view_of(&filter_targets.share)),
                ]
                .into_iter()
                .chain(bvh.bindings()),
            )
        })?;
        trace.prepared = Some(group);
        Ok(())
    }

    /// The colour attachments of a forward pipeline's shading pass ([`FORWARD_TARGETS`]),
    /// cleared: no surface, no ray. `None` before `prepare_traced`.
    pub fn forward_attachments(&self) -> Option<[Option<wgpu::RenderPassColorAttachment<'_>>; 3]> {
        let targets = self.targets.as_ref()?;
        let rays = targets.rays.as_ref()?;
        let cleared = manylights_gpu::binding::cleared_color;
        let none = wgpu::Color::TRANSPARENT;
        Some([
            cleared(&targets.unshadowed.view, none),
            cleared(&targets.normal.view, none),
            cleared(&rays.view, none),
        ])
    }

    /// The shadow pass, then the filter or the compose pass: after a forward pipeline's
    /// shading pass wrote [`FORWARD_TARGETS`].
    pub fn record_traced(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        view: &ViewBinding,
    ) {
        let (Some(trace), Some(targets)) = (&self.trace, &self.targets) else {
            return;
        };
        let Some(group) = &trace.prepared else {
            return;
        };
        {
            let mut pass = timed_compute_pass(encoder, Some(&mut *timer), SHADOW_TRACE_PASS);
            pass.set_pipeline(&trace.pipeline);
            pass.set_bind_group(0, &view.bind_group, &[]);
            pass.set_bind_group(3, group, &[]);
            let (width, height) = targets.size;
            pass.dispatch_workgroups(width.div_ceil(SCREEN_TILE), height.div_ceil(SCREEN_TILE), 1);
        }
        self.record(encoder, timer, view, targets);
    }
}

impl ShadowTrace {
    fn new(context: &GpuContext, library: &ShaderLibrary, view: &ViewBinding) -> GpuResult<Self> {
        let device = &context.device;
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let texture = |binding, sample_type| {
            texture_2d_entry(binding, wgpu::ShaderStages::COMPUTE, sample_type)
        };
        let mut entries = vec![
            texture(0, float),
            texture(1, float),
            texture(2, wgpu::TextureSampleType::Depth),
            storage_texture_entry(3, FILTER_FORMAT),
        ];
        entries.extend(GpuSceneBvh::layout_entries(wgpu::ShaderStages::COMPUTE));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow rays"),
            entries: &entries,
        });
        let module = library.create_module(context, &trace_program(), Default::default())?;
        let pipeline = context.scoped("creating the shadow pass", || {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("shadow rays"),
                bind_group_layouts: &[Some(&view.layout), None, None, Some(&layout)],
                immediate_size: 0,
            });
            context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("shadow rays"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("cs_trace"),
                compilation_options: Default::default(),
                cache: None,
            })
        })?;
        Ok(Self {
            layout,
            pipeline,
            group: CachedBindGroup::default(),
            prepared: None,
        })
    }
}
