// What the lights of the far field add to a surface, without shadows: an aggregate of the
// light tree's cut shaded as one light (`shade_aggregate`), and a light beyond its radius
// through the complement of the windowed falloff (`shade_light_complement`): the two terms
// a cluster's cut (far_terms.wgsl) sums. manylights' loops (cluster_lights.wgsl) shadow
// each term their own way; an engine's `clustered_radiance` (clustered_radiance.wgsl) sums
// them as they are.

#import manylights::cluster::far_nodes::{FarNode, window_complement}
#import manylights::cluster::far_terms::aggregate_term
#import manylights::lights::light_set::LIGHT_SPHERE
#import manylights::lights::shading::{LoopLight, shading_position, shade_area_light, spot_attenuation, FALLOFF_INVERSE_SQUARE}
#import manylights::lights::brdf::{LitSurface, brdf_of_loop}

// How a surface reflects light from one direction: radiance out = radiance in x n_dot_l x
// brdf.
struct ReflectedLight {
    n_dot_l: f32,
    brdf: vec3<f32>,
}

// Light arriving at the surface from the camera-relative `position`: its unit direction,
// squared distance and how the surface reflects it (n_dot_l 0: it does not, or the light
// is on the surface), its BRDF as a term of the loop's sum (`brdf_of_loop`).
struct Incoming {
    l: vec3<f32>,
    distance_squared: f32,
    reflected: ReflectedLight,
}

fn incoming_from(surface: LitSurface, view_dir: vec3<f32>, position: vec3<f32>) -> Incoming {
    let to_light = position - surface.position;
    let distance_squared = dot(to_light, to_light);
    if distance_squared <= 0.0 {
        return Incoming(vec3<f32>(0.0), 0.0, ReflectedLight(0.0, vec3<f32>(0.0)));
    }
    let l = to_light * inverseSqrt(distance_squared);
    let n_dot_l = dot(surface.normal, l);
    if n_dot_l <= 0.0 {
        return Incoming(l, distance_squared, ReflectedLight(0.0, vec3<f32>(0.0)));
    }
    // A term of the loop's sum: the BRDF without the sum's common factor (`brdf_of_loop`).
    return Incoming(l, distance_squared, ReflectedLight(n_dot_l, brdf_of_loop(surface, view_dir, l, n_dot_l)));
}

// The radiance of aggregate `node` at `surface` (`aggregate_term`, far_terms.wgsl): its
// term's incoming light times the BRDF toward it.
fn shade_aggregate(surface: LitSurface, view_dir: vec3<f32>, node: FarNode) -> vec3<f32> {
    let term = aggregate_term(node, shading_position(node.centroid) - surface.position, surface.normal);
    if !any(term.incoming > vec3<f32>(0.0)) {
        return vec3<f32>(0.0);
    }
    return term.incoming * brdf_of_loop(surface, view_dir, term.l, saturate(dot(surface.normal, term.l)));
}

// The complement of the windowed falloff from one light, a spot through its cone, an area
// light's integral times the window's complement at its centre.
fn shade_light_complement(surface: LitSurface, view_dir: vec3<f32>, light: LoopLight) -> vec3<f32> {
#ifndef NO_AREA_LIGHTS
    if light.kind >= LIGHT_SPHERE {
        let to_centre = light.position - surface.position;
        return shade_area_light(surface, view_dir, light, FALLOFF_INVERSE_SQUARE) * window_complement(dot(to_centre, to_centre), light.radius);
    }
#endif
    let incoming = incoming_from(surface, view_dir, light.position);
    if incoming.reflected.n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let strength = spot_attenuation(light, incoming.l) * window_complement(incoming.distance_squared, light.radius);
    return light.radiance * (strength * incoming.reflected.n_dot_l) * incoming.reflected.brdf;
}
