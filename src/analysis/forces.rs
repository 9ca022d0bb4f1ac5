//! Forces on bodies: the drag on the fixed cylinder and on a fixed sphere. The surface-stress
//! integration lives in [`crate::engine::bodies::traction`], because free discs need it inside
//! the step.

use crate::engine::bodies::traction::{on_contour, on_plane_wall};
pub use crate::engine::bodies::traction::{BodyForce, FluidView, Load};
use crate::engine::boundary::{Circle, Shape, Sphere};
use crate::engine::math::Vec2;
use crate::engine::step::Simulation;
use serde::{Deserialize, Serialize};

/// The fluid of `sim` as the integration reads it.
pub fn view(sim: &Simulation) -> FluidView<'_> {
    FluidView {
        state: &sim.state,
        kernel: &sim.kernel,
        domain: &sim.domain,
        fluid: &sim.fluid,
        walls: sim.walls(),
    }
}

/// The force on a circle at rest from the fluid of `sim`, integrated with `samples` surface
/// points.
pub fn on_cylinder(sim: &Simulation, circle: &Circle, samples: usize) -> BodyForce {
    on_circle(sim, circle, &|_| Vec2::zeros(), samples).force
}

/// The load on `circle`, whose surface moves at `wall_velocity(x)`.
pub fn on_circle(
    sim: &Simulation,
    circle: &Circle,
    wall_velocity: &dyn Fn(Vec2) -> Vec2,
    samples: usize,
) -> Load {
    crate::engine::bodies::traction::on_circle(view(sim), circle, wall_velocity, samples)
}

/// The x-force the driving pressure gradient exerts on a fixed cylinder, ρ g_x πR².
///
/// The body force g stands for the mean pressure gradient −∇P̄ = ρg of a pressure-driven
/// flow; the projection's periodic pressure p carries none of it. The physical pressure is
/// P = p − ρ g·x, whose part −ρ g·x pushes a body by ρ g·x̂ ∮ x n_x ds = ρ g_x πR² (divergence
/// theorem) — the same force the body force would exert on fluid of the cylinder's area. The
/// grid codes' drag (`cases/confined-cylinder-drag.csv`) is the force of P, so this term is
/// part of K; free discs feel it through their weight m g (`engine::bodies`). Left out, it reads
/// the confined cylinder's Newtonian K 5.3 % low (125.4 against 132.36; ρ g πR²/(η0⟨u⟩) = 7.0).
pub fn displaced(sim: &Simulation, circle: &Circle) -> f64 {
    sim.fluid.density * sim.state.body_force.x * std::f64::consts::PI * circle.radius.powi(2)
}

/// The x-momentum balance of a steady periodic channel with one fixed cylinder, each term in
/// units of η0⟨u⟩ (K's), for the equivalent pressure-driven flow ([`displaced`]): the drive
/// ρ g_x (V + πR²), the mean pressure gradient over the whole box, against the loads of the
/// cylinder (its surface integral, [`on_cylinder`], plus [`displaced`]) and of the plane walls
/// (none in a square array, `scene.walls = false`). In a steady state the fluid's momentum
/// does not change, so `residual` = (body − cylinder − walls)/body vanishes with the
/// discretisation error of the flow and of the integrals. `drag` = body − walls is the
/// cylinder's drag without its surface integral, and `contour` gives it without reading the
/// fields of the wall layers at all.
///
/// V is the particles' volume NδV, the area the body force acts on; at R/δr = 10 it falls
/// short of the box less πR² by about 0.09 (0.15 % of K), at R/δr ≥ 15 by less than 0.02 %.
///
/// Measured (Newtonian, rings = 3, fixed particles, second-order Laplacian): in the confined
/// cylinder `drag` 132.66, 132.50, 132.43 at R/δr = 10, 15, 20 against 132.36, the annuli
/// within 0.3 % of it, the surface integral 139.7 at R/δr = 10; in the square array
/// (c = π/36, first-order Laplacian) −1.45, −0.22, −0.20, −0.04 % from Sangani & Acrivos at
/// R/δr = 10, 15, 20, 40, the surface integral +6.1 % to +2.4 %. The surface fits extrapolate
/// the first layers' fields, and read the drag high by 2–6 % (validation page, *Confined
/// cylinder*).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct MomentumBalance {
    pub body: f64,
    pub cylinder: f64,
    pub walls: f64,
    pub residual: f64,
    /// body − walls: the cylinder's drag from the balance.
    #[serde(default)]
    pub drag: f64,
    /// ρ g_x πR²/(η0⟨u⟩), included in `body`, `cylinder`, `drag` and `contour`.
    #[serde(default)]
    pub displaced: f64,
    /// The cylinder's drag from the momentum balance of the annuli 3, 4 and 5 spacings wide
    /// ([`crate::engine::bodies::traction::on_contour`]); None where the contour's fits would
    /// reach a plane wall.
    pub contour: [Option<f64>; 3],
}

