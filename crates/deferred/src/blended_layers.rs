//! Blended surfaces (glTF's `BLEND`) shaded where deferred shades opaque ones: in compute,
//! from the same clusters (issue 61). The forward blended pass runs the cluster loop in
//! a fragment shader, the path the H200 runs about 34 times slower than compute; under
//! sponza-glass's glass it took 171 ms of a 174 ms frame. On the compute lighting paths
//! deferred instead
//! 1. stores each blended fragment in front of the opaque surface, unlit, as a node of its
//!    pixel's list (a fragment pass: `blended_layers_store.wgsl`), every attribute the
//!    forward pass would shade in f32;
//! 2. after the lighting (and the shadow filter), shades every pixel's layers with the
//!    cluster loop the forward pass runs and composites them over the opaque frame
//!    (a compute pass: `blended_layers_shade.wgsl`): the nearest [`SORTED_LAYERS`] sorted
//!    back to front with "over", any farther ones merged under them by weighted blended
//!    transparency.
//!
//! Sorting is per pixel, where the forward pass sorts objects by their boxes' centres: the
//! two agree wherever objects do not interleave in depth, and where they do the layers are
//! right and the forward pass is not.
//!
//! Memory: the lists' nodes come from one pool of [`POOL_LAYERS_PER_PIXEL`] nodes a pixel
//! ([`NODE_BYTES`] each, [`EMISSION_BYTES`] more with emissive materials) and a head a
//! pixel: 196 bytes a pixel, 406 MB at 1920x1080 (244 bytes and 506 MB with emission),
//! held to the device's largest storage binding. Fragments past the pool are not stored;
//! [`LayerCounts`] says how many, and the lab reports it.
//!
//! WebGPU's 8 storage buffers a stage: the frame's lighting binding takes all 8, and the
//! shading pass needs 3 of its own ([`LAYER_STORAGE_BUFFERS`]). A loop without a far
//! field binds the lighting without the far field's (5), so it fits; a loop with a far
//! field draws its blended surfaces forward ([`shades_in_layers`]).

use manylights_cluster::LightLoop;
use manylights_gpu::binding::{
    CachedBindGroup, depth_texture_entry, storage_entry, texture_2d_entry,
};
use manylights_gpu::blended::Transparency;
use manylights_gpu::{
    DepthConvention, GpuContext, GpuResult, GpuScene, PassName, PipelineKey, Program,
    ScenePipelineDesc, ShaderDef, ShaderLibrary, Specialized, ViewBinding, timed_compute_pass,
    wgpu,
};
use manylights_lights::Shading;
use manylights_pipeline::{
    BlendedPass, FrameInputs, FrameRecorder, LIGHTING_GROUP, PipelineBuild, PreparedBlended,
};

use crate::{LightingPath, SHADERS};

/// The store pass's timed name.
pub const LAYERS_STORE_PASS: PassName = PassName::new("blended layers (store)");
/// The shading and compositing pass's timed name.
pub const LAYERS_SHADING_PASS: PassName = PassName::new("blended layers (shading)");

/// Layers a pixel composites exactly sorted (the WGSL's `#SORTED_LAYERS`); farther ones
/// are merged by weight.
pub const SORTED_LAYERS: u32 = 4;
/// The node pool's size: this many layers for every pixel of the frame, on average.
pub const POOL_LAYERS_PER_PIXEL: u64 = 3;
/// One node (`LayerNode`): position, depth, normal, alpha, albedo, lobe, specular, next.
pub const NODE_BYTES: u64 = 64;
/// A node's emission (a fifth plane, f32), with emissive materials.
pub const EMISSION_BYTES: u64 = 16;
/// The storage buffers the shading pass binds besides the lighting's: heads, nodes,
/// counters.
pub const LAYER_STORAGE_BUFFERS: u32 = 3;
/// A pixel's list head.
const HEAD_BYTES: u64 = 4;

/// The store program for surfaces built for `shading` (composed per material variant).
pub fn store_program(shading: Shading, emissive: bool) -> Program {
    let program = Program::shading_materials(
        format!("blended_layers_store ({shading})"),
        &SHADERS,
        "deferred/blended_layers_store.wgsl",
    )
    .with_shading(shading);
    with_emission(program, emissive)
}

