//! The visibility buffer ([`GBufferLayout::Visibility`](crate::GBufferLayout)): the raster
//! writes only depth and, per pixel, the instance and triangle seen there; compute passes
//! then rebuild each pixel's surface and write the `packed` G-buffer that lighting reads.
//!
//! Why: on GPUs with few graphics units (the H200 has them on a fraction of its SMs), the
//! G-buffer pass's fragment work (every material texture sampled, 16 bytes written per
//! fragment, overdraw included) runs on those few units; here it runs once per pixel in
//! compute, on all of them.
//!
//! Passes, in order (`shaders/deferred/visibility*.wgsl`):
//! 1. raster ([`VISIBILITY_PASS`]): an indexed draw whose fragments read their triangle
//!    from the primitive index where the device has that optional feature; otherwise (WebGPU
//!    core) a non-indexed draw that fetches its vertices from storage, the triangle being
//!    the vertex index over 3; alpha-masked materials discard as in the G-buffer pass;
//! 2. classification ([`CLASSIFY_PASS`]): the 8x8 tiles each material covers, as one list
//!    per material with its indirect dispatch's arguments;
//! 3. resolve ([`RESOLVE_PASS`]): one indirect dispatch per material, with its bind group
//!    (WebGPU has no bindless textures), rebuilding the surface from the triangle
//!    (perspective-correct barycentrics, UV gradients across the pixel's 2x2 quad as a
//!    fragment's implicit derivatives take them, for the mip level) and writing the
//!    `packed` layout.

use manylights_gpu::{
    DepthConvention, GpuContext, GpuError, GpuResult, GpuScene, MaterialVariant, PassName,
    PipelineKey, Program, ScenePipelineDesc, ShaderDef, ShaderLibrary, Target, ViewBinding,
    timed_compute_pass, wgpu,
};

use crate::SHADERS;
use manylights_gpu::binding::storage_texture_entry;
use manylights_lights::Shading;

/// The raster's timed name.
pub const VISIBILITY_PASS: PassName = PassName::new("visibility");
/// The classification's timed name.
pub const CLASSIFY_PASS: PassName = PassName::new("visibility classify");
/// The resolve's timed name.
pub const RESOLVE_PASS: PassName = PassName::new("material resolve");

/// Instance and triangle per pixel.
pub(crate) const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
/// What the raster clears to: no instance (`NO_SURFACE` in the shaders).
const NO_SURFACE: f64 = u32::MAX as f64;
/// The tiles of classification and resolve (the shaders' workgroup size).
const TILE: u32 = manylights_gpu::SCREEN_TILE;
/// `MaterialTiles` in `visibility_classify.wgsl`: the indirect dispatch's three words
/// first.
const MATERIAL_TILES_STRIDE: u64 = 32;
/// `ResolveMaterial`'s stride in its uniform buffer: a dynamic offset per material.
const RESOLVE_MATERIAL_STRIDE: u64 = 256;
/// At most this many materials can share a tile (one per pixel).
const PIXELS_PER_TILE: u64 = (TILE * TILE) as u64;

/// The raster (composed per material variant: alpha-masked draws discard), drawn indexed
/// with the primitive index where the device has that feature, else fetching its vertices.
pub fn raster_program(primitive_index: bool) -> Program {
    let program = Program::shading_materials(
        if primitive_index {
            "visibility_raster_indexed"
        } else {
            "visibility_raster_pulled"
        },
        &SHADERS,
        "deferred/visibility.wgsl",
    );
    if primitive_index {
        program.with_def("PRIMITIVE_INDEX", ShaderDef::Bool(true))
    } else {
        program
    }
}

/// The classification's four entry points.
pub fn classify_program() -> Program {
    Program::shading_materials(
        "visibility_classify",
        &SHADERS,
        "deferred/visibility_classify.wgsl",
    )
}

/// The resolve: the material variant's sampling with explicit UV gradients, building
/// surfaces for `shading`.
pub fn resolve_program(shading: Shading) -> Program {
    Program::shading_materials(
        format!("visibility_resolve ({shading})"),
        &SHADERS,
        "deferred/visibility_resolve.wgsl",
    )
    .with_def("EXPLICIT_UV_GRADIENTS", ShaderDef::Bool(true))
    .with_shading(shading)
}

/// Stages that read the scene's geometry from storage.
const GEOMETRY_STAGES: wgpu::ShaderStages = wgpu::ShaderStages::VERTEX
    .union(wgpu::ShaderStages::FRAGMENT)
    .union(wgpu::ShaderStages::COMPUTE);

