//! The matrix's presets: the workloads the issues measured, by name (`bench --preset`).

use anyhow::bail;

use super::matrix::{Assignment, BenchMatrix, GridSpec};
use super::setting_axes::SettingAxes;
use indexmap::IndexMap;
use manylights::cluster::{
    AssignmentDesign, ClusterBoxes, ClusterSettings, FarField, FarFieldMethod, OptionalFarField,
    SpotCulling,
};
use manylights::lights::Shading;
use manylights::{GBufferLayout, ImageSize, LightingPath, PipelineKind, Transparency};

impl BenchMatrix {
    /// `reference`: the reference projects' workload (Sponza, lights in (-10,0,-5) to
    /// (10,8,5), radius 2, 1920x1080, 500 to 5,000 lights), every pipeline and layout.
    pub fn reference() -> Self {
        Self {
            lights: vec![500, 1000, 2000, 5000],
            sizes: vec![ImageSize::new(1920, 1080)],
            gbuffers: GBufferLayout::ALL.to_vec(),
            lighting: LightingPath::ALL.to_vec(),
            ..Self::default()
        }
    }

    /// `assignment`: the light assignment's cost against light count (Sponza, 1920x1080,
    /// radius 2 m, deferred compact/compute, 1,000 to 1,000,000 lights), today's design
    /// beside the grid's boxes and the first design (atomic fill and sort).
    pub fn assignment() -> Self {
        Self {
            pipelines: vec![PipelineKind::Deferred],
            lights: vec![1000, 5000, 20_000, 100_000, 1_000_000],
            sizes: vec![ImageSize::new(1920, 1080)],
            assignments: vec![
                Assignment::default(),
                Assignment::new(AssignmentDesign::TileMasks, ClusterBoxes::Grid),
                Assignment::new(AssignmentDesign::AtomicFill, ClusterBoxes::Grid),
            ],
            naive_light_limit: 0,
            reference_light_limit: 0,
            reference_samples: 64,
            ..Self::default()
        }
    }

    /// `scale`: up to 200,000 lights, in Sponza and in the pillars scene grown to 8.4
    /// million triangles, across light thresholds and grids.
    pub fn scale() -> Self {
        Self {
            scenes: vec!["sponza".into(), "pillars:32x64".into()],
            lights: vec![1000, 10_000, 50_000, 200_000],
            sizes: vec![ImageSize::new(1920, 1080)],
            grids: vec![
                GridSpec::default(),
                GridSpec {
                    tiles_x: 32,
                    tiles_y: 18,
                    slices: 64,
                    scheme: ClusterSettings::default().z_scheme,
                },
            ],
            thresholds: vec![0.05, 0.2],
            naive_light_limit: 5000,
            reference_light_limit: 5000,
            ..Self::default()
        }
    }

    /// `far-field`: the unbounded image approached by the radius alone and by each far-field
    /// method (Sponza, 1920x1080, 5,000 lights, deferred compact/compute, radius 1 to 14.1 m),
    /// every error against the unbounded reference.
    pub fn far_field() -> Self {
        Self {
            pipelines: vec![PipelineKind::Deferred],
            lights: vec![5000],
            sizes: vec![ImageSize::new(1920, 1080)],
            // Radius sqrt(0.2 / threshold): 1, 2, 4, 6.3, 14.1 m.
            thresholds: vec![0.2, 0.05, 0.0125, 0.005, 0.001],
            far_fields: std::iter::once(OptionalFarField(None))
                .chain(
                    [
                        (FarFieldMethod::Tree, 0.3),
                        (FarFieldMethod::Tree, 0.1),
                        (FarFieldMethod::Tree, 0.03),
                        (FarFieldMethod::Stochastic, 4.0),
                        (FarFieldMethod::Stochastic, 1.0),
                        (FarFieldMethod::Stochastic, 0.25),
                    ]
                    .map(|(method, tolerance)| {
                        OptionalFarField(Some(FarField {
                            tolerance,
                            ..FarField::new(method)
                        }))
                    }),
                )
                .collect(),
            ..Self::default()
        }
    }

