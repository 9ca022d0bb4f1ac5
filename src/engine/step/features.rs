//! The parts of a step that only some scenes have, chosen once per dimension: in the plane,
//! free surfaces (detection, Dirichlet pressure, surface tension, wetting, detached bodies),
//! rigid discs and an inflow buffer ([`PlaneFeatures`]); in space a sphere turning about a
//! held centre ([`SpaceFeatures`]), else the internal-flow step of the paper and nothing
//! else ([`InternalFlow`]).
//!
//! The step calls each hook at its place in Steps 1–7; the defaults do nothing, which is
//! what a scene without the feature needs, so 2D scenes without a free surface, discs or an
//! inflow run the same code as before and 3D needs no `if` in any stage.

use crate::engine::bodies::sphere::{SphereView, Turning, TurningSphere};
use crate::engine::bodies::traction::FluidView;
use crate::engine::bodies::{Bodies, BodyRecord, Coupling, DiscMotion};
use crate::engine::boundary::inflow::Inflow;
use crate::engine::boundary::{Ghosts, Wall};
use crate::engine::dimension::{Dim, Dimension, Matrix, Sym, Vector};
use crate::engine::free_surface::{
    BodyInputs, Cohesion, DetachedBodies, DirichletInputs, FreeSurface, FreeSurfaceStage,
};
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::Vec2;
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::Domain;
use crate::engine::ordering::Reorder;
use crate::engine::pressure::SurfaceRows;
use crate::engine::rheology::Fluid;
use crate::engine::state::State;
use crate::engine::timing::{Stage, StageSeconds};
use crate::engine::viscosity::Prescribed;
use crate::engine::volume::RowSupport;
use rayon::prelude::*;

/// A dimension the step runs in, with the features its scenes may have.
pub trait StepDimension<const D: usize>: Dimension<D>
where
    Dim<D>: Dimension<D>,
{
    type Features: Features<D>;
}

impl StepDimension<2> for Dim<2> {
    type Features = PlaneFeatures;
}

impl StepDimension<3> for Dim<3> {
    type Features = SpaceFeatures;
}

/// The features of a simulation in D dimensions, its type per [`StepDimension`].
pub type FeaturesOf<const D: usize> = <Dim<D> as StepDimension<D>>::Features;

/// What the predictor's surface force (Step 4) reads.
pub struct SurfaceForceInputs<'a, const D: usize>
where
    Dim<D>: Dimension<D>,
{
    pub hood: Hood<'a, D>,
    pub grad_u: &'a [Matrix<D>],
    /// ν of the viscous term and the viscosity factor (empty: uniform).
    pub nu: f64,
    pub factor: &'a [f64],
    pub domain: &'a Domain<D>,
    /// r* of the fluid particles.
    pub points: &'a [Vector<D>],
}

/// What Step 6 leaves to the features after u^{n+1} = u* − (δt/ρ)∇p.
pub struct AfterProjection<'a, const D: usize>
where
    Dim<D>: Dimension<D>,
{
    pub hood: Hood<'a, D>,
    pub points: &'a [Vector<D>],
    pub domain: &'a Domain<D>,
    /// u^n.
    pub velocity: &'a [Vector<D>],
    /// u^{n+1}, to be corrected.
    pub velocity_new: &'a mut [Vector<D>],
    pub body_force: Vector<D>,
    pub dt: f64,
}

/// What rigid bodies read after Step 7 to take their loads and move.
pub struct BodyStep<'a, const D: usize>
where
    Dim<D>: Dimension<D>,
{
    pub state: &'a mut State<D>,
    pub kernel: &'a QuinticSpline,
    pub domain: &'a Domain<D>,
    pub fluid: &'a Fluid,
    pub walls: &'a [Wall<D>],
    pub spacing: f64,
    pub particle_volume: f64,
    pub dt: f64,
    pub timers: &'a mut StageSeconds,
}

