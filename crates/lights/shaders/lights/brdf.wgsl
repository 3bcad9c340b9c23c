// The BRDFs the light loops apply, without any light: the surface as a loop reads it,
// made once per pixel (`surface_for_loop`), and each light's term from its direction
// (`brdf_of_loop`). The program's model (`scene::Shading`): glTF's metallic-roughness
// (SHADING_PBR) or Lambert plus Blinn-Phong. Apart from the lights (`shading.wgsl`) because
// it binds nothing but the specular fits' table: an engine composing with naga_oil
// imports it (`pbr_for_engines.wgsl`) without our camera's or materials' bindings, which
// naga_oil brings along with any module that imports them.

#import manylights::common::surface::Surface
#import manylights::lights::area::{blinn_phong_lobe_albedo, PI}
#import manylights::lights::specular_albedo::{AlbedoFit, albedo_fit, specular_albedo, specular_albedo_average, ltc_entries}

// The BRDF as the light loop applies it per light: without its common factor
// (`loop_sum_radiance`), which is the albedo in programs for diffuse materials
// (DIFFUSE_ONLY): there every term of a pixel's sum shares it, so the loop multiplies the
// sum by it once instead of every term (three products per light fewer).
// `n_dot_l`: n.l, which the caller tested positive.
fn brdf_of_loop(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>, n_dot_l: f32) -> vec3<f32> {
#ifdef DIFFUSE_ONLY
    return vec3<f32>(1.0);
#else
#ifdef SHADING_PBR
    return pbr_brdf(surface, view_dir, l, n_dot_l);
#else
    return blinn_phong_brdf(surface, view_dir, l);
#endif
#endif
}

// `brdf_of_loop`'s diffuse half, for light at n.l = `n_dot_l`.
fn diffuse_of_loop(surface: LitSurface, n_dot_l: f32) -> vec3<f32> {
#ifdef DIFFUSE_ONLY
    return vec3<f32>(1.0);
#else
#ifdef SHADING_PBR
    return pbr_diffuse(surface, n_dot_l);
#else
    return surface.albedo;
#endif
#endif
}

#ifndef DIFFUSE_ONLY
// `brdf_of_loop`'s specular half.
fn specular_of_loop(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>, n_dot_l: f32) -> vec3<f32> {
#ifdef SHADING_PBR
    return pbr_specular(surface, view_dir, l, n_dot_l);
#else
    return blinn_phong_specular(surface, view_dir, l);
#endif
}

// The specular lobe's directional albedo towards the eye: all it reflects of a uniform
// sky (PBR: E(n.v) with the pixel's F0, the fit `surface_for_loop` reads; Blinn-Phong:
// its lobe's integral seen head-on, `blinn_phong_lobe_albedo`).
fn specular_albedo_of_loop(surface: LitSurface) -> vec3<f32> {
#ifdef SHADING_PBR
    return surface.reflected_sky;
#else
    return surface.specular * blinn_phong_lobe_albedo(surface.lobe);
#endif
}
#endif

// Radiance from a light loop's sum of terms shaded with `brdf_of_loop`: the sum times the
// common factor the terms left out (DIFFUSE_ONLY: the albedo), or the sum itself. The sum
// is first held below a finite ceiling, so that a sum that overflowed times a black
// albedo is black, as its terms were, and not infinity times zero (NaN).
fn loop_sum_radiance(surface: LitSurface, sum: vec3<f32>) -> vec3<f32> {
#ifdef DIFFUSE_ONLY
    return min(sum, vec3<f32>(SUM_CEILING)) * surface.albedo;
#else
    return sum;
#endif
}

// Any large finite value will do. Not f32's largest: naga writes that back to WGSL (the
// page's path) as 340282350000000000000000000000000000000, a decimal above the largest
// f32, which Tint refuses ("value cannot be represented as 'f32'"; found by the page's
// shadowed wall, the first diffuse-only scene it drew).
const SUM_CEILING: f32 = 1e38;

