//! BiCGStab (van der Vorst 1992, right preconditioning) on a CSR matrix, preconditioned by
//! Jacobi or by a smoothed-aggregation AMG V-cycle ([`crate::amg`]).

use crate::amg::Amg;
use crate::vector::{dot, for_each_mut, norm, spmv, sum};
use crate::{NullSpace, Preconditioner, SolverOptions};
use sprs::CsMat;

/// The work vectors of one BiCGStab recurrence (r, r̂, p, v, s, t, y = M⁻¹p, z = M⁻¹s),
/// sized on first use and reused afterwards.
#[derive(Default)]
pub(crate) struct Vectors {
    pub r: Vec<f64>,
    pub r_hat: Vec<f64>,
    pub p: Vec<f64>,
    pub v: Vec<f64>,
    pub s: Vec<f64>,
    pub t: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Vectors {
    fn all(&self) -> [&Vec<f64>; 8] {
        [
            &self.r,
            &self.r_hat,
            &self.p,
            &self.v,
            &self.s,
            &self.t,
            &self.y,
            &self.z,
        ]
    }

    pub(crate) fn heap_bytes(&self) -> usize {
        let capacity: usize = self.all().iter().map(|v| v.capacity()).sum();
        capacity * std::mem::size_of::<f64>()
    }

    pub(crate) fn resize(&mut self, n: usize) {
        let Self {
            r,
            r_hat,
            p,
            v,
            s,
            t,
            y,
            z,
        } = self;
        for v in [r, r_hat, p, v, s, t, y, z] {
            v.resize(n, 0.0);
        }
    }
}

/// Work vectors of BiCGStab, sized on first use and reused afterwards.
#[derive(Default)]
pub struct BiCgStabWorkspace {
    vectors: Vectors,
    inv_diag: Vec<f64>,
    pub(crate) partials: Vec<f64>,
    /// The AMG hierarchy (AMG preconditioning only), its age in solves and the iterations
    /// of the first solve with it.
    amg: Option<Amg>,
    amg_age: usize,
    amg_baseline: usize,
}

/// Solves an AMG hierarchy serves before it is rebuilt, though the matrix changes every step
/// (moving particles change it slowly; its set-up costs several solves).
const AMG_MAX_AGE: usize = 20;
/// Largest off-diagonal row sum, relative to the diagonal, below which AMG is not built and
/// Jacobi is used. The implicit viscous matrix I − δtνL has the ratio c/(1 + c), c = δtν|L_ii|;
/// where it is small Jacobi already contracts fast and a V-cycle (~5 products) does not pay.
/// Measured viscous solve times, Jacobi against AMG: drop impact (ratio 0.62) 5.8 s against
/// 7.6 s; cylinder array R/δr = 9 (0.82) 0.31 against 0.33 s; R/δr = 18 (0.95) 3.9 against
/// 2.8 s; P2 (> 0.99) 15.5 against 8.3 s. The PPE's Laplacian rows have the ratio 1.
pub(crate) const WEAK_COUPLING: f64 = 0.9;
/// Jacobi iterations after which [`Preconditioner::Adaptive`] turns to AMG. An AMG iteration
/// costs ~5 Jacobi ones and its set-up ~100 (`rheosph bench --solvers`, 16k unknowns), and a
/// hierarchy serves up to [`AMG_MAX_AGE`] solves: a solve that needs 40 Jacobi iterations
/// would need hundreds at the tolerances of the PPE, where AMG needs ~10. The warm-started
/// Lagrangian PPE of an explicit run needs a few, and never pays for a hierarchy.
pub(crate) const JACOBI_BUDGET: usize = 40;

pub(crate) struct Outcome {
    pub converged: bool,
    pub iterations: usize,
    pub relative_residual: f64,
}

/// The operator BiCGStab iterates with: `A`, or for a constant null space the rank-one
/// augmented `A + c 1 1ᵀ` (non-singular when the left null vector of A is not orthogonal to 1).
struct Operator<'a> {
    a: &'a CsMat<f64>,
    rank_one: f64,
}

impl Operator<'_> {
    fn apply(&self, x: &[f64], y: &mut [f64], partials: &mut Vec<f64>) {
        spmv(self.a, x, y);
        if self.rank_one != 0.0 {
            let shift = self.rank_one * sum(x, partials);
            for_each_mut(y, |_, v| *v += shift);
        }
    }
}

