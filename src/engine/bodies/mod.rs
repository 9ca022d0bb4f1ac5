//! Rigid discs in the flow (the 2D counterpart of the suspended spheres of Vázquez-Quesada &
//! Ellero 2017): each is a circular wall whose mirrors carry its surface velocity
//! V + Ω ẑ × (x − c) ([`RigidNoSlip`]), moving as prescribed or as the fluid's load moves it.
//!
//! The coupling is staggered: the step runs with the discs' V^n, Ω^n, c^n as boundary
//! conditions; then the load of the new fluid state ([`traction`]) advances them,
//!
//!   (I + δt k_Ω)(Ω^{n+1} − Ω^n)/δt = T,
//!   (m + m_a + δt k_V)(V^{n+1} − V^n)/δt = F + m g + m_a a^n,   c^{n+1} = c^n + δt V^{n+1},
//!
//! with m = ρ_s πR², I = ½mR², g the scene's body force (acting on the disc's mass as on the
//! fluid's: the projection's pressure carries no hydrostatic part of a periodic body force;
//! what the pressure balances it carries, and F includes that), and a^n the previous step's
//! acceleration. The k and m_a terms vanish at a steady state and keep the explicit coupling
//! stable: the load responds within one step to the disc's own velocity, through the first
//! particle layer (the mirrors carry 2u_w), by ΔT ≈ −k_Ω ΔΩ and ΔF ≈ −k_V ΔV with
//! k_Ω = 2πη R³/δr, k_V = 2πη R/δr (η = η_s + Gδt, the solvent and the polymer's elastic
//! response over a step; measured: T changed by 7.9·10³ when Ω went from −8.2 to 8.2 at
//! R/δr = 8, η = 10, i.e. k_Ω = 482, against 2πηR³/δr = 503). Without the k_Ω term the freely
//! rotating disc of `cases/disc-in-shear.toml` flipped its spin every step (δt k_Ω/I = 2.1 > 2).
//! m_a = ρ_f πR² is the added mass of a circle (potential flow), the classic instability of
//! explicit coupling for light bodies; free discs are kept to ρ_s ≥ ρ_f.

pub mod contact;
pub mod traction;

use crate::engine::boundary::{Circle, Ghosts, RigidNoSlip, Shape, TensorMirror, Wall};
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use contact::Contact;
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
}

/// The evolving part of a disc (what a checkpoint stores).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscMotion {
    pub centre: Vec2,
    pub velocity: Vec2,
    pub spin: f64,
    pub acceleration: Vec2,
}

/// What the coupling's stabilising terms need of the fluid and the step.
#[derive(Clone, Copy, Debug)]
pub struct Coupling {
    /// ρ_f.
    pub fluid_density: f64,
    /// η = η_s + Gδt: the viscosity of the load's response within one step.
    pub response_viscosity: f64,
    /// δr.
    pub spacing: f64,
    pub dt: f64,
    /// The box (a disc's centre wraps across its periodic ends).
    pub domain: Domain,
}

impl Disc {
    pub fn mass(&self) -> f64 {
        self.density * std::f64::consts::PI * self.circle.radius.powi(2)
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
        }
    }

    /// u_w at a surface point.
    pub fn surface_velocity(&self, x: Vec2) -> Vec2 {
        self.condition(TensorMirror::Even).surface_velocity(x)
    }

    /// Advances V, Ω and c over one step under `load`, a contact force and the body force
    /// `g` (module docs).
    fn advance(&mut self, load: &Load, contact: Vec2, g: Vec2, c: &Coupling) {
        let (r, dt) = (self.circle.radius, c.dt);
        let k = 2.0 * std::f64::consts::PI * c.response_viscosity / c.spacing;
        let spin = |d: &Self| d.spin + dt * load.torque() / (d.inertia() + dt * k * r.powi(3));
        match self.motion {
            Motion::Prescribed => {}
            Motion::FreeRotation => self.spin = spin(self),
            Motion::Free => {
                self.spin = spin(self);
                let added = c.fluid_density * std::f64::consts::PI * r * r;
                let force =
                    load.force.total() + contact + self.mass() * g + added * self.acceleration;
                let dv = dt * force / (self.mass() + added + dt * k * r);
                self.acceleration = dv / dt;
                self.velocity += dv;
            }
        }
        self.circle.centre = c.domain.wrap(self.circle.centre + dt * self.velocity);
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
    /// The contact force on each disc in the last step (zero without contact).
    pub contact_forces: Vec<Vec2>,
    /// The short-range repulsion, if switched on.
    pub contact: Option<Contact>,
    tensor: TensorMirror,
}

impl Bodies {
    /// Appends the discs' walls to `walls`.
    pub fn new(
        discs: Vec<Disc>,
        contact: Option<Contact>,
        tensor: TensorMirror,
        walls: &mut Vec<Wall>,
    ) -> Self {
        let first = walls.len();
        walls.extend(discs.iter().map(|d| d.wall(tensor)));
        Self {
            walls: (first..walls.len()).collect(),
            loads: vec![Load::default(); discs.len()],
            contact_forces: vec![Vec2::zeros(); discs.len()],
            contact,
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

    /// Puts the discs' current positions and velocities into their walls.
    pub fn apply(&self, ghosts: &mut Ghosts) {
        for (d, &k) in self.discs.iter().zip(&self.walls) {
            ghosts.set_wall(k, d.wall(self.tensor));
        }
    }

    /// The loads of the fluid state in `view`, then the discs' motion over one step.
    pub fn advance(&mut self, view: FluidView, g: Vec2, coupling: &Coupling) {
        if let Some(contact) = &self.contact {
            self.contact_forces = contact.forces(&self.discs, &coupling.domain);
        }
        let contacts = self.contact_forces.iter();
        for ((d, load), &contact) in self
            .discs
            .iter_mut()
            .zip(self.loads.iter_mut())
            .zip(contacts)
        {
            let disc = *d;
            *load = traction::on_circle(
                view,
                &disc.circle,
                &|x| disc.surface_velocity(x),
                TRACTION_SAMPLES,
            );
            d.advance(load, contact, g, coupling);
        }
    }
}