// The BRDF towards the eye for light arriving from the unit direction `l`, on the lit side
// of the surface (callers test n.l first): Lambert plus Blinn-Phong specular. Programs for
// scenes without specular materials (DIFFUSE_ONLY) never call it (`brdf_of_loop`).
fn blinn_phong_brdf(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    return surface.albedo + blinn_phong_specular(surface, view_dir, l);
}

fn blinn_phong_specular(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let half_sum = l + view_dir;
    let half_length_squared = dot(half_sum, half_sum);
    if half_length_squared <= 0.0 {
        return vec3<f32>(0.0);
    }
    // The dot product scaled, rather than the vector normalized: one product, not three.
    let n_dot_h = max(dot(surface.normal, half_sum) * inverseSqrt(half_length_squared), 0.0);
    return surface.specular * pow(n_dot_h, surface.lobe);
}

// glTF 2.0's metallic-roughness BRDF (its Appendix B, with Filament's choices where it
// leaves them open, and an energy-conserving diffuse weight) towards the eye for light
// arriving from the unit direction `l`, on the lit side of the surface (callers test n.l
// first):
//   F D V + albedo / pi x (1 - E(n.v)) (1 - E(n.l)) / (1 - E_avg)
// with `albedo` the dielectric part's base colour (base x (1 - metallic)), F Schlick's
// Fresnel at v.h from F0 (`Surface::specular`: 0.04 blended to the base colour by
// metallic), D the GGX (Trowbridge-Reitz) distribution and V the height-correlated Smith
// visibility (G / (4 n.l n.v)), both in alpha = roughness^2. Lambert diffuse, not Burley:
// glTF's reference is Lambert, and Burley's is neither reciprocal nor energy conserving.
// The diffuse keeps what the specular lobe leaves on the way in and out (E: its
// directional albedo, specular_albedo.wgsl), not Appendix B's 1 - F(v.h), which reflects
// up to 1.84 times the light arriving at grazing views of smooth dielectrics
// (docs/architecture/materials.md).
//
// Everything that depends on the pixel alone (n.v, alpha^2, the visibility term's view
// half, the diffuse term's coefficients) is worked out once before the loop
// (`surface_for_loop`): here only what depends on the light.
#ifdef SHADING_PBR
fn pbr_brdf(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>, n_dot_l: f32) -> vec3<f32> {
    return pbr_diffuse(surface, n_dot_l) + pbr_specular(surface, view_dir, l, n_dot_l);
}

// The diffuse: its factors of the pixel alone times what the specular lobe leaves of the
// light, albedo x (1 - E(n.l)), as the pixel's sum of the fit's functions of n.l
// (`surface_for_loop`).
fn pbr_diffuse(surface: LitSurface, n_dot_l: f32) -> vec3<f32> {
    let p = 1.0 - n_dot_l;
    let p2 = p * p;
    let p4 = p2 * p2;
    let p8 = p4 * p4;
    return surface.diffuse_by_one + n_dot_l * surface.diffuse_by_mu + p2 * surface.diffuse_by_p_squared
        + p4 * surface.diffuse_by_p_fourth + p8 * surface.diffuse_by_p_eighth + (p8 * p8) * surface.diffuse_by_p_sixteenth;
}

