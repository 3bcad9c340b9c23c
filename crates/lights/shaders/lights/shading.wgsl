// The shading model, written once for every pipeline (and once more in f64 in
// `lights::reference`, the accuracy reference): a BRDF (`brdf.wgsl`) times the light's
// colour, intensity, falloff and (spot lights) cone attenuation.

#ifndef LIGHTS_IN_WORLD_SPACE
#import manylights::common::view::relative_to_origin
#endif
#import manylights::lights::light_set::{Light, LIGHT_SPOT, LIGHT_SPHERE, LIGHT_RECT, LIGHT_TRIANGLE, MIN_DISTANCE_SQUARED, second_edge}
#import manylights::lights::area::{area_cosine_integral, representative_point, PI}
#import manylights::lights::brdf::{LitSurface, brdf_of_loop, diffuse_of_loop, INV_PI}
#ifndef DIFFUSE_ONLY
#import manylights::lights::brdf::{specular_of_loop, specular_albedo_of_loop}
#endif

// Falloff modes (`lights::Falloff`).
// saturate(1 - (d/r)^4)^2 / max(d^2, eps): smooth, reaches exactly 0 at the radius.
const FALLOFF_WINDOWED_INVERSE_SQUARE: u32 = #FALLOFF_WINDOWED_INVERSE_SQUARE;
// clamp(1 - (d/r)^4, 0, 1) / d^2: the reference projects' falloff (no epsilon).
const FALLOFF_REFERENCE_PROJECTS: u32 = #FALLOFF_REFERENCE_PROJECTS;
// 1 / max(d^2, eps), no radius: the accuracy reference, only exact when every light is shaded.
const FALLOFF_INVERSE_SQUARE: u32 = #FALLOFF_INVERSE_SQUARE;


// `ratio_squared`: (distance / radius)^2, which the loop's reach test takes too;
// `inverse_square`: 1 / distance^2, from the inverse distance the light's direction needed
// anyway (one reciprocal fewer per evaluation than dividing).
fn light_falloff(mode: u32, ratio_squared: f32, inverse_square: f32) -> f32 {
    let window = 1.0 - ratio_squared * ratio_squared;
    switch mode {
        case FALLOFF_REFERENCE_PROJECTS: {
            return clamp(window, 0.0, 1.0) * inverse_square;
        }
        case FALLOFF_INVERSE_SQUARE: {
            return min(inverse_square, MAX_INVERSE_SQUARE);
        }
        default: {
            let w = saturate(window);
            return w * w * min(inverse_square, MAX_INVERSE_SQUARE);
        }
    }
}

// 1 / MIN_DISTANCE_SQUARED: the inverse square's ceiling.
const MAX_INVERSE_SQUARE: f32 = 1.0 / MIN_DISTANCE_SQUARED;

// A spot light's cone attenuation towards the unit direction `l` (from the lit point to
// the light); 1 for point lights. glTF's smooth falloff: saturate(t)^2 with
// t = (cos a - cos outer) / (cos inner - cos outer), a the angle from the spot's axis,
// evaluated as the equal
//   t = (sin2_outer - sin^2 a) / (sin2_outer - sin2_inner) x (cos inner + cos outer) / (cos a + cos outer)
// (multiply out cos^2 x - cos^2 y = sin^2 y - sin^2 x), with sin^2 a = |l x axis|^2: no
// cancellation, so needle-thin cones (1e-4 rad, where every cosine rounds to 1) keep their
// shape. inner == outer is a hard edge (glTF's sample code divides by max(0.001, ...)).
//
// POINT_LIGHTS_ONLY (a program for frames without spots, `cluster::LightLoop`): 1, the
// cone's code and the kind's load left out of the program.
fn spot_attenuation(light: LoopLight, l: vec3<f32>) -> f32 {
#ifdef POINT_LIGHTS_ONLY
    return 1.0;
#else
    if light.kind != LIGHT_SPOT {
        return 1.0;
    }
    let cos_angle = -dot(l, light.direction);
    let across = cross(l, light.direction);
    let sin2_angle = dot(across, across);
    // Outside the cone, or behind the light (the cone is at most a hemisphere).
    if cos_angle <= 0.0 || sin2_angle >= light.sin2_outer {
        return 0.0;
    }
    let edge = light.sin2_outer - light.sin2_inner;
    if sin2_angle <= light.sin2_inner || edge <= 0.0 {
        return 1.0;
    }
    let cos_outer = sqrt(1.0 - light.sin2_outer);
    let cos_inner = sqrt(1.0 - light.sin2_inner);
    let t = saturate((light.sin2_outer - sin2_angle) / edge * (cos_inner + cos_outer) / (cos_angle + cos_outer));
    return t * t;
#endif
}

