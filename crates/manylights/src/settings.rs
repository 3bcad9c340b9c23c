//! `FrameSettings`: everything that decides a frame, with the rules that tie the falloff to
//! the pipeline and the radius. Typed values only: the command line, the lab and the page
//! build it, none of them is needed to.

use manylights_cluster::FarField;
use manylights_gpu::blended::Transparency;
use manylights_gpu::{AntiAliasing, Exposure, Tonemap};
use manylights_lights::{
    DEFAULT_SATURATION, Falloff, LightShape, RadiusMode, Shading, SpotSettings,
};
use manylights_visibility::Shadows;

use glam::Vec3;
use manylights_scene::Aabb;

use crate::camera::{Camera, Projection};
use crate::pipelines::PipelineSettings;
use crate::scenes::LoadedScene;

/// Default light intensity: radiance 0.2 at 1 m (1000 lights light Sponza without
/// saturating the ACES curve at exposure 1).
pub const DEFAULT_INTENSITY: f32 = 0.2;
/// Default luminance threshold: with the default intensity, radius = sqrt(0.2 / 0.05) = 2 m,
/// the reference projects' radius in Sponza.
pub const DEFAULT_THRESHOLD: f32 = 0.05;

/// A frame's size in pixels, written `WIDTHxHEIGHT` (`1920x1080`) wherever a person or a
/// file names it: the command line, the lab's matrix, its reports and the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub struct ImageSize {
    pub width: u32,
    pub height: u32,
}

impl ImageSize {
    pub const fn new(width: u32, height: u32) -> Self {
        Self { width, height }
    }
}

impl From<ImageSize> for (u32, u32) {
    fn from(size: ImageSize) -> Self {
        (size.width, size.height)
    }
}

impl From<(u32, u32)> for ImageSize {
    fn from((width, height): (u32, u32)) -> Self {
        Self { width, height }
    }
}

impl std::fmt::Display for ImageSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl std::str::FromStr for ImageSize {
    type Err = String;

    /// `WIDTHxHEIGHT` (`x` or `X`, spaces around the numbers allowed), at least 1x1.
    fn from_str(text: &str) -> Result<Self, String> {
        let (w, h) = text
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("expected WIDTHxHEIGHT (e.g. 1920x1080), got '{text}'"))?;
        let parse = |v: &str| {
            v.trim()
                .parse::<u32>()
                .map_err(|_| format!("'{v}' in '{text}' is not a whole number"))
        };
        let size = ImageSize::new(parse(w)?, parse(h)?);
        if size.width == 0 || size.height == 0 {
            return Err(format!("the size must be at least 1x1, got '{text}'"));
        }
        Ok(size)
    }
}

/// Everything that decides a frame, in sections shaped by their owners: the pipeline (with
/// a clustered pipeline's light lists inside), the view, the lights, the shadows and the
/// post-processing; then the BRDF, the transparency and the budget, which are one dial each.
#[derive(Debug, Clone, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct FrameSettings {
    /// The shading pipeline and its own settings.
    pub pipeline: PipelineSettings,
    pub view: ViewSettings,
    pub lights: FrameLights,
    pub shadows: ShadowSettings,
    pub post: PostSettings,
    /// A GPU time per frame, in milliseconds, to stay within: the renderer shortens the
    /// generated lights' radius and, with a tree far field, the cut's slots (never beyond
    /// `radius` and the far field's slots) from the GPU times of the frames it has finished
    /// (`crate::budget`); [`crate::FrameStats::radius`] and `far_slots` say what it
    /// chose. `None`: they are the asked ones.
    pub budget: Option<f32>,
    /// The BRDF every pipeline shades with: glTF's metallic-roughness or Blinn-Phong (a
    /// program of each; the default is the scene file's own model).
    pub shading: Shading,
    /// How blended surfaces combine with what is behind them: sorted back to front per
    /// object (default), or weighted blended order-independent transparency.
    pub transparency: Transparency,
}

