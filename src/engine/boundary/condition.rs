//! Wall conditions: what a wall imposes, through the values its mirror particles carry
//! (King & Lind §III C). A mirror j of fluid particle i carries
//!
//! * the velocity `u_j = s u_i + b_j`: s = −1 and b = 0 for a wall at rest (no slip: the
//!   velocity vanishes on the wall to second order); a moving wall adds its own part b;
//! * the pressure `p_j = s_p p_i`: s_p = +1, a homogeneous Neumann condition (in the PPE the
//!   mirror's unknown *is* its parent's);
//! * a tensor (conformation, stress) mapped from its parent's.
//!
//! The linear factors s, s_p fold mirrors into their parents' columns of the implicit
//! matrices ([`crate::engine::laplacian_matrix`]); the operators read the same values from
//! [`super::Ghosts`]' extensions. A condition is a type implementing [`WallCondition`]; a
//! [`super::Wall`] is a shape with a condition.

use crate::engine::dimension::{Dim, Dimension, SymTensor};
use crate::engine::math::{Sym2, Vec2};
use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};
use std::fmt;

/// A point in D dimensions.
type Point<const D: usize> = SVector<f64, D>;
/// The symmetric tensor of D dimensions.
type Sym<const D: usize> = <Dim<D> as Dimension<D>>::Sym;

/// What a wall imposes on the values of its mirrors, in D dimensions (the default 2).
pub trait WallCondition<const D: usize = 2>: fmt::Debug + Send + Sync
where
    Dim<D>: Dimension<D>,
{
    /// s of `u_j = s u_i + b_j`.
    fn velocity_sign(&self) -> f64;
    /// b_j at a mirror point (zero for a wall at rest).
    fn velocity_offset(&self, _mirror: Point<D>) -> Point<D> {
        Point::<D>::zeros()
    }
    /// Whether b is not zero anywhere (so that it must be added at all).
    fn moves(&self) -> bool {
        false
    }
    /// s_p of `p_j = s_p p_i`.
    fn pressure_sign(&self) -> f64 {
        1.0
    }
    /// The mirror's tensor from its parent's; `normal` is the wall normal between them.
    fn tensor(&self, parent: &Sym<D>, normal: &Point<D>) -> Sym<D>;
    /// Whether the parent's tensor is first continued linearly to the mirror
    /// ([`TensorMirror::Linear`]).
    fn continues_tensor(&self) -> bool {
        false
    }
}

/// How a tensor is carried onto a no-slip wall's mirror particle.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum TensorMirror {
    /// `A_j = A_i + (r_j − r_i)·∇A_i`, ∇ the Bonet–Lok gradient over the parent's fluid
    /// neighbours (the default; [`super::continuation`]): the tensor continued across the
    /// wall to first order, so that the operators read a smooth field there. The even copy
    /// puts a kink into every tensor whose wall-normal derivative does not vanish at the wall:
    /// in the start-up channel (Oldroyd-B, β = 0.1, H/δr = 30) τ_xy = η_p ∂u/∂y is linear in
    /// y, and the even copy left the stress divergence of the first wall layers short, a
    /// steady velocity error of 0.85 % (τ_xy 1.8 %, τ_xx 4.6 %); continued, 0.32 % (0.12 %,
    /// 0.28 %), the rest being the velocity's mirror ([`super::VelocityExtension`]). The
    /// stress divergence reads it; the transport of A keeps the even copy (the conformation
    /// stage's `remap_rate` says why).
    #[default]
    Linear,
    /// `A_j = A_i`: even across a no-slip wall (King & Lind's; see [`NoSlip`]).
    Even,
    /// `A_j = P A_i P` with P = I − 2nnᵀ the reflection across the surface: the shear
    /// component odd across the wall (free-slip-like).
    Reflected,
}

/// A no-slip wall at rest: `u_j = −u_i`, `p_j = p_i`, and the conformation continued across
/// the wall ([`TensorMirror::Linear`]), even (`A_j = A_i`) or reflected.
///
/// Why not odd: the mirrored velocity `u_m(x, −y) = −u(x, y)` has wall-normal gradient
/// `∂u_m/∂y = +∂u/∂y`, so the shear rate, which drives the polymer stress, is even across a
/// no-slip wall, and its evolution `Ȧ = ∇u·A + A·∇uᵀ − f_R/λ` evaluated with the mirrored
/// gradient agrees with the parent's up to terms (∂u/∂x, ∂v/∂x) that vanish on the wall. The
/// odd, reflection-symmetric choice `P A P` (the free-slip one) would force τ_xy = 0 at the
/// wall, where for Poiseuille flow it is largest. The even copy is right at the wall but not
/// beyond it, where the continued one is. `tests/wall_stress.rs` measures the rules against
/// the analytic wall shear stress.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoSlip {
    pub tensor: TensorMirror,
}

