//! The directional albedo of PBR's specular lobe, tabulated: what lets the diffuse term
//! conserve energy (shaders/lights/specular_albedo.wgsl reads the same table).
//!
//! glTF's Appendix B weights the diffuse term by 1 - F(v.h), which towards grazing views
//! of smooth dielectrics reflects more than arrives (1.84 times at 89 degrees): the
//! specular lobe there takes far more than F(v.h) of the light. manylights instead weights
//! the diffuse by what the specular lobe leaves, in and out ("albedo scaling": Kulla and
//! Conty 2017, Revisiting Physically Based Shading at Imageworks; Enterprise PBR layers its
//! coat the same way):
//!
//!   f_diffuse = albedo / pi x (1 - E(n.v)) (1 - E(n.l)) / (1 - E_avg)
//!
//! with E(mu) the specular lobe's directional albedo at cos angle mu and E_avg its cosine
//! weighted average, 2 int E(mu) mu dmu. It is reciprocal (symmetric in the two angles),
//! and a white surface seen at mu reflects E(mu) specularly plus (1 - E(mu)) diffusely: at
//! most 1, exactly 1 where the table is exact.
//!
//! With Schlick's Fresnel E is linear in F0: E = F0 A + B, A and B functions of mu and the
//! perceptual roughness r ([`single_scatter`]). They are tabulated at [`MU_NODES`] x
//! [`ROUGHNESS_NODES`] nodes, uniform in mu over [0, 1] and in r over [0.045, 1], and
//! interpolated bilinearly. The node values are raised until the interpolation bounds the
//! integrals from above on a grid six times finer, then rounded up to f16 (what the GPU
//! stores): the diffuse then never takes energy the specular lobe took, at the price of a
//! little energy lost where the bound is loose (at most 0.3% for a dielectric up to 80
//! degrees, 8% at grazing; `docs/architecture/materials.md`). E_avg is the exact average
//! of the interpolated rows, rounded down, so the diffuse lobe's own albedo stays at most
//! (1 - E(n.v)) albedo.
//!
//! The table is generated from the f64 twin's integrals by
//! `cargo test -p manylights-lights --release -- --ignored write_specular_albedo_table`
//! and committed (`specular_albedo.bin`, 4 KiB); a test holds it to the integrals.

use half::f16;

/// Nodes along mu = n.l or n.v, uniform over [0, 1].
pub const MU_NODES: usize = 33;
/// Nodes along the perceptual roughness, uniform over [`ROUGHNESS_LOW`, 1].
pub const ROUGHNESS_NODES: usize = 33;
/// The roughness of the table's first row: GGX's floor (`reference::MIN_PERCEPTUAL_ROUGHNESS`).
pub const ROUGHNESS_LOW: f64 = 0.045;

/// The committed nodes: for each roughness row, for each mu node, A then B as
/// little-endian f16.
const NODES: &[u8] = include_bytes!("specular_albedo.bin");

/// The table as the GPU reads it (`specular_albedo.wgsl`): one texel a cell, four u32 of
/// two f16 each (A, B at the cell's corners), and a last column of the rows' averages.
pub const TEXTURE_SIZE: (u32, u32) = (MU_NODES as u32, ROUGHNESS_NODES as u32 - 1);

/// A and B at every node (f16 values, as the GPU has them), with each row's averages.
#[derive(Debug, Clone)]
pub struct SpecularAlbedoTable {
    /// `nodes[row][column]` = (A, B).
    nodes: Vec<[[f64; 2]; MU_NODES]>,
    /// Per row: 2 int A mu dmu and 2 int B mu dmu of the interpolated row, rounded down
    /// to f16.
    averages: Vec<[f64; 2]>,
}

