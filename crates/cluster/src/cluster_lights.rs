//! The group-3 resources of every clustered shading pass (`shaders/cluster/cluster_lights.wgsl`):
//! grid, list offsets, light indices, lights, the shading parameters, and (for clusters
//! whose list overflowed) the view-space lights and the clusters' boxes. Forward+ and the
//! deferred lighting passes share this layout and the function that shades a cluster.

use manylights_gpu::ShaderDef;
use manylights_lights::{Falloff, LightKinds, Shading};
use manylights_visibility::Shadows;

use crate::assign::GpuClusters;
use crate::far_field::FarFieldMethod;

/// A cluster debug view: what a clustered pipeline draws instead of the shaded image
/// (written into the HDR target and shown without tonemapping).
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum ClusterView {
    /// Lights per cluster: black (0) through blue, cyan, green, yellow, red to white
    /// (`max_lights` or more); the strip at the bottom is the legend, ticks at quarters.
    Heatmap { max_lights: f32 },
    /// Each depth slice in its own colour, tiles in a checkerboard.
    Slices,
    /// How many lights each pixel evaluated, in every channel (the shading loop's own
    /// count: tests hold it equal to the pixel's cluster list length).
    LightEvaluations,
}

/// Light count shown as white in the heatmap unless chosen.
pub const DEFAULT_HEATMAP_MAX: f32 = 64.0;

impl ClusterView {
    pub const ALL: [ClusterView; 3] = [
        ClusterView::Heatmap {
            max_lights: DEFAULT_HEATMAP_MAX,
        },
        ClusterView::Slices,
        ClusterView::LightEvaluations,
    ];

    /// Its code in `ClusteredShadingParams::debug_view` (the `CLUSTER_VIEW_*` shader defs).
    pub fn shader_code(&self) -> u32 {
        match self {
            ClusterView::Heatmap { .. } => 1,
            ClusterView::Slices => 2,
            ClusterView::LightEvaluations => 3,
        }
    }

    fn def_name(&self) -> &'static str {
        match self {
            ClusterView::Heatmap { .. } => "CLUSTER_VIEW_HEATMAP",
            ClusterView::Slices => "CLUSTER_VIEW_SLICES",
            ClusterView::LightEvaluations => "CLUSTER_VIEW_LIGHT_EVALUATIONS",
        }
    }

    /// The shader defs that give `cluster_lights.wgsl` the views' codes (among the
    /// crate's constants, which every program composed with its WGSL gets).
    pub(crate) fn shader_defs() -> Vec<(String, ShaderDef)> {
        Self::ALL
            .iter()
            .map(|view| {
                (
                    view.def_name().to_string(),
                    ShaderDef::UInt(view.shader_code()),
                )
            })
            .collect()
    }

    /// Light count shown as white in the heatmap (1 for other views).
    pub fn heatmap_max(&self) -> f32 {
        match self {
            ClusterView::Heatmap { max_lights } => max_lights.max(1.0),
            _ => 1.0,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            ClusterView::Heatmap { .. } => "heatmap",
            ClusterView::Slices => "slices",
            ClusterView::LightEvaluations => "evaluations",
        }
    }
}

manylights_gpu::named_choice!(ClusterView, "cluster view");

/// Codes from this one up are free for a pipeline's own debug views (the deferred
/// G-buffer channels); [`ClusterView`] codes stay below.
pub const FIRST_PIPELINE_VIEW_CODE: u32 = 16;

/// What a clustered shading pass outputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShadingOutput {
    /// The shaded image.
    Shaded,
    /// A cluster debug view.
    Cluster(ClusterView),
    /// A pipeline's own view, by its code (at least [`FIRST_PIPELINE_VIEW_CODE`]).
    Pipeline(u32),
}

impl ShadingOutput {
    /// Its code, `LOOP_OUTPUT` in cluster_lights.wgsl.
    pub fn shader_code(&self) -> u32 {
        match self {
            ShadingOutput::Shaded => 0,
            ShadingOutput::Cluster(view) => view.shader_code(),
            ShadingOutput::Pipeline(code) => *code,
        }
    }
}

