//! Generates `crates/lights/src/specular_albedo.bin`, the fit of PBR's specular albedo
//! (`manylights_lights::specular_albedo` says what it is and how it is read).

use manylights_lights::specular_albedo::{
    BASIS_TERMS, ROUGHNESS_LOW, ROUGHNESS_NODES, basis, single_scatter,
};

fn main() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../crates/lights/src/specular_albedo.bin");
    std::fs::write(&path, generate()).expect("writing the fit");
    println!("wrote {}", path.display());
}

/// Quadrature points per grid value when generating the fit.
const GENERATION_POINTS: u32 = 1 << 17;

/// Grid values of mu the fit is held above, uniform over [0, 1].
const GRID_MU: usize = 193;

/// Grid steps per roughness cell at which the fit is held above the integrals.
const GRID_STEPS: usize = 3;

/// The coefficient file: A and B from [`single_scatter`] on the grid, each fitted by
/// [`fit_term`], written as f32.
fn generate() -> Vec<u8> {
    let grid = fine_grid();
    let [a, b] = [0, 1].map(|term| fit_term(&grid, term));
    a.iter()
        .zip(&b)
        .flat_map(|(a, b)| a.iter().chain(b).copied())
        .flat_map(|c| (c as f32).to_le_bytes())
        .collect()
}

/// (A, B) from [`single_scatter`] on the grid: [`GRID_STEPS`] rows per roughness cell,
/// [`GRID_MU`] columns, `[row][column]`, rows on every core (the quadrature is the
/// generation's whole cost).
fn fine_grid() -> Vec<Vec<[f64; 2]>> {
    let rows = (ROUGHNESS_NODES - 1) * GRID_STEPS + 1;
    let row = |j: usize| -> Vec<[f64; 2]> {
        let r = ROUGHNESS_LOW + (1.0 - ROUGHNESS_LOW) * j as f64 / (rows - 1) as f64;
        (0..GRID_MU)
            .map(|i| single_scatter(i as f64 / (GRID_MU - 1) as f64, r, GENERATION_POINTS))
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

/// The coefficients of `term` (0: A, 1: B) at every row: the linear program that minimises
/// the rows' summed excess over the integrals, each weighted by mu + 0.02 (the diffuse
/// term is weighted by n.l; the constant keeps grazing angles in view), subject to the
/// interpolated fit being at or above every grid value. Solved by adding the grid values
/// the last solution fell below to a small program until none does (the whole grid at
/// once is tens of thousands of constraints, minutes for the solver). The constant
/// coefficients are then raised by 1e-6 so that rounding them to f32 keeps the bound.
fn fit_term(grid: &[Vec<[f64; 2]>], term: usize) -> Vec<[f64; BASIS_TERMS]> {
    let mus: Vec<f64> = (0..GRID_MU)
        .map(|i| i as f64 / (GRID_MU - 1) as f64)
        .collect();
    let bases: Vec<[f64; BASIS_TERMS]> = mus.iter().map(|&mu| basis(mu)).collect();
    let cost: [f64; BASIS_TERMS] = std::array::from_fn(|k| {
        mus.iter()
            .zip(&bases)
            .map(|(mu, at)| (mu + 0.02) * at[k])
            .sum()
    });
    // Each grid value's rows and their weights: the last grid row is the last node.
    let rows_of = |fine_row: usize| {
        let (row, step) = (fine_row / GRID_STEPS, fine_row % GRID_STEPS);
        if row == ROUGHNESS_NODES - 1 {
            (row - 1, 1.0)
        } else {
            (row, step as f64 / GRID_STEPS as f64)
        }
    };
    let fitted = |rows: &[[f64; BASIS_TERMS]], fine_row: usize, column: usize| {
        let (row, t) = rows_of(fine_row);
        (0..BASIS_TERMS)
            .map(|k| ((1.0 - t) * rows[row][k] + t * rows[row + 1][k]) * bases[column][k])
            .sum::<f64>()
    };
    // Start from every eighth column of every grid row.
    let mut active: Vec<(usize, usize)> = (0..grid.len())
        .flat_map(|fine_row| {
            (0..GRID_MU)
                .step_by(8)
                .map(move |column| (fine_row, column))
        })
        .collect();
    loop {
        let rows = solve_fit(&active, &cost, |fine_row, column| {
            let (row, t) = rows_of(fine_row);
            (row, t, bases[column], grid[fine_row][column][term])
        });
        let before = active.len();
        for (fine_row, values) in grid.iter().enumerate() {
            for (column, value) in values.iter().enumerate() {
                if fitted(&rows, fine_row, column) < value[term] - 1e-12
                    && !active.contains(&(fine_row, column))
                {
                    active.push((fine_row, column));
                }
            }
        }
        if active.len() == before {
            return rows
                .into_iter()
                .map(|mut coefficients| {
                    coefficients[0] += 1e-6;
                    coefficients
                })
                .collect();
        }
    }
}

/// The fit's linear program over the `active` grid values: `at` gives a value's row, its
/// position towards the next, the basis at its mu and the integral it must not fall below.
fn solve_fit(
    active: &[(usize, usize)],
    cost: &[f64; BASIS_TERMS],
    at: impl Fn(usize, usize) -> (usize, f64, [f64; BASIS_TERMS], f64),
) -> Vec<[f64; BASIS_TERMS]> {
    use microlp::{ComparisonOp, OptimizationDirection, Problem};
    let mut problem = Problem::new(OptimizationDirection::Minimize);
    let free = (f64::NEG_INFINITY, f64::INFINITY);
    let variables: Vec<[microlp::Variable; BASIS_TERMS]> = (0..ROUGHNESS_NODES)
        .map(|_| cost.map(|c| problem.add_var(c, free)))
        .collect();
    for &(fine_row, column) in active {
        let (row, t, basis_at, value) = at(fine_row, column);
        let mut terms = Vec::with_capacity(2 * BASIS_TERMS);
        for k in 0..BASIS_TERMS {
            terms.push((variables[row][k], (1.0 - t) * basis_at[k]));
            if t > 0.0 {
                terms.push((variables[row + 1][k], t * basis_at[k]));
            }
        }
        problem.add_constraint(&terms, ComparisonOp::Ge, value);
    }
    let solution = problem
        .solve()
        .expect("the fit's linear program")
        .into_solution()
        .expect("an optimal fit");
    variables
        .iter()
        .map(|row| row.map(|v| solution[v]))
        .collect()
}
