//! The renderer's read-backs, in one place: what tests, the lab and the viewer read from
//! the GPU after a frame (images, HDR radiance, lights, lists, statistics, the far field's
//! cuts). Each waits for the GPU; each has an `_async` twin for the page.

use manylights_cluster::{ClusterBoxes, ClusterStats};
use manylights_gpu::{SurfaceImage, SurfacePass, block_on};
use manylights_lights::{Falloff, GpuReference, GpuReferenceImage, Light};
use manylights_visibility::{
    GpuVisibleReference, GpuVisibleReferenceImage, VisibleReferenceInputs, VisibleReferenceRays,
};

use crate::pipelines::PipelineSettings;
use crate::settings::FrameSettings;

use super::{RenderError, Renderer};

impl Renderer {
    /// Waits for the GPU list statistics of the last frame (rendered with `cluster_stats`).
    pub fn wait_cluster_stats(&mut self) -> Result<Option<ClusterStats>, RenderError> {
        block_on(self.wait_cluster_stats_async())
    }

    /// [`Renderer::wait_cluster_stats`] without blocking.
    pub async fn wait_cluster_stats_async(&mut self) -> Result<Option<ClusterStats>, RenderError> {
        if let Some(stats) = self.list_statistics.wait_async(&self.context).await? {
            self.latest_cluster_stats = Some(stats);
        }
        Ok(self.latest_cluster_stats.clone())
    }

    /// The CPU reference for the GPU list statistics of the last clustered frame: reads
    /// the lists back (and, where the settings ask for false positives, the depth buffer and the
    /// view-space lights). Slow at large light counts: for tests.
    pub fn cpu_cluster_stats(&self, settings: &FrameSettings) -> Result<ClusterStats, RenderError> {
        let offsets = self.clusters.read_offsets(&self.context)?;
        let mut stats = ClusterStats::from_offsets(&offsets);
        let false_positives = settings
            .pipeline
            .clustering()
            .is_some_and(|clustering| clustering.false_positives);
        if false_positives {
            let grid = self.cluster_grid(settings)?;
            let lists = self.clusters.read_lists(&self.context)?;
            let count = self.lights.as_ref().map_or(0, |(_, l)| l.count);
            let spheres = self.clusters.read_view_lights(&self.context, count)?;
            let positions = self.view_positions(settings)?;
            stats.false_positive_ratio = Some(manylights_cluster::false_positive_ratio(
                &grid, &lists, &spheres, &positions,
            ));
        }
        Ok(stats)
    }

    /// View-space position of every pixel of the last frame, reconstructed from its depth
    /// buffer (`None` where nothing was drawn).
    pub fn view_positions(
        &self,
        settings: &FrameSettings,
    ) -> Result<Vec<Option<glam::Vec3>>, RenderError> {
        block_on(self.view_positions_async(settings))
    }

    /// [`Renderer::view_positions`] without blocking.
    pub async fn view_positions_async(
        &self,
        settings: &FrameSettings,
    ) -> Result<Vec<Option<glam::Vec3>>, RenderError> {
        let depth = manylights_gpu::targets::read_f32_rgba_async(
            &self.context,
            &self.targets()?.depth.texture,
        )
        .await?;
        let aspect = settings.view.size.0 as f32 / settings.view.size.1 as f32;
        let inverse = settings.view.camera.projection(aspect).inverse();
        let (w, h) = (settings.view.size.0 as f32, settings.view.size.1 as f32);
        let clear = self.depth.clear_value();
        Ok(depth
            .iter()
            .enumerate()
            .map(|(i, d)| {
                (d[0] != clear).then(|| {
                    let x = (i as u32 % settings.view.size.0) as f32 + 0.5;
                    let y = (i as u32 / settings.view.size.0) as f32 + 0.5;
                    let ndc = glam::Vec4::new(x / w * 2.0 - 1.0, 1.0 - y / h * 2.0, d[0], 1.0);
                    let p = inverse * ndc;
                    p.truncate() / p.w
                })
            })
            .collect())
    }

    /// Pixels of the last frame that show geometry.
    pub fn covered_pixels(&self) -> Result<u64, RenderError> {
        block_on(self.covered_pixels_async())
    }

    /// [`Renderer::covered_pixels`] without blocking.
    pub async fn covered_pixels_async(&self) -> Result<u64, RenderError> {
        let depth = manylights_gpu::targets::read_f32_rgba_async(
            &self.context,
            &self.targets()?.depth.texture,
        )
        .await?;
        let clear = self.depth.clear_value();
        Ok(depth.iter().filter(|d| d[0] != clear).count() as u64)
    }

    /// Light evaluations the last clustered frame made: the sum over visible pixels of
    /// their cluster's list length (the lab's work counter).
    pub fn light_evaluations(&self, settings: &FrameSettings) -> Result<u64, RenderError> {
        block_on(self.light_evaluations_async(settings))
    }

