//! [`ShadowRoute`]: where a frame's shadow rays are traced and what follows them, decided
//! by each pipeline from its own settings ([`crate::ShadingPipeline::shadow_route`]) and
//! handed back to it in [`crate::FrameInputs`], so no pipeline re-derives it from the mode.

use manylights_visibility::Shadows;

/// Where a frame's shadow rays are traced, and what follows them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShadowRoute {
    /// No shadow rays: no BVH is bound.
    Off,
    /// The shading loop traces every ray (exact shadows, a budget unfiltered, or a debug
    /// view's raw shares).
    InShadingLoop(Shadows),
    /// A forward pipeline's shadow pass traces one ray a pixel after shading, then the
    /// filter and history run as the mode says.
    ShadowPass(Shadows),
    /// Deferred's compute lighting traces the budget, then the filter and history run as
    /// the mode says.
    ComputeLighting(Shadows),
}

impl ShadowRoute {
    /// The forward pipelines' route for their shaded image: a budget of one ray a pixel
    /// in the shadow pass, every other mode in the shading loop.
    pub fn forward(shadows: Shadows) -> Self {
        match shadows {
            Shadows::Off => ShadowRoute::Off,
            _ if shadows.in_shadow_pass() => ShadowRoute::ShadowPass(shadows),
            _ => ShadowRoute::InShadingLoop(shadows),
        }
    }

    /// A debug view's route: its loop shows the rays' raw shares, unfiltered, and no pass
    /// follows it.
    pub fn for_debug_view(self) -> Self {
        match self {
            ShadowRoute::Off => ShadowRoute::Off,
            route => ShadowRoute::InShadingLoop(route.shadows().unfiltered()),
        }
    }

    /// This route, or why `requested` cannot take it in `pipeline`: a filter asked for
    /// where no pass follows the loop that would filter.
    pub fn refusing_unfollowed_filter(
        self,
        requested: Shadows,
        pipeline: &str,
    ) -> Result<Self, String> {
        if requested.spatially_filtered() && matches!(self, ShadowRoute::InShadingLoop(_)) {
            return Err(format!(
                "shadows `{requested}`: the spatial filter follows deferred's compute lighting \
                 paths (compute, tiles) and the forward pipelines' shadow pass, which traces \
                 one ray a pixel (`rays:1`); {pipeline} traces `{}` unfiltered",
                requested.unfiltered()
            ));
        }
        Ok(self)
    }

    /// The mode as requested (off where no ray is traced).
    pub fn shadows(&self) -> Shadows {
        match *self {
            ShadowRoute::Off => Shadows::Off,
            ShadowRoute::InShadingLoop(shadows)
            | ShadowRoute::ShadowPass(shadows)
            | ShadowRoute::ComputeLighting(shadows) => shadows,
        }
    }

    /// What a forward pipeline's shading loop is built for: the mode without its filter
    /// (the shadow pass filters).
    pub fn loop_shadows(&self) -> Shadows {
        self.shadows().unfiltered()
    }

    /// Whether rays are traced: the scene's BVH is built and bound.
    pub fn traced(&self) -> bool {
        *self != ShadowRoute::Off
    }

    /// Whether a forward pipeline's shadow pass follows the shading.
    pub fn in_shadow_pass(&self) -> bool {
        matches!(self, ShadowRoute::ShadowPass(_))
    }

    /// Whether the spatial filter (and, as the mode says, the history) follows the rays.
    pub fn filtered(&self) -> bool {
        match self {
            ShadowRoute::ShadowPass(shadows) | ShadowRoute::ComputeLighting(shadows) => {
                shadows.spatially_filtered()
            }
            ShadowRoute::Off | ShadowRoute::InShadingLoop(_) => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_forward_route_sends_one_ray_a_pixel_to_the_shadow_pass_only() {
        assert_eq!(ShadowRoute::forward(Shadows::Off), ShadowRoute::Off);
        assert_eq!(
            ShadowRoute::forward(Shadows::RaysTemporal(1)),
            ShadowRoute::ShadowPass(Shadows::RaysTemporal(1))
        );
        assert_eq!(
            ShadowRoute::forward(Shadows::Rays(4)),
            ShadowRoute::InShadingLoop(Shadows::Rays(4))
        );
        assert!(ShadowRoute::forward(Shadows::RaysSpatial(1)).filtered());
        assert!(!ShadowRoute::forward(Shadows::Rays(1)).filtered());
    }

    #[test]
    fn a_debug_view_traces_unfiltered_in_its_loop_and_is_not_refused() {
        let route = ShadowRoute::forward(Shadows::RaysSpatial(1)).for_debug_view();
        assert_eq!(route, ShadowRoute::InShadingLoop(Shadows::Rays(1)));
        assert!(!route.filtered());
        assert_eq!(ShadowRoute::Off.for_debug_view(), ShadowRoute::Off);
        // The refusal is asked of the shaded image's route, before the debug view's.
        let shaded = ShadowRoute::forward(Shadows::RaysSpatial(2));
        assert!(
            shaded
                .refusing_unfollowed_filter(Shadows::RaysSpatial(2), "naive")
                .is_err()
        );
    }
}
