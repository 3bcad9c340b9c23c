//! Upload of a [`Scene`] to the GPU: one vertex and one index buffer for all meshes (plus
//! a tangent stream only when the scene has normal maps), per-instance transforms in a
//! storage buffer (group 1), textures with GPU-generated mip chains, and one bind group
//! per material (group 2) whose layout has only the textures the scene uses.

use glam::Mat4;
use manylights_scene::{AlphaMode, Scene, SceneFeatures};
use wgpu::util::DeviceExt as _;

use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::shaders::{MaterialVariant, Program, ShaderLibrary};
use crate::targets::DEPTH_FORMAT;

mod materials;
use materials::{
    SceneTextures, material_bind_group, material_flags, material_layout, material_sampler,
};

/// Interleaved vertex: position, normal, uv (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

impl GpuVertex {
    /// The vertex buffer's attributes (locations 0, 1, 2), their offsets taken from the
    /// struct itself so the buffer's contract cannot drift from it.
    pub fn attributes() -> [wgpu::VertexAttribute; 3] {
        let attribute = |shader_location, format, offset: usize| wgpu::VertexAttribute {
            format,
            offset: offset as u64,
            shader_location,
        };
        [
            attribute(
                0,
                wgpu::VertexFormat::Float32x3,
                std::mem::offset_of!(GpuVertex, position),
            ),
            attribute(
                1,
                wgpu::VertexFormat::Float32x3,
                std::mem::offset_of!(GpuVertex, normal),
            ),
            attribute(
                2,
                wgpu::VertexFormat::Float32x2,
                std::mem::offset_of!(GpuVertex, uv),
            ),
        ]
    }
}

/// Mirrors `InstanceData` in `shaders/common/scene.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuInstance {
    pub model: [[f32; 4]; 4],
    pub normal_matrix: [[f32; 4]; 4],
}

impl GpuInstance {
    pub fn new(model: Mat4) -> Self {
        let normal = Mat4::from_mat3(glam::Mat3::from_mat4(model).inverse().transpose());
        Self {
            model: model.to_cols_array_2d(),
            normal_matrix: normal.to_cols_array_2d(),
        }
    }
}

/// What a pass that fetches its own vertices needs of an instance besides its transform
/// (the visibility buffer uploads these, `InstanceMesh` in its WGSL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InstanceMesh {
    /// Added to the mesh's indices (which count from its first vertex).
    pub base_vertex: i32,
    /// Index into the scene's materials.
    pub material: u32,
    /// The mesh's first index over 3.
    pub first_triangle: u32,
}

/// The scene's geometry as storage buffers, for passes that fetch vertices themselves
/// instead of through the vertex input (the visibility buffer's raster and resolve).
#[derive(Debug, Clone, Copy)]
pub struct SceneStorage<'a> {
    /// [`GpuVertex`] array.
    pub vertices: &'a wgpu::Buffer,
    /// u32 indices, every mesh's in one buffer; a draw's triangle `t` has indices
    /// `3t..3t+3` of it.
    pub indices: &'a wgpu::Buffer,
    /// One vec4 per vertex, only when the scene has normal maps.
    pub tangents: Option<&'a wgpu::Buffer>,
    /// The instances' transforms (`InstanceData` of `shaders/common/scene.wgsl`).
    pub instances: &'a wgpu::Buffer,
}

/// Mirrors `Material` in `shaders/common/material_bindings.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuMaterialUniform {
    pub base_color_factor: [f32; 4],
    pub specular_shininess: [f32; 4],
    pub alpha_cutoff_double_sided: [f32; 4],
    /// Emitted radiance (rgb); w unused.
    pub emissive: [f32; 4],
    /// Metallic (x) and perceptual roughness (y) factors; zw unused.
    pub metallic_roughness: [f32; 4],
}

/// Which pipeline a draw needs: alpha-tested or not, back faces culled or not, blended
/// over what is behind it (glTF's `BLEND`) or not.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct PipelineKey {
    pub alpha_mask: bool,
    pub double_sided: bool,
    /// Drawn after the opaque frame, back to front, blended over it
    /// ([`GpuScene::blended_keys`], [`GpuScene::draw_blended`]); never in an opaque pass.
    pub blend: bool,
}

