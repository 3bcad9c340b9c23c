//! Constructors for the bind-group-layout entries, parameter buffers and pass attachments
//! that every pass of the renderer repeats.

use crate::GpuContext;

/// A uniform buffer binding.
pub fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Uniform)
}

/// A storage buffer binding.
pub fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(
        binding,
        visibility,
        wgpu::BufferBindingType::Storage { read_only },
    )
}

/// A filterable colour texture sampled in the shader (`texture_2d<f32>`).
pub fn sampled_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    texture_2d_entry(
        binding,
        visibility,
        wgpu::TextureSampleType::Float { filterable: true },
    )
}

/// A single-sampled 2D texture of `sample_type`.
pub fn texture_2d_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A storage texture entry (write-only) for compute.
pub fn storage_texture_entry(
    binding: u32,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// A filtering sampler.
pub fn sampler_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// A sampler filtering linearly between texels and mip levels, clamped at the edges.
pub fn linear_clamp_sampler(device: &wgpu::Device, label: &str) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(label),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    })
}

/// A depth texture read with `textureLoad` (`texture_depth_2d`).
pub fn depth_texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    texture_2d_entry(binding, visibility, wgpu::TextureSampleType::Depth)
}

fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A bind group layout of `entries`.
pub fn bind_group_layout(
    context: &GpuContext,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    context
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries,
        })
}

/// A bind group of `layout` from `(binding, resource)` pairs: the one way bind groups are
/// written here, so each names only its bindings and what fills them.
pub fn bind_group<'a>(
    context: &GpuContext,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: impl IntoIterator<Item = (u32, wgpu::BindingResource<'a>)>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .into_iter()
        .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
        .collect();
    context.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Buffers bound whole, at bindings 0, 1, 2, ... in order (for [`bind_group`]).
pub fn buffers_in_order<'a>(
    buffers: impl IntoIterator<Item = &'a wgpu::Buffer>,
) -> impl Iterator<Item = (u32, wgpu::BindingResource<'a>)> {
    (0..).zip(buffers.into_iter().map(wgpu::Buffer::as_entire_binding))
}