/// Which light loop a clustered shading program runs: the settings that would otherwise
/// be branches taken at every pixel and light (the falloff, the far field's method, the
/// output, shadows, whether any light is a spot, whether any material is specular) made
/// constants of the program, so a frame
/// runs only the code its settings and lights use. Forward+ and deferred compose their
/// shading programs once per loop a frame asks for ([`LightLoop::shader_defs`]) and keep
/// them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LightLoop {
    falloff: Falloff,
    far_field: Option<FarFieldMethod>,
    output: u32,
    shadows: Shadows,
    /// No light of the frame is a spot or an area light: the cone's and the areas' code
    /// is left out (`POINT_LIGHTS_ONLY`).
    point_lights_only: bool,
    /// No light of the frame is an area light: the areas' code is left out
    /// (`NO_AREA_LIGHTS`), so frames of spots run the loop they ran before area lights.
    no_area_lights: bool,
    /// No material of the scene has a specular colour: the half vector and the specular
    /// power are left out, and the albedo multiplies each pixel's sum once instead of every
    /// light's term (`DIFFUSE_ONLY`). The OBJ Sponza's materials are all diffuse (Ks 0); the
    /// glTF Sponza's dielectrics reflect 4% (F0 0.04), so its frames keep the specular code.
    /// Blinn-Phong only: PBR's Fresnel reflects from every material.
    diffuse_only: bool,
    /// The BRDF (`SHADING_PBR`).
    shading: Shading,
}

impl LightLoop {
    /// The loop shading lights of `kinds` (without the code of the kinds absent) with
    /// `shading`'s BRDF on a scene whose materials have a Blinn-Phong specular colour or
    /// not (`specular`: without, Blinn-Phong programs leave out the specular code) with
    /// `falloff`, the far field of `clusters`' frame and `shadows`, writing `output`.
    pub fn for_frame(
        clusters: &GpuClusters,
        kinds: LightKinds,
        shading: Shading,
        specular: bool,
        falloff: Falloff,
        output: ShadingOutput,
        shadows: Shadows,
    ) -> Self {
        let far_field = clusters.far_field().settings().map(|far| far.method);
        // Debug views show the rays' raw shares: the filter is for the shaded image.
        let shadows = if output == ShadingOutput::Shaded {
            shadows
        } else {
            shadows.unfiltered()
        };
        Self {
            point_lights_only: !kinds.shaped,
            no_area_lights: !kinds.area,
            diffuse_only: !specular,
            ..Self::new(falloff, far_field, output).with_shadows(shadows)
        }
        .with_shading(shading)
    }

    /// This loop with `shading`'s BRDF (a PBR loop is never diffuse-only).
    pub fn with_shading(self, shading: Shading) -> Self {
        Self {
            shading,
            diffuse_only: self.diffuse_only && shading == Shading::BlinnPhong,
            ..self
        }
    }

    /// Whether the loop outputs the shaded image (not a debug view).
    pub fn shades(&self) -> bool {
        self.output == ShadingOutput::Shaded.shader_code()
    }

    /// The loop blended surfaces run beside this frame's (`None` where it draws a debug
    /// view: the clusters or the G-buffer alone): its shadows unfiltered, as the shadow
    /// filter reads the opaque surface.
    pub fn for_blended(self) -> Option<LightLoop> {
        self.shades()
            .then(|| self.with_shadows(self.shadows.unfiltered()))
    }

    /// A loop without shadows.
    pub fn new(falloff: Falloff, far_field: Option<FarFieldMethod>, output: ShadingOutput) -> Self {
        Self {
            falloff,
            far_field,
            output: output.shader_code(),
            shadows: Shadows::Off,
            point_lights_only: false,
            no_area_lights: false,
            diffuse_only: false,
            shading: Shading::default(),
        }
    }

    /// This loop with `shadows`.
    pub fn with_shadows(self, shadows: Shadows) -> Self {
        Self { shadows, ..self }
    }

    /// How the loop's shadows are traced.
    /// Whether the loop reads the far field (its programs bind the far field's buffers).
    pub fn has_far_field(&self) -> bool {
        self.far_field.is_some()
    }

