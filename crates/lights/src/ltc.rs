//! Linearly transformed cosines for GGX (Heitz, Dupuy, Hill and Neubelt 2016, "Real-Time
//! Polygonal-Light Shading with Linearly Transformed Cosines"): how an area light's
//! specular term is integrated (`specular_area_integral` in shaders/lights/shading.wgsl).
//!
//! PBR's specular lobe times n.l, for a view at cos angle mu and perceptual roughness r,
//! is close to a clamped cosine distribution D_o(w_o) = max(0, z_o) / pi whose directions
//! are mapped by a 3x3 matrix M, w = M w_o / |M w_o|. Its integral over a polygon is then
//! the clamped cosine's integral over the polygon mapped back by M^-1: Lambert's formula
//! for the corners M^-1 p, clipped at the horizon, over pi (the same integral the diffuse
//! term takes). The lobe's magnitude and Fresnel are the specular albedo E(n.v) = F0 A + B
//! ([`crate::specular_albedo`]), so
//!
//!   specular = E(n.v) x (1 / pi) integral over M^-1 P of n.l dl.
//!
//! M^-1 is fitted per (r, mu) in the frame (t, n x t, n), t the view's part along the
//! surface: the lobe is symmetric about the plane of n and v, so M^-1 has four entries
//! besides its middle one, which is scaled to 1 (a scale of M^-1 leaves the normalised
//! directions, and so the integral, unchanged). They are committed per roughness row of the
//! albedo fit ([`ROUGHNESS_NODES`], uniform in r) and per [`VIEW_NODES`] columns uniform in
//! sqrt(1 - mu), and interpolated bilinearly as the GPU does. The fit minimises the
//! difference between the lobe (Fresnel 1, normalised) and the distribution, sampled from
//! both (Heitz's error with the difference's first power, not its cube), by Nelder-Mead:
//! `cargo run --release --manifest-path tools/specular-albedo-fit/Cargo.toml --bin
//! ltc-fit` (13 s on 2 cores; `ltc.bin`, f32 entries). A test below states how far it is
//! from the lobe's integral over lights.

use glam::{DMat3, DVec3};

use crate::specular_albedo::cell;

pub use crate::specular_albedo::{ROUGHNESS_LOW, ROUGHNESS_NODES};

/// Columns of matrices along the view, uniform in sqrt(1 - mu) from mu = 1 to mu = 0.
pub const VIEW_NODES: usize = 32;

/// The committed entries (m00, m02, m20, m22) of each node's normalised M^-1, row by row
/// (roughness), column by column (view), as little-endian f32.
const ENTRIES: &[u8] = include_bytes!("ltc.bin");

/// The table of fitted inverse matrices.
#[derive(Debug, Clone)]
pub struct LtcTable {
    /// `entries[row * VIEW_NODES + column]` = (m00, m02, m20, m22) of M^-1 (m11 = 1).
    entries: Vec<[f64; 4]>,
}

impl LtcTable {
    /// The committed table.
    pub fn committed() -> &'static LtcTable {
        static TABLE: std::sync::OnceLock<LtcTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| {
            assert_eq!(ENTRIES.len(), ROUGHNESS_NODES * VIEW_NODES * 16, "ltc.bin");
            let values: Vec<f64> = ENTRIES
                .chunks_exact(4)
                .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
                .collect();
            LtcTable {
                entries: values
                    .chunks_exact(4)
                    .map(|e| [e[0], e[1], e[2], e[3]])
                    .collect(),
            }
        })
    }

    /// A table of `entries` (what the fit writes), row by row.
    pub fn from_entries(entries: Vec<[f64; 4]>) -> LtcTable {
        assert_eq!(entries.len(), ROUGHNESS_NODES * VIEW_NODES);
        LtcTable { entries }
    }

    /// The table as `ltc.bin` stores it.
    pub fn to_bytes(&self) -> Vec<u8> {
        self.entries
            .iter()
            .flatten()
            .flat_map(|&e| (e as f32).to_le_bytes())
            .collect()
    }

    /// M^-1 at cos view angle `mu` and perceptual roughness `roughness`, interpolated
    /// between the four nodes around it as the GPU does.
    pub fn inverse(&self, mu: f64, roughness: f64) -> DMat3 {
        let (row, s) = cell(
            (roughness - ROUGHNESS_LOW) / (1.0 - ROUGHNESS_LOW),
            ROUGHNESS_NODES,
        );
        let (column, t) = cell(view_coordinate(mu), VIEW_NODES);
        let at = |row: usize, column: usize| self.entries[row * VIEW_NODES + column];
        let lerp = |a: [f64; 4], b: [f64; 4], t: f64| -> [f64; 4] {
            std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t)
        };
        let low = lerp(at(row, column), at(row, column + 1), t);
        let high = lerp(at(row + 1, column), at(row + 1, column + 1), t);
        inverse_of_entries(lerp(low, high, s))
    }

    /// The entries as texels of four f32 bits, `[row][column]`.
    pub fn texels(&self) -> Vec<[u32; 4]> {
        self.entries
            .iter()
            .map(|e| e.map(|x| (x as f32).to_bits()))
            .collect()
    }
}

