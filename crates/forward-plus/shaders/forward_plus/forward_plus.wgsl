// Forward+ (clustered forward) shading: each fragment finds its cluster with the shared
// `cluster_index` and shades only that cluster's lights (`shade_cluster_lights`). With one
// shadow ray a pixel (SHADOW_PASS), `fs_shadow_pass` writes the unshadowed radiance, the
// normal and the ray it kept, and a compute pass traces it (visibility/shadow_trace.wgsl). With the
// optional depth pre-pass, the shading pass runs with depth test LessEqual and no depth
// writes, so hidden fragments are never shaded. The cluster debug views are programs of
// the same entry point composed with the view as their `LOOP_OUTPUT` (`cluster::LightLoop`);
// they write display colours into the HDR target.

#import manylights::common::view::view
#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface
#import manylights::lights::shading::to_hdr_target
#import manylights::cluster::cluster_index::cluster_index
#import manylights::cluster::listed_lights::grid
#import manylights::cluster::cluster_lights::{DEBUG_HEATMAP, DEBUG_SLICES, LOOP_OUTPUT, heatmap_pixel, shade_cluster_lights, slice_pixel}
#ifdef SHADOW_PASS
#import manylights::cluster::cluster_lights::shade_cluster
#import manylights::visibility::shadow_pass::ShadowPassTargets
#import manylights::visibility::shadow_rays::shadow_pass_targets
#endif

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

// Depth pre-pass for alpha-masked materials (opaque ones need no fragment stage).
@fragment
fn fs_depth(in: VertexOutput, @builtin(front_facing) front_facing: bool) {
    // Only for the alpha test inside.
    _ = fragment_surface(in, front_facing);
}

@fragment
fn fs_main(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let surface = fragment_surface(in, front_facing);
    let depth = -(view.view * vec4<f32>(in.world_position, 1.0)).z;
    let cluster = cluster_index(grid, in.clip_position.xy, depth);
    switch LOOP_OUTPUT {
        case DEBUG_HEATMAP: {
            return vec4<f32>(heatmap_pixel(in.clip_position.xy, cluster, surface.normal), 1.0);
        }
        case DEBUG_SLICES: {
            return vec4<f32>(slice_pixel(in.clip_position.xy, depth), 1.0);
        }
        default: {
            let view_dir = normalize(view.camera_position.xyz - surface.position);
            return to_hdr_target(shade_cluster_lights(surface, view_dir, cluster));
        }
    }
}

#ifdef SHADOW_PASS
@fragment
fn fs_shadow_pass(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> ShadowPassTargets {
    let surface = fragment_surface(in, front_facing);
    let depth = -(view.view * vec4<f32>(in.world_position, 1.0)).z;
    let cluster = cluster_index(grid, in.clip_position.xy, depth);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
    let unshadowed = shade_cluster(surface, view_dir, cluster).radiance;
    return shadow_pass_targets(to_hdr_target(unshadowed).rgb, to_hdr_target(surface.emission).rgb, surface.normal);
}
#endif
