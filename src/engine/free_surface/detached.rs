//! Detached bodies of liquid keep their momentum.
//!
//! A drop or a splash that has left the rest of the liquid (no neighbour pair joins it to
//! another particle, a wall's ghost or an inflow buffer) feels no force but the body force:
//! its linear momentum changes by g δt per unit mass in a step and its angular momentum about
//! its centre not at all. The Morris Laplacian (21) and the positive divergence (20) of the
//! polymer stress are sums of antisymmetric pair terms and keep both; the projection's
//! corrected pressure gradient (20)–(22) on the Dirichlet values of (35a) is not, and on a
//! body of surface particles it leaves a net force (a blob of 16 particles thrown off the
//! Wi = 1/3 jet sped up along x at 4g with no force along x, validation pages, *Free surfaces*). Its
//! antisymmetric form conserves momentum but, as the projection's gradient, made every
//! free-surface run unstable.
//!
//! [`DetachedBodies::conserve`] therefore takes the step's velocity change of every detached
//! body, Δu_i = u_i^{n+1} − u_i^n − g δt, and removes from it the uniform translation and
//! the rigid rotation that carry its net impulse Σ Δu_i and its net torque
//! Σ (r_i − c) × Δu_i (equal masses; the rotation ω × (r − c) with ω = torque / Σ|r_i − c|²).
//! What is left changes neither momentum; the body's internal motion is untouched. Bodies are
//! the connected components of the step's neighbour lists (at r*, which every operator of the
//! step used).

use crate::engine::math::Vec2;
use crate::engine::neighbours::{Domain, NeighbourList};
use serde::{Deserialize, Serialize};

/// Whether a detached body's momentum is kept (`scheme.free_surface.detached_momentum`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum DetachedMomentum {
    /// Each detached body's net impulse and torque of the step removed (module docs).
    #[default]
    Conserved,
    /// Left as the operators give it (the paper's scheme).
    Unconstrained,
}

/// Per-particle union–find and per-body sums, reused from step to step.
#[derive(Clone, Debug, Default)]
pub struct DetachedBodies {
    parent: Vec<u32>,
    /// Per body root: touches a wall ghost or the inflow.
    anchored: Vec<bool>,
    count: Vec<u32>,
    /// Per body root: the centre relative to the root particle, then the impulse per
    /// particle, the torque and the polar moment.
    centre: Vec<Vec2>,
    impulse: Vec<Vec2>,
    torque: Vec<f64>,
    inertia: Vec<f64>,
    /// Detached bodies corrected so far, summed over steps.
    pub body_steps: u64,
    /// The largest velocity a correction removed from a particle (in the velocity's units).
    pub largest_correction: f64,
}

/// What [`DetachedBodies::conserve`] reads: the lists and points (r*) of the step, the
/// inflow buffer's flags (empty: none) and the domain (for periodic images).
pub struct BodyInputs<'a> {
    pub list: &'a NeighbourList,
    pub points: &'a [Vec2],
    pub buffer: &'a [bool],
    pub domain: &'a Domain,
}