#[derive(Debug, Clone, Copy)]
struct MeshRange {
    first_index: u32,
    index_count: u32,
    base_vertex: i32,
}

#[derive(Debug)]
struct Draw {
    mesh: usize,
    instance: u32,
    material: usize,
    key: PipelineKey,
    /// The world-space box of the drawn mesh (blended draws are sorted by its centre).
    bounds: manylights_scene::Aabb,
}

/// A scene on the GPU, ready to draw with any pipeline built by
/// [`GpuScene::create_pipeline`].
#[derive(Debug)]
pub struct GpuScene {
    pub features: SceneFeatures,
    pub bounds: manylights_scene::Aabb,
    pub triangle_count: usize,
    /// World transforms of the instances, kept to re-express them relative to an origin.
    world_transforms: Vec<Mat4>,
    /// The origin the instance buffer currently holds transforms relative to.
    origin: glam::DVec3,
    instance_buffer: wgpu::Buffer,
    vertex_buffer: wgpu::Buffer,
    tangent_buffer: Option<wgpu::Buffer>,
    index_buffer: wgpu::Buffer,
    /// Per instance, its mesh's base vertex, material and first triangle.
    instance_meshes: Vec<InstanceMesh>,
    meshes: Vec<MeshRange>,
    /// Group 1: instance transforms.
    pub instance_layout: wgpu::BindGroupLayout,
    instance_bind_group: wgpu::BindGroup,
    /// Group 2: material parameters and textures.
    pub material_layout: wgpu::BindGroupLayout,
    material_bind_groups: Vec<wgpu::BindGroup>,
    /// Kept alive for the bind groups.
    _textures: Vec<wgpu::Texture>,
    /// Sorted by pipeline key, then material, so state changes are few.
    draws: Vec<Draw>,
}

/// Every mesh of a scene in one vertex and one index buffer (and, with normal maps, one
/// tangent stream), with each mesh's range.
struct PackedGeometry {
    vertices: Vec<GpuVertex>,
    tangents: Vec<[f32; 4]>,
    indices: Vec<u32>,
    meshes: Vec<MeshRange>,
}

impl PackedGeometry {
    fn pack(scene: &Scene, features: SceneFeatures) -> Self {
        let mut vertices = Vec::with_capacity(scene.vertex_count());
        let mut tangents = Vec::new();
        let mut indices = Vec::new();
        let mut meshes = Vec::with_capacity(scene.meshes.len());
        for mesh in &scene.meshes {
            meshes.push(MeshRange {
                first_index: indices.len() as u32,
                index_count: mesh.indices.len() as u32,
                base_vertex: vertices.len() as i32,
            });
            for i in 0..mesh.positions.len() {
                vertices.push(GpuVertex {
                    position: mesh.positions[i].to_array(),
                    normal: mesh.normals[i].to_array(),
                    uv: mesh.uvs[i].to_array(),
                });
            }
            if features.normal_maps {
                match &mesh.tangents {
                    Some(t) => tangents.extend(t.iter().map(|t| t.to_array())),
                    // Meshes without a normal map still need a stream of the same length.
                    None => tangents.extend(std::iter::repeat_n(
                        [1.0f32, 0.0, 0.0, 1.0],
                        mesh.positions.len(),
                    )),
                }
            }
            indices.extend_from_slice(&mesh.indices);
        }
        if vertices.is_empty() {
            // wgpu refuses zero-sized vertex buffers; an empty scene draws nothing anyway.
            vertices.push(GpuVertex::zeroed_vertex());
            indices.push(0);
        }
        Self {
            vertices,
            tangents,
            indices,
            meshes,
        }
    }

