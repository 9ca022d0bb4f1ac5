//! The load of the fluid on a solid circle: the force F = ∮ σ·n dS with σ = −pI + 2η_s D +
//! τ_p and n the body's outward normal, and the torque T = ∮ (x − c) × (σ·n) dS about its
//! centre, each split into pressure, solvent and polymer parts (per unit length, 2D). The
//! pressure has no torque on a circle (σ·n ∥ n ∥ x − c); its part is kept as a check.
//!
//! The surface values come from weighted least-squares fits (quintic-kernel weights, one
//! support) through the fluid particles around each of `samples` surface points: p and τ_p
//! linear (the wall value is the fit's constant), each velocity component quadratic with
//! u = u_w imposed at the wall point (no slip on a wall moving at u_w), whose linear
//! coefficients are ∇u at the wall. Both are exact for the fields they fit, so the surface
//! stress is second-order accurate.
//!
//! Where another no-slip wall (a plane wall, another disc) lies within one support of a
//! surface point, the velocity fits also take that wall's own velocity at the foot of each
//! fitted particle on it ([`other_walls`]). Without it a gap of about a spacing held one or
//! two particles and the fit extrapolated from the particles beside it, blind to the wall a
//! spacing away: a disc settling onto the floor (R/δr = 8, gap 1.1δr) felt a tangential force
//! along its own velocity, ≈ +1 000 V, and rolled away, its speed doubling every step (validation pages,
//! *Rigid discs*). Gaps wider than a support (every fixed body and every disc kept a support
//! apart) are unchanged.

use crate::engine::boundary::{Circle, Wall};
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::{Mat2, Sym2, Vec2};
use crate::engine::neighbours::Domain;
use crate::engine::rheology::Fluid;
use crate::engine::state::State;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// A force and its parts.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct BodyForce {
    pub pressure: [f64; 2],
    pub solvent: [f64; 2],
    pub polymer: [f64; 2],
}

/// A force and a torque (about the body's centre, counter-clockwise positive), with parts.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct Load {
    pub force: BodyForce,
    /// Pressure, solvent and polymer torques.
    pub torque: [f64; 3],
}

impl Load {
    pub fn torque(&self) -> f64 {
        self.torque.iter().sum()
    }
}

impl BodyForce {
    /// Adds pressure, solvent and polymer parts.
    fn add(&mut self, [fp, fs, ft]: [Vec2; 3]) {
        for a in 0..2 {
            self.pressure[a] += fp[a];
            self.solvent[a] += fs[a];
            self.polymer[a] += ft[a];
        }
    }

    pub fn total(&self) -> Vec2 {
        Vec2::new(
            self.pressure[0] + self.solvent[0] + self.polymer[0],
            self.pressure[1] + self.solvent[1] + self.polymer[1],
        )
    }
}

/// Weighted least squares with a fixed number of basis functions.
pub fn fit<const K: usize>(rows: &[([f64; K], f64, f64)]) -> Option<DVector<f64>> {
    let mut m = DMatrix::<f64>::zeros(K, K);
    let mut b = DVector::<f64>::zeros(K);
    for (basis, value, weight) in rows {
        let phi = DVector::<f64>::from_row_slice(basis);
        m += *weight * &phi * phi.transpose();
        b += *weight * *value * &phi;
    }
    m.lu().solve(&b)
}

/// The value at the origin of linear fits of τ_xx, τ_xy, τ_yy; None where one is singular.
fn tensor_fit(rows: &[Vec<([f64; 3], f64, f64)>; 3]) -> Option<Sym2> {
    let [xx, xy, yy] = [&rows[0], &rows[1], &rows[2]].map(|r| fit(r).map(|c| c[0]));
    Some(Sym2::new(xx?, xy?, yy?))
}

/// What the integration reads of a simulation.
#[derive(Clone, Copy)]
pub struct FluidView<'a> {
    pub state: &'a State,
    pub kernel: &'a QuinticSpline,
    pub domain: &'a Domain,
    pub fluid: &'a Fluid,
    /// Every wall of the step (the scene's and the discs'), for [`other_walls`].
    pub walls: &'a [Wall],
}

