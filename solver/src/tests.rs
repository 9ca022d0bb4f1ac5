//! Solver tests on matrices with known solutions.

use super::*;
use sprs::TriMat;

/// Index of grid point (i, j) on an m×m grid.
fn idx(m: usize, i: usize, j: usize) -> usize {
    i * m + j
}

/// 5-point Laplacian (−Δ, scaled by h²) with homogeneous Dirichlet boundaries: SPD.
fn dirichlet_laplacian(m: usize) -> CsMat<f64> {
    let mut t = TriMat::new((m * m, m * m));
    for i in 0..m {
        for j in 0..m {
            let k = idx(m, i, j);
            t.add_triplet(k, k, 4.0);
            if i > 0 {
                t.add_triplet(k, idx(m, i - 1, j), -1.0);
            }
            if i + 1 < m {
                t.add_triplet(k, idx(m, i + 1, j), -1.0);
            }
            if j > 0 {
                t.add_triplet(k, idx(m, i, j - 1), -1.0);
            }
            if j + 1 < m {
                t.add_triplet(k, idx(m, i, j + 1), -1.0);
            }
        }
    }
    t.to_csr()
}

/// Upwind convection–diffusion −Δu + c(x,y)·∇u on an m×m grid. Dirichlet (non-singular) or
/// periodic (rows sum to zero: singular with the constant right null vector; the variable
/// velocity makes it non-symmetric with a left null vector different from 1).
fn convection_diffusion(m: usize, periodic: bool, peclet: f64) -> CsMat<f64> {
    let mut t = TriMat::new((m * m, m * m));
    let h = 1.0 / m as f64;
    for i in 0..m {
        for j in 0..m {
            let k = idx(m, i, j);
            let (x, y) = (i as f64 * h, j as f64 * h);
            let cx = peclet * (2.0 * std::f64::consts::PI * y).sin();
            let cy = peclet * 0.5 * (2.0 * std::f64::consts::PI * x).cos();
            // neighbours: (di, dj, coefficient) of diffusion plus upwind convection, all ×h².
            let mut diag = 0.0;
            for (di, dj, c) in [(-1i64, 0i64, cx), (1, 0, -cx), (0, -1, cy), (0, 1, -cy)] {
                // Upwind: flow from the (−) side when c > 0.
                let convective = (c * h).max(0.0);
                let off = -1.0 - convective;
                diag -= off;
                let (ni, nj) = (i as i64 + di, j as i64 + dj);
                let inside = (0..m as i64).contains(&ni) && (0..m as i64).contains(&nj);
                if inside || periodic {
                    let ni = ni.rem_euclid(m as i64) as usize;
                    let nj = nj.rem_euclid(m as i64) as usize;
                    t.add_triplet(k, idx(m, ni, nj), off);
                }
            }
            t.add_triplet(k, k, diag);
        }
    }
    t.to_csr()
}

fn smooth_field(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| ((k as f64) * 0.37).sin() + 0.5 * ((k as f64) * 0.011).cos())
        .collect()
}

fn matvec(a: &CsMat<f64>, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; x.len()];
    vector::spmv(a, x, &mut y);
    y
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn remove_mean(x: &mut [f64]) {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    x.iter_mut().for_each(|v| *v -= mean);
}

#[test]
fn bicgstab_solves_dirichlet_laplacian() {
    let a = dirichlet_laplacian(40);
    let exact = smooth_field(1600);
    let b = matvec(&a, &exact);
    let mut x = vec![0.0; 1600];
    let report = Solver::new()
        .solve(&a, &b, &mut x, &SolverOptions::default())
        .unwrap();
    assert_eq!(report.method, Method::BiCgStab);
    assert!(!report.fell_back);
    assert!(report.relative_residual <= 1e-8, "{report:?}");
    // cond(A) ~ 700 for m = 40, so a 1e-8 residual bounds the error by ~1e-5 of |x|.
    assert!(
        max_diff(&x, &exact) < 1e-5,
        "error {}",
        max_diff(&x, &exact)
    );
}

#[test]
fn bicgstab_solves_nonsymmetric_convection_diffusion() {
    let a = convection_diffusion(30, false, 40.0);
    let exact = smooth_field(900);
    let b = matvec(&a, &exact);
    let mut x = vec![0.0; 900];
    let options = SolverOptions {
        relative_tolerance: 1e-10,
        ..Default::default()
    };
    let report = Solver::new().solve(&a, &b, &mut x, &options).unwrap();
    assert_eq!(report.method, Method::BiCgStab);
    assert!(
        max_diff(&x, &exact) < 1e-7,
        "error {}",
        max_diff(&x, &exact)
    );
}

