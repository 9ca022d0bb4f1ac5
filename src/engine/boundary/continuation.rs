//! Ghost values that continue the fluid's fields smoothly across a wall, instead of copying
//! the parent's value (even) or negating it (odd).
//!
//! A mirror's copy is exact only for the part of a field that is constant (even copy) or
//! linear in the wall distance (odd copy about the wall value). The extended field then has a
//! kink at the wall wherever the next term does not vanish, and every operator whose support
//! crosses the wall reads it as an O(1) error over the first wall layers:
//!
//! * a tensor copied even (`A_j = A_i`) loses its wall-normal slope: τ_xy = η_p ∂u/∂y of a
//!   channel is linear in y, and the stress divergence of the first layers fell short by the
//!   jump of that slope;
//! * a no-slip velocity mirrored odd (`u_j = 2u_w − u_i`) loses its wall-normal curvature:
//!   over a flat wall a parabola's Laplacian (21) in the first layer is −1.22 for −2.
//!
//! In the start-up channel (Oldroyd-B, Re = Wi = 1, β = 0.1, H/δr = 30) the two left a steady
//! velocity error of 0.85 % (τ_xy 1.8 %, τ_xx 4.6 %); continued, 0.009 % (Eulerian) and
//! 0.014 % (Lagrangian).
//!
//! Both continuations are linear in the fluid values, so each ghost keeps a stencil over its
//! parent k and k's fluid neighbours, built once per configuration ([`Continuation::build`]):
//!
//! * **tensor** (walls with [`super::TensorMirror::Linear`]): `T_g = T_k + arm·∇T_k` with
//!   arm = r_g − r_k and ∇ the Bonet–Lok gradient over k's fluid neighbours alone, corrected
//!   over that subset so that it is exact for a linear field in a support the wall truncates:
//!   `T_g = T_k + Σ_j a_j (T_j − T_k)`, `a_j = (B⁻ᵀ arm)·∇W_kj δV`,
//!   `B = Σ_j r_jk ⊗ ∇W_kj δV`;
//! * **velocity** (no-slip walls under [`VelocityExtension::Quadratic`]): the weighted
//!   least-squares quadratic `u_w + a·x + B:xx` about the wall point f = r_k + arm/2 through
//!   k and its fluid neighbours (their kernel weights about k, k weighted as its nearest
//!   neighbour), evaluated at the ghost: `u_g = u_w + Σ_j c_j (u_j − u_w)`.
//!
//! Where a fit is singular (fewer than five independent points, or a degenerate B) the ghost
//! keeps its mirror value.

use crate::engine::dimension::{Dim, Dimension};
use crate::engine::neighbours::NeighbourList;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the explicit operators extend a no-slip wall's velocity to its ghosts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum VelocityExtension {
    /// The mirror's `u_j = 2u_w − u_i` (King & Lind): exact for a velocity linear in the
    /// wall distance.
    Mirror,
    /// The quadratic continuation (module docs): exact for a velocity quadratic near the
    /// wall. The default: it removes the first wall layers' viscous-force error (module docs)
    /// and, with the tensor's continuation, the channel's steady error.
    #[default]
    Quadratic,
}

/// The listed pairs and the kernel of each pair k (the operators' kernel sums hold both):
/// W(r_k) and F(r_k), ∇W_k = F(r_k) r_k.
#[derive(Clone, Copy)]
pub struct PairKernel<'a, const D: usize = 2> {
    pub list: &'a NeighbourList<D>,
    pub value: &'a [f64],
    pub factor: &'a [f64],
}

/// What the stencils need of each ghost g.
pub struct GhostView<'a, const D: usize = 2> {
    pub parent: &'a [u32],
    pub arm: &'a [SVector<f64, D>],
    /// Whether ghost g's velocity is continued.
    pub velocity: &'a (dyn Fn(usize) -> bool + Sync),
    /// Whether ghost g's tensor is continued.
    pub tensor: &'a (dyn Fn(usize) -> bool + Sync),
}

/// One ghost's stencils: weights over `points` (k first, then k's fluid neighbours).
#[derive(Clone, Debug, Default)]
struct Stencil {
    points: Vec<u32>,
    /// c_j of the velocity (empty: mirror).
    velocity: Vec<f64>,
    /// a_j of the tensor (empty: copy), a_k = 0.
    tensor: Vec<f64>,
}

/// The stencils of every ghost for one configuration.
#[derive(Clone, Debug, Default)]
pub struct Continuation {
    stencils: Vec<Stencil>,
}