/// Where the frame is seen from and what it is drawn into.
#[serde_with::serde_as]
#[derive(Debug, Clone, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct ViewSettings {
    pub camera: Camera,
    /// Width x height in pixels (written `WIDTHxHEIGHT`, as [`ImageSize`]).
    #[serde_as(as = "serde_with::FromInto<ImageSize>")]
    pub size: (u32, u32),
    /// MSAA samples a pixel (1: none; 2, 4 or 8 where the device offers them): Forward+
    /// and naive draw into multisampled colour and depth, resolved; deferred refuses it.
    pub msaa: u32,
    /// Camera-relative rendering (default): positions are expressed relative to the camera
    /// (in f64 on the CPU), so scenes far from the world origin keep their precision. Off
    /// renders in world space, as most engines do (for comparison).
    pub camera_relative: bool,
}

/// The frame's lights: the generated ones (how many, their colours, spots and motion) and
/// the radius every light without a range of its own ends at.
#[derive(Debug, Clone, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct FrameLights {
    pub count: u32,
    pub seed: u32,
    pub intensity: f32,
    pub radius: RadiusMode,
    /// Colour saturation in [0, 1] (1: pure random hues, 0: white).
    pub saturation: f32,
    /// Which generated lights are spots, and their cones (the scene's own lights come
    /// from its file, whatever this says).
    pub spots: SpotSettings,
    /// The shape of the generated lights that are not spots (points, spheres or squares;
    /// `--light-shape`).
    pub shape: LightShape,
    /// The scene's emissive triangles are lights too (on by default; `--emissive-lights
    /// off` draws them glowing but lighting nothing).
    pub emissive: bool,
    /// Animation time in seconds (a fixed step gives reproducible frames).
    pub time: f32,
    /// Motion speed and wander; `None` uses the scene's default.
    pub animation: Option<(f32, f32)>,
}

/// Whether geometry blocks light, and the ray budget's random numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct ShadowSettings {
    /// `Exact` traces a shadow ray for every light a pixel evaluates, `Rays(k)` k rays a
    /// pixel to lights drawn by their unshadowed contribution (every pipeline; the
    /// scene's BVH is built on the first such frame).
    pub mode: Shadows,
    /// The seed of the ray budget's random numbers ([`Shadows::Rays`]): the same seed, the
    /// same image. Vary it from frame to frame (the viewer and `render --frames` count
    /// frames) for noise that changes, which averages out over frames.
    pub seed: u32,
}

/// What turns the HDR frame into the image shown.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct PostSettings {
    /// A fixed exposure, or one chosen on the GPU from the frame's luminance histogram.
    pub exposure: Exposure,
    pub tonemap: Tonemap,
    /// Temporal anti-aliasing, in every pipeline (not with MSAA). Its jitter is the
    /// frame's [`ShadowSettings::seed`]th point of the Halton sequence: the seed is the
    /// frame's number wherever frames are counted (the viewer, `render --frames`, the
    /// lab), so the same seed gives the same image and counting frames moves the jitter.
    pub anti_aliasing: AntiAliasing,
    /// Bloom: how far the frame is blended toward its bloom, 0 (off) to 1
    /// (`manylights_gpu::bloom`; 0.04 to 0.1 looks like a lens).
    pub bloom: f32,
}

impl PostSettings {
    /// Whether bloom is on.
    pub fn blooms(&self) -> bool {
        self.bloom > 0.0
    }
}

impl FrameSettings {
    /// The falloff the image has: the pipeline's, or inverse-square where a far field
    /// completes a clustered pipeline's windowed falloff.
    pub fn rendered_falloff(&self) -> Falloff {
        self.pipeline.rendered_falloff()
    }

    /// Sets the falloff and the far field together (the CLI, the lab and the viewer), by
    /// [`PipelineSettings::with_rendered_falloff`]'s rules.
    pub fn set_falloff(
        &mut self,
        falloff: Falloff,
        far_field: Option<FarField>,
    ) -> Result<(), String> {
        self.pipeline = self.pipeline.with_rendered_falloff(falloff, far_field)?;
        Ok(())
    }