#[test]
fn direct_lu_solves_nonsymmetric_convection_diffusion() {
    let a = convection_diffusion(30, false, 40.0);
    let exact = smooth_field(900);
    let b = matvec(&a, &exact);
    let mut x = vec![0.0; 900];
    let options = SolverOptions {
        strategy: Strategy::Direct,
        ..Default::default()
    };
    let report = Solver::new().solve(&a, &b, &mut x, &options).unwrap();
    assert_eq!(report.method, Method::SparseLu);
    assert!(!report.fell_back);
    assert!(report.relative_residual < 1e-12);
    assert!(max_diff(&x, &exact) < 1e-10);
}

/// Guards the closed-domain pressure problem: a singular, non-symmetric matrix with A1 = 0 and
/// an incompatible right-hand side b = A x* + μ* 1. Both paths must return the same zero-mean
/// x* (and absorb exactly μ*), not two different members of the null space.
#[test]
fn constant_null_space_is_removed_identically_on_both_paths() {
    let m = 24;
    let a = convection_diffusion(m, true, 25.0);
    let row_sum_max = (0..m * m)
        .map(|i| {
            a.outer_view(i)
                .unwrap()
                .iter()
                .map(|(_, v)| *v)
                .sum::<f64>()
                .abs()
        })
        .fold(0.0, f64::max);
    assert!(row_sum_max < 1e-12, "rows must sum to zero");
    let mut exact = smooth_field(m * m);
    remove_mean(&mut exact);
    let mu = 0.3;
    let b: Vec<f64> = matvec(&a, &exact).iter().map(|v| v + mu).collect();

    let iterative = SolverOptions {
        null_space: NullSpace::Constant,
        relative_tolerance: 1e-11,
        ..Default::default()
    };
    let direct = SolverOptions {
        strategy: Strategy::Direct,
        ..iterative
    };
    let mut x_iter = vec![0.0; m * m];
    let mut x_lu = vec![0.0; m * m];
    let r_iter = Solver::new()
        .solve(&a, &b, &mut x_iter, &iterative)
        .unwrap();
    let r_lu = Solver::new().solve(&a, &b, &mut x_lu, &direct).unwrap();
    assert_eq!(r_iter.method, Method::BiCgStab);
    assert_eq!(r_lu.method, Method::SparseLu);
    assert!(
        max_diff(&x_iter, &exact) < 1e-7,
        "iterative {}",
        max_diff(&x_iter, &exact)
    );
    assert!(
        max_diff(&x_lu, &exact) < 1e-9,
        "lu {}",
        max_diff(&x_lu, &exact)
    );
    assert!(max_diff(&x_iter, &x_lu) < 1e-7);
    assert!(x_iter.iter().sum::<f64>().abs() < 1e-9);
}

/// Guards the warm start of the closed-domain PPE: the previous pressure is stored with zero
/// mean, but the augmented operator's solution has a mean set by the incompatible part of b.
/// Without re-centring the initial residual, a perfect warm start would begin with the whole
/// μ1 as residual and cost as many iterations as a cold start.
#[test]
fn zero_mean_warm_start_of_singular_system_costs_no_iterations() {
    let m = 24;
    let a = convection_diffusion(m, true, 25.0);
    let mut exact = smooth_field(m * m);
    remove_mean(&mut exact);
    let b: Vec<f64> = matvec(&a, &exact).iter().map(|v| v + 0.3).collect();
    let options = SolverOptions {
        null_space: NullSpace::Constant,
        ..Default::default()
    };
    let mut x = exact.clone();
    let report = Solver::new().solve(&a, &b, &mut x, &options).unwrap();
    assert_eq!(report.iterations, 0, "{report:?}");
    assert!(max_diff(&x, &exact) < 1e-12);
}

