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

pub mod inflow;

use crate::engine::math::{Sym2, Vec2};

/// A straight wall normal to `axis` at `position`, the fluid on the side `fluid_side` (+1: the
/// fluid occupies coordinates above `position`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    pub axis: usize,
    pub position: f64,
    pub fluid_side: f64,
}

impl Wall {
    /// The wall y = 0 with the fluid above: a channel's bottom wall, a drop's or a jet's
    /// plate.
    pub fn floor() -> Self {
        Wall {
            axis: 1,
            position: 0.0,
            fluid_side: 1.0,
        }
    }

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

/// A solid circular cylinder (at rest) of `radius` about `centre`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    pub centre: Vec2,
    pub radius: f64,
}

impl Circle {
    /// Distance of `p` from the surface, positive in the fluid.
    pub fn distance(&self, p: &Vec2) -> f64 {
        (p - self.centre).norm() - self.radius
    }

    /// Mirror image of `p` across the surface along the radius: a particle at distance d
    /// outside lands at distance d inside, so r_ij is normal to, and bisected by, the surface.
    pub fn reflect(&self, p: &Vec2) -> Vec2 {
        let r = p - self.centre;
        let rho = r.norm();
        self.centre + r * ((2.0 * self.radius - rho) / rho)
    }

    /// Area of the mirrored ring element over the original's, (R − d)/(R + d): mirrors are
    /// packed closer inside a convex surface, so each carries less volume.
    pub fn volume_ratio(&self, p: &Vec2) -> f64 {
        let d = self.distance(p);
        (self.radius - d) / (self.radius + d)
    }

    /// Outward unit normal at the surface point nearest `p`.
    pub fn normal(&self, p: &Vec2) -> Vec2 {
        (p - self.centre).normalize()
    }
}

/// A no-slip solid surface that creates mirror particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    Plane(Wall),
    Circle(Circle),
}

impl Surface {
    pub fn distance(&self, p: &Vec2) -> f64 {
        match self {
            Surface::Plane(w) => w.distance(p),
            Surface::Circle(c) => c.distance(p),
        }
    }

    pub fn reflect(&self, p: &Vec2) -> Vec2 {
        match self {
            Surface::Plane(w) => w.reflect(p),
            Surface::Circle(c) => c.reflect(p),
        }
    }

    /// Volume of a mirror relative to its parent's (1 for a plane).
    pub fn volume_ratio(&self, p: &Vec2) -> f64 {
        match self {
            Surface::Plane(_) => 1.0,
            Surface::Circle(c) => c.volume_ratio(p),
        }
    }

    /// Unit normal of the surface near `p` (sign irrelevant for reflections).
    pub fn normal(&self, p: &Vec2) -> Vec2 {
        match self {
            Surface::Plane(w) => {
                let mut n = Vec2::zeros();
                n[w.axis] = 1.0;
                n
            }
            Surface::Circle(c) => c.normal(p),
        }
    }
}

/// How a tensor is carried onto a wall's mirror particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TensorMirror {
    /// `A_j = A_i`: even across a no-slip wall (the default; see module docs).
    #[default]
    Even,
    /// `A_j = P A_i P` with P = I − 2nnᵀ the reflection across the surface: the shear
    /// component odd across the wall (free-slip-like).
    Reflected,
}

/// The ghost particles of one step: ghost g has parent fluid particle `parent[g]` and was
/// mirrored across wall `wall[g]`.
#[derive(Clone, Debug, Default)]
pub struct Ghosts {
    pub parent: Vec<u32>,
    /// The surface each ghost mirrors across (index into `surfaces`).
    pub surface: Vec<u16>,
    /// Each ghost's volume relative to its parent's.
    pub volume: Vec<f64>,
    /// The surface normal between each ghost and its parent.
    pub normal: Vec<Vec2>,
    pub surfaces: Vec<Surface>,
    pub tensor_mirror: TensorMirror,
}

