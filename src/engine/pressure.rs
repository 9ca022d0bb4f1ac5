//! The pressure Poisson equation (25), `∇·(∇p/ρ) = ∇·u*/δt`, assembled every step (when the
//! particles moved) as a CSR matrix and handed to `rheosph-solver`.
//!
//! Row i discretises `−∇²p/ρ` with the Laplacian (21), `Σ_j c_ij (p_i − p_j) = −(∇·u*)_i/δt`,
//! `c_ij = −2 (r_ij·∇Ŵ_ij)/(ρ|r_ij|²) δV` (positive in full support). A wall mirror's pressure
//! is its parent's (homogeneous Neumann), so its coefficient joins the parent's column; a
//! particle's own mirror cancels out. Rows sum to zero: on a closed domain the matrix is
//! singular with the constant null space, which the solver removes (zero-mean pressure).
//!
//! With a free surface, the rows of FS particles become `p_i = p_D,i`, the inhomogeneous
//! Dirichlet condition of the normal-stress balance (35a) (or p = 0); the matrix is then
//! non-singular and non-symmetric (BiCGStab does not need symmetry).

use crate::engine::boundary::Ghosts;
use crate::engine::laplacian_matrix::{LaplacianMatrix, MirrorRule};
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use rheosph_solver::{SolveError, SolveReport, SolverOptions};

/// The PPE matrix, its right-hand side, and the solver.
#[derive(Default)]
pub struct PressureSystem {
    matrix: LaplacianMatrix,
    rhs: Vec<f64>,
}

impl PressureSystem {
    /// Heap bytes held (matrix, right-hand side, solver workspace).
    pub fn heap_bytes(&self) -> usize {
        self.matrix.heap_bytes() + crate::engine::vec_bytes(&self.rhs)
    }

    pub fn new() -> Self {
        Self::default()
    }

    /// The right-hand side `−∇·u*/δt`, with `dirichlet[i]` in the rows flagged in
    /// `surface` (both empty without a free surface).
    pub fn assemble_rhs(
        &mut self,
        divergence: &[f64],
        dt: f64,
        surface: &[bool],
        dirichlet: &[f64],
    ) {
        self.rhs.clear();
        self.rhs.extend(divergence.iter().map(|d| -d / dt));
        for (i, _) in surface.iter().enumerate().filter(|(_, &s)| s) {
            self.rhs[i] = dirichlet[i];
        }
    }

    /// Assembles the matrix `−∇²/ρ` for the fluid particles, with identity (Dirichlet) rows
    /// for the particles flagged in `surface` (empty: none).
    pub fn assemble_matrix(
        &mut self,
        list: &NeighbourList,
        sums: &KernelSums,
        ghosts: &Ghosts,
        density: f64,
        surface: &[bool],
    ) {
        self.matrix.assemble(
            list,
            sums,
            ghosts,
            MirrorRule::Even,
            0.0,
            -1.0 / density,
            surface,
        );
    }

    /// Number of stored matrix entries of the last assembly.
    pub fn nnz(&self) -> usize {
        self.matrix.nnz()
    }

    /// LU factorisations computed so far.
    pub fn factorisations(&self) -> usize {
        self.matrix.factorisations()
    }

    /// Solves the assembled system; `pressure` is the warm start on entry.
    pub fn solve(
        &mut self,
        pressure: &mut [f64],
        options: &SolverOptions,
    ) -> Result<SolveReport, SolveError> {
        self.matrix.solve(&self.rhs, pressure, options)
    }
}
