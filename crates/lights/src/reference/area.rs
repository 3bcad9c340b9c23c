//! Area lights in the f64 twin: the light integrated numerically, point by point, with
//! the BRDF and both cosines exact at every point (the GPU's shading splits the integral
//! at the BRDF and approximates its specular half: `shaders/lights/shading.wgsl` and `brdf.wgsl`).

use glam::{DVec3, Vec3};

use super::{Falloff, Shading, SurfacePoint, brdf};
use crate::light::{LIGHT_RECT, LIGHT_SPHERE, Light};

/// Points of `light` (a sphere's visible cap, a rectangle, a triangle) seen from `from`,
/// each with the solid angle it stands for (for flat lights cos(at the light) dA / r^2; 0
/// where the point is behind the light): the midpoints of cells of the light's parameter
/// square, split into four until each looks smaller than `max_angle` radians from `from`
/// (and, for a sphere, until no cell is cut by the horizon of `normal`'s plane), down to
/// [`MIN_CELL`] of the square's side. Adaptive, so a light touching the lit point or filling its sky is
/// integrated as finely where it is close as a small one is.
pub fn light_samples(
    light: &Light,
    from: DVec3,
    normal: DVec3,
    (max_angle, max_cell): (f64, f64),
) -> Vec<(DVec3, f64)> {
    let shape = Shape::new(light, from);
    let mut out = Vec::new();
    let mut cells = vec![(0.0f64, 0.0f64, 1.0f64)];
    while let Some((u, v, size)) = cells.pop() {
        let corners = [(u, v), (u + size, v), (u, v + size), (u + size, v + size)]
            .map(|(s, t)| shape.direction(s, t));
        let angle = corners
            .iter()
            .flat_map(|a| corners.iter().map(move |b| a.angle_between(*b)))
            .fold(0.0, f64::max);
        let heights = corners.map(|d| d.dot(normal));
        let cut = heights.iter().any(|h| *h > 0.0) && heights.iter().any(|h| *h <= 0.0);
        let too_large = angle > max_angle || (size > max_cell && angle > VISIBILITY_CELL_ANGLE);
        if size > MIN_CELL && (too_large || (cut && shape.is_sphere())) {
            let half = size / 2.0;
            cells.extend(
                [(u, v), (u + half, v), (u, v + half), (u + half, v + half)]
                    .map(|(s, t)| (s, t, half)),
            );
            continue;
        }
        out.push(shape.sample(u + size / 2.0, v + size / 2.0, size * size));
    }
    out
}

/// The largest angle [`shade_area_light`]'s cells subtend: 1/32 rad. The midpoint rule
/// errs by about (cell angle)^2 / 24 of the integrand's curvature, 4e-5 relative here.
pub const MAX_CELL_ANGLE: f64 = 1.0 / 32.0;

/// The reference with visibility splits every light into this many cells a side (32 x 32
/// points, each with its ray), or until its cells subtend [`VISIBILITY_CELL_ANGLE`]: a
/// shadow edge crossing the light is then placed to 1/32 of it, where the pipelines'
/// exact shadows take 4 x 4.
pub const VISIBILITY_GRID: f64 = 32.0;

/// Cells of a light that look smaller than this from the lit point, 1/512 rad (0.11
/// degrees), are not split further for its visibility: a small light far away
/// (sponza-embers' 6 cm embers at 3 m: 16 x 16 points, a quarter of the rays) places its
/// shadow edges as finely in angle as a large one close by. A light subtending 1/16 rad
/// or more keeps all 32 x 32 (the penumbra test's: at 1/256 its mean error against the
/// pipelines' 4 x 4 strata rose from 0.093 to 0.124, the coarser reference's own).
pub const VISIBILITY_CELL_ANGLE: f64 = 1.0 / 512.0;

/// The smallest cell, as a share of the light's side: 2^-12 (2.4 cm of a light 100 m across:
/// Lambert terms near such a light are exact by the closed form).
pub const MIN_CELL: f64 = 1.0 / 4096.0;

/// A light's parameter square mapped onto its surface (flat lights) or its cap's
/// directions (spheres), as seen from one point.
struct Shape {
    from: DVec3,
    kind: u32,
    centre: DVec3,
    first: DVec3,
    second: DVec3,
    /// Flat lights: unit normal and area.
    normal: DVec3,
    area: f64,
    /// Spheres: the cone of directions the sphere covers (all of them from inside).
    axis: DVec3,
    across: (DVec3, DVec3),
    cos_cap: f64,
}