impl Continuation {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.stencils)
            + self
                .stencils
                .iter()
                .map(|s| b(&s.points) + b(&s.velocity) + b(&s.tensor))
                .sum::<usize>()
    }

    /// The stencils of `ghosts` in the configuration of `list`, `sums` (the first `n_fluid`
    /// points the fluid's).
    pub fn build<const D: usize>(
        &mut self,
        pairs: PairKernel<D>,
        n_fluid: usize,
        ghosts: &GhostView<D>,
    ) where
        Dim<D>: Dimension<D>,
    {
        let list = pairs.list;
        let count = ghosts.parent.len();
        self.stencils.resize_with(count, Stencil::default);
        self.stencils
            .par_iter_mut()
            .enumerate()
            .for_each(|(g, stencil)| {
                let (velocity, tensor) = ((ghosts.velocity)(g), (ghosts.tensor)(g));
                stencil.points.clear();
                stencil.velocity.clear();
                stencil.tensor.clear();
                if !velocity && !tensor {
                    return;
                }
                let k = ghosts.parent[g] as usize;
                stencil.points.push(k as u32);
                let fluid = list
                    .range(k)
                    .filter(|&p| (list.index[p] as usize) < n_fluid);
                stencil.points.extend(fluid.clone().map(|p| list.index[p]));
                let arm = ghosts.arm[g];
                if velocity {
                    velocity_weights(pairs, fluid.clone(), arm, &mut stencil.velocity);
                }
                if tensor {
                    tensor_weights(pairs, fluid, arm, &mut stencil.tensor);
                }
            });
    }

    /// Overwrites the continued ghosts' velocities in `ghosts` (the ghost part of an extended
    /// field) from the fluid's `fluid`, with u_w = b_g/2 from the ghosts' no-slip offsets
    /// `offsets` (empty: walls at rest), read now because a moving wall's may change between
    /// configurations.
    pub fn velocity<const D: usize>(
        &self,
        fluid: &[SVector<f64, D>],
        offsets: &[SVector<f64, D>],
        ghosts: &mut [SVector<f64, D>],
    ) {
        ghosts
            .par_iter_mut()
            .zip(self.stencils.par_iter())
            .enumerate()
            .filter(|(_, (_, s))| !s.velocity.is_empty())
            .for_each(|(g, (u, s))| {
                let uw = offsets.get(g).map_or(SVector::zeros(), |b| 0.5 * b);
                let sum = s
                    .points
                    .iter()
                    .zip(&s.velocity)
                    .fold(SVector::zeros(), |acc, (&j, &c)| {
                        acc + c * (fluid[j as usize] - uw)
                    });
                *u = uw + sum;
            });
    }

    /// Ghost g's velocity stencil (points, c_j) where it has one.
    pub fn velocity_stencil(&self, g: usize) -> Option<(&[u32], &[f64])> {
        let s = self.stencils.get(g)?;
        (!s.velocity.is_empty()).then(|| (&s.points[..], &s.velocity[..]))
    }

    /// Writes each ghost's parent tensor into `ghosts`, continued where its stencil has one.
    pub fn tensor<T>(&self, fluid: &[T], parent: &[u32], ghosts: &mut [T])
    where
        T: Copy + Send + Sync + std::ops::Sub<Output = T> + std::ops::Mul<f64, Output = T>,
        T: std::ops::AddAssign,
    {
        ghosts.par_iter_mut().enumerate().for_each(|(g, t)| {
            let k = parent[g] as usize;
            *t = fluid[k];
            let Some(s) = self.stencils.get(g).filter(|s| !s.tensor.is_empty()) else {
                return;
            };
            for (&j, &a) in s.points.iter().zip(&s.tensor) {
                *t += (fluid[j as usize] - fluid[k]) * a;
            }
        });
    }
}

/// c_j of the velocity continuation at `arm` (module docs) into `c` (empty on entry), over
/// the parent and the `fluid` pair indices of its row; left empty where the fit is singular.
fn velocity_weights<const D: usize>(
    pairs: PairKernel<D>,
    fluid: impl Iterator<Item = usize> + Clone,
    arm: SVector<f64, D>,
    c: &mut Vec<f64>,
) where
    Dim<D>: Dimension<D>,
{
    let list = pairs.list;
    // Positions about the wall point, scaled by the support's reach for conditioning.
    let scale = fluid
        .clone()
        .map(|p| list.rij[p].norm())
        .fold(arm.norm(), f64::max);
    let nearest = fluid.clone().map(|p| pairs.value[p]).fold(0.0, f64::max);
    let rows = std::iter::once((-0.5 * arm, nearest))
        .chain(fluid.map(|p| (-list.rij[p] - 0.5 * arm, pairs.value[p])));
    Dim::<D>::quadratic_weights(rows, 0.5 * arm, scale, c);
}

