// Naive forward shading: every fragment loops over every light. The reference point of the
// lab: exact for any falloff (including the unbounded inverse-square one), and as slow as
// the light count. Writes linear radiance into the HDR target.

#import manylights::common::view::view
#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface
#import manylights::common::surface::Surface
#import manylights::lights::light_set::{Light, second_edge}
#import manylights::lights::lighting_group::{LIGHTS_BINDING, LOOP_PARAMS_BINDING}
#import manylights::lights::shading::{shade_light, to_hdr_target}
#import manylights::lights::brdf::surface_for_loop
#import manylights::gpu::weighted_blended::{BlendedFragment, WeightedOutput, weighted_blended_output}
#ifdef SHADOWS_EXACT
#import manylights::visibility::bvh::unless_light_shadowed
#endif
#ifdef SHADOW_RAYS
#import manylights::visibility::shadow_rays::{begin_shadow_rays, offer_shadow_ray, shadow_ratio, shadow_target}
#endif
#ifdef SHADOW_PASS
#import manylights::visibility::shadow_pass::ShadowPassTargets
#import manylights::visibility::shadow_rays::shadow_pass_targets
#endif

// The frame's lighting parameters (`pipeline::LightingUniform`): naive reads the light
// count; clustered loops read the same binding as `ClusteredShadingParams`.
struct LightingParams {
    heatmap_max: f32,
    // Lights in the buffer.
    light_count: u32,
    _pad0: u32,
    _pad1: u32,
}

// The program's falloff (`lights::Falloff`, FALLOFF_* in lights/shading.wgsl): a constant,
// so the loop does not branch on it.
const FALLOFF: u32 = #NAIVE_FALLOFF;

// The frame's lighting binding (`pipeline::FrameLighting`), of which naive reads every
// light, animated this frame, and their count; the lists it binds are not naive's.
@group(3) @binding(LIGHTS_BINDING) var<storage, read> lights: array<Light>;
@group(3) @binding(LOOP_PARAMS_BINDING) var<uniform> lighting: LightingParams;

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

// Every light's radiance at `surface`, seen along `view_dir`: with exact shadows, each
// light's unless its shadow ray is blocked; with a ray budget, unshadowed, each term offered
// to the rays (`begin_shadow_rays` first).
fn shade_every_light(surface: Surface, view_dir: vec3<f32>) -> vec3<f32> {
    var radiance = vec3<f32>(0.0);
    let lit = surface_for_loop(surface, view_dir);
    for (var i = 0u; i < lighting.light_count; i++) {
#ifdef SHADOWS_EXACT
        let light = lights[i];
        radiance += unless_light_shadowed(shade_light(lit, view_dir, light, FALLOFF), surface.position + view.origin.xyz, surface.normal, surface.position_error, light);
#else
#ifdef SHADOW_RAYS
        let light = lights[i];
        let term = shade_light(lit, view_dir, light, FALLOFF);
        offer_shadow_ray(term, shadow_target(light.kind, light.position - view.origin.xyz, light.direction, second_edge(light), surface.position));
        radiance += term;
#else
        radiance += shade_light(lit, view_dir, lights[i], FALLOFF);
#endif
#endif
    }
    return radiance;
}

@fragment
fn fs_main(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let surface = fragment_surface(in, front_facing);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
#ifdef SHADOW_RAYS
    begin_shadow_rays(surface.position);
#endif
    var radiance = shade_every_light(surface, view_dir);
#ifdef SHADOW_RAYS
    radiance *= shadow_ratio(surface.position + view.origin.xyz, surface.normal, surface.position_error);
#endif
    return to_hdr_target(surface.emission + radiance);
}

// With one shadow ray a pixel (SHADOW_PASS): the unshadowed radiance, the normal and the
// ray, traced by a compute pass after this one (visibility/shadow_trace.wgsl).
#ifdef SHADOW_PASS
@fragment
fn fs_shadow_pass(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> ShadowPassTargets {
    let surface = fragment_surface(in, front_facing);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
    begin_shadow_rays(surface.position);
    let unshadowed = shade_every_light(surface, view_dir);
    return shadow_pass_targets(to_hdr_target(unshadowed).rgb, to_hdr_target(surface.emission).rgb, surface.normal);
}
#endif

// Blended surfaces (glTF's `BLEND`), after the opaque frame: every light, as `fs_main`,
// with the surface's alpha, and its depth before the camera. A ray budget traces here,
// unfiltered (the shadow pass reads the opaque surface).
fn shade_blended(in: VertexOutput, front_facing: bool) -> BlendedFragment {
    let surface = fragment_surface(in, front_facing);
    let view_dir = normalize(view.camera_position.xyz - surface.position);
#ifdef SHADOW_RAYS
    begin_shadow_rays(surface.position);
#endif
    var radiance = shade_every_light(surface, view_dir);
#ifdef SHADOW_RAYS
#ifndef SHADOW_PASS
    radiance *= shadow_ratio(surface.position + view.origin.xyz, surface.normal, surface.position_error);
#endif
#endif
    let colour = vec4<f32>(to_hdr_target(surface.emission + radiance).rgb, surface.alpha);
    return BlendedFragment(colour, -(view.view * vec4<f32>(in.world_position, 1.0)).z);
}

// Sorted back to front per object, "over" the HDR target (`gpu::blended::OVER`).
@fragment
fn fs_blended(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return shade_blended(in, front_facing).colour;
}

// Weighted blended transparency: into the accumulation targets.
@fragment
fn fs_blended_weighted(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> WeightedOutput {
    return weighted_blended_output(shade_blended(in, front_facing));
}
