//! One projection time step of King & Lind (2021), Steps 1–7, eqs. (23)–(28), in ALE form.
//!
//! State at the start of step n: positions r^n, velocity u^n, pressure p^n and the
//! conformation A^{n−1/2} (stress lives at half steps, §III B). The step:
//!
//! 1. (Lagrangian) advect to r* = r^n + δt u^n, eq. (23).
//! 2. Mirrors, neighbour lists, Bonet–Lok L_i at r*; ∇u^n; shifting velocity u_ps
//!    (Lagrangian: Fickian, eqs. (40)–(42); Eulerian: u_ps = −u^n).
//! 3. Conformation to n+½ (log-conformation (29)–(32) or direct), τ_p, EVSS Φ, eq. (6).
//! 4. Predictor (24): u* = u^n + δt[u_ps·∇u^n + (β+α_V)η0/ρ ∇²u^n + ∇·Φ/ρ + g].
//! 5. PPE (25) for p^{n+1}.
//! 6. Projection (26): u^{n+1} = u* − (δt/ρ)∇p^{n+1} (the δt is implied by (25)).
//! 7. (Lagrangian) r^{n+1} = r^n + δt/2 (u^n + u^{n+1} + 2u_ps), eq. (27).
//!
//! δt follows (28). A stage the scene does not need costs nothing: a Newtonian fluid has no
//! conformation, an Eulerian run builds its neighbour lists once.

use crate::engine::boundary::inflow::Inflow;
use crate::engine::boundary::{Ghosts, Surface};
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::{Mat2, Sym2, Vec2};
use crate::engine::neighbours::{Domain, NeighbourList, NeighbourSearch};
use crate::engine::operators::{DivergenceForm, KernelSums};
use crate::engine::pressure::PressureSystem;
use crate::engine::rheology::{self, ConformationScheme, Fluid};
use crate::engine::shifting;
use crate::engine::surface::FreeSurface;
use crate::engine::timing::{Stage, StageSeconds};
use crate::setup::case::{Frame, PpeSolver, Scheme, SurfacePressure, Viscosity};
use rayon::prelude::*;
use rheosph_solver::{NullSpace, SolveReport, SolverOptions, Strategy};

/// Characteristic scales of a scene, for tolerances and breakdown thresholds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales {
    pub length: f64,
    pub velocity: f64,
}

/// Everything needed to start a simulation.
#[derive(Clone, Debug)]
pub struct Setup {
    pub domain: Domain,
    /// No-slip surfaces (walls, cylinders) that create mirror particles.
    pub walls: Vec<Surface>,
    pub positions: Vec<Vec2>,
    /// Initial velocity of each particle.
    pub velocity: Vec<Vec2>,
    pub spacing: f64,
    pub fluid: Fluid,
    pub scheme: Scheme,
    pub body_force: Vec2,
    pub scales: Scales,
    /// Free surfaces: detection and Dirichlet pressure (35a), the free-surface shifting
    /// (40)–(44) and the positive stress divergence (20).
    pub free_surface: bool,
    /// An inflow buffer (jets).
    pub inflow: Option<Inflow>,
}

/// The evolving particle state (fluid particles only, structure of arrays).
#[derive(Clone, Debug, Default)]
pub struct State {
    pub time: f64,
    pub steps: u64,
    /// r^n.
    pub position: Vec<Vec2>,
    /// u^n.
    pub velocity: Vec<Vec2>,
    /// p^n (zero mean on closed domains).
    pub pressure: Vec<f64>,
    /// A^{n−1/2}; empty for a Newtonian fluid.
    pub conformation: Vec<Sym2>,
    /// u_ps of the last step.
    pub shift_velocity: Vec<Vec2>,
}

/// Why a run stopped early.
#[derive(Clone, Debug, PartialEq)]
pub struct Breakdown {
    pub reason: String,
}

/// What one step did.
#[derive(Clone, Copy, Debug)]
pub struct StepReport {
    pub dt: f64,
    pub ppe: SolveReport,
}

