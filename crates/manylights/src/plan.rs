//! [`FramePlan`]: what a frame does, decided once from its [`FrameSettings`], the scene's
//! facts and the device's limits, or the reason it cannot be rendered. Every rule that ties
//! one dial to another lives here, so a new dial is a field of the settings and a rule of
//! this module: the renderer records what the plan says, the lab's matrix skips what
//! [`DialCombination::check`] refuses and the viewer greys it out.
//!
//! The plan is pure (no GPU, no state; the facts are read once, when a scene or device
//! arrives): the renderer hands in what it keeps between frames
//! (the previous camera, for the history passes) when it writes the view.

use glam::{DMat4, DVec3, Mat4, Vec3};
use manylights_cluster::{ClusterFrame, ClusterGrid, ClusterSettings, FarField};
use manylights_gpu::blended::Transparency;
use manylights_gpu::{
    AntiAliasing, DepthConvention, Exposure, GpuContext, GpuScene, PostChoices, Tonemap,
    ViewUniform,
};
use manylights_lights::{Falloff, Shading};
use manylights_pipeline::{EarlyDepth, ShadowRoute};
use manylights_scene::Aabb;
use manylights_visibility::Shadows;

use crate::pipelines::PipelineSettings;
use crate::settings::FrameSettings;

/// What the plan needs of a scene: its bounds and its blended objects' (world space).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneFacts {
    pub bounds: Aabb,
    pub blended_bounds: Vec<Aabb>,
}

impl SceneFacts {
    pub fn of(scene: &GpuScene) -> Self {
        Self {
            bounds: scene.bounds,
            blended_bounds: scene.blended_bounds(),
        }
    }
}

/// What the plan needs of a device: the MSAA sample counts its targets' formats support.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceFacts {
    pub msaa_sample_counts: Vec<u32>,
}

impl DeviceFacts {
    pub fn of(context: &GpuContext) -> Self {
        Self {
            msaa_sample_counts: context.msaa_sample_counts(),
        }
    }
}

impl Default for DeviceFacts {
    /// What WebGPU guarantees every device: 1 and 4 samples.
    fn default() -> Self {
        Self {
            msaa_sample_counts: vec![1, 4],
        }
    }
}

/// One frame's decisions: everything the renderer prepares and records a frame from.
#[derive(Debug, Clone, PartialEq)]
pub struct FramePlan {
    /// The pipeline the frame is drawn with, and its settings.
    pub pipeline: PipelineSettings,
    /// The camera, turned into a view once (in f64 where precision matters).
    pub view: PlannedView,
    /// The camera's position in world space (blended surfaces are drawn farthest first).
    pub eye: DVec3,
    /// How blended surfaces combine with what is behind them.
    pub transparency: Transparency,
    /// The animation's time, in seconds.
    pub light_time: f32,
    /// The clustered pipelines' light assignment; `None`: every pixel loops over every
    /// light (naive).
    pub clusters: Option<ClusterPlan>,
    /// What the depth target holds before the lights are assigned.
    pub early_depth: EarlyDepth,
    /// Where the frame's shadow rays are traced, filtered and accumulated.
    pub shadows: ShadowRoute,
    /// MSAA samples a pixel (1: none).
    pub samples: u32,
    /// The falloff the image has (a far field completes the windowed one to inverse-square).
    pub falloff: Falloff,
    /// The depth convention and BRDF the frame's pipelines are built for.
    pub depth: DepthConvention,
    pub shading: Shading,
    /// How the frame is shown: a debug view is shown as drawn (no exposure, no tonemap,
    /// no anti-aliasing, no bloom).
    pub exposure: Exposure,
    pub tonemap: Tonemap,
    pub anti_aliasing: AntiAliasing,
    /// Bloom's strength (0: none).
    pub bloom: f32,
    /// The light count a heatmap shows as white (1 where the frame shows none).
    pub heatmap_max: f32,
}

