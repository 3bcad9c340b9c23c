//! Area lights in the f64 twin: the light integrated numerically, point by point, with
//! the BRDF and both cosines exact at every point (the GPU's shading splits the integral
//! at the BRDF and approximates its specular half: `shaders/lights/shading.wgsl`).

use glam::{DVec3, Vec3};

use super::{Falloff, SurfacePoint, brdf};
use crate::light::{LIGHT_RECT, LIGHT_SPHERE, LIGHT_TRIANGLE, Light};

/// Points of `light` (a sphere's visible cap, a rectangle, a triangle) seen from
/// `from`, each with the solid angle it stands for times the light's radiance's share
/// (for flat lights cos(at the light) dA / r^2; 0 where the point is behind the light),
/// on a `grid` x `grid` midpoint rule over the light's parameters: the midpoint rule's
/// error falls as 1 / grid^2 for smooth integrands.
pub fn light_samples(light: &Light, from: DVec3, grid: u32) -> Vec<(DVec3, f64)> {
    let to_f64 = |v: Vec3| v.as_dvec3();
    let centre = to_f64(Vec3::from_array(light.position));
    let first = to_f64(Vec3::from_array(light.direction));
    let second = to_f64(light.second_edge());
    let cells = (0..grid).flat_map(|i| (0..grid).map(move |j| (i, j)));
    let midpoint = move |k: u32| (k as f64 + 0.5) / grid as f64;
    let cell_share = 1.0 / (grid * grid) as f64;
    match light.kind {
        LIGHT_SPHERE => {
            let radius = light.extent as f64;
            let to_centre = centre - from;
            let distance = to_centre.length();
            // The cone of directions the sphere covers (all of them from inside).
            let cos_cap = if distance > radius {
                (1.0 - (radius / distance).powi(2)).sqrt()
            } else {
                -1.0
            };
            let axis = if distance > 0.0 {
                to_centre / distance
            } else {
                DVec3::Z
            };
            let (u, v) = axis.any_orthonormal_pair();
            let solid_angle = std::f64::consts::TAU * (1.0 - cos_cap);
            cells
                .map(|(i, j)| {
                    let cos_theta = 1.0 - midpoint(i) * (1.0 - cos_cap);
                    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                    let phi = std::f64::consts::TAU * midpoint(j);
                    let direction = axis * cos_theta + (u * phi.cos() + v * phi.sin()) * sin_theta;
                    (from + direction, solid_angle * cell_share)
                })
                .collect()
        }
        LIGHT_RECT | LIGHT_TRIANGLE => {
            let facing = first.cross(second);
            let normal = facing.normalize();
            let area = if light.kind == LIGHT_RECT {
                4.0 * facing.length()
            } else {
                1.5 * facing.length()
            };
            let corners = [centre + first, centre + second, centre - first - second];
            cells
                .map(|(i, j)| {
                    let (s, t) = (midpoint(i), midpoint(j));
                    let point = if light.kind == LIGHT_RECT {
                        centre + (2.0 * s - 1.0) * first + (2.0 * t - 1.0) * second
                    } else {
                        // The square onto the triangle, area for area.
                        let root = s.sqrt();
                        corners[0] * (1.0 - root)
                            + corners[1] * (root * (1.0 - t))
                            + corners[2] * (root * t)
                    };
                    let to_point = point - from;
                    let distance_squared = to_point.length_squared();
                    let cos_light = normal.dot(-to_point) / distance_squared.sqrt();
                    let weight = if cos_light > 0.0 {
                        area * cell_share * cos_light / distance_squared
                    } else {
                        0.0
                    };
                    (point, weight)
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

/// The grid [`shade_area_light`] integrates with: finer the larger the light looks, from 8
/// x 8 to 96 x 96 (at 1 m from a light 1 m across).
pub fn integration_grid(light: &Light, from: DVec3) -> u32 {
    let centre = Vec3::from_array(light.position).as_dvec3();
    let angular_size = light.bounding_radius() as f64 / (centre - from).length().max(1e-9);
    (96.0 * angular_size).ceil().clamp(8.0, 96.0) as u32
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
/// the sum over its points of f(l) n.l times each point's share
/// ([`light_samples`] on [`integration_grid`]), only the points `visible` says the lit
/// point sees.
pub fn shade_area_light(
    point: &SurfacePoint,
    view_dir: DVec3,
    light: &Light,
    mode: Falloff,
    visible: impl Fn(DVec3) -> bool,
) -> DVec3 {
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
    let grid = integration_grid(light, point.position);
    let sum: DVec3 = light_samples(light, point.position, grid)
        .into_iter()
        .filter(|(_, weight)| *weight > 0.0)
        .filter_map(|(at, weight)| {
            let l = (at - point.position).normalize();
            let n_dot_l = point.normal.dot(l);
            (n_dot_l > 0.0 && visible(at)).then(|| brdf(point, view_dir, l) * (n_dot_l * weight))
        })
        .sum();
    radiance * window(mode, d2, radius) * sum
}
