//! `rheosph bench --solvers`: the PPE solve against N, Jacobi against AMG, beside the
//! memory-bandwidth bound of one sparse matrix–vector product on this machine.
//!
//! Each size assembles the PPE (25) of the developed, jittered Poiseuille state of
//! `rheosph bench` (closed periodic channel: the constant null space) with the right-hand
//! side −∇·u/δt of that state, and solves it from zero to the default relative tolerance
//! (10⁻⁸). The bound: a CSR product streams every stored value and column index once, the
//! row pointers, x (at least once) and y; at the bandwidth of a STREAM-like triad measured in
//! the same run, that traffic takes `spmv_bound_ms` (from DRAM: below ~64k unknowns the
//! matrix stays in cache and the product beats it). AMG's set-up and solve are timed apart
//! (the solve reusing the hierarchy). A solve's cost is reported as time per unknown and as
//! SpMV-bound equivalents (solve time over the bound).

use crate::app::bench::{case_at, developed, time_ms};
use crate::app::table::{self, fmt};
use crate::engine::boundary::Ghosts;
use crate::engine::math::Vec2;
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::{NeighbourList, NeighbourSearch};
use crate::engine::operators::KernelSums;
use crate::engine::pressure::PressureSystem;
use crate::engine::step::Simulation;
use anyhow::{Context, Result};
use rayon::prelude::*;
use rheosph_solver::amg::Amg;
use rheosph_solver::{NullSpace, Preconditioner, Solver, SolverOptions, Strategy};
use serde::{Deserialize, Serialize};
use sprs::CsMat;
use std::path::Path;
use std::time::Instant;

/// One size of the solver table and of `solvers.csv` (times in milliseconds).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SolverRow {
    pub unknowns: usize,
    #[serde(serialize_with = "fmt::fixed2")]
    pub nonzeros_per_row: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub spmv_ms: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub spmv_bound_ms: f64,
    pub jacobi_iterations: usize,
    #[serde(serialize_with = "fmt::fixed3")]
    pub jacobi_ms: f64,
    #[serde(serialize_with = "fmt::fixed3")]
    pub amg_setup_ms: f64,
    /// One V-cycle (the preconditioner's application).
    #[serde(serialize_with = "fmt::fixed3")]
    pub vcycle_ms: f64,
    pub amg_iterations: usize,
    #[serde(serialize_with = "fmt::fixed3")]
    pub amg_solve_ms: f64,
    pub amg_levels: usize,
    #[serde(serialize_with = "fmt::fixed3")]
    pub amg_complexity: f64,
    /// Solve time per unknown, µs (AMG: set-up included).
    #[serde(serialize_with = "fmt::fixed4")]
    pub jacobi_us_per_unknown: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub amg_us_per_unknown: f64,
    /// The machine's triad bandwidth the bounds are from, GB/s (the same on every row).
    #[serde(serialize_with = "fmt::fixed3")]
    pub triad_bandwidth_gb_s: f64,
}

/// Triad bandwidth a[i] = b[i] + s c[i] over arrays far beyond the caches, bytes/s.
pub fn triad_bandwidth() -> f64 {
    const N: usize = 1 << 24; // 3 × 128 MiB
    let b = vec![1.0_f64; N];
    let c = vec![2.0_f64; N];
    let mut a = vec![0.0_f64; N];
    let (ms, _) = time_ms(10, || {
        a.par_chunks_mut(1 << 14)
            .zip(b.par_chunks(1 << 14).zip(c.par_chunks(1 << 14)))
            .for_each(|(a, (b, c))| {
                for ((x, y), z) in a.iter_mut().zip(b).zip(c) {
                    *x = y + 3.0 * z;
                }
            });
    });
    std::hint::black_box(&a);
    // Read b and c, write a (plus the write-allocate read of a, not counted: a lower bound).
    3.0 * 8.0 * N as f64 / (ms * 1e-3)
}

/// Bytes one CSR product moves at least: values and column indices once, the row pointers,
/// x once and y once.
fn spmv_bytes(a: &CsMat<f64>) -> f64 {
    let (n, nnz) = (a.rows() as f64, a.nnz() as f64);
    nnz * (8.0 + std::mem::size_of::<usize>() as f64) + (n + 1.0) * 8.0 + 2.0 * n * 8.0
}

/// The PPE matrix and right-hand side of the developed state with ~`target` particles.
fn ppe_system(target: usize) -> Result<(CsMat<f64>, Vec<f64>)> {
    let resolution = (target as f64).sqrt().round().max(8.0) as usize;
    let case = case_at(resolution)?;
    let setup = case.setup().map_err(anyhow::Error::msg)?;
    let walls = setup.walls.clone();
    let mut sim = Simulation::new(setup);
    developed(&mut sim, &case)?;
    sim.reorder();
    let n = sim.particles();
    let kernel = sim.kernel;
    let mut ghosts = Ghosts::new(walls);
    let mut points = sim.state.position.clone();
    ghosts.build(kernel.support(), &mut points);
    let mut list = NeighbourList::default();
    NeighbourSearch::new().build(&sim.domain, &points, n, kernel.support(), &mut list);
    let mut sums = KernelSums::default();
    sums.update(&list, &kernel, sim.particle_volume());
    let mut u_ext: Vec<Vec2> = Vec::new();
    ghosts.extend_velocity(&sim.state.velocity, &mut u_ext);
    let mut divergence = vec![0.0; n];
    sums.divergence(&list, &u_ext, &mut divergence);
    let mut ppe = PressureSystem::new();
    ppe.assemble_matrix(
        Hood {
            list: &list,
            sums: &sums,
            ghosts: &ghosts,
        },
        case.fluid.density,
        &[],
    );
    ppe.assemble_rhs(&divergence, 1e-3, &[], &[]);
    Ok(ppe.system())
}