/// The traction σ·n at one surface point (moving at `uw`, outward normal `n` of the body),
/// split into its pressure, solvent and polymer parts; None where a fit is singular.
fn traction_at(
    view: &FluidView,
    near: &[usize],
    point: Vec2,
    n: Vec2,
    uw: Vec2,
) -> Option<[Vec2; 3]> {
    let FluidView {
        state: s,
        kernel,
        domain,
        fluid,
        ..
    } = *view;
    let support = kernel.support();
    let viscoelastic = fluid.model.is_viscoelastic();
    let (mut linear, mut quadratic_u, mut quadratic_v) = (Vec::new(), Vec::new(), Vec::new());
    let mut tau_rows: [Vec<([f64; 3], f64, f64)>; 3] = Default::default();
    for &i in near {
        let d = domain.min_image(s.position[i] - point);
        let r = d.norm();
        if r >= support {
            continue;
        }
        let w = kernel.value(r);
        let (x, y) = (d.x / kernel.h(), d.y / kernel.h());
        linear.push(([1.0, x, y], s.pressure[i], w));
        if viscoelastic {
            let t = fluid.polymer_stress(&s.conformation[i]);
            for (rows, value) in tau_rows.iter_mut().zip([t.xx, t.xy, t.yy]) {
                rows.push(([1.0, x, y], value, w));
            }
        }
        let q = [x, y, x * x, x * y, y * y];
        quadratic_u.push((q, s.velocity[i].x - uw.x, w));
        quadratic_v.push((q, s.velocity[i].y - uw.y, w));
    }
    for (d, u) in other_walls(view, near, point) {
        let w = kernel.value(d.norm());
        let (x, y) = (d.x / kernel.h(), d.y / kernel.h());
        let q = [x, y, x * x, x * y, y * y];
        quadratic_u.push((q, u.x - uw.x, w));
        quadratic_v.push((q, u.y - uw.y, w));
    }
    let (p, gu, gv) = (fit(&linear)?, fit(&quadratic_u)?, fit(&quadratic_v)?);
    let polymer = if viscoelastic {
        tensor_fit(&tau_rows)?
    } else {
        Sym2::ZERO
    };
    let h = kernel.h();
    let grad = Mat2::new(gu[0] / h, gu[1] / h, gv[0] / h, gv[1] / h);
    let strain = Sym2::sym_part(&grad) * (2.0 * fluid.solvent_viscosity());
    Some([-p[0] * n, strain.dot(&n), polymer.dot(&n)])
}

/// The no-slip points of the walls other than the surface at `point` that lie within one
/// support of it: for each particle of `near` within the support, the foot of its normal on
/// that wall (relative to `point`), with the wall's velocity there (half the mirror offset
/// 2u_w of a no-slip condition), where the foot is within the support too.
fn other_walls(view: &FluidView, near: &[usize], point: Vec2) -> Vec<(Vec2, Vec2)> {
    let (s, domain) = (view.state, view.domain);
    let support = view.kernel.support();
    let mut rows = Vec::new();
    for wall in view.walls {
        let gap = wall
            .shape
            .distance(&wall.shape.nearest_image(&point, Some(domain)));
        let no_slip = wall.condition.velocity_sign() < 0.0;
        if !no_slip || gap <= 1e-9 * support || gap >= support {
            continue;
        }
        for &i in near {
            let d = domain.min_image(s.position[i] - point);
            if d.norm() >= support {
                continue;
            }
            let p = wall.shape.nearest_image(&(point + d), Some(domain));
            let foot = 0.5 * (p + wall.shape.reflect(&p));
            let at = d + (foot - p);
            if at.norm() < support {
                rows.push((at, 0.5 * wall.condition.velocity_offset(foot)));
            }
        }
    }
    rows
}

/// The load on `circle`, whose surface moves at `wall_velocity(x)`, from the fluid, integrated
/// with `samples` surface points.
pub fn on_circle(
    view: FluidView,
    circle: &Circle,
    wall_velocity: &dyn Fn(Vec2) -> Vec2,
    samples: usize,
) -> Load {
    let s = view.state;
    let support = view.kernel.support();
    // Particles that can be within one support of the surface.
    let near: Vec<usize> = (0..s.position.len())
        .filter(|&i| {
            let d = view.domain.min_image(s.position[i] - circle.centre);
            d.norm() - circle.radius < support
        })
        .collect();
    let arc = 2.0 * std::f64::consts::PI * circle.radius / samples as f64;
    let mut load = Load::default();
    for k in 0..samples {
        let theta = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / samples as f64;
        let n = Vec2::new(theta.cos(), theta.sin());
        let point = circle.centre + circle.radius * n;
        let Some(parts) = traction_at(&view, &near, point, n, wall_velocity(point)) else {
            continue;
        };
        let [fp, fs, ft] = parts.map(|t| t * arc);
        load.force.add([fp, fs, ft]);
        let arm = point - circle.centre;
        for (t, part) in load.torque.iter_mut().zip([fp, fs, ft]) {
            *t += arm.x * part.y - arm.y * part.x;
        }
    }
    load
}