impl Shape {
    fn new(light: &Light, from: DVec3) -> Self {
        let centre = Vec3::from_array(light.position).as_dvec3();
        let first = Vec3::from_array(light.direction).as_dvec3();
        let second = light.second_edge().as_dvec3();
        let facing = first.cross(second);
        let to_centre = centre - from;
        let distance = to_centre.length();
        let radius = light.extent as f64;
        let axis = if distance > 0.0 {
            to_centre / distance
        } else {
            DVec3::Z
        };
        Self {
            from,
            kind: light.kind,
            centre,
            first,
            second,
            normal: facing.normalize_or_zero(),
            area: match light.kind {
                LIGHT_RECT => 4.0 * facing.length(),
                _ => 1.5 * facing.length(),
            },
            axis,
            across: axis.any_orthonormal_pair(),
            cos_cap: if light.kind == LIGHT_SPHERE && distance > radius {
                (1.0 - (radius / distance).powi(2)).sqrt()
            } else {
                -1.0
            },
        }
    }

    fn is_sphere(&self) -> bool {
        self.kind == LIGHT_SPHERE
    }

    /// The point of parameters (s, t) (a sphere's: one metre along its direction).
    fn point(&self, s: f64, t: f64) -> DVec3 {
        match self.kind {
            LIGHT_SPHERE => {
                let cos_theta = 1.0 - s * (1.0 - self.cos_cap);
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let phi = std::f64::consts::TAU * t;
                let (u, v) = self.across;
                self.from + self.axis * cos_theta + (u * phi.cos() + v * phi.sin()) * sin_theta
            }
            LIGHT_RECT => {
                self.centre + (2.0 * s - 1.0) * self.first + (2.0 * t - 1.0) * self.second
            }
            _ => {
                // The square onto the triangle, area for area.
                let corners = [
                    self.centre + self.first,
                    self.centre + self.second,
                    self.centre - self.first - self.second,
                ];
                let root = s.sqrt();
                corners[0] * (1.0 - root)
                    + corners[1] * (root * (1.0 - t))
                    + corners[2] * (root * t)
            }
        }
    }

    fn direction(&self, s: f64, t: f64) -> DVec3 {
        (self.point(s, t) - self.from).normalize_or_zero()
    }

    /// The point of parameters (s, t) and the solid angle of a cell of `share` of the
    /// square around it.
    fn sample(&self, s: f64, t: f64, share: f64) -> (DVec3, f64) {
        let point = self.point(s, t);
        if self.is_sphere() {
            return (point, std::f64::consts::TAU * (1.0 - self.cos_cap) * share);
        }
        let to_point = point - self.from;
        let distance_squared = to_point.length_squared();
        let cos_light = self.normal.dot(-to_point) / distance_squared.sqrt();
        let weight = if cos_light > 0.0 {
            self.area * share * cos_light / distance_squared
        } else {
            0.0
        };
        (point, weight)
    }
}

/// The light's cosine-weighted solid angle seen from `from` with unit normal `n` (the
/// integral of n.l over it) in closed form: Lambert's polygon formula clipped at the
/// horizon, the sphere's cap formula (the WGSL's `area_cosine_integral`, in f64). The
/// twin shades the constant part of a BRDF (Blinn-Phong's Lambert) with it, exactly, and
/// the rest by quadrature; `the_closed_forms_match_the_quadrature` holds the two to each
/// other.
pub fn cosine_integral(light: &Light, from: DVec3, n: DVec3) -> f64 {
    let centre = Vec3::from_array(light.position).as_dvec3() - from;
    match light.kind {
        LIGHT_SPHERE => sphere_closed_form(centre, light.extent as f64, n),
        kind => {
            // In f64 from the centre: corners summed in f32 would round a small light's
            // shape away.
            let first = Vec3::from_array(light.direction).as_dvec3();
            let second = light.second_edge().as_dvec3();
            let corners: Vec<DVec3> = if kind == LIGHT_RECT {
                vec![
                    centre - first - second,
                    centre + first - second,
                    centre + first + second,
                    centre - first + second,
                ]
            } else {
                vec![centre + first, centre + second, centre - first - second]
            };
            polygon_closed_form(&corners, n)
        }
    }
}