impl SpecularAlbedoTable {
    /// The committed table.
    pub fn committed() -> &'static SpecularAlbedoTable {
        static TABLE: std::sync::OnceLock<SpecularAlbedoTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| Self::from_bytes(NODES))
    }

    fn from_bytes(bytes: &[u8]) -> SpecularAlbedoTable {
        assert_eq!(
            bytes.len(),
            MU_NODES * ROUGHNESS_NODES * 4,
            "specular_albedo.bin"
        );
        let values: Vec<f64> = bytes
            .chunks_exact(2)
            .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f64())
            .collect();
        let nodes: Vec<[[f64; 2]; MU_NODES]> = values
            .chunks_exact(2 * MU_NODES)
            .map(|row| std::array::from_fn(|i| [row[2 * i], row[2 * i + 1]]))
            .collect();
        let averages = nodes
            .iter()
            .map(|row| {
                [0, 1].map(|k| {
                    let exact = cosine_weighted_average(&row.map(|n| n[k]));
                    round_f16(exact, false).to_f64()
                })
            })
            .collect();
        SpecularAlbedoTable { nodes, averages }
    }

    /// (A, B) at `mu` and perceptual roughness `roughness`, interpolated as the GPU does.
    pub fn terms(&self, mu: f64, roughness: f64) -> [f64; 2] {
        let (column, s) = cell(mu, MU_NODES);
        let (row, t) = cell(roughness_coordinate(roughness), ROUGHNESS_NODES);
        let along = |row: usize| {
            let (a, b) = (self.nodes[row][column], self.nodes[row][column + 1]);
            [0, 1].map(|k| a[k] + (b[k] - a[k]) * s)
        };
        let (low, high) = (along(row), along(row + 1));
        [0, 1].map(|k| low[k] + (high[k] - low[k]) * t)
    }

    /// E = F0 A + B per channel: the specular lobe's directional albedo.
    pub fn albedo(&self, f0: glam::DVec3, mu: f64, roughness: f64) -> glam::DVec3 {
        let [a, b] = self.terms(mu, roughness);
        f0 * a + b
    }

    /// E_avg = F0 A_avg + B_avg per channel, at the row position of `roughness`.
    pub fn average(&self, f0: glam::DVec3, roughness: f64) -> glam::DVec3 {
        let (row, t) = cell(roughness_coordinate(roughness), ROUGHNESS_NODES);
        let (low, high) = (self.averages[row], self.averages[row + 1]);
        let [a, b] = [0, 1].map(|k| low[k] + (high[k] - low[k]) * t);
        f0 * a + b
    }

    /// The texels of [`TEXTURE_SIZE`], row by row, as the GPU stores them.
    pub fn texels(&self) -> Vec<[u32; 4]> {
        let pack = |[a, b]: [f64; 2]| {
            u32::from(round_f16(a, true).to_bits())
                | (u32::from(round_f16(b, true).to_bits()) << 16)
        };
        let mut texels = Vec::new();
        for row in 0..ROUGHNESS_NODES - 1 {
            let (low, high) = (&self.nodes[row], &self.nodes[row + 1]);
            for column in 0..MU_NODES - 1 {
                texels.push([
                    pack(low[column]),
                    pack(low[column + 1]),
                    pack(high[column]),
                    pack(high[column + 1]),
                ]);
            }
            texels.push([pack(self.averages[row]), pack(self.averages[row + 1]), 0, 0]);
        }
        texels
    }
}

/// `value` in [0, 1] as a cell of `nodes` uniform nodes and the position within it.
fn cell(value: f64, nodes: usize) -> (usize, f64) {
    let cells = (nodes - 1) as f64;
    let x = value.clamp(0.0, 1.0) * cells;
    let index = (x as usize).min(nodes - 2);
    (index, x - index as f64)
}

/// The roughness's position along the table's rows, in [0, 1].
fn roughness_coordinate(roughness: f64) -> f64 {
    (roughness - ROUGHNESS_LOW) / (1.0 - ROUGHNESS_LOW)
}

/// 2 int_0^1 y(mu) mu dmu of the piecewise-linear `y` through uniform nodes, exactly.
fn cosine_weighted_average(y: &[f64]) -> f64 {
    let h = 1.0 / (y.len() - 1) as f64;
    y.windows(2)
        .enumerate()
        .map(|(i, pair)| {
            let (mu, slope) = (i as f64 * h, pair[1] - pair[0]);
            // 2 int_0^1 (y0 + slope t)(mu + h t) h dt
            2.0 * h * (pair[0] * mu + (pair[0] * h + slope * mu) / 2.0 + slope * h / 3.0)
        })
        .sum()
}

/// `value` as f16, rounded up (`up`) or down to a representable value.
fn round_f16(value: f64, up: bool) -> f16 {
    let nearest = f16::from_f64(value);
    let step = |v: f16| {
        let bits = v.to_bits();
        // Non-negative values only: the next value up is the next bit pattern.
        if up {
            f16::from_bits(bits + 1)
        } else if bits == 0 {
            v
        } else {
            f16::from_bits(bits - 1)
        }
    };
    match nearest.to_f64().partial_cmp(&value) {
        Some(std::cmp::Ordering::Less) if up => step(nearest),
        Some(std::cmp::Ordering::Greater) if !up => step(nearest),
        _ => nearest,
    }
}

