//! The number of space dimensions as a type, chosen once at set-up: [`Two`] or [`Three`].
//!
//! Code is written once, generic over `const D: usize` with nalgebra's fixed-size
//! `SVector<f64, D>` and `SMatrix<f64, D, D>`, and with the bound `Dim<D>: Dimension<D>`
//! where it needs what differs between the two: the symmetric tensor type and its
//! eigen-decomposition, 2 × 2 or 3 × 3 inverses, and the kernel's normalisation, which live
//! in `two.rs` and `three.rs`. Both are monomorphised for each dimension, so a hot loop never
//! tests it.

mod three;
mod two;

use crate::engine::second_order::Second;
use nalgebra::{SMatrix, SVector};
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Index, IndexMut, Mul, Sub};

/// D space dimensions: implemented for [`Dim<2>`](Two) and [`Dim<3>`](Three).
pub trait Dimension<const D: usize>: Copy + Debug + Send + Sync + 'static {
    /// A symmetric tensor (conformation, stresses).
    type Sym: SymTensor<Matrix = SMatrix<f64, D, D>, Vector = SVector<f64, D>>;
    /// The quintic spline's factor σ_d/h^d in W = σ_d/h^d [(3 − q)⁵ − 6(2 − q)⁵ + 15(1 − q)⁵]
    /// (Morris, Fox & Zhu 1997), so that W integrates to one over its support.
    fn quintic_normalisation(h: f64) -> f64;
    fn determinant(m: &SMatrix<f64, D, D>) -> f64;
    fn try_inverse(m: &SMatrix<f64, D, D>) -> Option<SMatrix<f64, D, D>>;
    /// Overwrites one particle's gradient and/or Laplacian weights with the second-order
    /// ones ([`crate::engine::second_order`]): the plane's 5 × 5 moment system; in 3D not
    /// written yet, the weights stay first order (a 3D set-up must refuse the option).
    #[allow(clippy::too_many_arguments)]
    fn second_order_row(
        grad: &mut [SVector<f64, D>],
        laplacian: &mut [f64],
        factor: &[f64],
        rij: &[SVector<f64, D>],
        h: f64,
        dv: f64,
        which: Second,
    );
    /// s times the part of `v` along the surface whose unit normal is `normal`: s(m·v)m with
    /// m the tangent in the plane, s(v − (v·n)n) in space.
    fn tangential(s: f64, v: &SVector<f64, D>, normal: &SVector<f64, D>) -> SVector<f64, D>;
    /// The weights c_j of the weighted least-squares fit `a·x + B:xx` (no constant term)
    /// through `rows` (point about the fit's origin, weight), evaluated at `at`, appended to
    /// `c` (Σ_j c_j f_j is the fit's value there); points are divided by `scale` first. Left
    /// empty where the moment matrix is singular or a weight is not finite. D + D(D+1)/2
    /// monomials: 5 in the plane, 9 in space.
    fn quadratic_weights(
        rows: impl Iterator<Item = (SVector<f64, D>, f64)> + Clone,
        at: SVector<f64, D>,
        scale: f64,
        c: &mut Vec<f64>,
    );
}

/// [`Dimension::quadratic_weights`] over the N monomials `basis` gives of a scaled point.
pub(crate) fn fit_weights<const D: usize, const N: usize>(
    basis: impl Fn(SVector<f64, D>) -> SVector<f64, N>,
    rows: impl Iterator<Item = (SVector<f64, D>, f64)> + Clone,
    at: SVector<f64, D>,
    scale: f64,
    c: &mut Vec<f64>,
) {
    let basis = |r: SVector<f64, D>| basis(r / scale);
    let mut m = SMatrix::<f64, N, N>::zeros();
    for (at, w) in rows.clone() {
        let b = basis(at);
        m += w * b * b.transpose();
    }
    let Some(inverse) = m.try_inverse() else {
        return;
    };
    let z = inverse * basis(at);
    c.extend(rows.map(|(at, w)| w * z.dot(&basis(at))));
    if !c.iter().all(|v| v.is_finite()) {
        c.clear();
    }
}

/// A vector (point, velocity) in D dimensions.
pub type Vector<const D: usize> = SVector<f64, D>;
/// A general D × D matrix (a velocity gradient: `[(a, b)] = ∂u_a/∂x_b`).
pub type Matrix<const D: usize> = SMatrix<f64, D, D>;
/// The symmetric tensor of D dimensions (needs the bound `Dim<D>: Dimension<D>`).
pub type Sym<const D: usize> = <Dim<D> as Dimension<D>>::Sym;

/// D space dimensions, as a type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim<const D: usize>;

/// The plane.
pub type Two = Dim<2>;

/// Space.
pub type Three = Dim<3>;