/// The visibility target's entry (`texture_2d<u32>`).
fn visibility_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// Mirrors `InstanceMesh` in `shaders/deferred/visibility_geometry.wgsl`
/// ([`manylights_gpu::InstanceMesh`] on the GPU).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuInstanceMesh {
    base_vertex: i32,
    material: u32,
    first_triangle: u32,
}

/// The scene's instance meshes in a storage buffer (one zeroed entry for a scene without
/// instances: wgpu refuses empty bindings).
fn instance_meshes_buffer(context: &GpuContext, scene: &GpuScene) -> GpuResult<wgpu::Buffer> {
    let mut records: Vec<GpuInstanceMesh> = scene
        .instance_meshes()
        .iter()
        .map(|mesh| GpuInstanceMesh {
            base_vertex: mesh.base_vertex,
            material: mesh.material,
            first_triangle: mesh.first_triangle,
        })
        .collect();
    if records.is_empty() {
        records.push(bytemuck::Zeroable::zeroed());
    }
    let bytes = std::mem::size_of_val(records.as_slice()) as u64;
    context.check_buffer_size("the visibility buffer's instance meshes", bytes, true)?;
    Ok(wgpu::util::DeviceExt::create_buffer_init(
        &context.device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("visibility instance meshes"),
            contents: bytemuck::cast_slice(&records),
            usage: wgpu::BufferUsages::STORAGE,
        },
    ))
}

/// A bind group entry viewing `target`.
fn texture(binding: u32, target: &Target) -> (u32, wgpu::BindingResource<'_>) {
    (binding, wgpu::BindingResource::TextureView(&target.view))
}

/// The visibility buffer's pipelines for one scene.
#[derive(Debug)]
pub(crate) struct VisibilityPipelines {
    /// Group 3 of every pass: the scene's vertices, indices, instance meshes (tangents).
    geometry_group: wgpu::BindGroup,
    _instance_meshes: wgpu::Buffer,
    pub(crate) raster: Vec<(PipelineKey, wgpu::RenderPipeline)>,
    /// The raster draws indexed and reads the primitive index (else it pulls vertices).
    primitive_index: bool,
    classify_layout: wgpu::BindGroupLayout,
    reset: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    offsets: wgpu::ComputePipeline,
    fill: wgpu::ComputePipeline,
    resolve_layout: wgpu::BindGroupLayout,
    resolve: wgpu::ComputePipeline,
    /// Material `m`'s index at offset `m * RESOLVE_MATERIAL_STRIDE`.
    resolve_materials: wgpu::Buffer,
    material_count: u32,
    emissive: bool,
}