/// The step's hooks for the features a scene may add to internal flow. Each does nothing
/// by default.
pub trait Features<const D: usize>: Send + Sync
where
    Dim<D>: Dimension<D>,
{
    /// Before Step 2: bodies place their walls where they will be at r* (`fluid`: the
    /// fluid positions of the last configuration, for walls that turn in place).
    fn move_walls(&mut self, _ghosts: &mut Ghosts<D>, _fluid: &[Vector<D>], _dt: f64) {}

    /// Step 2: find the free surface at r*.
    fn detect(&mut self, _hood: Hood<D>, _points: &[Vector<D>], _kernel: &QuinticSpline) {}

    /// The free surface of this step (None: the scene has none).
    fn surface(&self) -> Option<&FreeSurface<D>> {
        None
    }

    /// Step 2, after shifting: rows that must not shift (an inflow buffer) are held.
    fn hold_shift(&self, _shift_velocity: &mut [Vector<D>]) {}

    /// Step 4: a surface force per unit mass on the fluid (cohesion, or the shear-free
    /// surface's flux), None without one.
    fn surface_force(&mut self, _inputs: SurfaceForceInputs<D>) -> Option<&[Vector<D>]> {
        None
    }

    /// Rows whose velocity is prescribed (an inflow buffer) and its value.
    fn prescribed(&self) -> Prescribed<'_, D> {
        Prescribed {
            rows: &[],
            value: Vector::<D>::zeros(),
        }
    }

    /// Step 5: the free surface's Dirichlet rows, their values passed through `shift` (to
    /// the PPE's unknown) before the rows are chosen; None without a free surface. The
    /// features give `inputs` its prescribed rows.
    fn dirichlet_rows(
        &mut self,
        _inputs: &DirichletInputs<D>,
        _shift: &mut dyn FnMut(&mut [f64]),
    ) -> Option<SurfaceRows<'_>> {
        None
    }

    /// How much of row `i`'s support the fluid fills (a surface row's is partial).
    fn row_support(&self, _i: usize) -> RowSupport {
        RowSupport::Full
    }

    /// Whether Dirichlet rows fix the pressure's level.
    fn pins_pressure_level(&self) -> bool {
        false
    }

    /// Step 6, after the projection: surface particles held off walls, prescribed rows,
    /// the momentum of detached bodies.
    fn after_projection(&mut self, _step: AfterProjection<D>) {}

    /// The weakly compressible scheme's Steps 5–6, before continuity: the same holds.
    fn before_continuity(&mut self, _hood: Hood<D>, _points: &[Vector<D>], _u: &mut [Vector<D>]) {}

    /// The particles were reordered: per-particle data follows.
    fn reorder(&mut self, _order: &mut Reorder<D>) {}

    /// Step 7: an inflow feeds new particles (at the rest conformation `rest`).
    fn feed(&mut self, _rest: Sym<D>, _dt: f64, _state: &mut State<D>) {}

    /// After Step 7: bodies take their loads and move.
    fn move_bodies(&mut self, _step: BodyStep<D>) {}

    /// The bodies' motion, for a checkpoint (none without bodies).
    fn body_motions(&self) -> Vec<BodyRecord> {
        Vec::new()
    }

    /// Sets the bodies' motion (a checkpoint's), in order.
    fn restore_bodies(&mut self, _motions: &[BodyRecord]) {}

    /// Whether the particle count grows (an inflow feeds particles).
    fn grows(&self) -> bool {
        false
    }

    /// The particles are still in the box (a free surface has nothing else to hold them).
    fn check_particles(&self, _state: &State<D>, _domain: &Domain<D>) -> Result<(), String> {
        Ok(())
    }

    /// The bodies stay apart and off the walls (`support`: the kernel's).
    fn check_bodies(&self, _domain: &Domain<D>, _support: f64) -> Result<(), String> {
        Ok(())
    }

    fn heap_bytes(&self) -> usize {
        0
    }
}

/// Internal flow only: the 3D step, and what the plane's features reduce to when a scene
/// has none of them.
#[derive(Default)]
pub struct InternalFlow;

impl<const D: usize> Features<D> for InternalFlow where Dim<D>: Dimension<D> {}

/// The features of space: a sphere turning about its held centre, if the scene has one.
#[derive(Default)]
pub struct SpaceFeatures {
    pub sphere: Option<TurningSphere>,
    /// Why the last torque could not be taken, if it could not.
    failure: Option<String>,
}

impl SpaceFeatures {
    pub fn new(sphere: Option<TurningSphere>) -> Self {
        Self {
            sphere,
            failure: None,
        }
    }
}

impl Features<3> for SpaceFeatures {
    fn move_walls(&mut self, ghosts: &mut Ghosts<3>, fluid: &[Vector<3>], _dt: f64) {
        if let Some(s) = self.sphere.as_ref().filter(|s| s.turning == Turning::Free) {
            ghosts.set_condition(s.wall, s.wall(), fluid);
        }
    }

    fn move_bodies(&mut self, b: BodyStep<3>) {
        let Some(sphere) = self.sphere.as_mut() else {
            return;
        };
        let view = SphereView {
            state: b.state,
            kernel: b.kernel,
            domain: b.domain,
            fluid: b.fluid,
            spacing: b.spacing,
        };
        let eta = response_viscosity(b.fluid, b.dt);
        self.failure = b
            .timers
            .time(Stage::Bodies, || sphere.advance(view, eta, b.dt))
            .err();
    }

