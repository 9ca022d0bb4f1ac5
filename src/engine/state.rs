//! What a simulation evolves, and what a step reports.

use crate::engine::dimension::{Dim, Dimension};
use nalgebra::SVector;
use rheosph_solver::SolveReport;

/// Characteristic scales of a scene, for tolerances and breakdown thresholds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales {
    pub length: f64,
    pub velocity: f64,
}

/// The evolving particle state (fluid particles only, structure of arrays), in D = 2 or 3
/// dimensions.
#[derive(Clone, Debug)]
pub struct State<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub time: f64,
    pub steps: u64,
    /// r^n.
    pub position: Vec<SVector<f64, D>>,
    /// u^n.
    pub velocity: Vec<SVector<f64, D>>,
    /// p^n (zero mean on closed domains).
    pub pressure: Vec<f64>,
    /// A^{n−1/2}; empty for a Newtonian fluid.
    pub conformation: Vec<<Dim<D> as Dimension<D>>::Sym>,
    /// δt^{n−1}, the last step (0 before the first): A^{n−½} is the conformation at
    /// t^n − δt^{n−1}/2, so step 3 advances it over (δt^{n−1} + δt^n)/2 to t^n + δt^n/2.
    pub previous_dt: f64,
    /// u_ps of the last step.
    pub shift_velocity: Vec<SVector<f64, D>>,
    /// The body force of the next step (see [`crate::engine::drive`]).
    pub body_force: SVector<f64, D>,
}

impl<const D: usize> Default for State<D>
where
    Dim<D>: Dimension<D>,
{
    fn default() -> Self {
        Self::initial(Vec::new(), Vec::new(), Vec::new(), SVector::zeros())
    }
}

impl<const D: usize> State<D>
where
    Dim<D>: Dimension<D>,
{
    /// The state at t = 0: the particles at `positions` with `velocity`, no pressure, the
    /// conformation given (empty for a Newtonian fluid) and the initial body force.
    pub fn initial(
        position: Vec<SVector<f64, D>>,
        velocity: Vec<SVector<f64, D>>,
        conformation: Vec<<Dim<D> as Dimension<D>>::Sym>,
        body_force: SVector<f64, D>,
    ) -> Self {
        let n = position.len();
        Self {
            time: 0.0,
            steps: 0,
            position,
            velocity,
            pressure: vec![0.0; n],
            conformation,
            previous_dt: 0.0,
            shift_velocity: vec![SVector::zeros(); n],
            body_force,
        }
    }
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
    /// The PPE solve (None: the weakly compressible scheme has none).
    pub ppe: Option<SolveReport>,
    /// δt c/h with c the shear-wave speed of the stretched polymer (0 without polymer): the
    /// number the elastic limit bounds (see `engine::viscosity::elastic_limit`).
    pub elastic_courant: f64,
    /// BiCGStab iterations of the implicit viscous solve, both components (0 if explicit).
    pub viscous_iterations: usize,
    /// The largest |ρ/ρ0 − 1| after the step (0 for the projection, whose particles keep ρ0).
    pub density_deviation: f64,
    /// The speed of sound of the step (0 for the projection).
    pub sound_speed: f64,
}
