//! The time integrator, a type chosen once at set-up: King & Lind's projection (the PPE (25)
//! and the projection (26), [`ProjectionMethod`]) or the weakly compressible scheme of Fang
//! et al. ([`WeakMethod`]: an equation of state and continuity). Each owns only the stages
//! it uses; the step calls the chosen one through [`Integrator`] and never asks which it is.

use super::features::{AfterProjection, Features};
use super::Breakdown;
use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::frame::Frame;
use crate::engine::free_surface::DirichletInputs;
use crate::engine::gravity::Gravity;
use crate::engine::kernel::QuinticSpline;
use crate::engine::neighbourhood::Neighbourhood;
use crate::engine::neighbours::Domain;
use crate::engine::pressure::{PpeSettings, PressureStage};
use crate::engine::projection::ProjectionStage;
use crate::engine::rheology::Fluid;
use crate::engine::state::{Scales, State};
use crate::engine::timing::{Stage, StageSeconds};
use crate::engine::weakly_compressible::{MomentumInputs, WeakStage, DENSITY_DEVIATION_LIMIT};
use rheosph_solver::SolveReport;

/// The integrator's terms of the predictor (24).
pub(super) struct MomentumTerms<'a, const D: usize = 2> {
    /// ∇p^n (the incremental projection).
    pub old_pressure_gradient: Option<&'a [Vector<D>]>,
    /// The weakly compressible scheme's pressure, polymer-stress, artificial viscosity and
    /// stress accelerations.
    pub weak: Option<&'a [Vector<D>]>,
}

/// What Steps 5–6 read and write: the predictor's u*, the state, and the stages around.
pub(super) struct Correction<'a, const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub hood: &'a Neighbourhood<D>,
    /// The scene's free surface, inflow and detached bodies ([`Features`]).
    pub features: &'a mut dyn Features<D>,
    /// φ = η(γ̇)/η0 per particle (empty: uniform viscosity).
    pub viscosity_factor: &'a [f64],
    /// u* in, u^{n+1} out.
    pub velocity_star: &'a mut Vec<Vector<D>>,
    pub state: &'a mut State<D>,
    pub fluid: &'a Fluid,
    pub kernel: &'a QuinticSpline,
    pub domain: &'a Domain<D>,
    pub frame: Frame,
    pub gravity: Gravity,
    pub scales: &'a Scales,
    /// Whether the shift velocity transports the pressure (shifting on).
    pub shifting: bool,
    pub timers: &'a mut StageSeconds,
    pub dt: f64,
}

/// Steps 5–6 and what the rest of the step needs from them.
pub(super) trait Integrator<const D: usize = 2>: Send + Sync
where
    Dim<D>: Dimension<D>,
{
    /// The integrator's own step limit for smoothing length `h` and the fastest particle
    /// (∞: none).
    fn dt_limit(&self, _h: f64, _max_speed: f64) -> f64 {
        f64::INFINITY
    }

    /// Before a step: adapt to the largest principal polymer stress.
    fn follow_polymer(&mut self, _max_polymer_stress: f64) {}

    /// Step 4: this integrator's terms of the predictor.
    fn momentum<'a>(&'a mut self, inputs: &MomentumInputs<'a, D>) -> MomentumTerms<'a, D>;

    /// Steps 5–6: u^{n+1} and p^{n+1} from u*; the PPE solve's report, if there is one.
    fn correct(&mut self, step: Correction<D>) -> Result<Option<SolveReport>, Breakdown>;

    /// The invariant this integrator does not keep by construction.
    fn check(&self) -> Result<(), String> {
        Ok(())
    }

    /// The largest |ρ/ρ0 − 1| of the last step (0: incompressible).
    fn density_deviation(&self) -> f64 {
        0.0
    }

    /// The speed of sound of the last step (0: incompressible).
    fn sound_speed(&self) -> f64 {
        0.0
    }

    /// The fluid volume Σ m_i/ρ_i in units of δV: N for incompressible particles.
    fn volume(&self, pressure: &[f64]) -> f64 {
        pressure.len() as f64
    }

    fn heap_bytes(&self) -> usize;

    /// The particles moved: matrices built from their configuration are stale.
    fn configuration_changed(&mut self) {}

    /// The particle order changed, or a checkpoint is written: rebuild preconditioners.
    fn invalidate_preconditioner(&mut self) {}

    /// LU factorisations of the PPE so far.
    fn factorisations(&self) -> usize {
        0
    }

    /// Stored PPE entries of the last step.
    fn nnz(&self) -> usize {
        0
    }
}

