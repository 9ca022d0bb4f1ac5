//! Rigid discs in the flow (the 2D counterpart of the suspended spheres of Vázquez-Quesada &
//! Ellero 2017): each is a circular wall whose mirrors carry its surface velocity
//! V + Ω ẑ × (x − c) ([`RigidNoSlip`]), moving as prescribed or as the fluid's load moves it.
//!
//! The coupling is staggered: the step runs with the discs' V^n, Ω^n, c^n as boundary
//! conditions; then the load of the new fluid state ([`traction`]) advances them,
//!
//!   (I + δt k_Ω)(Ω^{n+1} − Ω^n)/δt = T,
//!   (m + m_a + δt k_V)(V^{n+1} − V^n)/δt = F + m g + (m − m_f) g_s + m_a a^n,
//!   c^{n+1} = c^n + δt V^{n+1},
//!
//! with m = ρ_s πR², I = ½mR², g the scene's body force (acting on the disc's mass as on the
//! fluid's: the projection's pressure carries no hydrostatic part of a periodic body force;
//! what the pressure balances it carries, and F includes that), g_s gravity for
//! sedimentation, whose hydrostatic part ρ_f g_s is left out of the fluid's pressure (so it
//! acts on the disc's buoyant mass m − m_f, m_f = ρ_f πR², and not on the fluid), and a^n the
//! previous step's acceleration. The k and m_a terms vanish at a steady state and keep the explicit coupling
//! stable: the load responds within one step to the disc's own velocity, through the first
//! particle layer (the mirrors carry 2u_w), by ΔT ≈ −k_Ω ΔΩ and ΔF ≈ −k_V ΔV with
//! k_Ω = 2πη R³/δr, k_V = 2πη R/δr (η = η_s + Gδt, the solvent and the polymer's elastic
//! response over a step; measured: T changed by 7.9·10³ when Ω went from −8.2 to 8.2 at
//! R/δr = 8, η = 10, i.e. k_Ω = 482, against 2πηR³/δr = 503). Without the k_Ω term the freely
//! rotating disc of `cases/disc-in-shear.toml` flipped its spin every step (δt k_Ω/I = 2.1 > 2).
//! m_a = c_a ρ_f πR², with c_a = 1 (`coupling_added_mass`) the added mass of a circle in
//! unbounded potential flow: the classic instability of explicit coupling for light bodies.
//! If the fluid's true response to a mode of the discs' accelerations has added mass M, the
//! lagged term makes the error of that mode grow by (m_a − M)/(m + m_a) per step, so the
//! coupling is stable for M < m + 2m_a. A lone disc (M ≈ ρ_f πR²) is stable for any ρ_s ≥ ρ_f;
//! rows of discs in a closed box, moving against each other, squeeze the fluid between them
//! and have a larger M: twelve discs at ρ_s = 2ρ_f (M ≈ 4ρ_f πR² there) alternated their
//! forces step by step with c_a = 1 and settle with c_a = 3 (validation pages). m_a vanishes at a
//! steady state; a larger c_a only slows the approach to it. Free discs are kept to ρ_s ≥ ρ_f.
//!
//! Under g_s the discs settle as in a closed container: [`Bodies::hold_return_flow`] keeps
//! the net volume flux along the periodic axis at zero (module docs there).

pub mod contact;
pub mod sphere;
pub mod traction;

use crate::engine::boundary::{Circle, Ghosts, RigidNoSlip, Shape, TensorMirror, Wall};
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use contact::{Contact, Squeeze};
use std::sync::Arc;
use traction::{FluidView, Load};

/// Surface points of the load integration per disc.
pub const TRACTION_SAMPLES: usize = 128;

/// How a disc moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// At its given V and Ω for ever (V = Ω = 0: fixed; V ≠ 0: towed; Ω ≠ 0: turned).
    Prescribed,
    /// Centre held, spinning freely under the fluid's torque.
    FreeRotation,
    /// Translating and spinning under the fluid's load and the body force.
    Free,
}