/// Lambert's polygon formula (the WGSL's `polygon_cosine_integral`) in f64: corners
/// relative to the lit point, counter-clockwise seen from the lit side, clipped at the
/// horizon first.
pub fn polygon_closed_form(corners: &[DVec3], n: DVec3) -> f64 {
    let mut clipped = Vec::new();
    for (i, &a) in corners.iter().enumerate() {
        let b = corners[(i + 1) % corners.len()];
        let (ha, hb) = (a.dot(n), b.dot(n));
        if ha > 0.0 {
            clipped.push(a);
        }
        if (ha > 0.0) != (hb > 0.0) && ha != hb {
            clipped.push(a + (b - a) * (ha / (ha - hb)));
        }
    }
    let mut sum = 0.0;
    for (i, &a) in clipped.iter().enumerate() {
        let b = clipped[(i + 1) % clipped.len()];
        let across = a.cross(b);
        if across.length() > 0.0 {
            sum += across.length().atan2(a.dot(b)) * n.dot(across) / across.length();
        }
    }
    (-0.5 * sum).max(0.0)
}

/// The sphere's closed form (the WGSL's `sphere_cosine_integral`) in f64.
pub fn sphere_closed_form(centre: DVec3, radius: f64, n: DVec3) -> f64 {
    let d2 = centre.length_squared();
    if d2 <= radius * radius {
        return std::f64::consts::PI;
    }
    let sin2 = radius * radius / d2;
    let cos_t = n.dot(centre) / d2.sqrt();
    if cos_t * cos_t >= sin2 {
        return std::f64::consts::PI * sin2 * cos_t.max(0.0);
    }
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let cot = (1.0 / sin2 - 1.0).sqrt();
    let y = (-cot * cos_t / sin_t).clamp(-1.0, 1.0);
    let chord = sin_t * (1.0 - y * y).sqrt();
    ((cos_t * y.acos() - cot * chord) * sin2 + chord.atan2(cot)).max(0.0)
}

/// The window of `mode` at squared distance `d2` from a light of radius `radius`: the
/// falloff without its inverse square.
pub fn window(mode: Falloff, d2: f64, radius: f64) -> f64 {
    let ratio_squared = d2 / (radius * radius);
    let window = 1.0 - ratio_squared * ratio_squared;
    match mode {
        Falloff::WindowedInverseSquare => window.clamp(0.0, 1.0).powi(2),
        Falloff::ReferenceProjects => window.clamp(0.0, 1.0),
        Falloff::InverseSquare => 1.0,
    }
}

