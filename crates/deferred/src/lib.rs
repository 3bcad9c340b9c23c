//! Clustered deferred shading. A G-buffer pass (`shaders/deferred/gbuffer.wgsl`) writes
//! only what lighting needs, in one of three [`GBufferLayout`]s; a lighting pass reads it,
//! finds each pixel's cluster with the shared `cluster_index`, and shades that cluster's
//! lights, either as a fullscreen fragment pass or as a compute pass over 8x8 tiles
//! ([`LightingPath`]).
//!
//! Layouts, bytes per pixel including the 4-byte depth buffer (without / with the specular
//! channel, which holds F0 in every PBR frame and exists in Blinn-Phong frames only when a
//! material of the scene has a specular colour):
//! - `full`: position + lobe (exponent or roughness), normal, albedo (and specular) all in
//!   f32: 52 / 68 B, lossless, matches naive.
//! - `compact`: position from depth, octahedral normal in 2x16 bits, albedo sRGB 8-bit
//!   with the lobe's code in alpha (and specular sRGB 8-bit): 12 / 16 B.
//! - `packed`: one Rgba32Uint (albedo 8:8:8 + lobe 8, normal 16:16, specular 8:8:8)
//!   plus depth: 20 B.
//!
//! Blended (`BLEND`) materials cannot be deferred (one surface per pixel): they are shaded
//! forward from the same clusters after the lighting (`manylights_cluster::BlendedPass`).
//!
//! ```no_run
//! use manylights_deferred::{DeferredPipeline, DeferredSettings};
//! use manylights_cluster::GpuClusters;
//! use manylights_pipeline::{
//!     FrameInputs, FrameRecorder, PipelineBuild, PreparedShading, ShadingPipeline,
//! };
//! # fn frame(build: &PipelineBuild, inputs: &FrameInputs, recorder: &mut FrameRecorder, clusters: &GpuClusters) -> manylights_gpu::GpuResult<()> {
//! let mut pipeline = DeferredPipeline::new(build)?; // once per scene
//! let settings = DeferredSettings::default();
//! // Every frame, with `clusters` prepared for it (and the depth `early_depth` promises):
//! // the G-buffer, then (in `record`) the cluster assignment, which given its depth lists
//! // only what is seen, then the lighting.
//! let prepared = pipeline.prepare(inputs, clusters, &settings)?;
//! let depth = prepared.record_depth(recorder);
//! prepared.record(recorder, depth);
//! # Ok(()) }
//! ```

mod blended_layers;
mod frame;
mod programs;
mod settings;
mod visibility;

use manylights_cluster::LightLoop;
use manylights_gpu::binding::CachedBindGroup;
use manylights_gpu::{
    DepthConvention, GpuContext, GpuError, GpuResult, GpuScene, HDR_FORMAT, PassName, PipelineKey,
    RenderTargets, ScenePipelineDesc, ShaderDef, ShaderLibrary, ShaderModules, Specialized, Target,
    ViewBinding, shader_files, wgpu,
};
use manylights_lights::Shading;
use manylights_visibility::ShadowFilter;

use blended_layers::BlendedSurfaces;
pub use blended_layers::{
    EMISSION_BYTES, LAYER_STORAGE_BUFFERS, LAYERS_SHADING_PASS, LAYERS_STORE_PASS, LayerCounts,
    NODE_BYTES, POOL_LAYERS_PER_PIXEL, SORTED_LAYERS, shade_program, shades_in_layers,
    store_program,
};
pub use frame::DeferredFrame;
pub use manylights_visibility::{
    RASTER_PLANE_PIXELS_INVERSE, REBUILT_DEPTH_ULPS, rebuilt_position_error,
};
pub use manylights_visibility::{
    SHADOW_FILTER_COLUMNS_PASS, SHADOW_FILTER_ROWS_PASS, SHADOW_FILTER_TEMPORAL_PASS,
};
pub use programs::{codec_probe_program, gbuffer_program, lighting_program, programs};
pub use settings::{DeferredSettings, DeferredView, GBufferChannel, GBufferLayout, LightingPath};
pub use visibility::{
    CLASSIFY_PASS, RESOLVE_PASS, VISIBILITY_PASS, classify_program, raster_program, resolve_program,
};