/// One disc: its circle (centre c^n), V^n, Ω^n, density and motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    pub circle: Circle,
    pub velocity: Vec2,
    pub spin: f64,
    pub density: f64,
    pub motion: Motion,
    /// The last step's acceleration (V^n − V^{n−1})/δt.
    pub acceleration: Vec2,
    /// m_a of the coupling in units of ρ_f πR² (1: the unbounded disc's; module docs).
    pub coupling_added_mass: f64,
}

/// The evolving part of a disc (what a checkpoint stores).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscMotion {
    pub centre: Vec2,
    pub velocity: Vec2,
    pub spin: f64,
    pub acceleration: Vec2,
}

/// What a checkpoint keeps of one body: a disc's [`DiscMotion`] as (c_x, c_y, V_x, V_y, Ω,
/// a_x, a_y); a turning sphere's Ω and last torque as (Ω_x, Ω_y, Ω_z, T_x, T_y, T_z, 0).
pub type BodyRecord = [f64; 7];

impl DiscMotion {
    pub fn record(&self) -> BodyRecord {
        let (c, v, a) = (self.centre, self.velocity, self.acceleration);
        [c.x, c.y, v.x, v.y, self.spin, a.x, a.y]
    }

    pub fn from_record(v: &BodyRecord) -> Self {
        Self {
            centre: Vec2::new(v[0], v[1]),
            velocity: Vec2::new(v[2], v[3]),
            spin: v[4],
            acceleration: Vec2::new(v[5], v[6]),
        }
    }
}

/// What the coupling's stabilising terms need of the fluid and the step.
#[derive(Clone, Copy, Debug)]
pub struct Coupling {
    /// ρ_f.
    pub fluid_density: f64,
    /// η = η_s + Gδt: the viscosity of the load's response within one step.
    pub response_viscosity: f64,
    /// η0 = η_s + η_p: the lubrication's viscosity ([`contact`]).
    pub viscosity: f64,
    /// δr.
    pub spacing: f64,
    pub dt: f64,
    /// The box (a disc's centre wraps across its periodic ends).
    pub domain: Domain,
    /// The factor on k_V and k_Ω for the disc being advanced: max(1, (2δr/s)²) with s its
    /// narrowest gap to another disc or a wall. In a gap of a spacing or two the particles
    /// that both surfaces hold follow the disc less within a step, and the load answers its
    /// own motion more strongly than in open fluid. Measured on a disc settling onto the
    /// floor under lubrication (R/δr = 8, η = 10, δt ≈ 0.26, k_V = 503): the explicit
    /// coupling's error alternated in sign from s ≈ 0.15R = 1.2δr (tangential speed and spin
    /// first) and doubled each step at s ≈ 0.12R, i.e. a response of ≈ 2k_V and ≈ 3.5k_V,
    /// growing about as s^{−2.2}; the coupling is stable while its k exceeds half the true
    /// response. 1 wherever the gap exceeds 2δr (every run kept a kernel support apart); like
    /// k_V, it multiplies V^{n+1} − V^n and vanishes at a steady state.
    pub stiffening: f64,
}

impl Coupling {
    /// The coupling for a disc whose narrowest gap is `gap` ([`Self::stiffening`]).
    pub fn at_gap(&self, gap: f64) -> Self {
        let s = gap.max(0.05 * self.spacing);
        Self {
            stiffening: (2.0 * self.spacing / s).powi(2).max(1.0),
            ..*self
        }
    }
}

impl Disc {
    /// πR².
    pub fn area(&self) -> f64 {
        std::f64::consts::PI * self.circle.radius.powi(2)
    }

    pub fn mass(&self) -> f64 {
        self.density * self.area()
    }

    /// I = ½ m R² about the centre.
    pub fn inertia(&self) -> f64 {
        0.5 * self.mass() * self.circle.radius.powi(2)
    }

