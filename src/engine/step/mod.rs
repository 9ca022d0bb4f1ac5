//! One projection time step of King & Lind (2021), Steps 1–7, eqs. (23)–(28), in ALE form.
//!
//! State at the start of step n: positions r^n, velocity u^n, pressure p^n and the
//! conformation A^{n−1/2} (stress lives at half steps, §III B). [`Simulation::step`] calls one
//! stage per step of the paper, each a type chosen at set-up that owns its buffers:
//!
//! 1. [`Frame`](crate::engine::frame::Frame): advect to r* = r^n + δt u^n, eq. (23) (fixed particles stay).
//! 2. [`Neighbourhood`]: mirrors, neighbour lists, Bonet–Lok L_i at r*; ∇u^n; the optional
//!    [`FreeSurfaceStage`] (36)–(39); the [`Shifting`] velocity u_ps (40)–(42).
//! 3. [`ConformationStage`] (viscoelastic fluids): A to n+½ (29)–(32), EVSS Φ, eq. (6).
//! 4. [`predict`], eq. (24), with the explicit or implicit [`ViscousStage`].
//! 5. The time integrator ([`integrator`], chosen once): the PPE (25) for p^{n+1} or its
//!    increment ([`PressureStage`], [`ProjectionStage`]), or the weakly compressible
//!    scheme's equation of state and continuity, which replace Steps 5–6.
//! 6. Projection (26): u^{n+1} = u* − (δt/ρ)∇p^{n+1} (the δt is implied by (25)).
//! 7. [`Frame`](crate::engine::frame::Frame): r^{n+1} = r^n + δt/2 (u^n + u^{n+1} + 2u_ps), eq. (27).
//!
//! δt follows (28) ([`Viscosity::dt_limit`](crate::engine::viscosity::Viscosity::dt_limit)).

mod checks;
mod features;
mod integrator;

pub use crate::engine::ordering::REORDER_INTERVAL;
pub use crate::engine::state::{Breakdown, Scales, State, StepReport};
pub use features::{
    Features, FeaturesOf, InternalFlow, PlaneFeatures, SpaceFeatures, StepDimension,
};

use crate::engine::bodies::contact::Contact;
use crate::engine::bodies::sphere::{SphereView, TurningSphere};
use crate::engine::bodies::{Bodies, BodyRecord, Disc, DiscSet};
use crate::engine::boundary::inflow::Inflow;
use crate::engine::boundary::{Ghosts, Wall};
use crate::engine::dimension::{Dim, Dimension, Sym, SymTensor, Vector};
use crate::engine::drive::{box_volume, Drive};
use crate::engine::frame::StepVelocities;
use crate::engine::free_surface::{
    Cohesion, DetachedBodies, DetachedMomentum, FreeSurface, FreeSurfaceStage, SurfaceTensionForm,
    Wetting,
};
use crate::engine::gravity::Gravity;
use crate::engine::kernel::{QuinticSpline, H_OVER_DR};
use crate::engine::kinematics::Kinematics;
use crate::engine::math::Vec2;
use crate::engine::neighbourhood::{default_skin, Geometry, Hood, Neighbourhood};
use crate::engine::neighbours::Domain;
use crate::engine::operators::DivergenceForm;
use crate::engine::ordering::Reordering;
use crate::engine::predictor::{predict, PredictorTerms};
use crate::engine::pressure::PressureStage;
use crate::engine::projection::ProjectionStage;
use crate::engine::resolution::Resolution;
use crate::engine::rheology::hourglass::{HourglassControl, HourglassFields};
use crate::engine::rheology::{ConformationChoice, ConformationStage, Flow, Fluid};
use crate::engine::scheme::{Method, Scheme};
use crate::engine::shifting::{ShiftInputs, ShiftRule, Shifting};
use crate::engine::stabilisation::PressureStabilisation;
use crate::engine::timing::{Stage, StageSeconds};
use crate::engine::viscosity::{
    elastic_wave_speed, Diffusion, DtInputs, ShearDependentViscosity, ViscousStage,
};
use crate::engine::volume::VolumeRelaxation;
use crate::engine::weakly_compressible::{MomentumInputs, WeakStage};
use features::{BodyStep, SurfaceForceInputs};
use integrator::{Correction, Integrator, ProjectionMethod, WeakMethod};
use rayon::prelude::*;

/// Everything needed to start a simulation in the plane.
#[derive(Clone, Debug)]
pub struct Setup {
    pub domain: Domain,
    /// Solid walls (planes, cylinders) that create mirror particles.
    pub walls: Vec<Wall>,
    pub positions: Vec<Vec2>,
    /// Initial velocity of each particle.
    pub velocity: Vec<Vec2>,
    pub spacing: f64,
    pub fluid: Fluid,
    pub scheme: Scheme,
    /// The initial body force per unit mass, and how it evolves.
    pub body_force: Vec2,
    pub drive: Drive,
    pub scales: Scales,
    /// Free surfaces: detection and Dirichlet pressure (35a), the free-surface shifting
    /// (40)–(44) and the positive stress divergence (20).
    pub free_surface: bool,
    /// An inflow buffer (jets).
    pub inflow: Option<Inflow>,
    /// Rigid discs, prescribed or free (their walls are added after `walls`).
    pub discs: Vec<Disc>,
    /// The discs' short-range repulsion, if any.
    pub contact: Option<Contact>,
    /// Gravity on the discs' buoyant mass, its hydrostatic part not in the fluid's pressure
    /// (sedimentation; see [`crate::engine::bodies`]).
    pub gravity: Vec2,
    /// The static contact angle (radians, through the liquid) where a free surface with
    /// surface tension meets a flat wall; None: no condition there.
    pub contact_angle: Option<f64>,
    /// The particles' layout: uniform, or graded along walls (fixed particles only).
    pub resolution: Resolution,
}

