//! The directional albedo of PBR's specular lobe, fitted: what lets the diffuse term
//! conserve energy (shaders/lights/specular_albedo.wgsl evaluates the same fit).
//!
//! glTF's Appendix B weights the diffuse term by 1 - F(v.h), which towards grazing views
//! of smooth dielectrics reflects more than arrives (1.84 times at 89 degrees): the
//! specular lobe there takes far more than F(v.h) of the light. manylights instead weights
//! the diffuse by what the specular lobe leaves, in and out ("albedo scaling": Kulla and
//! Conty 2017, Revisiting Physically Based Shading at Imageworks; Enterprise PBR layers its
//! coat the same way):
//!
//!   f_diffuse = albedo / pi x (1 - E(n.l)) (1 - E(n.v)) / (1 - E_avg)
//!
//! with E(mu) the specular lobe's directional albedo at cos angle mu and E_avg its cosine
//! weighted average, 2 int E(mu) mu dmu. It is reciprocal (symmetric in the two angles),
//! and a white surface seen at mu reflects E(mu) specularly plus (1 - E(mu)) diffusely: at
//! most 1, exactly 1 where E is exact.
//!
//! With Schlick's Fresnel E is linear in F0: E = F0 A + B, A and B functions of mu and the
//! perceptual roughness r ([`single_scatter`]). Each is a sum of [`BASIS_TERMS`] functions
//! of mu, 1, mu, p^2, p^4, p^8 and p^16 with p = 1 - mu (the powers follow the Fresnel rim
//! that smooth lobes have at grazing angles), with coefficients at [`ROUGHNESS_NODES`]
//! rows uniform in r over [0.045, 1], interpolated linearly between rows. So the light
//! loop evaluates E(n.l) with a few multiply-adds from coefficients the pixel reads once,
//! where a table of mu cost a load per light (issue 60: 1.4 ms of the H200's 11.6 at
//! 100,000 lights). E_avg follows from the coefficients exactly (each basis function's
//! cosine-weighted average is a fraction).
//!
//! The coefficients are the tightest fit that bounds the integrals from above, everywhere
//! on a grid of mu and r finer than the rows, interpolation between rows included: one
//! linear program over every row, minimising the fit's cosine-weighted excess while no
//! grid value is above it. Bounding from above means the diffuse never takes energy the
//! lobe took; the price is energy lost where the bound is loose (the test below states
//! it). The fit is generated from the f64 twin's integrals by
//! `cargo run --release --manifest-path tools/specular-albedo-fit/Cargo.toml` and
//! committed (`specular_albedo.bin`, f32 coefficients); a test holds it to the integrals.

/// The smallest n.v the visibility term divides by (`MIN_N_DOT_V` in brdf.wgsl), where the
/// fit's domain starts.
pub const MIN_N_DOT_V: f64 = 1e-4;

/// Rows of coefficients along the perceptual roughness, uniform over [`ROUGHNESS_LOW`, 1].
pub const ROUGHNESS_NODES: usize = 33;
/// The roughness of the first row: GGX's floor (`reference::MIN_PERCEPTUAL_ROUGHNESS`).
pub const ROUGHNESS_LOW: f64 = 0.045;
/// Functions of mu each of A and B sums: 1, mu, p^2, p^4, p^8, p^16 (p = 1 - mu).
pub const BASIS_TERMS: usize = 6;

/// The committed coefficients: for each row, A's then B's, as little-endian f32.
const COEFFICIENTS: &[u8] = include_bytes!("specular_albedo.bin");

/// The basis functions at `mu`, in the coefficients' order.
pub fn basis(mu: f64) -> [f64; BASIS_TERMS] {
    let p = 1.0 - mu;
    let p2 = p * p;
    let p4 = p2 * p2;
    let p8 = p4 * p4;
    [1.0, mu, p2, p4, p8, p8 * p8]
}