impl VisibilityPipelines {
    pub(crate) fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        scene: &GpuScene,
        view: &ViewBinding,
        depth: DepthConvention,
        shading: Shading,
    ) -> GpuResult<Self> {
        check_geometry_fits(context, scene)?;
        let (geometry_layout, geometry_group, instance_meshes) = geometry_binding(context, scene)?;
        let primitive_index = context
            .device
            .features()
            .contains(wgpu::Features::PRIMITIVE_INDEX);
        let raster = raster_pipelines(
            context,
            library,
            scene,
            view,
            depth,
            &geometry_layout,
            primitive_index,
        )?;
        // Classification and resolve see the scene's material variant without the alpha
        // mask (the raster applied it).
        let variant = scene.material_variant(PipelineKey::default());
        let (classify_layout, [reset, count, offsets, fill]) =
            classify_passes(context, library, variant, &geometry_layout)?;
        let emissive = scene.features.emissive;
        let (resolve_layout, resolve) = resolve_pass(
            context,
            library,
            scene,
            view,
            variant,
            shading,
            &geometry_layout,
        )?;
        let (resolve_materials, material_count) = resolve_materials(context, scene)?;
        Ok(Self {
            geometry_group,
            _instance_meshes: instance_meshes,
            raster,
            primitive_index,
            classify_layout,
            reset,
            count,
            offsets,
            fill,
            resolve_layout,
            resolve,
            resolve_materials,
            material_count,
            emissive,
        })
    }

    /// The per-size resources writing `packed` (and `emission`), the G-buffer lighting reads.
    pub(crate) fn frame(
        &self,
        context: &GpuContext,
        scene: &GpuScene,
        size: (u32, u32),
        packed: &Target,
        emission: Option<&Target>,
    ) -> GpuResult<VisibilityFrame> {
        let device = &context.device;
        let visibility = Target::new(
            context,
            "visibility",
            size,
            VISIBILITY_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        )?;
        let tiles = (size.0.div_ceil(TILE), size.1.div_ceil(TILE));
        let tile_count = u64::from(tiles.0) * u64::from(tiles.1);
        let materials = u64::from(self.material_count.max(1));
        // Each material can appear in every tile, each tile holds at most one material per
        // pixel: the list never needs more than the smaller of the two.
        let list_bytes = tile_count * materials.min(PIXELS_PER_TILE) * 4;
        context.check_buffer_size("the visibility buffer's tile lists", list_bytes, true)?;
        let tile_list = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("visibility tile lists"),
            size: list_bytes.max(4),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let material_tiles = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("visibility material tiles"),
            size: materials * MATERIAL_TILES_STRIDE,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            mapped_at_creation: false,
        });
        let (classify_group, resolve_group) = self.frame_groups(
            context,
            scene,
            [&visibility, packed],
            emission,
            &material_tiles,
            &tile_list,
        )?;
        Ok(VisibilityFrame {
            visibility,
            tiles,
            material_tiles,
            _tile_list: tile_list,
            classify_group,
            resolve_group,
        })
    }

    /// Classification's group (the visibility target, each material's tiles, the tile
    /// list) and the resolve's (the same with the instances, the packed target it writes,
    /// the emission target, and each material's index at its dynamic offset).
    fn frame_groups(
        &self,
        context: &GpuContext,
        scene: &GpuScene,
        [visibility, packed]: [&Target; 2],
        emission: Option<&Target>,
        material_tiles: &wgpu::Buffer,
        tile_list: &wgpu::Buffer,
    ) -> GpuResult<(wgpu::BindGroup, wgpu::BindGroup)> {
        let classify_resources = [
            texture(0, visibility),
            (1, material_tiles.as_entire_binding()),
            (2, tile_list.as_entire_binding()),
        ];
        let mut resolve_resources = vec![
            (0, scene.storage().instances.as_entire_binding()),
            texture(1, visibility),
            (2, material_tiles.as_entire_binding()),
            (3, tile_list.as_entire_binding()),
            texture(4, packed),
            (
                6,
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.resolve_materials,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
            ),
        ];
        if self.emissive {
            let emission = emission.ok_or_else(|| {
                GpuError::Unsupported("the visibility buffer's emission target is missing".into())
            })?;
            resolve_resources.push(texture(5, emission));
        }
        let (classify_group, resolve_group) =
            context.scoped("creating the visibility buffer's bind groups", || {
                (
                    manylights_gpu::binding::bind_group(
                        context,
                        "visibility classify",
                        &self.classify_layout,
                        classify_resources,
                    ),
                    manylights_gpu::binding::bind_group(
                        context,
                        "material resolve",
                        &self.resolve_layout,
                        resolve_resources,
                    ),
                )
            })?;
        Ok((classify_group, resolve_group))
    }

    /// The raster's colour attachment for `frame`, cleared to no surface.
    pub(crate) fn attachment(
        frame: &VisibilityFrame,
    ) -> Option<wgpu::RenderPassColorAttachment<'_>> {
        manylights_gpu::binding::cleared_color(
            &frame.visibility.view,
            wgpu::Color {
                r: NO_SURFACE,
                g: NO_SURFACE,
                b: 0.0,
                a: 0.0,
            },
        )
    }

    /// Records the raster's draws into `pass` (whose attachments are [`Self::attachment`]
    /// and the depth buffer; group 0 is set).
    pub(crate) fn draw(&self, pass: &mut wgpu::RenderPass<'_>, scene: &GpuScene) {
        pass.set_bind_group(3, &self.geometry_group, &[]);
        for (key, pipeline) in &self.raster {
            pass.set_pipeline(pipeline);
            if self.primitive_index {
                scene.draw(pass, *key);
            } else {
                scene.draw_pulled(pass, *key);
            }
        }
    }

    /// Records classification and resolve after the raster.
    pub(crate) fn record_resolve(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mut timer: Option<&mut manylights_gpu::GpuTimer>,
        scene: &GpuScene,
        view: &ViewBinding,
        frame: &VisibilityFrame,
    ) {
        {
            let mut pass = timed_compute_pass(encoder, timer.as_deref_mut(), CLASSIFY_PASS);
            pass.set_bind_group(0, &frame.classify_group, &[]);
            pass.set_bind_group(3, &self.geometry_group, &[]);
            pass.set_pipeline(&self.reset);
            pass.dispatch_workgroups(self.material_count.max(1).div_ceil(64), 1, 1);
            pass.set_pipeline(&self.count);
            pass.dispatch_workgroups(frame.tiles.0, frame.tiles.1, 1);
            pass.set_pipeline(&self.offsets);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&self.fill);
            pass.dispatch_workgroups(frame.tiles.0, frame.tiles.1, 1);
        }
        let mut pass = timed_compute_pass(encoder, timer, RESOLVE_PASS);
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &view.bind_group, &[]);
        pass.set_bind_group(3, &self.geometry_group, &[]);
        // Every material has its bind group (checked when the pipelines were built).
        for material in 0..self.material_count {
            let Some(group) = scene.material_bind_group(material as usize) else {
                continue;
            };
            let offset = u64::from(material) * RESOLVE_MATERIAL_STRIDE;
            pass.set_bind_group(1, &frame.resolve_group, &[offset as u32]);
            pass.set_bind_group(2, group, &[]);
            pass.dispatch_workgroups_indirect(
                &frame.material_tiles,
                u64::from(material) * MATERIAL_TILES_STRIDE,
            );
        }
    }
}

