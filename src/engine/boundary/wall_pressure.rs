//! The pressure a wall's ghosts carry: the Neumann condition of the PPE.
//!
//! King & Lind (§III C) give a mirror its parent's pressure, `p_j = p_i`: a homogeneous
//! Neumann condition ∂p/∂n = 0. The normal momentum balance at a no-slip wall at rest says
//! instead (Du/Dt·n = 0 there)
//!
//! ```text
//!     ∂p/∂n = n·(∇·Φ + ρg) + η n·∇²u,
//! ```
//!
//! and next to a curved wall n·∇·τ_p is the polymer's hoop stress T/R (T the tension along
//! the streamlines wrapped round it): at the Wi = 4 cylinder array (R/δr = 9) it reached
//! 2 000–4 800 (in units of ρU²/R) on the particles that later crossed the cylinder, and the
//! pressure gradient that balanced it 1.2δr from the wall fell to zero 0.6δr from it (validation pages,
//! *High Weissenberg number*). Adami, Hu & Adams (2012) put the body force (and the wall's
//! acceleration) into the wall pressure for the same reason.
//!
//! [`WallPressure::Momentum`] keeps the polymer and body-force part of that balance: ghost g
//! of parent k carries
//!
//! ```text
//!     p_g = p_k + ((r_g − r_k)·n) (n·f_k),   f_k = (∇·Φ)_k + ρg,
//! ```
//!
//! the Taylor step from the parent along the wall normal n with the gradient the balance
//! gives (the viscous part, which needs ∇²u at the wall, is left out). The offsets apply to
//! the pressure itself, never to the increment of the incremental projection (whose old
//! pressure carries them), and not to walls whose pressure sign is −1.

use super::Ghosts;
use crate::engine::math::Vec2;
use serde::{Deserialize, Serialize};

/// The Neumann condition of the wall pressure.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum WallPressure {
    /// `p_j = p_i` (King & Lind): ∂p/∂n = 0.
    #[default]
    Neumann,
    /// ∂p/∂n = n·(∇·Φ + ρg), the normal momentum balance (module docs).
    Momentum,
}

impl Ghosts {
    /// Sets every ghost's pressure offset from the force density `force` (∇·Φ + ρg per
    /// fluid particle) and the positions `points` (fluid, then ghosts, as built).
    pub fn set_pressure_gradient(&mut self, points: &[Vec2], force: &[Vec2]) {
        let n_fluid = points.len() - self.parent.len();
        self.pressure_offset.clear();
        self.normal_force.clear();
        for g in 0..self.parent.len() {
            let k = self.parent[g] as usize;
            if self.pressure_sign[self.wall[g] as usize] < 0.0 {
                self.pressure_offset.push(0.0);
                self.normal_force.push(0.0);
                continue;
            }
            let d = points[n_fluid + g] - points[k];
            let d = self.domain.as_ref().map_or(d, |domain| domain.min_image(d));
            let n = self.normal[g];
            self.pressure_offset.push(d.dot(&n) * n.dot(&force[k]));
            self.normal_force.push(n.dot(&force[k]));
        }
    }

    /// The ghosts' u* as the PPE's divergence must see it when the pressure carries offsets:
    /// `velocity_ext` (u* extended by the mirrors) gains `2 (δt/ρ)(n·f_k) n` on every ghost.
    /// The offsets continue the normal gradient n·f across the wall, so the gradient the PPE
    /// implies at a ghost has the normal part (∇p)_g·n = −(∇p)_k·n + 2 n·f, while the mirror
    /// makes the normal velocity odd: the projected ghost u*_g − (δt/ρ)(∇p)_g is the mirror
    /// of the projected parent only with this term. Without it the first layer keeps a
    /// divergence the solve cannot remove; in a pool at rest (g = 1, depth 0.8, δr = 0.04)
    /// the offsets lifted the bottom row off the floor and the pool rose 13 % in 20 time
    /// units (validation pages, *Still water*). Nothing to do without offsets.
    pub fn continue_force(&self, dt_over_rho: f64, velocity_ext: &mut [Vec2]) {
        if self.normal_force.is_empty() {
            return;
        }
        let n_fluid = velocity_ext.len() - self.normal_force.len();
        let ghosts = velocity_ext[n_fluid..].iter_mut();
        for ((u, f), n) in ghosts.zip(&self.normal_force).zip(&self.normal) {
            *u += 2.0 * dt_over_rho * f * n;
        }
    }

    /// Fluid pressures followed by the ghosts': the parent's by the wall's sign, plus the
    /// offset of [`Self::set_pressure_gradient`] when one was set for these ghosts. For the
    /// pressure itself; an increment takes [`Self::extend_pressure`].
    pub fn extend_full_pressure(&self, fluid: &[f64], out: &mut Vec<f64>) {
        self.extend_pressure(fluid, out);
        if !self.pressure_offset.is_empty() {
            let n = fluid.len();
            for (p, c) in out[n..].iter_mut().zip(&self.pressure_offset) {
                *p += c;
            }
        }
    }