    /// Sets centre, velocity, spin and acceleration.
    pub fn set_motion(&mut self, m: &DiscMotion) {
        self.circle.centre = m.centre;
        self.velocity = m.velocity;
        self.spin = m.spin;
        self.acceleration = m.acceleration;
    }

    /// The no-slip condition of its surface (its mirrors' velocities).
    fn condition(&self, tensor: TensorMirror) -> RigidNoSlip {
        RigidNoSlip {
            tensor,
            centre: self.circle.centre,
            radius: self.circle.radius,
            velocity: self.velocity,
            spin: self.spin,
        }
    }

    /// The wall its mirrors are built from.
    pub fn wall(&self, tensor: TensorMirror) -> Wall {
        Wall {
            shape: Shape::Circle(self.circle),
            condition: Arc::new(self.condition(tensor)),
            contact_angle: None,
        }
    }

    /// The disc where the step's fluid is: c^n + δt V^n, as Step 1 moves the particles to
    /// r* = r^n + δt u^n (eq. (23)). Its walls and its load are taken there; at c^n the
    /// particles moving with a disc met it δt V closer in front and farther behind. (In
    /// `cases/disc-sedimentation.toml` this changed the terminal velocity by < 0.2 %; the
    /// O(δt) error found there was the return flow's, see [`Bodies::hold_return_flow`].)
    pub fn ahead(&self, dt: f64, domain: Option<&Domain>) -> Disc {
        let mut d = *self;
        let c = self.circle.centre + dt * self.velocity;
        d.circle.centre = domain.map_or(c, |b| b.wrap(c));
        d
    }

    /// u_w at a surface point.
    pub fn surface_velocity(&self, x: Vec2) -> Vec2 {
        self.condition(TensorMirror::Even).surface_velocity(x)
    }

    /// 2πη/δr: k_V/R and k_Ω/R³ of the coupling's response (module docs), times the
    /// coupling's stiffening in a narrow gap ([`Coupling::stiffening`]).
    fn response(c: &Coupling) -> f64 {
        2.0 * std::f64::consts::PI * c.response_viscosity / c.spacing * c.stiffening
    }

    /// M = m + m_a + δt k_V: the inertia of its translation in the coupling (module docs).
    fn coupled_mass(&self, c: &Coupling) -> f64 {
        let added = self.coupling_added_mass * (c.fluid_density * self.area());
        self.mass() + added + c.dt * Self::response(c) * self.circle.radius
    }

    /// 1/M ([`Self::coupled_mass`]); 0 when its translation is not free.
    pub fn mobility(&self, c: &Coupling) -> f64 {
        if self.motion == Motion::Free {
            1.0 / self.coupled_mass(c)
        } else {
            0.0
        }
    }

    /// Advances V and Ω over one step under `load`, a contact force and the `forcing`
    /// (module docs).
    fn accelerate(&mut self, load: &Load, contact: Vec2, forcing: Forcing, c: &Coupling) {
        let Forcing {
            body_force: g,
            gravity: gs,
            return_gradient: grad,
        } = forcing;
        let (r, dt) = (self.circle.radius, c.dt);
        let k = Self::response(c);
        let spin = |d: &Self| d.spin + dt * load.torque() / (d.inertia() + dt * k * r.powi(3));
        match self.motion {
            Motion::Prescribed => {}
            Motion::FreeRotation => self.spin = spin(self),
            Motion::Free => {
                self.spin = spin(self);
                let displaced = c.fluid_density * self.area();
                let buoyant = self.mass() - displaced;
                let added = self.coupling_added_mass * displaced;
                let force = load.force.total()
                    + contact
                    + self.mass() * g
                    + buoyant * gs
                    + Vec2::new(-self.area() * grad, 0.0)
                    + added * self.acceleration;
                let dv = dt * force / self.coupled_mass(c);
                self.acceleration = dv / dt;
                self.velocity += dv;
            }
        }
    }

