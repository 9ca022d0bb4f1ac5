//! The quintic spline kernel of Morris, Fox & Zhu (1997), support radius 3h, used with an
//! initial particle spacing δr = h/1.3 (King & Lind §III: about 44 neighbours in full support).

use crate::engine::dimension::{Dim, Dimension};

/// Smoothing length over initial particle spacing, h/δr.
pub const H_OVER_DR: f64 = 1.3;
/// Support radius over smoothing length.
pub const SUPPORT_OVER_H: f64 = 3.0;

/// The quintic spline `W(r, h)` in two or three dimensions.
#[derive(Clone, Copy, Debug)]
pub struct QuinticSpline {
    h: f64,
    inv_h: f64,
    /// Normalisation σ_d/h^d: 7/(478π h²) in 2D, 1/(120π h³) in 3D.
    sigma: f64,
    /// σ_d/h^d as a function of h, for the same kernel at another spacing.
    normalisation: fn(f64) -> f64,
}

impl QuinticSpline {
    /// The 2D kernel.
    pub fn new(h: f64) -> Self {
        Self::in_dimension::<2>(h)
    }

    /// The kernel in D dimensions: only the normalisation differs.
    pub fn in_dimension<const D: usize>(h: f64) -> Self
    where
        Dim<D>: Dimension<D>,
    {
        Self::with_normalisation(h, Dim::<D>::quintic_normalisation)
    }

    fn with_normalisation(h: f64, normalisation: fn(f64) -> f64) -> Self {
        Self {
            h,
            inv_h: 1.0 / h,
            sigma: normalisation(h),
            normalisation,
        }
    }

    /// The 2D kernel for particles spaced `dr` (h = 1.3 δr).
    pub fn for_spacing(dr: f64) -> Self {
        Self::new(H_OVER_DR * dr)
    }

    /// This kernel's dimension at spacing `dr` (graded resolution: a row's own kernel).
    pub fn at_spacing(&self, dr: f64) -> Self {
        Self::with_normalisation(H_OVER_DR * dr, self.normalisation)
    }

    pub fn h(&self) -> f64 {
        self.h
    }

    /// Support radius 3h.
    pub fn support(&self) -> f64 {
        SUPPORT_OVER_H * self.h
    }

    /// W(r).
    pub fn value(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
        self.sigma * (pow5(a) - 6.0 * pow5(b) + 15.0 * pow5(c))
    }

    /// dW/dr (≤ 0).
    pub fn derivative(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
        -5.0 * self.sigma * self.inv_h * (pow4(a) - 6.0 * pow4(b) + 15.0 * pow4(c))
    }

    /// W(r) and F(r) (see [`Self::gradient_factor`]) from one set of powers: the same values
    /// as the two calls, bit for bit.
    pub fn value_and_gradient_factor(&self, r: f64) -> (f64, f64) {
        let q = r * self.inv_h;
        let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
        let (a4, b4, c4) = (pow4(a), pow4(b), pow4(c));
        let value = self.sigma * (a4 * a - 6.0 * (b4 * b) + 15.0 * (c4 * c));
        let factor = if r < 1e-9 * self.h {
            -120.0 * self.sigma * self.inv_h * self.inv_h
        } else {
            -5.0 * self.sigma * self.inv_h * (a4 - 6.0 * b4 + 15.0 * c4) / r
        };
        (value, factor)
    }

    /// `F(r) = (dW/dr)/r`, so that the kernel gradient is `∇_i W_ij = F(r_ij) r_ij`.
    /// Finite at r = 0, where it tends to W''(0).
    pub fn gradient_factor(&self, r: f64) -> f64 {
        if r < 1e-9 * self.h {
            // d²W/dq² at q = 0: σ·20·(27 − 6·8 + 15) = −120σ.
            -120.0 * self.sigma * self.inv_h * self.inv_h
        } else {
            self.derivative(r) / r
        }
    }
}

fn pow4(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2
}

