//! Sparse linear algebra for rheosph. Knows nothing of SPH.
//!
//! The main entry point is [`Solver::solve`]: a CSR matrix (sprs), a right-hand side and an
//! initial guess go in; the solution and a [`SolveReport`] come out. The primary path is
//! Jacobi-preconditioned BiCGStab (our own, on sprs), warm-started from the guess; when it does
//! not reach its tolerance the solver falls back to faer's sparse LU.
//!
//! Singular systems whose null space is the constant vector (a pressure Poisson equation on a
//! closed domain) are handled identically on both paths: both solve
//!
//! ```text
//!     A x + μ 1 = b,    Σ x = 0,
//! ```
//!
//! i.e. the incompatible part of `b` (its component along the left null vector) is absorbed
//! by one uniform residual μ and the free constant is fixed by a zero mean. The direct path
//! factorises the sparse `A + s e_k e_kᵀ` and recovers the bordered solution with two cached
//! auxiliary solves (a deflation, see `lu.rs`); the iterative path applies the rank-one
//! augmented operator `A + (s/n) 1 1ᵀ`, whose solution differs from the bordered one only by
//! a constant that the zero-mean projection removes (see [`NullSpace`]).
//!
//! All reductions are computed over fixed-size blocks and summed in order, so the results do
//! not depend on the number of threads.

pub mod amg;
mod bicgstab;
mod lanes;
mod lu;
pub mod vector;

use sprs::CsMat;

pub use bicgstab::BiCgStabWorkspace;

/// Which algorithm produced the solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Jacobi-preconditioned BiCGStab.
    BiCgStab,
    /// faer sparse LU with partial pivoting.
    SparseLu,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::BiCgStab => "bicgstab",
            Method::SparseLu => "sparse-lu",
        }
    }
}

/// Which solver to try first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// BiCGStab, falling back to sparse LU when it does not converge.
    IterativeWithFallback,
    /// Sparse LU only.
    Direct,
}

/// The null space of the matrix, if it is known to be singular.
/// The preconditioner of BiCGStab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preconditioner {
    /// The inverse diagonal.
    Jacobi,
    /// One smoothed-aggregation AMG V-cycle ([`amg`]); the hierarchy is rebuilt when the
    /// matrix changes.
    Amg,
    /// Jacobi, turning to AMG for the rest of a solve (and the next solves while its
    /// hierarchy is fresh) once Jacobi has spent a budget of iterations.
    Adaptive,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NullSpace {
    /// The matrix is non-singular.
    None,
    /// Every row sums to zero: `A 1 = 0`. The solution is returned with zero mean, and the
    /// incompatible part of the right-hand side is removed as one uniform shift μ.
    Constant,
}

/// Options of one solve.
#[derive(Clone, Copy, Debug)]
pub struct SolverOptions {
    /// Relative tolerance on ‖b − A x‖ / ‖b‖ (Euclidean norms).
    pub relative_tolerance: f64,
    /// Absolute floor on ‖b − A x‖, for right-hand sides at round-off level.
    pub absolute_tolerance: f64,
    pub max_iterations: usize,
    pub null_space: NullSpace,
    pub strategy: Strategy,
    /// The caller's promise that the matrix equals the one of the previous solve: the direct
    /// path then reuses its factorisation (a fixed-particle run factorises once).
    pub matrix_unchanged: bool,
    /// Jacobi, or an AMG V-cycle (BiCGStab only).
    pub preconditioner: Preconditioner,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-8,
            absolute_tolerance: 0.0,
            max_iterations: 2000,
            null_space: NullSpace::None,
            strategy: Strategy::IterativeWithFallback,
            matrix_unchanged: false,
            preconditioner: Preconditioner::Jacobi,
        }
    }
}