impl<const D: usize> WallCondition<D> for NoSlip
where
    Dim<D>: Dimension<D>,
{
    fn velocity_sign(&self) -> f64 {
        -1.0
    }

    fn tensor(&self, parent: &Sym<D>, normal: &Point<D>) -> Sym<D> {
        match self.tensor {
            TensorMirror::Even | TensorMirror::Linear => *parent,
            TensorMirror::Reflected => {
                let reflection =
                    SMatrix::<f64, D, D>::identity() - 2.0 * normal * normal.transpose();
                parent.congruence(&reflection)
            }
        }
    }

    fn continues_tensor(&self) -> bool {
        self.tensor == TensorMirror::Linear
    }
}

/// A no-slip plane wall sliding along itself at `velocity`: `u_j = 2u_w − u_i`, so that the
/// velocity on the wall is u_w to second order; pressure and conformation as [`NoSlip`].
/// The wall velocity must be tangential (a plane wall does not move through the fluid).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlidingNoSlip<const D: usize = 2> {
    pub tensor: TensorMirror,
    pub velocity: Point<D>,
}

impl<const D: usize> WallCondition<D> for SlidingNoSlip<D>
where
    Dim<D>: Dimension<D>,
{
    fn velocity_sign(&self) -> f64 {
        -1.0
    }

    fn velocity_offset(&self, _mirror: Point<D>) -> Point<D> {
        2.0 * self.velocity
    }

    fn moves(&self) -> bool {
        self.velocity != Point::<D>::zeros()
    }

    fn tensor(&self, parent: &Sym<D>, normal: &Point<D>) -> Sym<D> {
        NoSlip {
            tensor: self.tensor,
        }
        .tensor(parent, normal)
    }

    fn continues_tensor(&self) -> bool {
        self.tensor == TensorMirror::Linear
    }
}

/// A no-slip wall moving rigidly: translating at `velocity` and spinning at `spin`
/// (counter-clockwise) about `centre`, so that its surface point x_s moves at
/// u_w = V + Ω ẑ × (x_s − c). The mirror of a particle across a circle of `radius` about
/// `centre` carries `u_j = 2u_w(x_s) − u_i` with x_s where r_ij crosses the surface (on the
/// radius through the mirror); pressure and conformation as [`NoSlip`]. The pressure mirror
/// stays even: the normal pressure gradient of the body's acceleration, ρ a·n, is left out
/// (it is ρΩ²R for steady rotation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidNoSlip {
    pub tensor: TensorMirror,
    pub centre: Vec2,
    pub radius: f64,
    pub velocity: Vec2,
    pub spin: f64,
}

impl RigidNoSlip {
    /// The surface velocity at a point x: V + Ω ẑ × (x − c).
    pub fn surface_velocity(&self, x: Vec2) -> Vec2 {
        let r = x - self.centre;
        self.velocity + self.spin * Vec2::new(-r.y, r.x)
    }
}

impl WallCondition for RigidNoSlip {
    fn velocity_sign(&self) -> f64 {
        -1.0
    }

    fn velocity_offset(&self, mirror: Vec2) -> Vec2 {
        let r = mirror - self.centre;
        let surface = self.centre + r * (self.radius / r.norm().max(f64::MIN_POSITIVE));
        2.0 * self.surface_velocity(surface)
    }

    fn moves(&self) -> bool {
        self.velocity != Vec2::zeros() || self.spin != 0.0
    }

    fn tensor(&self, parent: &Sym2, normal: &Vec2) -> Sym2 {
        NoSlip {
            tensor: self.tensor,
        }
        .tensor(parent, normal)
    }

    fn continues_tensor(&self) -> bool {
        self.tensor == TensorMirror::Linear
    }
}

/// A no-slip sphere turning rigidly at `spin` about its `centre` (in space): its surface
/// point x_s moves at u_w = Ω × (x_s − c), and the mirror of a particle carries
/// `u_j = 2u_w(x_s) − u_i` with x_s where r_ij crosses the surface (on the radius through the
/// mirror); pressure and conformation as [`NoSlip`]. It counts as moving even at Ω = 0, so
/// that the ghosts keep offsets for the spin a freely turning sphere takes up later
/// ([`crate::engine::bodies::sphere`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurningNoSlip {
    pub tensor: TensorMirror,
    pub centre: SVector<f64, 3>,
    pub radius: f64,
    pub spin: SVector<f64, 3>,
}

impl WallCondition<3> for TurningNoSlip {
    fn velocity_sign(&self) -> f64 {
        -1.0
    }