/// Per-step work arrays, sized once and reused.
#[derive(Default)]
struct Workspace {
    points: Vec<Vec2>,
    ghosts: Ghosts,
    search: NeighbourSearch,
    list: NeighbourList,
    sums: KernelSums,
    lists_valid: bool,
    /// Point volumes relative to δV (empty: all 1).
    volumes: Vec<f64>,
    /// The PPE matrix must be reassembled (the particle configuration changed).
    matrix_stale: bool,
    reorder: crate::engine::ordering::Reorder,
    velocity_ext: Vec<Vec2>,
    grad_u: Vec<Mat2>,
    grad_c: Vec<Vec2>,
    tensor_ext: Vec<Sym2>,
    log_conformation: Vec<Sym2>,
    advection: Vec<Sym2>,
    phi: Vec<Sym2>,
    div_phi: Vec<Vec2>,
    laplacian: Vec<Vec2>,
    velocity_star: Vec<Vec2>,
    divergence: Vec<f64>,
    pressure_ext: Vec<f64>,
    /// The pressure increment p^{n+1} − p^n of an incremental projection.
    pressure_increment: Vec<f64>,
    grad_p: Vec<Vec2>,
    /// Free-surface sets and normals, the predictor's velocity gradient and the Dirichlet
    /// pressure of FS particles (free-surface scenes only).
    surface: FreeSurface,
    grad_u_star: Vec<Mat2>,
    surface_pressure: Vec<f64>,
    surface_region: Vec<bool>,
    ppe: PressureSystem,
    viscous: crate::engine::viscosity::ImplicitViscosity,
}

/// A running simulation.
pub struct Simulation {
    pub fluid: Fluid,
    pub scheme: Scheme,
    pub kernel: QuinticSpline,
    pub spacing: f64,
    pub domain: Domain,
    pub body_force: Vec2,
    pub scales: Scales,
    pub free_surface: bool,
    /// The inflow buffer of a jet; its flags follow the particle order.
    pub inflow: Option<Inflow>,
    pub state: State,
    pub timers: StageSeconds,
    ws: Workspace,
}

/// Kinetic energy per unit mass above which a run has run away: an r.m.s. speed of 100 U.
const RUNAWAY_SPEED_FACTOR: f64 = 100.0;
/// Relative residual of the implicit viscous solves: well below the O(δt) splitting error.
const VISCOUS_TOLERANCE: f64 = 1e-10;
/// Steps between Morton reorderings of a Lagrangian run: particles move a fraction of δr per
/// step, so locality decays slowly.
pub const REORDER_INTERVAL: u64 = 50;
/// Fewest neighbours (a quarter of a full support's ~48) for which a free-surface particle's
/// velocity gradient, and so its normal-stress pressure (35a), is trusted; sparser ones (a
/// splash, a thread's tip) take p = 0. Measured: the Oldroyd-B jet at Wi = 5/3 broke down at
/// t = 0.30 s after a surface particle with 7 neighbours carried p = 912 Pa from (35a).
const MIN_SURFACE_NEIGHBOURS: usize = 12;
/// tr A beyond which the conformation has run away (polymer stretch ~10⁶ of rest length).
const RUNAWAY_TRACE: f64 = 1e12;

impl Simulation {
    pub fn new(setup: Setup) -> Self {
        let n = setup.positions.len();
        let conformation = if setup.fluid.model.is_viscoelastic() {
            vec![setup.fluid.model.rest_conformation(); n]
        } else {
            Vec::new()
        };
        let mut ghosts = Ghosts::new(setup.walls);
        ghosts.tensor_mirror = setup.scheme.wall_conformation;
        Self {
            kernel: QuinticSpline::for_spacing(setup.spacing),
            fluid: setup.fluid,
            scheme: setup.scheme,
            spacing: setup.spacing,
            domain: setup.domain,
            body_force: setup.body_force,
            scales: setup.scales,
            free_surface: setup.free_surface,
            inflow: setup.inflow,
            state: State {
                time: 0.0,
                steps: 0,
                position: setup.positions,
                velocity: setup.velocity,
                pressure: vec![0.0; n],
                conformation,
                shift_velocity: vec![Vec2::zeros(); n],
            },
            timers: StageSeconds::default(),
            ws: Workspace {
                ghosts,
                ..Default::default()
            },
        }
    }

    pub fn particles(&self) -> usize {
        self.state.position.len()
    }

    /// Particle volume δV = δr².
    pub fn particle_volume(&self) -> f64 {
        self.spacing * self.spacing
    }

