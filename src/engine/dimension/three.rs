//! Three dimensions: [`Sym3`] and its Jacobi eigen-decomposition.

use super::{Dim, Dimension, SymTensor};
use crate::engine::math::{Mat3, Sym3, Vec3};
use crate::engine::second_order::Second;
use nalgebra::SVector;

impl Dimension<3> for Dim<3> {
    type Sym = Sym3;
    /// 1/(120π h³) (Morris, Fox & Zhu 1997).
    fn quintic_normalisation(h: f64) -> f64 {
        1.0 / (120.0 * std::f64::consts::PI * h * h * h)
    }
    #[inline]
    fn determinant(m: &Mat3) -> f64 {
        m.determinant()
    }
    #[inline]
    fn try_inverse(m: &Mat3) -> Option<Mat3> {
        m.try_inverse()
    }
    fn second_order_row(
        grad: &mut [Vec3],
        laplacian: &mut [f64],
        factor: &[f64],
        rij: &[Vec3],
        h: f64,
        dv: f64,
        which: Second,
    ) {
        let _ = (grad, laplacian, factor, rij, h, dv, which);
    }
    fn tangential(s: f64, v: &Vec3, normal: &Vec3) -> Vec3 {
        s * (v - v.dot(normal) * normal)
    }
    fn quadratic_weights(
        rows: impl Iterator<Item = (Vec3, f64)> + Clone,
        at: Vec3,
        scale: f64,
        c: &mut Vec<f64>,
    ) {
        let basis = |r: Vec3| {
            let (x, y, z) = (r.x, r.y, r.z);
            SVector::<f64, 9>::from([x, y, z, x * x, x * y, x * z, y * y, y * z, z * z])
        };
        super::fit_weights(basis, rows, at, scale, c);
    }
}

impl SymTensor for Sym3 {
    const DIM: usize = 3;
    const ZERO: Self = Sym3::ZERO;
    const IDENTITY: Self = Sym3::IDENTITY;
    type Matrix = Mat3;
    type Vector = Vec3;
    type Values = [f64; 3];

    #[inline]
    fn entry(&self, i: usize, j: usize) -> f64 {
        Sym3::entry(self, i, j)
    }
    #[inline]
    fn from_entries(f: impl Fn(usize, usize) -> f64) -> Self {
        Sym3::from_entries(f)
    }
    #[inline]
    fn diagonal(values: &[f64; 3]) -> Self {
        Sym3::new(values[0], 0.0, 0.0, values[1], 0.0, values[2])
    }
    #[inline]
    fn values_from(f: impl Fn(usize) -> f64) -> [f64; 3] {
        [f(0), f(1), f(2)]
    }
    #[inline]
    fn trace(&self) -> f64 {
        Sym3::trace(self)
    }
    #[inline]
    fn det(&self) -> f64 {
        Sym3::det(self)
    }
    #[inline]
    fn is_finite(&self) -> bool {
        Sym3::is_finite(self)
    }
    #[inline]
    fn contract(&self, other: &Self) -> f64 {
        Sym3::contract(self, other)
    }
    #[inline]
    fn dot(&self, v: &Vec3) -> Vec3 {
        Sym3::dot(self, v)
    }
    #[inline]
    fn sym_part(m: &Mat3) -> Self {
        Sym3::sym_part(m)
    }
    #[inline]
    fn to_mat(&self) -> Mat3 {
        Sym3::to_mat(self)
    }
    #[inline]
    fn transpose(m: &Mat3) -> Mat3 {
        m.transpose()
    }
    #[inline]
    fn congruence(&self, m: &Mat3) -> Self {
        Sym3::congruence(self, m)
    }
    #[inline]
    fn eigen_decomposition(&self) -> ([f64; 3], Mat3) {
        let e = self.eigen();
        (e.values, e.rotation)
    }
    #[inline]
    fn log(&self) -> Self {
        Sym3::log(self)
    }
    #[inline]
    fn exp(&self) -> Self {
        Sym3::exp(self)
    }
    #[inline]
    fn max_eigenvalue(&self) -> f64 {
        Sym3::max_eigenvalue(self)
    }
}