    /// The pressure offsets of the ghosts (empty: homogeneous Neumann).
    pub fn pressure_offsets(&self) -> &[f64] {
        &self.pressure_offset
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::{Circle, Plane, Shape, TensorMirror, Wall};

    /// Two particles over the no-slip floor y = 0, mirrored: the fluid points, then the ghosts.
    fn two_over_a_floor() -> (Ghosts, Vec<Vec2>) {
        let plane = Shape::Plane(Plane {
            axis: 1,
            position: 0.0,
            fluid_side: 1.0,
        });
        let mut ghosts = Ghosts::new(vec![Wall::no_slip(plane, TensorMirror::Even)]);
        let mut points = vec![Vec2::new(0.3, 0.05), Vec2::new(0.7, 0.12)];
        ghosts.build(0.2, &mut points);
        (ghosts, points)
    }

    /// A pressure that is linear across a plane wall, p = p0 + f y, is carried exactly by
    /// the mirrors when f is the normal force density; homogeneous mirrors carry p0 + f y_i.
    #[test]
    fn mirrors_continue_the_normal_gradient_of_the_balance() {
        let (mut ghosts, points) = two_over_a_floor();
        assert_eq!(ghosts.len(), 2);
        let (p0, f) = (2.0, -3.0);
        let pressure: Vec<f64> = points[..2].iter().map(|r| p0 + f * r.y).collect();
        let force = vec![Vec2::new(5.0, f); 2];
        ghosts.set_pressure_gradient(&points, &force);
        let mut ext = Vec::new();
        ghosts.extend_full_pressure(&pressure, &mut ext);
        for (g, p) in ext[2..].iter().enumerate() {
            let exact = p0 + f * points[2 + g].y;
            assert!((p - exact).abs() < 1e-12, "ghost {g}: {p} against {exact}");
        }
        // The tangential force (5) does not enter; the increment is not offset.
        ghosts.extend_pressure(&pressure, &mut ext);
        assert!((ext[2] - pressure[0]).abs() < 1e-15);
    }

    /// A fluid at rest whose u* is the force's increment alone, u* = (δt/ρ) f: with the
    /// continuation its ghosts carry the same normal velocity, so ∇·u* = 0 across the wall
    /// and the PPE returns the hydrostatic pressure; the plain mirror reverses it. The
    /// tangential part keeps the mirror's sign (the offsets carry no tangential gradient).
    #[test]
    fn continued_ghosts_carry_the_force_increment() {
        let (mut ghosts, points) = two_over_a_floor();
        let (f, dt_over_rho) = (Vec2::new(5.0, -3.0), 0.1);
        ghosts.set_pressure_gradient(&points, &[f, f]);
        let u_star = vec![dt_over_rho * f; 2];
        let mut ext = Vec::new();
        ghosts.extend_velocity(&u_star, &mut ext);
        assert!(
            (ext[2].y + u_star[0].y).abs() < 1e-15,
            "the mirror reverses it"
        );
        ghosts.continue_force(dt_over_rho, &mut ext);
        for g in &ext[2..] {
            assert!((g.y - dt_over_rho * f.y).abs() < 1e-15, "normal: {g:?}");
            assert!((g.x + dt_over_rho * f.x).abs() < 1e-15, "tangential: {g:?}");
        }
    }

    /// Across a circle the offset is the radial step times the radial force: a hoop
    /// tension pulling inward (f_r < 0) raises the pressure inside the wall.
    #[test]
    fn a_hoop_pull_raises_the_mirror_pressure() {
        let circle = Shape::Circle(Circle {
            centre: Vec2::zeros(),
            radius: 1.0,
        });
        let mut ghosts = Ghosts::new(vec![Wall::no_slip(circle, TensorMirror::Even)]);
        let mut points = vec![Vec2::new(0.0, 1.05)];
        ghosts.build(0.2, &mut points);
        let force = vec![Vec2::new(0.0, -100.0)];
        ghosts.set_pressure_gradient(&points, &force);
        let offset = ghosts.pressure_offsets()[0];
        let step = points[1].y - points[0].y;
        assert!(step < 0.0);
        assert!((offset - step * -100.0).abs() < 1e-12);
        assert!(offset > 0.0);
    }
    /// The PPE with the offsets moved to its right-hand side
    /// ([`crate::engine::pressure::wall_pressure_rhs`]) is solved by the hydrostatic field
    /// p = F y of a fluid at rest under a force density F normal to two plane walls: the
    /// folded matrix times that field equals the moved offsets to round-off. With
    /// homogeneous mirrors the same field leaves a residual of order F/δr in the wall rows
    /// (the PPE would flatten it there).
    #[test]
    fn the_ppe_holds_a_hydrostatic_pressure_between_walls() {
        use crate::engine::boundary::Field;
        use crate::engine::laplacian_matrix::{fixture, LaplacianMatrix};
        let fixture::WalledLattice {
            points,
            n,
            spacing: dr,
            mut ghosts,
            list,
            sums,
        } = fixture::walled_lattice(12);
        let (density, force) = (1.0, -7.0);
        let mut matrix = LaplacianMatrix::default();
        matrix.assemble(
            &list,
            &sums,
            &ghosts,
            Field::Pressure,
            0.0,
            -1.0 / density,
            &[],
            &[],
        );
        let a = matrix.to_csr();
        let p: Vec<f64> = points[..n].iter().map(|r| force * r.y).collect();
        let mut ap = vec![0.0; n];
        rheosph_solver::vector::spmv(&a, &p, &mut ap);
        let flattened = ap.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(
            flattened > 0.1 * force.abs() / dr,
            "homogeneous mirrors: {flattened}"
        );
        ghosts.set_pressure_gradient(&points, &vec![Vec2::new(0.0, force); n]);
        let mut rhs = vec![0.0; n];
        crate::engine::pressure::wall_pressure_rhs(
            crate::engine::neighbourhood::Hood {
                list: &list,
                sums: &sums,
                ghosts: &ghosts,
            },
            density,
            &[],
            &mut rhs,
        );
        let residual = ap
            .iter()
            .zip(&rhs)
            .fold(0.0_f64, |m, (x, b)| m.max((x - b).abs()));
        assert!(residual < 1e-9 * force.abs() / dr, "residual {residual}");
    }
}