    /// c^{n+1} by eq. (27)'s trapezoid, as the particles move, after a velocity change `dv`
    /// of the lubrication (part of this step's acceleration).
    fn move_centre(&mut self, dv: Vec2, c: &Coupling) {
        let dt = c.dt;
        self.acceleration += dv / dt;
        let mean = self.velocity - 0.5 * dt * self.acceleration;
        self.circle.centre = c.domain.wrap(self.circle.centre + dt * mean);
    }
}

/// The discs of a simulation and the walls they own.
#[derive(Clone, Debug, Default)]
pub struct Bodies {
    pub discs: Vec<Disc>,
    /// The index of each disc's wall among the ghosts' walls.
    walls: Vec<usize>,
    /// The load on each disc after the last step.
    pub loads: Vec<Load>,
    /// The contact force on each disc in the last step, repulsion and lubrication (zero
    /// without contact).
    pub contact_forces: Vec<Vec2>,
    /// The short-range repulsion, if switched on.
    pub contact: Option<Contact>,
    /// g_s: gravity on the discs' buoyant mass (sedimentation; module docs).
    pub gravity: Vec2,
    /// The fluid's own body force (the scene's, constant under g_s): what the state's body
    /// force is besides the return flow's −G/ρ_f, so that G needs no state of its own.
    base_force: Vec2,
    tensor: TensorMirror,
}

/// The discs of a scene with their contact model and the sedimentation gravity g_s (zero:
/// none).
pub struct DiscSet {
    pub discs: Vec<Disc>,
    pub contact: Option<Contact>,
    pub gravity: Vec2,
}

/// What accelerates a free disc besides its load and contacts: the body force g, the
/// sedimentation gravity g_s on its buoyant mass, and the return flow's pressure gradient
/// G (x component).
#[derive(Clone, Copy)]
struct Forcing {
    body_force: Vec2,
    gravity: Vec2,
    return_gradient: f64,
}

