//! Visibility: which lights a surface point sees. The scene's triangles go into a BVH once
//! per scene ([`SceneBvh`]; the geometry is static, only lights move). The f64 accuracy
//! reference traces its shadow rays here ([`SceneBvh::light_visible`]); the GPU traces the
//! same rays through the same tree in WGSL (`shaders/visibility/bvh.wgsl`, bound from
//! [`GpuSceneBvh`]), in compute and fragment shaders alike: no ray-tracing hardware, so it
//! runs on lavapipe, the H200 and in the browser.
//!
//! ```no_run
//! # fn f(scene: &manylights_scene::Scene) -> Result<(), manylights_visibility::VisibilityError> {
//! use glam::DVec3;
//! let bvh = manylights_visibility::SceneBvh::build(scene)?;
//! let lit = bvh.light_visible(DVec3::ZERO, DVec3::Y, DVec3::new(0.0, 2.0, 0.0));
//! # Ok(()) }
//! ```
//!
//! An engine traces the same shadow rays from its own shader: the tree of its own
//! triangles ([`SceneBvh::from_triangles`]) uploaded ([`GpuSceneBvh::new`]), and
//! [`ShadowQueries`], the WGSL (`manylights_shadows_unless_shadowed`, ...) and the bind
//! group at the index it picks:
//!
//! ```no_run
//! # fn engine(context: &manylights_gpu::GpuContext, positions: &[glam::Vec3], indices: &[u32]) -> Result<(), Box<dyn std::error::Error>> {
//! use manylights_visibility::{GpuSceneBvh, SceneBvh, ShadowQueries};
//! let bvh = GpuSceneBvh::new(context, &SceneBvh::from_triangles(positions, indices)?)?;
//! let shadows = ShadowQueries::new(context, 2);
//! let wgsl = shadows.wgsl(&manylights_gpu::ShaderLibrary::Embedded)?; // beside the engine's
//! let group = shadows.bind_group(context, &bvh)?; // bound at 2
//! # let _ = (wgsl, group);
//! # Ok(()) }
//! ```

mod bvh;
mod gpu;
mod masks;
mod rebuilt;
pub mod shadow_filter;
pub mod shadow_queries;
pub mod test_scenes;
mod visible_reference;

use manylights_gpu::{ShaderModules, shader_files};

pub use bvh::{
    BvhNode, BvhTriangle, Hit, MAX_DEPTH, SHADOW_OFFSET_ABSOLUTE, SHADOW_OFFSET_RELATIVE, SceneBvh,
    ShadowRay, shadow_offset, shadow_ray,
};
pub use gpu::{FIRST_BINDING, GpuSceneBvh, ROW_TEXELS};
pub use masks::{ATLAS_WIDTH, CoverageMasks, MAX_MASKS, MaskRect, NO_MASK};
pub use rebuilt::{RASTER_PLANE_PIXELS_INVERSE, REBUILT_DEPTH_ULPS, rebuilt_position_error};
pub use shadow_filter::{
    FILTER_FORMAT, FORWARD_TARGETS, FilterTargets, FrameShadows, SHADOW_COMPOSE_PASS,
    SHADOW_FILTER_COLUMNS_PASS, SHADOW_FILTER_ROWS_PASS, SHADOW_FILTER_TEMPORAL_PASS,
    SHADOW_TRACE_PASS, ShadowFilter, ShadowPassInputs, filter_program, trace_program,
};
pub use shadow_queries::ShadowQueries;
pub use visible_reference::{
    GpuVisibleReference, GpuVisibleReferenceImage, VISIBLE_REFERENCE_SAMPLERS,
    VisibleReferenceInputs, VisibleReferenceRays, visible_reference_program,
};

/// This crate's WGSL: the traversal, a probe that runs it for tests, the ray budget, the
/// positions rebuilt from depth, the shadow pass and the filter of its share.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "visibility",
    files: shader_files![
        "visibility/bvh.wgsl",
        "visibility/bvh_probe.wgsl",
        "visibility/shadow_rays.wgsl",
        "visibility/rebuilt.wgsl",
        "visibility/shadow_pass.wgsl",
        "visibility/shadow_trace.wgsl",
        "visibility/shadow_filter.wgsl",
        "visibility/visible_reference.wgsl"
    ],
    uses: &[
        &manylights_gpu::shaders::SHADERS,
        &manylights_lights::SHADERS,
    ],
    constants: shader_constants,
};

/// The constants of this crate's WGSL: the traversal's and the rebuilt positions' bound.
fn shader_constants() -> Vec<(String, manylights_gpu::ShaderDef)> {
    let mut defs = gpu::shader_defs();
    defs.extend(rebuilt::shader_defs());
    defs.extend(visible_reference::shader_defs());
    defs
}