/// Restarts allowed when the recurrence breaks down or the recursive residual drifts from
/// the true one.
pub(crate) const MAX_RESTARTS: usize = 8;

impl BiCgStabWorkspace {
    pub(crate) fn heap_bytes(&self) -> usize {
        self.vectors.heap_bytes()
            + (self.inv_diag.capacity() + self.partials.capacity()) * std::mem::size_of::<f64>()
            + self.amg.as_ref().map_or(0, |a| a.heap_bytes())
    }

    /// Drops the AMG hierarchy: the next solve builds a new one (after a reordering of the
    /// unknowns, or where a run's continuation from a checkpoint must match).
    pub fn invalidate(&mut self) {
        self.amg = None;
    }

    /// Whether an AMG hierarchy is held.
    pub(crate) fn has_amg(&self) -> bool {
        self.amg.is_some()
    }

    /// The level sizes of the AMG hierarchy last used (empty with Jacobi).
    pub fn amg_levels(&self) -> Vec<usize> {
        self.amg.as_ref().map_or(Vec::new(), |a| a.sizes())
    }

    fn resize(&mut self, n: usize) {
        self.vectors.resize(n);
        self.inv_diag.resize(n, 0.0);
    }

    pub(crate) fn solve(
        &mut self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolverOptions,
    ) -> Outcome {
        let n = b.len();
        self.resize(n);
        let rank_one = match options.null_space {
            NullSpace::None => 0.0,
            NullSpace::Constant => mean_abs_diagonal(a) / n as f64,
        };
        let op = Operator { a, rank_one };
        // The preconditioner is set up only when an iteration is needed: a warm start often
        // meets the tolerance as it is, and an AMG hierarchy costs several solves to build.
        let mut preconditioned = false;
        // The adaptive preconditioner has tried AMG in this solve.
        let mut switched = false;
        if options.null_space == NullSpace::Constant {
            remove_mean(x, &mut self.partials);
        }
        let b_norm = norm(b, &mut self.partials);
        let target = (options.relative_tolerance * b_norm).max(options.absolute_tolerance);

        let mut iterations = 0;
        // The true residual that met the target (the projected residual of the final x up
        // to round-off: removing x's mean changes A x only by the rows' round-off sums).
        let mut converged_residual = None;
        for restart in 0..=MAX_RESTARTS {
            self.true_residual(&op, b, x, rank_one);
            let mut residual = norm(&self.vectors.r, &mut self.partials);
            if restart == 0 && residual > b_norm {
                // The guess is worse than none (e.g. the previous step's pressure when it
                // was mostly the correction of that step's leftover divergence): start cold.
                x.iter_mut().for_each(|v| *v = 0.0);
                self.true_residual(&op, b, x, rank_one);
                residual = norm(&self.vectors.r, &mut self.partials);
            }
            if residual <= target {
                converged_residual = Some(residual);
                break;
            }
            if iterations >= options.max_iterations {
                break;
            }
            if !preconditioned {
                self.choose_preconditioner(a, options, rank_one);
                preconditioned = true;
            }
            let mut budget = options.max_iterations - iterations;
            let adapting = options.preconditioner == Preconditioner::Adaptive
                && self.amg.is_none()
                && !switched;
            if adapting {
                if iterations >= JACOBI_BUDGET {
                    // Jacobi has had its share: AMG for the rest of this solve and the
                    // next ones while the hierarchy is fresh.
                    self.build_amg(a, options);
                    switched = true;
                    continue;
                }
                budget = budget.min(JACOBI_BUDGET - iterations);
            }
            iterations += self.iterate(&op, x, target, budget);
        }
        if options.null_space == NullSpace::Constant {
            remove_mean(x, &mut self.partials);
        }
        let relative_residual = match converged_residual {
            Some(residual) => residual / b_norm,
            None => self.projected_residual(a, b, x, options.null_space) / b_norm,
        };
        let converged = converged_residual.is_some();
        if preconditioned && self.amg.is_some() {
            // A hierarchy that has lost its grip (iterations doubled since its first solve)
            // is rebuilt at the next solve.
            if self.amg_age == 0 {
                self.amg_baseline = iterations;
            } else if iterations > 2 * self.amg_baseline + 4 {
                self.amg_age = AMG_MAX_AGE;
            }
            self.amg_age += 1;
        }
        Outcome {
            converged: converged && relative_residual.is_finite(),
            iterations,
            relative_residual,
        }
    }