/// What a solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// The method that produced the returned solution.
    pub method: Method,
    /// BiCGStab iterations spent (also when the fallback then ran).
    pub iterations: usize,
    /// Final true relative residual ‖b − μ1 − A x‖ / ‖b‖ of the returned solution
    /// (μ = 0 unless the null space is constant). 0 when b = 0.
    pub relative_residual: f64,
    /// Whether BiCGStab failed and the sparse LU produced the solution.
    pub fell_back: bool,
    /// Whether the solve ended on the absolute floor without reaching the relative
    /// tolerance: a right-hand side at round-off level, where the relative residual is
    /// meaningless (it is then O(1) by design).
    pub on_absolute_floor: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error("matrix is {rows}x{cols}, right-hand side has {rhs} entries and guess {guess}")]
    Dimension {
        rows: usize,
        cols: usize,
        rhs: usize,
        guess: usize,
    },
    #[error("right-hand side or initial guess is not finite")]
    NonFinite,
    #[error("sparse LU failed: {0}")]
    Lu(String),
    #[error("no method reached the tolerance: best relative residual {0:.3e}")]
    NotConverged(f64),
}

/// A reusable solver: owns every work vector, so repeated solves of the same size allocate
/// nothing.
#[derive(Default)]
pub struct Solver {
    bicgstab: BiCgStabWorkspace,
    factorisation: Option<lu::Factorisation>,
    factorisations: usize,
    lu_x: Vec<f64>,
    /// The workspaces of [`Solver::solve_many`]'s lanes.
    lanes: Vec<bicgstab::Vectors>,
    lane_scratch: lanes::Scratch,
    /// The lanes' guesses, kept to start over one after the other (see [`lanes::solve`]).
    lane_guesses: Vec<Vec<f64>>,
    /// The last lock-step attempt turned to AMG; set until a solve needs no hierarchy.
    lanes_gave_up: bool,
}

impl Solver {
    pub fn new() -> Self {
        Self::default()
    }

    /// Solves `A x = b` (or the null-space-constrained problem, see [`NullSpace`]).
    ///
    /// `x` holds the initial guess on entry (the warm start) and the solution on exit. On
    /// error `x` is left holding the best iterate found.
    pub fn solve(
        &mut self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolverOptions,
    ) -> Result<SolveReport, SolveError> {
        check(a, b, x)?;
        let b_norm = vector::norm(b, &mut self.bicgstab.partials);
        if b_norm == 0.0 {
            x.iter_mut().for_each(|v| *v = 0.0);
            return Ok(ZERO_RIGHT_HAND_SIDE);
        }
        let mut iterations = 0;
        let mut best_residual = f64::INFINITY;
        if options.strategy == Strategy::IterativeWithFallback {
            let outcome = self.bicgstab.solve(a, b, x, options);
            iterations = outcome.iterations;
            best_residual = outcome.relative_residual;
            if outcome.converged {
                return Ok(converged(
                    outcome.iterations,
                    outcome.relative_residual,
                    options,
                ));
            }
        }
        self.fall_back(
            a,
            b,
            x,
            options,
            Unconverged {
                iterations,
                best_residual,
                b_norm,
            },
        )
    }