/// King & Lind's projection: the PPE (25) with Dirichlet rows on a free surface, then (26).
pub(super) struct ProjectionMethod<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    projection: ProjectionStage<D>,
    pressure: PressureStage<D>,
    ppe: PpeSettings,
}

impl<const D: usize> ProjectionMethod<D>
where
    Dim<D>: Dimension<D>,
{
    pub fn new(
        projection: ProjectionStage<D>,
        pressure: PressureStage<D>,
        ppe: PpeSettings,
    ) -> Self {
        Self {
            projection,
            pressure,
            ppe,
        }
    }

    /// Step 5: the pressure Poisson equation (25), with Dirichlet rows on a free surface.
    fn pressure_poisson(&mut self, c: &mut Correction<D>) -> Result<SolveReport, Breakdown> {
        let (fluid, dt) = (c.fluid, c.dt);
        let rho_g = fluid.density * c.state.body_force;
        let ahead = if c.frame.moves_particles() { dt } else { 0.0 };
        let (hood, points) = (c.hood.parts(), &c.hood.points);
        let (pressure, projection) = (&mut self.pressure, &mut self.projection);
        let s = &mut *c.state;
        let features = &mut *c.features;
        let (gravity, factor) = (c.gravity, c.viscosity_factor);
        c.timers.time(Stage::PpeAssembly, || {
            pressure.divergence(hood, c.velocity_star);
            let divergence = pressure.divergence_mut();
            projection.stabilise(hood, &s.pressure, fluid.density, dt, divergence);
            let inputs = DirichletInputs {
                hood,
                points,
                fluid,
                viscosity_factor: factor,
                velocity_star: pressure.velocity_star_ext(),
                velocity: &s.velocity,
                ahead,
                conformation: &s.conformation,
                prescribed: &[],
            };
            let n = s.pressure.len();
            let mut shift = |values: &mut [f64]| {
                gravity.reduce(values, &points[..n], rho_g);
                projection.dirichlet_for_unknown(values, &s.pressure);
            };
            let rows = features.dirichlet_rows(&inputs, &mut shift);
            pressure.assemble(hood, fluid.density, dt, rows.unwrap_or_default());
            pressure.relax_volume(hood, |i| features.row_support(i), dt);
        });
        let dirichlet = c.features.pins_pressure_level();
        let unknown = projection.unknown(&mut s.pressure, self.ppe.warm_start);
        let scales = c.scales;
        c.timers
            .time(Stage::PpeSolve, || {
                pressure.solve(unknown, dirichlet, scales, dt)
            })
            .map_err(|e| Breakdown {
                reason: format!("pressure Poisson solve failed: {e}"),
            })
    }

    /// Step 6: u^{n+1} = u* − (δt/ρ)∇p^{n+1} (or ∇ of the increment), written over u*.
    fn project(&mut self, c: &mut Correction<D>) {
        let dt_over_rho = c.dt / c.fluid.density;
        let (pressure, projection) = (&mut self.pressure, &mut self.projection);
        let s = &mut *c.state;
        let (hood, u_star) = (c.hood, &mut *c.velocity_star);
        let (features, domain, dt) = (&mut *c.features, c.domain, c.dt);
        c.timers.time(Stage::Projection, || {
            let solved = projection.update_pressure(&mut s.pressure);
            pressure.project(hood.parts(), solved, dt_over_rho, u_star);
            features.after_projection(AfterProjection {
                hood: hood.parts(),
                points: &hood.points,
                domain,
                velocity: &s.velocity,
                velocity_new: u_star,
                body_force: s.body_force,
                dt,
            });
        });
    }
}