    /// Keeps, builds or drops the AMG hierarchy; Jacobi's diagonal whenever there is none.
    /// The adaptive choice keeps a fresh hierarchy and otherwise starts with Jacobi.
    fn choose_preconditioner(&mut self, a: &CsMat<f64>, options: &SolverOptions, rank_one: f64) {
        let stale = self.amg.as_ref().is_none_or(|m| m.rows() != a.rows())
            || (!options.matrix_unchanged && self.amg_age >= AMG_MAX_AGE);
        let wanted = options.preconditioner == Preconditioner::Amg;
        let keep = wanted || options.preconditioner == Preconditioner::Adaptive;
        if keep && !stale {
            return;
        }
        if wanted {
            self.build_amg(a, options);
        } else {
            self.amg = None;
        }
        if self.amg.is_none() {
            jacobi(a, rank_one, &mut self.inv_diag);
        }
    }

    /// An AMG hierarchy for `a`, unless it is weakly coupled: Jacobi contracts by its ratio
    /// or better per iteration (then none).
    fn build_amg(&mut self, a: &CsMat<f64>, options: &SolverOptions) {
        if off_diagonal_ratio(a) >= WEAK_COUPLING {
            let singular = options.null_space == NullSpace::Constant;
            self.amg = Some(Amg::setup(a, singular));
            self.amg_age = 0;
        } else {
            self.amg = None;
        }
    }

    /// The true residual r = b − A'x into `self.vectors.r`. For the rank-one operator, x is first
    /// shifted by the constant that removes the residual's mean: A'(k1) = c n k 1, and a
    /// zero-mean warm start (the previous pressure) would otherwise begin with the whole
    /// incompatible part μ1 of b as its residual.
    fn true_residual(&mut self, op: &Operator, b: &[f64], x: &mut [f64], rank_one: f64) {
        let n = b.len();
        op.apply(x, &mut self.vectors.r, &mut self.partials);
        for_each_mut(&mut self.vectors.r, |i, ri| *ri = b[i] - *ri);
        if rank_one != 0.0 {
            let mean = sum(&self.vectors.r, &mut self.partials) / n as f64;
            let shift = mean / (rank_one * n as f64);
            for_each_mut(x, |_, v| *v += shift);
            for_each_mut(&mut self.vectors.r, |_, ri| *ri -= mean);
        }
    }

    /// One BiCGStab cycle from the current true residual in `self.r`. Returns the iterations
    /// spent; stops on convergence of the recursive residual, breakdown, or the budget.
    fn iterate(&mut self, op: &Operator, x: &mut [f64], target: f64, budget: usize) -> usize {
        let Self {
            vectors,
            inv_diag,
            partials,
            amg,
            ..
        } = self;
        let Vectors {
            r,
            r_hat,
            p,
            v,
            s,
            t,
            y,
            z,
        } = vectors;
        let mut precondition = |x: &[f64], y: &mut [f64]| match amg.as_mut() {
            Some(m) => m.apply(x, y),
            None => apply_jacobi(inv_diag, x, y),
        };
        r_hat.copy_from_slice(r);
        p.iter_mut().for_each(|e| *e = 0.0);
        v.iter_mut().for_each(|e| *e = 0.0);
        let (mut rho, mut alpha, mut omega): (f64, f64, f64) = (1.0, 1.0, 1.0);
        let tiny = f64::MIN_POSITIVE.sqrt();
        for k in 0..budget {
            let rho_new = dot(r_hat, r, partials);
            if rho_new.abs() < tiny || omega.abs() < tiny {
                return k; // breakdown: restart from the true residual
            }
            let beta = (rho_new / rho) * (alpha / omega);
            rho = rho_new;
            {
                let (r, v) = (&*r, &*v);
                for_each_mut(p, |i, pi| *pi = r[i] + beta * (*pi - omega * v[i]));
            }
            precondition(p, y);
            op.apply(y, v, partials);
            let denominator = dot(r_hat, v, partials);
            if denominator.abs() < tiny {
                return k;
            }
            alpha = rho / denominator;
            {
                let (r, v) = (&*r, &*v);
                for_each_mut(s, |i, si| *si = r[i] - alpha * v[i]);
            }
            if norm(s, partials) <= target {
                let y = &*y;
                for_each_mut(x, |i, xi| *xi += alpha * y[i]);
                return k + 1;
            }
            precondition(s, z);
            op.apply(z, t, partials);
            let tt = dot(t, t, partials);
            omega = if tt > 0.0 {
                dot(t, s, partials) / tt
            } else {
                0.0
            };
            {
                let (y, z) = (&*y, &*z);
                for_each_mut(x, |i, xi| *xi += alpha * y[i] + omega * z[i]);
            }
            {
                let (s, t) = (&*s, &*t);
                for_each_mut(r, |i, ri| *ri = s[i] - omega * t[i]);
            }
            if norm(r, partials) <= target {
                return k + 1;
            }
        }
        budget
    }