/// A uniform buffer of `size` bytes that the CPU rewrites each frame.
pub fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A colour attachment cleared to `clear` and stored.
pub fn cleared_color(
    view: &wgpu::TextureView,
    clear: wgpu::Color,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(clear),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// A depth attachment loaded or cleared as asked, and stored.
pub fn depth_attachment(
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<f32>,
) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// A render pipeline drawing the fullscreen triangle of `shaders/common/fullscreen.wgsl`
/// (vertex entry `vs_fullscreen`, no vertex buffers, no depth) into one target.
pub fn fullscreen_pipeline(
    context: &GpuContext,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fragment_entry: &str,
    target: impl Into<wgpu::ColorTargetState>,
    compilation_options: wgpu::PipelineCompilationOptions<'_>,
) -> wgpu::RenderPipeline {
    context.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: compilation_options.clone(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment_entry),
            compilation_options,
            targets: &[Some(target.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Compute passes of one program: a bind group layout of their own (after `shared`, e.g.
/// the view's) and one pipeline per entry point, created in one error scope. The one way
/// the renderer's compute passes are made (animation, assignment, statistics, far field,
/// exposure, tonemap).
#[derive(Debug)]
pub struct ComputePasses<const N: usize> {
    /// The passes' own group, bound after the shared ones.
    pub layout: wgpu::BindGroupLayout,
    /// One per entry point, in the order asked.
    pub pipelines: [wgpu::ComputePipeline; N],
}

impl<const N: usize> ComputePasses<N> {
    pub fn new(
        context: &GpuContext,
        module: &wgpu::ShaderModule,
        label: &str,
        shared: &[&wgpu::BindGroupLayout],
        entries: &[wgpu::BindGroupLayoutEntry],
        entry_points: [&str; N],
    ) -> crate::GpuResult<Self> {
        context.scoped(&format!("creating the {label} pipelines"), || {
            let layout =
                context
                    .device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some(&format!("{label} layout")),
                        entries,
                    });
            let layouts: Vec<&wgpu::BindGroupLayout> =
                shared.iter().copied().chain([&layout]).collect();
            let pipelines = compute_pipelines(context, label, &layouts, module, entry_points);
            Self { layout, pipelines }
        })
    }
}

/// One compute pipeline per entry point of `module`, sharing one layout made of
/// `bind_group_layouts` (the passes of one program: assignment, statistics, exposure).
pub fn compute_pipelines<const N: usize>(
    context: &GpuContext,
    label: &str,
    bind_group_layouts: &[&wgpu::BindGroupLayout],
    module: &wgpu::ShaderModule,
    entries: [&str; N],
) -> [wgpu::ComputePipeline; N] {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> =
        bind_group_layouts.iter().copied().map(Some).collect();
    let pipeline_layout = context
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
    entries.map(|entry| compute_pipeline(context, &pipeline_layout, module, entry))
}

/// The compute pipeline of `entry` in `module`, labelled with the entry point's name.
fn compute_pipeline(
    context: &GpuContext,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// One compute pipeline per entry point of a module whose entry points share one table of
/// bindings in their last group but each use only part of it (the cluster assignment's
/// twelve buffers). Each pipeline's layout holds only the bindings its entry point uses,
/// because WebGPU counts every storage buffer of a pipeline's layout against its 8 per
/// stage, used or not; each entry point then gets its own bind group from the shared table.
#[derive(Debug)]
pub struct EntryPointPipelines<const N: usize> {
    passes: [EntryPointPass; N],
}

#[derive(Debug)]
struct EntryPointPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    bindings: Vec<u32>,
}

impl<const N: usize> EntryPointPipelines<N> {
    /// `table` describes every binding of the group after `shared_layouts` (e.g. the
    /// view's); `used[i]` lists the bindings `entries[i]` uses
    /// ([`crate::ComposedShader::bindings_used`]).
    pub fn new(
        context: &GpuContext,
        label: &str,
        shared_layouts: &[&wgpu::BindGroupLayout],
        module: &wgpu::ShaderModule,
        table: &[wgpu::BindGroupLayoutEntry],
        entries: [&str; N],
        used: [Vec<u32>; N],
    ) -> Self {
        let mut used = used.into_iter();
        let passes = entries.map(|entry| {
            let bindings = used.next().unwrap_or_default();
            let layout_entries: Vec<wgpu::BindGroupLayoutEntry> = table
                .iter()
                .filter(|entry| bindings.contains(&entry.binding))
                .copied()
                .collect();
            let layout =
                context
                    .device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some(&format!("{label}: {entry}")),
                        entries: &layout_entries,
                    });
            let layouts: Vec<Option<&wgpu::BindGroupLayout>> = shared_layouts
                .iter()
                .copied()
                .chain([&layout])
                .map(Some)
                .collect();
            let pipeline_layout =
                context
                    .device
                    .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some(entry),
                        bind_group_layouts: &layouts,
                        immediate_size: 0,
                    });
            let pipeline = compute_pipeline(context, &pipeline_layout, module, entry);
            EntryPointPass {
                pipeline,
                layout,
                bindings,
            }
        });
        Self { passes }
    }

    /// The pipeline of the `index`-th entry point.
    pub fn pipeline(&self, index: usize) -> &wgpu::ComputePipeline {
        &self.passes[index].pipeline
    }

    /// One bind group per entry point, each with the resources of `table` (binding,
    /// resource) its entry point uses.
    pub fn bind_groups(
        &self,
        context: &GpuContext,
        label: &str,
        table: &[(u32, wgpu::BindingResource<'_>)],
    ) -> [wgpu::BindGroup; N] {
        std::array::from_fn(|index| {
            let pass = &self.passes[index];
            bind_group(
                context,
                label,
                &pass.layout,
                table
                    .iter()
                    .filter(|(binding, _)| pass.bindings.contains(binding))
                    .map(|(binding, resource)| (*binding, resource.clone())),
            )
        })
    }
}

/// A bind group kept for as long as what it binds stays the same: the prepared frame's way
/// of building bind groups in `prepare` and never while recording. The key is the layout
/// and every bound resource by identity (wgpu's handles compare by object), so a buffer
/// grown, a target resized or a scene reloaded rebuilds the group, and nothing else does:
/// there is no dirty flag to forget.
#[derive(Debug, Default)]
pub struct CachedBindGroup {
    built: Option<(BindingKey, wgpu::BindGroup)>,
}

/// The identity of a bind group's layout and resources, in binding order.
#[derive(Debug, Clone, PartialEq, Eq)]
struct BindingKey {
    layout: wgpu::BindGroupLayout,
    resources: Vec<(u32, BoundResource)>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum BoundResource {
    Buffer(wgpu::Buffer, wgpu::BufferAddress, Option<wgpu::BufferSize>),
    Sampler(wgpu::Sampler),
    View(wgpu::TextureView),
}

impl BoundResource {
    /// `None` for the array bindings the renderer does not use (never kept).
    fn of(resource: &wgpu::BindingResource) -> Option<Self> {
        Some(match resource {
            wgpu::BindingResource::Buffer(binding) => {
                Self::Buffer(binding.buffer.clone(), binding.offset, binding.size)
            }
            wgpu::BindingResource::Sampler(sampler) => Self::Sampler((*sampler).clone()),
            wgpu::BindingResource::TextureView(view) => Self::View((*view).clone()),
            _ => return None,
        })
    }
}

impl CachedBindGroup {
    /// The bind group of `layout` binding `resources`: the one built before if it bound the
    /// same objects, else a new one (counted by the context). Handles are shared: the clone
    /// returned is the kept group.
    pub fn get<'a>(
        &mut self,
        context: &GpuContext,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        resources: impl IntoIterator<Item = (u32, wgpu::BindingResource<'a>)>,
    ) -> wgpu::BindGroup {
        let resources: Vec<(u32, wgpu::BindingResource<'a>)> = resources.into_iter().collect();
        // Array bindings (unused by the renderer) have no key: such a group is never kept.
        let key = resources
            .iter()
            .map(|(binding, resource)| Some((*binding, BoundResource::of(resource)?)))
            .collect::<Option<Vec<_>>>()
            .map(|resources| BindingKey {
                layout: layout.clone(),
                resources,
            });
        if let (Some((built, group)), Some(key)) = (&self.built, &key)
            && built == key
        {
            return group.clone();
        }
        let group = bind_group(context, label, layout, resources);
        self.built = key.map(|key| (key, group.clone()));
        group
    }
}
