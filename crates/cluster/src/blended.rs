//! Blended surfaces (glTF's `BLEND`) shaded forward from the cluster lists after the opaque
//! frame (`shaders/cluster/blended.wgsl`), as every engine shades transparency forward from
//! the clusters its opaque frame uses: the program Forward+ and deferred give the pipeline
//! crate's `BlendedPass`, and the loop it runs ([`LightLoop::for_blended`]). The cluster
//! boxes must reach the blended surfaces: [`crate::GpuClusters::set_blended_bounds`].

use manylights_gpu::Program;

use crate::{LightLoop, SHADERS};

/// The blended pass's program running `light_loop` (composed per material variant).
pub fn blended_program(light_loop: LightLoop) -> Program {
    Program::shading_materials(
        format!("blended ({})", light_loop.label()),
        &SHADERS,
        "cluster/blended.wgsl",
    )
    .with_defs(light_loop.shader_defs())
}
