//! [`FrameLighting`]: the one binding every lighting pass of a frame reads, at group 3 —
//! the lights, the light lists (or stand-ins where a pipeline shades every light), the far
//! field, the scene's BVH and PBR's specular albedo table. The renderer builds its group
//! once a frame, after the lists are prepared; every pipeline builds its programs on the
//! one layout and binds the one group. Before it, Forward+ and deferred each built the same
//! group from their own copy of the lists' layout and naive a third, with numbers of its
//! own, so a new input of the light loop meant three layouts and three groups to change.
//!
//! The binding numbers are named once, in `lights/lighting_group.wgsl` (mirrored by
//! [`manylights_lights::lighting_group`]), from 0 with no gaps; the modules that declare
//! the bindings (the lists, the loop's parameters, the far field, the BVH, the specular
//! tables) import their numbers from it. A program declares only what it reads; the
//! layout holds them all, so one group serves every program.

use manylights_gpu::binding::{CachedBindGroup, storage_entry, uniform_buffer, uniform_entry};
use manylights_gpu::{GpuContext, wgpu};
use manylights_lights::lighting_group::{self as binding, FAR_FIELD_BINDINGS};
use manylights_lights::{GpuLights, LightKinds, SpecularTables};
use manylights_visibility::GpuSceneBvh;

/// The bind group index every lighting pass binds [`FrameLighting`]'s group at.
pub const LIGHTING_GROUP: u32 = manylights_lights::MANYLIGHTS_GROUP;

/// Mirrors `ClusteredShadingParams` in `shaders/cluster/cluster_lights.wgsl` and
/// `LightingParams` in `shaders/naive/naive.wgsl` (binding `LOOP_PARAMS`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightingUniform {
    /// The light count the heatmap shows as white (1 where the frame shows no heatmap).
    pub heatmap_max: f32,
    /// The lights in the buffer (the naive loop's bound).
    pub light_count: u32,
    pub _pad: [u32; 2],
}

/// A frame's light lists as the lighting passes bind them (the cluster crate's, in
/// binding order; this crate does not depend on clustering).
#[derive(Debug, Clone, Copy)]
pub struct ListBuffers<'a> {
    /// 0: the grid (`ClusterParams`).
    pub grid: &'a wgpu::Buffer,
    /// 1, 2: each cluster's list offsets and the lists' light indices.
    pub offsets: &'a wgpu::Buffer,
    pub indices: &'a wgpu::Buffer,
    /// 5, 6: the lights in view space and the boxes assignment tested them against.
    pub view_lights: &'a wgpu::Buffer,
    pub bounds: &'a wgpu::Buffer,
    /// 7 to 10: the far field's parameters, nodes, lists and order.
    pub far_field: [&'a wgpu::Buffer; 4],
}

/// What a frame's lighting group binds.
#[derive(Debug, Clone, Copy)]
pub struct LightingInputs<'a> {
    /// The lists; `None`: a pipeline that shades every light (stand-ins are bound).
    pub lists: Option<ListBuffers<'a>>,
    /// The lights, animated this frame.
    pub lights: &'a GpuLights,
    /// The scene's BVH (an empty tree when the frame traces no shadows).
    pub bvh: &'a GpuSceneBvh,
    /// PBR's specular albedo and LTC tables.
    pub specular_tables: &'a SpecularTables,
    /// The light count the heatmap shows as white (1 where the frame shows none).
    pub heatmap_max: f32,
}

/// A frame's lighting group, with the facts about what it binds that passes read beside
/// it: the lights' kinds (a loop without spots is specialised) and the BVH (the forward
/// shadow pass binds it in a group of its own).
#[derive(Debug, Clone)]
pub struct BoundLighting<'a> {
    /// The group every lighting pass binds at [`LIGHTING_GROUP`].
    pub group: wgpu::BindGroup,
    /// The same binding without the far field's (on [`FrameLighting::near_field_layout`]):
    /// for a pass that runs a loop without a far field and needs storage bindings of its
    /// own beside it.
    pub near_field_group: wgpu::BindGroup,
    /// The kinds of light bound (loops leave out the code of those absent).
    pub light_kinds: LightKinds,
    /// The BVH the group binds (an empty tree when the frame traces no shadows).
    pub bvh: &'a GpuSceneBvh,
}