/// A clustered frame's light assignment.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterPlan {
    /// The grid, design, boxes, far field and spot culling the lists are built with.
    pub frame: ClusterFrame,
    /// The blended objects' view-space boxes: blended surfaces lie in front of the depth
    /// the visible-sample boxes shrink to, so the boxes grow over these.
    pub blended_boxes: Vec<(Vec3, Vec3)>,
    /// The lists' statistics computed on the GPU; `None`: not computed.
    pub statistics: Option<ListStatistics>,
}

/// Which statistics of the light lists a frame computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ListStatistics {
    /// Also the false-positive ratio (a pass over the depth buffer).
    pub false_positives: bool,
}

/// The dials whose combinations a frame may refuse, without the values a scene or a camera
/// decides: what the lab's matrix asks of each configuration before a scene is loaded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DialCombination {
    pub pipeline: PipelineSettings,
    pub samples: u32,
    pub shadows: Shadows,
    pub anti_aliasing: AntiAliasing,
    /// The frame's size (what a refusal's memory figures are counted at).
    pub size: (u32, u32),
}

impl DialCombination {
    pub fn of(settings: &FrameSettings) -> Self {
        Self {
            pipeline: settings.pipeline,
            samples: settings.view.msaa,
            shadows: settings.shadows.mode,
            anti_aliasing: settings.post.anti_aliasing,
            size: settings.view.size,
        }
    }

    /// The shadow route, or the first rule the combination breaks.
    pub fn check(&self) -> Result<ShadowRoute, String> {
        self.shadows.check()?;
        let route = self.pipeline.shadow_route(self.shadows)?;
        self.check_samples(route)?;
        if let Some(far) = self.pipeline.far_field() {
            far.validate()?;
            if self.pipeline.falloff() != Falloff::WindowedInverseSquare {
                return Err(format!(
                    "a far field completes the windowed falloff, not `{}` (PipelineSettings::with_rendered_falloff)",
                    self.pipeline.falloff()
                ));
            }
        }
        Ok(route)
    }

    /// MSAA's sample count, and what it does not combine with: deferred's G-buffer, the
    /// forward shadow pass and the false-positive count, which read one surface a pixel.
    fn check_samples(&self, route: ShadowRoute) -> Result<(), String> {
        let samples = self.samples;
        if ![1, 2, 4, 8].contains(&samples) {
            return Err(format!(
                "--msaa {samples}: MSAA takes 1 (off), 2, 4 or 8 samples a pixel"
            ));
        }
        if samples == 1 {
            return Ok(());
        }
        if self.anti_aliasing == AntiAliasing::Taa {
            return Err(format!(
                "--aa taa with {samples}x MSAA: temporal anti-aliasing reprojects from the \
                 single-sampled depth, which MSAA frames do not write; use one or the other"
            ));
        }
        if let PipelineSettings::Deferred(deferred) = &self.pipeline {
            let (w, h) = self.size;
            let bytes = |samples: u64| {
                samples
                    * u64::from(manylights_deferred::bytes_per_pixel(deferred.layout, true))
                    * u64::from(w)
                    * u64::from(h)
            };
            return Err(format!(
                "{samples}x MSAA: deferred shades one G-buffer surface a pixel; MSAA would need a \
                 G-buffer per sample ({} at {w}x{h} for the {} layout, against {}) and \
                 per-sample shading at edges (Lauritzen 2010), which this renderer does not \
                 build: use forward-plus or naive for MSAA",
                memory(bytes(u64::from(samples))),
                deferred.layout,
                memory(bytes(1)),
            ));
        }
        if let ShadowRoute::ShadowPass(shadows) = route {
            return Err(format!(
                "shadows `{shadows}` with {samples}x MSAA: the forward shadow pass traces from \
                 one surface a pixel; with MSAA use `exact`, `rays:2` or `rays:4`, traced in the \
                 shading pass"
            ));
        }
        if self
            .pipeline
            .clustering()
            .is_some_and(|clustering| clustering.stats && clustering.false_positives)
        {
            return Err(
                "the false-positive count reads one depth a pixel: it is not counted with MSAA"
                    .into(),
            );
        }
        Ok(())
    }
}