    /// Frames a still view takes to reach its steady state (every history full: the shadow
    /// filter's, temporal anti-aliasing's): what a measurement renders before it reads a
    /// frame, each with the next seed.
    pub fn settle_frames(&self) -> u32 {
        let anti_aliasing = match self.post.anti_aliasing {
            AntiAliasing::Taa => manylights_gpu::taa::JITTER_SAMPLES,
            AntiAliasing::Off => 0,
        };
        self.shadows.mode.settle_frames().max(anti_aliasing)
    }

    /// The exposure and curve the frame is shown with: the settings' own, except that a
    /// debug view is shown as drawn (no exposure, no tonemap).
    pub fn shown_exposure(&self) -> (Exposure, Tonemap) {
        if self.pipeline.shows_debug_view() {
            (Exposure::Manual(1.0), Tonemap::None)
        } else {
            (self.post.exposure, self.post.tonemap)
        }
    }

    /// [`FrameSettings::default`] placed in `scene`: its first camera preset and the BRDF
    /// its file defines.
    pub fn for_scene(scene: &LoadedScene) -> Self {
        let mut settings = Self {
            shading: scene.scene.shading,
            ..Self::default()
        };
        settings.view.camera = scene.default_camera();
        settings
    }

    /// These settings placed in `scene` as `choices` name the camera and the BRDF. Errors
    /// say which choice the scene refuses (a preset it does not have).
    pub fn placed_in(self, scene: &LoadedScene, choices: &SceneChoices) -> Result<Self, String> {
        let mut camera = match &choices.camera {
            Some(text) => scene.camera(text)?,
            None => scene.default_camera(),
        };
        if let Some(height) = choices.orthographic {
            camera.projection = Projection::Orthographic { height };
        }
        camera.reverse_z = choices.reverse_z;
        Ok(Self {
            view: ViewSettings {
                camera,
                ..self.view
            },
            shading: choices.shading.unwrap_or(scene.scene.shading),
            ..self
        })
    }
}

impl Default for FrameSettings {
    /// 1280x720, 1000 lights, clustered deferred (compact G-buffer, tiles lighting),
    /// vivid light colours and a fixed exposure of 1 (`render` and the viewer default to
    /// automatic exposure on their command line; accuracy comparisons keep one fixed
    /// exposure so it can neither hide nor create error). The camera frames a 2 m cube at
    /// the origin and the BRDF is metallic-roughness until the settings are placed in a
    /// scene ([`FrameSettings::for_scene`], [`FrameSettings::placed_in`]).
    fn default() -> Self {
        Self {
            pipeline: PipelineSettings::default(),
            view: ViewSettings {
                camera: Camera::fit(&Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))),
                size: (1280, 720),
                msaa: 1,
                camera_relative: true,
            },
            lights: FrameLights {
                count: 1000,
                seed: 1,
                intensity: DEFAULT_INTENSITY,
                radius: RadiusMode::LuminanceThreshold(DEFAULT_THRESHOLD),
                saturation: DEFAULT_SATURATION,
                spots: SpotSettings::default(),
                shape: LightShape::Point,
                emissive: true,
                time: 0.0,
                animation: None,
            },
            shadows: ShadowSettings {
                mode: Shadows::Off,
                seed: 0,
            },
            post: PostSettings {
                exposure: Exposure::Manual(1.0),
                tonemap: Tonemap::AcesFit,
                anti_aliasing: AntiAliasing::Off,
                bloom: 0.0,
            },
            budget: None,
            shading: Shading::Pbr,
            transparency: Transparency::default(),
        }
    }
}

/// What of a frame is named before its scene is loaded: the camera (a preset's name or a
/// position, and its projection) and the BRDF. The command line and the lab's matrix name
/// them so; [`FrameSettings::placed_in`] resolves them in the loaded scene.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneChoices {
    /// A preset's name or `x,y,z,yaw,pitch[,fov]` ([`LoadedScene::camera`]); `None`: the
    /// scene's first preset.
    pub camera: Option<String>,
    /// An orthographic projection of this height (metres) instead of the camera's own.
    pub orthographic: Option<f32>,
    pub reverse_z: bool,
    /// The BRDF; `None`: the one the scene's file defines ([`manylights_scene::Scene::shading`]).
    pub shading: Option<Shading>,
}
