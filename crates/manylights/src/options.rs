//! [`FrameOptions`]: a frame as a person chooses it (a pipeline by name and its dials, a
//! camera preset, a far field or none), and [`FrameSettings::from_options`], the one place
//! such a choice becomes the settings a frame runs with. The command line, the lab and the
//! viewer all describe frames this way, so the lab cannot render a configuration
//! differently from `manylights render` with the same choices. Parsing stays outside: clap
//! (the lab's `cli`) fills these fields and nothing here knows it exists.

use manylights_cluster::{AssignmentDesign, ClusterBoxes, ClusterSettings, FarField, SpotCulling};
use manylights_deferred::{GBufferLayout, LightingPath};
use manylights_gpu::{AutoExposure, Exposure, Tonemap};
use manylights_lights::{DEFAULT_SATURATION, Falloff, RadiusMode, Shading, SpotCone, SpotSettings};
use manylights_visibility::Shadows;

use crate::camera::Projection;
use crate::pipelines::{DebugView, PipelineKind, PipelineSettings};
use crate::plan::DialCombination;
use crate::scenes::LoadedScene;
use crate::settings::{DEFAULT_INTENSITY, DEFAULT_THRESHOLD, FrameSettings};

/// A frame as chosen. [`Default`] is `manylights render` without flags: deferred (compact
/// G-buffer, tiles lighting), 1280x720, 1000 lights, automatic exposure.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameOptions {
    pub pipeline: PipelineKind,
    /// Deferred only.
    pub gbuffer: GBufferLayout,
    /// Deferred only.
    pub lighting: LightingPath,
    /// Forward+ only.
    pub depth_prepass: bool,
    pub debug_view: DebugView,
    /// The heatmap's white point (lights per cluster).
    pub heatmap_max: f32,
    /// With a far field, the windowed falloff stands for the inverse-square one it completes.
    pub falloff: Falloff,
    pub far_field: Option<FarField>,
    /// A preset's name or `x,y,z,yaw,pitch[,fov]` ([`LoadedScene::camera`]); `None`: the
    /// scene's first preset.
    pub camera: Option<String>,
    /// An orthographic projection of this height (metres) instead of the camera's own.
    pub orthographic: Option<f32>,
    pub reverse_z: bool,
    pub size: (u32, u32),
    pub lights: u32,
    pub seed: u32,
    pub intensity: f32,
    pub saturation: f32,
    /// The fraction of generated lights that are spots.
    pub spot_fraction: f32,
    /// The spots' inner and outer cone angles, in degrees.
    pub spot_angles_degrees: (f32, f32),
    pub spot_culling: SpotCulling,
    pub shadows: Shadows,
    pub budget: Option<f32>,
    pub radius: RadiusMode,
    pub time: f32,
    pub tonemap: Tonemap,
    pub exposure: Exposure,
    pub cluster: ClusterSettings,
    pub assignment: AssignmentDesign,
    pub cluster_boxes: ClusterBoxes,
    /// List statistics and the false-positive ratio, on the GPU.
    pub stats: bool,
    /// The BRDF; `None`: the one the scene's file defines ([`manylights_scene::Scene::shading`]).
    pub shading: Option<Shading>,
    /// How blended surfaces combine with what is behind them.
    pub transparency: crate::Transparency,
    /// MSAA samples a pixel (1: off).
    pub msaa: u32,
}

impl Default for FrameOptions {
    fn default() -> Self {
        Self {
            pipeline: PipelineKind::Deferred,
            gbuffer: GBufferLayout::Compact,
            lighting: LightingPath::Tiles,
            depth_prepass: true,
            debug_view: DebugView::NONE,
            heatmap_max: 64.0,
            falloff: Falloff::WindowedInverseSquare,
            far_field: None,
            camera: None,
            orthographic: None,
            reverse_z: false,
            size: (1280, 720),
            lights: 1000,
            seed: 1,
            intensity: DEFAULT_INTENSITY,
            saturation: DEFAULT_SATURATION,
            spot_fraction: 0.0,
            spot_angles_degrees: (20.0, 30.0),
            spot_culling: SpotCulling::default(),
            shadows: Shadows::Off,
            budget: None,
            radius: RadiusMode::LuminanceThreshold(DEFAULT_THRESHOLD),
            time: 0.0,
            tonemap: Tonemap::AcesFit,
            exposure: Exposure::Auto(AutoExposure::CONVERGE_NOW),
            cluster: ClusterSettings::default(),
            assignment: AssignmentDesign::default(),
            cluster_boxes: ClusterBoxes::default(),
            stats: false,
            shading: None,
            transparency: crate::Transparency::Sorted,
            msaa: 1,
        }
    }
}