/// a_j of the tensor continuation at `arm` (module docs) into `a` (empty on entry), over the
/// parent (a_k = 0) and the `fluid` pair indices of its row; left empty where B is singular.
fn tensor_weights<const D: usize>(
    pairs: PairKernel<D>,
    fluid: impl Iterator<Item = usize> + Clone,
    arm: SVector<f64, D>,
    a: &mut Vec<f64>,
) where
    Dim<D>: Dimension<D>,
{
    let list = pairs.list;
    let mut b = SMatrix::<f64, D, D>::zeros();
    for p in fluid.clone() {
        b -= pairs.factor[p] * list.rij[p] * list.rij[p].transpose();
    }
    let Some(inverse) = Dim::<D>::try_inverse(&b) else {
        return;
    };
    let w = inverse.transpose() * arm;
    a.push(0.0);
    a.extend(fluid.map(|p| w.dot(&(pairs.factor[p] * list.rij[p]))));
    if !a.iter().all(|v| v.is_finite()) {
        a.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::{Ghosts, Plane, Shape, TensorMirror, Wall};
    use crate::engine::kernel::QuinticSpline;
    use crate::engine::math::{Sym2, Vec2};
    use crate::engine::neighbours::{Domain, NeighbourSearch};

    /// W(r_k) and F(r_k) of each listed pair.
    type Pairs = (Vec<f64>, Vec<f64>);

    /// A lattice over the floor y = 0 (periodic in x), its mirrors, lists and pair kernels.
    fn floor_lattice() -> (Ghosts, Vec<Vec2>, NeighbourList, Pairs) {
        let (dr, m) = (0.1, 12);
        let kernel = QuinticSpline::for_spacing(dr);
        let mut points: Vec<Vec2> = (0..m * m)
            .map(|k| Vec2::new((k % m) as f64 * dr + 0.05, (k / m) as f64 * dr + 0.05))
            .collect();
        let n = points.len();
        let domain = Domain {
            min: Vec2::new(0.0, -1.0),
            max: Vec2::new(m as f64 * dr, 2.0),
            periodic: [true, false],
        };
        let floor = Wall::no_slip(Shape::Plane(Plane::floor()), TensorMirror::Linear);
        let mut ghosts = Ghosts::new(vec![floor]);
        ghosts.domain = Some(domain);
        ghosts.build(kernel.support(), &mut points);
        let mut list = NeighbourList::default();
        NeighbourSearch::default().build(&domain, &points, n, kernel.support(), &mut list);
        let (value, factor): (Vec<f64>, Vec<f64>) = (0..list.pairs())
            .map(|k| kernel.value_and_gradient_factor(list.rij[k].norm()))
            .unzip();
        let sums = (value, factor);
        let pairs = PairKernel {
            list: &list,
            value: &sums.0,
            factor: &sums.1,
        };
        ghosts.prepare_continuation(pairs, n, kernel.support());
        (ghosts, points, list, sums)
    }

    /// A velocity quadratic in y that vanishes on the wall is continued exactly (the mirror
    /// misses it by d²u''), and a tensor linear in y is continued exactly (the even copy
    /// misses it by 2d ∂T/∂y).
    #[test]
    fn continuations_are_exact_for_their_polynomials() {
        let (ghosts, points, _, _) = floor_lattice();
        let n = points.len() - ghosts.len();
        let u = |r: &Vec2| Vec2::new(3.0 * r.y - 2.0 * r.y * r.y, r.y * r.y);
        let fluid: Vec<Vec2> = points[..n].iter().map(u).collect();
        let mut ext = Vec::new();
        ghosts.continue_velocity(&fluid, &mut ext);
        for g in 0..ghosts.len() {
            let exact = u(&points[n + g]);
            assert!(
                (ext[n + g] - exact).norm() < 1e-9,
                "{} {}",
                ext[n + g],
                exact
            );
        }
        let t = |r: &Vec2| Sym2::new(1.0 + r.y, 2.0 - 3.0 * r.y, 4.0);
        let fluid: Vec<Sym2> = points[..n].iter().map(t).collect();
        let mut ext = Vec::new();
        ghosts.continue_tensor(&fluid, &mut ext);
        for g in 0..ghosts.len() {
            let d = ext[n + g] - t(&points[n + g]);
            assert!(d.contract(&d).sqrt() < 1e-9, "{:?}", d);
        }
    }

    /// Under `Mirror` the velocity keeps the odd copy `u_j = −u_i`.
    #[test]
    fn mirror_extension_keeps_the_odd_copy() {
        let (mut ghosts, points, list, sums) = floor_lattice();
        let n = points.len() - ghosts.len();
        ghosts.set_velocity_extension(VelocityExtension::Mirror);
        let pairs = PairKernel {
            list: &list,
            value: &sums.0,
            factor: &sums.1,
        };
        let support = QuinticSpline::for_spacing(0.1).support();
        ghosts.prepare_continuation(pairs, n, support);
        let fluid: Vec<Vec2> = points[..n]
            .iter()
            .map(|r| Vec2::new(r.y * r.y, 0.0))
            .collect();
        let mut ext = Vec::new();
        ghosts.continue_velocity(&fluid, &mut ext);
        for g in 0..ghosts.len() {
            assert_eq!(ext[n + g], -fluid[ghosts.parent[g] as usize]);
        }
    }

    /// In space: over the floor y = 0 of a 14 × 6 × 14 lattice (not periodic), the quadratic
    /// continuation is exact for a velocity quadratic in x, y and z that vanishes on the
    /// wall (its nine-monomial fit), and the tensor continuation for a tensor linear in all
    /// three, at every ghost whose parent's support lies inside the lattice (1e-9: the fits'
    /// round-off over ~250 points).
    #[test]
    fn continuations_are_exact_for_their_polynomials_in_3d() {
        use crate::engine::kernel::H_OVER_DR;
        use crate::engine::math::{Sym3, Vec3};
        let (dr, m, rows) = (0.1, 14, 6);
        let kernel = QuinticSpline::in_dimension::<3>(H_OVER_DR * dr);
        let mut points: Vec<Vec3> = (0..m * rows * m)
            .map(|k| {
                Vec3::new(
                    (k / (rows * m)) as f64,
                    ((k / m) % rows) as f64,
                    (k % m) as f64,
                )
            })
            .map(|c| c.add_scalar(0.5) * dr)
            .collect();
        let n = points.len();
        let side = m as f64 * dr;
        let domain = Domain::<3> {
            min: Vec3::new(0.0, -1.0, 0.0),
            max: Vec3::new(side, 2.0, side),
            periodic: [false; 3],
        };
        let floor = Wall::<3>::no_slip(Shape::Plane(Plane::floor()), TensorMirror::Linear);
        let mut ghosts = Ghosts::new(vec![floor]);
        ghosts.build(kernel.support(), &mut points);
        let mut list = NeighbourList::default();
        NeighbourSearch::<3>::new().build(&domain, &points, n, kernel.support(), &mut list);
        let (value, factor): (Vec<f64>, Vec<f64>) = (0..list.pairs())
            .map(|k| kernel.value_and_gradient_factor(list.rij[k].norm()))
            .unzip();
        let pairs = PairKernel {
            list: &list,
            value: &value,
            factor: &factor,
        };
        ghosts.prepare_continuation(pairs, n, kernel.support());
        let inside = |r: &Vec3| {
            let reach = kernel.support() + 1e-9;
            [r.x, r.z].iter().all(|&c| c > reach && c < side - reach)
        };
        let u = |r: &Vec3| {
            let (x, y, z) = (r.x, r.y, r.z);
            Vec3::new(
                3.0 * y - 2.0 * y * y + x * y,
                y * z - 0.5 * y,
                y * (1.0 + x - z),
            )
        };
        let fluid: Vec<Vec3> = points[..n].iter().map(u).collect();
        let mut ext = Vec::new();
        ghosts.continue_velocity(&fluid, &mut ext);
        let t = |r: &Vec3| {
            Sym3::from_entries(|a, b| 1.0 + (a + 2 * b) as f64 * r.x - r.y * (a as f64) + 0.3 * r.z)
        };
        let tensors: Vec<Sym3> = points[..n].iter().map(t).collect();
        let mut ext_t = Vec::new();
        ghosts.continue_tensor(&tensors, &mut ext_t);
        let mut checked = 0;
        for g in (0..ghosts.len()).filter(|&g| inside(&points[ghosts.parent[g] as usize])) {
            let at = points[n + g];
            assert!(
                (ext[n + g] - u(&at)).norm() < 1e-9,
                "{} {}",
                ext[n + g],
                u(&at)
            );
            let d = ext_t[n + g] - t(&at);
            assert!(d.contract(&d).sqrt() < 1e-9, "{d:?}");
            checked += 1;
        }
        assert!(checked > 100, "{checked} ghosts checked");
    }
}