/// Everything needed to start an internal flow in D dimensions: walls, particles, fluid and
/// scheme, without the plane's features (a 3D simulation starts from this alone).
#[derive(Clone, Debug)]
pub struct FlowSetup<const D: usize>
where
    Dim<D>: Dimension<D>,
{
    pub domain: Domain<D>,
    pub walls: Vec<Wall<D>>,
    pub positions: Vec<Vector<D>>,
    pub velocity: Vec<Vector<D>>,
    pub spacing: f64,
    pub fluid: Fluid,
    pub scheme: Scheme,
    pub body_force: Vector<D>,
    pub drive: Drive,
    pub scales: Scales,
    /// A sphere turning about its held centre (in space only; its wall is among `walls`).
    pub sphere: Option<TurningSphere>,
    /// The volume the bulk velocity averages over (None: the box, ⟨u⟩ = Q/H or Q/(HW); a
    /// pipe's inside πR²L, ⟨u⟩ = Q/(πR²)).
    pub flow_volume: Option<f64>,
}

/// The stage objects of the step, built once from the scheme.
struct Stages<const D: usize>
where
    Dim<D>: StepDimension<D>,
{
    reordering: Reordering,
    /// Step 1's r* (fluid), then step 2's mirrors, lists and kernel sums.
    hood: Neighbourhood<D>,
    /// u^n extended to the ghosts, ∇u^n and the constitutive gradient.
    kinematics: Kinematics<D>,
    shifting: Shifting<D>,
    conformation: Option<ConformationStage<D>>,
    /// The polymer stress's hourglass control (None: off, or no polymer).
    hourglass: Option<HourglassControl<D>>,
    viscous: ViscousStage<D>,
    /// φ = η(γ̇)/η0 of a generalised Newtonian fluid (None: uniform viscosity).
    shear_viscosity: Option<ShearDependentViscosity>,
    /// ν of the viscous term: (β + α_V)η0/ρ (η0/ρ for a Newtonian fluid).
    nu: f64,
    velocity_star: Vec<Vector<D>>,
    /// Steps 5–6: the projection or the weakly compressible scheme.
    integrator: Box<dyn Integrator<D>>,
    /// Free surfaces, bodies, inflow: what the scene adds to internal flow.
    features: FeaturesOf<D>,
}

/// A running simulation in D = 2 (the default) or 3 dimensions.
pub struct Simulation<const D: usize = 2>
where
    Dim<D>: StepDimension<D>,
{
    pub fluid: Fluid,
    pub scheme: Scheme,
    pub kernel: QuinticSpline,
    pub spacing: f64,
    pub domain: Domain<D>,
    pub drive: Drive,
    /// The volume the bulk velocity averages over ([`FlowSetup::flow_volume`]).
    pub flow_volume: f64,
    pub scales: Scales,
    pub state: State<D>,
    pub timers: StageSeconds,
    stages: Stages<D>,
}

/// The neighbourhood of `walls` under `scheme`'s wall and operator settings, for particles
/// `spacing` apart or graded by `resolution`.
fn neighbourhood<const D: usize>(
    walls: Vec<Wall<D>>,
    scheme: &Scheme,
    spacing: f64,
    resolution: Resolution<D>,
) -> Neighbourhood<D>
where
    Dim<D>: Dimension<D>,
{
    let mut ghosts = Ghosts::new(walls);
    ghosts.set_model(scheme.wall_model, spacing);
    ghosts.set_velocity_extension(scheme.wall_velocity);
    let mut hood = Neighbourhood::new(ghosts);
    hood.sums.configure(scheme.operators);
    hood.set_resolution(resolution);
    hood
}

/// What [`Simulation::assemble`] puts together besides the flow's set-up.
struct Parts<const D: usize>
where
    Dim<D>: StepDimension<D>,
{
    kernel: QuinticSpline,
    hood: Neighbourhood<D>,
    shifting: Shifting<D>,
    form: Option<DivergenceForm>,
    integrator: Box<dyn Integrator<D>>,
    features: FeaturesOf<D>,
}