/// This crate's WGSL: the codecs, each layout's write and read halves, the G-buffer pass
/// and the two lighting paths.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "deferred",
    files: shader_files![
        "deferred/codecs.wgsl",
        "deferred/full_write.wgsl",
        "deferred/full_read.wgsl",
        "deferred/compact_write.wgsl",
        "deferred/compact_read.wgsl",
        "deferred/packed_write.wgsl",
        "deferred/packed_read.wgsl",
        "deferred/gbuffer.wgsl",
        "deferred/lighting.wgsl",
        "deferred/lighting_fragment.wgsl",
        "deferred/lighting_compute.wgsl",
        "deferred/codec_probe.wgsl",
        "deferred/visibility_geometry.wgsl",
        "deferred/visibility.wgsl",
        "deferred/visibility_classify.wgsl",
        "deferred/visibility_resolve.wgsl",
        "deferred/blended_layers.wgsl",
        "deferred/blended_layers_store.wgsl",
        "deferred/blended_layers_shade.wgsl",
    ],
    uses: &[&manylights_cluster::SHADERS],
    constants: shader_constants,
};

/// The deferred shaders' constants: the G-buffer debug views' codes, and the layers a
/// pixel's blended surfaces sort (`blended_layers.wgsl`).
fn shader_constants() -> Vec<(String, ShaderDef)> {
    let mut constants = GBufferChannel::shader_defs();
    constants.push(("SORTED_LAYERS".into(), ShaderDef::UInt(SORTED_LAYERS)));
    constants
}

/// The G-buffer pass's timed name.
pub const GBUFFER_PASS: PassName = PassName::new("g-buffer");
/// The fragment lighting pass's timed name.
pub const LIGHTING_FRAGMENT_PASS: PassName = PassName::new("lighting (fragment)");
/// The compute lighting pass's timed name.
pub const LIGHTING_COMPUTE_PASS: PassName = PassName::new("lighting (compute)");
/// The tiles path's lighting pass's timed name.
pub const LIGHTING_TILES_PASS: PassName = PassName::new("lighting (tiles)");

/// The depth buffer's binding in every layout's read group (`gbuffer_depth`).
const DEPTH_BINDING: u32 = 4;

/// The emission target's binding in the read group (`gbuffer_emission` in lighting.wgsl),
/// present only when a material of the scene emits light.
const EMISSION_BINDING: u32 = 5;

/// Emitted radiance is HDR (emissive strength goes past 1): half floats, 8 B a pixel, a
/// target of its own in every layout, created only for scenes with emissive materials.
const EMISSION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The id of the `GBUFFER_SPECULAR` pipeline constant in the read halves.
pub const GBUFFER_SPECULAR_ID: &str = "0";

/// Lighting asked for before `record_depth` drew the layout's G-buffer.
fn not_drawn(layout: GBufferLayout) -> manylights_gpu::GpuError {
    manylights_gpu::GpuError::Unsupported(format!(
        "the {layout} G-buffer was not drawn (record_depth first)"
    ))
}

/// The formats of a layout's colour targets (the specular one last, where it exists).
fn target_formats(layout: GBufferLayout, specular: bool) -> Vec<wgpu::TextureFormat> {
    use wgpu::TextureFormat as F;
    let mut formats = match layout {
        GBufferLayout::Full => vec![F::Rgba32Float, F::Rgba32Float, F::Rgba32Float],
        GBufferLayout::Compact => vec![F::Rg16Uint, F::Rgba8UnormSrgb],
        GBufferLayout::Packed | GBufferLayout::Visibility => return vec![F::Rgba32Uint],
    };
    if specular {
        formats.push(match layout {
            GBufferLayout::Full => F::Rgba32Float,
            _ => F::Rgba8UnormSrgb,
        });
    }
    formats
}