/// The x-loads of the plane walls y = const of `sim` (none in a square array).
fn wall_load(sim: &Simulation) -> (f64, Vec<f64>) {
    let length = sim.domain.max.x - sim.domain.min.x;
    let wall_samples = ((2.0 * length / sim.spacing).ceil() as usize).max(64);
    let planes: Vec<f64> = sim
        .walls()
        .iter()
        .filter_map(|w| match w.shape {
            Shape::Plane(p) if p.axis == 1 => Some(p.position),
            _ => None,
        })
        .collect();
    let load = planes
        .iter()
        .map(|&y| {
            on_plane_wall(view(sim), y, length, Vec2::zeros(), wall_samples)
                .total()
                .x
        })
        .sum();
    (load, planes)
}

/// The drive of the equivalent pressure-driven flow, ρ g_x (V + πR²), V the particles'
/// volume ([`MomentumBalance`]).
fn drive(sim: &Simulation, circle: &Circle) -> f64 {
    sim.fluid.density * sim.fluid_volume() * sim.state.body_force.x + displaced(sim, circle)
}

/// [`MomentumBalance::drag`] alone, in units of η0`u_mean`: the drive less the plates' load.
pub fn balance_drag(sim: &Simulation, circle: &Circle, u_mean: f64) -> f64 {
    (drive(sim, circle) - wall_load(sim).0) / (sim.fluid.viscosity * u_mean)
}

/// [`MomentumBalance`] of `sim` for `circle` (its surface integral over `samples` points)
/// in a channel periodic along x whose walls are the planes y = const of the scene, with mean
/// velocity `u_mean`.
pub fn momentum_balance(
    sim: &Simulation,
    circle: &Circle,
    samples: usize,
    u_mean: f64,
) -> MomentumBalance {
    let scale = 1.0 / (sim.fluid.viscosity * u_mean);
    let (walls, planes) = wall_load(sim);
    let displaced = displaced(sim, circle) * scale;
    let body = drive(sim, circle) * scale;
    let cylinder = on_cylinder(sim, circle, samples).total().x * scale + displaced;
    let walls = walls * scale;
    let clearance = planes
        .iter()
        .map(|y| (circle.centre.y - y).abs())
        .fold(f64::INFINITY, f64::min);
    let contour = [3.0, 4.0, 5.0].map(|m| {
        let r = circle.radius + m * sim.spacing;
        if r + sim.kernel.support() > clearance {
            return None;
        }
        let n = ((4.0 * std::f64::consts::PI * r / sim.spacing).ceil() as usize).max(64);
        let g = sim.state.body_force;
        Some(on_contour(view(sim), circle, r, g, n).x * scale + displaced)
    });
    MomentumBalance {
        body,
        cylinder,
        walls,
        residual: (body - cylinder - walls) / body,
        drag: body - walls,
        displaced,
        contour,
    }
}

/// Zick & Homsy (1982), Table 2, simple cubic arrays: the solid fraction c and the drag
/// coefficient K = F/(6πη a U), U the superficial velocity. The last is close packing,
/// c = π/6.
pub const ZICK_HOMSY_SIMPLE_CUBIC: [(f64, f64); 7] = [
    (0.027, 2.008),
    (0.064, 2.810),
    (0.125, 4.292),
    (0.216, 7.442),
    (0.343, 15.4),
    (0.45, 28.1),
    (std::f64::consts::FRAC_PI_6, 42.1),
];

/// Zick & Homsy's K at solid fraction `c` where their table has it (within 0.1 % of c).
pub fn zick_homsy(c: f64) -> Option<f64> {
    ZICK_HOMSY_SIMPLE_CUBIC
        .iter()
        .find(|(ct, _)| (c - ct).abs() < 1e-3 * ct)
        .map(|&(_, k)| k)
}

/// The x-drag on a fixed sphere, the only sink of momentum in a box periodic along every
/// axis, from the box's momentum balance: ρ g_x (V + (4/3)πa³), V = NδV the particles'
/// volume. The body force stands for a mean pressure gradient, which also pushes the solid
/// ([`displaced`] in the plane); in a steady state the fluid's momentum does not change, so
/// the sphere holds the whole drive. While the flow develops the balance includes the
/// fluid's acceleration, and this is not yet the drag.
pub fn sphere_drag(sim: &Simulation<3>, sphere: &Sphere) -> f64 {
    let solid = 4.0 / 3.0 * std::f64::consts::PI * sphere.radius.powi(3);
    sim.fluid.density * sim.state.body_force[0] * (sim.fluid_volume() + solid)
}