impl DetachedBodies {
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.parent)
            + b(&self.anchored)
            + b(&self.count)
            + b(&self.centre)
            + b(&self.impulse)
            + b(&self.torque)
            + b(&self.inertia)
    }

    fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let grand = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grand;
            i = grand;
        }
        i
    }

    /// Joins every neighbour pair; marks the roots of bodies that touch a ghost or the inflow.
    fn label(&mut self, inputs: &BodyInputs) {
        let n = inputs.points.len();
        self.parent.clear();
        self.parent.extend(0..n as u32);
        reset(&mut self.anchored, n, false);
        for i in 0..n {
            for &j in &inputs.list.index[inputs.list.range(i)] {
                if j as usize >= n {
                    self.anchored[i] = true;
                    continue;
                }
                let (a, b) = (self.find(i as u32), self.find(j));
                if a != b {
                    self.parent[a.max(b) as usize] = a.min(b);
                }
            }
            if inputs.buffer.get(i).copied().unwrap_or(false) {
                self.anchored[i] = true;
            }
        }
        for i in 0..n {
            let root = self.find(i as u32) as usize;
            self.parent[i] = root as u32;
            self.anchored[root] |= self.anchored[i];
        }
    }

    /// Removes from every detached body the net impulse and torque of the step: `old` is
    /// u^n, `new` u^{n+1} (corrected in place), `g` the body force per unit mass, `dt` the
    /// step. Returns the number of detached bodies.
    pub fn conserve(
        &mut self,
        inputs: &BodyInputs,
        old: &[Vec2],
        new: &mut [Vec2],
        g: Vec2,
        dt: f64,
    ) -> usize {
        self.label(inputs);
        let n = inputs.points.len();
        let offset = |s: &Self, i: usize| {
            let root = s.parent[i] as usize;
            inputs
                .domain
                .min_image(inputs.points[i] - inputs.points[root])
        };
        reset(&mut self.count, n, 0);
        reset(&mut self.centre, n, Vec2::zeros());
        reset(&mut self.impulse, n, Vec2::zeros());
        reset(&mut self.torque, n, 0.0);
        reset(&mut self.inertia, n, 0.0);
        for i in 0..n {
            let root = self.parent[i] as usize;
            if self.anchored[root] {
                continue;
            }
            let d = offset(self, i);
            self.count[root] += 1;
            self.centre[root] += d;
            self.impulse[root] += new[i] - old[i] - g * dt;
        }
        let mut bodies = 0;
        for root in 0..n {
            if self.count[root] > 0 {
                let c = self.count[root] as f64;
                self.centre[root] /= c;
                self.impulse[root] /= c;
                bodies += 1;
            }
        }
        for i in 0..n {
            let root = self.parent[i] as usize;
            if self.anchored[root] {
                continue;
            }
            let d = offset(self, i) - self.centre[root];
            let du = new[i] - old[i] - g * dt - self.impulse[root];
            self.torque[root] += d.x * du.y - d.y * du.x;
            self.inertia[root] += d.norm_squared();
        }
        for (i, u) in new.iter_mut().enumerate() {
            let root = self.parent[i] as usize;
            if self.anchored[root] {
                continue;
            }
            let d = offset(self, i) - self.centre[root];
            let inertia = self.inertia[root];
            let omega = if inertia > 0.0 {
                self.torque[root] / inertia
            } else {
                0.0
            };
            let correction = self.impulse[root] + omega * Vec2::new(-d.y, d.x);
            *u -= correction;
            self.largest_correction = self.largest_correction.max(correction.norm());
        }
        self.body_steps += bodies as u64;
        bodies
    }
}

/// `v` as `n` copies of `value`, in its own buffer.
fn reset<T: Clone>(v: &mut Vec<T>, n: usize, value: T) {
    v.clear();
    v.resize(n, value);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lists joining points within `reach` (no ghosts), in a large non-periodic domain.
    fn lists(points: &[Vec2], reach: f64) -> NeighbourList {
        let mut list = NeighbourList {
            offsets: vec![0],
            ..Default::default()
        };
        for (i, p) in points.iter().enumerate() {
            for (j, q) in points.iter().enumerate() {
                if i != j && (p - q).norm() < reach {
                    list.index.push(j as u32);
                    list.rij.push(p - q);
                }
            }
            list.offsets.push(list.index.len());
        }
        list
    }

    #[test]
    fn a_detached_body_loses_its_net_impulse_and_torque_but_keeps_its_internal_motion() {
        // A unit square (points 0–3) and, 10 away, three points of which one (5) sees a ghost
        // (index 7): the square is detached, the other body anchored.
        let points: Vec<Vec2> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .iter()
            .chain(&[(10.0, 0.0), (11.0, 0.0), (10.0, 1.0)])
            .map(|&(x, y)| Vec2::new(x, y))
            .collect();
        let mut list = lists(&points, 1.5);
        list.index[list.offsets[5]] = 7;
        let domain = Domain {
            min: Vec2::new(-100.0, -100.0),
            max: Vec2::new(100.0, 100.0),
            periodic: [false, false],
        };
        let inputs = BodyInputs {
            list: &list,
            points: &points,
            buffer: &[],
            domain: &domain,
        };
        let old = vec![Vec2::new(0.3, -0.2); 7];
        let (g, dt) = (Vec2::new(0.0, -1.0), 0.1);
        let c = Vec2::new(0.5, 0.5);
        // A squeeze about the centre (x in, y out): no net impulse, and no torque on a square.
        let squeeze = |p: &Vec2| {
            let d = p - c;
            Vec2::new(-d.x, d.y)
        };
        // Gravity's impulse, the squeeze, and a spurious push and spin on every point.
        let mut new: Vec<Vec2> = points
            .iter()
            .zip(&old)
            .map(|(p, u)| {
                u + g * dt + squeeze(p) + Vec2::new(0.5, 0.1) + 0.2 * Vec2::new(-p.y, p.x)
            })
            .collect();
        let anchored: Vec<Vec2> = new[4..].to_vec();
        let mut bodies = DetachedBodies::default();
        assert_eq!(bodies.conserve(&inputs, &old, &mut new, g, dt), 1);
        for (i, p) in points[..4].iter().enumerate() {
            let kept = old[i] + g * dt + squeeze(p);
            assert!(
                (new[i] - kept).norm() < 1e-14,
                "{i}: {} against {kept}",
                new[i]
            );
        }
        assert_eq!(&new[4..], &anchored[..], "the anchored body is untouched");
    }
}