/// The view's position along the columns: sqrt(1 - mu), in [0, 1].
pub fn view_coordinate(mu: f64) -> f64 {
    (1.0 - mu.clamp(0.0, 1.0)).sqrt()
}

/// The cos view angle of column `column`.
pub fn column_mu(column: usize) -> f64 {
    let x = column as f64 / (VIEW_NODES - 1) as f64;
    1.0 - x * x
}

/// The perceptual roughness of row `row`.
pub fn row_roughness(row: usize) -> f64 {
    ROUGHNESS_LOW + (1.0 - ROUGHNESS_LOW) * row as f64 / (ROUGHNESS_NODES - 1) as f64
}

/// M^-1 of the entries (m00, m02, m20, m22), with m11 = 1 and the rest 0.
pub fn inverse_of_entries([m00, m02, m20, m22]: [f64; 4]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(m00, 0.0, m20),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(m02, 0.0, m22),
    )
}

/// GGX's specular lobe with Fresnel 1 times n.l, D V n.l (height-correlated Smith), in
/// the frame whose z is the normal: `view` and `l` unit vectors. What the matrices fit.
pub fn ggx_lobe(view: DVec3, l: DVec3, alpha: f64) -> f64 {
    if l.z <= 0.0 {
        return 0.0;
    }
    let h = (view + l).normalize_or_zero();
    if h.z <= 0.0 {
        return 0.0;
    }
    let alpha2 = alpha * alpha;
    let mu = view.z.max(crate::reference::MIN_N_DOT_V);
    let d = h.z * h.z * (alpha2 - 1.0) + 1.0;
    let distribution = alpha2 / (std::f64::consts::PI * d * d);
    let visibility = 0.5
        / (l.z * (mu * mu * (1.0 - alpha2) + alpha2).sqrt()
            + mu * (l.z * l.z * (1.0 - alpha2) + alpha2).sqrt());
    distribution * visibility * l.z
}

/// The frame the matrices are fitted in, for unit normal `n` and view `view_dir`: rows
/// t (the view's part along the surface), n x t and n. Any t where the view is the normal
/// (the lobe is round there).
pub fn frame(n: DVec3, view_dir: DVec3) -> DMat3 {
    let along = view_dir - n * n.dot(view_dir);
    let t = if along.length_squared() > 1e-12 {
        along.normalize()
    } else {
        n.any_orthonormal_vector()
    };
    DMat3::from_cols(t, n.cross(t), n).transpose()
}