    /// The time step. Explicit viscosity: eq. (28), `dt_factor · min(h/max|u|, ρh²/η0)`.
    /// Implicit viscosity: `dt_factor · min(h/max(max|u|, U), h/c)` with
    /// c = √(η_p/(ρλ)) the elastic shear-wave speed (the stress coupling stays explicit) and
    /// U the scene's velocity scale (which bounds the first steps from rest).
    pub fn stable_dt(&self) -> f64 {
        let h = self.kernel.h();
        let max_speed = self
            .state
            .velocity
            .par_iter()
            .map(|u| u.norm())
            .reduce(|| 0.0, f64::max);
        let f = &self.fluid;
        let limit = match self.scheme.viscosity {
            Viscosity::Explicit => {
                let viscous = f.density * h * h / f.viscosity;
                let advective = if max_speed > 0.0 {
                    h / max_speed
                } else {
                    f64::INFINITY
                };
                viscous.min(advective)
            }
            Viscosity::Implicit => {
                let advective = h / max_speed.max(self.scales.velocity);
                let elastic = if f.model.is_viscoelastic() && f.polymer_viscosity() > 0.0 {
                    h / (f.polymer_viscosity() / (f.density * f.relaxation_time)).sqrt()
                } else {
                    f64::INFINITY
                };
                advective.min(elastic)
            }
        };
        self.scheme.dt_factor * limit
    }

    /// Sorts the fluid particles along a Morton curve of their cells (see
    /// [`crate::engine::ordering`]). Lagrangian runs do this every [`REORDER_INTERVAL`] steps,
    /// Eulerian runs once.
    pub fn reorder(&mut self) {
        let t0 = std::time::Instant::now();
        let cell = self.kernel.support();
        let ws = &mut self.ws;
        let s = &mut self.state;
        if ws.reorder.compute(&self.domain, &s.position, cell) {
            ws.reorder.apply_vec2(&mut s.position);
            ws.reorder.apply_vec2(&mut s.velocity);
            ws.reorder.apply_vec2(&mut s.shift_velocity);
            ws.reorder.apply_scalar(&mut s.pressure);
            ws.reorder.apply_sym(&mut s.conformation);
            if let Some(inflow) = self.inflow.as_mut() {
                ws.reorder.apply_bool(&mut inflow.flags);
            }
            ws.lists_valid = false;
        }
        self.timers
            .add(Stage::Neighbours, t0.elapsed().as_secs_f64());
    }

    /// Replaces the state with a restored one and marks the caches derived from the particle
    /// configuration (neighbour lists, kernel sums, PPE matrix and LU factors) for rebuilding.
    /// The last step's velocity gradient is dropped, as before a first step.
    pub fn restore_state(&mut self, state: State) {
        self.state = state;
        self.ws.lists_valid = false;
        self.ws.matrix_stale = true;
        self.ws.grad_u.clear();
    }