    /// [`Renderer::light_evaluations`] without blocking.
    pub async fn light_evaluations_async(
        &self,
        settings: &FrameSettings,
    ) -> Result<u64, RenderError> {
        let grid = self.cluster_grid(settings)?;
        let offsets = self.clusters.read_offsets_async(&self.context).await?;
        let width = settings.view.size.0 as usize;
        Ok(self
            .view_positions_async(settings)
            .await?
            .iter()
            .enumerate()
            .filter_map(|(i, p)| p.map(|p| (i, p)))
            .map(|(i, p)| {
                let cluster = grid.cluster_of_fragment(
                    (i % width) as f32 + 0.5,
                    (i / width) as f32 + 0.5,
                    -p.z,
                );
                let c = grid.flat_index(cluster) as usize;
                u64::from(offsets[c + 1] - offsets[c])
            })
            .sum())
    }

    /// What the last deferred frame's blended layers counted (fragments stored, any past
    /// the pool, pixels whose farther layers were merged): `None` where no deferred frame
    /// on a compute path had blended surfaces. Waits for the GPU.
    pub fn read_blended_layer_counts(
        &self,
    ) -> Result<Option<manylights_deferred::LayerCounts>, RenderError> {
        block_on(self.read_blended_layer_counts_async())
    }

    /// [`Renderer::read_blended_layer_counts`] without blocking.
    pub async fn read_blended_layer_counts_async(
        &self,
    ) -> Result<Option<manylights_deferred::LayerCounts>, RenderError> {
        if !matches!(self.last_pipeline, PipelineSettings::Deferred(_)) {
            return Ok(None);
        }
        let deferred = self
            .pipelines
            .get(&(self.depth, self.shading))
            .and_then(|pipelines| pipelines.deferred());
        match deferred {
            Some(deferred) => Ok(deferred.read_layer_counts_async(&self.context).await?),
            None => Ok(None),
        }
    }

    /// The GPU light lists of the last clustered frame (tests, the lab).
    pub fn read_light_lists(&self) -> Result<manylights_cluster::LightLists, RenderError> {
        Ok(self.clusters.read_lists(&self.context)?)
    }

    /// Each cluster's far-field cut as the last frame with the tree chose it: entries
    /// (node index, exact flag in the top bit) per cluster (tests, the lab).
    pub fn read_far_field_cuts(&self) -> Result<Vec<Vec<u32>>, RenderError> {
        Ok(self.clusters.far_field().read_cuts(&self.context)?)
    }

    /// The light tree's sorted lights as the last frame with the tree sorted them: (leaf
    /// key, light index) in the tree's order (tests).
    pub fn read_far_field_order(&self) -> Result<Vec<(u32, u32)>, RenderError> {
        Ok(self.clusters.far_field().read_order(&self.context)?)
    }

    /// The view-space spheres the last clustered frame assigned.
    pub fn read_view_lights(&self) -> Result<Vec<manylights_cluster::ViewSphere>, RenderError> {
        let count = self.lights.as_ref().map_or(0, |(_, l)| l.count);
        Ok(self.clusters.read_view_lights(&self.context, count)?)
    }

    /// Every light's volume as the last clustered frame's assignment tested it (spots
    /// with their view-space cones): the CPU reference's input with spots.
    pub fn read_light_volumes(&self) -> Result<Vec<manylights_cluster::LightVolume>, RenderError> {
        let count = self.lights.as_ref().map_or(0, |(_, l)| l.count);
        Ok(self.clusters.read_light_volumes(&self.context, count)?)
    }

    /// The boxes the last clustered frame tested its lights against (the visible samples'
    /// or the grid's; empty where no sample falls): the CPU reference's input for it.
    pub fn read_cluster_bounds(&self) -> Result<Vec<manylights_scene::Aabb>, RenderError> {
        Ok(self.clusters.read_bounds(&self.context)?)
    }

    /// Which boxes the last clustered frame tested (visible ones need the pipeline's early
    /// depth).
    pub fn cluster_boxes_used(&self) -> ClusterBoxes {
        self.clusters.boxes_used()
    }

    /// The view of the tonemapped output of the last frame (for presenting it).
    pub fn output_view(&self) -> Option<&manylights_gpu::wgpu::TextureView> {
        self.targets.as_ref().map(|t| &t.output.view)
    }

    /// The tonemapped output of the last frame.
    pub fn read_output(&self) -> Result<image::RgbaImage, RenderError> {
        block_on(self.read_output_async())
    }

    /// [`Renderer::read_output`] without blocking.
    pub async fn read_output_async(&self) -> Result<image::RgbaImage, RenderError> {
        Ok(manylights_gpu::targets::read_rgba8_async(
            &self.context,
            &self.targets()?.output.texture,
        )
        .await?)
    }

    /// The linear HDR radiance of the last frame, row-major.
    pub fn read_hdr(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        block_on(self.read_hdr_async())
    }

    /// [`Renderer::read_hdr`] without blocking (the page's lab awaits it).
    pub async fn read_hdr_async(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        Ok(manylights_gpu::targets::read_f32_rgba_async(
            &self.context,
            &self.targets()?.hdr.texture,
        )
        .await?)
    }

