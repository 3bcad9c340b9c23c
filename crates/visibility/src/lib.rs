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

mod bvh;
mod gpu;
mod masks;
pub mod test_scenes;

use manylights_gpu::{ShaderModules, shader_files};

pub use bvh::{
    BvhNode, BvhTriangle, Hit, MAX_DEPTH, SHADOW_OFFSET_ABSOLUTE, SHADOW_OFFSET_RELATIVE, SceneBvh,
    ShadowRay, shadow_offset, shadow_ray,
};
pub use gpu::{FIRST_BINDING, GpuSceneBvh, ROW_TEXELS};
pub use masks::{ATLAS_WIDTH, CoverageMasks, MAX_MASKS, MaskRect, NO_MASK};

/// This crate's WGSL: the traversal, and a probe that runs it for tests.
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "visibility",
    files: shader_files!["visibility/bvh.wgsl", "visibility/bvh_probe.wgsl"],
    uses: &[&manylights_gpu::shaders::SHADERS],
    constants: gpu::shader_defs,
};

/// The traversal run on rays for tests (`tests/bvh.rs`): entry `probe`; rays at group 3
/// binding 0, results at binding 1, the BVH at [`FIRST_BINDING`].
pub fn probe_program() -> manylights_gpu::Program {
    manylights_gpu::Program::new("bvh_probe", &SHADERS, "visibility/bvh_probe.wgsl")
}

/// Every program of this crate (for `cargo xtask validate-shaders`).
pub fn programs() -> Vec<manylights_gpu::Program> {
    vec![probe_program()]
}

/// Whether geometry blocks light in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Shadows {
    /// Every light reaches every point within its range (no visibility: the fastest).
    #[default]
    Off,
    /// Every light a pixel evaluates gets a shadow ray through the scene's BVH (far-field
    /// aggregates: one ray to the aggregate's power centroid).
    Exact,
}

impl Shadows {
    pub const ALL: [Shadows; 2] = [Shadows::Off, Shadows::Exact];

    pub fn name(&self) -> &'static str {
        match self {
            Shadows::Off => "off",
            Shadows::Exact => "exact",
        }
    }

    /// Whether shadow rays are traced.
    pub fn traced(&self) -> bool {
        *self != Shadows::Off
    }
}

manylights_gpu::named_choice!(Shadows, "shadows");

/// Why a scene's BVH could not be built or uploaded.
#[derive(Debug, thiserror::Error)]
pub enum VisibilityError {
    #[error("triangle {triangle} of the scene has a vertex that is not a finite number")]
    NonFinite { triangle: usize },
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
