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
//! non-singular and non-symmetric (BiCGStab does not need symmetry). Under a blended surface
//! indicator a particle on (36)'s ramp takes a row between the two,
//! `(1 − s)·(Poisson row) + s·D_i·(p_i − p_D,i) = 0` with D_i its Poisson row's diagonal
//! ([`SurfaceRows::blended`]).

use crate::engine::boundary::Field;
use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::frame::Frame;
use crate::engine::laplacian_matrix::{LaplacianMatrix, Operator};
use crate::engine::neighbourhood::Hood;
use crate::engine::operators::PpeLaplacian;
use crate::engine::settings::{in_range, positive, Invalid};
use crate::engine::state::Scales;
use crate::engine::volume::{RowSupport, VolumeRelaxation};
use rayon::prelude::*;
use rheosph_solver::{NullSpace, SolveError, SolveReport, SolverOptions, Strategy};
use serde::{Deserialize, Serialize};

/// The free surface's rows of the PPE (all empty without a free surface).
#[derive(Clone, Copy, Debug, Default)]
pub struct SurfaceRows<'a> {
    /// Rows replaced by the Dirichlet row `p_i = p_D,i`.
    pub dirichlet: &'a [bool],
    /// p_D of every row (zero off the surface), already shifted to the PPE's unknown.
    pub values: &'a [f64],
    /// Rows `(i, s)` that are s times a Dirichlet row scaled by their Poisson diagonal and
    /// (1 − s) times their Poisson row, 0 < s < 1 (a blended surface indicator).
    pub blended: &'a [(usize, f64)],
}

impl SurfaceRows<'_> {
    /// Whether any row pins the pressure's level (otherwise it is defined up to a constant).
    pub fn pin_level(&self) -> bool {
        !self.blended.is_empty() || self.dirichlet.iter().any(|&r| r)
    }
}

/// The PPE matrix, its right-hand side, and the solver.
#[derive(Default)]
pub struct PressureSystem {
    matrix: LaplacianMatrix,
    rhs: Vec<f64>,
    /// The blended rows of the last assembly: `(i, s, D_i)` with D_i the diagonal of row i's
    /// Poisson row.
    blended: Vec<(usize, f64, f64)>,
}

impl PressureSystem {
    /// Heap bytes held (matrix, right-hand side, solver workspace).
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        self.matrix.heap_bytes() + b(&self.rhs) + b(&self.blended)
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
    pub fn assemble_matrix<const D: usize>(&mut self, hood: Hood<D>, density: f64, surface: &[bool])
    where
        Dim<D>: Dimension<D>,
    {
        let op = Operator {
            field: Field::Pressure,
            d: 0.0,
            c: -1.0 / density,
            factor: &[],
        };
        self.matrix.assemble(hood, op, surface);
    }

    /// After [`Self::assemble_matrix`], which gave the `blended` rows Poisson rows: each
    /// becomes `(1 − s)·(Poisson row) + s·D_i·e_i` ([`SurfaceRows::blended`]).
    pub fn blend_matrix_rows(&mut self, blended: &[(usize, f64)]) {
        self.blended.clear();
        for &(i, s) in blended {
            let diagonal = self.matrix.blend_with_identity(i, s);
            self.blended.push((i, s, diagonal));
        }
    }

    /// After the right-hand side is complete: a blended row's becomes
    /// `(1 − s)·b_i + s·D_i·p_D,i` (`values`: p_D of every row).
    pub fn blend_rhs_rows(&mut self, values: &[f64]) {
        for &(i, s, diagonal) in &self.blended {
            self.rhs[i] = (1.0 - s) * self.rhs[i] + s * diagonal * values[i];
        }
    }

    /// Number of stored matrix entries of the last assembly.
    pub fn nnz(&self) -> usize {
        self.matrix.nnz()
    }

    /// A copy of the last assembled matrix and right-hand side (for benchmarks).
    pub fn system(&self) -> (sprs::CsMat<f64>, Vec<f64>) {
        (self.matrix.to_csr(), self.rhs.clone())
    }

    /// LU factorisations computed so far.
    pub fn factorisations(&self) -> usize {
        self.matrix.factorisations()
    }