/// The traversal run on rays for tests (`tests/bvh.rs`): entry `probe`; rays at group 3
/// binding 0, results at binding 1, the BVH at [`FIRST_BINDING`].
pub fn probe_program() -> manylights_gpu::Program {
    manylights_gpu::Program::new("bvh_probe", &SHADERS, "visibility/bvh_probe.wgsl")
}

/// Every program of this crate (for `cargo xtask validate-shaders`).
pub fn programs() -> Vec<manylights_gpu::Program> {
    let references = [
        manylights_scene::Shading::Pbr,
        manylights_scene::Shading::BlinnPhong,
    ]
    .map(visible_reference_program);
    let shadow_queries =
        manylights_gpu::Program::new("shadow_queries", &SHADERS, "visibility/bvh.wgsl");
    [
        probe_program(),
        filter_program(),
        trace_program(),
        shadow_queries,
    ]
    .into_iter()
    .chain(references)
    .collect()
}

/// Whether geometry blocks light in a frame, and how its shadow rays are spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum Shadows {
    /// Every light reaches every point within its range (no visibility: the fastest).
    #[default]
    Off,
    /// Every light a pixel evaluates gets a shadow ray through the scene's BVH (far-field
    /// aggregates: one ray to the aggregate's power centroid).
    Exact,
    /// A fixed budget of this many rays a pixel, whatever the light count
    /// (`visibility/shadow_rays.wgsl`): the loop sums every light unshadowed, exactly, and
    /// draws one light per ray in proportion to its unshadowed contribution; the rays'
    /// visible share scales the sum (the ratio estimator). A pixel lit by at most this
    /// many lights gets a ray to each of them: exact shadows.
    Rays(u32),
    /// [`Shadows::Rays`] with the visible share denoised by an edge-aware spatial filter
    /// (guided by depth and normal; deferred's compute lighting paths).
    RaysSpatial(u32),
    /// [`Shadows::RaysSpatial`] with the filtered share accumulated over frames: reprojected
    /// through last frame's camera, rejected where the surface or its unshadowed light
    /// changed, and held near this frame's share (deferred's compute lighting paths).
    RaysTemporal(u32),
}