/// The shading program running `light_loop` (the blended loop: shadows unfiltered), on
/// the lighting path `path` (tiles: the tile-shared loop, one depth rank at a time).
pub fn shade_program(emissive: bool, path: LightingPath, light_loop: LightLoop) -> Program {
    let program = Program::new(
        format!("blended_layers_shade_{path} ({})", light_loop.label()),
        &SHADERS,
        "deferred/blended_layers_shade.wgsl",
    )
    .with_defs(light_loop.shader_defs());
    let program = match path {
        LightingPath::Tiles => program.with_def("LIGHTING_TILES", ShaderDef::Bool(true)),
        _ => program,
    };
    with_emission(program, emissive)
}

fn with_emission(program: Program, emissive: bool) -> Program {
    if emissive {
        program.with_def("EMISSIVE", ShaderDef::Bool(true))
    } else {
        program
    }
}

/// Whether blended surfaces under `light_loop` are shaded as layers: where the loop has
/// no far field. The shading pass binds the lighting without the far field's buffers (5
/// storage buffers) and 3 of its own: WebGPU's 8 a stage. With a far field it would need
/// 11, which WebGPU does not guarantee, so those loops draw their blended surfaces forward
/// (on every device alike: the page and the native frame agree).
pub fn shades_in_layers(light_loop: LightLoop) -> bool {
    !light_loop.has_far_field()
}

/// A deferred frame's blended surfaces: drawn forward from the clusters after the lighting
/// (`pipeline::BlendedPass`: the fragment path, weighted transparency, far fields), or
/// stored as layers and shaded in compute ([`shades_in_layers`]).
#[derive(Debug)]
pub(crate) struct BlendedSurfaces {
    forward: BlendedPass<LightLoop>,
    layers: BlendedLayers,
    /// The frame's lighting binding's layout, the forward pass's group 3.
    lighting_layout: wgpu::BindGroupLayout,
    /// The HDR target as a compute pass's output, the layers' group 2.
    output_layout: wgpu::BindGroupLayout,
}

/// What the blended layers' shading program is specialised by: the lighting path it runs
/// on and the light loop of the frame's blended surfaces (`LightLoop::for_blended`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct LayersShadeKey {
    pub path: LightingPath,
    pub light_loop: LightLoop,
}

/// A frame's blended surfaces, prepared: one way or the other.
#[derive(Debug)]
pub(crate) enum PreparedSurfaces<'a> {
    Forward(PreparedBlended<'a>),
    Layers(PreparedLayers<'a>),
}

impl BlendedSurfaces {
    /// The blended surfaces of `build`'s pipeline, whose compute paths write the HDR
    /// target through a group of `output_layout`.
    pub(crate) fn new(build: &PipelineBuild, output_layout: &wgpu::BindGroupLayout) -> Self {
        Self {
            forward: BlendedPass::new(build.library, build.depth),
            layers: BlendedLayers::new(build),
            lighting_layout: build.lighting_layout.clone(),
            output_layout: output_layout.clone(),
        }
    }

    /// The frame's blended surfaces under `blended_loop` (`LightLoop::for_blended`), on the
    /// lighting path `path`, with `hdr_output` the HDR target as the compute paths' output
    /// (`None` on the fragment path): `None` when the scene has none.
    pub(crate) fn prepare<'a>(
        &'a mut self,
        frame: &FrameInputs,
        key: LayersShadeKey,
        hdr_output: Option<wgpu::BindGroup>,
    ) -> GpuResult<Option<PreparedSurfaces<'a>>> {
        let sorted = frame.transparency == Transparency::Sorted;
        let blended_loop = key.light_loop;
        match hdr_output {
            Some(hdr) if sorted && shades_in_layers(blended_loop) => Ok(self
                .layers
                .prepare(frame, key, &self.output_layout, hdr)?
                .map(PreparedSurfaces::Layers)),
            _ => Ok(self
                .forward
                .prepare(
                    frame,
                    &self.lighting_layout,
                    blended_loop,
                    manylights_cluster::blended_program,
                )?
                .map(PreparedSurfaces::Forward)),
        }
    }

    /// A frame begins: what the layers counted is an earlier frame's until it stores some.
    pub(crate) fn begin_frame(&mut self) {
        self.layers.begin_frame();
    }

    /// What the last frame's layers counted (`BlendedLayers::read_counts_async`).
    pub(crate) async fn read_layer_counts_async(
        &self,
        context: &GpuContext,
    ) -> GpuResult<Option<LayerCounts>> {
        self.layers.read_counts_async(context).await
    }
}

impl PreparedSurfaces<'_> {
    /// The blended surfaces over the HDR target, after everything else writes it.
    pub(crate) fn record(&self, frame: &mut FrameRecorder) {
        match self {
            PreparedSurfaces::Forward(forward) => forward.record(frame),
            PreparedSurfaces::Layers(layers) => layers.record(frame),
        }
    }
}

