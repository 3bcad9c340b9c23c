//! This crate's programs in one list; each is defined beside the pass that runs it, so
//! the light buffer's module (`gpu.rs`) knows no pass above it.

use manylights_gpu::Program;

use crate::Shading;
use crate::gpu::{animate_program, pbr_program};

/// Every program of this crate, in every variant (what `cargo xtask validate-shaders`
/// validates).
pub fn programs() -> Vec<Program> {
    let references =
        [Shading::Pbr, Shading::BlinnPhong].map(crate::gpu_reference::reference_program);
    std::iter::once(animate_program())
        .chain(references)
        .chain(std::iter::once(pbr_program(crate::MANYLIGHTS_GROUP)))
        .collect()
}