    pub fn shadows(&self) -> Shadows {
        self.shadows
    }

    /// The shaded image with the default falloff and no far field (the loop of a program
    /// that only writes depth: it never runs it).
    pub fn plain() -> Self {
        Self::new(Falloff::default(), None, ShadingOutput::Shaded)
    }

    /// The shader defs that make this loop (`LIGHT_LOOP_*` in cluster_lights.wgsl): every
    /// program importing cluster_lights.wgsl is composed with one loop's.
    pub fn shader_defs(&self) -> Vec<(String, ShaderDef)> {
        let mut defs = vec![
            (
                "LIGHT_LOOP_FALLOFF".to_string(),
                ShaderDef::UInt(self.falloff.shader_mode()),
            ),
            (
                "LIGHT_LOOP_OUTPUT".to_string(),
                ShaderDef::UInt(self.output),
            ),
        ];
        let far_def = match self.far_field {
            None => None,
            Some(FarFieldMethod::Tree) => Some("LIGHT_LOOP_FAR_TREE"),
            Some(FarFieldMethod::Stochastic) => Some("LIGHT_LOOP_FAR_STOCHASTIC"),
        };
        defs.extend(far_def.map(|name| (name.to_string(), ShaderDef::Bool(true))));
        if self.shadows.traced() {
            defs.push(("LIGHT_LOOP_SHADOWS".to_string(), ShaderDef::Bool(true)));
        }
        defs.extend(self.shadows.shader_defs());
        if self.point_lights_only {
            defs.push(("POINT_LIGHTS_ONLY".to_string(), ShaderDef::Bool(true)));
        }
        if self.point_lights_only || self.no_area_lights {
            defs.push(("NO_AREA_LIGHTS".to_string(), ShaderDef::Bool(true)));
        }
        if self.diffuse_only {
            defs.push(("DIFFUSE_ONLY".to_string(), ShaderDef::Bool(true)));
        }
        defs.extend(manylights_gpu::shading_defs(self.shading));
        defs
    }

    /// For labels and logs: `windowed falloff, far field tree, output 1`.
    pub fn label(&self) -> String {
        let far = self.far_field.map_or("no far field".to_string(), |method| {
            format!("far field {method}")
        });
        let lights = if self.point_lights_only {
            "point lights"
        } else if self.no_area_lights {
            "point and spot lights"
        } else {
            "point, spot and area lights"
        };
        let materials = if self.diffuse_only {
            "diffuse"
        } else {
            "diffuse and specular"
        };
        let materials = format!("{materials} {}", self.shading);
        format!(
            "{} falloff, {far}, output {}, shadows {}, {lights}, {materials} materials",
            self.falloff, self.output, self.shadows
        )
    }

