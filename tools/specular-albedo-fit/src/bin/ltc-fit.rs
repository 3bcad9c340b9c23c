//! Generates `crates/lights/src/ltc.bin`, the linearly transformed cosines that integrate
//! GGX's lobe over area lights (`manylights_lights::ltc` says what they are and how they
//! are read).
//!
//! Each node (roughness row, view column) fits M = [X Y Z] A, with Z the lobe's mean
//! direction, Y the normal to the plane of incidence, X = Y x Z, and
//! A = [[m11, 0, m13], [0, m22, 0], [0, 0, 1]]: three parameters (one, m11 = m22, for the
//! view along the normal, where the lobe is round). The error is the difference between
//! the lobe and the distribution (times the lobe's norm), at 32 x 32 points drawn from
//! each and weighted by the sum of their densities: Heitz et al.'s, whose cube of the
//! difference is replaced by its first power, which fits the integrals over lights better
//! (the test in `manylights_lights::ltc`: a mean error of 1.35% of the lobe's albedo and
//! a worst of 17%, where the cube gave 1.7% and 21%). Nelder-Mead minimises it,
//! each view column starting from the one before (the lobe turns smoothly), each row's
//! first from the rougher row's.

use glam::{DMat3, DVec3};
use manylights_lights::ltc::{
    LtcTable, ROUGHNESS_NODES, VIEW_NODES, column_mu, ggx_lobe, row_roughness,
};

/// Points drawn from each distribution per error evaluation, per axis.
const POINTS: usize = 32;

fn main() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../crates/lights/src/ltc.bin");
    // Each row's first column (the round lobe) from the rougher row's, in order.
    let mut round = vec![0.0; ROUGHNESS_NODES];
    let mut start = 1.0;
    for row in (0..ROUGHNESS_NODES).rev() {
        let alpha = row_roughness(row).powi(2);
        let fit = nelder_mead(&[start], |p| {
            error(&Lobe::new(1.0, alpha), &matrix([p[0], p[0], 0.0], DVec3::Z))
        });
        round[row] = fit[0].abs().max(1e-7);
        start = round[row];
    }
    // The rows on every core, each along its columns.
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let rows: Vec<(usize, Vec<[f64; 4]>)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|first| {
                let round = &round;
                scope.spawn(move || {
                    (first..ROUGHNESS_NODES)
                        .step_by(threads)
                        .map(|row| (row, fit_row(row, round[row])))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("a fitting thread"))
            .collect()
    });
    let mut rows = rows;
    rows.sort_by_key(|(row, _)| *row);
    let table = LtcTable::from_entries(rows.into_iter().flat_map(|(_, r)| r).collect());
    std::fs::write(&path, table.to_bytes()).expect("writing the table");
    println!("wrote {}", path.display());
}

/// The entries of one roughness row, column by column.
fn fit_row(row: usize, round: f64) -> Vec<[f64; 4]> {
    let alpha = row_roughness(row).powi(2);
    let mut parameters = [round, round, 0.0];
    let mut entries = Vec::with_capacity(VIEW_NODES);
    for column in 0..VIEW_NODES {
        let lobe = Lobe::new(column_mu(column), alpha);
        let axis = lobe.mean_direction();
        let m = if column == 0 {
            matrix(parameters, axis)
        } else {
            let fit = nelder_mead(&parameters, |p| {
                error(&lobe, &matrix([p[0], p[1], p[2]], axis))
            });
            parameters = [fit[0], fit[1], fit[2]];
            matrix(parameters, axis)
        };
        let inverse = m.inverse();
        let inverse = inverse / inverse.y_axis.y;
        entries.push([
            inverse.x_axis.x,
            inverse.z_axis.x,
            inverse.x_axis.z,
            inverse.z_axis.z,
        ]);
        eprintln!(
            "row {row:2} (alpha {alpha:.4}) column {column:2} (mu {:.3}): error {:.3e}",
            column_mu(column),
            error(&lobe, &m)
        );
    }
    entries
}

/// M for parameters (m11, m22, m13) about the mean direction `axis` (in the xz plane).
fn matrix([m11, m22, m13]: [f64; 3], axis: DVec3) -> DMat3 {
    let z = axis;
    let y = DVec3::Y;
    let x = y.cross(z);
    let a = DMat3::from_cols(
        DVec3::new(m11.abs().max(1e-7), 0.0, 0.0),
        DVec3::new(0.0, m22.abs().max(1e-7), 0.0),
        DVec3::new(m13, 0.0, 1.0),
    );
    DMat3::from_cols(x, y, z) * a
}

/// GGX's lobe (Fresnel 1) for one view.
struct Lobe {
    view: DVec3,
    alpha: f64,
    /// Its integral over the hemisphere, E(n.v) with F0 = 1.
    norm: f64,
}

impl Lobe {
    fn new(mu: f64, alpha: f64) -> Lobe {
        let mu = mu.max(1e-4);
        let view = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let mut lobe = Lobe {
            view,
            alpha,
            norm: 1.0,
        };
        lobe.norm = (0..POINTS * POINTS * 16)
            .map(|i| lobe.sample(hammersley(i, POINTS * POINTS * 16)))
            .map(|l| lobe.value(l) / lobe.density(l).max(1e-300))
            .filter(|w| w.is_finite())
            .sum::<f64>()
            / (POINTS * POINTS * 16) as f64;
        lobe
    }

    fn value(&self, l: DVec3) -> f64 {
        ggx_lobe(self.view, l, self.alpha)
    }