    /// The buffers on the GPU, with the instances' transforms (an identity where the scene
    /// has no instance: wgpu refuses empty bindings).
    fn upload(
        &self,
        context: &GpuContext,
        scene: &Scene,
        features: SceneFeatures,
    ) -> GpuResult<GeometryBuffers> {
        let vertex_bytes = (self.vertices.len() * std::mem::size_of::<GpuVertex>()) as u64;
        context.check_buffer_size("scene vertex buffer", vertex_bytes, false)?;
        context.check_buffer_size("scene index buffer", self.indices.len() as u64 * 4, false)?;
        let instances: Vec<GpuInstance> = scene
            .instances
            .iter()
            .map(|i| GpuInstance::new(i.transform))
            .collect();
        let instance_data = if instances.is_empty() {
            vec![GpuInstance::new(Mat4::IDENTITY)]
        } else {
            instances
        };
        context.check_buffer_size(
            "instance buffer",
            (instance_data.len() * std::mem::size_of::<GpuInstance>()) as u64,
            true,
        )?;

        let device = &context.device;
        context.scoped("uploading scene geometry", || {
            let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene vertices"),
                contents: bytemuck::cast_slice(&self.vertices),
                // Storage too: the visibility buffer's passes fetch vertices themselves.
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE,
            });
            let tangent_buffer = features.normal_maps.then(|| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("scene tangents"),
                    contents: bytemuck::cast_slice(&self.tangents),
                    usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE,
                })
            });
            let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene indices"),
                contents: bytemuck::cast_slice(&self.indices),
                usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
            });
            let instance_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene instances"),
                contents: bytemuck::cast_slice(&instance_data),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            });
            GeometryBuffers {
                vertex_buffer,
                tangent_buffer,
                index_buffer,
                instance_buffer,
            }
        })
    }
}

/// A scene's geometry on the GPU.
struct GeometryBuffers {
    vertex_buffer: wgpu::Buffer,
    tangent_buffer: Option<wgpu::Buffer>,
    index_buffer: wgpu::Buffer,
    instance_buffer: wgpu::Buffer,
}

/// One draw per instance, sorted by pipeline key, then material, so state changes are few.
fn sorted_draws(scene: &Scene) -> Vec<Draw> {
    let mut draws: Vec<Draw> = scene
        .instances
        .iter()
        .enumerate()
        .map(|(instance, placed)| {
            let material = scene.meshes[placed.mesh].material;
            let (_, double_sided) = material_flags(&scene.materials[material]);
            let alpha_mode = scene.materials[material].alpha_mode;
            Draw {
                mesh: placed.mesh,
                instance: instance as u32,
                material,
                key: PipelineKey {
                    alpha_mask: matches!(alpha_mode, AlphaMode::Mask { .. }),
                    double_sided,
                    blend: alpha_mode == AlphaMode::Blend,
                },
                bounds: scene.meshes[placed.mesh]
                    .bounds
                    .transformed(&placed.transform),
            }
        })
        .collect();
    draws.sort_by_key(|d| (d.key, d.material));
    draws
}

/// Group 1 of every scene pass: the instances' transforms, read by vertex shaders only (the
/// visibility buffer's compute resolve binds the same buffer in a group of its own). A
/// storage buffer visible to compute here would count against every scene pipeline's
/// compute-stage limit beside group 3's lighting binding, which is visible to compute for
/// deferred's lighting: 9 where WebGPU guarantees 8.
fn instance_binding(
    context: &GpuContext,
    instance_buffer: &wgpu::Buffer,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let layout = context
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("instance layout"),
            entries: &[crate::binding::storage_entry(
                0,
                wgpu::ShaderStages::VERTEX,
                true,
            )],
        });
    let group = crate::binding::bind_group(
        context,
        "instance bind group",
        &layout,
        crate::binding::buffers_in_order([instance_buffer]),
    );
    (layout, group)
}

