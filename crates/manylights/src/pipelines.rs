//! Which pipeline shades a frame, with that pipeline's own settings: a frame cannot ask a
//! pipeline for what it does not have (a G-buffer view of Forward+, an unbounded falloff of
//! a clustered pipeline), so such requests fail where the settings are built, with the
//! reason, rather than inside a frame.

use manylights_cluster::{ClusterView, ClusteringSettings, FarField, GpuClusters};
use manylights_deferred::{
    DeferredPipeline, DeferredSettings, DeferredView, GBufferLayout, LightingPath,
};
use manylights_forward_plus::{ForwardPlusPipeline, ForwardPlusSettings};
use manylights_lights::{BoundedFalloff, Falloff};
use manylights_naive::{NaivePipeline, NaiveSettings};
use manylights_pipeline::{EarlyDepth, EveryLight, ShadingPipeline, ShadowRoute};
use manylights_visibility::Shadows;

/// How the renderer hands a pipeline what its [`ShadingPipeline::LightLists`] type names:
/// the renderer's cluster lists, prepared and assigned for the frame, or nothing.
pub(crate) trait FrameLightLists {
    /// Whether the renderer assigns lights to clusters for this pipeline's frames.
    const CLUSTERED: bool;

    fn from_clusters(clusters: &GpuClusters) -> &Self;
}

impl FrameLightLists for EveryLight {
    const CLUSTERED: bool = false;

    fn from_clusters(_: &GpuClusters) -> &Self {
        &EveryLight
    }
}

impl FrameLightLists for GpuClusters {
    const CLUSTERED: bool = true;

    fn from_clusters(clusters: &GpuClusters) -> &Self {
        clusters
    }
}

/// Whether `P`'s frames shade from cluster lists (from its type, not its settings).
fn clustered<P: ShadingPipeline>() -> bool
where
    P::LightLists: FrameLightLists,
{
    <P::LightLists as FrameLightLists>::CLUSTERED
}

/// The shading pipelines, by name (`naive`, `forward-plus`, `deferred`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum PipelineKind {
    /// Every fragment loops over every light: exact for any falloff, the reference.
    Naive,
    /// Clustered forward: each fragment shades its cluster's light list.
    ForwardPlus,
    /// Clustered deferred: a G-buffer pass, then lighting per pixel over its cluster.
    /// The default (with the compact G-buffer and tiles lighting): the fastest pipeline
    /// measured on every GPU we have.
    #[default]
    Deferred,
}

impl PipelineKind {
    pub const ALL: [PipelineKind; 3] = [
        PipelineKind::Naive,
        PipelineKind::ForwardPlus,
        PipelineKind::Deferred,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            PipelineKind::Naive => "naive",
            PipelineKind::ForwardPlus => "forward-plus",
            PipelineKind::Deferred => "deferred",
        }
    }
}

manylights_gpu::named_choice!(PipelineKind, "pipeline");

/// A pipeline and its settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum PipelineSettings {
    Naive(NaiveSettings),
    ForwardPlus(ForwardPlusSettings),
    Deferred(DeferredSettings),
}

impl Default for PipelineSettings {
    fn default() -> Self {
        PipelineSettings::Deferred(DeferredSettings::default())
    }
}

impl PipelineSettings {
    /// Naive forward with a falloff.
    pub fn naive(falloff: Falloff) -> Self {
        PipelineSettings::Naive(NaiveSettings { falloff })
    }

    /// Forward+ with its defaults (depth pre-pass, windowed falloff, no debug view).
    pub fn forward_plus() -> Self {
        PipelineSettings::ForwardPlus(ForwardPlusSettings::default())
    }

    /// Deferred in a layout and on a lighting path (windowed falloff, no debug view).
    pub fn deferred(layout: GBufferLayout, lighting: LightingPath) -> Self {
        PipelineSettings::Deferred(DeferredSettings {
            layout,
            lighting,
            ..Default::default()
        })
    }

    /// The default settings of a pipeline.
    pub fn of_kind(kind: PipelineKind) -> Self {
        match kind {
            PipelineKind::Naive => PipelineSettings::Naive(NaiveSettings::default()),
            PipelineKind::ForwardPlus => {
                PipelineSettings::ForwardPlus(ForwardPlusSettings::default())
            }
            PipelineKind::Deferred => PipelineSettings::Deferred(DeferredSettings::default()),
        }
    }