impl FramePlan {
    /// What the plan refuses from the settings alone, whatever the scene and device: the
    /// values no combination can fix and the combinations of dials (returning the shadows'
    /// route). The budget asks it before it steps, so a refused frame leaves the budget's
    /// state as it was.
    pub fn check_dials(settings: &FrameSettings) -> Result<ShadowRoute, String> {
        check_values(settings)?;
        DialCombination::of(settings).check()
    }

    /// The plan of a frame with `settings` of `scene` on a device with `device`'s limits,
    /// or why it cannot be rendered.
    pub fn decide(
        settings: &FrameSettings,
        scene: &SceneFacts,
        device: &DeviceFacts,
    ) -> Result<Self, String> {
        let shadows = Self::check_dials(settings)?;
        if !device.msaa_sample_counts.contains(&settings.view.msaa) {
            return Err(format!(
                "{}x MSAA: this device's targets support {:?} samples a pixel",
                settings.view.msaa, device.msaa_sample_counts
            ));
        }
        let view = PlannedView::new(settings, scene);
        let clusters = match settings.pipeline.clustering() {
            Some(clustering) => Some(ClusterPlan {
                frame: clustering.frame(view.cluster_grid(&clustering.grid, settings.view.size)?),
                blended_boxes: view.boxes_in_view(&scene.blended_bounds),
                statistics: clustering.stats.then_some(ListStatistics {
                    false_positives: clustering.false_positives,
                }),
            }),
            None => None,
        };
        let (exposure, tonemap) = settings.shown_exposure();
        let debug_view = settings.pipeline.shows_debug_view();
        Ok(Self {
            pipeline: settings.pipeline,
            view,
            eye: settings.view.camera.position.as_dvec3(),
            transparency: settings.transparency,
            light_time: settings.lights.time,
            clusters,
            early_depth: settings.pipeline.early_depth(),
            shadows,
            samples: settings.view.msaa,
            falloff: settings.rendered_falloff(),
            depth: settings.view.camera.depth_convention(),
            shading: settings.shading,
            exposure,
            tonemap,
            anti_aliasing: match debug_view {
                true => AntiAliasing::Off,
                false => settings.post.anti_aliasing,
            },
            bloom: if debug_view { 0.0 } else { settings.post.bloom },
            heatmap_max: settings
                .pipeline
                .cluster_view()
                .map_or(1.0, |view| view.heatmap_max()),
        })
    }

    /// What the post stack does with this frame (`follows_own_frame`: the last frame was
    /// drawn by the same pipeline, so the histories carry over).
    pub fn post_choices(&self, follows_own_frame: bool) -> PostChoices {
        PostChoices {
            anti_aliasing: self.anti_aliasing,
            bloom: self.bloom,
            exposure: self.exposure,
            tonemap: self.tonemap,
            follows_own_frame,
        }
    }

    /// The light lists' statistics this frame computes, if any.
    pub fn list_statistics(&self) -> Option<ListStatistics> {
        self.clusters
            .as_ref()
            .and_then(|clusters| clusters.statistics)
    }

    /// The far field's cut when it is a light tree this frame cuts.
    pub fn tree_far_field(&self) -> Option<FarField> {
        self.pipeline.tree_far_field()
    }
}

