//! The numerical scheme: every variant of the method, chosen once at set-up. The time step
//! builds one stage object per choice ([`crate::engine::step::Simulation::new`]); nothing
//! re-tests these inside the time loop.

use crate::engine::boundary::{TensorMirror, WallModel};
use crate::engine::frame::Frame;
use crate::engine::free_surface::{FreeSurfaceSettings, SurfaceTensionSettings, WettingSettings};
use crate::engine::kinematics::ConstitutiveGradient;
use crate::engine::operators::OperatorSettings;
use crate::engine::pressure::PpeSettings;
use crate::engine::projection::Projection;
use crate::engine::rheology::{ConformationIntegrator, ConformationScheme};
use crate::engine::viscosity::Viscosity;
use crate::engine::weakly_compressible::WeaklyCompressible;

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
    /// The gradient's and the Laplacian's variants.
    pub operators: OperatorSettings,
    /// `[scheme.free_surface]`.
    pub free_surface: FreeSurfaceSettings,
    /// `[scheme.surface_tension]`.
    pub surface_tension: SurfaceTensionSettings,
    /// `[scheme.wetting]`.
    pub wetting: WettingSettings,
}

impl Scheme {
    /// The free-surface choices, for [`crate::engine::free_surface::FreeSurfaceStage`].
    pub fn surface_options(&self) -> crate::engine::free_surface::SurfaceOptions {
        crate::engine::free_surface::SurfaceOptions {
            pressure: self.free_surface.pressure,
            contact_rows: self.free_surface.contact_rows,
            time_level: self.surface_tension.time_level,
            shear: self.free_surface.shear,
            gradient: self.free_surface.gradient,
            indicator: self.free_surface.indicator,
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
