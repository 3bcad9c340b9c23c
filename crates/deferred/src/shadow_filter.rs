//! The spatial filter of the shadow rays' visible share (`Shadows::RaysSpatial`): the
//! compute lighting paths write the unshadowed radiance, the rays' share and the normal
//! (and only the emission to the HDR target); two fullscreen passes filter the share along
//! rows, then along columns, adding the unshadowed radiance times the filtered share to
//! the HDR target (`shaders/deferred/shadow_filter.wgsl`).

use manylights_gpu::{
    GpuContext, GpuResult, HDR_FORMAT, PassName, Program, RenderTargets, ShaderLibrary, Target,
    ViewBinding, wgpu,
};
use manylights_pipeline::FrameRecorder;

use crate::SHADERS;

/// The filter's passes' timed names.
pub const SHADOW_FILTER_ROWS_PASS: PassName = PassName::new("shadow filter (rows)");
pub const SHADOW_FILTER_COLUMNS_PASS: PassName = PassName::new("shadow filter (columns)");

/// The unshadowed radiance, the shares and the normals: half floats (the radiance as the
/// HDR target holds it; shares within [0, 1] to 2^-11; normals to 2^-11 a component).
const FILTER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The filter's program: `fs_rows` and `fs_columns`.
pub fn filter_program() -> Program {
    Program::new("shadow_filter", &SHADERS, "deferred/shadow_filter.wgsl")
}

/// The filter's layouts and pipelines, and its targets at the frame's size.
#[derive(Debug)]
pub(crate) struct ShadowFilter {
    /// Group 2 of a compute lighting pass with the filter: the HDR target (emission), the
    /// unshadowed radiance, the rays' share and the normal, as storage textures.
    pub(crate) output_layout: wgpu::BindGroupLayout,
    /// The filter passes' group 1: the unshadowed radiance, a share, the normals, depth.
    read_layout: wgpu::BindGroupLayout,
    rows: wgpu::RenderPipeline,
    columns: wgpu::RenderPipeline,
    targets: Option<FilterTargets>,
}

/// The filter's textures for one frame size, and the groups that bind them.
#[derive(Debug)]
pub(crate) struct FilterTargets {
    size: (u32, u32),
    /// The frame's targets these groups bind (rebuilt when the renderer replaces them).
    hdr: wgpu::Texture,
    depth: wgpu::Texture,
    _unshadowed: Target,
    _share: Target,
    _normal: Target,
    /// The share filtered along rows: the columns pass's input.
    rows: Target,
    pub(crate) output_group: wgpu::BindGroup,
    rows_group: wgpu::BindGroup,
    columns_group: wgpu::BindGroup,
}

