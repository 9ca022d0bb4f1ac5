//! The force of the fluid on a fixed sphere, read off a control sphere around it: the
//! momentum balance of the fluid between the body and a sphere S_r of radius r > a,
//!
//!   F = ∮_{S_r} (σ·n − ρ u (u·n)) dA + ρ g (4/3)π(r³ − a³) + ρ g (4/3)πa³,
//!
//! σ = −pI + 2η_s D + τ_p, in a steady state (the fluid's momentum inside does not change). The
//! last term is the mean pressure gradient's push on the solid that the body force stands
//! for (as in `analysis::forces::sphere_drag`). On S_r the fields are smooth and every
//! particle's support is full, so the surface values are fitted from the particles alone, as
//! the plane's contour integral does ([`crate::engine::bodies::traction::on_contour`]):
//! p and τ_p linear, each velocity component quadratic, in weighted least squares about each
//! surface point (quintic-kernel weights, one support). Beside the box's momentum balance it
//! gives the drag without the body force of every particle, so the two disagree by the
//! discretisation error of the flow near the body and of the integral.

use crate::engine::bodies::sphere::{fibonacci, PolymerFits};
use crate::engine::bodies::traction::fit;
use crate::engine::boundary::Sphere;
use crate::engine::dimension::Vector;
use crate::engine::math::{Mat3, Sym3};
use crate::engine::step::Simulation;
use rayon::prelude::*;

/// A fitted surface point: its stress traction less the momentum flux, σ·n − ρu(u·n).
fn traction(
    sim: &Simulation<3>,
    near: &[usize],
    tau: &[Sym3],
    point: Vector<3>,
    n: Vector<3>,
) -> Option<Vector<3>> {
    let s = &sim.state;
    let (h, support) = (sim.kernel.h(), sim.kernel.support());
    let viscoelastic = sim.fluid.model.is_viscoelastic();
    let mut linear = Vec::new();
    let mut quadratic: [Vec<([f64; 10], f64, f64)>; 3] = Default::default();
    let mut polymer = PolymerFits::default();
    for &i in near {
        let d = sim.domain.min_image(s.position[i] - point);
        if d.norm() >= support {
            continue;
        }
        let w = sim.kernel.value(d.norm());
        let (x, y, z) = (d.x / h, d.y / h, d.z / h);
        let l = [1.0, x, y, z];
        linear.push((l, s.pressure[i], w));
        let q = [1.0, x, y, z, x * x, x * y, x * z, y * y, y * z, z * z];
        for (a, rows) in quadratic.iter_mut().enumerate() {
            rows.push((q, s.velocity[i][a], w));
        }
        if viscoelastic {
            polymer.push(l, &tau[i], w);
        }
    }
    let p = fit(&linear)?[0];
    let mut u = Vector::<3>::zeros();
    let mut grad = Mat3::zeros();
    for (a, rows) in quadratic.iter().enumerate() {
        let c = fit(rows)?;
        u[a] = c[0];
        for b in 0..3 {
            grad[(a, b)] = c[1 + b] / h;
        }
    }
    let tau_p = match viscoelastic {
        true => polymer.value()?,
        false => Sym3::ZERO,
    };
    let strain = Sym3::sym_part(&grad) * (2.0 * sim.fluid.solvent_viscosity());
    let flux = u * (sim.fluid.density * u.dot(&n));
    Some(-p * n + strain.dot(&n) + tau_p.dot(&n) - flux)
}

/// The force on `sphere` from the control sphere of `radius` about its centre (module docs),
/// integrated over `samples` points of a Fibonacci spiral (each an equal area); None where a
/// fit fails (a surface point without enough particles about it).
pub fn on_control_sphere(
    sim: &Simulation<3>,
    sphere: &Sphere,
    radius: f64,
    samples: usize,
) -> Option<Vector<3>> {
    let s = &sim.state;
    let support = sim.kernel.support();
    let near: Vec<usize> = (0..s.position.len())
        .filter(|&i| {
            let d = sim.domain.min_image(s.position[i] - sphere.centre).norm();
            (d - radius).abs() < support
        })
        .collect();
    let tau = sim.polymer_stress();
    let area = 4.0 * std::f64::consts::PI * radius * radius / samples as f64;
    let normals: Vec<Vector<3>> = fibonacci(samples, 0.0).collect();
    let surface: Option<Vec<Vector<3>>> = normals
        .par_iter()
        .map(|&n| traction(sim, &near, &tau, sphere.centre + n * radius, n))
        .collect();
    let integral: Vector<3> = surface?.iter().sum::<Vector<3>>() * area;
    let enclosed = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    Some(integral + s.body_force * (sim.fluid.density * enclosed))
}