#[test]
fn warm_start_from_solution_costs_no_iterations_and_near_guess_costs_fewer() {
    let a = dirichlet_laplacian(40);
    let exact = smooth_field(1600);
    let b = matvec(&a, &exact);
    let options = SolverOptions::default();
    let mut solver = Solver::new();

    let mut x = exact.clone();
    let warm = solver.solve(&a, &b, &mut x, &options).unwrap();
    assert_eq!(warm.iterations, 0);

    let mut cold_x = vec![0.0; 1600];
    let cold = solver.solve(&a, &b, &mut cold_x, &options).unwrap();
    let mut near: Vec<f64> = exact
        .iter()
        .enumerate()
        .map(|(k, v)| v + 1e-4 * ((k % 7) as f64))
        .collect();
    let near_report = solver.solve(&a, &b, &mut near, &options).unwrap();
    assert!(
        near_report.iterations < cold.iterations,
        "{near_report:?} vs {cold:?}"
    );
}

#[test]
fn falls_back_to_lu_when_bicgstab_runs_out_of_iterations() {
    let a = convection_diffusion(30, false, 40.0);
    let exact = smooth_field(900);
    let b = matvec(&a, &exact);
    let mut x = vec![0.0; 900];
    let options = SolverOptions {
        max_iterations: 2,
        ..Default::default()
    };
    let report = Solver::new().solve(&a, &b, &mut x, &options).unwrap();
    assert_eq!(report.method, Method::SparseLu);
    assert!(report.fell_back);
    assert_eq!(report.iterations, 2);
    assert!(max_diff(&x, &exact) < 1e-10);
}

#[test]
fn zero_right_hand_side_gives_zero() {
    let a = dirichlet_laplacian(5);
    let mut x = vec![1.0; 25];
    let report = Solver::new()
        .solve(&a, &[0.0; 25], &mut x, &SolverOptions::default())
        .unwrap();
    assert!(x.iter().all(|v| *v == 0.0));
    assert_eq!(report.iterations, 0);
}

#[test]
fn mismatched_sizes_and_non_finite_input_are_errors() {
    let a = dirichlet_laplacian(5);
    let mut x = vec![0.0; 24];
    assert!(matches!(
        Solver::new().solve(&a, &[1.0; 25], &mut x, &SolverOptions::default()),
        Err(SolveError::Dimension { .. })
    ));
    let mut x = vec![0.0; 25];
    let mut b = vec![1.0; 25];
    b[3] = f64::NAN;
    assert!(matches!(
        Solver::new().solve(&a, &b, &mut x, &SolverOptions::default()),
        Err(SolveError::NonFinite)
    ));
}

/// Reductions are blocked and summed in order: one thread and two threads must give
/// bit-identical solutions on a system large enough to run in parallel.
#[test]
fn result_does_not_depend_on_thread_count() {
    let a = convection_diffusion(120, true, 25.0);
    let n = 120 * 120;
    let mut exact = smooth_field(n);
    remove_mean(&mut exact);
    let b = matvec(&a, &exact);
    let options = SolverOptions {
        null_space: NullSpace::Constant,
        ..Default::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut x = vec![0.0; n];
            let report = Solver::new().solve(&a, &b, &mut x, &options).unwrap();
            (x, report.iterations)
        })
    };
    let (x1, i1) = run(1);
    let (x2, i2) = run(2);
    assert_eq!(i1, i2);
    assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()));
}

/// A fixed-particle run factorises once: with `matrix_unchanged` the LU is reused for new
/// right-hand sides, and a changed matrix (the flag off) is factorised again.
#[test]
fn direct_path_reuses_its_factorisation_while_the_matrix_is_unchanged() {
    let a = convection_diffusion(20, false, 10.0);
    let mut solver = Solver::new();
    let mut options = SolverOptions {
        strategy: Strategy::Direct,
        ..Default::default()
    };
    for k in 0..3 {
        let exact: Vec<f64> = smooth_field(400)
            .iter()
            .map(|v| v * (k + 1) as f64)
            .collect();
        let b = matvec(&a, &exact);
        let mut x = vec![0.0; 400];
        solver.solve(&a, &b, &mut x, &options).unwrap();
        assert!(max_diff(&x, &exact) < 1e-10);
        options.matrix_unchanged = true;
    }
    assert_eq!(solver.factorisations(), 1);
    options.matrix_unchanged = false;
    let mut x = vec![0.0; 400];
    solver
        .solve(&a, &matvec(&a, &smooth_field(400)), &mut x, &options)
        .unwrap();
    assert_eq!(solver.factorisations(), 2);
}