/// Radiance from one area light towards `view_dir`: L x window(distance to its centre) x
/// the sum over its points of f(l) n.l times each point's solid angle ([`light_samples`]),
/// only the points `visible` (when given) says the lit point sees.
pub fn shade_area_light(
    point: &SurfacePoint,
    view_dir: DVec3,
    light: &Light,
    mode: Falloff,
    visible: Option<&dyn Fn(DVec3) -> bool>,
) -> DVec3 {
    let shadowed = visible.is_some();
    let visible = |at: DVec3| visible.is_none_or(|visible| visible(at));
    let centre = Vec3::from_array(light.position).as_dvec3();
    let d2 = (centre - point.position).length_squared();
    let radius = light.radius as f64;
    if mode.is_bounded() && d2 >= radius * radius {
        return DVec3::ZERO;
    }
    let area = light.area() as f64;
    if area <= 0.0 {
        return DVec3::ZERO;
    }
    let radiance = DVec3::from_array(light.color.map(f64::from)) * (light.intensity as f64 / area);
    // Blinn-Phong's Lambert term is a constant: unshadowed, it is exactly the albedo times
    // the closed form, and only its specular lobe (if any) needs the quadrature.
    let lambert = point.shading == Shading::BlinnPhong && !shadowed;
    if lambert && point.specular == DVec3::ZERO {
        return radiance
            * window(mode, d2, radius)
            * point.albedo
            * cosine_integral(light, point.position, point.normal);
    }
    // With visibility, VISIBILITY_GRID^2 points (fewer where they would look smaller than
    // VISIBILITY_CELL_ANGLE): the light's shadow edges are where the integrand jumps, and
    // only points find them.
    let max_cell = if shadowed { 1.0 / VISIBILITY_GRID } else { 1.0 };
    let sum: DVec3 = light_samples(
        light,
        point.position,
        point.normal,
        (MAX_CELL_ANGLE, max_cell),
    )
    .into_iter()
    .filter(|(_, weight)| *weight > 0.0)
    .filter_map(|(at, weight)| {
        let l = (at - point.position).normalize();
        let n_dot_l = point.normal.dot(l);
        let f = if lambert {
            brdf(point, view_dir, l) - point.albedo
        } else {
            brdf(point, view_dir, l)
        };
        (n_dot_l > 0.0 && visible(at)).then(|| f * (n_dot_l * weight))
    })
    .sum();
    let exact = if lambert {
        point.albedo * cosine_integral(light, point.position, point.normal)
    } else {
        DVec3::ZERO
    };
    radiance * window(mode, d2, radius) * (exact + sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quadrature(light: &Light, from: DVec3, n: DVec3) -> f64 {
        light_samples(light, from, n, (1.0 / 256.0, 1.0))
            .into_iter()
            .map(|(at, weight)| weight * (at - from).normalize().dot(n).max(0.0))
            .sum()
    }

    /// The WGSL's polynomial for angle / sin(angle) (`visible_edge_integral` in
    /// shaders/lights/area.wgsl, its coefficients read from the file) is within 3e-7 of
    /// acos(x) / sqrt(1 - x^2) over 0 <= x <= 1, as its comment says.
    #[test]
    fn the_edge_fit_holds_its_stated_error() {
        let source = include_str!("../../shaders/lights/area.wgsl");
        let coefficients: Vec<f64> = (0..7)
            .map(|k| {
                let name = format!("const EDGE_FIT_{k}: f32 = ");
                let start = source.find(&name).expect("the coefficient") + name.len();
                let end = start + source[start..].find(';').expect("its end");
                source[start..end].parse().expect("a number")
            })
            .collect();
        let mut worst: f64 = 0.0;
        for i in 0..=100_000 {
            let t = i as f64 / 100_000.0;
            let x = 1.0 - t;
            let exact = if t == 0.0 {
                1.0
            } else {
                x.acos() / (1.0 - x * x).sqrt()
            };
            let fit = coefficients.iter().rev().fold(0.0, |sum, c| sum * t + c);
            let approximation = 1.0 + t * (1.0 / 3.0 + t * fit);
            worst = worst.max((approximation / exact - 1.0).abs());
        }
        assert!(worst < 3e-7, "largest relative error {worst:e}");
    }

    #[test]
    fn the_closed_forms_match_the_quadrature() {
        let n = DVec3::Y;
        let white = Vec3::ONE;
        // Above, tilted, cut by the horizon, straddling it, seen edge-on.
        for centre in [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.7, 0.5, -0.3),
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(0.5, 0.0, 0.2),
            Vec3::new(2.0, 0.05, 1.0),
        ] {
            let sphere = Light::sphere(centre, 10.0, white, 1.0, 0.3);
            let exact = sphere_closed_form(centre.as_dvec3(), 0.3, n);
            let numeric = quadrature(&sphere, DVec3::ZERO, n);
            assert!(
                (exact - numeric).abs() <= 1e-4 * numeric.max(1e-3),
                "sphere at {centre}: closed form {exact}, quadrature {numeric}"
            );
            for (first, second) in [
                (Vec3::X * 0.4, Vec3::Z * 0.25),
                (Vec3::new(0.3, 0.2, 0.0), Vec3::new(0.0, 0.1, 0.4)),
            ] {
                // Both facings of the pair: one of them faces the point.
                for (a, b) in [(first, second), (second, first)] {
                    let rect = Light::rect(centre, 10.0, white, 1.0, (a, b));
                    let corners: Vec<DVec3> = rect.corners().iter().map(|c| c.as_dvec3()).collect();
                    let exact = polygon_closed_form(&corners, n);
                    let numeric = quadrature(&rect, DVec3::ZERO, n);
                    assert!(
                        (exact - numeric).abs() <= 1e-4 * numeric.max(1e-3),
                        "rect at {centre} ({a}, {b}): closed form {exact}, quadrature {numeric}"
                    );
                }
            }
        }
    }
}
