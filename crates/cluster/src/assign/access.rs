//! What other passes, the renderer and tests read of [`GpuClusters`]: its capacity, the
//! frame it prepared, its buffers, and the lists and boxes read back.

use manylights_gpu::{GpuContext, GpuError, GpuResult, wgpu};
use manylights_scene::Aabb;

use super::GpuClusters;
use super::design::{ClusterBoxes, ClusterFrame};
use super::gpu_layout::{GpuClusterBounds, GpuViewLight, MaskLayout};
use crate::assign_reference::{LightLists, LightVolume, ViewSphere};
use crate::far_field::GpuFarField;
use crate::grid::ClusterGrid;

impl GpuClusters {
    /// Current capacity of the light index list, in entries (what the next `prepare`
    /// allocates).
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Sets the most the tile masks may take (tests use a tiny budget so that walk groups
    /// share masks); applies from the next `prepare`.
    pub fn set_mask_budget(&mut self, bytes: u64) {
        self.mask_budget = bytes;
        self.buffers = None;
    }

    /// The tile masks' layout of the current buffers (`None` before `prepare`).
    pub fn mask_layout(&self) -> Option<MaskLayout> {
        self.buffers.as_ref().map(|buffers| buffers.masks)
    }

    /// The frame prepared last (`None` before `prepare`).
    pub fn frame(&self) -> Option<&ClusterFrame> {
        self.prepared.as_ref().map(|prepared| &prepared.frame)
    }

    /// The grid of the frame prepared last.
    pub fn grid(&self) -> Option<&ClusterGrid> {
        self.frame().map(|frame| &frame.grid)
    }

    /// The boxes the prepared frame tests: [`ClusterBoxes::VisibleSamples`] only if chosen
    /// and the frame's depth was given.
    pub fn boxes_used(&self) -> ClusterBoxes {
        self.prepared
            .as_ref()
            .map_or(ClusterBoxes::Grid, |prepared| prepared.boxes_used)
    }

    /// The far field: its settings, the shading passes' buffers, its read-backs.
    pub fn far_field(&self) -> &GpuFarField {
        &self.far_field
    }

    /// The parameters uniform (`ClusterParams`), which the shading passes read too.
    pub fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// The boxes the prepared frame tests its lights against (see
    /// [`GpuClusters::boxes_used`]): `ClusterBounds` in `shaders/cluster/bounds.wgsl`.
    pub fn bounds_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        let (prepared, buffers, _) = self.prepared()?;
        Ok(buffers.tested(prepared.boxes_used).0)
    }

    pub fn offsets_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.prepared()?.1.offsets)
    }

    pub fn indices_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.prepared()?.1.indices)
    }

    /// Each light in view space (`ViewLight`: its sphere, then its spot cone), as assignment
    /// tested it.
    pub fn view_lights_buffer(&self) -> GpuResult<&wgpu::Buffer> {
        Ok(&self.prepared()?.1.view_lights)
    }

    /// The boxes the last frame tested, read back ([`Aabb::EMPTY`] for a cluster no visible
    /// sample falls in): the CPU reference's input for that frame.
    pub fn read_bounds(&self, context: &GpuContext) -> GpuResult<Vec<Aabb>> {
        let (_, buffers, _) = self.prepared()?;
        let raw: Vec<GpuClusterBounds> =
            manylights_gpu::targets::read_buffer(context, self.bounds_buffer()?)?;
        Ok(raw
            .iter()
            .take(buffers.clusters as usize)
            .map(GpuClusterBounds::aabb)
            .collect())
    }

    /// Every light's volume as the last assignment tested it (tests: the CPU reference
    /// assigns the same volumes).
    pub fn read_light_volumes(
        &self,
        context: &GpuContext,
        count: u32,
    ) -> GpuResult<Vec<LightVolume>> {
        let (_, buffers, _) = self.prepared()?;
        let lights: Vec<[[f32; 4]; 2]> =
            manylights_gpu::targets::read_buffer(context, &buffers.view_lights)?;
        Ok(lights
            .into_iter()
            .take(count as usize)
            .map(|[sphere, cone]| LightVolume::from_vec4s(sphere, cone))
            .collect())
    }

    /// The lists as built on the GPU (tests, statistics).
    pub fn read_lists(&self, context: &GpuContext) -> GpuResult<LightLists> {
        let (_, buffers, _) = self.prepared()?;
        let offsets = self.read_offsets(context)?;
        let total = *offsets.last().unwrap_or(&0) as usize;
        if total > buffers.capacity as usize {
            return Err(GpuError::Unsupported(format!(
                "the last frame's lists ({total} entries) overflowed the index buffer ({} entries) and were cut short; the buffer grows at the next frame, render again to read them",
                buffers.capacity
            )));
        }
        let mut indices: Vec<u32> =
            manylights_gpu::targets::read_buffer(context, &buffers.indices)?;
        indices.truncate(total);
        Ok(LightLists { offsets, indices })
    }

    /// The per-cluster list offsets only (statistics).
    pub fn read_offsets(&self, context: &GpuContext) -> GpuResult<Vec<u32>> {
        manylights_gpu::block_on(self.read_offsets_async(context))
    }

    /// [`GpuClusters::read_offsets`] without blocking.
    pub async fn read_offsets_async(&self, context: &GpuContext) -> GpuResult<Vec<u32>> {
        let (_, buffers, _) = self.prepared()?;
        let mut offsets: Vec<u32> =
            manylights_gpu::targets::read_buffer_async(context, &buffers.offsets).await?;
        offsets.truncate(buffers.clusters as usize + 1);
        Ok(offsets)
    }

    /// The view-space spheres the GPU assigned (the CPU reference's exact input).
    pub fn read_view_lights(&self, context: &GpuContext, count: u32) -> GpuResult<Vec<ViewSphere>> {
        let (_, buffers, _) = self.prepared()?;
        let raw: Vec<GpuViewLight> =
            manylights_gpu::targets::read_buffer(context, &buffers.view_lights)?;
        Ok(raw
            .iter()
            .take(count as usize)
            .map(|light| ViewSphere::from_vec4(light.sphere))
            .collect())
    }
}