/// The values no combination can fix: the camera, the size, the exposure, the time and the
/// budget.
fn check_values(settings: &FrameSettings) -> Result<(), String> {
    settings.view.camera.validate()?;
    if settings.view.size.0 == 0 || settings.view.size.1 == 0 {
        return Err(format!(
            "size {}x{} is empty",
            settings.view.size.0, settings.view.size.1
        ));
    }
    let exposure_ok = match settings.post.exposure {
        Exposure::Manual(value) => value.is_finite() && value >= 0.0,
        Exposure::Auto(auto) => {
            auto.compensation_ev.is_finite() && (0.0..=1.0).contains(&auto.adaptation)
        }
    };
    if let Some(budget) = settings.budget.filter(|ms| !(ms.is_finite() && *ms > 0.0)) {
        return Err(format!(
            "a frame-time budget must be a finite number of milliseconds above 0, got {budget}"
        ));
    }
    if !(0.0..=1.0).contains(&settings.post.bloom) {
        return Err(format!(
            "--bloom {}: bloom's strength is a blend from 0 (off) to 1 (all bloom)",
            settings.post.bloom
        ));
    }
    if !settings.lights.time.is_finite() || !exposure_ok {
        return Err(format!(
            "time must be finite, a fixed exposure finite and not negative, an automatic one's compensation finite and adaptation within 0..1 (time {}, exposure {:?})",
            settings.lights.time, settings.post.exposure
        ));
    }
    Ok(())
}

/// `bytes` for a person: MiB, or KiB below one MiB (a tiny frame's G-buffer is not 0 MiB).
fn memory(bytes: u64) -> String {
    if bytes >= 1 << 20 {
        format!("{:.0} MiB", bytes as f64 / 1048576.0)
    } else {
        format!("{:.0} KiB", bytes as f64 / 1024.0)
    }
}

/// Where a frame was seen from, in world coordinates: what the next frame's history passes
/// reproject through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewedFrom {
    /// With the frame's jitter.
    pub world_to_clip: DMat4,
    pub position: DVec3,
    /// Temporal anti-aliasing's jitter of the frame, in NDC (zero without it).
    pub jitter: [f32; 2],
}

/// The camera of one frame as the passes use it.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedView {
    /// The world position the scene's coordinates are relative to: the camera's with
    /// camera-relative rendering (the view is then only a rotation), the world's origin
    /// without.
    pub origin: Vec3,
    /// Scene coordinates to view space.
    pub view: Mat4,
    /// With temporal anti-aliasing's jitter, so the clusters and the shading agree on
    /// where each pixel's sample is.
    pub projection: Mat4,
    /// Temporal anti-aliasing's jitter, in NDC (zero without it).
    pub jitter: [f32; 2],
    /// The mip bias of material textures (`gpu::taa::TEXTURE_LOD_BIAS` under TAA, else 0).
    pub texture_lod_bias: f32,
    /// Where this frame is seen from (f64): the next frame's previous view.
    pub viewed_from: ViewedFrom,
    /// The scene's bounds in view space (computed in f64): the cluster grid fits its depth
    /// range to them.
    pub scene_in_view: Aabb,
    /// World to view space, in f64 (the view's translation included).
    world_to_view: DMat4,
    /// The camera's position in scene coordinates.
    camera_in_scene: Vec3,
    size: (u32, u32),
    near: f32,
    far: f32,
    /// The depth empty pixels keep: shaders tell them by it.
    clear_depth: f32,
    shadow_seed: u32,
}