// The share of a light's power an aggregate of lights (the far field's tree, which takes
// every light as a point of its intensity) counts: 1 for a point light and a sphere; for
// a spot the fraction of all directions its outer cone covers, (1 - cos outer) / 2,
// written as sin2_outer / (2 (1 + cos outer)) to keep thin cones' precision; for a flat
// light 1/4, its mean intensity over all directions against its intensity along the
// normal (a one-sided Lambertian emitter sends pi L A of power, a point of intensity L A
// sends 4 pi L A). The aggregate keeps the power, and a flat light's direction as its
// `light_emission_dipole`.
fn light_power_share(light: Light) -> f32 {
    if light.kind >= LIGHT_RECT {
        return 0.25;
    }
    if light.kind != LIGHT_SPOT {
        return 1.0;
    }
    return light.sin2_outer / (2.0 * (1.0 + sqrt(1.0 - light.sin2_outer)));
}

// How a flat light's intensity leans towards its normal n, as a share of its mean
// intensity, for the far field's aggregates: I max(0, n.w) is I (1/4 + n.w / 2 + ...) in
// spherical harmonics, so against the mean I / 4 the first band is 2 n. An aggregate sums
// these dipoles weighted by its lights' mean intensities and sends 1 + dipole.w / weight
// of its mean towards w, never below 0 (`shade_aggregate`): flat lights all facing one way
// light what they face and nothing more than 30 degrees behind their plane. Points,
// spheres and spots (whose cones the tree spreads over every direction, as before) have
// none. Why the first band and not a blend of a flat light along the mean normal with
// lights that emit every way (exact where all face one way): sponza-embers' embers face
// every way of a half circle, and there the blend doubled the first band's error
// (docs/architecture/area-lights.md).
fn light_emission_dipole(light: Light) -> vec3<f32> {
    if light.kind < LIGHT_RECT {
        return vec3<f32>(0.0);
    }
    return 2.0 * normalize(cross(light.direction, second_edge(light)));
}

// A world-space position in the space the loop shades in: relative to the camera's origin
// in manylights' passes (`relative_to_origin`, which binds our camera at group 0); the
// world itself with LIGHTS_IN_WORLD_SPACE, in an engine's shader whose surface positions
// are world positions and whose group 0 is its own (`cluster::ListedLights::clustered_radiance_wgsl`).
fn shading_position(world: vec3<f32>) -> vec3<f32> {
#ifdef LIGHTS_IN_WORLD_SPACE
    return world;
#else
    return relative_to_origin(world);
#endif
}

// A light as the shading loop evaluates it: what depends on the light alone worked out
// once (its camera-relative position, its radiance at 1 m or an area light's emitted
// radiance, 1 / radius^2), so that a loop
// sharing one light among many pixels (the tile-shared loop, cluster/tile_lights.wgsl)
// pays for it once per tile and not once per pixel. 32 bytes in programs for frames
// without spots or area lights (POINT_LIGHTS_ONLY), 64 with the cone (an area light's
// extent, left out by NO_AREA_LIGHTS, pads to 80); with exact shadows (SHADOWS_EXACT)
// the world position too, where their rays aim exactly (a ray budget aims from the
// camera-relative position: it saves the tile loop 16 bytes of workgroup memory a light).
struct LoopLight {
    // Camera-relative position (`relative_to_origin`).
    position: vec3<f32>,
    radius: f32,
    // color * intensity; for an area light, color * intensity / area, its radiance.
    radiance: vec3<f32>,
    inverse_radius_squared: f32,
#ifndef POINT_LIGHTS_ONLY
    direction: vec3<f32>,
    kind: u32,
    sin2_outer: f32,
    sin2_inner: f32,
#ifndef NO_AREA_LIGHTS
    extent: f32,
#endif
#endif
#ifdef SHADOWS_EXACT
    world_position: vec3<f32>,
#endif
}

fn loop_light(light: Light) -> LoopLight {
    return LoopLight(
        shading_position(light.position),
        light.radius,
#ifdef NO_AREA_LIGHTS
        light.color * light.intensity,
#else
        light.color * light.intensity * emitted_per_intensity(light),
#endif
        1.0 / (light.radius * light.radius),
#ifndef POINT_LIGHTS_ONLY
        light.direction,
        light.kind,
        light.sin2_outer,
        light.sin2_inner,
#ifndef NO_AREA_LIGHTS
        light.extent,
#endif
#endif
#ifdef SHADOWS_EXACT
        light.position,
#endif
    );
}

