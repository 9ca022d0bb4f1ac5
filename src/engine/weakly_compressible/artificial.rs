//! The two stabilising terms of classic weakly compressible SPH, as Fang et al. (2006) use them
//! (their eqs. (30)–(44)):
//!
//! * Monaghan's artificial viscosity (Monaghan 1992), for an approaching pair (u_ij·r_ij < 0)
//!   `Π_ij = (−α_Π c φ_ij + β_Π φ_ij²)/ρ̄_ij`, `φ_ij = h u_ij·r_ij/(|r_ij|² + 0.01h²)`, a
//!   pressure-like term of the pair; 0 for a receding pair. Wróblewski, Boryczko & Kopeć
//!   (2008, eq. (10)) multiply φ_ij by (e^{|u_ij|} − 1)/|u_ij| to make it depend on the
//!   pair's relative speed, a shear-rate dependent (thickening) artificial viscosity: here
//!   with |u_ij| over a velocity scale v0 (`scheme.wcsph.artificial_viscosity_velocity`).
//! * The artificial stress of Monaghan (2000) and Gray, Monaghan & Swift (2001): in the
//!   principal frame of the total stress σ = −pI + τ, each tensile principal stress σ' > 0
//!   adds `R' = −ε σ'/ρ²`; the pair term `f_ijⁿ (R_i + R_j)`, `f_ij = W(r_ij)/W(δr)`, is a
//!   short-range repulsion between particles in tension, against the tensile instability.

use crate::engine::kernel::QuinticSpline;
use crate::engine::math::{Sym2, Vec2};

/// Monaghan's artificial viscosity: the coefficients α_Π (linear, a bulk and shear viscosity
/// ~ α_Π c h) and β_Π (quadratic, against interpenetration); with a velocity scale v0, the
/// shear-rate dependent form of Wróblewski, Boryczko & Kopeć (2008, eq. (10)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArtificialViscosity {
    pub alpha: f64,
    pub beta: f64,
    /// v0 of eq. (10): φ_ij is multiplied by (e^{|u_ij|/v0} − 1)/(|u_ij|/v0) ≥ 1, so the
    /// pair's viscosity grows with its relative speed (the seed writes e^{|v_ij|} − 1 over
    /// |v_ij| in its own units: v0 = 1 there). None: Monaghan's.
    pub velocity_scale: Option<f64>,
}

impl ArtificialViscosity {
    pub fn is_off(&self) -> bool {
        self.alpha == 0.0 && self.beta == 0.0
    }

    /// Π_ij of a pair with relative velocity u_ij, separation r_ij, mean density ρ̄, sound
    /// speed c and smoothing length h (Fang et al. 2006, eqs. (31)–(37)).
    #[inline]
    pub fn pair(&self, u_ij: Vec2, r_ij: Vec2, rho_mean: f64, c: f64, h: f64) -> f64 {
        let approach = u_ij.dot(&r_ij);
        if approach >= 0.0 {
            return 0.0;
        }
        let mut phi = h * approach / (r_ij.norm_squared() + 0.01 * h * h);
        if let Some(v0) = self.velocity_scale {
            // (e^x − 1)/x with x = |u_ij|/v0, 1 at x = 0 (exp_m1 keeps it exact there).
            let x = u_ij.norm() / v0;
            phi *= if x > 0.0 { x.exp_m1() / x } else { 1.0 };
        }
        (-self.alpha * c * phi + self.beta * phi * phi) / rho_mean
    }
}

/// The artificial stress: ε (0 = off) and the exponent n of f_ijⁿ, with W(δr) of the kernel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArtificialStress {
    pub epsilon: f64,
    pub exponent: i32,
}

impl ArtificialStress {
    pub fn is_off(&self) -> bool {
        self.epsilon == 0.0
    }