/// The G-buffer pass writes all its colour targets at once: their bytes per sample (each
/// aligned as WebGPU counts them) must fit the device's
/// `max_color_attachment_bytes_per_sample` (32 on every WebGPU adapter; the full layout
/// needs 48 to 64, which many browsers' adapters grant and some do not). An error that
/// names the limit, instead of a failed pipeline.
fn check_bytes_per_sample(
    context: &GpuContext,
    layout: GBufferLayout,
    targets: &[Option<wgpu::ColorTargetState>],
) -> GpuResult<()> {
    let needed = targets.iter().flatten().fold(0, |bytes: u32, target| {
        let alignment = target.format.target_component_alignment().unwrap_or(1);
        bytes.next_multiple_of(alignment) + target.format.target_pixel_byte_cost().unwrap_or(0)
    });
    let allowed = context
        .device
        .limits()
        .max_color_attachment_bytes_per_sample;
    if needed > allowed {
        return Err(GpuError::LimitExceeded {
            what: format!(
                "the {} G-buffer's colour targets (bytes a pixel)",
                layout.name()
            ),
            needed: u64::from(needed),
            limit: "max_color_attachment_bytes_per_sample",
            allowed: u64::from(allowed),
        });
    }
    Ok(())
}

/// Bytes per pixel of a layout, the 4-byte depth buffer (and the visibility buffer's
/// instance and triangle) included.
pub fn bytes_per_pixel(layout: GBufferLayout, specular: bool) -> u32 {
    let visibility = match layout {
        GBufferLayout::Visibility => visibility::VISIBILITY_FORMAT
            .block_copy_size(None)
            .unwrap_or(0),
        _ => 0,
    };
    4 + visibility
        + target_formats(layout, specular)
            .iter()
            .map(|f| f.block_copy_size(None).unwrap_or(0))
            .sum::<u32>()
}

/// Whether the G-buffer stores a specular colour for frames shaded with `shading` on a scene
/// with (`scene_specular`) or without Blinn-Phong specular materials: always under PBR,
/// where it is F0; under Blinn-Phong only when a material has one.
pub fn stores_specular(scene_specular: bool, shading: Shading) -> bool {
    scene_specular || shading == Shading::Pbr
}

/// Whether a layout stores specular in a target of its own (full, compact).
fn has_specular_target(layout: GBufferLayout) -> bool {
    matches!(layout, GBufferLayout::Full | GBufferLayout::Compact)
}

/// The G-buffer textures of one size and layout, and the bind group lighting reads them
/// through.
#[derive(Debug)]
struct GBuffer {
    size: (u32, u32),
    /// The depth texture its read group binds (the frame's targets, when it was built).
    depth: wgpu::Texture,
    targets: Vec<Target>,
    /// 1x1 stand-in bound where a layout's specular texture would be when the scene has
    /// no specular (never read: the shader's GBUFFER_SPECULAR is false).
    _placeholder: Option<Target>,
    /// Emitted radiance, when a material of the scene emits.
    emission: Option<Target>,
    read_group: wgpu::BindGroup,
    /// The visibility buffer's own targets, for that layout.
    visibility: Option<visibility::VisibilityFrame>,
}

/// Per-layout pipelines, built on first use.
#[derive(Debug)]
struct LayoutPipelines {
    /// The G-buffer pass's pipelines (empty for the visibility buffer, whose raster is in
    /// `visibility`).
    gbuffer: Vec<(PipelineKey, wgpu::RenderPipeline)>,
    visibility: Option<visibility::VisibilityPipelines>,
    read_layout: wgpu::BindGroupLayout,
}

/// What a lighting pipeline is specialized for: the G-buffer layout it reads, its path
/// and its light loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct LightingKey {
    layout: GBufferLayout,
    path: LightingPath,
    light_loop: LightLoop,
}