    pub fn kind(&self) -> PipelineKind {
        match self {
            PipelineSettings::Naive(_) => PipelineKind::Naive,
            PipelineSettings::ForwardPlus(_) => PipelineKind::ForwardPlus,
            PipelineSettings::Deferred(_) => PipelineKind::Deferred,
        }
    }

    pub fn falloff(&self) -> Falloff {
        match self {
            PipelineSettings::Naive(s) => s.falloff,
            PipelineSettings::ForwardPlus(s) => s.falloff.into(),
            PipelineSettings::Deferred(s) => s.falloff.into(),
        }
    }

    /// The same settings with another falloff, if this pipeline can render it.
    pub fn with_falloff(mut self, falloff: Falloff) -> Result<Self, String> {
        match &mut self {
            PipelineSettings::Naive(s) => s.falloff = falloff,
            PipelineSettings::ForwardPlus(s) => s.falloff = BoundedFalloff::try_from(falloff)?,
            PipelineSettings::Deferred(s) => s.falloff = BoundedFalloff::try_from(falloff)?,
        }
        Ok(self)
    }

    /// The falloff the image has: the pipeline's, or inverse-square where a far field
    /// completes a clustered pipeline's windowed falloff.
    pub fn rendered_falloff(&self) -> Falloff {
        match self.far_field() {
            Some(_) => Falloff::InverseSquare,
            None => self.falloff(),
        }
    }

    /// The same settings rendering `falloff`, with `far_field`. Naive renders any falloff
    /// exactly and has no far field. Forward+ and deferred render inverse-square only with
    /// a far field, and a far field only for inverse-square: it approximates what the
    /// windowed falloff leaves out beyond each radius, so windowed + far field =
    /// inverse-square.
    pub fn with_rendered_falloff(
        self,
        falloff: Falloff,
        far_field: Option<FarField>,
    ) -> Result<Self, String> {
        if let Some(far) = &far_field {
            far.validate()?;
        }
        let mut pipeline = match (falloff, far_field) {
            _ if !self.needs_clusters() => {
                if far_field.is_some() {
                    return Err(format!(
                        "the {} pipeline shades every light exactly: it has no far field",
                        self.kind()
                    ));
                }
                return self.with_falloff(falloff);
            }
            (Falloff::InverseSquare, Some(_)) => {
                self.with_falloff(Falloff::WindowedInverseSquare)?
            }
            (Falloff::InverseSquare, None) => {
                return Err(format!(
                    "the {} pipeline renders the unbounded inverse-square falloff only with a far field (lights are culled at their radius; the far field approximates the rest): add --far-field tree or --far-field stochastic",
                    self.kind()
                ));
            }
            (bounded, Some(_)) => {
                return Err(format!(
                    "a far field completes the windowed falloff to the unbounded inverse-square one, so it renders `--falloff inverse-square` only (not `{bounded}`)"
                ));
            }
            (bounded, None) => self.with_falloff(bounded)?,
        };
        if let Some(clustering) = pipeline.clustering_mut() {
            clustering.far_field = far_field;
        }
        Ok(pipeline)
    }

    /// [`Self::with_rendered_falloff`] for a falloff as the command line and the lab name
    /// it: with a far field, the windowed falloff the far field completes stands for the
    /// inverse-square one it renders; any other falloff is passed on (and refused with a
    /// far field).
    pub fn with_asked_falloff(
        self,
        falloff: Falloff,
        far_field: Option<FarField>,
    ) -> Result<Self, String> {
        let rendered = match (falloff, far_field) {
            (Falloff::WindowedInverseSquare, Some(_)) => Falloff::InverseSquare,
            (asked, _) => asked,
        };
        self.with_rendered_falloff(rendered, far_field)
    }

    /// The light lists' settings of a clustered pipeline (`None`: naive, which shades
    /// every light).
    pub fn clustering(&self) -> Option<&ClusteringSettings> {
        match self {
            PipelineSettings::Naive(_) => None,
            PipelineSettings::ForwardPlus(s) => Some(&s.clustering),
            PipelineSettings::Deferred(s) => Some(&s.clustering),
        }
    }

