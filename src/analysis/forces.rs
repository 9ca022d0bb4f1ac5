//! The force of the fluid on a solid cylinder, F = ∮ σ·n dS with σ = −pI + 2η_s D + τ_p and n
//! the body's outward normal, split into its pressure, solvent and polymer parts, and the
//! drag coefficient K = F_x/(η0 ⟨u⟩) (per unit length, 2D).
//!
//! The surface values come from weighted least-squares fits (quintic-kernel weights, one
//! support) through the fluid particles around each of `samples` surface points: p and τ_p
//! linear (the wall value is the fit's constant), each velocity component quadratic with
//! u = 0 imposed at the wall point (no slip), whose linear coefficients are ∇u at the wall.
//! Both are exact for the fields they fit, so the surface stress is second-order accurate.

use crate::engine::boundary::Circle;
use crate::engine::math::{Mat2, Sym2, Vec2};
use crate::engine::step::Simulation;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// A force and its parts.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct BodyForce {
    pub pressure: [f64; 2],
    pub solvent: [f64; 2],
    pub polymer: [f64; 2],
}

impl BodyForce {
    pub fn total(&self) -> Vec2 {
        Vec2::new(
            self.pressure[0] + self.solvent[0] + self.polymer[0],
            self.pressure[1] + self.solvent[1] + self.polymer[1],
        )
    }
}

/// Weighted least squares with a fixed number of basis functions.
fn fit<const K: usize>(rows: &[([f64; K], f64, f64)]) -> Option<DVector<f64>> {
    let mut m = DMatrix::<f64>::zeros(K, K);
    let mut b = DVector::<f64>::zeros(K);
    for (basis, value, weight) in rows {
        let phi = DVector::<f64>::from_row_slice(basis);
        m += *weight * &phi * phi.transpose();
        b += *weight * *value * &phi;
    }
    m.lu().solve(&b)
}

/// The force on `circle` from the fluid of `sim`, integrated with `samples` surface points.
pub fn on_cylinder(sim: &Simulation, circle: &Circle, samples: usize) -> BodyForce {
    let s = &sim.state;
    let kernel = &sim.kernel;
    let support = kernel.support();
    let domain = &sim.domain;
    let tau = sim.polymer_stress();
    let eta_s = sim.fluid.solvent_viscosity();
    // Particles that can be within one support of the surface.
    let near: Vec<usize> = (0..s.position.len())
        .filter(|&i| circle.distance(&s.position[i]) < support)
        .collect();
    let arc = 2.0 * std::f64::consts::PI * circle.radius / samples as f64;
    let mut force = BodyForce::default();
    for k in 0..samples {
        let theta = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / samples as f64;
        let n = Vec2::new(theta.cos(), theta.sin());
        let point = circle.centre + circle.radius * n;
        let (mut linear, mut quadratic_u, mut quadratic_v) = (Vec::new(), Vec::new(), Vec::new());
        let mut tau_rows: [Vec<([f64; 3], f64, f64)>; 3] = Default::default();
        for &i in &near {
            let d = domain.min_image(s.position[i] - point);
            let r = d.norm();
            if r >= support {
                continue;
            }
            let w = kernel.value(r);
            let (x, y) = (d.x / kernel.h(), d.y / kernel.h());
            linear.push(([1.0, x, y], s.pressure[i], w));
            for (rows, value) in tau_rows.iter_mut().zip([tau[i].xx, tau[i].xy, tau[i].yy]) {
                rows.push(([1.0, x, y], value, w));
            }
            let q = [x, y, x * x, x * y, y * y];
            quadratic_u.push((q, s.velocity[i].x, w));
            quadratic_v.push((q, s.velocity[i].y, w));
        }
        let (Some(p), Some(gu), Some(gv)) = (fit(&linear), fit(&quadratic_u), fit(&quadratic_v))
        else {
            continue;
        };
        let t: Vec<f64> = tau_rows
            .iter()
            .filter_map(|rows| fit(rows).map(|c| c[0]))
            .collect();
        if t.len() != 3 {
            continue;
        }
        let h = kernel.h();
        let grad = Mat2::new(gu[0] / h, gu[1] / h, gv[0] / h, gv[1] / h);
        let strain = Sym2::sym_part(&grad) * (2.0 * eta_s);
        let polymer = Sym2::new(t[0], t[1], t[2]);
        let fp = -p[0] * n * arc;
        let fs = strain.dot(&n) * arc;
        let ft = polymer.dot(&n) * arc;
        for a in 0..2 {
            force.pressure[a] += fp[a];
            force.solvent[a] += fs[a];
            force.polymer[a] += ft[a];
        }
    }
    force
}
