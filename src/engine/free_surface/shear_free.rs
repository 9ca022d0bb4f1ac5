//! The shear-free condition in the viscous term of the surface rows
//! (`experimental.surface_shear = "shear-free"`).
//!
//! A free surface carries no tangential stress: t·(τ − pI)·n = 0, i.e.
//! ∂u_t/∂n = −∂u_n/∂t for a Newtonian liquid. The Laplacian of (21) on a surface particle's
//! truncated support has no neighbours beyond the surface, so it carries no flux through it:
//! it imposes ∂u/∂n = 0 there. The normal part of that flux is the normal viscous stress,
//! which (35a) already puts into the Dirichlet pressure. The tangential part is missing. For a
//! linear field u = G r the truncated sum gives G c_i, with c_i = Σ_j w_ij r_ij, zero in a
//! full support. |c_i| is the surface's length per unit area that the sum misses, and
//! −c_i/|c_i| is its outward normal n. So the missing tangential flux is supplied as
//!
//! `a_i = ν φ_i |c_i| (∂u_t/∂n) t = −ν φ_i |c_i| (n·G_i t) t`
//!
//! on FS particles, with G = ∇u of the step and φ the viscosity factor of a generalised
//! Newtonian fluid. The term is explicit (its rate ν|c|/δr is that of the explicit viscous
//! term on one row of particles).
//!
//! Measured on the oscillating drop (Oh = 0.05, second-order gradient, midpoint curvature),
//! decay rate against the exact linear theory 0.1773:
//! * without the term: 0.1761, 0.1573, 0.1504 at R/δr = 10, 20, 40 (−0.7, −11, −15 %, not
//!   converging);
//! * with it: 0.2221, 0.1936, 0.1834 (+25, +9.2, +3.4 %, order about 1.4).
//!
//! Adding the normal part as well (|c|(n·G n)n) over-damps (+32, +14 % at R/δr = 10, 20). So
//! does applying the term on the next row in (NS) as well (+34, +17 %). Linear theory
//! splits the damping of a capillary wave half and half between the normal stress and the
//! vortical layer of the shear-free condition. The deficit without the term is the second
//! half, not resolved.

use crate::engine::free_surface::FreeSurface;
use crate::engine::math::{Mat2, Vec2};
use crate::engine::neighbourhood::Hood;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The viscous term's tangential flux through a free surface (`experimental.surface_shear`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceShear {
    /// None: the truncated Laplacian of (21), which imposes ∂u_t/∂n = 0 (the paper's).
    #[default]
    Truncated,
    /// The shear-free condition's flux, ∂u_t/∂n = −∂u_n/∂t (module docs).
    ShearFree,
}

/// The accelerations of the shear-free flux, with their buffer.
#[derive(Clone, Debug, Default)]
pub struct ShearFreeSurface {
    acceleration: Vec<Vec2>,
}

impl ShearFreeSurface {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.acceleration)
    }

    /// a_i of the module docs for every fluid particle (zero off FS), from ∇u (`grad_u`),
    /// ν and the viscosity factor φ (fluid then ghosts; empty: uniform).
    pub fn accelerations(
        &mut self,
        hood: Hood,
        surface: &FreeSurface,
        grad_u: &[Mat2],
        nu: f64,
        factor: &[f64],
    ) -> &[Vec2] {
        let list = hood.list;
        self.acceleration.resize(list.rows(), Vec2::zeros());
        self.acceleration
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, a)| {
                *a = if surface.on_surface[i] {
                    let phi = factor.get(i).copied().unwrap_or(1.0);
                    nu * phi * tangential_flux(i, hood, &grad_u[i])
                } else {
                    Vec2::zeros()
                };
            });
        &self.acceleration
    }
}

/// |c_i| (∂u_t/∂n) t with ∂u_t/∂n = −n·G t, n = −c_i/|c_i| (module docs).
fn tangential_flux(i: usize, hood: Hood, g: &Mat2) -> Vec2 {
    let Hood { list, sums, .. } = hood;
    let c: Vec2 = list
        .range(i)
        .map(|k| sums.laplacian_weight(list, k) * list.rij[k])
        .sum();
    let missing = c.norm();
    if missing == 0.0 {
        return Vec2::zeros();
    }
    let n = -c / missing;
    let t = Vec2::new(-n.y, n.x);
    -missing * n.dot(&(g * t)) * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::neighbours::Domain;

    /// A slab of particles with its free surface at the top (y = H), in the flow
    /// u = (a y, b x): ∂u_t/∂n = a and ∂u_n/∂t = b. The FS particles get the flux −b along x
    /// (scaled by |c|), and nothing when b = 0, whatever a is (the truncated Laplacian's own
    /// ∂u/∂n = 0 is left as it is); off the surface, nothing.
    #[test]
    fn the_flux_is_minus_the_tangential_derivative_of_the_normal_velocity() {
        let dr = 0.1;
        let mut points = Vec::new();
        for iy in 0..10 {
            for ix in 0..40 {
                points.push(Vec2::new((ix as f64 + 0.5) * dr, (iy as f64 + 0.5) * dr));
            }
        }
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(4.0, 3.0),
            periodic: [true, false],
        };
        let (list, sums, fs) = crate::engine::free_surface::surface_of(&domain, &points, dr);
        let n = points.len();
        let top = |i: usize| points[i].y > 0.9;
        let flux = |a: f64, b: f64| {
            let g = vec![Mat2::new(0.0, a, b, 0.0); n];
            let mut stage = ShearFreeSurface::default();
            stage
                .accelerations(Hood::without_walls(&list, &sums), &fs, &g, 1.0, &[])
                .to_vec()
        };
        let sheared = flux(3.0, 0.0);
        let turning = flux(0.0, 2.0);
        for i in 0..n {
            assert_eq!(
                fs.on_surface[i],
                top(i) || points[i].y < 0.1,
                "particle {i}"
            );
            if top(i) {
                assert!(sheared[i].norm() < 1e-9, "{:?}", sheared[i]);
                // |c| is the row's missing surface per unit area, about 1/δr.
                let per_dr = -turning[i].x / 2.0 * dr;
                assert!(per_dr > 0.5 && per_dr < 2.0, "|c| δr = {per_dr}");
                assert!(turning[i].y.abs() < 1e-9 * turning[i].x.abs());
            } else if !fs.on_surface[i] {
                assert_eq!(turning[i], Vec2::zeros());
            }
        }
    }
}
