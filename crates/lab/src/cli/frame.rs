//! The flags made into a frame: [`RenderArgs::settings`] (on [`FrameSettings::default`], as
//! the lab builds its frames) and what only the loaded scene resolves
//! ([`RenderArgs::scene_choices`]).

use manylights::cluster::{ClusterSettings, ClusteringSettings, TileSpec};
use manylights::gpu::{AutoExposure, Exposure};
use manylights::lights::{SpotCone, SpotSettings};
use manylights::{
    FrameLights, FrameSettings, LoadedScene, PipelineSettings, PostSettings, SceneChoices,
};

use super::RenderArgs;

impl RenderArgs {
    /// The frame these flags choose, before a scene places its camera and BRDF
    /// ([`Self::scene_choices`]). The flags that set one field each are the rows of
    /// [`super::SETTING_FLAGS`], set by path with `--set` after the rest; the flags here
    /// combine several fields or convert a unit (the pipeline's kind and its grid, the far
    /// field's tolerance and seed with the falloff it completes, the debug view, `--exposure`
    /// or its compensation, `--no-depth-prepass`, the spots' angles in degrees), the
    /// command line's only logic. Errors say which flag the pipeline cannot take (a G-buffer
    /// view of Forward+, a far field or a cluster flag of naive).
    pub fn settings(&self) -> Result<FrameSettings, String> {
        let mut pipeline = PipelineSettings::of_kind(self.pipeline);
        if let PipelineSettings::ForwardPlus(forward_plus) = &mut pipeline {
            forward_plus.depth_prepass = !self.no_depth_prepass;
        }
        let clustering = self.clustering();
        match pipeline.clustering_mut() {
            Some(chosen) => *chosen = clustering,
            None if clustering != ClusteringSettings::default() => {
                return Err(format!(
                    "the {} pipeline shades every light: it has no light lists to build or count (--tiles, --tile-size, --slices, --z-scheme, --z-range, --stats, and the light lists' settings, are Forward+'s and deferred's)",
                    self.pipeline
                ));
            }
            None => {}
        }
        let far_field = self.far_field.0.map(|mut far| {
            far.tolerance = self.far_tolerance.unwrap_or(far.tolerance);
            far.seed = self.far_seed;
            far
        });
        let pipeline = pipeline
            .with_asked_falloff(self.falloff, far_field)?
            .with_debug_view(self.debug_view)?
            .with_heatmap_max(self.heatmap_max);
        let defaults = FrameSettings::default();
        let (inner, outer) = self.spot_angles;
        let mut settings = FrameSettings {
            pipeline,
            lights: FrameLights {
                spots: SpotSettings {
                    cone: SpotCone {
                        inner: inner.to_radians(),
                        outer: outer.to_radians(),
                    },
                    ..defaults.lights.spots
                },
                ..defaults.lights
            },
            post: self.post(),
            ..defaults
        };
        self.setting_args.apply(&mut settings)?;
        Ok(settings)
    }

    /// The exposure: `--exposure`, or automatic with `--exposure-compensation`.
    fn post(&self) -> PostSettings {
        PostSettings {
            exposure: match self.exposure {
                Some(value) => Exposure::Manual(value),
                None => Exposure::Auto(AutoExposure {
                    compensation_ev: self.exposure_compensation,
                    ..AutoExposure::CONVERGE_NOW
                }),
            },
            ..FrameSettings::default().post
        }
    }

    /// The light lists' settings these flags choose (the far field is set with the
    /// falloff).
    fn clustering(&self) -> ClusteringSettings {
        let mut grid = ClusterSettings::default();
        if let Some((x, y)) = self.tiles {
            grid.tiles = TileSpec::Count { x, y };
        }
        if let Some(pixels) = self.tile_size {
            grid.tiles = TileSpec::PixelSize(pixels);
        }
        if let Some(slices) = self.slices {
            grid.z_slices = slices;
        }
        if let Some(scheme) = self.z_scheme {
            grid.z_scheme = scheme.with_first_slice_far(self.first_slice);
        }
        if let Some(z_range) = self.z_range {
            grid.z_range = z_range;
        }
        ClusteringSettings {
            grid,
            stats: self.stats,
            false_positives: self.stats,
            // No far field (it is set with the falloff); a field added needs nothing here.
            ..ClusteringSettings::default()
        }
    }

    /// The camera and the BRDF these flags name, placed when the scene is loaded.
    pub fn scene_choices(&self) -> SceneChoices {
        SceneChoices {
            camera: self.camera.clone(),
            orthographic: self.orthographic,
            reverse_z: self.reverse_z,
            shading: self.shading,
        }
    }
}

/// The frame settings the arguments describe, placed in a loaded scene: `render`'s and
/// the viewer's.
pub fn frame_settings(args: &RenderArgs, scene: &LoadedScene) -> anyhow::Result<FrameSettings> {
    args.settings()
        .and_then(|settings| settings.placed_in(scene, &args.scene_choices()))
        .map_err(|reason| anyhow::anyhow!("invalid frame settings: {reason}"))
}
