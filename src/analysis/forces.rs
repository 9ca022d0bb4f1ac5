//! Forces on bodies: the drag on the fixed cylinder. The surface-stress integration lives in
//! [`crate::engine::bodies::traction`], because free discs need it inside the step.

pub use crate::engine::bodies::traction::{BodyForce, FluidView, Load};
use crate::engine::boundary::Circle;
use crate::engine::math::Vec2;
use crate::engine::step::Simulation;

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
