// Unlit base colour: draws each surface's material colour (factor x texture, alpha test
// honoured) with no lighting. Used by the GPU round-trip test and as the albedo debug view.

#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

@fragment
fn fs_main(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let surface = fragment_surface(in, front_facing);
    return vec4<f32>(surface.albedo, 1.0);
}
