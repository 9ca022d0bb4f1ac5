//! What a simulation starts from, what it evolves, and what a step reports.

use crate::engine::boundary::inflow::Inflow;
use crate::engine::boundary::Surface;
use crate::engine::math::{Sym2, Vec2};
use crate::engine::neighbours::Domain;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use rheosph_solver::SolveReport;

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