impl GpuScene {
    pub fn upload(context: &GpuContext, scene: &Scene, library: &ShaderLibrary) -> GpuResult<Self> {
        let device = &context.device;
        let features = scene.features();

        let geometry = PackedGeometry::pack(scene, features);
        let GeometryBuffers {
            vertex_buffer,
            tangent_buffer,
            index_buffer,
            instance_buffer,
        } = geometry.upload(context, scene, features)?;
        let meshes = geometry.meshes;

        let (instance_layout, instance_bind_group) = instance_binding(context, &instance_buffer);

        let textures = SceneTextures::upload(context, library, scene)?;
        let sampler = material_sampler(device);

        let material_layout = material_layout(device, features);
        let material_bind_groups = context.scoped("creating material bind groups", || {
            scene
                .materials
                .iter()
                .map(|material| {
                    material_bind_group(
                        context,
                        &material_layout,
                        &textures,
                        &sampler,
                        material,
                        features,
                    )
                })
                .collect::<Vec<_>>()
        })?;

        let draws = sorted_draws(scene);
        let instance_meshes = scene
            .instances
            .iter()
            .map(|placed| InstanceMesh {
                base_vertex: meshes[placed.mesh].base_vertex,
                material: scene.meshes[placed.mesh].material as u32,
                first_triangle: meshes[placed.mesh].first_index / 3,
            })
            .collect();

        Ok(Self {
            features,
            bounds: scene.bounds(),
            triangle_count: scene.triangle_count(),
            world_transforms: scene.instances.iter().map(|i| i.transform).collect(),
            origin: glam::DVec3::ZERO,
            instance_buffer,
            vertex_buffer,
            tangent_buffer,
            index_buffer,
            instance_meshes,
            meshes,
            instance_layout,
            instance_bind_group,
            material_layout,
            material_bind_groups,
            _textures: textures.textures,
            draws,
        })
    }

    /// Re-expresses the instance transforms relative to `origin` (computed in f64), for
    /// camera-relative rendering: far from the world origin, f32 world positions lose
    /// millimetres, positions relative to the camera do not.
    pub fn set_origin(&mut self, context: &GpuContext, origin: glam::DVec3) {
        if origin == self.origin || self.world_transforms.is_empty() {
            return;
        }
        let to_origin = glam::DMat4::from_translation(-origin);
        let instances: Vec<GpuInstance> = self
            .world_transforms
            .iter()
            .map(|model| {
                let relative = (to_origin * model.as_dmat4()).as_mat4();
                GpuInstance {
                    normal_matrix: GpuInstance::new(*model).normal_matrix,
                    model: relative.to_cols_array_2d(),
                }
            })
            .collect();
        context
            .queue
            .write_buffer(&self.instance_buffer, 0, bytemuck::cast_slice(&instances));
        self.origin = origin;
    }

    /// Pipeline keys of this scene's opaque and alpha-tested draws, in draw order: what
    /// the depth, G-buffer and shading passes draw.
    pub fn pipeline_keys(&self) -> Vec<PipelineKey> {
        let mut keys: Vec<PipelineKey> = self.draws.iter().map(|d| d.key).collect();
        keys.dedup();
        keys.retain(|key| !key.blend);
        keys
    }

    /// Pipeline keys of this scene's blended draws (none for most scenes): each pipeline's
    /// forward pass for blended surfaces builds one pipeline per key.
    pub fn blended_keys(&self) -> Vec<PipelineKey> {
        let mut keys: Vec<PipelineKey> = self.draws.iter().map(|d| d.key).collect();
        keys.dedup();
        keys.retain(|key| key.blend);
        keys
    }

    /// The world-space boxes of the blended draws (the cluster boxes must reach them:
    /// a blended surface lies in front of the depth the frame laid down).
    pub fn blended_bounds(&self) -> Vec<manylights_scene::Aabb> {
        self.draws
            .iter()
            .filter(|d| d.key.blend)
            .map(|d| d.bounds)
            .collect()
    }

    /// The blended draws in the order they are drawn, farthest first from `eye` (world
    /// space): sorted by the distance to their box's centre, per object (intersecting
    /// objects and an object's own triangles are not sorted). For [`GpuScene::draw_blended`].
    pub fn blended_back_to_front(&self, eye: glam::DVec3) -> Vec<usize> {
        let mut order: Vec<(f64, usize)> = self
            .draws
            .iter()
            .enumerate()
            .filter(|(_, d)| d.key.blend)
            .map(|(i, d)| {
                let centre = ((d.bounds.min + d.bounds.max) * 0.5).as_dvec3();
                (centre.distance_squared(eye), i)
            })
            .collect();
        // Farthest first; equal distances in draw order.
        order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        order.into_iter().map(|(_, i)| i).collect()
    }