// The specular F D V.
fn pbr_specular(surface: LitSurface, view_dir: vec3<f32>, l: vec3<f32>, n_dot_l: f32) -> vec3<f32> {
    let half_sum = l + view_dir;
    let half_length_squared = dot(half_sum, half_sum);
    // l = -v (the eye exactly opposite the light, possible only below a mapped normal):
    // no half vector; Fresnel there is total, so nothing is reflected.
    if half_length_squared <= 0.0 {
        return vec3<f32>(0.0);
    }
    // The half vector h is never normalized: its products with n and v follow from the
    // sum's (l and v are unit vectors: v.(l + v) = 1 + l.v = |l + v|^2 / 2).
    let inverse_half_length = inverseSqrt(half_length_squared);
    let n = surface.normal;
    let n_dot_half_sum = n_dot_l + surface.n_dot_view;
    let n_dot_h = n_dot_half_sum * inverse_half_length;
    let alpha2 = surface.alpha_squared;
    // D: alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2), with 1 - (n.h)^2 taken as |n x h|^2:
    // near the highlight's peak the subtraction would cancel every digit f32 has.
    let across = cross(n, half_sum);
    let d = (dot(across, across) + n_dot_half_sum * n_dot_half_sum * alpha2) * (inverse_half_length * inverse_half_length);
    // V: 0.5 / (n.l sqrt((n.v)^2 (1 - alpha^2) + alpha^2) + n.v sqrt((n.l)^2 (1 - alpha^2) + alpha^2)),
    // the first square root the pixel's.
    let lambda_v = n_dot_l * surface.view_visibility;
    let lambda_l = surface.n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - alpha2) + alpha2);
    // D x V with one division (a reciprocal is the loop's dearest instruction).
    let distribution_visibility = select(0.0, alpha2 * (0.5 * INV_PI) / (d * d * (lambda_v + lambda_l)), n_dot_h > 0.0);
    // F: Schlick's approximation at the angle between the view and the half vector.
    let v_dot_h = saturate(0.5 * half_length_squared * inverse_half_length);
    let fresnel = surface.specular + (vec3<f32>(1.0) - surface.specular) * pow5(1.0 - v_dot_h);
    return fresnel * distribution_visibility;
}
#endif

// The surface as a light loop reads it, made once per pixel before the loop
// (`surface_for_loop`): under PBR with the BRDF's terms of the pixel alone, so that each
// light pays only for its own (H200, 100,000 lights, tiles lighting: 12.46 -> 12.01 ms;
// with the half vector left unnormalized, 11.62; with the diffuse's E(n.l) a sum of
// functions of n.l rather than a table load, 10.98).
struct LitSurface {
    position: vec3<f32>,
    normal: vec3<f32>,
    // The diffuse reflectance (Blinn-Phong; PBR's `diffuse_by_*` replace it in the loop).
    albedo: vec3<f32>,
    specular: vec3<f32>,
    // Blinn-Phong's exponent (PBR's roughness is in the terms below).
    lobe: f32,
    position_error: f32,
#ifdef SHADING_PBR
    // n.v, and n.v held at a small positive value where the view grazes the surface or
    // is just below it (interpolated and mapped normals): the visibility term stays finite.
    n_dot_view: f32,
    n_dot_v: f32,
    // GGX's alpha^2 (alpha = roughness^2, the roughness at its floor at least).
    alpha_squared: f32,
    // sqrt((n.v)^2 (1 - alpha^2) + alpha^2): the visibility term's half of the view.
    view_visibility: f32,
    // The diffuse term for light at mu = n.l, the diffuse weight of the pixel (albedo / pi
    // x (1 - E(n.v)) / (1 - E_avg)) times 1 - E(mu), as the sum of the albedo fit's
    // functions of mu (specular_albedo.wgsl) with these coefficients: a few multiply-adds
    // a light where a table of mu cost a load.
    diffuse_by_one: vec3<f32>,
    diffuse_by_mu: vec3<f32>,
    diffuse_by_p_squared: vec3<f32>,
    diffuse_by_p_fourth: vec3<f32>,
    diffuse_by_p_eighth: vec3<f32>,
    diffuse_by_p_sixteenth: vec3<f32>,
    // E(n.v) with the pixel's F0: what the specular lobe reflects of a uniform sky, which
    // an area light's specular term never exceeds (`shade_area_light`).
    reflected_sky: vec3<f32>,
#ifndef NO_AREA_LIGHTS
    // From world directions to the clamped cosine's whose image is this pixel's specular
    // lobe: the frame (t, n x t, n), t the view along the surface, then the fitted M^-1
    // (`ltc_entries`). An area light's specular term integrates over its corners mapped
    // by it (`specular_area_integral`).
    to_cosine: mat3x3<f32>,
#endif
#endif
}