/// The frame's lighting binding: its layout, its parameters and the group of the last
/// frame, kept while it binds the same objects.
#[derive(Debug)]
pub struct FrameLighting {
    layout: wgpu::BindGroupLayout,
    /// The layout without the far field's bindings (7 to 10).
    near_field_layout: wgpu::BindGroupLayout,
    near_field_group: CachedBindGroup,
    uniform: wgpu::Buffer,
    /// What a frame without lists binds in their place: nothing reads them there.
    no_lists: (wgpu::Buffer, wgpu::Buffer),
    bind_group: CachedBindGroup,
    last_params: Option<LightingUniform>,
}

impl FrameLighting {
    /// Every stage that runs a light loop: Forward+'s and naive's fragments, deferred's
    /// fragment and compute lighting.
    const STAGES: wgpu::ShaderStages =
        wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

    pub fn new(context: &GpuContext) -> Self {
        let entries = Self::layout_entries();
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            manylights_gpu::binding::bind_group_layout(context, label, entries)
        };
        let near_field: Vec<wgpu::BindGroupLayoutEntry> = entries
            .iter()
            .filter(|entry| !FAR_FIELD_BINDINGS.contains(&entry.binding))
            .copied()
            .collect();
        let near_field_layout = layout("frame lighting layout without the far field", &near_field);
        let layout = layout("frame lighting layout", &entries);
        let uniform = uniform_buffer(
            &context.device,
            "frame lighting params",
            std::mem::size_of::<LightingUniform>(),
        );
        // Large enough for any one element of the lists' arrays and structs.
        let stand_in = |label, usage| {
            context.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 256,
                usage,
                mapped_at_creation: false,
            })
        };
        let no_lists = (
            stand_in("no light lists (uniform)", wgpu::BufferUsages::UNIFORM),
            stand_in("no light lists (storage)", wgpu::BufferUsages::STORAGE),
        );
        Self {
            layout,
            near_field_layout,
            near_field_group: CachedBindGroup::default(),
            uniform,
            no_lists,
            bind_group: CachedBindGroup::default(),
            last_params: None,
        }
    }

    /// Every binding of the layout, in number order ([`manylights_lights::lighting_group`]).
    fn layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        let stages = Self::STAGES;
        let storage = |binding| storage_entry(binding, stages, true);
        let uniform = |binding| uniform_entry(binding, stages);
        let mut entries = vec![
            uniform(binding::GRID),
            storage(binding::LIST_OFFSETS),
            storage(binding::LIST_INDICES),
            storage(binding::LIGHTS),
            uniform(binding::LOOP_PARAMS),
            storage(binding::VIEW_LIGHTS),
            storage(binding::CLUSTER_BOUNDS),
            uniform(binding::FAR_FIELD),
            storage(binding::FAR_NODES),
            storage(binding::FAR_LISTS),
            storage(binding::FAR_ORDER),
        ];
        entries.extend(GpuSceneBvh::layout_entries(stages));
        entries.push(SpecularTables::layout_entry(stages));
        entries
    }

    /// The storage buffers a stage binds through the layout (`near_field`: through
    /// [`Self::near_field_layout`]). WebGPU guarantees 8 a stage; the full layout takes
    /// them all.
    pub fn storage_buffers(near_field: bool) -> u32 {
        let storage = |entry: &&wgpu::BindGroupLayoutEntry| {
            matches!(
                entry.ty,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { .. },
                    ..
                }
            ) && !(near_field && FAR_FIELD_BINDINGS.contains(&entry.binding))
        };
        Self::layout_entries().iter().filter(storage).count() as u32
    }

    /// The layout every lighting program is built on, at [`LIGHTING_GROUP`].
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The layout without the far field's bindings: programs whose loop has no far field
    /// read nothing from them, and a pass that needs storage buffers of its own beside the
    /// loop's (the blended layers' shading) has room for them on it within WebGPU's 8.
    pub fn near_field_layout(&self) -> &wgpu::BindGroupLayout {
        &self.near_field_layout
    }

    /// What a pipeline is built from, its lighting programs on this binding's layouts.
    pub fn pipeline_build<'a>(
        &'a self,
        gpu: &'a GpuContext,
        library: &'a manylights_gpu::ShaderLibrary,
        scene: &'a manylights_gpu::GpuScene,
        view: &'a manylights_gpu::ViewBinding,
        depth: manylights_gpu::DepthConvention,
        shading: manylights_lights::Shading,
    ) -> crate::PipelineBuild<'a> {
        crate::PipelineBuild {
            gpu,
            library,
            scene,
            view,
            depth,
            shading,
            lighting_layout: &self.layout,
            near_field_layout: &self.near_field_layout,
        }
    }

    /// The frame's group of `inputs`, with the parameters written when they change. The
    /// group of the last frame when it binds the same objects.
    pub fn bind<'a>(
        &mut self,
        context: &GpuContext,
        inputs: LightingInputs<'a>,
    ) -> BoundLighting<'a> {
        let LightingInputs {
            lists,
            lights,
            bvh,
            specular_tables,
            heatmap_max,
        } = inputs;
        let params = LightingUniform {
            heatmap_max,
            light_count: lights.count,
            _pad: [0; 2],
        };
        if self.last_params != Some(params) {
            context
                .queue
                .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&params));
            self.last_params = Some(params);
        }
        let (no_uniform, no_storage) = &self.no_lists;
        let lists = lists.unwrap_or(ListBuffers {
            grid: no_uniform,
            offsets: no_storage,
            indices: no_storage,
            view_lights: no_storage,
            bounds: no_storage,
            far_field: [no_uniform, no_storage, no_storage, no_storage],
        });
        let [far_params, far_nodes, far_lists, far_order] = lists.far_field;
        let buffers = [
            (binding::GRID, lists.grid),
            (binding::LIST_OFFSETS, lists.offsets),
            (binding::LIST_INDICES, lists.indices),
            (binding::LIGHTS, &lights.buffer),
            (binding::LOOP_PARAMS, &self.uniform),
            (binding::VIEW_LIGHTS, lists.view_lights),
            (binding::CLUSTER_BOUNDS, lists.bounds),
            (binding::FAR_FIELD, far_params),
            (binding::FAR_NODES, far_nodes),
            (binding::FAR_LISTS, far_lists),
            (binding::FAR_ORDER, far_order),
        ];
        let bindings = || {
            (buffers.iter())
                .map(|(binding, buffer)| (*binding, buffer.as_entire_binding()))
                .chain(bvh.bindings())
                .chain([specular_tables.binding()])
        };
        let group = self
            .bind_group
            .get(context, "frame lighting", &self.layout, bindings());
        let near_field_group = self.near_field_group.get(
            context,
            "frame lighting without the far field",
            &self.near_field_layout,
            bindings().filter(|(binding, _)| !FAR_FIELD_BINDINGS.contains(binding)),
        );
        BoundLighting {
            group,
            near_field_group,
            light_kinds: lights.kinds,
            bvh,
        }
    }
}

#[cfg(test)]
mod tests {
    /// The layout binds every number of the lighting group's table, in order, and nothing
    /// else: a binding added to the table and not to the layout (or the other way) fails
    /// here, before any program is built on it.
    #[test]
    fn the_layout_holds_the_lighting_groups_table_in_order() {
        let bound: Vec<u32> = super::FrameLighting::layout_entries()
            .iter()
            .map(|entry| entry.binding)
            .collect();
        let table: Vec<u32> = manylights_lights::lighting_group::ALL
            .iter()
            .map(|(_, binding)| *binding)
            .collect();
        assert_eq!(bound, table);
    }
}