    /// Records the blended draws in `order` ([`GpuScene::blended_back_to_front`]), each
    /// with the pipeline `pipeline_for` gives its key (the caller has set group 0 and any
    /// groups from 3 on); a key without a pipeline is skipped.
    pub fn draw_blended<'p>(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        order: &[usize],
        pipeline_for: impl Fn(PipelineKey) -> Option<&'p wgpu::RenderPipeline>,
    ) {
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        if let Some(tangents) = &self.tangent_buffer {
            pass.set_vertex_buffer(1, tangents.slice(..));
        }
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_bind_group(1, &self.instance_bind_group, &[]);
        for draw in order.iter().filter_map(|&i| self.draws.get(i)) {
            let Some(pipeline) = pipeline_for(draw.key) else {
                continue;
            };
            pass.set_pipeline(pipeline);
            pass.set_bind_group(2, &self.material_bind_groups[draw.material], &[]);
            let mesh = self.meshes[draw.mesh];
            pass.draw_indexed(
                mesh.first_index..mesh.first_index + mesh.index_count,
                mesh.base_vertex,
                draw.instance..draw.instance + 1,
            );
        }
    }

    /// The shader variant for pipelines of `key` in this scene.
    pub fn material_variant(&self, key: PipelineKey) -> MaterialVariant {
        MaterialVariant {
            base_color_texture: self.features.base_color_textures,
            normal_map: self.features.normal_maps,
            alpha_mask: key.alpha_mask,
            emissive: self.features.emissive,
            metallic_roughness_texture: self.features.metallic_roughness_textures,
        }
    }

    /// Builds a pipeline that draws this scene's geometry with `desc.program` for the
    /// draws of `desc.key`. Bind groups: 0 view, 1 instances, 2 material, then
    /// `desc.extra_layouts` from group 3.
    pub fn create_pipeline(
        &self,
        context: &GpuContext,
        library: &ShaderLibrary,
        desc: &ScenePipelineDesc,
    ) -> GpuResult<wgpu::RenderPipeline> {
        let module =
            library.create_module(context, desc.program, self.material_variant(desc.key))?;
        let mut layouts = vec![
            Some(desc.view_layout),
            Some(&self.instance_layout),
            Some(&self.material_layout),
        ];
        layouts.extend(desc.extra_layouts.iter().map(|l| Some(*l)));
        let vertex_attributes = GpuVertex::attributes();
        let tangent_attributes = wgpu::vertex_attr_array![3 => Float32x4];
        let mut buffers = vec![Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<GpuVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &vertex_attributes,
        })];
        if desc.pulls_vertices {
            buffers.clear();
        } else if self.features.normal_maps {
            buffers.push(Some(wgpu::VertexBufferLayout {
                array_stride: 16,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &tangent_attributes,
            }));
        }
        let label = format!("{} {:?}", desc.label, desc.key);
        context.scoped(&format!("creating pipeline {label}"), || {
            let layout = context
                .device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(&label),
                    bind_group_layouts: &layouts,
                    immediate_size: 0,
                });
            context.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(desc.vertex_entry),
                    compilation_options: Default::default(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: if desc.key.double_sided {
                        None
                    } else {
                        Some(wgpu::Face::Back)
                    },
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(desc.depth_write),
                    depth_compare: Some(desc.depth_compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: desc.samples,
                    ..Default::default()
                },
                fragment: desc.fragment_entry.map(|entry| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: desc.color_targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }

    /// The geometry as storage buffers, for passes that fetch vertices themselves.
    pub fn storage(&self) -> SceneStorage<'_> {
        SceneStorage {
            vertices: &self.vertex_buffer,
            indices: &self.index_buffer,
            tangents: self.tangent_buffer.as_ref(),
            instances: &self.instance_buffer,
        }
    }

    /// Per instance, what a pass that fetches its own vertices needs besides the transform.
    pub fn instance_meshes(&self) -> &[InstanceMesh] {
        &self.instance_meshes
    }

    /// How many materials the scene has (bind groups for [`GpuScene::material_bind_group`]).
    pub fn material_count(&self) -> usize {
        self.material_bind_groups.len()
    }

    /// Material `index`'s group 2, for passes that shade one material at a time.
    pub fn material_bind_group(&self, index: usize) -> Option<&wgpu::BindGroup> {
        self.material_bind_groups.get(index)
    }

    /// Records the draws of pipelines with `key` for a pipeline that fetches its vertices
    /// itself ([`ScenePipelineDesc::pulls_vertices`]): non-indexed, so the vertex index is
    /// the position in the scene's index buffer (its triangle is that over 3), and the
    /// instance index is the instance. The caller has set the pipeline, group 0 and any
    /// groups from 3 on.
    pub fn draw_pulled(&self, pass: &mut wgpu::RenderPass<'_>, key: PipelineKey) {
        self.for_each_draw(pass, key, |pass, mesh, instances| {
            pass.draw(
                mesh.first_index..mesh.first_index + mesh.index_count,
                instances,
            );
        });
    }

    /// Records the draws of pipelines with `key` (the caller has set the pipeline and
    /// group 0 and any groups from 3 on).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, key: PipelineKey) {
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        if let Some(tangents) = &self.tangent_buffer {
            pass.set_vertex_buffer(1, tangents.slice(..));
        }
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        self.for_each_draw(pass, key, |pass, mesh, instances| {
            pass.draw_indexed(
                mesh.first_index..mesh.first_index + mesh.index_count,
                mesh.base_vertex,
                instances,
            );
        });
    }

    /// Binds the instances (group 1) and, as it changes, each draw's material (group 2),
    /// and records each draw of `key` with `record` (its mesh and its instance range).
    fn for_each_draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        key: PipelineKey,
        record: impl Fn(&mut wgpu::RenderPass<'_>, MeshRange, std::ops::Range<u32>),
    ) {
        pass.set_bind_group(1, &self.instance_bind_group, &[]);
        let mut bound_material = None;
        for draw in self.draws.iter().filter(|d| d.key == key) {
            if bound_material != Some(draw.material) {
                pass.set_bind_group(2, &self.material_bind_groups[draw.material], &[]);
                bound_material = Some(draw.material);
            }
            record(
                pass,
                self.meshes[draw.mesh],
                draw.instance..draw.instance + 1,
            );
        }
    }
}