/// Iterations of BiCGStab with `preconditioner` on `a` (relative tolerance 1e-8) and the
/// error against the known solution.
fn iterations_with(
    a: &CsMat<f64>,
    preconditioner: Preconditioner,
    null_space: NullSpace,
) -> (usize, f64) {
    let n = a.rows();
    let mut exact = smooth_field(n);
    if null_space == NullSpace::Constant {
        remove_mean(&mut exact);
    }
    let b = matvec(a, &exact);
    let mut x = vec![0.0; n];
    let options = SolverOptions {
        preconditioner,
        null_space,
        max_iterations: 5000,
        ..Default::default()
    };
    let r = Solver::new().solve(a, &b, &mut x, &options).unwrap();
    assert_eq!(r.method, Method::BiCgStab, "{preconditioner:?}: fell back");
    (r.iterations, max_diff(&x, &exact))
}

/// The AMG V-cycle makes the iteration count of a Laplacian nearly independent of its size,
/// where Jacobi's grows like the grid's side: 40² and 120² unknowns, Dirichlet. Bounds: AMG
/// ≤ 25 iterations at both sizes (a V(1,1) smoothed-aggregation cycle contracts by ~0.1–0.3
/// per application on the 5-point Laplacian), Jacobi ≥ 3× more at 120².
#[test]
fn amg_iterations_do_not_grow_with_the_grid() {
    for m in [40, 120] {
        let a = dirichlet_laplacian(m);
        let (amg, error) = iterations_with(&a, Preconditioner::Amg, NullSpace::None);
        let (jacobi, _) = iterations_with(&a, Preconditioner::Jacobi, NullSpace::None);
        eprintln!("m = {m}: AMG {amg}, Jacobi {jacobi} iterations");
        assert!(amg <= 25, "m = {m}: AMG {amg} iterations");
        assert!(error < 1e-4, "m = {m}: error {error}");
        if m == 120 {
            assert!(jacobi >= 3 * amg, "Jacobi {jacobi} vs AMG {amg}");
        }
    }
}

/// AMG on the singular periodic, non-symmetric convection–diffusion operator (constant null
/// space, the closed-domain PPE's case): converges to the zero-mean solution.
#[test]
fn amg_handles_the_constant_null_space() {
    let a = convection_diffusion(60, true, 10.0);
    let (iterations, error) = iterations_with(&a, Preconditioner::Amg, NullSpace::Constant);
    let (jacobi, _) = iterations_with(&a, Preconditioner::Jacobi, NullSpace::Constant);
    eprintln!("periodic convection-diffusion: AMG {iterations}, Jacobi {jacobi} iterations");
    assert!(error < 1e-5, "error {error}");
    assert!(iterations < jacobi, "AMG {iterations} vs Jacobi {jacobi}");
}

/// The adaptive preconditioner is Jacobi where Jacobi finishes within its budget of 40
/// iterations (the same iterations, 10² unknowns) and turns to AMG where it does not (120²:
/// at most the budget plus AMG's own ≤ 25, far below Jacobi's).
#[test]
fn adaptive_preconditioner_is_jacobi_until_jacobi_runs_long() {
    let small = dirichlet_laplacian(10);
    let (adaptive, error) = iterations_with(&small, Preconditioner::Adaptive, NullSpace::None);
    let (jacobi, _) = iterations_with(&small, Preconditioner::Jacobi, NullSpace::None);
    assert!(jacobi < 40, "Jacobi {jacobi} iterations on 10²");
    assert_eq!(adaptive, jacobi);
    assert!(error < 1e-4, "error {error}");
    let large = dirichlet_laplacian(120);
    let (adaptive, error) = iterations_with(&large, Preconditioner::Adaptive, NullSpace::None);
    let (jacobi, _) = iterations_with(&large, Preconditioner::Jacobi, NullSpace::None);
    eprintln!("120²: adaptive {adaptive}, Jacobi {jacobi} iterations");
    assert!(adaptive <= 40 + 25, "adaptive {adaptive} iterations");
    assert!(
        3 * adaptive < jacobi,
        "adaptive {adaptive} vs Jacobi {jacobi}"
    );
    assert!(error < 1e-4, "error {error}");
}

