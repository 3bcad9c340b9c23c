// The G-buffer pass: rasterises the scene once, writing only what lighting needs, in the
// chosen layout (`write_gbuffer` of <layout>_write.wgsl). Alpha-masked materials discard
// here (their own pipeline), as in the forward pipelines.

#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface
#ifdef GBUFFER_FULL
#import manylights::deferred::full_write::{GBufferOutput, write_gbuffer}
#endif
#ifdef GBUFFER_COMPACT
#import manylights::deferred::compact_write::{GBufferOutput, write_gbuffer}
#endif
#ifdef GBUFFER_PACKED
#import manylights::deferred::packed_write::{GBufferOutput, write_gbuffer}
#endif

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

@fragment
fn fs_gbuffer(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> GBufferOutput {
    return write_gbuffer(fragment_surface(in, front_facing));
}