    /// [`Self::clustering`], to change.
    pub fn clustering_mut(&mut self) -> Option<&mut ClusteringSettings> {
        match self {
            PipelineSettings::Naive(_) => None,
            PipelineSettings::ForwardPlus(s) => Some(&mut s.clustering),
            PipelineSettings::Deferred(s) => Some(&mut s.clustering),
        }
    }

    /// The same settings building their light lists with `clustering` (naive, which has
    /// none, is returned as it is).
    pub fn with_clustering(mut self, clustering: ClusteringSettings) -> Self {
        if let Some(lists) = self.clustering_mut() {
            *lists = clustering;
        }
        self
    }

    /// Asks a clustered pipeline for its lists' statistics (`lists`) and, with them, the
    /// false-positive ratio; naive has no lists to count, and is left as it is.
    pub fn set_list_statistics(&mut self, lists: bool, false_positives: bool) {
        if let Some(clustering) = self.clustering_mut() {
            clustering.stats = lists;
            clustering.false_positives = false_positives;
        }
    }

    /// Whether the frame counts its light lists' statistics.
    pub fn counts_list_statistics(&self) -> bool {
        self.clustering().is_some_and(|clustering| clustering.stats)
    }

    /// The far field of a clustered pipeline's lists, if it has one.
    pub fn far_field(&self) -> Option<FarField> {
        self.clustering()
            .and_then(|clustering| clustering.far_field)
    }

    /// The far field when it is a light tree the frame cuts (what a budget's slots move).
    pub fn tree_far_field(&self) -> Option<FarField> {
        self.far_field()
            .filter(|far| far.method == manylights_cluster::FarFieldMethod::Tree)
    }

    /// Another pipeline's default settings, keeping the falloff where it can, the light
    /// lists' settings and the cluster views the two share (how the viewer switches
    /// pipelines).
    pub fn switched_to(&self, kind: PipelineKind) -> Self {
        let mut switched = Self::of_kind(kind);
        // Naive renders exactly what a far field approximates.
        let falloff = match switched.needs_clusters() {
            true => self.falloff(),
            false => self.rendered_falloff(),
        };
        if let Ok(with_falloff) = switched.with_falloff(falloff) {
            switched = with_falloff;
        }
        if let (Some(kept), Some(clustering)) = (self.clustering(), switched.clustering_mut()) {
            *clustering = *kept;
        }
        if let Some(view) = self.cluster_view() {
            match &mut switched {
                PipelineSettings::ForwardPlus(s) => s.debug_view = Some(view),
                PipelineSettings::Deferred(s) => s.debug_view = Some(DeferredView::Cluster(view)),
                PipelineSettings::Naive(_) => {}
            }
        }
        switched
    }

    /// The cluster debug view these settings draw, if any.
    pub fn cluster_view(&self) -> Option<ClusterView> {
        match self {
            PipelineSettings::ForwardPlus(s) => s.debug_view,
            PipelineSettings::Deferred(DeferredSettings {
                debug_view: Some(DeferredView::Cluster(view)),
                ..
            }) => Some(*view),
            _ => None,
        }
    }

    /// The debug view the frame draws ([`DebugView::NONE`] when it is shaded).
    pub fn debug_view(&self) -> DebugView {
        match self {
            PipelineSettings::Naive(_) => DebugView::NONE,
            PipelineSettings::ForwardPlus(s) => DebugView(s.debug_view.map(DeferredView::Cluster)),
            PipelineSettings::Deferred(s) => DebugView(s.debug_view),
        }
    }

    /// The debug view's name (`None` when the frame is shaded).
    pub fn debug_view_name(&self) -> Option<String> {
        self.debug_view().0.map(|view| view.to_string())
    }