/// The raster and resolve read the scene's vertices and indices as one storage binding
/// each: a scene too large for one is refused with the limit's name.
fn check_geometry_fits(context: &GpuContext, scene: &GpuScene) -> GpuResult<()> {
    let storage = scene.storage();
    let limit = context.device.limits().max_storage_buffer_binding_size;
    for (what, buffer) in [
        ("the scene's vertices", storage.vertices),
        ("the scene's indices", storage.indices),
    ] {
        if buffer.size() > limit {
            return Err(GpuError::LimitExceeded {
                what: format!("{what} as one storage binding (visibility buffer)"),
                needed: buffer.size(),
                limit: "max_storage_buffer_binding_size",
                allowed: limit,
            });
        }
    }
    Ok(())
}

/// Group 3 of every visibility pass: the scene's vertices, indices, each instance's mesh
/// (and tangents, where the scene has them).
fn geometry_binding(
    context: &GpuContext,
    scene: &GpuScene,
) -> GpuResult<(wgpu::BindGroupLayout, wgpu::BindGroup, wgpu::Buffer)> {
    let storage = scene.storage();
    let mut geometry_entries = vec![
        manylights_gpu::binding::storage_entry(0, GEOMETRY_STAGES, true),
        manylights_gpu::binding::storage_entry(1, GEOMETRY_STAGES, true),
        manylights_gpu::binding::storage_entry(2, GEOMETRY_STAGES, true),
    ];
    let instance_meshes = instance_meshes_buffer(context, scene)?;
    let mut geometry_buffers = vec![storage.vertices, storage.indices, &instance_meshes];
    if let Some(tangents) = storage.tangents {
        geometry_entries.push(manylights_gpu::binding::storage_entry(
            3,
            GEOMETRY_STAGES,
            true,
        ));
        geometry_buffers.push(tangents);
    }
    let layout = context
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("visibility geometry layout"),
            entries: &geometry_entries,
        });
    let group = manylights_gpu::binding::bind_group(
        context,
        "visibility geometry",
        &layout,
        manylights_gpu::binding::buffers_in_order(geometry_buffers),
    );
    Ok((layout, group, instance_meshes))
}

/// The raster's pipelines, one per material key of the scene (fetching its vertices
/// itself where the device has no primitive index).
fn raster_pipelines(
    context: &GpuContext,
    library: &ShaderLibrary,
    scene: &GpuScene,
    view: &ViewBinding,
    depth: DepthConvention,
    geometry_layout: &wgpu::BindGroupLayout,
    primitive_index: bool,
) -> GpuResult<Vec<(PipelineKey, wgpu::RenderPipeline)>> {
    let raster_program = raster_program(primitive_index);
    let targets = [Some(VISIBILITY_FORMAT.into())];
    scene
        .pipeline_keys()
        .into_iter()
        .map(|key| {
            let desc = ScenePipelineDesc {
                label: "visibility raster",
                program: &raster_program,
                key,
                view_layout: &view.layout,
                extra_layouts: &[geometry_layout],
                vertex_entry: "vs_visibility",
                fragment_entry: Some("fs_visibility"),
                color_targets: &targets,
                depth_write: true,
                depth_compare: depth.nearer(),
                pulls_vertices: !primitive_index,
                samples: 1,
            };
            Ok((key, scene.create_pipeline(context, library, &desc)?))
        })
        .collect()
}

