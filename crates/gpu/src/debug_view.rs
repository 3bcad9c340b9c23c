//! What a frame shows instead of (or as) the lit image: the debug views every pipeline
//! shares the vocabulary of. Pipelines that cannot draw a view refuse it.

/// A debug view (`DEBUG_*` in `shaders/cluster/cluster_lights.wgsl`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum DebugView {
    /// The lit, tonemapped image.
    #[default]
    None,
    /// Lights per cluster: black (0) through blue, cyan, green, yellow, red to white
    /// (`max_lights` or more); the strip at the bottom is the legend, ticks at quarters.
    ClusterHeatmap {
        max_lights: f32,
    },
    /// Each depth slice in its own colour, tiles in a checkerboard.
    ZSlices,
    /// G-buffer channels (deferred only): albedo, normal (as 0.5 + 0.5 n), view depth
    /// (1 m per shade step of a 16 m ramp), world position (fractional metres).
    Albedo,
    Normal,
    Depth,
    Position,
    /// Clustered pipelines: how many lights each pixel evaluated, in every channel of the
    /// HDR target (the shading loop's own count: tests hold it equal to the pixel's cluster
    /// list length).
    LightEvaluations,
}

impl DebugView {
    pub fn shader_code(&self) -> u32 {
        match self {
            DebugView::None => 0,
            DebugView::ClusterHeatmap { .. } => 1,
            DebugView::ZSlices => 2,
            DebugView::Albedo => 3,
            DebugView::Normal => 4,
            DebugView::Depth => 5,
            DebugView::Position => 6,
            DebugView::LightEvaluations => 7,
        }
    }

    pub fn is_cluster_view(&self) -> bool {
        matches!(
            self,
            DebugView::ClusterHeatmap { .. } | DebugView::ZSlices | DebugView::LightEvaluations
        )
    }

    pub fn is_gbuffer_view(&self) -> bool {
        matches!(
            self,
            DebugView::Albedo | DebugView::Normal | DebugView::Depth | DebugView::Position
        )
    }

    /// Light count shown as white in the heatmap (1 otherwise).
    pub fn heatmap_max(&self) -> f32 {
        match self {
            DebugView::ClusterHeatmap { max_lights } => max_lights.max(1.0),
            _ => 1.0,
        }
    }
}