impl Shadows {
    /// The ray budgets offered: powers of two up to [`MAX_SHADOW_RAYS`].
    pub const ALL: [Shadows; 11] = [
        Shadows::Off,
        Shadows::Exact,
        Shadows::Rays(1),
        Shadows::Rays(2),
        Shadows::Rays(4),
        Shadows::RaysSpatial(1),
        Shadows::RaysSpatial(2),
        Shadows::RaysSpatial(4),
        Shadows::RaysTemporal(1),
        Shadows::RaysTemporal(2),
        Shadows::RaysTemporal(4),
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Shadows::Off => "off",
            Shadows::Exact => "exact",
            Shadows::Rays(rays) => {
                const NAMES: [&str; MAX_SHADOW_RAYS as usize] =
                    ["rays:1", "rays:2", "rays:3", "rays:4"];
                Self::budget_name(&NAMES, *rays)
            }
            Shadows::RaysSpatial(rays) => {
                const NAMES: [&str; MAX_SHADOW_RAYS as usize] = [
                    "rays:1+spatial",
                    "rays:2+spatial",
                    "rays:3+spatial",
                    "rays:4+spatial",
                ];
                Self::budget_name(&NAMES, *rays)
            }
            Shadows::RaysTemporal(rays) => {
                const NAMES: [&str; MAX_SHADOW_RAYS as usize] = [
                    "rays:1+spatial+temporal",
                    "rays:2+spatial+temporal",
                    "rays:3+spatial+temporal",
                    "rays:4+spatial+temporal",
                ];
                Self::budget_name(&NAMES, *rays)
            }
        }
    }

    /// Whether shadow rays are traced.
    pub fn traced(&self) -> bool {
        *self != Shadows::Off
    }

    fn budget_name(names: &[&'static str], rays: u32) -> &'static str {
        match rays.checked_sub(1).and_then(|i| names.get(i as usize)) {
            Some(name) => name,
            None => "rays:unsupported",
        }
    }

    /// Why this mode cannot render, if it cannot: a ray budget outside 1 to
    /// [`MAX_SHADOW_RAYS`].
    pub fn check(&self) -> Result<(), String> {
        match self.ray_budget() {
            Some(rays) if !(1..=MAX_SHADOW_RAYS).contains(&rays) => Err(format!(
                "a shadow ray budget of {rays} rays a pixel: from 1 to {MAX_SHADOW_RAYS} are \
                 supported"
            )),
            _ => Ok(()),
        }
    }

    /// The rays a pixel traces with a fixed budget; `None` for off and exact.
    pub fn ray_budget(&self) -> Option<u32> {
        match self {
            Shadows::Rays(rays) | Shadows::RaysSpatial(rays) | Shadows::RaysTemporal(rays) => {
                Some(*rays)
            }
            Shadows::Off | Shadows::Exact => None,
        }
    }

    /// Whether a spatial filter denoises the ray budget's visible share.
    pub fn spatially_filtered(&self) -> bool {
        matches!(self, Shadows::RaysSpatial(_) | Shadows::RaysTemporal(_))
    }

    /// Whether the filtered share is accumulated over frames.
    pub fn temporally_accumulated(&self) -> bool {
        matches!(self, Shadows::RaysTemporal(_))
    }

    /// Frames a static view takes to reach this mode's steady state (its history full):
    /// what a measurement renders before it reads a frame.
    pub fn settle_frames(&self) -> u32 {
        if self.temporally_accumulated() {
            SHADOW_HISTORY_FRAMES
        } else {
            0
        }
    }

    /// The same rays without their filter (what debug views and pipelines without the
    /// filter trace).
    pub fn unfiltered(self) -> Self {
        match self {
            Shadows::RaysSpatial(rays) | Shadows::RaysTemporal(rays) => Shadows::Rays(rays),
            other => other,
        }
    }

    /// Whether a forward pipeline (Forward+, naive) traces this mode's rays in the shadow
    /// pass after its shading pass, in compute ([`ShadowFilter::record_traced`]): a budget
    /// of [`SHADOW_PASS_RAYS`]. Larger budgets trace in their fragment shader, unfiltered.
    pub fn in_shadow_pass(&self) -> bool {
        self.ray_budget() == Some(SHADOW_PASS_RAYS)
    }

    /// The shader defs of a forward pipeline's shading program for this mode: the
    /// unfiltered mode's (the shadow pass filters), with `SHADOW_PASS` where it traces.
    pub fn forward_shader_defs(&self) -> Vec<(String, manylights_gpu::ShaderDef)> {
        let mut defs = self.unfiltered().shader_defs();
        if self.in_shadow_pass() {
            defs.push((
                "SHADOW_PASS".to_string(),
                manylights_gpu::ShaderDef::Bool(true),
            ));
        }
        defs
    }

    /// The shader defs of this mode for a light loop: `SHADOWS_EXACT`, or `SHADOW_RAYS`
    /// with the budget (`visibility/shadow_rays.wgsl`); none without shadows.
    pub fn shader_defs(&self) -> Vec<(String, manylights_gpu::ShaderDef)> {
        use manylights_gpu::ShaderDef;
        match self {
            Shadows::Off => Vec::new(),
            Shadows::Exact => vec![("SHADOWS_EXACT".to_string(), ShaderDef::Bool(true))],
            Shadows::Rays(rays) => vec![("SHADOW_RAYS".to_string(), ShaderDef::UInt(*rays))],
            Shadows::RaysSpatial(rays) | Shadows::RaysTemporal(rays) => vec![
                ("SHADOW_RAYS".to_string(), ShaderDef::UInt(*rays)),
                ("SHADOW_FILTER".to_string(), ShaderDef::Bool(true)),
            ],
        }
    }
}

/// The largest ray budget [`Shadows::Rays`] offers: each ray's reservoir is a component of
/// a vector in each thread's registers (`visibility/shadow_rays.wgsl`).
pub const MAX_SHADOW_RAYS: u32 = 4;

/// The rays a pixel the forward pipelines' shadow pass traces: the ray's light (16 bytes)
/// beside the unshadowed radiance and the normal fills the 32 bytes of colour targets a
/// sample WebGPU guarantees ([`FORWARD_TARGETS`]).
pub const SHADOW_PASS_RAYS: u32 = 1;

/// The most frames [`Shadows::RaysTemporal`] averages: each new frame's share weighs at
/// least 1/16, so a static view's frame-to-frame change falls to about 1/16 of the
/// filtered share's (`shaders/visibility/shadow_filter.wgsl` declares it again).
pub const SHADOW_HISTORY_FRAMES: u32 = 16;

manylights_gpu::named_choice!(Shadows, "shadows");

/// Why a scene's BVH could not be built or uploaded.
#[derive(Debug, thiserror::Error)]
pub enum VisibilityError {
    #[error("triangle {triangle} of the scene has a vertex that is not a finite number")]
    NonFinite { triangle: usize },
    #[error("triangles: {0}")]
    BadTriangles(String),
    #[error(
        "the scene's BVH is {depth} levels deep, more than the GPU traversal's stack holds \
         ({} levels)",
        MAX_DEPTH
    )]
    TooDeep { depth: u32 },
    #[error("the scene has {masks} alpha-masked materials; shadows support at most {limit}")]
    TooManyMasks { masks: usize, limit: usize },
    #[error("the alpha masks need an atlas {height} texels high; WebGPU guarantees {limit}")]
    AtlasFull { height: u32, limit: u32 },
    #[error("the scene's {what} need {texels} texels; a WebGPU texture holds {limit}")]
    TooLarge {
        what: String,
        texels: u64,
        limit: u64,
    },
    #[error(transparent)]
    Gpu(#[from] manylights_gpu::GpuError),
}