impl<const D: usize> Integrator<D> for ProjectionMethod<D>
where
    Dim<D>: Dimension<D>,
{
    fn momentum<'a>(&'a mut self, m: &MomentumInputs<'a, D>) -> MomentumTerms<'a, D> {
        MomentumTerms {
            old_pressure_gradient: self.projection.old_pressure_gradient(m.hood, m.pressure),
            weak: None,
        }
    }

    fn correct(&mut self, mut c: Correction<D>) -> Result<Option<SolveReport>, Breakdown> {
        let report = self.pressure_poisson(&mut c)?;
        self.project(&mut c);
        Ok(Some(report))
    }

    fn heap_bytes(&self) -> usize {
        self.projection.heap_bytes() + self.pressure.heap_bytes()
    }

    fn configuration_changed(&mut self) {
        self.pressure.configuration_changed();
    }

    fn invalidate_preconditioner(&mut self) {
        self.pressure.invalidate_preconditioner();
    }

    fn factorisations(&self) -> usize {
        self.pressure.factorisations()
    }

    fn nnz(&self) -> usize {
        self.pressure.nnz()
    }
}

/// Weakly compressible SPH: the pressure from an equation of state and continuity, with the
/// polymer stress in its own symmetric momentum sum (see
/// [`crate::engine::weakly_compressible`]).
pub(super) struct WeakMethod {
    stage: WeakStage,
}

impl WeakMethod {
    pub fn new(stage: WeakStage) -> Self {
        Self { stage }
    }
}

impl Integrator<2> for WeakMethod {
    fn dt_limit(&self, h: f64, max_speed: f64) -> f64 {
        self.stage.dt_limit(h, max_speed)
    }

    fn follow_polymer(&mut self, max_polymer_stress: f64) {
        self.stage.follow_polymer(max_polymer_stress);
    }

    fn momentum<'a>(&'a mut self, m: &MomentumInputs<'a>) -> MomentumTerms<'a> {
        MomentumTerms {
            old_pressure_gradient: None,
            weak: Some(self.stage.momentum(m)),
        }
    }

    /// p^{n+1} from continuity with u^{n+1}, which the predictor's u* is.
    fn correct(&mut self, c: Correction) -> Result<Option<SolveReport>, Breakdown> {
        let hood = c.hood.parts();
        c.features
            .before_continuity(hood, &c.hood.points, c.velocity_star);
        let s = c.state;
        let shift = c.shifting.then_some(&s.shift_velocity[..]);
        let (stage, kernel, u_star, dt) = (&mut self.stage, c.kernel, &*c.velocity_star, c.dt);
        c.timers.time(Stage::Projection, || {
            stage.continuity(hood, kernel, u_star, shift, &mut s.pressure, dt)
        });
        Ok(None)
    }

    fn check(&self) -> Result<(), String> {
        let deviation = self.stage.density_deviation();
        if deviation > DENSITY_DEVIATION_LIMIT {
            return Err(format!(
                "density deviates by {:.1} % from ρ0 (weak compressibility is designed for ~1 %): the speed of sound is too low for this flow",
                100.0 * deviation
            ));
        }
        Ok(())
    }

    fn density_deviation(&self) -> f64 {
        self.stage.density_deviation()
    }

    fn sound_speed(&self) -> f64 {
        self.stage.sound_speed()
    }

    fn volume(&self, pressure: &[f64]) -> f64 {
        self.stage.volume(pressure)
    }

    fn heap_bytes(&self) -> usize {
        self.stage.heap_bytes()
    }
}