    fn check_bodies(&self, _domain: &Domain<3>, _support: f64) -> Result<(), String> {
        self.failure.clone().map_or(Ok(()), Err)
    }

    fn body_motions(&self) -> Vec<BodyRecord> {
        let record = |s: &TurningSphere| {
            let (w, t) = (s.spin, s.torque);
            [w.x, w.y, w.z, t.x, t.y, t.z, 0.0]
        };
        self.sphere.iter().map(record).collect()
    }

    fn restore_bodies(&mut self, motions: &[BodyRecord]) {
        if let (Some(s), Some(v)) = (self.sphere.as_mut(), motions.first()) {
            s.spin = Vector::<3>::new(v[0], v[1], v[2]);
            s.torque = Vector::<3>::new(v[3], v[4], v[5]);
        }
    }
}

/// η = η_s + Gδt: the viscosity of a body's load's response within one step (the solvent's
/// and the polymer's elastic response over δt; `engine::bodies`).
fn response_viscosity(fluid: &Fluid, dt: f64) -> f64 {
    let elastic = if fluid.model.is_viscoelastic() && fluid.relaxation_time > 0.0 {
        fluid.polymer_viscosity() / fluid.relaxation_time * dt
    } else {
        0.0
    };
    fluid.solvent_viscosity() + elastic
}

/// The plane's features: each None (or empty) unless the scene has it.
pub struct PlaneFeatures {
    pub free_surface: Option<FreeSurfaceStage>,
    /// A surface tension as a cohesion force (None: none, or the capillary jump σκ).
    pub cohesion: Option<Cohesion>,
    /// Free surfaces under the projection: the detached bodies whose momentum the step
    /// keeps (None: not corrected).
    pub detached: Option<DetachedBodies>,
    /// The rigid discs and the walls they own.
    pub bodies: Bodies,
    /// The inflow buffer of a jet; its flags follow the particle order.
    pub inflow: Option<Inflow>,
}

impl PlaneFeatures {
    fn buffer(&self) -> &[bool] {
        self.inflow.as_ref().map_or(&[], |b| &b.flags)
    }
}

impl Features<2> for PlaneFeatures {
    fn move_walls(&mut self, ghosts: &mut Ghosts, _fluid: &[Vec2], dt: f64) {
        if !self.bodies.is_empty() {
            self.bodies.apply(ghosts, dt);
        }
    }

    fn detect(&mut self, hood: Hood, points: &[Vec2], kernel: &QuinticSpline) {
        let buffer = self.inflow.as_ref().map_or(&[][..], |b| &b.flags);
        if let Some(fs) = self.free_surface.as_mut() {
            fs.detect(hood, points, kernel, buffer);
        }
    }

    fn surface(&self) -> Option<&FreeSurface> {
        self.free_surface.as_ref().map(|fs| &fs.surface)
    }

    fn hold_shift(&self, shift_velocity: &mut [Vec2]) {
        if let Some(inflow) = self.inflow.as_ref() {
            inflow.prescribe(shift_velocity, Vec2::zeros());
        }
    }

    fn surface_force(&mut self, f: SurfaceForceInputs<2>) -> Option<&[Vec2]> {
        match (self.cohesion.as_mut(), self.free_surface.as_mut()) {
            (Some(c), _) => Some(c.accelerations(f.domain, f.points)),
            (None, Some(fs)) => fs.shear_free_accelerations(f.hood, f.grad_u, f.nu, f.factor),
            (None, None) => None,
        }
    }