    /// Advances one step of at most `dt_max`.
    pub fn step(&mut self, dt_max: f64) -> Result<StepReport, Breakdown> {
        let due = match self.scheme.frame {
            Frame::Lagrangian => self.state.steps % REORDER_INTERVAL == 0,
            Frame::Eulerian => self.state.steps == 0,
        };
        if due && self.scheme.reorder {
            self.reorder();
        }
        let dt = self.stable_dt().min(dt_max);
        let n = self.particles();
        let lagrangian = self.scheme.frame == Frame::Lagrangian;
        let Self {
            fluid,
            scheme,
            kernel,
            spacing,
            domain,
            body_force,
            scales,
            free_surface,
            inflow,
            state,
            timers,
            ws,
        } = self;
        let free_surface = *free_surface;
        let buffer: &[bool] = inflow.as_ref().map_or(&[], |b| &b.flags);
        let prescribed = inflow.as_ref().map_or(Vec2::zeros(), |b| b.velocity);

        // Step 1: intermediate positions r*.
        timers.time(Stage::Advection, || {
            ws.points.clear();
            if lagrangian {
                ws.points.extend(
                    state
                        .position
                        .iter()
                        .zip(&state.velocity)
                        .map(|(r, u)| domain.wrap(r + dt * u)),
                );
            } else {
                ws.points.extend_from_slice(&state.position);
            }
        });

        // Step 2: mirrors, neighbours, kernel sums (once for fixed particles).
        timers.time(Stage::Neighbours, || {
            if lagrangian || !ws.lists_valid {
                ws.ghosts.build(kernel.support(), &mut ws.points);
                ws.search
                    .build(domain, &ws.points, n, kernel.support(), &mut ws.list);
                if ws.ghosts.has_volume_ratios() {
                    ws.ghosts.point_volumes(n, &mut ws.volumes);
                } else {
                    ws.volumes.clear();
                }
                ws.sums
                    .update_with_volumes(&ws.list, kernel, *spacing * *spacing, &ws.volumes);
                ws.lists_valid = true;
                ws.matrix_stale = true;
            }
        });

        // Step 2: ∇u^n, the free surface (36)–(39) and the shifting velocity.
        timers.time(Stage::Kinematics, || {
            if free_surface {
                ws.surface.detect(&ws.list, &ws.sums, kernel);
                // Inflow buffer particles take Dirichlet rows (p = 0) and are not near the
                // surface themselves.
                for i in buffered(buffer) {
                    ws.surface.on_surface[i] = true;
                    ws.surface.near_surface[i] = false;
                }
            }
            ws.ghosts
                .extend_velocity(&state.velocity, &mut ws.velocity_ext);
            ws.grad_u.resize(n, Mat2::zeros());
            ws.sums
                .gradient_vector(&ws.list, &ws.velocity_ext, &mut ws.grad_u);
            let u_ps = &mut state.shift_velocity;
            match (scheme.frame, scheme.shifting) {
                (Frame::Eulerian, _) => {
                    u_ps.par_iter_mut()
                        .zip(state.velocity.par_iter())
                        .for_each(|(s, u)| *s = -u);
                }
                (Frame::Lagrangian, true) => {
                    ws.grad_c.resize(n, Vec2::zeros());
                    shifting::concentration_gradient(
                        &ws.list,
                        &ws.sums,
                        kernel,
                        *spacing,
                        &mut ws.grad_c,
                    );
                    if free_surface {
                        if scheme.surface_repulsion {
                            shifting::add_repulsion(
                                &ws.list,
                                kernel,
                                &ws.surface.on_surface,
                                &mut ws.grad_c,
                            );
                        }
                        ws.surface.region(&mut ws.surface_region);
                        shifting::free_surface_shifting_velocity(
                            &ws.grad_c,
                            &state.velocity,
                            &ws.surface_region,
                            &ws.surface.normal,
                            kernel.h(),
                            dt,
                            u_ps,
                        );
                        shifting::keep_off_walls(
                            &ws.points[..n],
                            &ws.ghosts.surfaces,
                            &ws.surface_region,
                            kernel.support(),
                            u_ps,
                        );
                    } else {
                        shifting::internal_shifting_velocity(&ws.grad_c, kernel.h(), dt, u_ps);
                    }
                }
                (Frame::Lagrangian, false) => u_ps.iter_mut().for_each(|s| *s = Vec2::zeros()),
            }
            for i in buffered(buffer) {
                u_ps[i] = Vec2::zeros();
            }
        });

        // Step 3: conformation to n + 1/2, polymer stress, EVSS Φ and its divergence.
        let viscoelastic = fluid.model.is_viscoelastic();
        if viscoelastic {
            timers.time(Stage::Constitutive, || {
                let form = if free_surface {
                    DivergenceForm::Positive
                } else {
                    DivergenceForm::Negative
                };
                constitutive_update(fluid, scheme, dt, form, state, ws);
            });
        }

        // Step 4: predictor u*, eq. (24): the viscous term explicit, or implicit (see
        // `viscosity`) with the rest of (24) as its right-hand side.
        let implicit = scheme.viscosity == Viscosity::Implicit;
        let nu = if viscoelastic {
            (fluid.beta + scheme.evss_alpha) * fluid.viscosity / fluid.density
        } else {
            fluid.viscosity / fluid.density
        };
        timers.time(Stage::Predictor, || {
            ws.laplacian.resize(n, Vec2::zeros());
            if !implicit {
                ws.sums
                    .laplacian_vector(&ws.list, &ws.velocity_ext, &mut ws.laplacian);
            }
            let inv_rho = 1.0 / fluid.density;
            let g = *body_force;
            ws.velocity_star.resize(n, Vec2::zeros());
            let (grad_u, lap, div_phi) = (&ws.grad_u, &ws.laplacian, &ws.div_phi);
            let u_ps = &state.shift_velocity;
            let explicit_nu = if implicit { 0.0 } else { nu };
            // Incremental projection: −∇p^n/ρ in the predictor (zero otherwise).
            ws.grad_p.resize(n, Vec2::zeros());
            if scheme.incremental_projection {
                ws.ghosts
                    .extend_scalar(&state.pressure, &mut ws.pressure_ext);
                ws.sums
                    .gradient_scalar(&ws.list, &ws.pressure_ext, &mut ws.grad_p);
            }
            let old_grad_p = &ws.grad_p;
            let pressure_factor = if scheme.incremental_projection {
                inv_rho
            } else {
                0.0
            };
            ws.velocity_star
                .par_iter_mut()
                .zip(state.velocity.par_iter())
                .enumerate()
                .for_each(|(i, (us, u))| {
                    let stress = if viscoelastic {
                        div_phi[i] * inv_rho
                    } else {
                        Vec2::zeros()
                    };
                    *us = u + dt
                        * (grad_u[i] * u_ps[i] + explicit_nu * lap[i] + stress + g
                            - pressure_factor * old_grad_p[i]);
                });
        });
        if implicit {
            timers
                .time(Stage::Viscous, || {
                    for i in buffered(buffer) {
                        ws.velocity_star[i] = prescribed;
                    }
                    ws.viscous.solve(
                        &ws.list,
                        &ws.sums,
                        &ws.ghosts,
                        nu * dt,
                        &state.velocity,
                        &mut ws.velocity_star,
                        buffer,
                        VISCOUS_TOLERANCE,
                    )
                })
                .map_err(|e| Breakdown {
                    reason: format!("implicit viscous solve failed: {e}"),
                })?;
        }

        // Step 5: pressure Poisson equation.
        timers.time(Stage::PpeAssembly, || {
            ws.ghosts
                .extend_velocity(&ws.velocity_star, &mut ws.velocity_ext);
            ws.divergence.resize(n, 0.0);
            ws.sums
                .divergence(&ws.list, &ws.velocity_ext, &mut ws.divergence);
            if free_surface {
                surface_pressure(fluid, scheme, state, buffer, ws);
            }
            let fs: &[bool] = if free_surface {
                &ws.surface.on_surface
            } else {
                &[]
            };
            if ws.matrix_stale {
                ws.ppe
                    .assemble_matrix(&ws.list, &ws.sums, &ws.ghosts, fluid.density, fs);
            }
            ws.ppe
                .assemble_rhs(&ws.divergence, dt, fs, &ws.surface_pressure);
        });
        let dirichlet = free_surface && ws.surface.on_surface.iter().any(|&s| s);
        let matrix_unchanged = !std::mem::replace(&mut ws.matrix_stale, false);
        let options = SolverOptions {
            relative_tolerance: scheme.ppe_tolerance,
            // The residual is (∇·u^{n+1})/δt per particle: stop at an r.m.s. divergence of
            // ppe_divergence_tolerance·U/L (this also ends solves of round-off-level
            // right-hand sides, e.g. a fluid at rest).
            absolute_tolerance: scheme.ppe_divergence_tolerance
                * (n as f64).sqrt()
                * scales.velocity
                / (scales.length * dt),
            max_iterations: scheme.ppe_max_iterations,
            null_space: if dirichlet {
                NullSpace::None
            } else {
                NullSpace::Constant
            },
            strategy: match (scheme.ppe_solver, scheme.frame) {
                (PpeSolver::Lu, _) | (PpeSolver::Auto, Frame::Eulerian) => Strategy::Direct,
                _ => Strategy::IterativeWithFallback,
            },
            matrix_unchanged,
        };
        // The unknown: p^{n+1} (warm-started from p^n), or the increment p^{n+1} − p^n
        // (started from zero: it vanishes as the flow settles).
        let unknown = if scheme.incremental_projection {
            ws.pressure_increment.clear();
            ws.pressure_increment.resize(n, 0.0);
            &mut ws.pressure_increment
        } else {
            if !scheme.ppe_warm_start {
                state.pressure.iter_mut().for_each(|p| *p = 0.0);
            }
            &mut state.pressure
        };
        let ppe = timers
            .time(Stage::PpeSolve, || ws.ppe.solve(unknown, &options))
            .map_err(|e| Breakdown {
                reason: format!("pressure Poisson solve failed: {e}"),
            })?;

        // Step 6: projection, u^{n+1} = u* − (δt/ρ)∇p^{n+1} (or ∇ of the increment), written
        // over u*.
        timers.time(Stage::Projection, || {
            let solved = if scheme.incremental_projection {
                state
                    .pressure
                    .par_iter_mut()
                    .zip(ws.pressure_increment.par_iter())
                    .for_each(|(p, dp)| *p += dp);
                &ws.pressure_increment
            } else {
                &state.pressure
            };
            ws.ghosts.extend_scalar(solved, &mut ws.pressure_ext);
            ws.grad_p.resize(n, Vec2::zeros());
            ws.sums
                .gradient_scalar(&ws.list, &ws.pressure_ext, &mut ws.grad_p);
            let scale = dt / fluid.density;
            let grad_p = &ws.grad_p;
            ws.velocity_star
                .par_iter_mut()
                .zip(grad_p.par_iter())
                .for_each(|(u, gp)| *u -= scale * gp);
            for i in buffered(buffer) {
                ws.velocity_star[i] = prescribed;
            }
        });

        // Step 7: r^{n+1} = r^n + δt/2 (u^n + u^{n+1} + 2u_ps), then u^{n+1} becomes the state.
        timers.time(Stage::Advection, || {
            if lagrangian {
                let (u_old, u_new, u_ps) =
                    (&state.velocity, &ws.velocity_star, &state.shift_velocity);
                state
                    .position
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(i, r)| {
                        *r = domain.wrap(*r + 0.5 * dt * (u_old[i] + u_new[i] + 2.0 * u_ps[i]));
                    });
            }
            std::mem::swap(&mut state.velocity, &mut ws.velocity_star);
            if let Some(inflow) = inflow.as_mut() {
                feed(inflow, fluid, dt, state);
            }
        });