impl ShadowFilter {
    pub(crate) fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view: &ViewBinding,
    ) -> GpuResult<Self> {
        let device = &context.device;
        let storage = |binding, format| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        };
        let output_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred lighting output with the shadow filter's inputs"),
            entries: &[
                storage(0, HDR_FORMAT),
                storage(1, FILTER_FORMAT),
                storage(2, FILTER_FORMAT),
                storage(3, FILTER_FORMAT),
            ],
        });
        let texture = |binding, sample_type| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let read_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow filter read"),
            entries: &[
                texture(0, float),
                texture(1, float),
                texture(2, float),
                texture(3, wgpu::TextureSampleType::Depth),
            ],
        });
        let module = library.create_module(context, &filter_program(), Default::default())?;
        let (rows, columns) = context.scoped("creating the shadow filter", || {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("shadow filter"),
                bind_group_layouts: &[Some(&view.layout), Some(&read_layout)],
                immediate_size: 0,
            });
            let pipeline = |label: &str, entry: &str, target: wgpu::ColorTargetState| {
                context.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_fullscreen"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: Default::default(),
                    depth_stencil: None,
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some(entry),
                        compilation_options: Default::default(),
                        targets: &[Some(target)],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
            // The columns pass adds its light to the emission the lighting wrote, and
            // leaves the target's alpha as it is.
            let add = wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::Zero,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
            };
            (
                pipeline("shadow filter (rows)", "fs_rows", FILTER_FORMAT.into()),
                pipeline(
                    "shadow filter (columns)",
                    "fs_columns",
                    wgpu::ColorTargetState {
                        format: HDR_FORMAT,
                        blend: Some(add),
                        write_mask: wgpu::ColorWrites::ALL,
                    },
                ),
            )
        })?;
        Ok(Self {
            output_layout,
            read_layout,
            rows,
            columns,
            targets: None,
        })
    }

    /// The filter's targets for `targets` (made again when their size or textures change).
    pub(crate) fn prepare(
        &mut self,
        context: &GpuContext,
        targets: &RenderTargets,
    ) -> GpuResult<&FilterTargets> {
        let current = self.targets.as_ref().is_some_and(|t| {
            t.size == targets.size
                && t.hdr == targets.hdr.texture
                && t.depth == targets.depth.texture
        });
        if !current {
            self.targets = Some(self.make_targets(context, targets)?);
        }
        self.targets.as_ref().ok_or_else(|| {
            manylights_gpu::GpuError::Unsupported("shadow filter targets missing".into())
        })
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
        let rows = make(
            "shadow filter: share along rows",
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        )?;
        let depth_view = targets
            .depth
            .texture
            .create_view(&wgpu::TextureViewDescriptor {
                aspect: wgpu::TextureAspect::DepthOnly,
                ..Default::default()
            });
        fn view(target: &Target) -> wgpu::BindingResource<'_> {
            wgpu::BindingResource::TextureView(&target.view)
        }
        let (output_group, rows_group, columns_group) =
            context.scoped("binding the shadow filter", || {
                let bind = |label, layout, resources: [wgpu::BindingResource; 4]| {
                    manylights_gpu::binding::bind_group(
                        context,
                        label,
                        layout,
                        resources
                            .into_iter()
                            .enumerate()
                            .map(|(i, r)| (i as u32, r)),
                    )
                };
                (
                    bind(
                        "deferred lighting output with the shadow filter's inputs",
                        &self.output_layout,
                        [
                            view(&targets.hdr),
                            view(&unshadowed),
                            view(&share),
                            view(&normal),
                        ],
                    ),
                    bind(
                        "shadow filter (rows)",
                        &self.read_layout,
                        [
                            view(&unshadowed),
                            view(&share),
                            view(&normal),
                            wgpu::BindingResource::TextureView(&depth_view),
                        ],
                    ),
                    bind(
                        "shadow filter (columns)",
                        &self.read_layout,
                        [
                            view(&unshadowed),
                            view(&rows),
                            view(&normal),
                            wgpu::BindingResource::TextureView(&depth_view),
                        ],
                    ),
                )
            })?;
        Ok(FilterTargets {
            size,
            hdr: targets.hdr.texture.clone(),
            depth: targets.depth.texture.clone(),
            _unshadowed: unshadowed,
            _share: share,
            _normal: normal,
            rows,
            output_group,
            rows_group,
            columns_group,
        })
    }

    /// The two passes, after the lighting pass wrote their inputs.
    pub(crate) fn record(&self, frame: &mut FrameRecorder, targets: &FilterTargets) {
        let passes = [
            (
                &self.rows,
                &targets.rows_group,
                &targets.rows.view,
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                SHADOW_FILTER_ROWS_PASS,
            ),
            (
                &self.columns,
                &targets.columns_group,
                &frame.targets.hdr.view,
                wgpu::LoadOp::Load,
                SHADOW_FILTER_COLUMNS_PASS,
            ),
        ];
        for (pipeline, group, target, load, name) in passes {
            let mut pass = frame
                .encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(name.as_str()),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: frame.timer.render_pass(name),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &frame.view.bind_group, &[]);
            pass.set_bind_group(1, group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}