    fn prescribed(&self) -> Prescribed<'_> {
        Prescribed {
            rows: self.buffer(),
            value: self.inflow.as_ref().map_or(Vec2::zeros(), |b| b.velocity),
        }
    }

    fn dirichlet_rows(
        &mut self,
        inputs: &DirichletInputs,
        shift: &mut dyn FnMut(&mut [f64]),
    ) -> Option<SurfaceRows<'_>> {
        let fs = self.free_surface.as_mut()?;
        let buffer = self.inflow.as_ref().map_or(&[][..], |b| &b.flags);
        let inputs = &DirichletInputs {
            prescribed: buffer,
            ..*inputs
        };
        fs.dirichlet_pressure(inputs);
        shift(fs.values_mut());
        let hood = inputs.hood;
        fs.choose_rows(hood.list, inputs.points, hood.ghosts);
        Some(fs.dirichlet())
    }

    fn row_support(&self, i: usize) -> RowSupport {
        self.free_surface
            .as_ref()
            .map_or(RowSupport::Full, |fs| fs.surface.row_support(i))
    }

    fn pins_pressure_level(&self) -> bool {
        self.free_surface
            .as_ref()
            .is_some_and(|fs| fs.dirichlet().pin_level())
    }

    fn after_projection(&mut self, a: AfterProjection<2>) {
        if let Some(fs) = self.free_surface.as_mut() {
            fs.hold_off_walls(a.velocity_new);
        }
        if let Some(inflow) = self.inflow.as_ref() {
            inflow.prescribe(a.velocity_new, inflow.velocity);
        }
        let buffer = self.inflow.as_ref().map_or(&[][..], |b| &b.flags);
        if let Some(bodies) = self.detached.as_mut() {
            let n = a.velocity.len();
            let inputs = BodyInputs {
                list: a.hood.list,
                points: &a.points[..n],
                buffer,
                domain: a.domain,
            };
            bodies.conserve(&inputs, a.velocity, a.velocity_new, a.body_force, a.dt);
        }
    }

    /// Under `contact_rows = "held"` (the only choice besides `surface` that the weakly
    /// compressible scheme takes) the surface particles within δr/4 of a wall lose their
    /// velocity into it; under `surface` nothing is held.
    fn before_continuity(&mut self, hood: Hood, points: &[Vec2], u: &mut [Vec2]) {
        if let Some(inflow) = self.inflow.as_ref() {
            inflow.prescribe(u, inflow.velocity);
        }
        if let Some(fs) = self.free_surface.as_mut() {
            fs.choose_rows(hood.list, points, hood.ghosts);
            fs.hold_off_walls(u);
        }
    }

    fn reorder(&mut self, order: &mut Reorder) {
        if let Some(inflow) = self.inflow.as_mut() {
            order.apply_bool(&mut inflow.flags);
        }
    }

    fn feed(&mut self, rest: Sym<2>, dt: f64, state: &mut State) {
        if let Some(inflow) = self.inflow.as_mut() {
            inflow.feed(rest, dt, state);
        }
    }

    fn move_bodies(&mut self, b: BodyStep<2>) {
        if self.bodies.is_empty() {
            return;
        }
        let g = b.state.body_force;
        let fluid = b.fluid;
        let coupling = Coupling {
            fluid_density: fluid.density,
            response_viscosity: response_viscosity(fluid, b.dt),
            viscosity: fluid.viscosity,
            spacing: b.spacing,
            dt: b.dt,
            domain: *b.domain,
            stiffening: 1.0,
        };
        let view = FluidView {
            state: b.state,
            kernel: b.kernel,
            domain: b.domain,
            fluid,
            walls: b.walls,
        };
        let bodies = &mut self.bodies;
        b.timers
            .time(Stage::Bodies, || bodies.advance(view, g, &coupling));
        let (velocity, dv, dt) = (&mut b.state.velocity, b.particle_volume, b.dt);
        b.state.body_force = b.timers.time(Stage::Bodies, || {
            bodies.hold_return_flow(velocity, dv, fluid.density, g, dt)
        });
    }

    fn grows(&self) -> bool {
        self.inflow.is_some()
    }

    fn body_motions(&self) -> Vec<BodyRecord> {
        let motion = |d: &crate::engine::bodies::Disc| DiscMotion {
            centre: d.circle.centre,
            velocity: d.velocity,
            spin: d.spin,
            acceleration: d.acceleration,
        };
        self.bodies
            .discs
            .iter()
            .map(|d| motion(d).record())
            .collect()
    }

    fn restore_bodies(&mut self, motions: &[BodyRecord]) {
        for (d, m) in self.bodies.discs.iter_mut().zip(motions) {
            d.set_motion(&DiscMotion::from_record(m));
        }
    }

    fn check_particles(&self, state: &State, domain: &Domain) -> Result<(), String> {
        if self.free_surface.is_none() {
            return Ok(());
        }
        let d = domain;
        match state
            .position
            .par_iter()
            .find_any(|p| (0..2).any(|a| !d.periodic[a] && (p[a] < d.min[a] || p[a] > d.max[a])))
        {
            Some(p) => Err(format!(
                "a particle left the domain at ({:.4}, {:.4})",
                p.x, p.y
            )),
            None => Ok(()),
        }
    }

    fn check_bodies(&self, domain: &Domain, support: f64) -> Result<(), String> {
        super::checks::check_discs(&self.bodies, domain, support)
    }

    fn heap_bytes(&self) -> usize {
        self.free_surface.as_ref().map_or(0, |f| f.heap_bytes())
            + self.cohesion.as_ref().map_or(0, Cohesion::heap_bytes)
            + self.detached.as_ref().map_or(0, DetachedBodies::heap_bytes)
    }
}
