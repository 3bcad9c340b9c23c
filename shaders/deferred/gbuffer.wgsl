// The G-buffer pass: rasterises the scene once, writing only what lighting needs, in the
// chosen layout (`write_gbuffer` of <layout>_write.wgsl). Alpha-masked materials discard
// here (their own pipeline), as in the forward pipelines.

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

@fragment
fn fs_gbuffer(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> GBufferOutput {
    return write_gbuffer(fragment_surface(in, front_facing));
}