// The surface as a light loop reads it. Every loop calls it (naive, `shade_cluster`, the
// tile-shared loop, the references), and `pbr_brdf` expects it.
fn surface_for_loop(surface: Surface, view_dir: vec3<f32>) -> LitSurface {
#ifdef SHADING_PBR
    let n_dot_v = max(dot(surface.normal, view_dir), MIN_N_DOT_V);
    let roughness = max(surface.lobe, MIN_PERCEPTUAL_ROUGHNESS);
    let alpha = roughness * roughness;
    let alpha2 = alpha * alpha;
    let fit = albedo_fit(roughness);
    let weight = pbr_diffuse_weight(surface, n_dot_v, fit);
    let reflected_sky = specular_albedo(surface.specular, n_dot_v, fit);
    // weight x (1 - F0 A(mu) - B(mu)), per basis function.
    let by_f0 = weight * surface.specular;
    return LitSurface(
        surface.position,
        surface.normal,
        surface.albedo,
        surface.specular,
        surface.lobe,
        surface.position_error,
        dot(surface.normal, view_dir),
        n_dot_v,
        alpha2,
        sqrt(n_dot_v * n_dot_v * (1.0 - alpha2) + alpha2),
        weight - by_f0 * fit.a_first.x - weight * fit.b_first.x,
        -(by_f0 * fit.a_first.y + weight * fit.b_first.y),
        -(by_f0 * fit.a_first.z + weight * fit.b_first.z),
        -(by_f0 * fit.a_first.w + weight * fit.b_first.w),
        -(by_f0 * fit.a_last.x + weight * fit.b_last.x),
        -(by_f0 * fit.a_last.y + weight * fit.b_last.y),
        reflected_sky,
#ifndef NO_AREA_LIGHTS
        to_cosine(surface.normal, view_dir, ltc_entries(n_dot_v, roughness)),
#endif
    );
#else
    return LitSurface(surface.position, surface.normal, surface.albedo, surface.specular, surface.lobe, surface.position_error);
#endif
}

#ifndef NO_AREA_LIGHTS
// `LitSurface.to_cosine` for unit normal `n`, the view `view_dir` and M^-1's entries
// (m00, m02, m20, m22; m11 = 1): its rows are M^-1's rows applied to the frame's.
fn to_cosine(n: vec3<f32>, view_dir: vec3<f32>, entries: vec4<f32>) -> mat3x3<f32> {
    let along = view_dir - n * dot(n, view_dir);
    // Where the view is the normal the lobe is round: any t.
    let other = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    let t = select(normalize(cross(n, other)), normalize(along), dot(along, along) > 1e-12);
    return transpose(mat3x3<f32>(entries.x * t + entries.y * n, cross(n, t), entries.z * t + entries.w * n));
}
#endif

// The diffuse term's factors that depend on the pixel alone:
// albedo / pi x (1 - E(n.v)) / (1 - E_avg), zero where the specular lobe reflects
// everything (E_avg >= 1: F0 of 1, where the albedo is 0 too).
fn pbr_diffuse_weight(surface: Surface, n_dot_v: f32, fit: AlbedoFit) -> vec3<f32> {
    let kept = vec3<f32>(1.0) - specular_albedo_average(surface.specular, fit);
    let out = vec3<f32>(1.0) - specular_albedo(surface.specular, n_dot_v, fit);
    return select(vec3<f32>(0.0), surface.albedo * INV_PI * out / kept, kept > vec3<f32>(0.0));
}

fn pow5(x: f32) -> f32 {
    let x2 = x * x;
    return x2 * x2 * x;
}

const INV_PI: f32 = 0.318309886183791;
// The perceptual roughness GGX is evaluated at, at least: Filament's floor for f32
// (alpha 0.002). Below it alpha^2 (4e-6) nears f32's resolution of 1 - (n.h)^2 at the
// highlight, and the peak D = 1 / (pi alpha^2) (8e4) would grow without bound; a mirror
// (roughness 0) shades as this very sharp lobe. The f64 twin uses the same floor.
const MIN_PERCEPTUAL_ROUGHNESS: f32 = 0.045;
// The smallest n.v the visibility term divides by (Filament adds 1e-5 to |n.v|).
const MIN_N_DOT_V: f32 = 1e-4;