/// What the store pass counted in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LayerCounts {
    /// Blended fragments in front of the opaque surface (stored, or past the pool).
    pub fragments: u32,
    /// Of those, the ones past the pool (not drawn).
    pub past_pool: u32,
    /// Pixels with more than [`SORTED_LAYERS`] layers (their farther layers merged).
    pub merged_pixels: u32,
}

/// The store and shading passes' pipelines and the frame's pool.
#[derive(Debug)]
struct BlendedLayers {
    library: ShaderLibrary,
    /// The lighting binding's layout without the far field's (loops without one).
    near_field_layout: wgpu::BindGroupLayout,
    brdf: Shading,
    emissive: bool,
    depth: DepthConvention,
    store_layout: wgpu::BindGroupLayout,
    shade_layout: wgpu::BindGroupLayout,
    store_pipelines: Option<Vec<(PipelineKey, wgpu::RenderPipeline)>>,
    shade_pipelines: Specialized<LayersShadeKey, wgpu::ComputePipeline>,
    pool: Option<LayerPool>,
    store_group: CachedBindGroup,
    shade_group: CachedBindGroup,
    /// The last frame prepared stored layers (what `read_counts_async` reads is its).
    in_last_frame: bool,
}

/// The lists' storage for one frame size.
#[derive(Debug)]
struct LayerPool {
    size: (u32, u32),
    heads: wgpu::Buffer,
    nodes: wgpu::Buffer,
    /// Claimed nodes and merged pixels (`LayerCounters`).
    counters: wgpu::Buffer,
    /// Nodes the pool holds.
    capacity: u64,
    /// The opaque frame, copied from the HDR target the shading pass writes.
    opaque: manylights_gpu::Target,
}

/// A frame's blended layers, prepared: the pipelines of its loop and the groups they bind.
#[derive(Debug)]
pub(crate) struct PreparedLayers<'a> {
    store_pipelines: &'a [(PipelineKey, wgpu::RenderPipeline)],
    shade_pipeline: &'a wgpu::ComputePipeline,
    pool: &'a LayerPool,
    store_group: wgpu::BindGroup,
    shade_group: wgpu::BindGroup,
    /// The blended draws (their order is the store's: any order stores the same lists).
    draws: Vec<usize>,
    /// The HDR target as a storage texture (the lighting's output group).
    output_group: wgpu::BindGroup,
    lighting: wgpu::BindGroup,
}