    /// A direction drawn as GGX's visible... half vectors distributed as D n.h, mirrored.
    fn sample(&self, (u, v): (f64, f64)) -> DVec3 {
        let alpha2 = self.alpha * self.alpha;
        let phi = 2.0 * std::f64::consts::PI * v;
        let cos_h = ((1.0 - u) / (1.0 + (alpha2 - 1.0) * u)).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let h = DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
        2.0 * self.view.dot(h) * h - self.view
    }

    /// The density of [`Lobe::sample`] at `l`: D n.h / (4 v.h).
    fn density(&self, l: DVec3) -> f64 {
        let h = (self.view + l).normalize_or_zero();
        let v_dot_h = self.view.dot(h);
        if h.z <= 0.0 || v_dot_h <= 0.0 {
            return 0.0;
        }
        let alpha2 = self.alpha * self.alpha;
        let d = h.z * h.z * (alpha2 - 1.0) + 1.0;
        alpha2 / (std::f64::consts::PI * d * d) * h.z / (4.0 * v_dot_h)
    }

    /// The lobe's mean direction (normalised), in the xz plane.
    fn mean_direction(&self) -> DVec3 {
        let n = POINTS * POINTS * 16;
        let sum: DVec3 = (0..n)
            .map(|i| self.sample(hammersley(i, n)))
            .filter(|l| l.z > 0.0)
            .map(|l| {
                let w = self.value(l) / self.density(l).max(1e-300);
                if w.is_finite() { l * w } else { DVec3::ZERO }
            })
            .sum();
        let direction = DVec3::new(sum.x, 0.0, sum.z);
        if direction.length_squared() > 0.0 {
            direction.normalize()
        } else {
            DVec3::Z
        }
    }
}

/// The normalised distribution of M at `l`: D_o(M^-1 l) times the Jacobian.
fn ltc_density(inverse: &DMat3, determinant: f64, l: DVec3) -> f64 {
    let original = *inverse * l;
    let length = original.length();
    let z = original.z / length;
    if z <= 0.0 {
        return 0.0;
    }
    z / std::f64::consts::PI * determinant / (length * length * length)
}

/// The error between the lobe and M's distribution times the lobe's norm (Heitz et al.'s,
/// with the difference's first power).
fn error(lobe: &Lobe, m: &DMat3) -> f64 {
    let inverse = m.inverse();
    let determinant = inverse.determinant().abs();
    let mut sum = 0.0;
    for i in 0..POINTS * POINTS {
        let (u, v) = (
            ((i % POINTS) as f64 + 0.5) / POINTS as f64,
            ((i / POINTS) as f64 + 0.5) / POINTS as f64,
        );
        // One direction drawn from the distribution (a cosine-distributed one mapped by
        // M), one from the lobe.
        let r = u.sqrt();
        let phi = 2.0 * std::f64::consts::PI * v;
        let original = DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt());
        for l in [(*m * original).normalize(), lobe.sample((u, v))] {
            let density_ltc = ltc_density(&inverse, determinant, l);
            let density_lobe = lobe.density(l);
            let difference = (lobe.value(l) - lobe.norm * density_ltc).abs();
            let weight = density_ltc + density_lobe;
            if weight > 0.0 {
                sum += difference / weight;
            }
        }
    }
    sum / (POINTS * POINTS) as f64
}

/// Point `i` of the `n`-point Hammersley set.
fn hammersley(i: usize, n: usize) -> (f64, f64) {
    (
        (i as f64 + 0.5) / n as f64,
        f64::from((i as u32).reverse_bits()) / 4_294_967_296.0,
    )
}

/// Nelder-Mead from `start` (steps of 5% of each parameter, or 0.05), 400 iterations or
/// until the simplex's values agree to 1e-9 relative.
fn nelder_mead(start: &[f64], f: impl Fn(&[f64]) -> f64) -> Vec<f64> {
    let n = start.len();
    let mut simplex: Vec<Vec<f64>> = vec![start.to_vec()];
    for k in 0..n {
        let mut p = start.to_vec();
        p[k] += if p[k].abs() > 1e-3 { 0.05 * p[k] } else { 0.05 };
        simplex.push(p);
    }
    let mut values: Vec<f64> = simplex.iter().map(|p| f(p)).collect();
    for _ in 0..400 {
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        simplex = order.iter().map(|&i| simplex[i].clone()).collect();
        values = order.iter().map(|&i| values[i]).collect();
        if (values[n] - values[0]).abs() <= 1e-9 * values[0].abs().max(1e-30) {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|k| simplex[..n].iter().map(|p| p[k]).sum::<f64>() / n as f64)
            .collect();
        let towards = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|k| centroid[k] + t * (simplex[n][k] - centroid[k]))
                .collect()
        };
        let reflected = towards(-1.0);
        let reflected_value = f(&reflected);
        if reflected_value < values[0] {
            let expanded = towards(-2.0);
            let expanded_value = f(&expanded);
            if expanded_value < reflected_value {
                (simplex[n], values[n]) = (expanded, expanded_value);
            } else {
                (simplex[n], values[n]) = (reflected, reflected_value);
            }
        } else if reflected_value < values[n - 1] {
            (simplex[n], values[n]) = (reflected, reflected_value);
        } else {
            let contracted = towards(0.5);
            let contracted_value = f(&contracted);
            if contracted_value < values[n] {
                (simplex[n], values[n]) = (contracted, contracted_value);
            } else {
                for i in 1..=n {
                    simplex[i] = (0..n)
                        .map(|k| simplex[0][k] + 0.5 * (simplex[i][k] - simplex[0][k]))
                        .collect();
                    values[i] = f(&simplex[i]);
                }
            }
        }
    }
    let best = (0..=n)
        .min_by(|&a, &b| values[a].total_cmp(&values[b]))
        .expect("a simplex");
    simplex[best].clone()
}
