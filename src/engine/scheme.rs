//! The numerical scheme: every variant of the method, chosen once at set-up. The time step
//! builds one stage object per choice ([`crate::engine::step::Simulation::new`]); nothing
//! re-tests these inside the time loop.

use crate::engine::boundary::{TensorMirror, WallModel, WallPressure};
use crate::engine::frame::Frame;
use crate::engine::free_surface::{SurfacePressure, SurfaceTensionForm};
use crate::engine::kinematics::ConstitutiveGradient;
use crate::engine::operators::{GradientOrder, LaplacianOrder};
use crate::engine::projection::Projection;
use crate::engine::rheology::{ConformationIntegrator, ConformationScheme};
use crate::engine::viscosity::Viscosity;
use crate::engine::weakly_compressible::WeaklyCompressible;
use serde::{Deserialize, Serialize};

/// Numerical scheme settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scheme {
    /// The projection (ISPH, the paper's) or the weakly compressible scheme.
    pub method: Method,
    /// A fixed time step instead of the stability rules (None: the rules).
    pub time_step: Option<f64>,
    pub frame: Frame,
    pub conformation: ConformationScheme,
    /// The conformation update's order in time.
    pub conformation_integrator: ConformationIntegrator,
    /// The velocity gradient the constitutive update sees.
    pub constitutive_gradient: ConstitutiveGradient,
    /// The ALE remap of the conformation: central (the paper's) or limited.
    pub conformation_remap: crate::engine::rheology::Remap,
    /// Fickian shifting in the Lagrangian frame.
    pub shifting: bool,
    /// α_V of the EVSS splitting, eqs. (6)–(8).
    pub evss_alpha: f64,
    /// ξ of the hourglass control (0 = off), `engine::rheology::hourglass`.
    pub hourglass_control: f64,
    /// The factor 0.2 of the time-step rule (28).
    pub dt_factor: f64,
    pub viscosity: Viscosity,
    /// Relative residual of the implicit viscous solves.
    pub viscous_tolerance: f64,
    pub projection: Projection,
    pub ppe: PpeSettings,
    /// Periodically sort particles along a Morton curve for memory locality.
    pub reorder: bool,
    /// The Verlet skin of the neighbour search, in units of δr (None: by the step's size,
    /// [`crate::engine::neighbourhood::default_skin`]).
    pub neighbour_skin: Option<f64>,
    /// How the conformation is carried onto wall mirrors.
    pub wall_conformation: TensorMirror,
    /// Mirrors or a fixed ghost lattice behind plane walls.
    pub wall_model: WallModel,
    /// How the explicit operators continue a no-slip wall's velocity to its ghosts.
    pub wall_velocity: crate::engine::boundary::VelocityExtension,
    /// Where the body force enters: the predictor or a reduced pressure.
    pub gravity: crate::engine::gravity::Gravity,
    /// The Neumann condition of the wall pressure: ∂p/∂n = 0 or the normal momentum balance.
    pub wall_pressure: WallPressure,
    /// Consistency order of the corrected gradient of eq. (20)–(22).
    pub gradient_order: GradientOrder,
    /// Consistency order of the Laplacian of eq. (21).
    pub laplacian_order: LaplacianOrder,
    /// The PPE's Laplacian: (21) as `laplacian_order` has it, or made exact for linear fields.
    pub ppe_laplacian: crate::engine::operators::PpeLaplacian,
    /// Free surfaces: the Dirichlet pressure rule.
    pub free_surface_pressure: SurfacePressure,
    /// Free surfaces: the neighbours of the normal-stress rule's velocity gradient.
    pub surface_gradient: crate::engine::free_surface::SurfaceGradient,
    /// The PPE row of a surface particle in a wall's first half-spacing.
    pub contact_line_rows: crate::engine::free_surface::ContactRows,
    /// Free surfaces: the repulsive term of (42)–(44) in the shifting of internal particles.
    pub surface_repulsion: bool,
    /// How a surface tension acts: in the free-surface pressure or as a cohesion force.
    pub surface_tension: SurfaceTensionForm,
    /// Where in the step the capillary pressure's curvature is taken.
    pub capillary_time_level: crate::engine::free_surface::CapillaryTimeLevel,
    /// How a contact particle's curvature is found.
    pub contact_curvature: crate::engine::free_surface::ContactCurvature,
    /// Which curve meets a wall at the contact angle: the centres' or the surface's.
    pub contact_angle_at: crate::engine::free_surface::ContactAngleAt,
    /// The viscous term's tangential flux through a free surface.
    pub surface_shear: crate::engine::free_surface::SurfaceShear,
    /// Free surfaces: whether surface membership is sharp (36) or blended.
    pub surface_indicator: crate::engine::free_surface::SurfaceIndicator,
    /// Free surfaces: whether a body of liquid detached from the rest keeps its momentum.
    pub detached_momentum: crate::engine::free_surface::DetachedMomentum,
}

