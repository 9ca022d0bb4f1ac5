//! Mirror particles for straight no-slip walls (King & Lind §III C).
//!
//! For every fluid particle i within one kernel support of a wall, a ghost j is placed so that
//! r_ij is perpendicular to, and bisected by, the wall. Ghost values are slaved to the parent:
//!
//! * velocity `u_j = −u_i`, so that the wall velocity is zero to second order;
//! * pressure `p_j = p_i`, a homogeneous Neumann condition (in the PPE the ghost's unknown *is*
//!   the parent's);
//! * conformation and stress copied, `A_j = A_i` (even extension). The mirrored velocity
//!   `u_m(x, −y) = −u(x, y)` has wall-normal gradient `∂u_m/∂y = +∂u/∂y`: the shear rate, which
//!   drives the polymer stress, is even across a no-slip wall, and its evolution
//!   `Ȧ = ∇u·A + A·∇uᵀ − f_R/λ` evaluated with the mirrored gradient agrees with the parent's
//!   up to terms (∂u/∂x, ∂v/∂x) that vanish on the wall. The odd, reflection-symmetric choice
//!   `P A P` (the free-slip one) would force τ_xy = 0 at the wall, where for Poiseuille flow it
//!   is largest. `tests/wall_stress.rs` measures both against the analytic wall shear stress.

use crate::math::{Sym2, Vec2};

/// A straight wall normal to `axis` at `position`, the fluid on the side `fluid_side` (+1: the
/// fluid occupies coordinates above `position`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    pub axis: usize,
    pub position: f64,
    pub fluid_side: f64,
}

impl Wall {
    /// Signed distance of `p` from the wall, positive in the fluid.
    pub fn distance(&self, p: &Vec2) -> f64 {
        (p[self.axis] - self.position) * self.fluid_side
    }

    /// Mirror image of `p` across the wall.
    pub fn reflect(&self, p: &Vec2) -> Vec2 {
        let mut q = *p;
        q[self.axis] = 2.0 * self.position - p[self.axis];
        q
    }
}

/// How a tensor is carried onto a wall's mirror particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TensorMirror {
    /// `A_j = A_i`: even across a no-slip wall (the default; see module docs).
    #[default]
    Even,
    /// `A_j = P A_i P` with P the reflection: τ_xy odd across the wall (free-slip-like).
    Reflected,
}

/// The ghost particles of one step: ghost g has parent fluid particle `parent[g]` and was
/// mirrored across wall `wall[g]`.
#[derive(Clone, Debug, Default)]
pub struct Ghosts {
    pub parent: Vec<u32>,
    pub wall: Vec<u16>,
    pub walls: Vec<Wall>,
    pub tensor_mirror: TensorMirror,
}

impl Ghosts {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::vec_bytes(&self.parent)
            + crate::vec_bytes(&self.wall)
            + crate::vec_bytes(&self.walls)
    }

    pub fn new(walls: Vec<Wall>) -> Self {
        Self {
            walls,
            ..Default::default()
        }
    }

    pub fn len(&self) -> usize {
        self.parent.len()
    }

    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }

    /// Creates mirrors of the fluid particles within `reach` of a wall, appending their
    /// positions to `points` (which holds the fluid positions on entry).
    pub fn build(&mut self, reach: f64, points: &mut Vec<Vec2>) {
        self.parent.clear();
        self.wall.clear();
        let n_fluid = points.len();
        for i in 0..n_fluid {
            for (w, wall) in self.walls.iter().enumerate() {
                if wall.distance(&points[i]) < reach {
                    let q = wall.reflect(&points[i]);
                    points.push(q);
                    self.parent.push(i as u32);
                    self.wall.push(w as u16);
                }
            }
        }
    }

    /// The parent fluid index of extended index `j` (identity for fluid particles).
    #[inline]
    pub fn owner(&self, j: usize, n_fluid: usize) -> usize {
        if j < n_fluid {
            j
        } else {
            self.parent[j - n_fluid] as usize
        }
    }

    /// Fluid velocities followed by the ghosts' no-slip values `u_j = −u_i`.
    pub fn extend_velocity(&self, fluid: &[Vec2], out: &mut Vec<Vec2>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(self.parent.iter().map(|&p| -fluid[p as usize]));
    }

    /// Fluid scalars followed by the ghosts' copies (homogeneous Neumann).
    pub fn extend_scalar(&self, fluid: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(self.parent.iter().map(|&p| fluid[p as usize]));
    }

    /// Fluid tensors followed by the ghosts' mirrored values (see [`TensorMirror`]).
    pub fn extend_tensor(&self, fluid: &[Sym2], out: &mut Vec<Sym2>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(self.parent.iter().map(|&p| {
            let t = fluid[p as usize];
            match self.tensor_mirror {
                TensorMirror::Even => t,
                // P = I − 2 e_a e_aᵀ for an axis-aligned wall flips the off-diagonal component.
                TensorMirror::Reflected => Sym2::new(t.xx, -t.xy, t.yy),
            }
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel() -> Ghosts {
        Ghosts::new(vec![
            Wall {
                axis: 1,
                position: 0.0,
                fluid_side: 1.0,
            },
            Wall {
                axis: 1,
                position: 1.0,
                fluid_side: -1.0,
            },
        ])
    }

    #[test]
    fn mirrors_are_bisected_by_the_wall() {
        let mut g = channel();
        let mut pts = vec![
            Vec2::new(0.3, 0.05),
            Vec2::new(0.4, 0.5),
            Vec2::new(0.1, 0.9),
        ];
        g.build(0.2, &mut pts);
        assert_eq!(g.parent, vec![0, 2]);
        assert!((pts[3] - Vec2::new(0.3, -0.05)).norm() < 1e-15);
        assert!((pts[4] - Vec2::new(0.1, 1.1)).norm() < 1e-15);
        for (k, &p) in g.parent.iter().enumerate() {
            let mid = 0.5 * (pts[p as usize] + pts[3 + k]);
            let wall = g.walls[g.wall[k] as usize];
            assert!((mid.y - wall.position).abs() < 1e-15);
        }
    }

    #[test]
    fn ghost_values_follow_the_no_slip_rules() {
        let mut g = channel();
        let mut pts = vec![Vec2::new(0.3, 0.05)];
        g.build(0.2, &mut pts);
        let mut u = Vec::new();
        g.extend_velocity(&[Vec2::new(2.0, -1.0)], &mut u);
        assert_eq!(u[1], Vec2::new(-2.0, 1.0));
        let mut p = Vec::new();
        g.extend_scalar(&[3.5], &mut p);
        assert_eq!(p[1], 3.5);
        let mut a = Vec::new();
        g.extend_tensor(&[Sym2::new(5.0, 2.0, 1.0)], &mut a);
        assert_eq!(a[1], Sym2::new(5.0, 2.0, 1.0));
        g.tensor_mirror = TensorMirror::Reflected;
        g.extend_tensor(&[Sym2::new(5.0, 2.0, 1.0)], &mut a);
        assert_eq!(a[1], Sym2::new(5.0, -2.0, 1.0));
    }
}