impl Ghosts {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.parent)
            + crate::engine::vec_bytes(&self.surface)
            + crate::engine::vec_bytes(&self.volume)
            + crate::engine::vec_bytes(&self.normal)
            + crate::engine::vec_bytes(&self.surfaces)
    }

    pub fn new(surfaces: Vec<Surface>) -> Self {
        Self {
            surfaces,
            ..Default::default()
        }
    }

    /// Plane walls only.
    pub fn walls(walls: Vec<Wall>) -> Self {
        Self::new(walls.into_iter().map(Surface::Plane).collect())
    }

    /// Whether any ghost carries a volume other than its parent's.
    pub fn has_volume_ratios(&self) -> bool {
        self.surfaces
            .iter()
            .any(|s| matches!(s, Surface::Circle(_)))
    }

    pub fn len(&self) -> usize {
        self.parent.len()
    }

    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }

    /// Creates mirrors of the fluid particles within `reach` of a surface, appending their
    /// positions to `points` (which holds the fluid positions on entry).
    pub fn build(&mut self, reach: f64, points: &mut Vec<Vec2>) {
        self.parent.clear();
        self.surface.clear();
        self.volume.clear();
        self.normal.clear();
        let n_fluid = points.len();
        for i in 0..n_fluid {
            for (w, surface) in self.surfaces.iter().enumerate() {
                if surface.distance(&points[i]) < reach {
                    let q = surface.reflect(&points[i]);
                    self.volume.push(surface.volume_ratio(&points[i]));
                    self.normal.push(surface.normal(&points[i]));
                    points.push(q);
                    self.parent.push(i as u32);
                    self.surface.push(w as u16);
                }
            }
        }
    }

    /// Volumes of all points relative to a fluid particle's (1 for fluid particles).
    pub fn point_volumes(&self, n_fluid: usize, out: &mut Vec<f64>) {
        out.clear();
        out.resize(n_fluid, 1.0);
        out.extend_from_slice(&self.volume);
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
        out.extend(self.parent.iter().zip(&self.normal).map(|(&p, n)| {
            let t = fluid[p as usize];
            match self.tensor_mirror {
                TensorMirror::Even => t,
                TensorMirror::Reflected => {
                    let reflection =
                        crate::engine::math::Mat2::identity() - 2.0 * n * n.transpose();
                    t.congruence(&reflection)
                }
            }
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel() -> Ghosts {
        Ghosts::walls(vec![
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
            let Surface::Plane(wall) = g.surfaces[g.surface[k] as usize] else {
                panic!()
            };
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

    /// Across a circle the mirror sits on the same radius at the same distance inside, the
    /// segment's midpoint lies on the surface, its volume shrinks by (R − d)/(R + d), and the
    /// reflected tensor rule uses the local radial normal.
    #[test]
    fn circle_mirrors_are_bisected_by_the_surface() {
        let c = Circle {
            centre: Vec2::new(3.0, 2.0),
            radius: 1.0,
        };
        let mut g = Ghosts::new(vec![Surface::Circle(c)]);
        let p = Vec2::new(3.0 + 1.1 * 0.6, 2.0 + 1.1 * 0.8);
        let mut pts = vec![p, Vec2::new(0.2, 0.2)];
        g.build(0.3, &mut pts);
        assert_eq!(g.parent, vec![0]);
        let m = pts[2];
        let mid = 0.5 * (p + m);
        assert!(
            ((mid - c.centre).norm() - 1.0).abs() < 1e-14,
            "midpoint on the circle"
        );
        assert!(((m - c.centre).norm() - 0.9).abs() < 1e-14);
        let radial = (p - c.centre).normalize();
        assert!(
            (m - p).normalize().dot(&radial) + 1.0 < 1e-14,
            "along the radius"
        );
        assert!((g.volume[0] - 0.9 / 1.1).abs() < 1e-14);
        // The reflected rule flips the normal–tangential shear in the local frame.
        g.tensor_mirror = TensorMirror::Reflected;
        let n = radial;
        let t = Vec2::new(-n.y, n.x);
        let shear = Sym2::new(2.0 * n.x * t.x, n.x * t.y + n.y * t.x, 2.0 * n.y * t.y); // n⊗t + t⊗n
        let mut out = Vec::new();
        g.extend_tensor(&[shear, Sym2::ZERO], &mut out);
        let d = out[2] + shear;
        assert!(d.contract(&d).sqrt() < 1e-14);
    }
}