/// What differs between the scene pipelines of different passes.
#[derive(Debug)]
pub struct ScenePipelineDesc<'a> {
    pub label: &'a str,
    pub program: &'a Program,
    pub key: PipelineKey,
    pub view_layout: &'a wgpu::BindGroupLayout,
    pub extra_layouts: &'a [&'a wgpu::BindGroupLayout],
    pub vertex_entry: &'a str,
    /// `None` for depth-only passes.
    pub fragment_entry: Option<&'a str>,
    pub color_targets: &'a [Option<wgpu::ColorTargetState>],
    pub depth_write: bool,
    pub depth_compare: wgpu::CompareFunction,
    /// The vertex shader fetches its vertices from [`GpuScene::storage`] (no vertex
    /// buffers); drawn with [`GpuScene::draw_pulled`].
    pub pulls_vertices: bool,
    /// Samples a pixel of the targets drawn (MSAA; 1 without).
    pub samples: u32,
}

impl GpuVertex {
    fn zeroed_vertex() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

#[cfg(test)]
mod layout_tests {
    use super::{GpuInstance, GpuMaterialUniform};
    use crate::assert_wgsl_layout;

    #[test]
    fn instance_and_material_match_wgsl() {
        let program = crate::base_color::program();
        assert_wgsl_layout!(
            program,
            "common/scene.wgsl",
            InstanceData
                == GpuInstance {
                    model: model,
                    normal_matrix: normal_matrix,
                }
        );
        assert_wgsl_layout!(
            program,
            "common/material_bindings.wgsl",
            Material
                == GpuMaterialUniform {
                    base_color_factor: base_color_factor,
                    specular_shininess: specular_shininess,
                    alpha_cutoff_double_sided: alpha_cutoff_double_sided,
                    emissive: emissive,
                    metallic_roughness: metallic_roughness,
                }
        );
    }
}
