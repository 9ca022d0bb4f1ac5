//! The axial force of a pipe's wall on the fluid, and with it a body's drag from the pipe's
//! momentum balance. In a steady state the fluid's momentum does not change, so along the
//! axis the body force (standing for the mean pressure gradient), the wall and the body
//! balance:
//!
//!   F_x = ρ g_x (V + V_s) + W_x,   W_x = −∮_wall (σ·n)_x dA,
//!
//! F_x the fluid's drag on the body, V the particles' volume, V_s the body's (which the mean
//! gradient also pushes, as in `analysis::forces::sphere_drag`), n the wall's normal into
//! the fluid. The pressure has no axial part on the wall, so (σ·n)_x = (2η_s D·n + τ_p·n)_x,
//! fitted at points on the wall as the sphere's torque is
//! ([`crate::engine::bodies::sphere::wall_traction`]): the velocity quadratic with the
//! wall's velocity imposed, τ_p linear. It reads the drag without the body's surface or a
//! control surface around it, so beside them it shows how well the balance closes.

use crate::engine::bodies::sphere::wall_traction;
use crate::engine::dimension::Vector;
use crate::engine::step::Simulation;
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Wall points per δr² of the wall's area.
const SAMPLES_PER_AREA: f64 = 2.0;

/// The inside of a pipe along x: its axis at (y, z) = `axis`, its radius, and the wall's
/// velocity along x.
#[derive(Clone, Copy, Debug)]
pub struct PipeWall {
    pub axis: [f64; 2],
    pub radius: f64,
    pub velocity: f64,
}

/// W_x (module docs) over the whole periodic length; None where a fit is singular.
pub fn axial_load(sim: &Simulation<3>, wall: PipeWall) -> Option<f64> {
    let s = &sim.state;
    let (dr, support) = (sim.spacing, sim.kernel.support());
    let length = sim.domain.max.x - sim.domain.min.x;
    let [cy, cz] = wall.axis;
    let from_wall = |p: &Vector<3>| wall.radius - (p.y - cy).hypot(p.z - cz);
    // The particles within a support of the wall, in slabs along x a support or more
    // long, so that each wall point looks at its own slab and the two beside it.
    let slabs = ((length / support).floor() as usize).max(3);
    let slab = |x: f64| (((x - sim.domain.min.x) / length * slabs as f64) as usize).min(slabs - 1);
    let mut near: Vec<Vec<usize>> = vec![Vec::new(); slabs];
    for (i, p) in s.position.iter().enumerate() {
        if from_wall(p) < support {
            near[slab(p.x)].push(i);
        }
    }
    let per_length = ((SAMPLES_PER_AREA.sqrt() * length / dr).ceil() as usize).max(1);
    let around = ((SAMPLES_PER_AREA.sqrt() * TAU * wall.radius / dr).ceil() as usize).max(8);
    let area = length * TAU * wall.radius / (per_length * around) as f64;
    let view = sim.sphere_view();
    let uw = Vector::<3>::new(wall.velocity, 0.0, 0.0);
    let axial: Option<Vec<f64>> = (0..per_length * around)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k / around, k % around);
            let x = sim.domain.min.x + (i as f64 + 0.5) * length / per_length as f64;
            let theta = TAU * (j as f64 + 0.5 * (i % 2) as f64) / around as f64;
            let (c, sn) = (theta.cos(), theta.sin());
            let point = Vector::<3>::new(x, cy + wall.radius * c, cz + wall.radius * sn);
            let n = Vector::<3>::new(0.0, -c, -sn);
            let m = slab(x);
            let candidates: Vec<usize> = [m + slabs - 1, m, m + 1]
                .iter()
                .flat_map(|&b| near[b % slabs].iter().copied())
                .collect();
            wall_traction(view, &candidates, point, &n, uw).map(|t| t.x)
        })
        .collect();
    Some(-axial?.iter().sum::<f64>() * area)
}

/// The drag F_x on a body of volume `body_volume` in the pipe whose wall's load is
/// `wall_load` ([`axial_load`]; module docs).
pub fn body_drag(sim: &Simulation<3>, wall_load: f64, body_volume: f64) -> f64 {
    let drive = sim.fluid.density * sim.state.body_force.x * (sim.fluid_volume() + body_volume);
    drive + wall_load
}
