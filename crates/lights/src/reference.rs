//! The shading model in f64: the accuracy reference for every GPU pipeline. It mirrors
//! `shaders/lights/shading.wgsl` and `brdf.wgsl` term for term (the BRDF of the surface's [`Shading`]:
//! glTF's metallic-roughness or Lambert plus Blinn-Phong, times colour x intensity x
//! falloff), without the f32 and half-float roundings.

use glam::DVec3;
pub use manylights_scene::Shading;

use crate::light::Light;

pub mod area;
mod visible_estimate;
pub use visible_estimate::{VisibleRadiance, shade_visible_estimate};

/// Smallest squared distance (m^2) the inverse-square law divides by: 1 cm squared.
///
/// Measured effect (`tests::epsilon_effect`): it changes a light's contribution by less
/// than 1% at distances of 10 cm and more, by exactly a factor d^2/eps below 1 cm, and
/// caps the contribution of a light touching a surface at 1e4 x intensity instead of
/// infinity. The same constant is in `shaders/lights/light_set.wgsl`.
pub const MIN_DISTANCE_SQUARED: f64 = 1e-4;

/// How a light's contribution falls off with distance d (radius r).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum Falloff {
    /// saturate(1 - (d/r)^4)^2 / max(d^2, eps): smooth, exactly 0 at the radius. Default.
    #[default]
    WindowedInverseSquare,
    /// clamp(1 - (d/r)^4, 0, 1) / d^2: the reference projects' falloff (no epsilon).
    ReferenceProjects,
    /// 1 / max(d^2, eps), unbounded: the accuracy reference.
    InverseSquare,
}

impl Falloff {
    /// The value of this mode in `shaders/lights/shading.wgsl`.
    pub fn shader_mode(&self) -> u32 {
        match self {
            Falloff::WindowedInverseSquare => 0,
            Falloff::ReferenceProjects => 1,
            Falloff::InverseSquare => 2,
        }
    }

    /// Whether the light's radius bounds its reach (so light lists can cull by it).
    pub fn is_bounded(&self) -> bool {
        !matches!(self, Falloff::InverseSquare)
    }

    pub const ALL: [Falloff; 3] = [
        Falloff::WindowedInverseSquare,
        Falloff::ReferenceProjects,
        Falloff::InverseSquare,
    ];

    /// Its name on command lines, in the lab and the viewer.
    pub fn name(&self) -> &'static str {
        match self {
            Falloff::WindowedInverseSquare => "windowed",
            Falloff::ReferenceProjects => "reference-projects",
            Falloff::InverseSquare => "inverse-square",
        }
    }
}

manylights_gpu::named_choice!(Falloff, "falloff");

/// A falloff whose radius bounds a light's reach: what pipelines that cull lights by
/// their radius (Forward+, deferred) can render exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum BoundedFalloff {
    #[default]
    WindowedInverseSquare,
    ReferenceProjects,
}

impl From<BoundedFalloff> for Falloff {
    fn from(bounded: BoundedFalloff) -> Falloff {
        match bounded {
            BoundedFalloff::WindowedInverseSquare => Falloff::WindowedInverseSquare,
            BoundedFalloff::ReferenceProjects => Falloff::ReferenceProjects,
        }
    }
}

impl TryFrom<Falloff> for BoundedFalloff {
    type Error = String;

    fn try_from(falloff: Falloff) -> Result<Self, String> {
        match falloff {
            Falloff::WindowedInverseSquare => Ok(BoundedFalloff::WindowedInverseSquare),
            Falloff::ReferenceProjects => Ok(BoundedFalloff::ReferenceProjects),
            Falloff::InverseSquare => Err(
                "the inverse-square falloff has no radius, so clustered pipelines cannot cull by it: use the naive pipeline, or a far field (FrameSettings::set_falloff, `--far-field`) which completes the windowed falloff to it".into(),
            ),
        }
    }
}

impl std::fmt::Display for BoundedFalloff {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        Falloff::from(*self).fmt(f)
    }
}