        state.time += dt;
        state.steps += 1;
        let t0 = std::time::Instant::now();
        let checked = self.check();
        self.timers
            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
        checked?;
        Ok(StepReport { dt, ppe })
    }

    /// Breakdown detection: non-finite values, runaway kinetic energy or conformation, lost
    /// positive definiteness (direct integration), particles through a wall.
    pub fn check(&self) -> Result<(), Breakdown> {
        let s = &self.state;
        let fail = |reason: String| Err(Breakdown { reason });
        if !s
            .velocity
            .par_iter()
            .all(|u| u.x.is_finite() && u.y.is_finite())
        {
            return fail("non-finite velocity".into());
        }
        if !s.pressure.par_iter().all(|p| p.is_finite()) {
            return fail("non-finite pressure".into());
        }
        let mean_square = crate::analysis::diagnostics::blocked_sum(s.velocity.len(), |i| {
            s.velocity[i].norm_squared()
        }) / s.velocity.len() as f64;
        let limit = RUNAWAY_SPEED_FACTOR * self.scales.velocity;
        if mean_square.sqrt() > limit {
            return fail(format!(
                "runaway kinetic energy: r.m.s. speed {:.3e} exceeds {RUNAWAY_SPEED_FACTOR} U",
                mean_square.sqrt()
            ));
        }
        if let Some(bad) = s.conformation.par_iter().find_any(|a| !a.is_finite()) {
            return fail(format!("non-finite conformation tensor {bad:?}"));
        }
        if s.conformation.par_iter().any(|a| a.trace() > RUNAWAY_TRACE) {
            return fail(format!("runaway conformation: tr A > {RUNAWAY_TRACE:e}"));
        }
        if self.scheme.conformation == ConformationScheme::Direct
            && s.conformation
                .par_iter()
                .any(|a| a.det() <= 0.0 || a.trace() <= 0.0)
        {
            return fail("conformation tensor lost positive definiteness".into());
        }
        if self.free_surface {
            let d = &self.domain;
            if let Some(p) = s.position.par_iter().find_any(|p| {
                (0..2).any(|a| !d.periodic[a] && (p[a] < d.min[a] || p[a] > d.max[a]))
            }) {
                return fail(format!(
                    "a particle left the domain at ({:.4}, {:.4})",
                    p.x, p.y
                ));
            }
        }
        let walls = &self.ws.ghosts.surfaces;
        if let Some(p) = s
            .position
            .par_iter()
            .find_any(|p| walls.iter().any(|w| w.distance(p) <= 0.0))
        {
            return fail(format!(
                "a particle crossed a wall at ({:.4}, {:.4})",
                p.x, p.y
            ));
        }
        Ok(())
    }

    /// Polymer stress τ_p at n−1/2 for every particle (zero for Newtonian).
    pub fn polymer_stress(&self) -> Vec<Sym2> {
        if !self.fluid.model.is_viscoelastic() {
            return vec![Sym2::ZERO; self.particles()];
        }
        self.state
            .conformation
            .par_iter()
            .map(|a| self.fluid.polymer_stress(a))
            .collect()
    }

    /// Heap bytes held by the particle state and every per-step buffer (LU factors, when a
    /// direct solve is used, are faer's and not counted).
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        let s = &self.state;
        let w = &self.ws;
        b(&s.position)
            + b(&s.velocity)
            + b(&s.pressure)
            + b(&s.conformation)
            + b(&s.shift_velocity)
            + b(&w.points)
            + w.ghosts.heap_bytes()
            + w.search.heap_bytes()
            + w.list.heap_bytes()
            + w.sums.heap_bytes()
            + b(&w.velocity_ext)
            + b(&w.grad_u)
            + b(&w.grad_c)
            + b(&w.tensor_ext)
            + b(&w.log_conformation)
            + b(&w.advection)
            + b(&w.phi)
            + b(&w.div_phi)
            + b(&w.laplacian)
            + b(&w.velocity_star)
            + b(&w.divergence)
            + b(&w.pressure_ext)
            + b(&w.pressure_increment)
            + b(&w.grad_p)
            + w.surface.heap_bytes()
            + b(&w.grad_u_star)
            + b(&w.surface_pressure)
            + b(&w.surface_region)
            + w.ppe.heap_bytes()
            + w.viscous.heap_bytes()
            + w.reorder.heap_bytes()
    }

    /// Neighbour pairs of the last step (for memory and cost reports).
    pub fn neighbour_pairs(&self) -> usize {
        self.ws.list.pairs()
    }

    /// LU factorisations of the PPE so far (an Eulerian run factorises once).
    pub fn ppe_factorisations(&self) -> usize {
        self.ws.ppe.factorisations()
    }

    /// Stored PPE entries of the last step.
    pub fn ppe_nonzeros(&self) -> usize {
        self.ws.ppe.nnz()
    }
}