impl Simulation<2> {
    pub fn new(setup: Setup) -> Self {
        let scheme = setup.scheme;
        let fluid = &setup.fluid;
        let kernel = QuinticSpline::for_spacing(setup.spacing);
        let mut walls = setup.walls;
        let cohesive = scheme.surface_tension.form == SurfaceTensionForm::Cohesion;
        let cohesion = (cohesive && fluid.surface_tension > 0.0).then(|| {
            let shapes: Vec<_> = walls.iter().map(|w| w.shape).collect();
            Cohesion::new(
                fluid.surface_tension,
                fluid.density,
                setup.spacing,
                kernel.support(),
                &shapes,
                setup.contact_angle,
            )
        });
        // The contact angle holds at the scene's walls, not at the discs' (added below).
        let wetting = setup.contact_angle.filter(|_| !cohesive).map(|theta| {
            let angles = walls
                .iter()
                .map(|w| (w.shape, w.contact_angle.unwrap_or(theta)));
            Wetting::per_wall(angles.collect(), setup.spacing, scheme.wetting)
        });
        let bodies = Bodies::new(
            DiscSet {
                discs: setup.discs,
                contact: setup.contact,
                gravity: setup.gravity,
            },
            setup.body_force,
            scheme.wall_conformation,
            &mut walls,
        );
        let hood = neighbourhood(walls, &scheme, setup.spacing, setup.resolution);
        // Free surfaces take the positive divergence form of (20) with L = I; the weakly
        // compressible scheme sums the polymer stress in its own momentum form.
        let form = match scheme.method {
            Method::WeaklyCompressible(_) => None,
            Method::Projection if setup.free_surface => Some(DivergenceForm::Positive),
            Method::Projection => Some(DivergenceForm::Negative),
        };
        let features = PlaneFeatures {
            free_surface: setup.free_surface.then(|| {
                let sigma = if cohesive { 0.0 } else { fluid.surface_tension };
                FreeSurfaceStage::new(scheme.surface_options(), sigma, setup.spacing, wetting)
            }),
            cohesion,
            detached: (setup.free_surface
                && scheme.method == Method::Projection
                && scheme.free_surface.detached_momentum == DetachedMomentum::Conserved)
                .then(DetachedBodies::default),
            bodies,
            inflow: setup.inflow,
        };
        let parts = Parts {
            shifting: shifting(&scheme, setup.free_surface, setup.contact, setup.spacing),
            integrator: integrator(&scheme, fluid, &kernel, setup.spacing),
            kernel,
            hood,
            form,
            features,
        };
        let flow = FlowSetup {
            domain: setup.domain,
            walls: Vec::new(),
            positions: setup.positions,
            velocity: setup.velocity,
            spacing: setup.spacing,
            fluid: setup.fluid,
            scheme,
            body_force: setup.body_force,
            drive: setup.drive,
            scales: setup.scales,
            sphere: None,
            flow_volume: None,
        };
        Self::assemble(flow, parts)
    }

    /// The inflow buffer of a jet; its flags follow the particle order.
    pub fn inflow(&self) -> Option<&Inflow> {
        self.stages.features.inflow.as_ref()
    }
}

impl Simulation<3> {
    /// The sphere turning about its held centre, if the scene has one.
    pub fn turning_sphere(&self) -> Option<&TurningSphere> {
        self.stages.features.sphere.as_ref()
    }

    /// What a sphere's torque integration reads of the current state.
    pub fn sphere_view(&self) -> SphereView<'_> {
        SphereView {
            state: &self.state,
            kernel: &self.kernel,
            domain: &self.domain,
            fluid: &self.fluid,
            spacing: self.spacing,
        }
    }

    /// A simulation in space: internal flow between walls, in periodic boxes and pipes.
    /// Refused, naming the setting, where the scheme asks for what is written only in the
    /// plane.
    pub fn in_space(setup: FlowSetup<3>) -> Result<Self, String> {
        let scheme = &setup.scheme;
        if let Some(key) = plane_only(scheme) {
            return Err(format!("{key} is written for 2D scenes only"));
        }
        let kernel = QuinticSpline::in_dimension::<3>(H_OVER_DR * setup.spacing);
        let sphere = setup.sphere;
        let hood = neighbourhood(
            setup.walls.clone(),
            scheme,
            setup.spacing,
            Resolution::Uniform,
        );
        let parts = Parts {
            shifting: shifting(scheme, false, None, setup.spacing),
            integrator: projection_method(scheme, &setup.fluid, &kernel, setup.spacing),
            kernel,
            hood,
            form: Some(DivergenceForm::Negative),
            features: SpaceFeatures::new(sphere),
        };
        Ok(Self::assemble(setup, parts))
    }
}