    /// Drops the solver's preconditioner.
    pub fn invalidate_preconditioner(&mut self) {
        self.matrix.invalidate_preconditioner();
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

/// Steps 5 and 6: the PPE of one step and the projection of u* with its solution, in D
/// dimensions (the default 2).
pub struct PressureStage<const D: usize = 2> {
    system: PressureSystem,
    settings: PpeSettings,
    strategy: Strategy,
    /// u* followed by the ghosts' values.
    velocity_ext: Vec<Vector<D>>,
    divergence: Vec<f64>,
    pressure_ext: Vec<f64>,
    gradient: Vec<Vector<D>>,
    /// The matrix must be reassembled (the particle configuration changed).
    matrix_stale: bool,
    /// The density-invariant source, if chosen.
    volume: Option<VolumeRelaxation>,
}

impl<const D: usize> PressureStage<D>
where
    Dim<D>: Dimension<D>,
{
    pub fn new(settings: PpeSettings, frame: Frame, volume: Option<VolumeRelaxation>) -> Self {
        Self {
            system: PressureSystem::new(),
            settings,
            strategy: settings.solver.strategy(frame, D),
            velocity_ext: Vec::new(),
            divergence: Vec::new(),
            pressure_ext: Vec::new(),
            gradient: Vec::new(),
            matrix_stale: false,
            volume,
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        self.system.heap_bytes()
            + b(&self.velocity_ext)
            + b(&self.divergence)
            + b(&self.pressure_ext)
            + b(&self.gradient)
    }

    /// With a [`VolumeRelaxation`], after [`Self::assemble`]: the density-invariant source in
    /// the rows with a full support (`support`: outside the free surface's FS and NS).
    pub fn relax_volume(
        &mut self,
        hood: Hood<D>,
        support: impl Fn(usize) -> RowSupport + Sync,
        dt: f64,
    ) {
        let Some(volume) = self.volume else {
            return;
        };
        volume.add_source(hood, support, dt, &mut self.system.rhs);
    }

    /// The particle configuration changed: the matrix (and any LU factors) must be rebuilt.
    pub fn configuration_changed(&mut self) {
        self.matrix_stale = true;
    }

    /// Step 5: ∇·u* (negative form of (20)), with u* extended to the ghosts.
    pub fn divergence(&mut self, hood: Hood<D>, velocity_star: &[Vector<D>]) {
        let Hood { list, sums, ghosts } = hood;
        ghosts.continue_velocity(velocity_star, &mut self.velocity_ext);
        self.divergence.resize(velocity_star.len(), 0.0);
        sums.divergence(list, &self.velocity_ext, &mut self.divergence);
    }

    /// The PPE's divergence of the last [`Self::divergence`], for terms that add to it (the
    /// incremental projection's stabilisation).
    pub fn divergence_mut(&mut self) -> &mut [f64] {
        &mut self.divergence
    }

    /// u* followed by the ghosts' values, after [`Self::divergence`].
    pub fn velocity_star_ext(&self) -> &[Vector<D>] {
        &self.velocity_ext
    }

    /// Step 5: the matrix (when the particles moved, or a row is blended) and the right-hand
    /// side, with the free surface's `rows`.
    pub fn assemble(&mut self, hood: Hood<D>, density: f64, dt: f64, rows: SurfaceRows) {
        // A blended row's weight changes with (36)'s margin even where the particles
        // stand still (an Eulerian frame), and so does a row that was blended last step.
        if !rows.blended.is_empty() || !self.system.blended.is_empty() {
            self.matrix_stale = true;
        }
        if self.matrix_stale {
            let system = &mut self.system;
            system.assemble_matrix(hood, density, rows.dirichlet);
            system.blend_matrix_rows(rows.blended);
        }
        let system = &mut self.system;
        system.assemble_rhs(&self.divergence, dt, rows.dirichlet, rows.values);
        system.blend_rhs_rows(rows.values);
    }

    /// Step 5: solves for `unknown` (its initial guess on entry). `dirichlet`: some rows are
    /// Dirichlet rows (otherwise the pressure is defined up to a constant).
    pub fn solve(
        &mut self,
        unknown: &mut [f64],
        dirichlet: bool,
        scales: &Scales,
        dt: f64,
    ) -> Result<SolveReport, SolveError> {
        let n = unknown.len();
        let s = &self.settings;
        let options = SolverOptions {
            relative_tolerance: s.tolerance,
            // The residual is (∇·u^{n+1})/δt per particle: stop at an r.m.s. divergence of
            // divergence_tolerance·U/L (this also ends solves of round-off-level right-hand
            // sides, e.g. a fluid at rest).
            absolute_tolerance: s.divergence_tolerance * (n as f64).sqrt() * scales.velocity
                / (scales.length * dt),
            max_iterations: s.max_iterations,
            null_space: if dirichlet {
                NullSpace::None
            } else {
                NullSpace::Constant
            },
            strategy: self.strategy,
            matrix_unchanged: !std::mem::replace(&mut self.matrix_stale, false),
            preconditioner: s.preconditioner.resolve(),
        };
        self.system.solve(unknown, &options)
    }

    /// Step 6, eq. (26): u* −= (δt/ρ)∇φ, φ the solved field (p^{n+1} or its increment).
    pub fn project(
        &mut self,
        hood: Hood<D>,
        solved: &[f64],
        dt_over_rho: f64,
        velocity_star: &mut [Vector<D>],
    ) {
        let Hood { list, sums, ghosts } = hood;
        ghosts.extend_pressure(solved, &mut self.pressure_ext);
        self.gradient
            .resize(velocity_star.len(), Vector::<D>::zeros());
        sums.gradient_scalar(list, &self.pressure_ext, &mut self.gradient);
        velocity_star
            .par_iter_mut()
            .zip(self.gradient.par_iter())
            .for_each(|(u, gp)| *u -= dt_over_rho * gp);
    }

    /// Stored PPE entries of the last assembly.
    pub fn nnz(&self) -> usize {
        self.system.nnz()
    }

    /// Drops the solver's preconditioner.
    pub fn invalidate_preconditioner(&mut self) {
        self.system.invalidate_preconditioner();
    }

    /// LU factorisations so far.
    pub fn factorisations(&self) -> usize {
        self.system.factorisations()
    }
}

/// `[scheme.ppe]`: how the PPE (25) is built and solved.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PpeSettings {
    /// `auto` (sparse LU for fixed particles in 2D, BiCGStab with an LU fallback when they
    /// move and in 3D), `bicgstab` or `lu`.
    pub solver: PpeSolver,
    /// BiCGStab's preconditioner, here and in the implicit viscous solve: `auto`, `jacobi` or
    /// `amg`.
    pub preconditioner: PreconditionerChoice,
    /// Relative residual ‖b − Ap‖/‖b‖ at which BiCGStab stops.
    pub tolerance: f64,
    /// Or the r.m.s. divergence (in units of U/H) the residual corresponds to, whichever is
    /// reached first: ‖b − Ap‖ ≤ this · √n · (U/H)/δt.
    pub divergence_tolerance: f64,
    /// BiCGStab iteration budget before the sparse-LU fallback.
    pub max_iterations: usize,
    /// Start BiCGStab from the previous step's pressure (true) or from zero.
    pub warm_start: bool,
    /// α of the density-invariant source, the fraction of a particle's concentration error
    /// the projection removes per step (0: off, the paper's projection;
    /// [`crate::engine::volume`]).
    /// Read from `[experimental]` (`setup::experimental`), not from this table.
    #[serde(skip)]
    pub volume_relaxation: f64,
    /// `standard` (the Laplacian of `scheme.operators.laplacian`) or `linear-exact` (made
    /// exact for linear fields where the support is truncated): the PPE's Laplacian.
    /// Read from `[experimental]` (`setup::experimental`), not from this table.
    #[serde(skip)]
    pub laplacian: PpeLaplacian,
}

impl Default for PpeSettings {
    fn default() -> Self {
        Self {
            solver: PpeSolver::Auto,
            preconditioner: PreconditionerChoice::Auto,
            tolerance: 1e-8,
            // Chosen by its effect on the L2 error: from 1e-10 to 1e-6 the time-mean velocity
            // error changes by < 1 % (relative) on Poiseuille (H/δr = 30, 11.6 → 0.27
            // BiCGStab iterations per step) and Taylor–Green (N = 50, 40 → 16); at 1e-3 the
            // Poiseuille error starts to grow (+0.5 %). Two decades of margin.
            divergence_tolerance: 1e-6,
            max_iterations: 1000,
            warm_start: true,
            volume_relaxation: 0.0,
            laplacian: PpeLaplacian::Standard,
        }
    }
}

impl PpeSettings {
    /// The table's own checks (keys relative to `[scheme.ppe]`).
    pub fn validate(&self) -> Result<(), Invalid> {
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            let got = self.tolerance;
            return Err(Invalid::new(
                "tolerance",
                format!("must be in (0, 1), got {got}"),
            ));
        }
        positive("divergence_tolerance", self.divergence_tolerance)?;
        if self.max_iterations == 0 {
            return Err(Invalid::new("max_iterations", "must be at least 1"));
        }
        in_range("volume_relaxation", self.volume_relaxation, 0.0, 1.0)?;
        Ok(())
    }
}

/// BiCGStab's preconditioner.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PreconditionerChoice {
    /// Jacobi, turning to AMG within a solve that Jacobi does not finish in 40 iterations
    /// (see the validation pages' speed section).
    Auto,
    Jacobi,
    Amg,
}