/// The fitted lobe's integral over the polygon `corners` (relative to the lit point, in the
/// frame of [`frame`]), normalised: the share of E(n.v) the polygon reflects.
pub fn polygon_integral(inverse: DMat3, corners: &[DVec3]) -> f64 {
    let mapped: Vec<DVec3> = corners.iter().map(|&p| inverse * p).collect();
    crate::reference::area::polygon_closed_form(&mapped, DVec3::Z) / std::f64::consts::PI
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specular_albedo::single_scatter;

    /// The lobe's integral over square lights (quadrature of [`ggx_lobe`], 512 x 512 points)
    /// against E(n.v) (Fresnel 1) times the committed fit's: lights at the mirror
    /// direction (0.4 m and 1.5 m at 2 m) and off it, from sharp to rough lobes and from
    /// normal to grazing views. Measured: a mean error of 1.35% of the lobe's albedo, the
    /// worst 17% (a 1.5 m light at 81 degrees that the horizon cuts: the distribution
    /// reaches below the horizon where the lobe does not). Held at 3% and 20%, the test
    /// prints the figures; `LTC_PLACEMENTS=1` prints every light's.
    #[test]
    fn the_fit_integrates_the_lobe_over_lights() {
        let table = LtcTable::committed();
        let (mut worst_share, mut worst_relative): (f64, f64) = (0.0, 0.0);
        let (mut sum_share, mut count) = (0.0, 0.0);
        for roughness in [0.2f64, 0.35, 0.5, 0.7, 1.0] {
            for mu in [0.95f64, 0.7, 0.4, 0.15] {
                let alpha = roughness * roughness;
                let view = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let mirror = DVec3::new(-view.x, 0.0, view.z);
                let albedo: f64 = single_scatter(mu, roughness, 1 << 16).iter().sum();
                let inverse = table.inverse(mu, roughness);
                for (aim, size) in [
                    (mirror, 0.4),
                    (mirror, 1.5),
                    (DVec3::new(0.3, 0.5, 0.8), 0.8),
                ] {
                    let centre = aim.normalize() * 2.0;
                    let across = centre.any_orthonormal_pair();
                    let (first, second) = (across.0 * size / 2.0, across.1 * size / 2.0);
                    let corners = [
                        centre - first - second,
                        centre + first - second,
                        centre + first + second,
                        centre - first + second,
                    ];
                    let corners = if (first.cross(second)).dot(-centre) > 0.0 {
                        corners
                    } else {
                        [corners[0], corners[3], corners[2], corners[1]]
                    };
                    let exact = quadrature(&corners, view, alpha, 512);
                    let fitted = albedo * polygon_integral(inverse, &corners);
                    // The error as a share of all the lobe reflects (the light's radiance
                    // times it is the error in radiance), and relative to the light's own
                    // term where the light holds a tenth of the lobe at least.
                    let share = (fitted - exact).abs() / albedo;
                    worst_share = worst_share.max(share);
                    sum_share += share;
                    count += 1.0;
                    if exact > 0.1 * albedo {
                        worst_relative = worst_relative.max((fitted - exact).abs() / exact);
                    }
                    if std::env::var_os("LTC_PLACEMENTS").is_some() {
                        println!(
                            "r {roughness} mu {mu} aim {aim:.2} size {size}: lobe share {:.4}, \
                             fitted {:.4}",
                            exact / albedo,
                            fitted / albedo
                        );
                    }
                }
            }
        }
        let mean_share = sum_share / count;
        println!(
            "LTC against the lobe's integral over {count} lights: error as a share of the \
             lobe's albedo, mean {mean_share:.4}, worst {worst_share:.4}; relative to the \
             light's term where it holds a tenth of the lobe, worst {worst_relative:.3}"
        );
        assert!(mean_share < 0.03, "mean error {mean_share}");
        assert!(worst_share < 0.2, "worst error {worst_share}");
    }

    /// The quadrature of the lobe over the quad `corners` (a parallelogram), `n x n`
    /// midpoints, each weighted by its solid angle.
    fn quadrature(corners: &[DVec3; 4], view: DVec3, alpha: f64, n: usize) -> f64 {
        let (origin, u, v) = (corners[0], corners[1] - corners[0], corners[3] - corners[0]);
        let normal = u.cross(v);
        let cell_area = normal.length() / (n * n) as f64;
        let normal = normal.normalize();
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let s = (i as f64 + 0.5) / n as f64;
                let t = (j as f64 + 0.5) / n as f64;
                let p = origin + u * s + v * t;
                let d2 = p.length_squared();
                let l = p / d2.sqrt();
                let solid_angle = cell_area * normal.dot(l).abs() / d2;
                sum += ggx_lobe(view, l, alpha) * solid_angle;
            }
        }
        sum
    }

    /// Every fitted matrix keeps a polygon's winding (positive determinant) and is finite.
    #[test]
    fn every_matrix_keeps_the_winding() {
        let table = LtcTable::committed();
        for entry in &table.entries {
            let determinant = inverse_of_entries(*entry).determinant();
            assert!(determinant.is_finite() && determinant > 0.0, "{entry:?}");
        }
    }
}
