// The shading model, written once for every pipeline (and once more in f64 in
// `lights::reference`, the accuracy reference): Lambert diffuse plus Blinn-Phong specular,
// times the light's colour, intensity and falloff.

#import manylights::common::view::relative_to_origin
#import manylights::common::surface::Surface
#import manylights::lights::light_set::PointLight

// Falloff modes (`lights::Falloff`).
// saturate(1 - (d/r)^4)^2 / max(d^2, eps): smooth, reaches exactly 0 at the radius.
const FALLOFF_WINDOWED_INVERSE_SQUARE: u32 = 0u;
// clamp(1 - (d/r)^4, 0, 1) / d^2: the reference projects' falloff (no epsilon).
const FALLOFF_REFERENCE_PROJECTS: u32 = 1u;
// 1 / max(d^2, eps), no radius: the accuracy reference, only exact when every light is shaded.
const FALLOFF_INVERSE_SQUARE: u32 = 2u;

// Smallest squared distance the inverse-square law divides by (1 cm squared); see
// `lights::reference::MIN_DISTANCE_SQUARED` for its measured effect.
const MIN_DISTANCE_SQUARED: f32 = 1e-4;

fn light_falloff(mode: u32, distance_squared: f32, radius: f32) -> f32 {
    let ratio_squared = distance_squared / (radius * radius);
    let window = 1.0 - ratio_squared * ratio_squared;
    switch mode {
        case FALLOFF_REFERENCE_PROJECTS: {
            return clamp(window, 0.0, 1.0) / distance_squared;
        }
        case FALLOFF_INVERSE_SQUARE: {
            return 1.0 / max(distance_squared, MIN_DISTANCE_SQUARED);
        }
        default: {
            let w = saturate(window);
            return w * w / max(distance_squared, MIN_DISTANCE_SQUARED);
        }
    }
}

// Whether a light can reach a point at this squared distance under this falloff.
fn light_reaches(mode: u32, distance_squared: f32, radius: f32) -> bool {
    return mode == FALLOFF_INVERSE_SQUARE || distance_squared < radius * radius;
}

// Outgoing radiance towards the viewer from one point light.
fn shade_point_light(surface: Surface, view_dir: vec3<f32>, light: PointLight, mode: u32) -> vec3<f32> {
    let to_light = relative_to_origin(light.position) - surface.position;
    let distance_squared = dot(to_light, to_light);
    if !light_reaches(mode, distance_squared, light.radius) {
        return vec3<f32>(0.0);
    }
    // A light exactly on the surface has no direction: it lights nothing (no NaN).
    if distance_squared <= 0.0 {
        return vec3<f32>(0.0);
    }
    let l = to_light * inverseSqrt(distance_squared);
    let reflected = reflected_light(surface, view_dir, l);
    if reflected.n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let radiance = light.color * (light.intensity * light_falloff(mode, distance_squared, light.radius));
    return radiance * reflected.n_dot_l * reflected.brdf;
}

// How a surface reflects light arriving from the unit direction `l` towards the eye:
// radiance out = radiance in x n_dot_l x brdf (zero when the light is behind the surface).
struct ReflectedLight {
    n_dot_l: f32,
    brdf: vec3<f32>,
}

fn reflected_light(surface: Surface, view_dir: vec3<f32>, l: vec3<f32>) -> ReflectedLight {
    let n_dot_l = dot(surface.normal, l);
    if n_dot_l <= 0.0 {
        return ReflectedLight(0.0, vec3<f32>(0.0));
    }
    let half_sum = l + view_dir;
    let half_length_squared = dot(half_sum, half_sum);
    var specular = vec3<f32>(0.0);
    if half_length_squared > 0.0 {
        let n_dot_h = max(dot(surface.normal, half_sum * inverseSqrt(half_length_squared)), 0.0);
        specular = surface.specular * pow(n_dot_h, surface.shininess);
    }
    return ReflectedLight(n_dot_l, surface.albedo + specular);
}

// Largest finite value of the Rgba16Float HDR target. Sums of many bright lights can
// exceed it; they are clamped here rather than stored as infinity (which would turn into
// NaN in later arithmetic and break tonemapping and image comparisons).
const HDR_MAX: f32 = 65504.0;

fn to_hdr_target(color: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(min(color, vec3<f32>(HDR_MAX)), 1.0);
}
