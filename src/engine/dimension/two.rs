//! Two dimensions: [`Sym2`] and its closed-form eigen-decomposition.

use super::{Dim, Dimension, SymTensor};
use crate::engine::math::{Mat2, Sym2, Vec2};
use crate::engine::second_order::Second;
use nalgebra::SVector;

impl Dimension<2> for Dim<2> {
    type Sym = Sym2;
    /// 7/(478π h²) (Morris, Fox & Zhu 1997).
    fn quintic_normalisation(h: f64) -> f64 {
        7.0 / (478.0 * std::f64::consts::PI * h * h)
    }
    #[inline]
    fn determinant(m: &Mat2) -> f64 {
        m.determinant()
    }
    #[inline]
    fn try_inverse(m: &Mat2) -> Option<Mat2> {
        m.try_inverse()
    }
    fn second_order_row(
        grad: &mut [Vec2],
        laplacian: &mut [f64],
        factor: &[f64],
        rij: &[Vec2],
        h: f64,
        dv: f64,
        which: Second,
    ) {
        crate::engine::second_order::second_order_row(grad, laplacian, factor, rij, h, dv, which);
    }
    fn tangential(s: f64, v: &Vec2, normal: &Vec2) -> Vec2 {
        let m = Vec2::new(-normal.y, normal.x);
        s * m.dot(v) * m
    }
    fn quadratic_weights(
        rows: impl Iterator<Item = (Vec2, f64)> + Clone,
        at: Vec2,
        scale: f64,
        c: &mut Vec<f64>,
    ) {
        let basis = |r: Vec2| SVector::<f64, 5>::from([r.x, r.y, r.x * r.x, r.x * r.y, r.y * r.y]);
        super::fit_weights(basis, rows, at, scale, c);
    }
}

impl SymTensor for Sym2 {
    const DIM: usize = 2;
    const ZERO: Self = Sym2::ZERO;
    const IDENTITY: Self = Sym2::IDENTITY;
    type Matrix = Mat2;
    type Vector = Vec2;
    type Values = [f64; 2];

    #[inline]
    fn entry(&self, i: usize, j: usize) -> f64 {
        match i + j {
            0 => self.xx,
            1 => self.xy,
            _ => self.yy,
        }
    }
    #[inline]
    fn from_entries(f: impl Fn(usize, usize) -> f64) -> Self {
        Sym2::new(f(0, 0), f(0, 1), f(1, 1))
    }
    #[inline]
    fn diagonal(values: &[f64; 2]) -> Self {
        Sym2::new(values[0], 0.0, values[1])
    }
    #[inline]
    fn values_from(f: impl Fn(usize) -> f64) -> [f64; 2] {
        [f(0), f(1)]
    }
    #[inline]
    fn trace(&self) -> f64 {
        Sym2::trace(self)
    }
    #[inline]
    fn det(&self) -> f64 {
        Sym2::det(self)
    }
    #[inline]
    fn is_finite(&self) -> bool {
        Sym2::is_finite(self)
    }
    #[inline]
    fn contract(&self, other: &Self) -> f64 {
        Sym2::contract(self, other)
    }
    #[inline]
    fn dot(&self, v: &Vec2) -> Vec2 {
        Sym2::dot(self, v)
    }
    #[inline]
    fn sym_part(m: &Mat2) -> Self {
        Sym2::sym_part(m)
    }
    #[inline]
    fn to_mat(&self) -> Mat2 {
        Sym2::to_mat(self)
    }
    #[inline]
    fn transpose(m: &Mat2) -> Mat2 {
        m.transpose()
    }
    #[inline]
    fn congruence(&self, m: &Mat2) -> Self {
        Sym2::congruence(self, m)
    }
    #[inline]
    fn eigen_decomposition(&self) -> ([f64; 2], Mat2) {
        let e = self.eigen();
        (e.values, e.rotation())
    }
    #[inline]
    fn log(&self) -> Self {
        Sym2::log(self)
    }
    #[inline]
    fn exp(&self) -> Self {
        Sym2::exp(self)
    }
    #[inline]
    fn max_eigenvalue(&self) -> f64 {
        Sym2::max_eigenvalue(self)
    }
}