    /// Solves `A x_m = b_m` for M right-hand sides of one matrix: the result of
    /// [`Self::solve`] on each in turn (the later ones told the matrix is unchanged), bit
    /// for bit. Where BiCGStab stays on Jacobi without a null space (an implicit viscous
    /// step's components), the solves run in lock-step and share each pass over the matrix
    /// ([`lanes`]); otherwise one after the other.
    pub fn solve_many<const M: usize>(
        &mut self,
        a: &CsMat<f64>,
        b: [&[f64]; M],
        x: [&mut [f64]; M],
        options: &SolverOptions,
    ) -> Result<[SolveReport; M], SolveError> {
        if !self.lanes_apply(options) || M < 2 || self.lanes_gave_up {
            let reports = self.one_after_another(a, b, x, options);
            // Jacobi served without a hierarchy: the lanes may try again.
            self.lanes_gave_up &= self.bicgstab.has_amg();
            return reports;
        }
        for (b, x) in b.iter().zip(&x) {
            check(a, b, x)?;
        }
        self.lanes
            .resize_with(M.max(self.lanes.len()), Default::default);
        self.lane_guesses
            .resize_with(M.max(self.lane_guesses.len()), Vec::new);
        for (saved, x) in self.lane_guesses.iter_mut().zip(&x) {
            saved.clear();
            saved.extend_from_slice(x);
        }
        let mut x = x;
        let lanes = {
            let x: [&mut [f64]; M] = x.each_mut().map(|x| &mut **x);
            lanes::solve(a, b, x, &mut self.lanes, &mut self.lane_scratch, options)
        };
        let Some(outcomes) = lanes else {
            for (x, saved) in x.iter_mut().zip(&self.lane_guesses) {
                x.copy_from_slice(saved);
            }
            // Not again while the matrix wants AMG: the attempt cost ~40 iterations.
            self.lanes_gave_up = true;
            return self.one_after_another(a, b, x, options);
        };
        if options.preconditioner == Preconditioner::Jacobi {
            self.bicgstab.invalidate();
        }
        let mut reports = [ZERO_RIGHT_HAND_SIDE; M];
        let mut options = *options;
        for (c, (outcome, x)) in outcomes.iter().zip(x).enumerate() {
            if outcome.converged {
                reports[c] = converged(outcome.iterations, outcome.relative_residual, &options);
                continue;
            }
            let b_norm = vector::norm(b[c], &mut self.bicgstab.partials);
            let unconverged = Unconverged {
                iterations: outcome.iterations,
                best_residual: outcome.relative_residual,
                b_norm,
            };
            let factorisations = self.factorisations;
            reports[c] = self.fall_back(a, b[c], x, &options, unconverged)?;
            // Later lanes reuse the factors of this matrix.
            options.matrix_unchanged |= self.factorisations > factorisations;
        }
        Ok(reports)
    }

    /// [`Self::solve`] on each right-hand side in turn, the later ones told the matrix is
    /// unchanged.
    fn one_after_another<const M: usize>(
        &mut self,
        a: &CsMat<f64>,
        b: [&[f64]; M],
        x: [&mut [f64]; M],
        options: &SolverOptions,
    ) -> Result<[SolveReport; M], SolveError> {
        let mut reports = [ZERO_RIGHT_HAND_SIDE; M];
        for (c, (b, x)) in b.into_iter().zip(x).enumerate() {
            let options = SolverOptions {
                matrix_unchanged: options.matrix_unchanged || c > 0,
                ..*options
            };
            reports[c] = self.solve(a, b, x, &options)?;
        }
        Ok(reports)
    }

    /// Whether [`Self::solve_many`] can try its solves in lock-step: BiCGStab on Jacobi (the
    /// adaptive choice starts there when no hierarchy is held) and no null space.
    fn lanes_apply(&self, options: &SolverOptions) -> bool {
        let iterative = options.strategy == Strategy::IterativeWithFallback
            && options.null_space == NullSpace::None;
        let jacobi = match options.preconditioner {
            Preconditioner::Jacobi => true,
            Preconditioner::Amg => false,
            Preconditioner::Adaptive => !self.bicgstab.has_amg(),
        };
        iterative && jacobi
    }

