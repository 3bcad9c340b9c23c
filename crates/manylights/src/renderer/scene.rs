//! What outlives frames: the scene and its BVH, the depth convention the pipelines were
//! built for, the light lists' capacity, and the device (recovered after a loss).

use super::*;

impl Renderer {
    /// After the device was lost: creates a new device (the adapter chosen again,
    /// compatible with `surface` when one is given) and rebuilds every GPU resource on it,
    /// keeping the scene and fixed lights; the next frame renders as the lost one would
    /// have. On error the renderer is unchanged (and still lost).
    pub fn recover_device(
        &mut self,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<(), RenderError> {
        let context = self.context.recreate(surface)?;
        let mut fresh = Renderer::new(context, self.scene.clone())?;
        if let Some((LightSource::Fixed(lights), _)) = &self.lights {
            fresh.set_fixed_lights(lights)?;
        }
        *self = fresh;
        Ok(())
    }

    /// Starts the light index list over at `capacity` entries (tests use a tiny one to
    /// exercise growth).
    pub fn reset_light_list_capacity(&mut self, capacity: u32) -> Result<(), RenderError> {
        self.clusters =
            GpuClusters::with_capacity(&self.context, &self.library, &self.view, capacity)?;
        Ok(())
    }

    /// Shades this frame with the pipelines of `depth` and `shading`: the camera may switch
    /// between standard and reverse-Z (the depth tests and clears differ), the frame
    /// between BRDFs (every program that builds or shades a surface is the BRDF's own).
    /// Each set is built on its first frame and kept for a switch back.
    pub(super) fn use_pipelines_for(&mut self, depth: DepthConvention, shading: Shading) {
        self.same_pipelines_as_last_frame = (depth, shading) == (self.depth, self.shading);
        self.depth = depth;
        self.shading = shading;
    }

    /// Replaces the scene, keeping the device. Everything for the new scene is built
    /// before anything is replaced, so on error the renderer still shows the old one.
    pub fn load_scene(&mut self, scene: LoadedScene) -> Result<(), RenderError> {
        let gpu_scene = GpuScene::upload(&self.context, &scene.scene, &self.library)?;
        let build = self.lighting.pipeline_build(
            &self.context,
            &self.library,
            &gpu_scene,
            &self.view,
            self.depth,
            self.shading,
        );
        // The pipelines of every other depth convention and BRDF were the old scene's.
        let mut pipelines = Specialized::default();
        pipelines.get_or_build((self.depth, self.shading), |_| {
            Pipelines::built_for(&build, &self.last_pipeline)
        })?;
        self.scene = scene;
        self.scene_facts = SceneFacts::of(&gpu_scene);
        self.gpu_scene = gpu_scene;
        self.pipelines = pipelines;
        self.shadow_bvh = None;
        // The light box belongs to the scene: regenerate the lights on the next frame.
        self.lights = None;
        Ok(())
    }

    /// The scene's BVH (what shadow rays are traced through, on the CPU for the f64
    /// reference): built and uploaded on the first call, kept until the scene changes.
    pub fn scene_bvh(&mut self) -> Result<std::sync::Arc<SceneBvh>, RenderError> {
        if let Some((bvh, _)) = &self.shadow_bvh {
            return Ok(bvh.clone());
        }
        let shadow_error = |source| RenderError::Shadows {
            scene: self.scene.name.clone(),
            source,
        };
        let started = web_time::Instant::now();
        let bvh = SceneBvh::build(&self.scene.scene).map_err(shadow_error)?;
        let gpu = self
            .context
            .scoped("uploading the scene's BVH", || {
                GpuSceneBvh::new(&self.context, &bvh)
            })?
            .map_err(shadow_error)?;
        log::info!(
            "scene BVH: {} triangles, {} nodes, depth {}, {:.1} MiB on the GPU, built in {:.0} ms",
            bvh.triangles().len(),
            bvh.nodes().len(),
            bvh.depth(),
            gpu.bytes as f64 / (1024.0 * 1024.0),
            started.elapsed().as_secs_f64() * 1000.0
        );
        let bvh = std::sync::Arc::new(bvh);
        self.shadow_bvh = Some((bvh.clone(), gpu));
        Ok(bvh)
    }
}