impl BlendedLayers {
    pub(crate) fn new(build: &PipelineBuild) -> Self {
        let (context, library) = (build.gpu, build.library);
        let (brdf, emissive, depth) = (build.shading, build.scene.features.emissive, build.depth);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let compute = wgpu::ShaderStages::COMPUTE;
        let store_entries = [
            storage_entry(0, fragment, false),
            storage_entry(1, fragment, false),
            storage_entry(2, fragment, false),
            depth_texture_entry(3, fragment),
        ];
        let unfiltered = wgpu::TextureSampleType::Float { filterable: false };
        let shade_entries = [
            storage_entry(0, compute, true),
            storage_entry(1, compute, true),
            storage_entry(2, compute, false),
            texture_2d_entry(3, compute, unfiltered),
        ];
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            manylights_gpu::binding::bind_group_layout(context, label, entries)
        };
        Self {
            library: library.clone(),
            near_field_layout: build.near_field_layout.clone(),
            brdf,
            emissive,
            depth,
            store_layout: layout("blended layers store layout", &store_entries),
            shade_layout: layout("blended layers shade layout", &shade_entries),
            store_pipelines: None,
            shade_pipelines: Specialized::default(),
            pool: None,
            store_group: CachedBindGroup::default(),
            shade_group: CachedBindGroup::default(),
            in_last_frame: false,
        }
    }

    /// A frame that stores no layers begins: the counts of an earlier one are no longer
    /// the last frame's.
    pub(crate) fn begin_frame(&mut self) {
        self.in_last_frame = false;
    }

    /// The frame's layers, shaded by `key`'s loop (without a far field) on its compute
    /// lighting path: `None` when the scene has no blended surfaces. `output_layout` and
    /// `output_group`: the HDR target as the compute lighting's output.
    pub(crate) fn prepare<'a>(
        &'a mut self,
        frame: &FrameInputs,
        key: LayersShadeKey,
        output_layout: &wgpu::BindGroupLayout,
        output_group: wgpu::BindGroup,
    ) -> GpuResult<Option<PreparedLayers<'a>>> {
        let (context, scene, view, targets) = (frame.gpu, frame.scene, frame.view, frame.targets);
        let keys = scene.blended_keys();
        if keys.is_empty() {
            return Ok(None);
        }
        self.in_last_frame = true;
        if self.store_pipelines.is_none() {
            self.store_pipelines = Some(self.build_store_pipelines(context, scene, view, &keys)?);
        }
        self.prepare_pool(context, targets.size)?;
        // The loop has no far field (`shades_in_layers`): it reads the lighting binding
        // without it, which leaves room for the pass's own storage buffers.
        let layouts = [
            &view.layout,
            &self.shade_layout,
            output_layout,
            &self.near_field_layout,
        ];
        let (library, emissive) = (&self.library, self.emissive);
        let shade_pipeline = &*self.shade_pipelines.get_or_build(key, |key| {
            build_shade_pipeline(context, library, layouts, emissive, key)
        })?;
        let Some(pool) = &self.pool else {
            unreachable!("prepare_pool made the pool")
        };
        let depth_view = manylights_gpu::targets::depth_only_view(&targets.depth.texture);
        let buffer = |b: &'a wgpu::Buffer| b.as_entire_binding();
        let store = [
            (0, buffer(&pool.heads)),
            (1, buffer(&pool.nodes)),
            (2, buffer(&pool.counters)),
            (3, wgpu::BindingResource::TextureView(&depth_view)),
        ];
        let shade = [
            (0, buffer(&pool.heads)),
            (1, buffer(&pool.nodes)),
            (2, buffer(&pool.counters)),
            (3, wgpu::BindingResource::TextureView(&pool.opaque.view)),
        ];
        let store_group =
            self.store_group
                .get(context, "blended layers store", &self.store_layout, store);
        let shade_group =
            self.shade_group
                .get(context, "blended layers shading", &self.shade_layout, shade);
        Ok(Some(PreparedLayers {
            store_pipelines: self.store_pipelines.as_deref().unwrap_or_default(),
            shade_pipeline,
            pool,
            store_group,
            shade_group,
            draws: scene.blended_back_to_front(frame.eye),
            output_group,
            lighting: frame.lighting.near_field_group.clone(),
        }))
    }

    /// What the last frame's store and shading passes counted (`None` before any frame
    /// with blended surfaces on a compute path). Waits for the GPU.
    pub(crate) async fn read_counts_async(
        &self,
        context: &GpuContext,
    ) -> GpuResult<Option<LayerCounts>> {
        let Some(pool) = self.pool.as_ref().filter(|_| self.in_last_frame) else {
            return Ok(None);
        };
        let counters: Vec<u32> =
            manylights_gpu::targets::read_buffer_async(context, &pool.counters).await?;
        let (claimed, merged_pixels) = (counters[0], counters[1]);
        let stored = u32::try_from(pool.capacity).unwrap_or(u32::MAX);
        Ok(Some(LayerCounts {
            fragments: claimed,
            past_pool: claimed.saturating_sub(stored),
            merged_pixels,
        }))
    }

    fn build_store_pipelines(
        &self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        keys: &[PipelineKey],
    ) -> GpuResult<Vec<(PipelineKey, wgpu::RenderPipeline)>> {
        let program = store_program(self.brdf, self.emissive);
        keys.iter()
            .map(|&key| {
                let desc = ScenePipelineDesc {
                    label: "blended layers store",
                    program: &program,
                    key,
                    view_layout: &view.layout,
                    extra_layouts: &[&self.store_layout],
                    vertex_entry: "vs_main",
                    fragment_entry: Some("fs_store_layer"),
                    color_targets: &[],
                    depth_write: false,
                    depth_compare: self.depth.nearer(),
                    pulls_vertices: false,
                    samples: 1,
                };
                Ok((key, scene.create_pipeline(context, &self.library, &desc)?))
            })
            .collect()
    }

    /// The pool for frames of `size` (made anew only when the size changes).
    fn prepare_pool(&mut self, context: &GpuContext, size: (u32, u32)) -> GpuResult<()> {
        if self.pool.as_ref().is_some_and(|pool| pool.size == size) {
            return Ok(());
        }
        let pixels = u64::from(size.0) * u64::from(size.1);
        let limits = context.device.limits();
        let largest = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let node_bytes = NODE_BYTES + if self.emissive { EMISSION_BYTES } else { 0 };
        let capacity = (pixels * POOL_LAYERS_PER_PIXEL)
            .min(largest / node_bytes)
            .max(1);
        let storage = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
            context.check_buffer_size(label, bytes, true)?;
            context.scoped(&format!("creating the {label}"), || {
                context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | usage,
                    mapped_at_creation: false,
                })
            })
        };
        let cleared = wgpu::BufferUsages::COPY_DST;
        let opaque = manylights_gpu::Target::new(
            context,
            "blended layers' opaque frame",
            size,
            manylights_gpu::HDR_FORMAT,
            wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::TEXTURE_BINDING,
        )?;
        self.pool = Some(LayerPool {
            size,
            heads: storage("blended layer heads", pixels * HEAD_BYTES, cleared)?,
            nodes: storage(
                "blended layer nodes",
                capacity * node_bytes,
                wgpu::BufferUsages::empty(),
            )?,
            counters: storage(
                "blended layer counters",
                8,
                cleared | wgpu::BufferUsages::COPY_SRC,
            )?,
            capacity,
            opaque,
        });
        Ok(())
    }
}