/// `solve_many` on the components of an implicit diffusion step: each result is the one a
/// solve on its own gives, bit for bit (the lanes share only the passes over the matrix),
/// with Jacobi and with the adaptive choice (whose Jacobi budget the tight tolerance
/// exhausts), through the LU fallback, and with a zero right-hand side among the lanes.
#[test]
fn lock_step_solves_equal_one_solve_after_another_bit_for_bit() {
    let m = 100; // 10,000 unknowns: the parallel kernels
    let diffusion = convection_diffusion(m, false, 3.0);
    // I + c A, weakly coupled as the viscous matrix (off-diagonal ratio below 0.9).
    let largest = diffusion.diag().data().iter().copied().fold(0.0, f64::max);
    let identity = CsMat::<f64>::eye(m * m);
    let weak = &identity + &diffusion.map(|v| v * 8.5 / largest);
    let ratio = bicgstab::off_diagonal_ratio(&weak);
    assert!(
        ratio < bicgstab::WEAK_COUPLING && ratio > 0.8,
        "ratio {ratio}"
    );
    // Strongly coupled: the adaptive choice turns to AMG, and the lanes start over one
    // after the other.
    let strong = &identity + &diffusion.map(|v| v * 200.0 / largest);
    assert!(bicgstab::off_diagonal_ratio(&strong) > bicgstab::WEAK_COUPLING);
    let n = m * m;
    let b0 = smooth_field(n);
    let b1: Vec<f64> = (0..n)
        .map(|i| ((i * 7919) % 1000) as f64 / 1000.0 - 0.4)
        .collect();
    let b2: Vec<f64> = (0..n).map(|i| (i as f64 * 0.013).cos()).collect();
    let guess: Vec<f64> = b0.iter().map(|v| 0.9 * v).collect();
    // The third: BiCGStab stopped early, the LU takes over each lane (the later ones
    // reusing its factors).
    let runs = [
        (&weak, Preconditioner::Jacobi, 2000),
        (&weak, Preconditioner::Adaptive, 2000),
        (&weak, Preconditioner::Jacobi, 5),
        (&strong, Preconditioner::Adaptive, 2000),
    ];
    for (a, preconditioner, max_iterations) in runs {
        let options = SolverOptions {
            relative_tolerance: 1e-13,
            preconditioner,
            max_iterations,
            ..Default::default()
        };
        let mut one_by_one = Solver::new();
        let mut expected = [guess.clone(), b1.clone(), guess.clone()];
        let mut reports = Vec::new();
        for (c, (b, x)) in [&b0, &b1, &b2].into_iter().zip(&mut expected).enumerate() {
            let options = SolverOptions {
                matrix_unchanged: c > 0,
                ..options
            };
            reports.push(one_by_one.solve(a, b, x, &options).unwrap());
        }
        let mut lanes = Solver::new();
        assert!(lanes.lanes_apply(&options));
        let mut got = [guess.clone(), b1.clone(), guess.clone()];
        let [g0, g1, g2] = &mut got;
        let lane_reports = lanes
            .solve_many(a, [&b0, &b1, &b2], [g0, g1, g2], &options)
            .unwrap();
        assert_eq!(lanes.lanes.len(), 3, "the lock-step path was taken");
        assert_eq!(lane_reports.to_vec(), reports, "{preconditioner:?}");
        if max_iterations < bicgstab::JACOBI_BUDGET {
            assert!(reports[0].fell_back && reports[1].fell_back);
            assert_eq!(lanes.factorisations(), 1);
        } else {
            assert!(reports[0].iterations > bicgstab::JACOBI_BUDGET);
            assert_ne!(reports[0].iterations, reports[1].iterations);
        }
        for (g, e) in got.iter().zip(&expected) {
            let same = g.iter().zip(e).all(|(g, e)| g.to_bits() == e.to_bits());
            assert!(same, "{preconditioner:?}");
        }
        assert!(max_diff(&matvec(a, &got[0]), &b0) < 1e-10);
        let amg = !lanes.bicgstab.amg_levels().is_empty();
        assert_eq!(
            amg,
            std::ptr::eq(a, &strong),
            "a hierarchy only where AMG took over"
        );
    }
    // A zero right-hand side among the lanes: x = 0 at once, as on its own.
    let (mut x0, mut x1) = (guess.clone(), guess.clone());
    let options = SolverOptions::default();
    let zero = vec![0.0; n];
    let mut lanes = Solver::new();
    let reports = lanes
        .solve_many(&weak, [&b0, &zero], [&mut x0, &mut x1], &options)
        .unwrap();
    assert!(x1.iter().all(|v| *v == 0.0) && reports[1].iterations == 0);
    assert!(reports[0].iterations > 0 && max_diff(&matvec(&weak, &x0), &b0) < 1e-6);
}