impl std::str::FromStr for BoundedFalloff {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        text.parse::<Falloff>()?.try_into()
    }
}

/// The falloff factor at squared distance `d2` from a light of radius `radius`.
pub fn falloff(mode: Falloff, d2: f64, radius: f64) -> f64 {
    let ratio_squared = d2 / (radius * radius);
    let window = 1.0 - ratio_squared * ratio_squared;
    match mode {
        Falloff::WindowedInverseSquare => {
            let w = window.clamp(0.0, 1.0);
            w * w / d2.max(MIN_DISTANCE_SQUARED)
        }
        Falloff::ReferenceProjects => window.clamp(0.0, 1.0) / d2,
        Falloff::InverseSquare => 1.0 / d2.max(MIN_DISTANCE_SQUARED),
    }
}

/// A shaded point, in full precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub position: DVec3,
    /// Unit normal.
    pub normal: DVec3,
    /// Diffuse albedo: the base colour (Blinn-Phong), base x (1 - metallic) (PBR).
    pub albedo: DVec3,
    /// Specular colour (Blinn-Phong) or F0 (PBR).
    pub specular: DVec3,
    /// The specular lobe: Blinn-Phong's exponent or PBR's perceptual roughness.
    pub lobe: f64,
    /// The BRDF the point is shaded with.
    pub shading: Shading,
    /// Radiance the surface emits itself (zero for most materials): added to what the
    /// lights reflect, as every GPU pipeline adds it.
    pub emission: DVec3,
}

impl SurfacePoint {
    /// Pixel `index` of a full-precision surface capture, in f64 (the world position is
    /// the capture's origin plus its camera-relative position). The one conversion the lab
    /// and the tests share.
    pub fn from_capture(surface: &manylights_gpu::SurfaceImage, index: usize) -> SurfacePoint {
        let to_f64 = |v: [f32; 4]| DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        let normal_lobe = surface.normal_lobe[index];
        SurfacePoint {
            position: surface.origin + to_f64(surface.position[index]),
            normal: to_f64(normal_lobe).normalize_or_zero(),
            albedo: to_f64(surface.albedo[index]),
            specular: to_f64(surface.specular[index]),
            lobe: f64::from(normal_lobe[3]),
            shading: surface.shading,
            emission: to_f64(surface.emission[index]),
        }
    }
}

/// Radiance from one light towards `view_dir` (unit, from the point to the eye).
pub fn shade_light(point: &SurfacePoint, view_dir: DVec3, light: &Light, mode: Falloff) -> DVec3 {
    if light.is_area() {
        return area::shade_area_light(point, view_dir, light, mode, None);
    }
    let light_position = DVec3::from_array(light.position.map(f64::from));
    let radius = light.radius as f64;
    let to_light = light_position - point.position;
    let d2 = to_light.length_squared();
    if (mode.is_bounded() && d2 >= radius * radius) || d2 <= 0.0 {
        return DVec3::ZERO;
    }
    let l = to_light / d2.sqrt();
    let n_dot_l = point.normal.dot(l);
    if n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    let color = DVec3::from_array(light.color.map(f64::from));
    color
        * (light.intensity as f64 * spot_attenuation(light, l) * falloff(mode, d2, radius))
        * n_dot_l
        * brdf(point, view_dir, l)
}

/// The point's BRDF for light from the unit direction `l` seen from the unit direction
/// `view_dir`, on the lit side (n.l > 0; callers test it).
pub fn brdf(point: &SurfacePoint, view_dir: DVec3, l: DVec3) -> DVec3 {
    match point.shading {
        Shading::Pbr => pbr_brdf(point, view_dir, l),
        Shading::BlinnPhong => blinn_phong_brdf(point, view_dir, l),
    }
}

/// Lambert plus Blinn-Phong: albedo + specular (n.h)^exponent (no 1/pi: the convention
/// the Blinn-Phong scenes' light intensities were chosen in).
fn blinn_phong_brdf(point: &SurfacePoint, view_dir: DVec3, l: DVec3) -> DVec3 {
    let half = l + view_dir;
    let specular = if half.length_squared() > 0.0 {
        point.specular * point.normal.dot(half.normalize()).max(0.0).powf(point.lobe)
    } else {
        DVec3::ZERO
    };
    point.albedo + specular
}