    /// ‖b − μ1 − A x‖ with μ the mean of b − A x for a constant null space (μ = 0 otherwise).
    pub(crate) fn projected_residual(
        &mut self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &[f64],
        null_space: NullSpace,
    ) -> f64 {
        self.vectors.r.resize(b.len(), 0.0);
        spmv(a, x, &mut self.vectors.r);
        for_each_mut(&mut self.vectors.r, |i, ri| *ri = b[i] - *ri);
        if null_space == NullSpace::Constant {
            remove_mean(&mut self.vectors.r, &mut self.partials);
        }
        norm(&self.vectors.r, &mut self.partials)
    }
}

pub(crate) fn apply_jacobi(inv_diag: &[f64], x: &[f64], y: &mut [f64]) {
    for_each_mut(y, |i, yi| *yi = inv_diag[i] * x[i]);
}

/// Inverse diagonal of `A + shift 1 1ᵀ`; rows with a zero diagonal are left unscaled.
pub(crate) fn jacobi(a: &CsMat<f64>, shift: f64, inv_diag: &mut [f64]) {
    for_each_mut(inv_diag, |i, d| {
        let diag = diagonal_entries(a, i).sum::<f64>() + shift;
        *d = if diag != 0.0 && diag.is_finite() {
            1.0 / diag
        } else {
            1.0
        };
    });
}

/// The stored entries a_ii of row i (one, unless the matrix holds duplicates), read from
/// the row's own slice rather than by iterating over every entry of the matrix.
fn diagonal_entries(a: &CsMat<f64>, i: usize) -> impl Iterator<Item = f64> + '_ {
    let range = a.indptr().outer_inds_sz(i);
    let (indices, data) = (&a.indices()[range.clone()], &a.data()[range]);
    indices
        .iter()
        .zip(data)
        .filter(move |(j, _)| **j == i)
        .map(|(_, v)| *v)
}

/// max_i Σ_{j≠i} |a_ij| / |a_ii| (∞ for a zero diagonal).
pub(crate) fn off_diagonal_ratio(a: &CsMat<f64>) -> f64 {
    (0..a.rows())
        .map(|i| {
            let row = a.outer_view(i).expect("row in range");
            let (mut diag, mut off) = (0.0_f64, 0.0_f64);
            for (j, v) in row.iter() {
                if j == i {
                    diag += v.abs();
                } else {
                    off += v.abs();
                }
            }
            if diag > 0.0 {
                off / diag
            } else {
                f64::INFINITY
            }
        })
        .fold(0.0, f64::max)
}

pub(crate) fn mean_abs_diagonal(a: &CsMat<f64>) -> f64 {
    let n = a.rows().max(1);
    // Sequential in row order: the rounding of the rank-one shift does not depend on threads.
    let total: f64 = (0..a.rows())
        .flat_map(|i| diagonal_entries(a, i).map(f64::abs))
        .sum();
    if total > 0.0 {
        total / n as f64
    } else {
        1.0
    }
}

fn remove_mean(x: &mut [f64], partials: &mut Vec<f64>) {
    let mean = sum(x, partials) / x.len() as f64;
    for_each_mut(x, |_, v| *v -= mean);
}