impl PreconditionerChoice {
    /// The solver crate's preconditioner.
    pub fn resolve(self) -> rheosph_solver::Preconditioner {
        match self {
            PreconditionerChoice::Auto => rheosph_solver::Preconditioner::Adaptive,
            PreconditionerChoice::Jacobi => rheosph_solver::Preconditioner::Jacobi,
            PreconditionerChoice::Amg => rheosph_solver::Preconditioner::Amg,
        }
    }
}

/// Which linear solver the PPE uses.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PpeSolver {
    /// Sparse LU, factorised once, for fixed particles (Eulerian) in 2D; warm-started
    /// BiCGStab with LU fallback when the matrix changes every step (Lagrangian), and in 3D,
    /// where the factors fill in: at 15k particles (the sphere array, a/δr = 8) the
    /// factorisation took 70 s, the 31 BiCGStab solves of the same 32 steps 8 s.
    Auto,
    Bicgstab,
    Lu,
}

impl PpeSolver {
    /// The solver strategy in a frame, in `dimension`s.
    pub fn strategy(self, frame: Frame, dimension: usize) -> rheosph_solver::Strategy {
        let plane = dimension == 2;
        match (self, frame) {
            (PpeSolver::Lu, _) => rheosph_solver::Strategy::Direct,
            (PpeSolver::Auto, Frame::Eulerian) if plane => rheosph_solver::Strategy::Direct,
            _ => rheosph_solver::Strategy::IterativeWithFallback,
        }
    }
}