impl Scheme {
    /// The free-surface choices, for [`crate::engine::free_surface::FreeSurfaceStage`].
    pub fn surface_options(&self) -> crate::engine::free_surface::SurfaceOptions {
        crate::engine::free_surface::SurfaceOptions {
            pressure: self.free_surface_pressure,
            contact_rows: self.contact_line_rows,
            time_level: self.capillary_time_level,
            shear: self.surface_shear,
            gradient: self.surface_gradient,
            indicator: self.surface_indicator,
        }
    }

    /// ν of the viscous term of the predictor: (β + α_V)η0/ρ (η0/ρ for a Newtonian fluid),
    /// the ν the implicit solve uses.
    pub fn viscosity_nu(&self, fluid: &crate::engine::rheology::Fluid) -> f64 {
        if matches!(self.method, Method::WeaklyCompressible(_)) {
            // The polymer stress enters whole in the symmetric form, without EVSS.
            fluid.solvent_viscosity() / fluid.density
        } else if fluid.model.is_viscoelastic() {
            (fluid.beta + self.evss_alpha) * fluid.viscosity / fluid.density
        } else {
            fluid.viscosity / fluid.density
        }
    }
}

/// The time integrator: what replaces Steps 5–6 (the PPE and the projection).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// King & Lind's projection: the PPE (25) and the projection (26).
    Projection,
    /// Weakly compressible SPH: pressure from an equation of state and the continuity
    /// equation (see [`crate::engine::weakly_compressible`]).
    WeaklyCompressible(WeaklyCompressible),
}

/// How the PPE (25) is solved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PpeSettings {
    /// Relative residual ‖b − Ap‖/‖b‖ at which BiCGStab stops.
    pub tolerance: f64,
    /// Or the r.m.s. divergence (in units of U/L) the residual corresponds to, whichever is
    /// reached first.
    pub divergence_tolerance: f64,
    /// BiCGStab iteration budget before the sparse-LU fallback.
    pub max_iterations: usize,
    /// Start from the previous step's pressure (true) or from zero.
    pub warm_start: bool,
    pub solver: PpeSolver,
    /// The preconditioner of BiCGStab, here and in the implicit viscous solve.
    pub preconditioner: rheosph_solver::Preconditioner,
    /// α of the density-invariant source ([`crate::engine::volume`]; 0: off).
    pub volume_relaxation: f64,
}

/// Which linear solver the PPE uses.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum PpeSolver {
    /// Sparse LU, factorised once, for fixed particles (Eulerian); warm-started BiCGStab with
    /// LU fallback when the matrix changes every step (Lagrangian).
    Auto,
    Bicgstab,
    Lu,
}

impl PpeSolver {
    /// The solver strategy in a frame.
    pub fn strategy(self, frame: Frame) -> rheosph_solver::Strategy {
        match (self, frame) {
            (PpeSolver::Lu, _) | (PpeSolver::Auto, Frame::Eulerian) => {
                rheosph_solver::Strategy::Direct
            }
            _ => rheosph_solver::Strategy::IterativeWithFallback,
        }
    }
}