// 1 / area for an area light (its radiance is its intensity over its projected area:
// `lights::Light::emitted_radiance`), 1 for points and spots.
fn emitted_per_intensity(light: Light) -> f32 {
    let second = second_edge(light);
    switch light.kind {
        case LIGHT_SPHERE: {
            return 1.0 / (PI * light.extent * light.extent);
        }
        case LIGHT_RECT: {
            return 0.25 / length(cross(light.direction, second));
        }
        case LIGHT_TRIANGLE: {
            return (2.0 / 3.0) / length(cross(light.direction, second));
        }
        default: {
            return 1.0;
        }
    }
}

// Outgoing radiance towards the viewer from one light.
fn shade_light(surface: LitSurface, view_dir: vec3<f32>, light: Light, mode: u32) -> vec3<f32> {
    return shade_loop_light(surface, view_dir, loop_light(light), mode);
}

fn shade_loop_light(surface: LitSurface, view_dir: vec3<f32>, light: LoopLight, mode: u32) -> vec3<f32> {
#ifndef NO_AREA_LIGHTS
    if light.kind >= LIGHT_SPHERE {
        return shade_area_light(surface, view_dir, light, mode);
    }
#endif
    let to_light = light.position - surface.position;
    let distance_squared = dot(to_light, to_light);
    // (distance / radius)^2, which the window needs too: the reach test without a product
    // of its own. Past the radius the window is exactly zero, so where this and
    // `distance_squared < radius^2` round differently the term is zero either way.
    let ratio_squared = distance_squared * light.inverse_radius_squared;
    if mode != FALLOFF_INVERSE_SQUARE && !(ratio_squared < 1.0) {
        return vec3<f32>(0.0);
    }
    // n.l has the sign of n.(light - surface): a light behind the surface is refused
    // before the reciprocal square root. A light exactly on the surface has no direction:
    // it lights nothing (no NaN).
    let n_dot_to_light = dot(surface.normal, to_light);
    if n_dot_to_light <= 0.0 || distance_squared <= 0.0 {
        return vec3<f32>(0.0);
    }
    let inverse_distance = inverseSqrt(distance_squared);
    // The direction, for the cone and the specular lobe only: programs with neither
    // (POINT_LIGHTS_ONLY, DIFFUSE_ONLY) never compute it.
    let l = to_light * inverse_distance;
    let n_dot_l = n_dot_to_light * inverse_distance;
    let falloff = light_falloff(mode, ratio_squared, inverse_distance * inverse_distance);
    // The scalar factors first: two vector products instead of three.
    let strength = spot_attenuation(light, l) * falloff * n_dot_l;
    return light.radiance * strength * brdf_of_loop(surface, view_dir, l, n_dot_l);
}

// The window a windowed falloff multiplies by at (distance / radius)^2 = `ratio_squared`
// (1 without a radius): `light_falloff` without its inverse square.
fn light_window(mode: u32, ratio_squared: f32) -> f32 {
    let window = 1.0 - ratio_squared * ratio_squared;
    switch mode {
        case FALLOFF_REFERENCE_PROJECTS: {
            return clamp(window, 0.0, 1.0);
        }
        case FALLOFF_INVERSE_SQUARE: {
            return 1.0;
        }
        default: {
            let w = saturate(window);
            return w * w;
        }
    }
}

#ifndef NO_AREA_LIGHTS
// A loop light's second edge (`second_edge`).
fn loop_second_edge(light: LoopLight) -> vec3<f32> {
    return vec3<f32>(light.sin2_outer, light.sin2_inner, light.extent);
}

