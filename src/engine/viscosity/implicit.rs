//! Implicit solvent (and EVSS) viscosity: the (β + α_V)η0∇²u term of the predictor (24)
//! taken at the new time level,
//!
//! ```text
//!     (I − δt ν L) u* = u^n + δt [u_ps·∇u^n + ∇·Φ/ρ + g],    ν = (β + α_V)η0/ρ,
//! ```
//!
//! with L the Morris Laplacian (21) and the wall mirrors' no-slip values u_j = −u_i folded
//! into the matrix (a moving wall's part b_j of u_j = −u_i + b_j goes to the right-hand side). The velocity components share the matrix; each is solved by
//! warm-started BiCGStab from u^n plus the previous step's u* − u (sparse-LU fallback), all
//! in lock-step where Jacobi preconditions them, so that each pass over the matrix serves
//! every component (`Solver::solve_many`; the products are memory-bound). The matrix is diagonally dominant
//! (an M-matrix in full support), so the solve is cheap, and δt is freed from the viscous
//! limit ρh²/η0 of (28): see [`super::Viscosity::dt_limit`].

use crate::engine::boundary::Field;
use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::laplacian_matrix::{LaplacianMatrix, Operator};
use crate::engine::neighbourhood::Hood;
use rheosph_solver::{NullSpace, Preconditioner, SolveError, SolveReport, SolverOptions, Strategy};

/// δt ν of an implicit viscous solve and the variable viscosity's factor φ (fluid then
/// ghosts; empty: uniform).
#[derive(Clone, Copy)]
pub struct Diffusion<'a> {
    pub nu_dt: f64,
    pub factor: &'a [f64],
}

/// Where an implicit viscous solve stops (the relative residual) and how it is
/// preconditioned.
#[derive(Clone, Copy)]
pub struct Accuracy {
    pub tolerance: f64,
    pub preconditioner: Preconditioner,
}

/// Reusable matrix and component buffers of the implicit viscous solve.
pub struct ImplicitViscosity<const D: usize = 2> {
    matrix: LaplacianMatrix,
    /// The right-hand side and the solution, one vector per component.
    rhs: [Vec<f64>; D],
    component: [Vec<f64>; D],
    /// u* − u^n of the previous step, per particle (empty: none, e.g. after a reorder).
    increment: Vec<Vector<D>>,
    /// Moving walls: the mirrors' offsets (extended) and their Laplacian.
    offsets: Vec<Vector<D>>,
    wall_term: Vec<Vector<D>>,
}

impl<const D: usize> Default for ImplicitViscosity<D> {
    fn default() -> Self {
        Self {
            matrix: LaplacianMatrix::default(),
            rhs: std::array::from_fn(|_| Vec::new()),
            component: std::array::from_fn(|_| Vec::new()),
            increment: Vec::new(),
            offsets: Vec::new(),
            wall_term: Vec::new(),
        }
    }
}

impl<const D: usize> ImplicitViscosity<D>
where
    Dim<D>: Dimension<D>,
{
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        self.matrix.heap_bytes()
            + self.rhs.iter().map(crate::engine::vec_bytes).sum::<usize>()
            + self
                .component
                .iter()
                .map(crate::engine::vec_bytes)
                .sum::<usize>()
            + crate::engine::vec_bytes(&self.increment)
            + crate::engine::vec_bytes(&self.offsets)
            + crate::engine::vec_bytes(&self.wall_term)
    }

    /// Moving walls: the mirrors' u_j = −u_i + b_j leave δtν Σ_j L_ij b_j over, which joins
    /// the right-hand side (the Laplacian of the field that is b on the mirrors and 0 on the
    /// fluid, with the explicit operator's weights, which the matrix shares). A continued
    /// ghost's b is the wall velocity's part of its stencil ([`Ghosts::extend_offsets`]); the
    /// matrix holds the rest, so the step is implicit in the continuation as in the mirror.
    fn add_wall_term(
        &mut self,
        hood: Hood<D>,
        nu_dt: f64,
        rhs: &mut [Vector<D>],
        prescribed: &[bool],
        factor: &[f64],
    ) {
        let Hood { list, sums, ghosts } = hood;
        if !ghosts.has_offsets() {
            return;
        }
        let n = rhs.len();
        ghosts.extend_offsets(n, &mut self.offsets);
        self.wall_term.resize(n, Vector::<D>::zeros());
        if factor.is_empty() {
            sums.laplacian_vector(list, &self.offsets, &mut self.wall_term);
        } else {
            sums.variable_laplacian_vector(list, &self.offsets, factor, &mut self.wall_term);
        }
        for (i, (u, w)) in rhs.iter_mut().zip(&self.wall_term).enumerate() {
            if !prescribed.get(i).copied().unwrap_or(false) {
                *u += nu_dt * w;
            }
        }
    }

    /// Drops the solver's preconditioner and the previous step's increment (indices changed,
    /// or a checkpoint was written that does not carry them).
    pub fn invalidate_preconditioner(&mut self) {
        self.matrix.invalidate_preconditioner();
        self.increment.clear();
    }

    /// Solves `(I − δt ν φ L) u* = rhs` for u* given the explicit part `rhs` (`velocity`,
    /// overwritten with u*). Rows flagged in `prescribed` (empty: none) keep their value
    /// (inflow particles). Returns the reports of the solves, one per component.
    pub fn solve(
        &mut self,
        hood: Hood<D>,
        diffusion: Diffusion,
        warm_start: &[Vector<D>],
        velocity: &mut [Vector<D>],
        prescribed: &[bool],
        accuracy: Accuracy,
    ) -> Result<[SolveReport; D], SolveError> {
        let Diffusion { nu_dt, factor } = diffusion;
        let Accuracy {
            tolerance,
            preconditioner,
        } = accuracy;
        let op = Operator {
            field: Field::Velocity,
            d: 1.0,
            c: -nu_dt,
            factor,
        };
        self.matrix.assemble(hood, op, prescribed);
        self.add_wall_term(hood, nu_dt, velocity, prescribed, factor);
        let options = SolverOptions {
            relative_tolerance: tolerance,
            absolute_tolerance: 0.0,
            max_iterations: 500,
            null_space: NullSpace::None,
            strategy: Strategy::IterativeWithFallback,
            matrix_unchanged: false,
            preconditioner,
        };
        for (axis, (rhs, component)) in self.rhs.iter_mut().zip(&mut self.component).enumerate() {
            rhs.clear();
            rhs.extend(velocity.iter().map(|u| u[axis]));
            // The guess u^n + (u* − u)^{n−1}: in a steady flow u* − u^n = δt∇p/ρ (standard
            // projection) is steady too, and the guess is then nearly the solution.
            component.clear();
            if self.increment.len() == warm_start.len() {
                let guess = warm_start.iter().zip(&self.increment);
                component.extend(guess.map(|(u, d)| u[axis] + d[axis]));
            } else {
                component.extend(warm_start.iter().map(|u| u[axis]));
            }
        }
        // The components share the matrix (and an AMG hierarchy or LU factors), and where
        // Jacobi serves, each pass over it.
        let rhs = self.rhs.each_ref().map(Vec::as_slice);
        let component = self.component.each_mut().map(Vec::as_mut_slice);
        let reports = self.matrix.solve_many(rhs, component, &options)?;
        for (axis, component) in self.component.iter().enumerate() {
            for (u, c) in velocity.iter_mut().zip(component) {
                u[axis] = *c;
            }
        }
        self.increment.clear();
        let increment = velocity.iter().zip(warm_start).map(|(s, u)| *s - *u);
        self.increment.extend(increment);
        Ok(reports)
    }
}