    /// The same settings showing `view`, if this pipeline has it.
    pub fn with_debug_view(mut self, view: DebugView) -> Result<Self, String> {
        match (&mut self, view.0) {
            (PipelineSettings::Naive(_), None) => {}
            (PipelineSettings::Naive(_), Some(view)) => {
                return Err(format!(
                    "the naive pipeline has no clusters or G-buffer to show (`{view}`)"
                ));
            }
            (PipelineSettings::ForwardPlus(s), None) => s.debug_view = None,
            (PipelineSettings::ForwardPlus(s), Some(DeferredView::Cluster(view))) => {
                s.debug_view = Some(view);
            }
            (PipelineSettings::ForwardPlus(_), Some(view @ DeferredView::GBuffer(_))) => {
                return Err(format!(
                    "Forward+ has no `{view}` view: it has no G-buffer (its views are heatmap, slices and evaluations; G-buffer channels are the deferred pipeline's)"
                ));
            }
            (PipelineSettings::Deferred(s), view) => s.debug_view = view,
        }
        Ok(self)
    }

    /// [`Self::with_debug_view`] by the view's name (`none` for the shaded image).
    pub fn with_debug_view_named(self, name: &str) -> Result<Self, String> {
        self.with_debug_view(name.parse()?)
    }

    /// Whether frames assign lights to clusters first (the pipeline's
    /// [`ShadingPipeline::LightLists`] are cluster lists).
    pub fn needs_clusters(&self) -> bool {
        match self {
            PipelineSettings::Naive(_) => clustered::<NaivePipeline>(),
            PipelineSettings::ForwardPlus(_) => clustered::<ForwardPlusPipeline>(),
            PipelineSettings::Deferred(_) => clustered::<DeferredPipeline>(),
        }
    }

    /// What the depth target holds before the lights are assigned.
    pub fn early_depth(&self) -> EarlyDepth {
        match self {
            PipelineSettings::Naive(s) => NaivePipeline::early_depth(s),
            PipelineSettings::ForwardPlus(s) => ForwardPlusPipeline::early_depth(s),
            PipelineSettings::Deferred(s) => DeferredPipeline::early_depth(s),
        }
    }

    /// Where the pipeline traces `shadows` with these settings and what follows the rays
    /// (each pipeline's [`ShadingPipeline::shadow_route`]), or why it cannot.
    pub fn shadow_route(&self, shadows: Shadows) -> Result<ShadowRoute, String> {
        match self {
            PipelineSettings::Naive(s) => NaivePipeline::shadow_route(s, shadows),
            PipelineSettings::ForwardPlus(s) => ForwardPlusPipeline::shadow_route(s, shadows),
            PipelineSettings::Deferred(s) => DeferredPipeline::shadow_route(s, shadows),
        }
    }

    /// Whether the frame shows a debug view (drawn as is: no exposure, no tonemap).
    pub fn shows_debug_view(&self) -> bool {
        match self {
            PipelineSettings::Naive(s) => NaivePipeline::shows_debug_view(s),
            PipelineSettings::ForwardPlus(s) => ForwardPlusPipeline::shows_debug_view(s),
            PipelineSettings::Deferred(s) => DeferredPipeline::shows_debug_view(s),
        }
    }

    /// Sets the heatmap's white point where the settings show the heatmap.
    pub fn with_heatmap_max(mut self, max_lights: f32) -> Self {
        let set = |view: &mut ClusterView| {
            if let ClusterView::Heatmap { max_lights: m } = view {
                *m = max_lights;
            }
        };
        match &mut self {
            PipelineSettings::ForwardPlus(ForwardPlusSettings {
                debug_view: Some(view),
                ..
            }) => set(view),
            PipelineSettings::Deferred(DeferredSettings {
                debug_view: Some(DeferredView::Cluster(view)),
                ..
            }) => set(view),
            _ => {}
        }
        self
    }

    /// A short description, e.g. `deferred compact compute` or `forward-plus (heatmap)`.
    pub fn describe(&self) -> String {
        let base = match self {
            PipelineSettings::Deferred(s) => format!("deferred {} {}", s.layout, s.lighting),
            PipelineSettings::ForwardPlus(s) if !s.depth_prepass => {
                "forward-plus (no pre-pass)".to_string()
            }
            other => other.kind().to_string(),
        };
        match self.debug_view_name() {
            Some(view) => format!("{base} ({view})"),
            None => base,
        }
    }
}