impl<const D: usize> Simulation<D>
where
    Dim<D>: StepDimension<D>,
{
    /// The simulation of `flow` (its walls already in `parts.hood`) with the stages the
    /// scheme chooses.
    fn assemble(flow: FlowSetup<D>, parts: Parts<D>) -> Self {
        let n = flow.positions.len();
        let skin = flow.scheme.neighbour_skin;
        let (fluid, scheme, kernel) = (flow.fluid, flow.scheme, parts.kernel);
        let viscoelastic = fluid.model.is_viscoelastic();
        let conformation = if viscoelastic {
            vec![fluid.model.rest_conformation(); n]
        } else {
            Vec::new()
        };
        let stages = Stages {
            reordering: Reordering::new(scheme.reorder, scheme.frame.moves_particles()),
            hood: parts.hood,
            kinematics: Kinematics::new(scheme.constitutive_gradient),
            shifting: parts.shifting,
            conformation: viscoelastic.then(|| {
                ConformationStage::new(
                    ConformationChoice {
                        scheme: scheme.conformation,
                        integrator: scheme.conformation_integrator,
                        remap: scheme.conformation_remap,
                    },
                    &fluid,
                    scheme.evss_alpha,
                    parts.form,
                )
            }),
            hourglass: HourglassControl::chosen(scheme.hourglass_control, viscoelastic, kernel.h()),
            viscous: scheme.viscosity.stage(scheme.viscous_tolerance),
            shear_viscosity: (!fluid.law.is_constant())
                .then(|| ShearDependentViscosity::new(fluid.law, fluid.viscosity)),
            nu: scheme.viscosity_nu(&fluid),
            velocity_star: Vec::new(),
            integrator: parts.integrator,
            features: parts.features,
        };
        let mut sim = Self {
            kernel,
            fluid,
            scheme,
            spacing: flow.spacing,
            domain: flow.domain,
            drive: flow.drive,
            flow_volume: flow.flow_volume.unwrap_or_else(|| box_volume(&flow.domain)),
            scales: flow.scales,
            state: State::initial(flow.positions, flow.velocity, conformation, flow.body_force),
            timers: StageSeconds::default(),
            stages,
        };
        sim.set_neighbour_skin(skin);
        sim
    }

    /// The Verlet skin of the neighbour search: `skin`·δr, or by default
    /// [`default_skin`] for the distance the particles move in one step at the velocity
    /// scale.
    pub fn set_neighbour_skin(&mut self, skin: Option<f64>) {
        let skin = skin.map_or_else(
            || default_skin(self.spacing, self.scales.velocity * self.stable_dt()),
            |s| s * self.spacing,
        );
        let support = self.kernel.support();
        self.stages.hood.set_skin(skin, support);
    }

    /// Whether the particle count grows during the run (an inflow feeds particles; such a
    /// run is not checkpointed).
    pub fn grows(&self) -> bool {
        self.stages.features.grows()
    }

    /// The rigid bodies' motion (V^n, Ω^n, c^n and the acceleration), in order; empty
    /// without bodies.
    pub fn body_motions(&self) -> Vec<BodyRecord> {
        self.stages.features.body_motions()
    }

    /// Sets the bodies' motion (a checkpoint's), in order.
    pub fn restore_bodies(&mut self, motions: &[BodyRecord]) {
        self.stages.features.restore_bodies(motions);
    }

    pub fn particles(&self) -> usize {
        self.state.position.len()
    }

    /// Particle volume δV = δr^D.
    pub fn particle_volume(&self) -> f64 {
        (0..D).fold(1.0, |v, _| v * self.spacing)
    }

    /// The time step: `dt_factor` times the limit of the viscosity scheme
    /// ([`Viscosity::dt_limit`](crate::engine::viscosity::Viscosity::dt_limit)): eq. (28)
    /// for explicit viscosity, the advective limit for implicit, and in both the elastic limit
    /// of the stretched polymer.
    pub fn stable_dt(&self) -> f64 {
        self.step_limit(self.max_polymer_stress()).0
    }

    /// The largest principal polymer stress over the particles (0 without polymer).
    fn max_polymer_stress(&self) -> f64 {
        let fluid = &self.fluid;
        self.state
            .conformation
            .par_iter()
            .map(|a| fluid.polymer_stress(a).max_eigenvalue())
            .reduce(|| 0.0, f64::max)
    }

    /// The stable step and the elastic wave speed it was limited by.
    fn step_limit(&self, max_polymer_stress: f64) -> (f64, f64) {
        let fluid = &self.fluid;
        let inputs = self.dt_inputs(max_polymer_stress);
        let limit = self
            .scheme
            .viscosity
            .dt_limit(fluid, self.stages.nu, &inputs);
        let wave_speed = elastic_wave_speed(fluid, max_polymer_stress);
        let acoustic = self.stages.integrator.dt_limit(inputs.h, inputs.max_speed);
        let dt = match self.scheme.time_step {
            Some(fixed) => fixed,
            None => (self.scheme.dt_factor * limit).min(acoustic),
        };
        (dt, wave_speed)
    }

    /// What the step's limits read. Under graded resolution the advective limit is each
    /// particle's own, min h_i/|u_i| (and h/U for the bulk), and the elastic limit takes the
    /// finest h: h is the finest, the speeds scaled to it.
    fn dt_inputs(&self, max_polymer_stress: f64) -> DtInputs {
        let velocity = &self.state.velocity;
        let local = self.stages.hood.local();
        let h = self.kernel.h();
        if local.len() != velocity.len() {
            let max_speed = velocity
                .par_iter()
                .map(|u| u.norm())
                .reduce(|| 0.0, f64::max);
            return DtInputs {
                h,
                max_speed,
                velocity_scale: self.scales.velocity,
                max_polymer_stress,
            };
        }
        let finest = local
            .iter()
            .map(|l| l.spacing)
            .fold(f64::INFINITY, f64::min);
        let rate = velocity
            .par_iter()
            .zip(local.par_iter())
            .map(|(u, l)| u.norm() / l.spacing)
            .reduce(|| 0.0, f64::max);
        DtInputs {
            h: H_OVER_DR * finest,
            max_speed: rate * finest,
            velocity_scale: self.scales.velocity * H_OVER_DR * finest / h,
            max_polymer_stress,
        }
    }

    /// The bulk velocity ⟨u⟩ = Σ u_x δV over the flow's volume (Q/H in a channel,
    /// Q/(πR²) in a pipe: [`FlowSetup::flow_volume`]), each particle's own volume under
    /// graded resolution.
    pub fn bulk_velocity(&self) -> f64 {
        let (velocity, local) = (&self.state.velocity, self.stages.hood.local());
        let sum = if local.len() != velocity.len() {
            let volume = self.particle_volume();
            crate::engine::reduce::blocked_sum(velocity.len(), |i| velocity[i][0]) * volume
        } else {
            crate::engine::reduce::blocked_sum(velocity.len(), |i| velocity[i][0] * local[i].volume)
        };
        sum / self.flow_volume
    }

    /// Sorts the fluid particles along a Morton curve of their cells (see
    /// [`crate::engine::ordering`]).
    pub fn reorder(&mut self) {
        let t0 = std::time::Instant::now();
        let s = &mut self.state;
        let cell = self.kernel.support();
        if let Some(order) = self.stages.hood.reorder(&self.domain, &s.position, cell) {
            order.apply_vec2(&mut s.position);
            order.apply_vec2(&mut s.velocity);
            order.apply_vec2(&mut s.shift_velocity);
            order.apply_scalar(&mut s.pressure);
            order.apply_sym(&mut s.conformation);
            self.stages.features.reorder(order);
            self.stages.integrator.invalidate_preconditioner();
            self.stages.viscous.invalidate_preconditioner();
        }
        self.timers
            .add(Stage::Neighbours, t0.elapsed().as_secs_f64());
    }

    /// Drops the linear solvers' preconditioners, so that the next step builds them from its
    /// own matrices, as a run continued from a checkpoint written now does: the run loop
    /// calls this at every checkpoint, which keeps continued runs bit-identical.
    pub fn reset_preconditioners(&mut self) {
        self.stages.integrator.invalidate_preconditioner();
        self.stages.viscous.invalidate_preconditioner();
    }

    /// Replaces the state with a restored one and marks the caches derived from the particle
    /// configuration (neighbour lists, kernel sums, PPE matrix and LU factors) for rebuilding.
    /// The last step's velocity gradient, the preconditioners and the viscous guess are
    /// dropped, as before a first step.
    pub fn restore_state(&mut self, state: State<D>) {
        self.state = state;
        self.stages.hood.invalidate();
        self.stages.integrator.configuration_changed();
        self.stages.kinematics.clear();
        self.reset_preconditioners();
    }

    /// Advances one step of at most `dt_max`: the paper's Steps 1–7.
    pub fn step(&mut self, dt_max: f64) -> Result<StepReport, Breakdown> {
        if self.stages.reordering.due(self.state.steps) {
            self.reorder();
        }
        let max_polymer_stress = self.max_polymer_stress();
        self.stages.integrator.follow_polymer(max_polymer_stress);
        let (stable, wave_speed) = self.step_limit(max_polymer_stress);
        let dt = stable.min(dt_max);
        self.intermediate_positions(dt);
        let st = &mut self.stages;
        let fluid = &st.hood.points[..st.hood.points.len().min(self.state.position.len())];
        st.features.move_walls(&mut st.hood.ghosts, fluid, dt);
        self.neighbourhoods();
        self.kinematics(dt);
        self.constitutive_update(dt);
        self.shift_pressure(Gravity::reduce);
        let projected = self
            .predictor(dt)
            .and_then(|iterations| Ok((iterations, self.correct(dt)?)));
        self.shift_pressure(Gravity::restore);
        let (viscous_iterations, ppe) = projected?;
        let density_deviation = self.stages.integrator.density_deviation();
        self.final_positions(dt);
        self.move_bodies(dt);
        if self.drive != Drive::Constant {
            let bulk = self.bulk_velocity();
            self.drive.update(&mut self.state.body_force, || bulk, dt);
        }
        self.state.time += dt;
        self.state.steps += 1;
        self.state.previous_dt = dt;
        let t0 = std::time::Instant::now();
        let checked = self.check();
        self.timers
            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
        checked?;
        Ok(StepReport {
            dt,
            ppe,
            elastic_courant: dt * wave_speed / self.finest_h(),
            viscous_iterations,
            density_deviation,
            sound_speed: self.stages.integrator.sound_speed(),
        })
    }

    /// Under `scheme.gravity = "reduced-pressure"`, the state's p becomes P = p − ρ g·r* for
    /// steps 4–6 (`shift` = [`Gravity::reduce`]) and p again after them
    /// ([`Gravity::restore`]); nothing otherwise.
    fn shift_pressure(&mut self, shift: fn(Gravity, &mut [f64], &[Vector<D>], Vector<D>)) {
        let s = &mut self.state;
        let rho_g = self.fluid.density * s.body_force;
        let points = &self.stages.hood.points[..s.pressure.len()];
        shift(self.scheme.gravity, &mut s.pressure, points, rho_g);
    }

    /// After step 7: the bodies' loads from the new state, then their motion.
    fn move_bodies(&mut self, dt: f64) {
        let particle_volume = self.particle_volume();
        self.stages.features.move_bodies(BodyStep {
            state: &mut self.state,
            kernel: &self.kernel,
            domain: &self.domain,
            fluid: &self.fluid,
            walls: &self.stages.hood.ghosts.walls,
            spacing: self.spacing,
            particle_volume,
            dt,
            timers: &mut self.timers,
        });
    }

    /// Step 1: r*, eq. (23).
    fn intermediate_positions(&mut self, dt: f64) {
        let (s, points) = (&self.state, &mut self.stages.hood.points);
        let (frame, domain) = (self.scheme.frame, &self.domain);
        self.timers.time(Stage::Advection, || {
            frame.intermediate_positions(domain, &s.position, &s.velocity, dt, points)
        });
    }

    /// Step 2: mirrors, neighbour lists and kernel sums at r* (once for fixed particles).
    fn neighbourhoods(&mut self) {
        let n = self.particles();
        let st = &mut self.stages;
        let geometry = Geometry {
            domain: &self.domain,
            kernel: &self.kernel,
            spacing: self.spacing,
        };
        let moving = self.scheme.frame.moves_particles();
        self.timers.time(Stage::Neighbours, || {
            if st.hood.update(moving, geometry, n) {
                st.integrator.configuration_changed();
            }
        });
    }

    /// Step 2: the free surface (36)–(39), ∇u^n and the shift velocity u_ps.
    fn kinematics(&mut self, dt: f64) {
        let (st, s, kernel) = (&mut self.stages, &mut self.state, &self.kernel);
        self.timers.time(Stage::Kinematics, || {
            let hood = st.hood.parts();
            let Hood { list, sums, ghosts } = hood;
            st.features.detect(hood, &st.hood.points, kernel);
            st.kinematics.update(hood, &s.velocity);
            if let Some(v) = st.shear_viscosity.as_mut() {
                v.update(&st.kinematics.grad_u, ghosts);
            }
            let inputs = ShiftInputs {
                list,
                sums,
                kernel,
                spacing: self.spacing,
                dt,
                points: &st.hood.points,
                walls: &ghosts.walls,
                surface: st.features.surface(),
            };
            st.shifting
                .compute(&inputs, &s.velocity, &mut s.shift_velocity);
            st.features.hold_shift(&mut s.shift_velocity);
        });
    }

    /// Step 3: the conformation to n + ½, polymer stress, EVSS Φ and its divergence, over
    /// the span [`ConformationStage::span`].
    fn constitutive_update(&mut self, dt: f64) {
        let (st, s, fluid) = (&mut self.stages, &mut self.state, &self.fluid);
        if let Some(stage) = st.conformation.as_mut() {
            let dt = stage.span(s.previous_dt, dt);
            let flow = Flow {
                grad_u: st.kinematics.constitutive(),
                u_ps: &s.shift_velocity,
            };
            self.timers.time(Stage::Constitutive, || {
                stage.update(fluid, dt, st.hood.parts(), flow, &mut s.conformation);
                if let Some(control) = st.hourglass.as_mut() {
                    let fields = HourglassFields {
                        velocity: &s.velocity,
                        grad_u: &st.kinematics.grad_u,
                        conformation: &s.conformation,
                    };
                    control.add(
                        st.hood.parts(),
                        fluid,
                        fields,
                        stage.stress_divergence_mut(),
                    );
                }
            });
        }
    }

    /// Step 4: the predictor u*, eq. (24), with the viscous term explicit or implicit.
    /// Returns the implicit solve's BiCGStab iterations (both components; 0 if explicit).
    fn predictor(&mut self, dt: f64) -> Result<usize, Breakdown> {
        let (st, s) = (&mut self.stages, &self.state);
        let inv_rho = 1.0 / self.fluid.density;
        let body_force = self.scheme.gravity.predictor_force(s.body_force);
        let factor = st.shear_viscosity.as_ref().map_or(&[][..], |v| v.factor());
        let fluid = &self.fluid;
        let kernel = &self.kernel;
        let (domain, n) = (&self.domain, s.position.len());
        self.timers.time(Stage::Predictor, || {
            let hood = st.hood.parts();
            let grad_u = &st.kinematics.grad_u;
            let surface_force = st.features.surface_force(SurfaceForceInputs {
                hood,
                grad_u,
                nu: st.nu,
                factor,
                domain,
                points: &st.hood.points[..n],
            });
            let inputs = MomentumInputs {
                hood,
                kernel,
                pressure: &s.pressure,
                velocity_ext: &st.kinematics.velocity_ext,
                conformation: &s.conformation,
                fluid,
                grad_u: &st.kinematics.grad_u,
            };
            let own = st.integrator.momentum(&inputs);
            let terms = PredictorTerms {
                grad_u: &st.kinematics.grad_u,
                u_ps: &s.shift_velocity,
                viscous: st
                    .viscous
                    .explicit_laplacian(hood.list, hood.sums, &st.kinematics.velocity_ext, factor)
                    .map(|(laplacian, weight)| (laplacian, weight * st.nu)),
                stress: st.conformation.as_ref().and_then(|c| c.stress_divergence()),
                weak: own.weak,
                surface_force,
                body_force,
                old_pressure_gradient: own.old_pressure_gradient,
                inv_rho,
            };
            predict(&terms, &s.velocity, dt, &mut st.velocity_star);
        });
        let nu_dt = st.nu * dt;
        let preconditioner = self.scheme.ppe.preconditioner.resolve();
        let reports = self
            .timers
            .time(Stage::Viscous, || {
                st.viscous.solve(
                    st.hood.parts(),
                    Diffusion { nu_dt, factor },
                    &s.velocity,
                    &mut st.velocity_star,
                    st.features.prescribed(),
                    preconditioner,
                )
            })
            .map_err(|e| Breakdown {
                reason: format!("implicit viscous solve failed: {e}"),
            })?;
        Ok(reports.map_or(0, |r| r.iter().map(|r| r.iterations).sum()))
    }

    /// Steps 5–6 by the chosen integrator: u^{n+1} over u*, p^{n+1}; the PPE's report.
    fn correct(&mut self, dt: f64) -> Result<Option<rheosph_solver::SolveReport>, Breakdown> {
        let st = &mut self.stages;
        let factor = st.shear_viscosity.as_ref().map_or(&[][..], |v| v.factor());
        st.integrator.correct(Correction {
            hood: &st.hood,
            features: &mut st.features,
            viscosity_factor: factor,
            velocity_star: &mut st.velocity_star,
            state: &mut self.state,
            fluid: &self.fluid,
            kernel: &self.kernel,
            domain: &self.domain,
            frame: self.scheme.frame,
            gravity: self.scheme.gravity,
            scales: &self.scales,
            shifting: self.scheme.shifting,
            timers: &mut self.timers,
            dt,
        })
    }

    /// Step 7: r^{n+1}, eq. (27); u^{n+1} becomes the state; an inflow feeds new particles.
    fn final_positions(&mut self, dt: f64) {
        let (st, s) = (&mut self.stages, &mut self.state);
        let (frame, domain) = (self.scheme.frame, &self.domain);
        let rest = self.fluid.model.rest_conformation();
        self.timers.time(Stage::Advection, || {
            frame.advance_positions(
                domain,
                &mut s.position,
                StepVelocities {
                    old: &s.velocity,
                    new: &st.velocity_star,
                    shift: &s.shift_velocity,
                },
                dt,
            );
            std::mem::swap(&mut s.velocity, &mut st.velocity_star);
            st.features.feed(rest, dt, s);
        });
    }

    /// The viscosity of every particle's viscous term: η(γ̇) of the last step for a
    /// generalised Newtonian fluid, the solvent viscosity η_s otherwise.
    pub fn viscosity(&self) -> Vec<f64> {
        let eta_s = self.fluid.solvent_viscosity();
        match self.stages.shear_viscosity.as_ref() {
            Some(v) if v.fluid_factor().len() == self.particles() => {
                v.fluid_factor().iter().map(|phi| phi * eta_s).collect()
            }
            _ => vec![eta_s; self.particles()],
        }
    }

    /// Polymer stress τ_p at n−1/2 for every particle (zero for Newtonian).
    pub fn polymer_stress(&self) -> Vec<Sym<D>> {
        if !self.fluid.model.is_viscoelastic() {
            return vec![Sym::<D>::ZERO; self.particles()];
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
        let (s, st) = (&self.state, &self.stages);
        b(&s.position)
            + b(&s.velocity)
            + b(&s.pressure)
            + b(&s.conformation)
            + b(&s.shift_velocity)
            + st.hood.heap_bytes()
            + st.kinematics.heap_bytes()
            + st.shifting.heap_bytes()
            + st.features.heap_bytes()
            + st.conformation.as_ref().map_or(0, |c| c.heap_bytes())
            + st.hourglass
                .as_ref()
                .map_or(0, HourglassControl::heap_bytes)
            + st.viscous.heap_bytes()
            + st.shear_viscosity.as_ref().map_or(0, |v| v.heap_bytes())
            + b(&st.velocity_star)
            + st.integrator.heap_bytes()
    }

    /// The fluid volume Σ m_i/ρ_i: N δV for the projection (incompressible particles), and
    /// with each particle's density from its pressure for the weakly compressible scheme.
    /// The smallest smoothing length: h, or the finest layer's under graded resolution.
    pub fn finest_h(&self) -> f64 {
        let local = self.stages.hood.local();
        local
            .iter()
            .map(|l| H_OVER_DR * l.spacing)
            .fold(self.kernel.h(), f64::min)
    }

    pub fn fluid_volume(&self) -> f64 {
        let dv = self.particle_volume();
        let local = self.stages.hood.local();
        if !local.is_empty() {
            return crate::engine::reduce::blocked_sum(local.len(), |i| local[i].volume);
        }
        self.stages.integrator.volume(&self.state.pressure) * dv
    }

    /// Neighbour pairs of the last step (for memory and cost reports).
    pub fn neighbour_pairs(&self) -> usize {
        self.stages.hood.list.pairs()
    }

    /// Cell searches for neighbours so far (steps within the Verlet skin run none).
    pub fn neighbour_searches(&self) -> usize {
        self.stages.hood.searches()
    }

    /// LU factorisations of the PPE so far (an Eulerian run factorises once).
    pub fn ppe_factorisations(&self) -> usize {
        self.stages.integrator.factorisations()
    }

    /// Stored PPE entries of the last step.
    pub fn ppe_nonzeros(&self) -> usize {
        self.stages.integrator.nnz()
    }

    /// The solid walls that create mirror particles.
    pub fn walls(&self) -> &[Wall<D>] {
        &self.stages.hood.ghosts.walls
    }
}

impl Simulation<2> {
    /// The free-surface sets and normals of the last step (free-surface scenes after their
    /// first step; None otherwise).
    pub fn surface(&self) -> Option<&FreeSurface> {
        self.stages
            .features
            .free_surface
            .as_ref()
            .map(|fs| &fs.surface)
            .filter(|s| s.on_surface.len() == self.particles())
    }

    /// How many times a surface particle was held off a wall
    /// ([`FreeSurfaceStage::hold_off_walls`]).
    pub fn surface_wall_holds(&self) -> u64 {
        self.stages
            .features
            .free_surface
            .as_ref()
            .map_or(0, |fs| fs.wall_holds)
    }

    /// Detached bodies of liquid corrected so far (summed over the steps) and the largest
    /// velocity one correction removed from a particle ([`DetachedBodies`]; zeros without).
    pub fn detached_corrections(&self) -> (u64, f64) {
        self.stages
            .features
            .detached
            .as_ref()
            .map_or((0, 0.0), |d| (d.body_steps, d.largest_correction))
    }

    /// The vorticity ω = ∂v/∂x − ∂u/∂y of the velocity at the start of the last step (the
    /// Bonet–Lok gradient of step 2; zeros before the first step).
    pub fn vorticity(&self) -> Vec<f64> {
        let n = self.particles();
        let grad_u = &self.stages.kinematics.grad_u;
        if grad_u.len() != n {
            return vec![0.0; n];
        }
        grad_u.iter().map(|g| g[(1, 0)] - g[(0, 1)]).collect()
    }

    /// The rigid discs (V^n, Ω^n, c^n) and the loads of the last step.
    pub fn bodies(&self) -> &Bodies {
        &self.stages.features.bodies
    }

    /// Steers prescribed disc `k`: its velocity V and spin Ω from the next step on, as if the
    /// case had given them (its centre moves by V δt a step, its surface drags the fluid).
    /// Refused, with the reason, for a disc the fluid moves (free or free-rotation: their
    /// motion is the result) and in the Eulerian frame, whose mirrors are built once.
    pub fn set_disc_motion(&mut self, k: usize, velocity: Vec2, spin: f64) -> Result<(), String> {
        let count = self.stages.features.bodies.discs.len();
        let moving_frame = self.scheme.frame.moves_particles();
        let disc = self
            .stages
            .features
            .bodies
            .discs
            .get_mut(k)
            .ok_or_else(|| format!("there is no disc {k} (the scene has {count})"))?;
        if disc.motion != crate::engine::bodies::Motion::Prescribed {
            return Err(format!(
                "disc {k} moves under the fluid's load ({:?}); only a prescribed disc is steered",
                disc.motion
            ));
        }
        if !moving_frame {
            return Err("the Eulerian frame builds the discs' mirrors once".into());
        }
        if !(velocity.x.is_finite() && velocity.y.is_finite() && spin.is_finite()) {
            return Err(format!(
                "velocity and spin must be finite, got [{}, {}] and {spin}",
                velocity.x, velocity.y
            ));
        }
        disc.velocity = velocity;
        disc.spin = spin;
        Ok(())
    }
}

/// The first setting of `scheme` that only the plane has, by its key (None: all run in 3D).
/// The weakly compressible scheme, volume relaxation, the second-order operators (their 3D
/// moment systems are not written) and the fixed ghost lattice are 2D.
pub fn plane_only(scheme: &Scheme) -> Option<&'static str> {
    use crate::engine::boundary::WallModel;
    use crate::engine::operators::{GradientOrder, LaplacianOrder, PpeLaplacian};
    let o = &scheme.operators;
    [
        (
            scheme.method != Method::Projection,
            "scheme.method = \"wcsph\"",
        ),
        (
            scheme.ppe.volume_relaxation > 0.0,
            "experimental.volume_relaxation",
        ),
        (
            o.gradient_order != GradientOrder::First,
            "scheme.operators.gradient = \"second\"",
        ),
        (
            o.laplacian_order != LaplacianOrder::First,
            "scheme.operators.laplacian = \"second\"",
        ),
        (
            o.ppe_laplacian != PpeLaplacian::Standard,
            "experimental.ppe_laplacian",
        ),
        (
            scheme.wall_model == WallModel::FixedGhost,
            "scheme.walls.model = \"fixed-ghost\"",
        ),
    ]
    .into_iter()
    .find_map(|(refused, key)| refused.then_some(key))
}