/// The shading pass's pipeline for `emissive` scenes, running `key`'s loop on its path,
/// on its four groups' `layouts` (view, layers, HDR output, lighting without the far
/// field).
fn build_shade_pipeline(
    context: &GpuContext,
    library: &ShaderLibrary,
    layouts: [&wgpu::BindGroupLayout; 4],
    emissive: bool,
    key: LayersShadeKey,
) -> GpuResult<wgpu::ComputePipeline> {
    let LayersShadeKey { path, light_loop } = key;
    let program = shade_program(emissive, path, light_loop);
    let module = library.create_module(context, &program, Default::default())?;
    let label = format!("blended layers shading ({path}, {})", light_loop.label());
    context.scoped(&format!("creating {label}"), || {
        let layout = context
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&label),
                bind_group_layouts: &layouts.map(Some),
                immediate_size: 0,
            });
        context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&label),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("cs_shade_layers"),
            compilation_options: Default::default(),
            cache: None,
        })
    })
}

impl PreparedLayers<'_> {
    /// The store pass over the blended draws, then the shading pass over the HDR target
    /// (after everything else writes it).
    pub(crate) fn record(&self, frame: &mut FrameRecorder) {
        let (scene, view, targets) = (frame.scene, frame.view, frame.targets);
        let (encoder, timer) = (&mut *frame.encoder, &mut *frame.timer);
        let pool = self.pool;
        encoder.clear_buffer(&pool.heads, 0, None);
        encoder.clear_buffer(&pool.counters, 0, None);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(LAYERS_STORE_PASS.as_str()),
                color_attachments: &[],
                // Read-only: the shader reads the same depth to test against.
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: targets.depth_view(),
                    depth_ops: None,
                    stencil_ops: None,
                }),
                timestamp_writes: timer.render_pass(LAYERS_STORE_PASS),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &view.bind_group, &[]);
            pass.set_bind_group(3, &self.store_group, &[]);
            scene.draw_blended(&mut pass, &self.draws, |key| {
                self.store_pipelines
                    .iter()
                    .find(|(k, _)| *k == key)
                    .map(|(_, pipeline)| pipeline)
            });
        }
        manylights_gpu::targets::copy_whole_texture(
            encoder,
            &targets.hdr.texture,
            &pool.opaque.texture,
        );
        let mut pass = timed_compute_pass(encoder, Some(timer), LAYERS_SHADING_PASS);
        pass.set_pipeline(self.shade_pipeline);
        pass.set_bind_group(0, &view.bind_group, &[]);
        pass.set_bind_group(1, &self.shade_group, &[]);
        pass.set_bind_group(2, &self.output_group, &[]);
        pass.set_bind_group(LIGHTING_GROUP, &self.lighting, &[]);
        let tile = manylights_gpu::SCREEN_TILE;
        pass.dispatch_workgroups(pool.size.0.div_ceil(tile), pool.size.1.div_ceil(tile), 1);
    }
}

#[cfg(test)]
mod tests {
    use manylights_pipeline::FrameLighting;

    /// The shading pass's storage buffers and the lighting's without the far field fit
    /// the 8 a stage every WebGPU adapter offers (`cargo xtask limits` checks the
    /// programs themselves).
    #[test]
    fn the_shading_pass_fits_webgpus_storage_buffers() {
        let near_field = FrameLighting::storage_buffers(true);
        assert_eq!(near_field, 5);
        assert_eq!(FrameLighting::storage_buffers(false), 8);
        assert!(near_field + super::LAYER_STORAGE_BUFFERS <= 8);
    }
}