/// The perceptual roughness GGX is evaluated at, at least (`MIN_PERCEPTUAL_ROUGHNESS` in
/// brdf.wgsl: Filament's floor for f32, alpha 0.002; the twin shades the same lobe).
pub const MIN_PERCEPTUAL_ROUGHNESS: f64 = 0.045;

/// The smallest n.v the visibility term divides by (`MIN_N_DOT_V` in brdf.wgsl); the
/// albedo fit's domain starts there.
pub use crate::specular_albedo::MIN_N_DOT_V;

/// glTF's metallic-roughness BRDF (brdf.wgsl's `pbr_brdf`) in f64: Appendix B's
/// specular F D V (GGX D, height-correlated Smith V, Schlick F) and a Lambert diffuse
/// weighted by what the specular lobe leaves in and out,
/// albedo / pi x (1 - E(n.v)) (1 - E(n.l)) / (1 - E_avg) ([`crate::specular_albedo`]).
fn pbr_brdf(point: &SurfacePoint, view_dir: DVec3, l: DVec3) -> DVec3 {
    let half = l + view_dir;
    if half.length_squared() <= 0.0 {
        return DVec3::ZERO;
    }
    let h = half.normalize();
    let n = point.normal;
    let n_dot_l = n.dot(l).clamp(0.0, 1.0);
    let n_dot_v = n.dot(view_dir).max(MIN_N_DOT_V);
    let n_dot_h = n.dot(h);
    let alpha = point.lobe.max(MIN_PERCEPTUAL_ROUGHNESS).powi(2);
    let alpha2 = alpha * alpha;
    let distribution = if n_dot_h > 0.0 {
        let d = n_dot_h * n_dot_h * (alpha2 - 1.0) + 1.0;
        alpha2 / (std::f64::consts::PI * d * d)
    } else {
        0.0
    };
    let visibility = 0.5
        / (n_dot_l * (n_dot_v * n_dot_v * (1.0 - alpha2) + alpha2).sqrt()
            + n_dot_v * (n_dot_l * n_dot_l * (1.0 - alpha2) + alpha2).sqrt());
    let v_dot_h = view_dir.dot(h).clamp(0.0, 1.0);
    let fresnel = point.specular + (DVec3::ONE - point.specular) * (1.0 - v_dot_h).powi(5);
    let roughness = point.lobe.max(MIN_PERCEPTUAL_ROUGHNESS);
    let table = crate::specular_albedo::SpecularAlbedoFit::committed();
    let kept = DVec3::ONE - table.average(point.specular, roughness);
    let out = DVec3::ONE - table.albedo(point.specular, n_dot_v, roughness);
    let into = DVec3::ONE - table.albedo(point.specular, n_dot_l, roughness);
    let weight = DVec3::select(kept.cmpgt(DVec3::ZERO), out * into / kept, DVec3::ZERO);
    point.albedo / std::f64::consts::PI * weight + fresnel * (distribution * visibility)
}