    /// `spots`: point lights against half of them spots (Sponza, 1920x1080, 5,000 and
    /// 100,000 lights, every pipeline; spots culled by their cone and by their range
    /// sphere, to measure the cone test's false positives).
    pub fn spots() -> Self {
        Self {
            lights: vec![5000, 100_000],
            sizes: vec![ImageSize::new(1920, 1080)],
            spot_fractions: vec![0.0, 0.5],
            spot_cullings: SpotCulling::ALL.to_vec(),
            ..Self::default()
        }
    }

    /// `materials`: the price of glTF's metallic-roughness against Blinn-Phong (Sponza,
    /// 1920x1080, 5,000 and 100,000 lights, Forward+ and deferred on every G-buffer layout
    /// with the default tiles lighting): the lighting pass's time, the light loop's rate and
    /// the G-buffer's bytes and time per layout, with each BRDF.
    pub fn materials() -> Self {
        Self {
            pipelines: vec![PipelineKind::ForwardPlus, PipelineKind::Deferred],
            lights: vec![5000, 100_000],
            sizes: vec![ImageSize::new(1920, 1080)],
            gbuffers: GBufferLayout::ALL.to_vec(),
            shadings: Shading::ALL.to_vec(),
            ..Self::default()
        }
    }

    /// `shadows`: shadows off, exact and with a ray budget of 1, 2 and 4 rays a pixel,
    /// unfiltered, filtered spatially, and filtered and accumulated over frames (Sponza,
    /// 1920x1080, 1,000 to 1,000,000 lights, deferred compact/tiles with the tree far field
    /// at tolerance 0.1, intensity 0.002): each against the reference with its own
    /// visibility (off against the unshadowed one), its error split in shadow and in
    /// light, its flicker and its lag.
    pub fn shadows() -> Self {
        Self {
            pipelines: vec![PipelineKind::Deferred],
            lights: vec![1000, 5000, 100_000, 1_000_000],
            sizes: vec![ImageSize::new(1920, 1080)],
            intensity: 0.002,
            far_fields: vec![OptionalFarField(Some(FarField {
                tolerance: 0.1,
                ..FarField::new(FarFieldMethod::Tree)
            }))],
            shadows: manylights::Shadows::ALL.to_vec(),
            naive_light_limit: 0,
            reference_light_limit: 0,
            ..Self::default()
        }
    }

    /// What the reference projects ask of a pipeline (issue 45): where Forward+ wins. Each
    /// pipeline, inside the castle and outside it, without and with blended banners and
    /// embers (`sponza-glass`, sorted and weighted), without and with MSAA (4x, 8x: Forward+
    /// and naive; deferred refuses it), at 1,000 and 10,000 lights.
    pub fn trade_offs() -> Self {
        Self {
            scenes: vec!["sponza".into(), "sponza-glass".into()],
            views: vec!["reference".into(), "outside".into()],
            lights: vec![1000, 10_000],
            sizes: vec![ImageSize::new(1920, 1080)],
            settings: SettingAxes(IndexMap::from([
                ("view.msaa".to_string(), vec![1.into(), 4.into(), 8.into()]),
                (
                    "transparency".to_string(),
                    Transparency::ALL.map(|t| t.name().into()).to_vec(),
                ),
            ])),
            naive_light_limit: 1000,
            reference_light_limit: 1000,
            reference_samples: 512,
            // Measured (issue 45) before sponza-glass's embers emitted and were lights.
            emissive_lights: false,
            ..Self::default()
        }
    }

    pub fn preset(name: &str) -> anyhow::Result<Self> {
        match name {
            "trade-offs" => Ok(Self::trade_offs()),
            "shadows" => Ok(Self::shadows()),
            "materials" => Ok(Self::materials()),
            "reference" => Ok(Self::reference()),
            "scale" => Ok(Self::scale()),
            "assignment" => Ok(Self::assignment()),
            "far-field" => Ok(Self::far_field()),
            "spots" => Ok(Self::spots()),
            other => {
                bail!(
                    "unknown preset '{other}' (reference, scale, assignment, far-field, spots, materials, shadows, trade-offs)"
                )
            }
        }
    }
}