/// Step 5 (free surfaces): the Dirichlet pressure of FS particles, (35a) with the predictor's
/// velocity gradient ∇u* and τ_p^{n+½} (or 0), less p^n for an incremental projection.
fn surface_pressure(
    fluid: &Fluid,
    scheme: &Scheme,
    state: &State,
    buffer: &[bool],
    ws: &mut Workspace,
) {
    let n = state.position.len();
    ws.surface_pressure.clear();
    ws.surface_pressure.resize(n, 0.0);
    if scheme.free_surface_pressure == SurfacePressure::NormalStress {
        ws.grad_u_star.resize(n, Mat2::zeros());
        ws.sums
            .gradient_vector(&ws.list, &ws.velocity_ext, &mut ws.grad_u_star);
        let eta_s = fluid.solvent_viscosity();
        let (fs, normal, grad) = (&ws.surface.on_surface, &ws.surface.normal, &ws.grad_u_star);
        let conformation = &state.conformation;
        let list = &ws.list;
        ws.surface_pressure
            .par_iter_mut()
            .enumerate()
            .filter(|(i, _)| fs[*i] && !buffer.get(*i).copied().unwrap_or(false))
            .filter(|(i, _)| list.range(*i).len() >= MIN_SURFACE_NEIGHBOURS)
            .for_each(|(i, p)| {
                let tau = if conformation.is_empty() {
                    Sym2::ZERO
                } else {
                    fluid.polymer_stress(&conformation[i])
                };
                *p = crate::engine::surface::normal_stress_pressure(
                    normal[i], &grad[i], &tau, eta_s,
                );
            });
    }
    if scheme.incremental_projection {
        ws.surface_pressure
            .par_iter_mut()
            .zip(state.pressure.par_iter())
            .for_each(|(p, old)| *p -= old);
    }
}