/// A spot light's cone attenuation towards the unit direction `l` (from the lit point to
/// the light), glTF's smooth falloff saturate(t)^2 with
/// t = (cos a - cos outer) / (cos inner - cos outer), straight from its definition in f64
/// (the WGSL evaluates an algebraically equal form that keeps f32 precision for thin
/// cones); 1 for point lights. inner == outer is a hard edge.
pub fn spot_attenuation(light: &Light, l: DVec3) -> f64 {
    if !light.is_spot() {
        return 1.0;
    }
    let axis = DVec3::from_array(light.direction.map(f64::from));
    let cos_angle = -l.dot(axis);
    let sin2_outer = light.sin2_outer as f64;
    let sin2_inner = light.sin2_inner as f64;
    let cos_outer = (1.0 - sin2_outer).sqrt();
    let cos_inner = (1.0 - sin2_inner).sqrt();
    if cos_angle <= cos_outer || cos_angle <= 0.0 {
        return 0.0;
    }
    if cos_angle >= cos_inner || cos_inner <= cos_outer {
        return 1.0;
    }
    let t = ((cos_angle - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
    t * t
}

/// Radiance towards the eye at `camera` from all lights.
pub fn shade(point: &SurfacePoint, camera: DVec3, lights: &[Light], mode: Falloff) -> DVec3 {
    let view_dir = (camera - point.position).normalize_or_zero();
    point.emission
        + lights
            .iter()
            .map(|light| shade_light(point, view_dir, light, mode))
            .sum::<DVec3>()
}

/// Radiance towards the eye at `camera` from the lights, as far as `visible` (whether a
/// world-space point of a light reaches the lit point: a shadow ray) lets them: the
/// reference with visibility. A point or spot is seen or not (one ray, only where it adds
/// something); an area light's integral counts the points of it that are seen
/// ([`visible_term`]).
pub fn shade_visible(
    point: &SurfacePoint,
    camera: DVec3,
    lights: &[Light],
    mode: Falloff,
    visible: impl Fn(DVec3) -> bool,
) -> DVec3 {
    let view_dir = (camera - point.position).normalize_or_zero();
    point.emission
        + lights
            .iter()
            .map(|light| {
                let term = shade_light(point, view_dir, light, mode);
                visible_term(point, view_dir, light, term, mode, &visible)
            })
            .sum::<DVec3>()
}

/// What of a light's unshadowed `term` reaches the point when `visible` says which of the
/// light's world-space points it sees: all or nothing for a point or spot (by its
/// position), the integral over the seen points for an area light (its quadrature with a
/// ray a point, [`area::shade_area_light`]).
pub fn visible_term(
    point: &SurfacePoint,
    view_dir: DVec3,
    light: &Light,
    term: DVec3,
    mode: Falloff,
    visible: &dyn Fn(DVec3) -> bool,
) -> DVec3 {
    if term == DVec3::ZERO {
        return DVec3::ZERO;
    }
    if light.is_area() {
        return area::shade_area_light(point, view_dir, light, mode, Some(visible));
    }
    if visible(glam::Vec3::from_array(light.position).as_dvec3()) {
        term
    } else {
        DVec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light_at(distance: f64, radius: f32) -> Light {
        Light::point(
            glam::Vec3::new(0.0, distance as f32, 0.0),
            radius,
            glam::Vec3::ONE,
            1.0,
        )
    }

    fn floor_point() -> SurfacePoint {
        SurfacePoint {
            position: DVec3::ZERO,
            normal: DVec3::Y,
            albedo: DVec3::ONE,
            specular: DVec3::ZERO,
            emission: DVec3::ZERO,
            lobe: 1.0,
            shading: Shading::BlinnPhong,
        }
    }

    /// Measures what `MIN_DISTANCE_SQUARED` does to a light straight above a surface,
    /// against the exact 1/d^2 law.
    #[test]
    fn epsilon_effect() {
        let exact = |d: f64| 1.0 / (d * d);
        let with_epsilon = |d: f64| {
            shade(
                &floor_point(),
                DVec3::new(0.0, 10.0, 0.0),
                &[light_at(d, 1e6)],
                Falloff::InverseSquare,
            )
            .x
        };
        // 10 cm and beyond: under 1% change.
        for d in [0.1, 0.2, 1.0, 10.0] {
            let relative = (with_epsilon(d) - exact(d)).abs() / exact(d);
            assert!(relative < 0.01, "d = {d}: {relative}");
        }
        // Below 1 cm the contribution is capped at 1/eps = 1e4 (the light's f32 position
        // makes the distance inexact, hence the tolerance).
        for d in [1e-3, 1e-5, 1e-7] {
            let value = with_epsilon(d);
            assert!(
                (value - 1.0 / MIN_DISTANCE_SQUARED).abs() < 1e-6 / MIN_DISTANCE_SQUARED,
                "d = {d}: {value}"
            );
        }
        // Exactly on the surface: nothing (no direction), never infinite or NaN.
        assert_eq!(with_epsilon(0.0), 0.0);
        // Without the epsilon (reference projects' falloff) 1 mm gives 1e6: the spike the
        // epsilon removes.
        let spike = shade(
            &floor_point(),
            DVec3::new(0.0, 10.0, 0.0),
            &[light_at(1e-3, 2.0)],
            Falloff::ReferenceProjects,
        )
        .x;
        assert!(spike > 0.99e6, "{spike}");
    }

    #[test]
    fn windowed_falloff_is_zero_at_the_radius_and_close_to_inverse_square_inside() {
        assert_eq!(falloff(Falloff::WindowedInverseSquare, 4.0, 2.0), 0.0);
        assert_eq!(falloff(Falloff::ReferenceProjects, 4.0, 2.0), 0.0);
        // At a tenth of the radius the window is 1 - 1e-4 squared.
        let inside = falloff(Falloff::WindowedInverseSquare, 0.04, 2.0);
        assert!((inside * 0.04 - (1.0 - 1e-4f64).powi(2)).abs() < 1e-12);
        // Monotonic decrease.
        let mut previous = f64::INFINITY;
        for step in 1..100 {
            let d = step as f64 * 0.02;
            let value = falloff(Falloff::WindowedInverseSquare, d * d, 2.0);
            assert!(value <= previous);
            previous = value;
        }
    }

    #[test]
    fn lambert_and_blinn_phong() {
        let mut point = floor_point();
        // Light at 45 degrees, 1 m away: diffuse = cos 45.
        let light = Light::point(
            glam::Vec3::new(
                std::f32::consts::FRAC_1_SQRT_2,
                std::f32::consts::FRAC_1_SQRT_2,
                0.0,
            ),
            1e6,
            glam::Vec3::new(1.0, 0.5, 0.25),
            2.0,
        );
        let diffuse = shade(
            &point,
            DVec3::new(0.0, 5.0, 0.0),
            &[light],
            Falloff::InverseSquare,
        );
        let expected = DVec3::new(1.0, 0.5, 0.25) * 2.0 * std::f64::consts::FRAC_1_SQRT_2;
        assert!(diffuse.abs_diff_eq(expected, 1e-6), "{diffuse}");
        // Mirror direction: the half vector is the normal, specular adds fully.
        point.specular = DVec3::splat(0.5);
        point.lobe = 32.0;
        let eye = DVec3::new(-1.0, 1.0, 0.0);
        let lit = shade(&point, eye, &[light], Falloff::InverseSquare);
        assert!(lit.abs_diff_eq(expected * 1.5, 1e-5), "{lit}");
        // A light below the surface contributes nothing.
        let below = Light {
            position: [0.0, -1.0, 0.0],
            ..light
        };
        assert_eq!(
            shade(&point, eye, &[below], Falloff::InverseSquare),
            DVec3::ZERO
        );
    }

    /// A point on the floor (normal +Y) with glTF's metallic-roughness material of base
    /// colour `base`.
    fn pbr_point(base: f64, metallic: f64, roughness: f64) -> SurfacePoint {
        SurfacePoint {
            albedo: DVec3::splat(base * (1.0 - metallic)),
            specular: DVec3::splat(0.04 + (base - 0.04) * metallic),
            lobe: roughness,
            shading: Shading::Pbr,
            ..floor_point()
        }
    }

    /// The unit direction `theta` from the normal (+Y), turned `phi` about it.
    fn direction(theta: f64, phi: f64) -> DVec3 {
        DVec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    }

    /// Points 0..n of the 2D Hammersley set, a low-discrepancy quadrature of the square.
    fn hammersley(n: u32) -> impl Iterator<Item = (f64, f64)> {
        (0..n).map(move |i| {
            let radical = f64::from(i.reverse_bits()) / 4_294_967_296.0;
            ((f64::from(i) + 0.5) / f64::from(n), radical)
        })
    }

    /// The directional albedo of `point` seen from `view`: the integral of BRDF x n.l over
    /// the hemisphere, as two quadratures matched to its terms (the diffuse one over
    /// cosine-distributed directions, the specular one over GGX-distributed half vectors,
    /// so that a sharp lobe is not missed between the points).
    fn directional_albedo(point: &SurfacePoint, view: DVec3) -> f64 {
        let (diffuse, specular) = directional_albedos(point, view);
        diffuse + specular
    }

    /// The diffuse and the specular terms' parts of [`directional_albedo`].
    fn directional_albedos(point: &SurfacePoint, view: DVec3) -> (f64, f64) {
        const POINTS: u32 = 1 << 16;
        let pi = std::f64::consts::PI;
        let alpha = point.lobe.max(MIN_PERCEPTUAL_ROUGHNESS).powi(2);
        let alpha2 = alpha * alpha;
        let (mut diffuse, mut specular) = (0.0, 0.0);
        for (u, w) in hammersley(POINTS) {
            // Diffuse: l cosine-distributed (pdf n.l / pi), so term x n.l / pdf = term x pi.
            let l = direction(u.sqrt().asin(), 2.0 * pi * w);
            diffuse += diffuse_term(point, view, l).x * pi;
            // Specular: h GGX-distributed (pdf D n.h), l the mirror of v about it
            // (pdf D n.h / (4 v.h)).
            let cos_h = ((1.0 - u) / (1.0 + (alpha2 - 1.0) * u)).sqrt();
            let h = direction(cos_h.acos(), 2.0 * pi * w);
            let v_dot_h = view.dot(h);
            let l = 2.0 * v_dot_h * h - view;
            if l.y > 0.0 && v_dot_h > 0.0 {
                let x = cos_h * cos_h * (alpha2 - 1.0) + 1.0;
                let d = alpha2 / (pi * x * x);
                let pdf = d * cos_h / (4.0 * v_dot_h);
                specular += specular_term(point, view, l).x * l.y / pdf;
            }
        }
        let points = f64::from(POINTS);
        (diffuse / points, specular / points)
    }

    /// The BRDF's diffuse term, (1 - F) albedo / pi, at (v, l).
    fn diffuse_term(point: &SurfacePoint, view: DVec3, l: DVec3) -> DVec3 {
        brdf(point, view, l) - specular_term(point, view, l)
    }

    /// The BRDF's specular term, F D V, at (v, l): the BRDF of the same point without albedo.
    fn specular_term(point: &SurfacePoint, view: DVec3, l: DVec3) -> DVec3 {
        brdf(
            &SurfacePoint {
                albedo: DVec3::ZERO,
                ..*point
            },
            view,
            l,
        )
    }

    /// The quadrature's error bound, checked where the albedo is known: a white mirror
    /// reflects everything.
    const QUADRATURE_TOLERANCE: f64 = 1e-3;

    /// The white furnace. A white metal and a white dielectric, at every roughness from the
    /// mirror to 1 and views from normal to grazing, reflect at most what reaches them
    /// (directional albedo <= 1; single scattering loses the rest of a rough metal's). The
    /// dielectric's diffuse term takes exactly what its specular lobe leaves, so it stays
    /// within the table's bound of 1 (0.5% up to 80 degrees). Fails if D is not normalized,
    /// if V is not the height-correlated visibility, if the diffuse term does not give up
    /// what the specular lobe reflects (Appendix B's 1 - F(v.h) reflects 1.84 at 89
    /// degrees) or gives up more.
    #[test]
    fn pbr_directional_albedo_is_bounded() {
        for theta in [0.0f64, 30.0, 60.0] {
            let mirror = pbr_point(1.0, 1.0, 0.0);
            let albedo = directional_albedo(&mirror, direction(theta.to_radians(), 0.0));
            assert!(
                (albedo - 1.0).abs() < QUADRATURE_TOLERANCE,
                "a white mirror at {theta} degrees reflects {albedo}"
            );
        }
        for metallic in [0.0, 1.0] {
            for roughness in [0.0, 0.045, 0.1, 0.25, 0.5, 0.75, 1.0] {
                for theta in [0.0f64, 30.0, 60.0, 80.0, 89.0] {
                    let point = pbr_point(1.0, metallic, roughness);
                    let albedo = directional_albedo(&point, direction(theta.to_radians(), 0.0));
                    println!(
                        "metallic {metallic}, roughness {roughness}, {theta} degrees: {albedo:.4}"
                    );
                    assert!(
                        albedo > 0.25 && albedo <= 1.0 + QUADRATURE_TOLERANCE,
                        "metallic {metallic}, roughness {roughness}, view {theta} degrees: {albedo}"
                    );
                    if metallic == 0.0 && theta <= 80.0 {
                        assert!(
                            albedo >= 0.995,
                            "a white dielectric of roughness {roughness} at {theta} degrees reflects only {albedo}"
                        );
                    }
                }
            }
        }
    }

    /// Helmholtz reciprocity: swapping the light and the eye leaves the BRDF unchanged.
    #[test]
    fn pbr_brdf_is_reciprocal() {
        let point = SurfacePoint {
            albedo: DVec3::new(0.5, 0.3, 0.1),
            specular: DVec3::new(0.2, 0.5, 0.9),
            ..pbr_point(0.5, 0.3, 0.35)
        };
        for (a, b) in [(0.1, 1.2), (0.7, 0.2), (1.3, 1.4), (0.0, 0.9)] {
            for phi in [0.0, 1.0, 2.5, 3.1] {
                let (v, l) = (direction(a, 0.0), direction(b, phi));
                let (forward, backward) = (brdf(&point, v, l), brdf(&point, l, v));
                assert!(
                    forward.abs_diff_eq(backward, 1e-12 * forward.max_element()),
                    "{forward} against {backward}"
                );
            }
        }
    }

    /// At normal incidence Fresnel is F0, a metal's base colour: with light and eye on the
    /// normal the BRDF is F0 x D(1) x V(1, 1) = F0 / (4 pi alpha^2).
    #[test]
    fn a_metals_reflectance_at_normal_incidence_is_its_base_colour() {
        let base = DVec3::new(0.95, 0.64, 0.54);
        for roughness in [0.1, 0.5, 1.0] {
            let point = SurfacePoint {
                albedo: DVec3::ZERO,
                specular: base,
                ..pbr_point(1.0, 1.0, roughness)
            };
            let alpha = roughness * roughness;
            let f0 = brdf(&point, DVec3::Y, DVec3::Y) * 4.0 * std::f64::consts::PI * alpha * alpha;
            assert!(f0.abs_diff_eq(base, 1e-12), "roughness {roughness}: {f0}");
        }
    }

    /// The highlight narrows and brightens as roughness falls: seen along the normal, the
    /// light's angle at which the reflected specular radiance halves grows with roughness,
    /// and the peak falls.
    #[test]
    fn the_highlight_narrows_as_roughness_falls() {
        let mut previous: Option<(f64, f64)> = None;
        for roughness in [0.1, 0.2, 0.4, 0.8] {
            let point = pbr_point(1.0, 1.0, roughness);
            // The eye on the normal, the light `angle` off it: the radiance reflected.
            let at =
                |angle: f64| specular_term(&point, DVec3::Y, direction(angle, 0.0)).x * angle.cos();
            let peak = at(0.0);
            let half_width = (1..15_000)
                .map(|step| f64::from(step) * 1e-4)
                .find(|&angle| at(angle) < 0.5 * peak)
                .expect("the lobe halves before the horizon");
            if let Some((previous_width, previous_peak)) = previous {
                assert!(
                    half_width > previous_width,
                    "roughness {roughness}: {half_width} <= {previous_width}"
                );
                assert!(
                    peak < previous_peak,
                    "roughness {roughness}: peak {peak} >= {previous_peak}"
                );
            }
            previous = Some((half_width, peak));
        }
    }

    /// Finite, non-negative radiance at the extremes: roughness 0 and 1, metallic 0 and 1,
    /// the eye and the light grazing the surface (and the eye just below it), a light
    /// touching the surface, and lights of 1 um and 1,000 km radius.
    #[test]
    fn pbr_shading_is_finite_at_the_extremes() {
        let grazing = std::f64::consts::FRAC_PI_2;
        let views = [0.0, 1.0, grazing - 1e-9, grazing, grazing + 1e-6];
        let light_positions = [
            glam::Vec3::new(0.0, 1.0, 0.0),
            glam::Vec3::new(1.0, 1e-7, 0.0),
            glam::Vec3::new(0.0, 1e-9, 0.0),
            glam::Vec3::new(1e-9, 0.0, 0.0),
            glam::Vec3::new(-0.7, 0.7, 0.0),
        ];
        for metallic in [0.0, 1.0] {
            for roughness in [0.0, 1e-9, 0.045, 1.0] {
                let point = pbr_point(1.0, metallic, roughness);
                for theta in views {
                    let eye = direction(theta, 0.0) * 2.0;
                    for position in light_positions {
                        for radius in [1e-6f32, 1e6] {
                            let light = Light::point(position, radius, glam::Vec3::ONE, 1e3);
                            for mode in Falloff::ALL {
                                let radiance = shade(&point, eye, &[light], mode);
                                assert!(
                                    radiance.is_finite() && radiance.min_element() >= 0.0,
                                    "metallic {metallic}, roughness {roughness}, view {theta}, light {position} r {radius}, {mode}: {radiance}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    fn spot_above_floor(cone: crate::SpotCone) -> Light {
        Light::spot(
            glam::Vec3::new(0.0, 1.0, 0.0),
            1e6,
            glam::Vec3::ONE,
            1.0,
            glam::Vec3::NEG_Y,
            cone,
        )
    }

    /// glTF's definition: full inside the inner cone, zero outside the outer, and
    /// saturate(t)^2 between; nothing behind the light.
    #[test]
    fn spot_attenuation_follows_the_gltf_definition() {
        let cone = crate::SpotCone {
            inner: 0.3,
            outer: 0.6,
        };
        let light = spot_above_floor(cone);
        let towards = |angle: f64| {
            // Direction from a lit point to the light, `angle` off the spot's axis.
            DVec3::new(angle.sin(), angle.cos(), 0.0)
        };
        assert_eq!(spot_attenuation(&light, towards(0.0)), 1.0);
        assert_eq!(spot_attenuation(&light, towards(0.29)), 1.0);
        assert_eq!(spot_attenuation(&light, towards(0.61)), 0.0);
        assert_eq!(spot_attenuation(&light, -towards(0.0)), 0.0);
        let angle: f64 = 0.45;
        let t = (angle.cos() - 0.6f64.cos()) / (0.3f64.cos() - 0.6f64.cos());
        let value = spot_attenuation(&light, towards(angle));
        // The cone's angles went through f32 sin^2.
        assert!((value - t * t).abs() < 1e-5, "{value} against {}", t * t);
        // A point light has no cone.
        assert_eq!(
            spot_attenuation(&light_at(1.0, 2.0), -towards(0.0)),
            1.0,
            "a point light lights every direction"
        );
    }

    /// A 1e-4 rad cone lights the point on its axis and nothing 2e-4 rad off it, and a
    /// hard-edged cone (inner == outer) is 1 inside and 0 outside.
    #[test]
    fn thin_and_hard_edged_cones() {
        let thin = spot_above_floor(crate::SpotCone {
            inner: 0.5e-4,
            outer: 1e-4,
        });
        assert_eq!(spot_attenuation(&thin, DVec3::Y), 1.0);
        let off = DVec3::new(2e-4f64.sin(), 2e-4f64.cos(), 0.0);
        assert_eq!(spot_attenuation(&thin, off), 0.0);
        let hard = spot_above_floor(crate::SpotCone {
            inner: 0.5,
            outer: 0.5,
        });
        assert_eq!(
            spot_attenuation(&hard, DVec3::new(0.49f64.sin(), 0.49f64.cos(), 0.0)),
            1.0
        );
        assert_eq!(
            spot_attenuation(&hard, DVec3::new(0.51f64.sin(), 0.51f64.cos(), 0.0)),
            0.0
        );
    }
}