    /// R_i of a particle of total stress σ and density ρ (Fang et al. 2006, eqs. (40)–(44)):
    /// −ε σ'/ρ² on each tensile principal axis, rotated back.
    pub fn tensor(&self, stress: &Sym2, rho: f64) -> Sym2 {
        let e = stress.eigen();
        let scale = -self.epsilon / (rho * rho);
        let r = |s: f64| if s > 0.0 { scale * s } else { 0.0 };
        Sym2::from_eigen(&e, [r(e.values[0]), r(e.values[1])])
    }

    /// f_ijⁿ = (W(r)/W(δr))ⁿ.
    #[inline]
    pub fn pair_weight(&self, kernel: &QuinticSpline, r: f64, w_spacing: f64) -> f64 {
        (kernel.value(r) / w_spacing).powi(self.exponent)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn artificial_viscosity_acts_on_approaching_pairs_only() {
        let av = ArtificialViscosity {
            alpha: 1.0,
            beta: 2.0,
            velocity_scale: None,
        };
        let r = Vec2::new(1.0, 0.0);
        assert_eq!(av.pair(Vec2::new(1.0, 0.0), r, 1.0, 10.0, 1.0), 0.0);
        // Approaching at speed 1 with h = |r| = 1: φ = −1/1.01, Π = (10 + 2/1.01²)/1.01.
        let phi: f64 = -1.0 / 1.01;
        let expected = -10.0 * phi + 2.0 * phi * phi;
        let got = av.pair(Vec2::new(-1.0, 0.0), r, 1.0, 10.0, 1.0);
        assert!((got - expected).abs() < 1e-14 && got > 0.0);
    }

    /// Eq. (10) of Wróblewski et al. (2008): φ_ij times (e^x − 1)/x, x = |u_ij|/v0, so the
    /// linear term of a pair approaching at v0 is e − 1 times Monaghan's, at 10⁻⁸ v0 it is
    /// Monaghan's, and a receding pair still feels nothing.
    #[test]
    fn velocity_dependent_viscosity_grows_with_the_pair_speed() {
        let monaghan = ArtificialViscosity {
            alpha: 1.0,
            beta: 0.0,
            velocity_scale: None,
        };
        let seed = ArtificialViscosity {
            velocity_scale: Some(2.0),
            ..monaghan
        };
        let r = Vec2::new(1.0, 0.0);
        let at = |av: &ArtificialViscosity, speed: f64| {
            av.pair(Vec2::new(-speed, 0.0), r, 1.0, 10.0, 1.0)
        };
        let ratio = at(&seed, 2.0) / at(&monaghan, 2.0);
        assert!(
            (ratio - (std::f64::consts::E - 1.0)).abs() < 1e-13,
            "{ratio}"
        );
        let slow = at(&seed, 2e-8) / at(&monaghan, 2e-8);
        assert!((slow - 1.0).abs() < 1e-7, "{slow}");
        assert_eq!(seed.pair(Vec2::new(2.0, 0.0), r, 1.0, 10.0, 1.0), 0.0);
    }

    #[test]
    fn artificial_stress_answers_tension_only() {
        let s = ArtificialStress {
            epsilon: 0.5,
            exponent: 4,
        };
        // Pure pressure p > 0 (compression): no artificial stress.
        assert_eq!(s.tensor(&Sym2::new(-2.0, 0.0, -2.0), 1.0), Sym2::ZERO);
        // Uniaxial tension 4 along x, compression along y: R = diag(−0.5·4, 0).
        let r = s.tensor(&Sym2::new(4.0, 0.0, -1.0), 1.0);
        assert!((r.xx + 2.0).abs() < 1e-14 && r.yy.abs() < 1e-14 && r.xy.abs() < 1e-14);
        // The same tension rotated by 45°: R rotates with it.
        let r = s.tensor(&Sym2::new(2.0, 2.0, 2.0), 2.0);
        assert!((r.xx + 0.25).abs() < 1e-14 && (r.xy + 0.25).abs() < 1e-14);
    }
}