    /// The exposure the last frame was tonemapped with, and (automatic exposure) the
    /// median luminance of its lit pixels. Waits for the GPU.
    pub fn read_exposure(&self) -> Result<manylights_gpu::ExposureStateGpu, RenderError> {
        Ok(self.post.tonemap().read_state(&self.context)?)
    }

    /// The lights as the GPU has them this frame (after animation).
    pub fn read_lights(&self) -> Result<Vec<Light>, RenderError> {
        block_on(self.read_lights_async())
    }

    /// [`Renderer::read_lights`] without blocking.
    pub async fn read_lights_async(&self) -> Result<Vec<Light>, RenderError> {
        let (_, lights) = self
            .lights
            .as_ref()
            .ok_or_else(|| RenderError::Settings("no lights yet".into()))?;
        Ok(lights.read_async(&self.context).await?)
    }

    /// Full-precision surface attributes for the camera of `settings` (for the f64
    /// reference).
    pub fn capture_surface(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<SurfaceImage, RenderError> {
        block_on(self.capture_surface_async(settings))
    }

    /// [`Renderer::capture_surface`] without blocking.
    pub async fn capture_surface_async(
        &mut self,
        settings: &FrameSettings,
    ) -> Result<SurfaceImage, RenderError> {
        let plan = self.plan(settings)?;
        self.update_view(&plan.view);
        let pass = SurfacePass::new(
            &self.context,
            &self.library,
            &self.gpu_scene,
            &self.view,
            settings.view.camera.depth_convention(),
            settings.shading,
        )?;
        let origin = plan.view.origin.as_dvec3();
        Ok(pass
            .capture_async(
                &self.context,
                &self.gpu_scene,
                &self.view,
                settings.view.size,
                origin,
            )
            .await?)
    }

    /// The full-frame reference on the GPU ([`GpuReference`]): every light as the GPU has
    /// them now (render the frame first, so they are animated to its time) at every pixel
    /// of `surface` (from [`Renderer::capture_surface`]), seen from `camera`, with
    /// `falloff`. Seconds at a million lights on a fast GPU; waits for it.
    pub async fn gpu_reference_async(
        &self,
        surface: &SurfaceImage,
        camera: glam::DVec3,
        falloff: Falloff,
    ) -> Result<GpuReferenceImage, RenderError> {
        let (_, lights) = self
            .lights
            .as_ref()
            .ok_or_else(|| RenderError::Settings("no lights yet: render a frame first".into()))?;
        let pass = GpuReference::new(&self.context, &self.library, surface.shading)?;
        Ok(pass
            .render_async(
                &self.context,
                surface,
                camera,
                lights,
                &self.specular_albedo,
                falloff,
            )
            .await?)
    }

    /// The full-frame reference with visibility on the GPU
    /// ([`GpuVisibleReference`]): as [`Renderer::gpu_reference_async`], each light counted
    /// where the f64 reference's shadow ray reaches it through the scene's BVH. With at
    /// most `rays.per_pixel` lights every ray is traced; beyond, the unshadowed reference
    /// runs first and weighs an estimate of about `rays.per_pixel` rays a pixel, with each
    /// pixel's standard error.
    pub async fn gpu_visible_reference_async(
        &mut self,
        surface: &SurfaceImage,
        camera: glam::DVec3,
        falloff: Falloff,
        rays: VisibleReferenceRays,
    ) -> Result<GpuVisibleReferenceImage, RenderError> {
        self.scene_bvh()?;
        let count = self.lights.as_ref().map_or(0, |(_, lights)| lights.count);
        let unshadowed = match rays.exact_for(count) {
            true => None,
            false => Some(self.gpu_reference_async(surface, camera, falloff).await?),
        };
        let (Some((_, lights)), Some((_, bvh))) = (&self.lights, &self.shadow_bvh) else {
            return Err(RenderError::Settings(
                "no lights yet: render a frame first".into(),
            ));
        };
        let pass = GpuVisibleReference::new(&self.context, &self.library, surface.shading)?;
        let inputs = VisibleReferenceInputs {
            surface,
            camera,
            lights,
            table: &self.specular_albedo,
            bvh,
            falloff,
            unshadowed: unshadowed.as_ref(),
        };
        Ok(pass.render_async(&self.context, &inputs, rays).await?)
    }

    /// [`Renderer::gpu_visible_reference_async`], blocking.
    pub fn gpu_visible_reference(
        &mut self,
        surface: &SurfaceImage,
        camera: glam::DVec3,
        falloff: Falloff,
        rays: VisibleReferenceRays,
    ) -> Result<GpuVisibleReferenceImage, RenderError> {
        block_on(self.gpu_visible_reference_async(surface, camera, falloff, rays))
    }

    /// [`Renderer::gpu_reference_async`], blocking.
    pub fn gpu_reference(
        &self,
        surface: &SurfaceImage,
        camera: glam::DVec3,
        falloff: Falloff,
    ) -> Result<GpuReferenceImage, RenderError> {
        block_on(self.gpu_reference_async(surface, camera, falloff))
    }
}