/// A symmetric DIM × DIM tensor: the operations the constitutive models and the
/// log-conformation update (eqs. (12)–(19), (29)–(33)) are written with.
pub trait SymTensor:
    Copy
    + Debug
    + Default
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<f64, Output = Self>
    + AddAssign
{
    /// The number of space dimensions, tr I.
    const DIM: usize;
    const ZERO: Self;
    const IDENTITY: Self;
    /// A general DIM × DIM matrix; `m[(a, b)]` for a velocity gradient is ∂u_a/∂x_b.
    type Matrix: Copy
        + Debug
        + Add<Output = Self::Matrix>
        + Mul<Output = Self::Matrix>
        + Index<(usize, usize), Output = f64>;
    /// A DIM-vector.
    type Vector: Copy + Debug;
    /// DIM eigenvalues, largest first.
    type Values: Copy + Debug + Index<usize, Output = f64> + IndexMut<usize> + AsRef<[f64]>;

    /// The component (i, j), either order.
    fn entry(&self, i: usize, j: usize) -> f64;
    /// The tensor whose component (i, j), i ≤ j, is `f(i, j)`.
    fn from_entries(f: impl Fn(usize, usize) -> f64) -> Self;
    /// diag(values) in the coordinate axes.
    fn diagonal(values: &Self::Values) -> Self;
    /// DIM values `f(0), f(1), …`.
    fn values_from(f: impl Fn(usize) -> f64) -> Self::Values;
    fn trace(&self) -> f64;
    fn det(&self) -> f64;
    fn is_finite(&self) -> bool;
    /// Frobenius product `self : other`.
    fn contract(&self, other: &Self) -> f64;
    /// `self·v`.
    fn dot(&self, v: &Self::Vector) -> Self::Vector;
    /// The symmetric part `(m + mᵀ)/2` of a general matrix.
    fn sym_part(m: &Self::Matrix) -> Self;
    fn to_mat(&self) -> Self::Matrix;
    fn transpose(m: &Self::Matrix) -> Self::Matrix;
    /// `m·self·mᵀ`.
    fn congruence(&self, m: &Self::Matrix) -> Self;
    /// Eigenvalues (largest first) and the rotation R whose columns are the eigenvectors,
    /// eq. (12): self = R diag(values) Rᵀ.
    fn eigen_decomposition(&self) -> (Self::Values, Self::Matrix);
    /// Matrix logarithm R ln Λ Rᵀ, eq. (13).
    fn log(&self) -> Self;
    /// Matrix exponential R exp(Λ) Rᵀ.
    fn exp(&self) -> Self;
    fn max_eigenvalue(&self) -> f64;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::{Sym2, Sym3};

    /// The quintic spline integrates to one over its support in each dimension:
    /// ∫ W dV = σ s_d ∫₀³ w(q) q^{d−1} dq with s_d the area of the unit sphere (2π, 4π),
    /// by Simpson's rule on 3 000 intervals (exact to round-off for the piecewise
    /// polynomial w up to the breakpoints at q = 1, 2, which fall on nodes).
    #[test]
    fn the_quintic_normalisation_makes_the_kernel_integrate_to_one() {
        fn integral<const D: usize>(sphere: f64) -> f64
        where
            Dim<D>: Dimension<D>,
        {
            let w = |q: f64| {
                let p = |x: f64| x.max(0.0).powi(5);
                p(3.0 - q) - 6.0 * p(2.0 - q) + 15.0 * p(1.0 - q)
            };
            let n = 3000;
            let dq = 3.0 / n as f64;
            let f = |k: usize| {
                let q = k as f64 * dq;
                w(q) * q.powi(D as i32 - 1)
            };
            let inner: f64 = (1..n)
                .map(|k| f(k) * if k % 2 == 1 { 4.0 } else { 2.0 })
                .sum();
            Dim::<D>::quintic_normalisation(1.0) * sphere * (f(0) + inner + f(n)) * dq / 3.0
        }
        let pi = std::f64::consts::PI;
        assert!((integral::<2>(2.0 * pi) - 1.0).abs() < 1e-12);
        assert!((integral::<3>(4.0 * pi) - 1.0).abs() < 1e-12);
    }

    /// Each type's eigen-decomposition reconstructs its tensor through the trait.
    #[test]
    fn eigen_decomposition_reconstructs_through_the_trait() {
        fn check<S: SymTensor>(a: S) {
            let (values, r) = a.eigen_decomposition();
            let back = S::diagonal(&values).congruence(&r);
            let d = back - a;
            assert!(
                d.contract(&d).sqrt() < 1e-13 * a.contract(&a).sqrt(),
                "{a:?}"
            );
            assert!((a.log().exp() - a).contract(&(a.log().exp() - a)) < 1e-24);
        }
        check(Sym2::new(3.0, 1.2, 0.5));
        check(Sym3::new(3.0, 1.2, -0.4, 2.5, 0.3, 1.1));
    }
}
