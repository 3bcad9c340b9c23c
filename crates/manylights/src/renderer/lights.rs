//! The frame's lights: generated from the settings (and animated on the GPU) or fixed by
//! the caller, uploaded again only when what decides them changed.

use super::*;

/// Where the frame's lights come from.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum LightSource {
    /// Generated from the frame settings and animated on the GPU, after which the scene's
    /// own lights, with its emissive triangles when the flag says so.
    Generated(LightSettings, bool),
    /// Given through [`Renderer::set_fixed_lights`]; never animated. Kept on the CPU too,
    /// to upload again after a device loss.
    Fixed(LightSet),
}

impl LightSource {
    /// The pass that moves generated lights to their positions at `time` (fixed lights
    /// never move).
    pub(super) fn animation<'a>(
        &self,
        animator: &'a mut LightAnimator,
        context: &GpuContext,
        lights: &GpuLights,
        time: f32,
    ) -> Option<manylights_lights::PreparedAnimation<'a>> {
        match self {
            LightSource::Generated(settings, _) => {
                Some(animator.prepare(context, lights, settings, time))
            }
            LightSource::Fixed(_) => None,
        }
    }
}

impl Renderer {
    pub(super) fn light_settings(&self, settings: &FrameSettings) -> LightSettings {
        let mut animation = AnimationParams::in_box(self.scene.light_box);
        if let Some((speed, wander)) = settings.lights.animation {
            animation.speed = speed;
            animation.wander = wander;
        }
        LightSettings {
            count: settings.lights.count,
            seed: settings.lights.seed,
            intensity: settings.lights.intensity,
            radius: settings.lights.radius,
            saturation: settings.lights.saturation,
            animation,
            spots: settings.lights.spots,
            shape: settings.lights.shape,
        }
    }

    /// Regenerates and uploads the lights when their settings changed (fixed lights stay).
    pub(super) fn prepare_lights(&mut self, settings: &FrameSettings) -> Result<(), RenderError> {
        let wanted = self.light_settings(settings);
        match self.lights.as_mut() {
            Some((LightSource::Fixed(_), _)) => return Ok(()),
            Some((LightSource::Generated(current, emissive), _))
                if *current == wanted && *emissive == settings.lights.emissive =>
            {
                return Ok(());
            }
            // Only the radius moved (a budget moves it every frame) and the scene has no
            // lights of its own (their radii come from theirs): the animation pass writes
            // the generated lights' radius, so they stay.
            Some((LightSource::Generated(current, emissive), _))
                if LightSettings {
                    radius: wanted.radius,
                    ..*current
                } == wanted
                    && *emissive == settings.lights.emissive
                    && self.scene.scene.lights.is_empty()
                    && !(settings.lights.emissive && self.scene.scene.features().emissive) =>
            {
                wanted
                    .validate()
                    .map_err(|e| RenderError::Settings(e.to_string()))?;
                *current = wanted;
                return Ok(());
            }
            _ => {}
        }
        // Checked before the CPU generates them: an absurd count (4 billion lights, 128 GB)
        // is a clear error, not an allocation failure that aborts the process.
        let bytes = u64::from(wanted.count.max(1)) * std::mem::size_of::<Light>() as u64;
        self.context
            .check_buffer_size(&format!("{} lights", wanted.count), bytes, true)?;
        let mut set =
            LightSet::generate(&wanted).map_err(|e| RenderError::Settings(e.to_string()))?;
        // The scene's own lights after the generated ones: the animation moves only the
        // first `wanted.count`, so these stay where the file put them.
        set.extend(crate::scenes::scene_lights(
            &self.scene.scene,
            wanted.radius,
        ));
        if settings.lights.emissive {
            set.extend(manylights_lights::emissive_lights(&self.scene.scene, wanted.radius).lights);
        }
        let mut uploaded = GpuLights::upload(&self.context, &set)?;
        uploaded.animated = wanted.count;
        self.lights = Some((
            LightSource::Generated(wanted, settings.lights.emissive),
            uploaded,
        ));
        Ok(())
    }

    /// Renders with exactly these lights (not animated; the frame settings' light fields
    /// are ignored) until [`Renderer::use_generated_lights`]. Lights with NaN or infinite
    /// fields, negative intensity or a non-positive radius are refused with the reason.
    pub fn set_fixed_lights(&mut self, lights: &LightSet) -> Result<(), RenderError> {
        lights
            .validate()
            .map_err(|e| RenderError::Settings(e.to_string()))?;
        let uploaded = GpuLights::upload(&self.context, lights)?;
        self.lights = Some((LightSource::Fixed(lights.clone()), uploaded));
        Ok(())
    }

    /// Goes back to lights generated and animated from the frame settings.
    pub fn use_generated_lights(&mut self) {
        self.lights = None;
    }
}
