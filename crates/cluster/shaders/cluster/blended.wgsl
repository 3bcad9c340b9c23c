// Blended surfaces (glTF's `BLEND`) shaded forward from the cluster lists, after the opaque
// frame: Forward+ and deferred draw them alike (`cluster::BlendedPass`), back to front per
// object, over the HDR target with the "over" operator (glTF's non-premultiplied alpha).
// A blended surface lies in front of the depth the frame laid down, so the cluster boxes
// are grown over the blended objects' bounds (`GpuClusters::set_blended_bounds`), and the
// fragment finds its cluster from its own depth. Exact shadows trace here as in the opaque
// loop; a ray budget traces its rays here too, unfiltered (the filter reads one surface
// a pixel: the opaque one).

#import manylights::common::view::view
#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface
#import manylights::lights::shading::to_hdr_target
#import manylights::cluster::cluster_index::cluster_index
#import manylights::cluster::listed_lights::grid
#import manylights::cluster::cluster_lights::shade_cluster_lights
#import manylights::gpu::weighted_blended::{BlendedFragment, WeightedOutput, weighted_blended_output}

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

fn shade_blended(in: VertexOutput, front_facing: bool) -> BlendedFragment {
    let surface = fragment_surface(in, front_facing);
    let depth = -(view.view * vec4<f32>(in.world_position, 1.0)).z;
    let cluster = cluster_index(grid, in.clip_position.xy, depth);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
    let shaded = to_hdr_target(shade_cluster_lights(surface, view_dir, cluster));
    return BlendedFragment(vec4<f32>(shaded.rgb, surface.alpha), depth);
}

// Sorted: blended "over" the HDR target.
@fragment
fn fs_blended(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return shade_blended(in, front_facing).colour;
}

// Weighted blended transparency: into the accumulation targets.
@fragment
fn fs_blended_weighted(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> WeightedOutput {
    return weighted_blended_output(shade_blended(in, front_facing));
}