/// A lighting pass's pipeline, on its path.
#[derive(Debug)]
enum LightingPipeline {
    Fragment(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
}

/// The deferred pipelines for one uploaded scene.
#[derive(Debug)]
pub struct DeferredPipeline {
    depth: DepthConvention,
    library: ShaderLibrary,
    /// Per-layout pipelines are built on first use (most sessions use one layout).
    /// The G-buffer stores a specular colour: always with PBR (its F0), with Blinn-Phong
    /// when a material of the scene has one.
    specular: bool,
    /// A material of the scene has a Blinn-Phong specular colour (else Blinn-Phong loops
    /// are diffuse-only).
    specular_materials: bool,
    /// The BRDF the G-buffer's surfaces are built for and the lighting evaluates.
    brdf: Shading,
    /// A material of the scene emits light: the G-buffer carries an emission target.
    emissive: bool,
    /// Group 3 of the lighting passes: the frame's lighting binding's layout
    /// (`FrameLighting`).
    lighting_layout: wgpu::BindGroupLayout,
    output_layout: wgpu::BindGroupLayout,
    /// Each G-buffer layout's own pipelines, built the first time a frame asks for it.
    layouts: Specialized<GBufferLayout, LayoutPipelines>,
    /// The lighting pass's pipelines, likewise.
    lighting: Specialized<LightingKey, LightingPipeline>,
    gbuffer: Option<(GBufferLayout, GBuffer)>,
    /// The compute lighting paths' output (the HDR target).
    output: CachedBindGroup,
    /// The spatial shadow filter, made on the first frame that asks for it.
    shadow_filter: Option<ShadowFilter>,
    /// Blended surfaces, drawn forward or stored as layers and shaded in compute.
    blended: BlendedSurfaces,
}

impl DeferredPipeline {
    /// What the last frame's blended layers counted (`None` before any frame with blended
    /// surfaces on a compute path). Waits for the GPU.
    pub async fn read_layer_counts_async(
        &self,
        context: &GpuContext,
    ) -> GpuResult<Option<LayerCounts>> {
        self.blended.read_layer_counts_async(context).await
    }