/// Each basis function's cosine-weighted average over the hemisphere, 2 int_0^1 f(mu) mu
/// dmu: 1, 2/3, and 2 / ((n + 1)(n + 2)) for p^n.
pub const BASIS_AVERAGES: [f64; BASIS_TERMS] = [
    1.0,
    2.0 / 3.0,
    2.0 / 12.0,
    2.0 / 30.0,
    2.0 / 90.0,
    2.0 / 306.0,
];

/// A's and B's coefficients at each roughness row (f32 values, as the GPU has them).
#[derive(Debug, Clone)]
pub struct SpecularAlbedoFit {
    /// `rows[row]` = [A's coefficients, B's coefficients].
    rows: Vec<[[f64; BASIS_TERMS]; 2]>,
}

impl SpecularAlbedoFit {
    /// The committed fit.
    pub fn committed() -> &'static SpecularAlbedoFit {
        static FIT: std::sync::OnceLock<SpecularAlbedoFit> = std::sync::OnceLock::new();
        FIT.get_or_init(|| Self::from_bytes(COEFFICIENTS))
    }

    fn from_bytes(bytes: &[u8]) -> SpecularAlbedoFit {
        assert_eq!(
            bytes.len(),
            ROUGHNESS_NODES * 2 * BASIS_TERMS * 4,
            "specular_albedo.bin"
        );
        let values: Vec<f64> = bytes
            .chunks_exact(4)
            .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            .collect();
        let rows = values
            .chunks_exact(2 * BASIS_TERMS)
            .map(|row| [0, 1].map(|k| std::array::from_fn(|i| row[k * BASIS_TERMS + i])))
            .collect();
        SpecularAlbedoFit { rows }
    }

    /// A's and B's coefficients at perceptual roughness `roughness`, interpolated between
    /// rows as the GPU does.
    fn coefficients(&self, roughness: f64) -> [[f64; BASIS_TERMS]; 2] {
        let (row, t) = cell(roughness_coordinate(roughness), ROUGHNESS_NODES);
        let (low, high) = (&self.rows[row], &self.rows[row + 1]);
        [0, 1].map(|k| std::array::from_fn(|i| low[k][i] + (high[k][i] - low[k][i]) * t))
    }

    /// (A, B) at `mu` and perceptual roughness `roughness`, evaluated as the GPU does.
    pub fn terms(&self, mu: f64, roughness: f64) -> [f64; 2] {
        let at = basis(mu.clamp(0.0, 1.0));
        self.coefficients(roughness)
            .map(|c| c.iter().zip(at).map(|(c, f)| c * f).sum::<f64>())
    }

    /// E = F0 A + B per channel: the specular lobe's directional albedo.
    pub fn albedo(&self, f0: glam::DVec3, mu: f64, roughness: f64) -> glam::DVec3 {
        let [a, b] = self.terms(mu, roughness);
        f0 * a + b
    }

    /// E_avg = F0 A_avg + B_avg per channel at `roughness`: the fit's own average, exactly.
    pub fn average(&self, f0: glam::DVec3, roughness: f64) -> glam::DVec3 {
        let [a, b]: [f64; 2] = self
            .coefficients(roughness)
            .map(|c| c.iter().zip(BASIS_AVERAGES).map(|(c, m)| c * m).sum());
        f0 * a + b
    }

    /// The fit as the GPU reads it (`specular_albedo.wgsl`): per roughness node, three
    /// texels of four u32 each, the bits of f32 coefficients (A's six, then B's six).
    pub fn texels(&self) -> Vec<[u32; 4]> {
        self.rows
            .iter()
            .flat_map(|[a, b]| {
                let bits: Vec<u32> = a.iter().chain(b).map(|&c| (c as f32).to_bits()).collect();
                bits.chunks_exact(4)
                    .map(|texel| [texel[0], texel[1], texel[2], texel[3]])
                    .collect::<Vec<_>>()
            })
            .collect()
    }
}

/// `value` in [0, 1] as a cell of `nodes` uniform nodes and the position within it (both
/// fits' lookups: this one and `ltc`).
pub(crate) fn cell(value: f64, nodes: usize) -> (usize, f64) {
    let cells = (nodes - 1) as f64;
    let x = value.clamp(0.0, 1.0) * cells;
    let index = (x as usize).min(nodes - 2);
    (index, x - index as f64)
}