// Outgoing radiance towards the viewer from an area light (sphere, rectangle, triangle) of
// uniform radiance L:
//   L x window(distance to its centre) x integral over the light of f(l) n.l dl
// (the window is the point lights' own: a function of the lit point alone, it leaves the
// integral as it is). The integral is split at the BRDF:
// - diffuse: f is constant (Blinn-Phong's Lambert) or nearly (PBR's weight 1 - E(n.l),
//   taken at the light's centre), so the term is f times the light's cosine-weighted solid
//   angle, exact (`area_cosine_integral`: Lambert's polygon formula clipped at the
//   horizon, the sphere's closed form);
// - specular: the lobe's value towards the light's point nearest the mirror direction
//   (the "representative point", Karis 2013) times the same solid angle, at most the
//   lobe's whole directional albedo. Exact for a light small against the lobe (it is then
//   the point light) and for one covering it (then it reflects L times the albedo); in
//   between it overestimates, most where a light half covers a sharp lobe.
//   docs/architecture/area-lights.md gives the measured error against the f64 twin, which
//   integrates the light numerically.
fn shade_area_light(surface: LitSurface, view_dir: vec3<f32>, light: LoopLight, mode: u32) -> vec3<f32> {
    let to_centre = light.position - surface.position;
    let ratio_squared = dot(to_centre, to_centre) * light.inverse_radius_squared;
    if mode != FALLOFF_INVERSE_SQUARE && !(ratio_squared < 1.0) {
        return vec3<f32>(0.0);
    }
    let second = loop_second_edge(light);
    let solid_angle = area_cosine_integral(light.kind, to_centre, light.direction, second, surface.normal);
    if !(solid_angle > 0.0) {
        return vec3<f32>(0.0);
    }
    let window = light_window(mode, ratio_squared);
    let n_dot_centre = saturate(dot(surface.normal, normalize(to_centre)));
    var reflected = diffuse_of_loop(surface, n_dot_centre) * solid_angle;
#ifndef DIFFUSE_ONLY
#ifdef SHADING_PBR
    reflected += surface.reflected_sky * specular_area_integral(surface, light.kind, to_centre, light.direction, second);
#else
    let towards = normalize(representative_point(light.kind, to_centre, light.direction, second, lobe_peak(surface, view_dir)));
    let n_dot_l = dot(surface.normal, towards);
    if n_dot_l > 0.0 {
        reflected += min(specular_of_loop(surface, view_dir, towards, n_dot_l) * solid_angle, specular_albedo_of_loop(surface));
    }
#endif
#endif
    return light.radiance * window * reflected;
}
#endif

#ifndef DIFFUSE_ONLY
#ifdef SHADING_PBR
#ifndef NO_AREA_LIGHTS
// The share of the specular albedo E(n.v) an area light reflects towards the eye: GGX's
// lobe integrated over the light as linearly transformed cosines (Heitz et al. 2016;
// `lights::ltc`), Lambert's polygon formula over the corners mapped by
// `surface.to_cosine`, over pi. A linear map keeps a rectangle a parallelogram and a
// triangle a triangle, so centre and edges map as they are. A sphere is taken as the
// square of its silhouette disc's area, in the disc's plane (the disc at distance
// d cos^2 s, radius d sin s cos s, s the cap's half-angle): the same solid angle, and the
// disc's corners are what a square's are not (docs/architecture/area-lights.md states it).
fn specular_area_integral(surface: LitSurface, kind: u32, centre: vec3<f32>, first: vec3<f32>, second: vec3<f32>) -> f32 {
    var flat_kind = kind;
    var flat_centre = centre;
    var flat_first = first;
    var flat_second = second;
    if kind == LIGHT_SPHERE {
        let distance_squared = dot(centre, centre);
        let radius_squared = second.z * second.z;
        if !(distance_squared > radius_squared) {
            return 1.0;
        }
        let cos_squared = 1.0 - radius_squared / distance_squared;
        let axis = centre * inverseSqrt(distance_squared);
        // Half the square's side: its area, 4 h^2, is pi (r cos s)^2.
        let half_side = 0.886226925 * sqrt(radius_squared * cos_squared);
        let other = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(axis.x) > 0.9);
        let across = normalize(cross(axis, other));
        flat_kind = LIGHT_RECT;
        flat_centre = centre * cos_squared;
        // first x second = -axis: the square faces the lit point.
        flat_first = across * half_side;
        flat_second = cross(across, axis) * half_side;
    }
    let m = surface.to_cosine;
    return area_cosine_integral(flat_kind, m * flat_centre, m * flat_first, m * flat_second, vec3<f32>(0.0, 0.0, 1.0)) * INV_PI;
}
#endif
#else
// The direction a specular lobe is strongest in: the mirror direction for a sharp lobe,
// leaning towards the normal as it widens (the BRDF times n.l peaks between the two:
// Lagarde and de Rousiers 2014, "Moving Frostbite to PBR", fitted for GGX). Blinn-Phong's
// exponent is taken as the GGX alpha of the same width, sqrt(2 / (s + 2)).
fn lobe_peak(surface: LitSurface, view_dir: vec3<f32>) -> vec3<f32> {
    let mirror = reflect(-view_dir, surface.normal);
#ifdef SHADING_PBR
    let alpha = sqrt(surface.alpha_squared);
#else
    let alpha = sqrt(2.0 / (surface.lobe + 2.0));
#endif
    let sharpness = 1.0 - alpha;
    return normalize(mix(surface.normal, mirror, sharpness * (sqrt(sharpness) + alpha)));
}
#endif
#endif

// Largest finite value of the Rgba16Float HDR target. Sums of many bright lights can
// exceed it; they are clamped here rather than stored as infinity (which would turn into
// NaN in later arithmetic and break tonemapping and image comparisons).
const HDR_MAX: f32 = 65504.0;

fn to_hdr_target(color: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(min(color, vec3<f32>(HDR_MAX)), 1.0);
}