/// The specular lobe's directional albedo split by F0: (A, B) with E = F0 A + B, the
/// integral over the hemisphere of D V F n.l (GGX, height-correlated Smith, Schlick's
/// Fresnel: F = F0 (1 - c) + c, c = (1 - v.h)^5) seen at cos angle `mu` with perceptual
/// roughness `roughness` (held at [`ROUGHNESS_LOW`], mu at the twin's smallest n.v). A
/// quadrature of `points` half vectors distributed as GGX (the 2D Hammersley set), so a
/// sharp lobe is not missed between them.
pub fn single_scatter(mu: f64, roughness: f64, points: u32) -> [f64; 2] {
    let pi = std::f64::consts::PI;
    let mu = mu.clamp(crate::reference::MIN_N_DOT_V, 1.0);
    let alpha = roughness.max(ROUGHNESS_LOW).powi(2);
    let alpha2 = alpha * alpha;
    let view = glam::DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let (mut a, mut b) = (0.0, 0.0);
    for i in 0..points {
        let u = (f64::from(i) + 0.5) / f64::from(points);
        let phi = 2.0 * pi * f64::from(i.reverse_bits()) / 4_294_967_296.0;
        // h with pdf D n.h; l the mirror of v about it, pdf D n.h / (4 v.h). The term
        // D V F n.l over that pdf is V F n.l 4 v.h / n.h.
        let cos_h = ((1.0 - u) / (1.0 + (alpha2 - 1.0) * u)).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let h = glam::DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
        let v_dot_h = view.dot(h);
        let n_dot_l = 2.0 * v_dot_h * cos_h - mu;
        if n_dot_l <= 0.0 || v_dot_h <= 0.0 {
            continue;
        }
        let visibility = 0.5
            / (n_dot_l * (mu * mu * (1.0 - alpha2) + alpha2).sqrt()
                + mu * (n_dot_l * n_dot_l * (1.0 - alpha2) + alpha2).sqrt());
        let weight = visibility * n_dot_l * 4.0 * v_dot_h / cos_h;
        let c = (1.0 - v_dot_h).powi(5);
        a += weight * (1.0 - c);
        b += weight * c;
    }
    [a, b].map(|x| x / f64::from(points))
}

/// Quadrature points per node when generating the table.
pub const GENERATION_POINTS: u32 = 1 << 17;

/// Grid points per cell and axis at which generation checks the bound.
const CHECK_STEPS: usize = 6;

/// Generates the node file: A and B from [`single_scatter`] on a grid [`CHECK_STEPS`]
/// times finer than the nodes, node values raised cell by cell until the bilinear
/// interpolation is at or above every grid value, then rounded up to f16.
pub fn generate() -> Vec<u8> {
    let fine = fine_grid();
    let mut nodes: Vec<Vec<[f64; 2]>> = (0..ROUGHNESS_NODES)
        .map(|j| {
            (0..MU_NODES)
                .map(|i| fine[j * CHECK_STEPS][i * CHECK_STEPS])
                .collect()
        })
        .collect();
    for term in 0..2 {
        // Raising a cell's corners raises its neighbours' interpolation too, never lowers
        // it: repeat until no cell falls short.
        while raise_cells_below(&mut nodes, &fine, term) {}
    }
    nodes
        .iter()
        .flatten()
        .flat_map(|node| node.map(|v| round_f16(v, true).to_le_bytes()))
        .flatten()
        .collect()
}