/// What a frame draws instead of the shaded image, by name: `none`, a cluster view
/// (`heatmap`, `slices`, `evaluations`: Forward+ and deferred) or a G-buffer channel
/// (`albedo`, `normal`, `depth`, `position`: deferred only). Which pipeline has which view is
/// [`PipelineSettings::with_debug_view`]'s to say.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub struct DebugView(pub Option<DeferredView>);

impl DebugView {
    /// The shaded image.
    pub const NONE: DebugView = DebugView(None);
}

impl std::fmt::Display for DebugView {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            None => f.write_str("none"),
            Some(view) => view.fmt(f),
        }
    }
}

impl std::str::FromStr for DebugView {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        if text == "none" {
            return Ok(DebugView::NONE);
        }
        text.parse().map(|view| DebugView(Some(view))).map_err(|_| {
            format!(
                "unknown debug view `{text}`: expected none, heatmap, slices, evaluations, albedo, normal, depth or position"
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for kind in PipelineKind::ALL {
            assert_eq!(kind.to_string().parse::<PipelineKind>(), Ok(kind));
        }
    }

    /// With a far field, the windowed falloff stands for the inverse-square one it is
    /// completed to; another bounded falloff with a far field is still refused.
    #[test]
    fn an_asked_windowed_falloff_with_a_far_field_renders_inverse_square() {
        use manylights_cluster::FarFieldMethod;
        let far = Some(FarField::new(FarFieldMethod::Tree));
        let asked = PipelineSettings::default()
            .with_asked_falloff(Falloff::WindowedInverseSquare, far)
            .expect("windowed with a far field");
        assert_eq!(asked.rendered_falloff(), Falloff::InverseSquare);
        assert_eq!(asked.far_field(), far);
        assert!(
            PipelineSettings::default()
                .with_asked_falloff(Falloff::ReferenceProjects, far)
                .is_err()
        );
        assert!(
            PipelineSettings::naive(Falloff::InverseSquare)
                .with_asked_falloff(Falloff::WindowedInverseSquare, far)
                .is_err()
        );
    }

    #[test]
    fn clustered_pipelines_refuse_the_unbounded_falloff() {
        for kind in [PipelineKind::ForwardPlus, PipelineKind::Deferred] {
            let error = PipelineSettings::of_kind(kind)
                .with_falloff(Falloff::InverseSquare)
                .expect_err("refused");
            assert!(error.contains("naive"), "{error}");
        }
        assert!(
            PipelineSettings::of_kind(PipelineKind::Naive)
                .with_falloff(Falloff::InverseSquare)
                .is_ok()
        );
    }

    #[test]
    fn views_only_where_the_pipeline_has_them() {
        let naive = PipelineSettings::of_kind(PipelineKind::Naive);
        assert!(naive.with_debug_view_named("heatmap").is_err());
        assert!(naive.with_debug_view_named("none").is_ok());
        let forward_plus = PipelineSettings::of_kind(PipelineKind::ForwardPlus);
        assert!(forward_plus.with_debug_view_named("albedo").is_err());
        assert!(forward_plus.with_debug_view_named("slices").is_ok());
        let deferred = PipelineSettings::of_kind(PipelineKind::Deferred);
        for name in [
            "heatmap",
            "slices",
            "evaluations",
            "albedo",
            "normal",
            "depth",
            "position",
        ] {
            let with_view = deferred.with_debug_view_named(name).expect(name);
            assert_eq!(with_view.debug_view_name().as_deref(), Some(name));
        }
    }

    #[test]
    fn switching_keeps_what_both_pipelines_have() {
        let heatmap = PipelineSettings::of_kind(PipelineKind::Deferred)
            .with_falloff(Falloff::ReferenceProjects)
            .and_then(|s| s.with_debug_view_named("heatmap"))
            .expect("settings");
        let forward_plus = heatmap.switched_to(PipelineKind::ForwardPlus);
        assert_eq!(forward_plus.falloff(), Falloff::ReferenceProjects);
        assert_eq!(forward_plus.debug_view_name().as_deref(), Some("heatmap"));
        let naive = heatmap.switched_to(PipelineKind::Naive);
        assert_eq!(naive.debug_view_name(), None);
    }
}