    /// Loops in which every falloff, far-field method (and none) and every one of
    /// `outputs` appears at least once: what shader validation composes (the axes are
    /// independent blocks of code, so their full product adds nothing but time).
    pub fn covering(outputs: &[ShadingOutput]) -> Vec<Self> {
        let falloffs = [
            Falloff::WindowedInverseSquare,
            Falloff::ReferenceProjects,
            Falloff::InverseSquare,
        ];
        let far_fields = [
            None,
            Some(FarFieldMethod::Tree),
            Some(FarFieldMethod::Stochastic),
        ];
        let shaded = [ShadingOutput::Shaded];
        let outputs = if outputs.is_empty() {
            &shaded[..]
        } else {
            outputs
        };
        let count = falloffs.len().max(far_fields.len()).max(outputs.len());
        let mut loops: Vec<Self> = (0..count)
            .map(|i| {
                Self::new(
                    falloffs[i % falloffs.len()],
                    far_fields[i % far_fields.len()],
                    outputs[i % outputs.len()],
                )
            })
            .collect();
        // Exact shadows and a ray budget, with every far field (each traces its own rays).
        loops.extend(far_fields.into_iter().flat_map(|far_field| {
            [Shadows::Exact, Shadows::Rays(4)].map(|shadows| {
                Self::new(Falloff::default(), far_field, ShadingOutput::Shaded)
                    .with_shadows(shadows)
            })
        }));
        // Point lights only and diffuse Blinn-Phong materials only, with every far field and
        // shadows.
        loops.extend(far_fields.map(|far_field| Self {
            point_lights_only: true,
            diffuse_only: true,
            shading: Shading::BlinnPhong,
            ..Self::new(Falloff::default(), far_field, ShadingOutput::Shaded)
        }));
        loops.push(Self {
            point_lights_only: true,
            diffuse_only: true,
            shading: Shading::BlinnPhong,
            ..Self::new(Falloff::default(), None, ShadingOutput::Shaded)
                .with_shadows(Shadows::Exact)
        });
        // Blinn-Phong with specular materials, every far field and shadows (the loops above
        // are PBR's).
        loops.extend(far_fields.map(|far_field| {
            Self::new(Falloff::default(), far_field, ShadingOutput::Shaded)
                .with_shadows(Shadows::Exact)
                .with_shading(Shading::BlinnPhong)
        }));
        loops
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covering_loops_hold_every_falloff_far_field_and_output() {
        let outputs = [
            ShadingOutput::Shaded,
            ShadingOutput::Cluster(ClusterView::Slices),
            ShadingOutput::Pipeline(FIRST_PIPELINE_VIEW_CODE),
        ];
        let loops = LightLoop::covering(&outputs);
        for falloff in Falloff::ALL {
            assert!(loops.iter().any(|l| l.falloff == falloff), "{falloff}");
        }
        for far_field in [
            None,
            Some(FarFieldMethod::Tree),
            Some(FarFieldMethod::Stochastic),
        ] {
            assert!(
                loops.iter().any(|l| l.far_field == far_field),
                "{far_field:?}"
            );
        }
        for output in outputs {
            let code = output.shader_code();
            assert!(loops.iter().any(|l| l.output == code), "{output:?}");
        }
        for shading in Shading::ALL {
            assert!(loops.iter().any(|l| l.shading == shading), "{shading}");
        }
    }

    #[test]
    fn each_setting_of_the_loop_is_a_def_and_only_a_far_field_adds_one() {
        let defs = |l: LightLoop| -> Vec<String> {
            l.shader_defs().into_iter().map(|(name, _)| name).collect()
        };
        assert_eq!(
            defs(LightLoop::plain()),
            ["LIGHT_LOOP_FALLOFF", "LIGHT_LOOP_OUTPUT", "SHADING_PBR"]
        );
        assert_eq!(
            defs(LightLoop::plain().with_shading(Shading::BlinnPhong)),
            ["LIGHT_LOOP_FALLOFF", "LIGHT_LOOP_OUTPUT"],
            "Blinn-Phong is the program without SHADING_PBR"
        );
        let tree = LightLoop::new(
            Falloff::WindowedInverseSquare,
            Some(FarFieldMethod::Tree),
            ShadingOutput::Shaded,
        );
        assert!(defs(tree).contains(&"LIGHT_LOOP_FAR_TREE".to_string()));
        assert_ne!(tree, LightLoop::plain(), "a far field is another program");
    }
}

#[cfg(test)]
mod layout_tests {
    use manylights_gpu::assert_wgsl_layout;
    use manylights_gpu::shaders::Program;
    use manylights_pipeline::LightingUniform;

    /// The frame's lighting parameters (`manylights_pipeline::FrameLighting`, binding 4)
    /// as the clustered loops read them.
    #[test]
    fn lighting_uniform_matches_wgsl() {
        // The struct lives in the module Forward+ and deferred import; composed on its own
        // here (with the defs those programs give it), so the names are not decorated.
        let program = Program::new(
            "cluster_lights",
            &crate::SHADERS,
            "cluster/cluster_lights.wgsl",
        )
        .with_defs(super::LightLoop::plain().shader_defs());
        assert_wgsl_layout!(
            program,
            "cluster/cluster_lights.wgsl",
            ClusteredShadingParams
                == LightingUniform {
                    heatmap_max: heatmap_max,
                    light_count: light_count,
                    _pad_z: _pad,
                    _pad_w: _pad + 4,
                }
        );
    }
}