impl Bodies {
    /// Appends the discs' walls to `walls`.
    pub fn new(
        set: DiscSet,
        base_force: Vec2,
        tensor: TensorMirror,
        walls: &mut Vec<Wall>,
    ) -> Self {
        let DiscSet {
            discs,
            contact,
            gravity,
        } = set;
        let first = walls.len();
        walls.extend(discs.iter().map(|d| d.wall(tensor)));
        Self {
            walls: (first..walls.len()).collect(),
            loads: vec![Load::default(); discs.len()],
            contact_forces: vec![Vec2::zeros(); discs.len()],
            contact,
            gravity,
            base_force,
            discs,
            tensor,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.discs.is_empty()
    }

    /// Whether any disc moves or may move (its mirrors must follow every step).
    pub fn move_walls(&self) -> bool {
        self.discs
            .iter()
            .any(|d| d.motion != Motion::Prescribed || d.velocity != Vec2::zeros())
    }

    /// Puts the discs' walls where the step of `dt` finds the fluid ([`Disc::ahead`]).
    pub fn apply(&self, ghosts: &mut Ghosts, dt: f64) {
        let domain = ghosts.domain;
        for (d, &k) in self.discs.iter().zip(&self.walls) {
            ghosts.set_wall(k, d.ahead(dt, domain.as_ref()).wall(self.tensor));
        }
    }

    /// Sedimentation in a closed container: the fluid a settling disc displaces flows back
    /// past it, the net volume flux Q = Σ_f u_x δV + Σ_d V_x πR² through a cross-section
    /// being zero. A periodic channel has no ends to force that: its pressure is periodic,
    /// and the walls alone would let the disc entrain the whole column until their friction
    /// carried its weight. The missing part is the uniform pressure gradient G of the
    /// container's length, held here as a constraint. The fluid feels it as the body force
    /// −G/ρ_f in the predictor, the discs as −πR²G on their volume ([`Disc::advance`]).
    /// After each step the flux left, Q, is removed by the uniform velocity change
    /// δu = −Q/Σ_f δV (which keeps u divergence-free), and the impulse ρ_f δu joins G for
    /// the next step. At a steady state δu → 0 and the splitting is exact; applied as an
    /// impulse alone, after the viscous solve, G left the walls a slip of G δt/ρ each step
    /// and the terminal velocity an O(δt) error. G lives in the fluid's body force `g`
    /// ([`Self::return_gradient`]); returns that force with the new G. Applied only when
    /// g_s ≠ 0.
    pub fn hold_return_flow(
        &mut self,
        velocity: &mut [Vec2],
        particle_volume: f64,
        rho_f: f64,
        g: Vec2,
        dt: f64,
    ) -> Vec2 {
        if self.gravity == Vec2::zeros() {
            return g;
        }
        let fluid_flux =
            crate::engine::reduce::blocked_sum(velocity.len(), |i| velocity[i].x) * particle_volume;
        let disc_flux: f64 = self.discs.iter().map(|d| d.velocity.x * d.area()).sum();
        let du = (fluid_flux + disc_flux) / (velocity.len() as f64 * particle_volume);
        velocity.iter_mut().for_each(|u| u.x -= du);
        let gradient = self.return_gradient(g, rho_f) + rho_f * du / dt;
        self.base_force - Vec2::new(gradient / rho_f, 0.0)
    }

    /// G, the return flow's pressure gradient in the fluid's body force `g` (0 without g_s).
    pub fn return_gradient(&self, g: Vec2, rho_f: f64) -> f64 {
        if self.gravity == Vec2::zeros() {
            return 0.0;
        }
        rho_f * (self.base_force.x - g.x)
    }

    /// The loads of the fluid state in `view`, then the discs' motion over one step under
    /// the fluid's body force `g` (with the return flow's part in it), the contact's
    /// repulsion explicit and its lubrication implicit.
    pub fn advance(&mut self, view: FluidView, g: Vec2, coupling: &Coupling) {
        let gradient = self.return_gradient(g, coupling.fluid_density);
        let g_own = g + Vec2::new(gradient / coupling.fluid_density, 0.0);
        if let Some(contact) = &self.contact {
            self.contact_forces = contact.forces(&self.discs, &coupling.domain);
        }
        let previous: Vec<Vec2> = self.discs.iter().map(|d| d.velocity).collect();
        let couplings: Vec<Coupling> = (0..self.discs.len())
            .map(|k| coupling.at_gap(contact::narrowest_gap(&self.discs, k, &coupling.domain)))
            .collect();
        let contacts = self.contact_forces.iter();
        for (((d, load), &contact), coupling) in self
            .discs
            .iter_mut()
            .zip(self.loads.iter_mut())
            .zip(contacts)
            .zip(&couplings)
        {
            let disc = d.ahead(coupling.dt, Some(&coupling.domain));
            *load = traction::on_circle(
                view,
                &disc.circle,
                &|x| disc.surface_velocity(x),
                TRACTION_SAMPLES,
            );
            let forcing = Forcing {
                body_force: g_own,
                gravity: self.gravity,
                return_gradient: gradient,
            };
            d.accelerate(load, contact, forcing, coupling);
        }
        let before: Vec<Vec2> = self.discs.iter().map(|d| d.velocity).collect();
        if let Some(contact) = &self.contact {
            let mobility: Vec<f64> = (self.discs.iter().zip(&couplings))
                .map(|(d, c)| d.mobility(c))
                .collect();
            let squeeze = Squeeze {
                mobility: &mobility,
                previous: &previous,
                viscosity: coupling.viscosity,
                dt: coupling.dt,
            };
            let lubrication = contact.lubricate(&mut self.discs, &squeeze, &coupling.domain);
            for (f, l) in self.contact_forces.iter_mut().zip(lubrication) {
                *f += l;
            }
        }
        for (d, v) in self.discs.iter_mut().zip(before) {
            let dv = d.velocity - v;
            d.move_centre(dv, coupling);
        }
    }
}