/// The force of the fluid on the plane wall y = `height` of a periodic channel of `length`
/// (the floor at 0 when `height` is 0, the lid otherwise), moving at `uw`, from `samples`
/// points along it.
pub fn on_plane_wall(
    view: FluidView,
    height: f64,
    length: f64,
    uw: Vec2,
    samples: usize,
) -> BodyForce {
    let s = view.state;
    let support = view.kernel.support();
    let near: Vec<usize> = (0..s.position.len())
        .filter(|&i| (s.position[i].y - height).abs() < support)
        .collect();
    // The body (the wall) lies below the floor and above the lid.
    let n = Vec2::new(0.0, if height == 0.0 { 1.0 } else { -1.0 });
    let dx = length / samples as f64;
    let mut force = BodyForce::default();
    for k in 0..samples {
        let point = Vec2::new((k as f64 + 0.5) * dx, height);
        let Some(parts) = traction_at(&view, &near, point, n, uw) else {
            continue;
        };
        force.add(parts.map(|t| t * dx));
    }
    force
}

/// The force on `circle` from a momentum balance over the annulus between it and the
/// concentric contour of `radius`: F = ∮ (σ − ρuu)·n dS over the contour + ρ g A_annulus, for a
/// steady flow under the body force `g` per unit mass. The contour's stress comes from fits
/// through interior particles only (p linear, u quadratic, each with its constant), so it does
/// not read the wall layers' fields that the surface integral [`on_circle`] extrapolates.
pub fn on_contour(view: FluidView, circle: &Circle, radius: f64, g: Vec2, samples: usize) -> Vec2 {
    let FluidView {
        state: s,
        kernel,
        domain,
        fluid,
        ..
    } = view;
    let support = kernel.support();
    let h = kernel.h();
    let near: Vec<usize> = (0..s.position.len())
        .filter(|&i| {
            let d = domain.min_image(s.position[i] - circle.centre).norm();
            (d - radius).abs() < support
        })
        .collect();
    let arc = 2.0 * std::f64::consts::PI * radius / samples as f64;
    let mut force = Vec2::zeros();
    for k in 0..samples {
        let theta = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / samples as f64;
        let n = Vec2::new(theta.cos(), theta.sin());
        let point = circle.centre + radius * n;
        let (mut linear, mut qu, mut qv) = (Vec::new(), Vec::new(), Vec::new());
        let mut tau: [Vec<([f64; 3], f64, f64)>; 3] = Default::default();
        for &i in &near {
            let d = domain.min_image(s.position[i] - point);
            if d.norm() >= support {
                continue;
            }
            let w = kernel.value(d.norm());
            let (x, y) = (d.x / h, d.y / h);
            linear.push(([1.0, x, y], s.pressure[i], w));
            let q = [1.0, x, y, x * x, x * y, y * y];
            qu.push((q, s.velocity[i].x, w));
            qv.push((q, s.velocity[i].y, w));
            if fluid.model.is_viscoelastic() {
                let t = fluid.polymer_stress(&s.conformation[i]);
                for (rows, v) in tau.iter_mut().zip([t.xx, t.xy, t.yy]) {
                    rows.push(([1.0, x, y], v, w));
                }
            }
        }
        let (Some(p), Some(gu), Some(gv)) = (fit(&linear), fit(&qu), fit(&qv)) else {
            continue;
        };
        let polymer = match fluid.model.is_viscoelastic() {
            true => tensor_fit(&tau),
            false => Some(Sym2::ZERO),
        };
        let Some(polymer) = polymer else {
            continue;
        };
        let grad = Mat2::new(gu[1] / h, gu[2] / h, gv[1] / h, gv[2] / h);
        let strain = Sym2::sym_part(&grad) * (2.0 * fluid.solvent_viscosity());
        let u = Vec2::new(gu[0], gv[0]);
        let flux = u * (fluid.density * u.dot(&n));
        force += (-p[0] * n + strain.dot(&n) + polymer.dot(&n) - flux) * arc;
    }
    let area = std::f64::consts::PI * (radius * radius - circle.radius * circle.radius);
    force + g * (fluid.density * area)
}