/// Steps 5–6 as `scheme.method` chooses.
fn integrator(
    scheme: &Scheme,
    fluid: &Fluid,
    kernel: &QuinticSpline,
    spacing: f64,
) -> Box<dyn Integrator> {
    match scheme.method {
        Method::Projection => projection_method(scheme, fluid, kernel, spacing),
        Method::WeaklyCompressible(w) => Box::new(WeakMethod::new(WeakStage::new(
            w,
            fluid.density,
            kernel,
            spacing,
        ))),
    }
}

/// King & Lind's projection, Steps 5–6.
fn projection_method<const D: usize>(
    scheme: &Scheme,
    fluid: &Fluid,
    kernel: &QuinticSpline,
    spacing: f64,
) -> Box<dyn Integrator<D>>
where
    Dim<D>: StepDimension<D>,
{
    Box::new(ProjectionMethod::new(
        ProjectionStage::new(
            scheme.projection,
            PressureStabilisation::new(fluid.density, fluid.viscosity, kernel.h()),
        )
        .with_rotational(
            fluid.density * scheme.viscosity.theta() * scheme.viscosity_nu(fluid),
            kernel.value(0.0),
        ),
        PressureStage::new(
            scheme.ppe,
            scheme.frame,
            VolumeRelaxation::new(scheme.ppe.volume_relaxation, kernel, spacing),
        ),
        scheme.ppe,
    ))
}

/// Step 2's shift rule; under a contact model for gaps narrower than the support it keeps
/// particles from shifting into walls within δr/2 ([`Shifting::keep_off_walls`]).
fn shifting<const D: usize>(
    scheme: &Scheme,
    free_surface: bool,
    contact: Option<Contact>,
    spacing: f64,
) -> Shifting<D>
where
    Dim<D>: Dimension<D>,
{
    let rule = ShiftRule::new(
        scheme.frame,
        scheme.shifting,
        free_surface,
        scheme.free_surface.repulsion,
    );
    let shifting = Shifting::new(rule);
    match contact {
        Some(c) if c.closes_gaps() => shifting.keep_off_walls(0.5 * spacing),
        _ => shifting,
    }
}