impl PlannedView {
    pub(crate) fn new(settings: &FrameSettings, scene: &SceneFacts) -> Self {
        let camera = &settings.view.camera;
        let rotation = camera.view_matrix_relative();
        let (origin, view) = if settings.view.camera_relative {
            (camera.position, rotation)
        } else {
            (Vec3::ZERO, camera.view_matrix())
        };
        let aspect = settings.view.size.0 as f32 / settings.view.size.1 as f32;
        let (jitter, texture_lod_bias) = match settings.post.anti_aliasing {
            AntiAliasing::Taa if !settings.pipeline.shows_debug_view() => (
                manylights_gpu::taa::jitter_in_ndc(settings.shadows.seed, settings.view.size),
                manylights_gpu::taa::TEXTURE_LOD_BIAS,
            ),
            _ => ([0.0; 2], 0.0),
        };
        // The jitter moves every point by the same NDC offset: a translation after the
        // projection (for a perspective one, scaled by w, so exact for every depth).
        let projection = Mat4::from_translation(Vec3::new(jitter[0], jitter[1], 0.0))
            * camera.projection(aspect);
        // In f64 throughout: far from the world origin an f32 view's translation is off by
        // more than the blended boxes' padding.
        let world_to_view =
            rotation.as_dmat4() * DMat4::from_translation(-camera.position.as_dvec3());
        let (low, high) = view_box(&world_to_view, &scene.bounds);
        let scene_in_view = match scene.bounds.is_empty() {
            true => Aabb::EMPTY,
            false => Aabb::new(low.as_vec3(), high.as_vec3()),
        };
        Self {
            origin,
            view,
            projection,
            jitter,
            texture_lod_bias,
            viewed_from: ViewedFrom {
                world_to_clip: projection.as_dmat4() * world_to_view,
                position: camera.position.as_dvec3(),
                jitter,
            },
            scene_in_view,
            world_to_view,
            camera_in_scene: camera.position - origin,
            size: settings.view.size,
            near: camera.near,
            far: camera.far,
            clear_depth: camera.depth_convention().clear_value(),
            shadow_seed: settings.shadows.seed,
        }
    }

    /// The view-space boxes of `world` boxes (the blended objects'), each widened by 1e-5
    /// of its size and distance for the GPU's f32 view.
    pub fn boxes_in_view(&self, world: &[Aabb]) -> Vec<(Vec3, Vec3)> {
        world
            .iter()
            .map(|world| {
                let (low, high) = view_box(&self.world_to_view, world);
                let pad = 1e-5
                    * (high - low)
                        .max_element()
                        .max(high.abs().max_element().max(low.abs().max_element()));
                ((low - pad).as_vec3(), (high + pad).as_vec3())
            })
            .collect()
    }

    /// The cluster grid: the scene's bounds in view space fit the depth range.
    pub(crate) fn cluster_grid(
        &self,
        grid: &ClusterSettings,
        size: (u32, u32),
    ) -> Result<ClusterGrid, String> {
        ClusterGrid::new(
            grid,
            size,
            self.projection,
            self.near,
            self.far,
            Some(self.scene_in_view),
        )
        .map_err(|e| e.to_string())
    }

    /// The view's uniform, with `previous` (the frame seen before; `None` on a first
    /// frame: this one) as its history's view.
    pub fn uniform(&self, previous: Option<ViewedFrom>) -> ViewUniform {
        let mut uniform = ViewUniform::new(
            self.view,
            self.projection,
            self.camera_in_scene,
            self.size,
            self.near,
            self.far,
        );
        uniform.near_far[2] = self.clear_depth;
        uniform.origin = self.origin.extend(0.0).to_array();
        uniform.seeds[0] = self.shadow_seed;
        // Last frame's camera, in this frame's scene coordinates (in f64, as the origin
        // may be far from the world's).
        let previous = previous.unwrap_or(self.viewed_from);
        let scene_to_world = DMat4::from_translation(self.origin.as_dvec3());
        uniform.previous_view_proj = (previous.world_to_clip * scene_to_world)
            .as_mat4()
            .to_cols_array_2d();
        uniform.previous_camera_position = (previous.position - self.origin.as_dvec3())
            .as_vec3()
            .extend(1.0)
            .to_array();
        uniform.texture_lod_bias[0] = self.texture_lod_bias;
        uniform.jitter = [
            self.jitter[0],
            self.jitter[1],
            previous.jitter[0],
            previous.jitter[1],
        ];
        uniform
    }
}

/// The view-space box of a world box: its corners through `world_to_view`, in f64.
fn view_box(world_to_view: &DMat4, world: &Aabb) -> (DVec3, DVec3) {
    let (mut low, mut high) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
    for corner in world.corners() {
        let at = world_to_view.transform_point3(corner.as_dvec3());
        low = low.min(at);
        high = high.max(at);
    }
    (low, high)
}

#[cfg(test)]
mod tests;