/// Indices of the inflow buffer's particles.
fn buffered(buffer: &[bool]) -> impl Iterator<Item = usize> + '_ {
    buffer
        .iter()
        .enumerate()
        .filter(|(_, &b)| b)
        .map(|(i, _)| i)
}

/// After step 7 (jets): buffer particles keep the rest conformation (no polymer stress
/// enters), those below the orifice are released, and new rows join the buffer on top.
fn feed(inflow: &mut Inflow, fluid: &Fluid, dt: f64, state: &mut State) {
    let rest = fluid.model.rest_conformation();
    let viscoelastic = !state.conformation.is_empty();
    if viscoelastic {
        for (a, _) in state
            .conformation
            .iter_mut()
            .zip(&inflow.flags)
            .filter(|(_, &b)| b)
        {
            *a = rest;
        }
    }
    let added = inflow.advance(dt, &state.position);
    let velocity = inflow.velocity;
    for p in added {
        state.position.push(p);
        state.velocity.push(velocity);
        state.pressure.push(0.0);
        state.shift_velocity.push(Vec2::zeros());
        if viscoelastic {
            state.conformation.push(rest);
        }
    }
}

/// Step 3: advance the conformation from n−½ to n+½, then Φ and ∇·Φ (`form` of (20)).
fn constitutive_update(
    fluid: &Fluid,
    scheme: &Scheme,
    dt: f64,
    form: DivergenceForm,
    state: &mut State,
    ws: &mut Workspace,
) {
    let n = state.position.len();
    let lambda = fluid.relaxation_time;
    let model = fluid.model;
    ws.advection.resize(n, Sym2::ZERO);
    match scheme.conformation {
        ConformationScheme::Log => {
            ws.log_conformation.resize(n, Sym2::ZERO);
            ws.log_conformation
                .par_iter_mut()
                .zip(state.conformation.par_iter())
                .for_each(|(psi, a)| *psi = a.log());
            ws.ghosts
                .extend_tensor(&ws.log_conformation, &mut ws.tensor_ext);
            ws.sums.advective_tensor(
                &ws.list,
                &ws.tensor_ext,
                &state.shift_velocity,
                &mut ws.advection,
            );
            let (psi, adv, grad) = (&ws.log_conformation, &ws.advection, &ws.grad_u);
            state
                .conformation
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, a)| {
                    *a = rheology::log_conformation_step(
                        &model, a, &psi[i], &adv[i], &grad[i], dt, lambda,
                    );
                });
        }
        ConformationScheme::Direct => {
            ws.ghosts
                .extend_tensor(&state.conformation, &mut ws.tensor_ext);
            ws.sums.advective_tensor(
                &ws.list,
                &ws.tensor_ext,
                &state.shift_velocity,
                &mut ws.advection,
            );
            let (adv, grad) = (&ws.advection, &ws.grad_u);
            state
                .conformation
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, a)| {
                    *a = rheology::direct_step(&model, a, &adv[i], &grad[i], dt, lambda);
                });
        }
    }
    // Φ = τ_p − α_V η0 2D, eq. (6), with D from ∇u^n.
    let evss = scheme.evss_alpha * fluid.viscosity;
    ws.phi.resize(n, Sym2::ZERO);
    let grad = &ws.grad_u;
    ws.phi
        .par_iter_mut()
        .zip(state.conformation.par_iter())
        .enumerate()
        .for_each(|(i, (phi, a))| {
            let strain_rate = Sym2::sym_part(&grad[i]) * 2.0;
            *phi = fluid.polymer_stress(a) - strain_rate * evss;
        });
    ws.ghosts.extend_tensor(&ws.phi, &mut ws.tensor_ext);
    ws.div_phi.resize(n, Vec2::zeros());
    ws.sums
        .divergence_tensor(&ws.list, &ws.tensor_ext, form, &mut ws.div_phi);
}

impl Simulation {
    /// The free-surface sets and normals of the last step (free-surface scenes after their
    /// first step; None otherwise).
    pub fn surface(&self) -> Option<&FreeSurface> {
        (self.free_surface && self.ws.surface.on_surface.len() == self.particles())
            .then_some(&self.ws.surface)
    }

    /// The vorticity ω = ∂v/∂x − ∂u/∂y of the velocity at the start of the last step (the
    /// Bonet–Lok gradient of step 2; zeros before the first step).
    pub fn vorticity(&self) -> Vec<f64> {
        let n = self.particles();
        if self.ws.grad_u.len() != n {
            return vec![0.0; n];
        }
        self.ws
            .grad_u
            .iter()
            .map(|g| g[(1, 0)] - g[(0, 1)])
            .collect()
    }
}