    fn build(build: &manylights_pipeline::PipelineBuild) -> GpuResult<Self> {
        let (context, library, scene) = (build.gpu, build.library, build.scene);
        let (depth, shading) = (build.depth, build.shading);
        let output_layout =
            context
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("deferred lighting output layout"),
                    entries: &[wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::StorageTexture {
                            access: wgpu::StorageTextureAccess::WriteOnly,
                            format: HDR_FORMAT,
                            view_dimension: wgpu::TextureViewDimension::D2,
                        },
                        count: None,
                    }],
                });
        Ok(Self {
            library: library.clone(),
            depth,
            specular: stores_specular(scene.features.specular, shading),
            specular_materials: scene.features.specular,
            brdf: shading,
            emissive: scene.features.emissive,
            lighting_layout: build.lighting_layout.clone(),
            layouts: Specialized::default(),
            lighting: Specialized::default(),
            gbuffer: None,
            output: CachedBindGroup::default(),
            shadow_filter: None,
            blended: BlendedSurfaces::new(build, &output_layout),
            output_layout,
        })
    }

    fn read_layout_entries(
        layout: GBufferLayout,
        emissive: bool,
    ) -> Vec<wgpu::BindGroupLayoutEntry> {
        let visibility = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let texture = |binding, sample_type| {
            manylights_gpu::binding::texture_2d_entry(binding, visibility, sample_type)
        };
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let uint = wgpu::TextureSampleType::Uint;
        let mut entries = match layout {
            GBufferLayout::Full => vec![
                texture(0, float),
                texture(1, float),
                texture(2, float),
                texture(3, float),
            ],
            GBufferLayout::Compact => vec![texture(0, uint), texture(1, float), texture(2, float)],
            GBufferLayout::Packed | GBufferLayout::Visibility => vec![texture(0, uint)],
        };
        entries.push(texture(DEPTH_BINDING, wgpu::TextureSampleType::Depth));
        if emissive {
            entries.push(texture(EMISSION_BINDING, float));
        }
        entries
    }

    /// Builds `layout`'s pipelines the first time a frame asks for them. The cache is taken
    /// out while they are built: building reads the rest of `self`.
    fn build_layout_if_new(
        &mut self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        layout: GBufferLayout,
    ) -> GpuResult<()> {
        let mut layouts = std::mem::take(&mut self.layouts);
        let built = layouts
            .get_or_build(layout, |layout| {
                self.build_pipelines(context, scene, view, layout)
            })
            .map(|_| ());
        self.layouts = layouts;
        built
    }

    fn build_pipelines(
        &self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        layout: GBufferLayout,
    ) -> GpuResult<LayoutPipelines> {
        let device = &context.device;
        let read_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("g-buffer {} read layout", layout.name())),
            entries: &Self::read_layout_entries(layout, self.emissive),
        });
        if layout == GBufferLayout::Visibility {
            return Ok(LayoutPipelines {
                gbuffer: Vec::new(),
                visibility: Some(visibility::VisibilityPipelines::new(
                    context,
                    &self.library,
                    scene,
                    view,
                    self.depth,
                    self.brdf,
                )?),
                read_layout,
            });
        }
        let formats = target_formats(layout, self.specular);
        // The write shader always outputs a specular location; without the channel the
        // pipeline has no target there and the output is dropped.
        let mut targets: Vec<Option<wgpu::ColorTargetState>> =
            formats.iter().map(|f| Some((*f).into())).collect();
        if has_specular_target(layout) && !self.specular {
            targets.push(None);
        }
        if self.emissive {
            targets.push(Some(EMISSION_FORMAT.into()));
        }
        check_bytes_per_sample(context, layout, &targets)?;
        let gbuffer_program = gbuffer_program(layout, self.brdf);
        let gbuffer = scene
            .pipeline_keys()
            .into_iter()
            .map(|key| {
                let desc = ScenePipelineDesc {
                    label: &format!("g-buffer {}", layout.name()),
                    program: &gbuffer_program,
                    key,
                    view_layout: &view.layout,
                    extra_layouts: &[],
                    vertex_entry: "vs_main",
                    fragment_entry: Some("fs_gbuffer"),
                    color_targets: &targets,
                    depth_write: true,
                    depth_compare: self.depth.nearer(),
                    pulls_vertices: false,
                    samples: 1,
                };
                Ok((key, scene.create_pipeline(context, &self.library, &desc)?))
            })
            .collect::<GpuResult<Vec<_>>>()?;
        Ok(LayoutPipelines {
            gbuffer,
            visibility: None,
            read_layout,
        })
    }

    /// Builds the lighting pipeline for `key` the first time a frame asks for it (after
    /// the layout's own pipelines). The cache is taken out while it is built, as in
    /// [`Self::build_layout_if_new`].
    fn build_lighting_if_new(
        &mut self,
        context: &GpuContext,
        view: &ViewBinding,
        key: LightingKey,
    ) -> GpuResult<()> {
        let mut lighting = std::mem::take(&mut self.lighting);
        let built = lighting
            .get_or_build(key, |key| self.build_lighting(context, view, key))
            .map(|_| ());
        self.lighting = lighting;
        built
    }

    /// The lighting's output group's layout: none on the fragment path (it writes its
    /// colour target); on the compute paths the HDR target's, or with the spatial shadow
    /// filter the filter's inputs' too.
    fn lighting_output_layout(
        &self,
        path: LightingPath,
        light_loop: LightLoop,
    ) -> Option<&wgpu::BindGroupLayout> {
        match (&self.shadow_filter, light_loop.shadows()) {
            _ if !path.is_compute() => None,
            (Some(filter), shadows) if shadows.spatially_filtered() => Some(&filter.output_layout),
            _ => Some(&self.output_layout),
        }
    }

    fn build_lighting(
        &self,
        context: &GpuContext,
        view: &ViewBinding,
        key: LightingKey,
    ) -> GpuResult<LightingPipeline> {
        let LightingKey {
            layout,
            path,
            light_loop,
        } = key;
        let device = &context.device;
        let read_layout = &self
            .layouts
            .get(&layout)
            .ok_or_else(|| not_drawn(layout))?
            .read_layout;
        let constants: Vec<(&str, f64)> = if has_specular_target(layout) {
            vec![(GBUFFER_SPECULAR_ID, if self.specular { 1.0 } else { 0.0 })]
        } else {
            Vec::new()
        };
        let compilation_options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        };
        let module = self.library.create_module(
            context,
            &lighting_program(layout, path, self.emissive, light_loop),
            Default::default(),
        )?;
        let label = format!(
            "deferred lighting {} ({path}, {})",
            layout.name(),
            light_loop.label()
        );
        context.scoped(&format!("creating {label}"), || {
            let output_layout = self.lighting_output_layout(path, light_loop);
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&label),
                bind_group_layouts: &[
                    Some(&view.layout),
                    Some(read_layout),
                    output_layout,
                    Some(&self.lighting_layout),
                ],
                immediate_size: 0,
            });
            match path {
                LightingPath::Fragment => {
                    LightingPipeline::Fragment(manylights_gpu::binding::fullscreen_pipeline(
                        context,
                        &label,
                        &pipeline_layout,
                        &module,
                        "fs_lighting",
                        HDR_FORMAT,
                        compilation_options.clone(),
                    ))
                }
                LightingPath::Compute | LightingPath::Tiles => LightingPipeline::Compute(
                    context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(&label),
                        layout: Some(&pipeline_layout),
                        module: &module,
                        entry_point: Some("cs_lighting"),
                        compilation_options: compilation_options.clone(),
                        cache: None,
                    }),
                ),
            }
        })
    }

    /// (Re)creates the G-buffer for this layout and size.
    fn prepare_gbuffer(
        &mut self,
        context: &GpuContext,
        scene: &GpuScene,
        layout: GBufferLayout,
        targets: &RenderTargets,
    ) -> GpuResult<()> {
        let size = targets.size;
        if self.gbuffer.as_ref().is_some_and(|(l, g)| {
            *l == layout && g.size == size && g.depth == targets.depth.texture
        }) {
            return Ok(());
        }
        let pipelines = self.layouts.get(&layout).ok_or_else(|| not_drawn(layout))?;
        let (gbuffer_targets, placeholder, emission) =
            self.gbuffer_targets(context, layout, size)?;
        let read_group = Self::read_group(
            context,
            layout,
            &pipelines.read_layout,
            &gbuffer_targets,
            placeholder.as_ref(),
            emission.as_ref(),
            &targets.depth.texture,
        )?;
        let visibility = match &pipelines.visibility {
            Some(visibility) => Some(visibility.frame(
                context,
                scene,
                size,
                &gbuffer_targets[0],
                emission.as_ref(),
            )?),
            None => None,
        };
        self.gbuffer = Some((
            layout,
            GBuffer {
                size,
                depth: targets.depth.texture.clone(),
                targets: gbuffer_targets,
                _placeholder: placeholder,
                emission,
                read_group,
                visibility,
            },
        ));
        Ok(())
    }

    /// The layout's targets at `size`; the 1x1 placeholder bound where the layout has a
    /// specular channel the scene does not write; the emission target of an emissive scene.
    fn gbuffer_targets(
        &self,
        context: &GpuContext,
        layout: GBufferLayout,
        size: (u32, u32),
    ) -> GpuResult<(Vec<Target>, Option<Target>, Option<Target>)> {
        // The visibility buffer's G-buffer is written by compute passes.
        let written_by = match layout {
            GBufferLayout::Visibility => wgpu::TextureUsages::STORAGE_BINDING,
            _ => wgpu::TextureUsages::RENDER_ATTACHMENT,
        };
        let usage = written_by | wgpu::TextureUsages::TEXTURE_BINDING;
        let targets = target_formats(layout, self.specular)
            .into_iter()
            .enumerate()
            .map(|(i, format)| {
                let label = format!("g-buffer {} {i}", layout.name());
                Target::new(context, &label, size, format, usage)
            })
            .collect::<GpuResult<Vec<_>>>()?;
        let placeholder = if has_specular_target(layout) && !self.specular {
            let format = *target_formats(layout, true)
                .last()
                .unwrap_or(&wgpu::TextureFormat::Rgba8UnormSrgb);
            let usage = wgpu::TextureUsages::TEXTURE_BINDING;
            let label = "g-buffer specular placeholder";
            Some(Target::new(context, label, (1, 1), format, usage)?)
        } else {
            None
        };
        let emission = match self.emissive {
            true => Some(Target::new(
                context,
                "g-buffer emission",
                size,
                EMISSION_FORMAT,
                usage,
            )?),
            false => None,
        };
        Ok((targets, placeholder, emission))
    }

    /// The lighting pass's group 1: the layout's colour targets (and placeholder) in
    /// binding order, the depth buffer and the emission target.
    fn read_group(
        context: &GpuContext,
        layout: GBufferLayout,
        read_layout: &wgpu::BindGroupLayout,
        targets: &[Target],
        placeholder: Option<&Target>,
        emission: Option<&Target>,
        depth: &wgpu::Texture,
    ) -> GpuResult<wgpu::BindGroup> {
        let views = targets.iter().chain(placeholder).map(|t| &t.view);
        // The layout's colour bindings, in target order (depth and emission apart).
        let bindings: Vec<u32> = Self::read_layout_entries(layout, false)
            .iter()
            .map(|entry| entry.binding)
            .filter(|&binding| binding != DEPTH_BINDING)
            .collect();
        let depth_view = manylights_gpu::targets::depth_only_view(depth);
        let colour = bindings.iter().copied().zip(views);
        let depth = std::iter::once((DEPTH_BINDING, &depth_view));
        let emission_view = emission.map(|e| (EMISSION_BINDING, &e.view));
        let resources = colour
            .chain(depth)
            .chain(emission_view)
            .map(|(binding, view)| (binding, wgpu::BindingResource::TextureView(view)));
        context.scoped("creating the g-buffer bind group", || {
            manylights_gpu::binding::bind_group(context, "g-buffer read", read_layout, resources)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_program_validates() {
        for result in ShaderLibrary::Embedded.validate_all(&programs()) {
            if let Err(error) = result {
                panic!("{error}");
            }
        }
    }

    #[test]
    fn every_layout_and_path_is_declared() {
        let names: Vec<String> = programs().into_iter().map(|p| p.name).collect();
        for layout in GBufferLayout::ALL {
            if layout == GBufferLayout::Visibility {
                for name in [
                    "visibility_raster_pulled",
                    "visibility_raster_indexed",
                    "visibility_classify",
                    "visibility_resolve (pbr)",
                    "visibility_resolve (blinn-phong)",
                ] {
                    assert!(names.contains(&name.to_string()), "{name}");
                }
            } else {
                for shading in Shading::ALL {
                    let name = format!("gbuffer_{layout} ({shading})");
                    assert!(names.contains(&name), "{name}");
                }
            }
            for path in LightingPath::ALL {
                let prefix = format!("deferred_lighting_{}_{path} (", layout.stored());
                assert!(
                    names.iter().any(|name| name.starts_with(&prefix)),
                    "{prefix}"
                );
            }
        }
    }

    #[test]
    fn documented_bytes_per_pixel() {
        assert_eq!(bytes_per_pixel(GBufferLayout::Full, true), 68);
        assert_eq!(bytes_per_pixel(GBufferLayout::Full, false), 52);
        assert_eq!(bytes_per_pixel(GBufferLayout::Compact, true), 16);
        assert_eq!(bytes_per_pixel(GBufferLayout::Compact, false), 12);
        assert_eq!(bytes_per_pixel(GBufferLayout::Packed, true), 20);
        assert_eq!(bytes_per_pixel(GBufferLayout::Packed, false), 20);
        assert_eq!(bytes_per_pixel(GBufferLayout::Visibility, true), 28);
        assert_eq!(bytes_per_pixel(GBufferLayout::Visibility, false), 28);
    }
}