    fn velocity_offset(&self, mirror: SVector<f64, 3>) -> SVector<f64, 3> {
        let r = mirror - self.centre;
        let on_surface = r * (self.radius / r.norm().max(f64::MIN_POSITIVE));
        2.0 * self.spin.cross(&on_surface)
    }

    fn moves(&self) -> bool {
        true
    }

    fn tensor(&self, parent: &Sym<3>, normal: &SVector<f64, 3>) -> Sym<3> {
        NoSlip {
            tensor: self.tensor,
        }
        .tensor(parent, normal)
    }

    fn continues_tensor(&self) -> bool {
        self.tensor == TensorMirror::Linear
    }
}

/// The condition of a [`super::shape::Corner`]'s point-reflected ghost: the mirror across
/// wall `second` of the mirror across wall `first`. With `u_a = s₁u_i + b₁(x_a)` on the first
/// mirror x_a and `u_c = s₂u_a + b₂(x_c)` on its mirror x_c, the ghost carries
/// `u_c = s₁s₂ u_i + s₂b₁(x_a) + b₂(x_c)`, where x_a is x_c reflected back across the second
/// wall (perpendicular reflections commute); pressure factor s_p₁s_p₂; the tensor mapped by
/// one condition, then the other.
#[derive(Debug)]
pub struct Corner<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub first: (super::Plane, std::sync::Arc<dyn WallCondition<D>>),
    pub second: (super::Plane, std::sync::Arc<dyn WallCondition<D>>),
}

impl<const D: usize> Corner<D>
where
    Dim<D>: Dimension<D>,
{
    fn unit_normal(plane: &super::Plane) -> Point<D> {
        let mut n = Point::<D>::zeros();
        n[plane.axis] = 1.0;
        n
    }
}

impl<const D: usize> WallCondition<D> for Corner<D>
where
    Dim<D>: Dimension<D>,
{
    fn velocity_sign(&self) -> f64 {
        self.first.1.velocity_sign() * self.second.1.velocity_sign()
    }

    fn velocity_offset(&self, mirror: Point<D>) -> Point<D> {
        let first_mirror = self.second.0.reflect(&mirror);
        self.second.1.velocity_sign() * self.first.1.velocity_offset(first_mirror)
            + self.second.1.velocity_offset(mirror)
    }

    fn moves(&self) -> bool {
        self.first.1.moves() || self.second.1.moves()
    }

    fn pressure_sign(&self) -> f64 {
        self.first.1.pressure_sign() * self.second.1.pressure_sign()
    }

    fn tensor(&self, parent: &Sym<D>, _normal: &Point<D>) -> Sym<D> {
        let once = self
            .first
            .1
            .tensor(parent, &Self::unit_normal(&self.first.0));
        self.second
            .1
            .tensor(&once, &Self::unit_normal(&self.second.0))
    }

    fn continues_tensor(&self) -> bool {
        self.first.1.continues_tensor() || self.second.1.continues_tensor()
    }
}

/// A plane lid sliding along x with the regularised profile of Fattal & Kupferman (2005),
/// u_w(x) = 16U (x/L)²(1 − x/L)², which vanishes with its slope at the corners x = 0, L
/// (a uniform lid's corner singularities make the stress unbounded there for any Wi).
/// Mirrors carry u_j = 2u_w(x_j) − u_i at their own x (a plane mirror's x is its
/// parent's); pressure and conformation as [`NoSlip`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegularisedLid {
    pub tensor: TensorMirror,
    /// U, the lid's speed at x = L/2.
    pub speed: f64,
    /// L, the lid's length from x = 0.
    pub length: f64,
}

impl RegularisedLid {
    /// u_w(x) along x, zero beyond the lid.
    pub fn velocity_at(&self, x: f64) -> f64 {
        let s = (x / self.length).clamp(0.0, 1.0);
        16.0 * self.speed * s * s * (1.0 - s) * (1.0 - s)
    }
}

impl<const D: usize> WallCondition<D> for RegularisedLid
where
    Dim<D>: Dimension<D>,
{
    fn velocity_sign(&self) -> f64 {
        -1.0
    }

    fn velocity_offset(&self, mirror: Point<D>) -> Point<D> {
        let mut b = Point::<D>::zeros();
        b[0] = 2.0 * self.velocity_at(mirror[0]);
        b
    }

    fn moves(&self) -> bool {
        self.speed != 0.0
    }

    fn tensor(&self, parent: &Sym<D>, normal: &Point<D>) -> Sym<D> {
        NoSlip {
            tensor: self.tensor,
        }
        .tensor(parent, normal)
    }

    fn continues_tensor(&self) -> bool {
        self.tensor == TensorMirror::Linear
    }
}