fn pow5(x: f64) -> f64 {
    pow4(x) * x
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The fused evaluation gives the two separate ones bit for bit (the kernel sums use it,
    /// and results must not change with it), at r = 0, inside each branch and past 3h.
    #[test]
    fn value_and_gradient_factor_match_the_separate_calls() {
        let k = QuinticSpline::for_spacing(0.05);
        for m in 0..400 {
            let r = m as f64 * 3.2 * k.h / 400.0;
            let (w, f) = k.value_and_gradient_factor(r);
            assert_eq!(w.to_bits(), k.value(r).to_bits(), "W at r = {r}");
            assert_eq!(f.to_bits(), k.gradient_factor(r).to_bits(), "F at r = {r}");
        }
    }

    /// ∫W dA = 1: midpoint quadrature on a fine polar grid (exact to ~1e-8).
    #[test]
    fn kernel_is_normalised() {
        let k = QuinticSpline::new(0.7);
        let n = 20_000;
        let dr = k.support() / n as f64;
        let integral: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                2.0 * PI * r * k.value(r) * dr
            })
            .sum();
        assert!((integral - 1.0).abs() < 1e-8, "∫W = {integral}");
        assert!(k.value(k.support()) < 1e-12 * k.value(0.0));
        assert_eq!(k.value(10.0), 0.0);
    }

    /// The derivative matches a central difference of W (to the difference's O(ε²) error).
    #[test]
    fn derivative_matches_finite_difference() {
        let k = QuinticSpline::new(1.0);
        let eps = 1e-6;
        for &r in &[0.1, 0.5, 0.99, 1.01, 1.7, 2.5, 2.99] {
            let fd = (k.value(r + eps) - k.value(r - eps)) / (2.0 * eps);
            assert!((fd - k.derivative(r)).abs() < 1e-8, "r = {r}");
        }
        assert!(k.derivative(0.0).abs() < 1e-15);
        let near_zero = k.derivative(1e-5) / 1e-5;
        assert!((near_zero - k.gradient_factor(0.0)).abs() < 1e-6 * near_zero.abs());
    }

    /// Gradient consistency on a regular lattice: Σ_j (r_j − r_i) ⊗ ∇W_ij δV = I, the
    /// property Bonet–Lok correction restores where it fails (eq. (22)).
    #[test]
    fn lattice_gradient_moment_is_identity() {
        let dr = 0.1;
        let k = QuinticSpline::for_spacing(dr);
        let mut m = [[0.0; 2]; 2];
        let reach = 5;
        for i in -reach..=reach {
            for j in -reach..=reach {
                let rij = [-(i as f64) * dr, -(j as f64) * dr]; // r_i − r_j with r_i = 0
                let r = (rij[0] * rij[0] + rij[1] * rij[1]).sqrt();
                if r == 0.0 {
                    continue;
                }
                let f = k.gradient_factor(r);
                for a in 0..2 {
                    for b in 0..2 {
                        m[a][b] += -rij[a] * f * rij[b] * dr * dr;
                    }
                }
            }
        }
        // Lattice sums of a smooth kernel with h = 1.3δr converge spectrally; 1e-3 is loose.
        assert!(
            (m[0][0] - 1.0).abs() < 1e-3 && (m[1][1] - 1.0).abs() < 1e-3,
            "{m:?}"
        );
        assert!(m[0][1].abs() < 1e-12);
    }

    /// In 3D: ∫W dV = 1 (midpoint rule in r, ~1e-8), and on a simple cubic lattice
    /// h = 1.3δr the Shepard sum Σ_j W_ij δV and the gradient moment
    /// Σ_j (r_j − r_i) ⊗ ∇W_ij δV are 1 and I to the lattice sums' spectral accuracy (1e-3 is
    /// loose, as in 2D), with about 4π(3.9)³/3 ≈ 248 neighbours in full support.
    #[test]
    fn the_3d_kernel_is_normalised_and_consistent_on_a_lattice() {
        let dr = 0.1;
        let k = QuinticSpline::in_dimension::<3>(crate::engine::kernel::H_OVER_DR * dr);
        let n = 20_000;
        let step = k.support() / n as f64;
        let integral: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * step;
                4.0 * PI * r * r * k.value(r) * step
            })
            .sum();
        assert!((integral - 1.0).abs() < 1e-8, "∫W = {integral}");
        let (mut shepard, mut moment, mut neighbours) = (0.0, [[0.0; 3]; 3], 0);
        let volume = dr * dr * dr;
        let reach = 4;
        for i in -reach..=reach {
            for j in -reach..=reach {
                for l in -reach..=reach {
                    let rji = [i as f64 * dr, j as f64 * dr, l as f64 * dr];
                    let r = rji.iter().map(|x| x * x).sum::<f64>().sqrt();
                    shepard += k.value(r) * volume;
                    if r == 0.0 || r >= k.support() {
                        continue;
                    }
                    neighbours += 1;
                    let f = k.gradient_factor(r);
                    for a in 0..3 {
                        for b in 0..3 {
                            // ∇_i W_ij = F(r) (r_i − r_j) = −F(r) r_ji.
                            moment[a][b] += rji[a] * (-f * rji[b]) * volume;
                        }
                    }
                }
            }
        }
        assert!((shepard - 1.0).abs() < 1e-3, "Σ W δV = {shepard}");
        for a in 0..3 {
            for b in 0..3 {
                let expected = if a == b { 1.0 } else { 0.0 };
                assert!((moment[a][b] - expected).abs() < 1e-3, "{moment:?}");
            }
        }
        assert!((240..=260).contains(&neighbours), "{neighbours} neighbours");
    }
}