/// (A, B) from [`single_scatter`] on the grid [`CHECK_STEPS`] times finer than the nodes,
/// `[row][column]`, rows on every core (the quadrature is the generation's whole cost).
fn fine_grid() -> Vec<Vec<[f64; 2]>> {
    let (columns, rows) = (
        (MU_NODES - 1) * CHECK_STEPS + 1,
        (ROUGHNESS_NODES - 1) * CHECK_STEPS + 1,
    );
    let row = |j: usize| -> Vec<[f64; 2]> {
        let r = ROUGHNESS_LOW + (1.0 - ROUGHNESS_LOW) * j as f64 / (rows - 1) as f64;
        (0..columns)
            .map(|i| single_scatter(i as f64 / (columns - 1) as f64, r, GENERATION_POINTS))
            .collect()
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|first| {
                scope.spawn(move || {
                    (first..rows)
                        .step_by(threads)
                        .map(|j| (j, row(j)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let mut rows_by_index: Vec<(usize, Vec<[f64; 2]>)> = workers
            .into_iter()
            .flat_map(|w| w.join().expect("a generation thread"))
            .collect();
        rows_by_index.sort_by_key(|(j, _)| *j);
        rows_by_index
            .into_iter()
            .map(|(_, values)| values)
            .collect()
    })
}

/// Raises the four corners of every cell whose bilinear interpolation of `term` falls
/// below a `fine` grid value by the largest shortfall; whether any was raised.
fn raise_cells_below(nodes: &mut [Vec<[f64; 2]>], fine: &[Vec<[f64; 2]>], term: usize) -> bool {
    let mut raised = false;
    for j in 0..ROUGHNESS_NODES - 1 {
        for i in 0..MU_NODES - 1 {
            let corner = |dj: usize, di: usize| nodes[j + dj][i + di][term];
            let mut deficit: f64 = 0.0;
            for dj in 0..=CHECK_STEPS {
                for di in 0..=CHECK_STEPS {
                    let s = di as f64 / CHECK_STEPS as f64;
                    let t = dj as f64 / CHECK_STEPS as f64;
                    let low = corner(0, 0) + (corner(0, 1) - corner(0, 0)) * s;
                    let high = corner(1, 0) + (corner(1, 1) - corner(1, 0)) * s;
                    let value = fine[j * CHECK_STEPS + dj][i * CHECK_STEPS + di][term];
                    deficit = deficit.max(value - (low + (high - low) * t));
                }
            }
            if deficit > 0.0 {
                raised = true;
                for (dj, di) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    nodes[j + dj][i + di][term] += deficit;
                }
            }
        }
    }
    raised
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regenerates `specular_albedo.bin` (minutes in release).
    #[test]
    #[ignore]
    fn write_specular_albedo_table() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/specular_albedo.bin");
        std::fs::write(&path, generate()).expect("writing the table");
    }

    /// The committed table bounds the integrals from above, between its nodes too (at
    /// points off the generation's grid), within the quadrature's own error; and it is
    /// tight where it matters (normal to 60 degrees, within 1%).
    #[test]
    fn the_table_bounds_the_specular_albedo_from_above() {
        // The error of 2^18 points (measured against 2^20: under 1e-5) plus the
        // generation's own (2^17: under 1e-4).
        const QUADRATURE: f64 = 2e-4;
        let table = SpecularAlbedoTable::committed();
        let mut worst_below: f64 = 0.0;
        for step in 0..200 {
            // A low-discrepancy walk over the (mu, r) square off the node grid.
            let mu = (f64::from(step) * 0.618_033_988_7 + 0.013).fract();
            let r = ROUGHNESS_LOW
                + (1.0 - ROUGHNESS_LOW) * (f64::from(step) * 0.754_877_666 + 0.029).fract();
            let exact = single_scatter(mu, r, 1 << 18);
            let tabulated = table.terms(mu, r);
            for k in 0..2 {
                worst_below = worst_below.max(exact[k] - tabulated[k]);
                assert!(
                    tabulated[k] >= exact[k] - QUADRATURE,
                    "mu {mu}, roughness {r}: term {k} tabulated {} below its integral {}",
                    tabulated[k],
                    exact[k]
                );
                if mu >= 0.5 {
                    assert!(
                        tabulated[k] <= exact[k] + 0.01,
                        "mu {mu}, roughness {r}: term {k} tabulated {} far above {}",
                        tabulated[k],
                        exact[k]
                    );
                }
            }
        }
        println!("largest shortfall below the integrals: {worst_below:.1e}");
    }

    /// The averages are those of the interpolated rows: a white specular lobe's
    /// complement integrates to 1 - E_avg, so the diffuse lobe's albedo is exactly
    /// (1 - E(v)) (up to the rounding down of E_avg).
    #[test]
    fn the_averages_integrate_the_interpolated_rows() {
        let table = SpecularAlbedoTable::committed();
        for r in [ROUGHNESS_LOW, 0.1, 0.3, 0.61, 1.0] {
            let points = 20_000;
            let integral: f64 = (0..points)
                .map(|i| {
                    let mu = (f64::from(i) + 0.5) / f64::from(points);
                    let [a, b] = table.terms(mu, r);
                    2.0 * (a + b) * mu / f64::from(points)
                })
                .sum();
            let average = table.average(glam::DVec3::ONE, r).x;
            assert!(
                average <= integral + 1e-6 && average >= integral - 2e-3,
                "roughness {r}: average {average}, integral {integral}"
            );
        }
    }

    #[test]
    fn rounding_to_f16_goes_the_asked_way() {
        for value in [0.0, 1e-5, 0.1, 0.3333, 0.9999, 1.0] {
            assert!(round_f16(value, true).to_f64() >= value);
            assert!(round_f16(value, false).to_f64() <= value);
            assert!((round_f16(value, true).to_f64() - value).abs() <= value * 1e-3 + 1e-7);
        }
    }
}