/// The roughness's position along the rows, in [0, 1].
fn roughness_coordinate(roughness: f64) -> f64 {
    (roughness - ROUGHNESS_LOW) / (1.0 - ROUGHNESS_LOW)
}

/// The specular lobe's directional albedo split by F0: (A, B) with E = F0 A + B, the
/// integral over the hemisphere of D V F n.l (GGX, height-correlated Smith, Schlick's
/// Fresnel: F = F0 (1 - c) + c, c = (1 - v.h)^5) seen at cos angle `mu` with perceptual
/// roughness `roughness` (held at [`ROUGHNESS_LOW`], mu at the twin's smallest n.v). A
/// quadrature of `points` half vectors distributed as GGX (the 2D Hammersley set), so a
/// sharp lobe is not missed between them.
pub fn single_scatter(mu: f64, roughness: f64, points: u32) -> [f64; 2] {
    let pi = std::f64::consts::PI;
    let mu = mu.clamp(MIN_N_DOT_V, 1.0);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed fit bounds the integrals from above, between its rows and grid points
    /// too (at points off the generation's grid), within the quadrature's own error; and it
    /// is tight where it matters (from normal incidence to 60 degrees, within 0.005).
    #[test]
    fn the_fit_bounds_the_specular_albedo_from_above() {
        // The error of 2^18 points (measured against 2^20: under 1e-5) plus the
        // generation's own (2^17: under 1e-4).
        const QUADRATURE: f64 = 2e-4;
        let fit = SpecularAlbedoFit::committed();
        let mut worst_below: f64 = 0.0;
        let mut worst_above: f64 = 0.0;
        for step in 0..200 {
            // A low-discrepancy walk over the (mu, r) square off the grid.
            let mu = (f64::from(step) * 0.618_033_988_7 + 0.013).fract();
            let r = ROUGHNESS_LOW
                + (1.0 - ROUGHNESS_LOW) * (f64::from(step) * 0.754_877_666 + 0.029).fract();
            let exact = single_scatter(mu, r, 1 << 18);
            let fitted = fit.terms(mu, r);
            for k in 0..2 {
                worst_below = worst_below.max(exact[k] - fitted[k]);
                assert!(
                    fitted[k] >= exact[k] - QUADRATURE,
                    "mu {mu}, roughness {r}: term {k} fitted {} below its integral {}",
                    fitted[k],
                    exact[k]
                );
                if mu >= 0.5 {
                    worst_above = worst_above.max(fitted[k] - exact[k]);
                    assert!(
                        fitted[k] <= exact[k] + 0.005,
                        "mu {mu}, roughness {r}: term {k} fitted {} far above {}",
                        fitted[k],
                        exact[k]
                    );
                }
            }
        }
        println!(
            "largest shortfall below the integrals: {worst_below:.1e}; largest excess from \
             normal incidence to 60 degrees: {worst_above:.1e}"
        );
    }

    /// The averages are those of the fitted rows: a white specular lobe's complement
    /// integrates to 1 - E_avg, so the diffuse lobe's albedo is exactly (1 - E(v)).
    #[test]
    fn the_averages_integrate_the_fitted_rows() {
        let fit = SpecularAlbedoFit::committed();
        for r in [ROUGHNESS_LOW, 0.1, 0.3, 0.61, 1.0] {
            let points = 20_000;
            let integral: f64 = (0..points)
                .map(|i| {
                    let mu = (f64::from(i) + 0.5) / f64::from(points);
                    let [a, b] = fit.terms(mu, r);
                    2.0 * (a + b) * mu / f64::from(points)
                })
                .sum();
            let average = fit.average(glam::DVec3::ONE, r).x;
            assert!(
                (average - integral).abs() <= 1e-6,
                "roughness {r}: average {average}, integral {integral}"
            );
        }
    }
}