impl FrameOptions {
    /// The pipeline and its settings; settings the pipeline does not have are refused with
    /// the reason (a G-buffer view of Forward+, the unbounded falloff of a clustered
    /// pipeline without a far field).
    pub fn pipeline_settings(&self) -> Result<PipelineSettings, String> {
        let mut pipeline = PipelineSettings::of_kind(self.pipeline);
        match &mut pipeline {
            PipelineSettings::Deferred(deferred) => {
                deferred.layout = self.gbuffer;
                deferred.lighting = self.lighting;
            }
            PipelineSettings::ForwardPlus(forward_plus) => {
                forward_plus.depth_prepass = self.depth_prepass;
            }
            PipelineSettings::Naive(_) => {}
        }
        // The falloff is set with the far field (`FrameSettings::from_options`); a falloff
        // this pipeline cannot render at all is refused here already.
        if self.far_field.is_none() {
            pipeline = pipeline.with_falloff(self.falloff)?;
        }
        Ok(pipeline
            .with_debug_view(self.debug_view)?
            .with_heatmap_max(self.heatmap_max))
    }

    /// The dials whose combination a frame may refuse, as chosen here: what the lab's
    /// matrix asks of a configuration before a scene is loaded. Errors say which choice a
    /// pipeline cannot take.
    pub fn dial_combination(&self) -> Result<DialCombination, String> {
        let (pipeline, far_field) = crate::settings::with_falloff(
            self.pipeline_settings()?,
            self.rendered_falloff(),
            self.far_field,
        )?;
        Ok(DialCombination {
            pipeline,
            far_field,
            samples: self.msaa,
            shadows: self.shadows,
            false_positives: self.stats,
            size: self.size,
        })
    }

    /// Why a frame of these choices would be refused whatever its scene and camera
    /// ([`crate::FramePlan::decide`]'s rules of combination), if it would.
    pub fn refusal(&self) -> Option<String> {
        self.dial_combination()
            .and_then(|dials| dials.check())
            .err()
    }

    /// The falloff the frame renders: a far field completes the windowed falloff to the
    /// unbounded one it approximates.
    fn rendered_falloff(&self) -> Falloff {
        if self.far_field.is_some() && self.falloff == Falloff::WindowedInverseSquare {
            Falloff::InverseSquare
        } else {
            self.falloff
        }
    }
}

impl FrameSettings {
    /// The settings `options` describe for `scene` (its camera presets). Errors say which
    /// choice the pipeline or the scene refuses.
    pub fn from_options(options: &FrameOptions, scene: &LoadedScene) -> Result<Self, String> {
        let invalid = |reason: String| format!("invalid frame settings: {reason}");
        let mut settings = FrameSettings::for_scene(scene);
        let mut camera = match &options.camera {
            Some(text) => scene.camera(text)?,
            None => scene.default_camera(),
        };
        if let Some(height) = options.orthographic {
            camera.projection = Projection::Orthographic { height };
        }
        camera.reverse_z = options.reverse_z;
        settings.pipeline = options.pipeline_settings().map_err(invalid)?;
        settings.cluster = options.cluster;
        settings.assignment = options.assignment;
        settings.cluster_boxes = options.cluster_boxes;
        settings
            .set_falloff(options.rendered_falloff(), options.far_field)
            .map_err(invalid)?;
        settings.cluster_stats = options.stats;
        settings.false_positives = options.stats;
        settings.camera = camera;
        settings.size = options.size;
        settings.light_count = options.lights;
        settings.seed = options.seed;
        settings.intensity = options.intensity;
        settings.light_saturation = options.saturation;
        let (inner, outer) = options.spot_angles_degrees;
        settings.spots = SpotSettings {
            fraction: options.spot_fraction,
            cone: SpotCone {
                inner: inner.to_radians(),
                outer: outer.to_radians(),
            },
        };
        settings.spot_culling = options.spot_culling;
        settings.shadows = options.shadows;
        settings.budget = options.budget;
        settings.radius = options.radius;
        settings.time = options.time;
        settings.tonemap = options.tonemap;
        settings.exposure = options.exposure;
        settings.shading = options.shading.unwrap_or(scene.scene.shading);
        settings.transparency = options.transparency;
        settings.msaa = options.msaa;
        Ok(settings)
    }
}