/// Classification's layout (group 0) and its four passes: reset, count, offsets, fill.
fn classify_passes(
    context: &GpuContext,
    library: &ShaderLibrary,
    variant: MaterialVariant,
    geometry_layout: &wgpu::BindGroupLayout,
) -> GpuResult<(wgpu::BindGroupLayout, [wgpu::ComputePipeline; 4])> {
    let compute = wgpu::ShaderStages::COMPUTE;
    let device = &context.device;
    let classify_entries = [
        visibility_entry(0),
        manylights_gpu::binding::storage_entry(1, compute, false),
        manylights_gpu::binding::storage_entry(2, compute, false),
    ];
    let classify_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("visibility classify layout"),
        entries: &classify_entries,
    });
    let module = library.create_module(context, &classify_program(), variant)?;
    let passes = context.scoped("creating the classification", || {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("visibility classify"),
            bind_group_layouts: &[Some(&classify_layout), None, None, Some(geometry_layout)],
            immediate_size: 0,
        });
        ["cs_reset", "cs_count", "cs_offsets", "cs_fill"].map(|entry| {
            context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        })
    })?;
    Ok((classify_layout, passes))
}

/// The material resolve's layout (group 1, with the material index at a dynamic offset)
/// and its pass, which rebuilds the packed G-buffer (and emission) a material at a time.
fn resolve_pass(
    context: &GpuContext,
    library: &ShaderLibrary,
    scene: &GpuScene,
    view: &ViewBinding,
    variant: MaterialVariant,
    shading: Shading,
    geometry_layout: &wgpu::BindGroupLayout,
) -> GpuResult<(wgpu::BindGroupLayout, wgpu::ComputePipeline)> {
    let compute = wgpu::ShaderStages::COMPUTE;
    let device = &context.device;
    let mut resolve_entries = vec![
        manylights_gpu::binding::storage_entry(0, compute, true),
        visibility_entry(1),
        manylights_gpu::binding::storage_entry(2, compute, true),
        manylights_gpu::binding::storage_entry(3, compute, true),
        storage_texture_entry(4, wgpu::TextureFormat::Rgba32Uint),
        wgpu::BindGroupLayoutEntry {
            binding: 6,
            visibility: compute,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: None,
            },
            count: None,
        },
    ];
    if scene.features.emissive {
        resolve_entries.push(storage_texture_entry(5, crate::EMISSION_FORMAT));
    }
    let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("visibility resolve layout"),
        entries: &resolve_entries,
    });
    let module = library.create_module(context, &resolve_program(shading), variant)?;
    let resolve = context.scoped("creating the material resolve", || {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("material resolve"),
            bind_group_layouts: &[
                Some(&view.layout),
                Some(&resolve_layout),
                Some(&scene.material_layout),
                Some(geometry_layout),
            ],
            immediate_size: 0,
        });
        context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("material resolve"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("cs_resolve"),
            compilation_options: Default::default(),
            cache: None,
        })
    })?;
    Ok((resolve_layout, resolve))
}

/// Each material's index at its dynamic offset in one uniform buffer, and the count. The
/// resolve binds each material's group while recording, where nothing may fail: a material
/// without one is refused here.
fn resolve_materials(context: &GpuContext, scene: &GpuScene) -> GpuResult<(wgpu::Buffer, u32)> {
    let material_count = scene.material_count() as u32;
    if let Some(missing) =
        (0..material_count).find(|&m| scene.material_bind_group(m as usize).is_none())
    {
        return Err(GpuError::Unsupported(format!(
            "material {missing} has no bind group"
        )));
    }
    let mut material_words =
        vec![0u8; (material_count.max(1) as u64 * RESOLVE_MATERIAL_STRIDE) as usize];
    for material in 0..material_count {
        let offset = (u64::from(material) * RESOLVE_MATERIAL_STRIDE) as usize;
        material_words[offset..offset + 4].copy_from_slice(&material.to_le_bytes());
    }
    let buffer = wgpu::util::DeviceExt::create_buffer_init(
        &context.device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("resolve materials"),
            contents: &material_words,
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    Ok((buffer, material_count))
}

/// The visibility buffer's resources of one size.
#[derive(Debug)]
pub(crate) struct VisibilityFrame {
    visibility: Target,
    /// Tiles across and down.
    tiles: (u32, u32),
    material_tiles: wgpu::Buffer,
    _tile_list: wgpu::Buffer,
    classify_group: wgpu::BindGroup,
    resolve_group: wgpu::BindGroup,
}

#[cfg(test)]
mod layout_tests {
    use super::{GpuInstanceMesh, classify_program};
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn instance_mesh_matches_wgsl() {
        assert_wgsl_layout!(
            classify_program(),
            "deferred/visibility_geometry.wgsl",
            InstanceMesh
                == GpuInstanceMesh {
                    base_vertex: base_vertex,
                    material: material,
                    first_triangle: first_triangle,
                }
        );
    }
}