/// Solves from zero with `preconditioner`; returns (iterations, ms). With `twice`, a second
/// solve from zero follows with the matrix declared unchanged (AMG reuses its hierarchy) and
/// is the one timed: the solve without set-up.
fn cold_solve(
    a: &CsMat<f64>,
    b: &[f64],
    preconditioner: Preconditioner,
    twice: bool,
) -> Result<(usize, f64)> {
    let mut options = SolverOptions {
        max_iterations: 5000,
        null_space: NullSpace::Constant,
        strategy: Strategy::IterativeWithFallback,
        preconditioner,
        ..SolverOptions::default()
    };
    let mut solver = Solver::new();
    let mut result = (0, 0.0);
    for _ in 0..if twice { 2 } else { 1 } {
        let mut x = vec![0.0; b.len()];
        let start = Instant::now();
        let report = solver
            .solve(a, b, &mut x, &options)
            .map_err(|e| anyhow::anyhow!("{preconditioner:?} solve: {e}"))?;
        if report.fell_back {
            anyhow::bail!("{preconditioner:?}-BiCGStab did not converge in 5000 iterations");
        }
        result = (report.iterations, start.elapsed().as_secs_f64() * 1e3);
        options.matrix_unchanged = true;
    }
    Ok(result)
}

/// One size.
pub fn solver_row(target: usize, bandwidth: f64) -> Result<SolverRow> {
    let (a, b) = ppe_system(target)?;
    let n = a.rows();
    let mut y = vec![0.0; n];
    let x = vec![1.0; n];
    let repeats = (20_000_000 / a.nnz().max(1)).clamp(3, 200);
    let (spmv_ms, _) = time_ms(repeats, || rheosph_solver::vector::spmv(&a, &x, &mut y));
    let (jacobi_iterations, jacobi_ms) = cold_solve(&a, &b, Preconditioner::Jacobi, false)?;
    let (amg_setup_ms, mut amg) = time_ms(1, || Amg::setup(&a, true));
    let (vcycle_ms, _) = time_ms(repeats.min(20), || amg.apply(&b, &mut y));
    let (amg_iterations, amg_solve_ms) = cold_solve(&a, &b, Preconditioner::Amg, true)?;
    let amg_total_ms = amg_setup_ms + amg_solve_ms;
    let per_unknown = |ms: f64| ms * 1e3 / n as f64;
    Ok(SolverRow {
        unknowns: n,
        nonzeros_per_row: a.nnz() as f64 / n as f64,
        spmv_ms,
        spmv_bound_ms: spmv_bytes(&a) / bandwidth * 1e3,
        jacobi_iterations,
        jacobi_ms,
        amg_setup_ms,
        vcycle_ms,
        amg_iterations,
        amg_solve_ms,
        amg_levels: amg.sizes().len(),
        amg_complexity: amg.complexity(),
        jacobi_us_per_unknown: per_unknown(jacobi_ms),
        amg_us_per_unknown: per_unknown(amg_total_ms),
        triad_bandwidth_gb_s: bandwidth * 1e-9,
    })
}

/// Runs every size, prints the table and writes `solvers.csv` and `solvers.txt` in `out`.
pub fn run(sizes: &[usize], out: &Path, quiet: bool) -> Result<Vec<SolverRow>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let bandwidth = triad_bandwidth();
    let mut table = format!(
        "PPE solves from zero to 1e-8, {} threads; triad bandwidth {:.2} GB/s\n{:>8} {:>6} {:>8} {:>8} {:>16} {:>9} {:>16} {:>7} {:>6} {:>7} {:>9} {:>9} {:>7} {:>7}\n",
        rayon::current_num_threads(),
        bandwidth * 1e-9,
        "N", "nnz/N", "SpMV ms", "bound", "Jacobi ms (it)", "AMG setup", "AMG solve (it)",
        "levels", "cx", "Vcyc ms", "Jac us/N", "AMG us/N", "Jac/bd", "AMG/bd"
    );
    if !quiet {
        eprint!("{table}");
    }
    let mut rows = Vec::new();
    for &size in sizes {
        let r = solver_row(size, bandwidth)?;
        let line = format!(
            "{:>8} {:>6.1} {:>8.3} {:>8.3} {:>9.1} ({:>4}) {:>9.1} {:>9.1} ({:>4}) {:>7} {:>6.2} {:>7.2} {:>9.3} {:>9.3} {:>7.0} {:>7.0}\n",
            r.unknowns, r.nonzeros_per_row, r.spmv_ms, r.spmv_bound_ms, r.jacobi_ms,
            r.jacobi_iterations, r.amg_setup_ms, r.amg_solve_ms, r.amg_iterations, r.amg_levels,
            r.amg_complexity, r.vcycle_ms, r.jacobi_us_per_unknown, r.amg_us_per_unknown,
            r.jacobi_ms / r.spmv_bound_ms,
            (r.amg_setup_ms + r.amg_solve_ms) / r.spmv_bound_ms,
        );
        if !quiet {
            eprint!("{line}");
        }
        table.push_str(&line);
        rows.push(r);
    }
    let csv = table::write_rows(&rows);
    crate::app::io::write_atomic(&out.join("solvers.csv"), csv.as_bytes())?;
    crate::app::io::write_atomic(&out.join("solvers.txt"), table.as_bytes())?;
    Ok(rows)
}