    /// The sparse LU after BiCGStab did not converge (or the direct strategy): its solution
    /// when its residual is the better one.
    fn fall_back(
        &mut self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolverOptions,
        unconverged: Unconverged,
    ) -> Result<SolveReport, SolveError> {
        let Unconverged {
            iterations,
            best_residual,
            b_norm,
        } = unconverged;
        let fell_back = options.strategy == Strategy::IterativeWithFallback;
        let mut lu_x = std::mem::take(&mut self.lu_x);
        lu_x.resize(b.len(), 0.0);
        let direct = self.direct(a, b, &mut lu_x, options);
        let residual = self
            .bicgstab
            .projected_residual(a, b, &lu_x, options.null_space)
            / b_norm;
        if direct.is_ok() && residual.is_finite() && residual <= best_residual {
            x.copy_from_slice(&lu_x);
        }
        self.lu_x = lu_x;
        match direct {
            Ok(()) => {
                if !residual.is_finite() || residual > best_residual {
                    return Err(SolveError::NotConverged(best_residual));
                }
                Ok(SolveReport {
                    method: Method::SparseLu,
                    iterations,
                    relative_residual: residual,
                    fell_back,
                    on_absolute_floor: false,
                })
            }
            Err(e) if best_residual.is_finite() && fell_back => {
                let _ = e;
                Err(SolveError::NotConverged(best_residual))
            }
            Err(e) => Err(e),
        }
    }
}

/// Where BiCGStab left a solve that the LU then takes over.
#[derive(Clone, Copy)]
struct Unconverged {
    iterations: usize,
    best_residual: f64,
    b_norm: f64,
}

/// The report of a right-hand side b = 0, whose solution x = 0 is returned at once.
const ZERO_RIGHT_HAND_SIDE: SolveReport = SolveReport {
    method: Method::BiCgStab,
    iterations: 0,
    relative_residual: 0.0,
    fell_back: false,
    on_absolute_floor: false,
};

/// The report of a converged BiCGStab solve.
fn converged(iterations: usize, relative_residual: f64, options: &SolverOptions) -> SolveReport {
    SolveReport {
        method: Method::BiCgStab,
        iterations,
        relative_residual,
        fell_back: false,
        on_absolute_floor: relative_residual > options.relative_tolerance,
    }
}

/// A square CSR matrix, with a right-hand side and a guess of its size, all finite.
fn check(a: &CsMat<f64>, b: &[f64], x: &[f64]) -> Result<(), SolveError> {
    let (rows, cols) = a.shape();
    if rows != cols || b.len() != rows || x.len() != rows || !a.is_csr() {
        return Err(SolveError::Dimension {
            rows,
            cols,
            rhs: b.len(),
            guess: x.len(),
        });
    }
    if !b.iter().chain(x.iter()).all(|v| v.is_finite()) {
        return Err(SolveError::NonFinite);
    }
    Ok(())
}

impl Solver {
    /// Heap bytes of the iterative workspace (the LU factors, when present, are faer's and
    /// not counted).
    /// Drops any preconditioner built from an earlier matrix (see
    /// [`BiCgStabWorkspace::invalidate`]).
    pub fn invalidate_preconditioner(&mut self) {
        self.bicgstab.invalidate();
    }

    pub fn heap_bytes(&self) -> usize {
        self.bicgstab.heap_bytes()
            + self
                .lanes
                .iter()
                .map(bicgstab::Vectors::heap_bytes)
                .sum::<usize>()
            + self.lane_scratch.heap_bytes()
            + self
                .lane_guesses
                .iter()
                .map(|v| v.capacity() * 8)
                .sum::<usize>()
    }

    /// Number of LU factorisations computed so far (reuse shows as solves without one).
    pub fn factorisations(&self) -> usize {
        self.factorisations
    }

    fn direct(
        &mut self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolverOptions,
    ) -> Result<(), SolveError> {
        let reusable = options.matrix_unchanged
            && self
                .factorisation
                .as_ref()
                .is_some_and(|f| f.fits(b.len(), options.null_space));
        if !reusable {
            self.factorisation = None;
            self.factorisation = Some(lu::Factorisation::new(a, options.null_space)?);
            self.factorisations += 1;
        }
        match &self.factorisation {
            Some(f) => f.solve(b, x),
            None => Err(SolveError::Lu("no factorisation".into())),
        }
    }
}

#[cfg(test)]
mod tests;
