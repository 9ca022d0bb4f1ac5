//! The constitutive models of King & Lind Table I, one type each, as a strain function f_S and
//! a relaxation function f_R of the conformation tensor A (2D: tr I = 2):
//!
//! | model | f_S | f_R |
//! | --- | --- | --- |
//! | Oldroyd-B, UCM | A − I | A − I |
//! | FENE-P | A/(1 − tr A/L²) − I | A/(1 − tr A/L²) − I |
//! | FENE-CR | (A − I)/(1 − tr A/L²) | (A − I)/(1 − tr A/L²) |
//! | linear PTT | A − I | [1 + ε tr(A − I)](A − I) |
//! | exponential PTT | A − I | exp[ε tr(A − I)](A − I) |
//! | Giesekus | A − I | αA² + (1 − 2α)A − (1 − α)I |
//!
//! All but Giesekus have f_R = α_R(β_R A − I) with α_R, β_R functions of tr A, which the
//! quasi-analytic source step (32) uses.

use crate::engine::math::Sym2;

/// A model in the strain/relaxation form of Table I.
pub trait Constitutive {
    /// f_S(A), eq. (9): τ_p = (η_p/λ) f_S(A).
    fn strain(&self, a: &Sym2) -> Sym2;
    /// f_R(A), eq. (10).
    fn relaxation(&self, a: &Sym2) -> Sym2;
    /// `(α_R, β_R)` with f_R = α_R(β_R A − I), or `None` (then the source step is (33)).
    fn relaxation_coefficients(&self, a: &Sym2) -> Option<(f64, f64)>;
    /// The conformation of the fluid at rest, f_R(A) = 0 (I for all but FENE-P).
    fn rest_conformation(&self) -> Sym2 {
        Sym2::IDENTITY
    }
}

fn deviation(a: &Sym2) -> Sym2 {
    *a - Sym2::IDENTITY
}

/// Oldroyd-B.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OldroydB;

impl Constitutive for OldroydB {
    fn strain(&self, a: &Sym2) -> Sym2 {
        deviation(a)
    }
    fn relaxation(&self, a: &Sym2) -> Sym2 {
        deviation(a)
    }
    fn relaxation_coefficients(&self, _a: &Sym2) -> Option<(f64, f64)> {
        Some((1.0, 1.0))
    }
}

/// FENE-P with extensibility L² (> 2, the trace at rest in 2D). The Peterlin factor
/// 1/(1 − tr A/L²) multiplies A in both functions; the rest state is A = L²/(L² + 2) I.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeneP {
    pub l2: f64,
}

impl FeneP {
    /// 1/(1 − tr A/L²); infinite when tr A reaches L² (the chains' full extension).
    fn peterlin(&self, a: &Sym2) -> f64 {
        1.0 / (1.0 - a.trace() / self.l2)
    }
}

impl Constitutive for FeneP {
    fn strain(&self, a: &Sym2) -> Sym2 {
        *a * self.peterlin(a) - Sym2::IDENTITY
    }
    fn relaxation(&self, a: &Sym2) -> Sym2 {
        self.strain(a)
    }
    fn relaxation_coefficients(&self, a: &Sym2) -> Option<(f64, f64)> {
        Some((1.0, self.peterlin(a)))
    }
    fn rest_conformation(&self) -> Sym2 {
        Sym2::IDENTITY * (self.l2 / (self.l2 + 2.0))
    }
}

/// FENE-CR with extensibility L²: constant shear viscosity, extension-limited normal stress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeneCr {
    pub l2: f64,
}

impl FeneCr {
    fn peterlin(&self, a: &Sym2) -> f64 {
        1.0 / (1.0 - a.trace() / self.l2)
    }
}

impl Constitutive for FeneCr {
    fn strain(&self, a: &Sym2) -> Sym2 {
        deviation(a) * self.peterlin(a)
    }
    fn relaxation(&self, a: &Sym2) -> Sym2 {
        self.strain(a)
    }
    fn relaxation_coefficients(&self, a: &Sym2) -> Option<(f64, f64)> {
        Some((self.peterlin(a), 1.0))
    }
}

/// Linear Phan-Thien–Tanner with extensibility parameter ε.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearPtt {
    pub epsilon: f64,
}

impl LinearPtt {
    fn factor(&self, a: &Sym2) -> f64 {
        1.0 + self.epsilon * (a.trace() - 2.0)
    }
}

impl Constitutive for LinearPtt {
    fn strain(&self, a: &Sym2) -> Sym2 {
        deviation(a)
    }
    fn relaxation(&self, a: &Sym2) -> Sym2 {
        deviation(a) * self.factor(a)
    }
    fn relaxation_coefficients(&self, a: &Sym2) -> Option<(f64, f64)> {
        Some((self.factor(a), 1.0))
    }
}

/// Exponential Phan-Thien–Tanner with extensibility parameter ε.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExponentialPtt {
    pub epsilon: f64,
}

impl ExponentialPtt {
    fn factor(&self, a: &Sym2) -> f64 {
        (self.epsilon * (a.trace() - 2.0)).exp()
    }
}

impl Constitutive for ExponentialPtt {
    fn strain(&self, a: &Sym2) -> Sym2 {
        deviation(a)
    }
    fn relaxation(&self, a: &Sym2) -> Sym2 {
        deviation(a) * self.factor(a)
    }
    fn relaxation_coefficients(&self, a: &Sym2) -> Option<(f64, f64)> {
        Some((self.factor(a), 1.0))
    }
}

/// Giesekus with mobility α ∈ [0, ½]. f_R is quadratic in A, so the source step is explicit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Giesekus {
    pub alpha: f64,
}

impl Constitutive for Giesekus {
    fn strain(&self, a: &Sym2) -> Sym2 {
        deviation(a)
    }
    fn relaxation(&self, a: &Sym2) -> Sym2 {
        let m = a.to_mat();
        let a2 = Sym2::sym_part(&(m * m));
        a2 * self.alpha + *a * (1.0 - 2.0 * self.alpha) - Sym2::IDENTITY * (1.0 - self.alpha)
    }
    fn relaxation_coefficients(&self, _a: &Sym2) -> Option<(f64, f64)> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Sym2, b: Sym2) -> bool {
        let d = a - b;
        d.contract(&d).sqrt() < 1e-12 * (1.0 + b.contract(&b).sqrt())
    }

    /// Hand-computed values of each model at A = [[3, 1], [1, 2]] (tr A = 5, tr(A − I) = 3,
    /// A² = [[10, 5], [5, 5]]).
    #[test]
    fn strain_and_relaxation_functions_match_hand_values() {
        let a = Sym2::new(3.0, 1.0, 2.0);
        // FENE-P, L² = 10: 1/(1 − 5/10) = 2.
        let p = FeneP { l2: 10.0 };
        assert!(close(p.strain(&a), Sym2::new(5.0, 2.0, 3.0)));
        assert!(close(p.relaxation(&a), Sym2::new(5.0, 2.0, 3.0)));
        // FENE-CR, L² = 10: 2(A − I).
        let c = FeneCr { l2: 10.0 };
        assert!(close(c.strain(&a), Sym2::new(4.0, 2.0, 2.0)));
        // L-PTT, ε = 0.5: (1 + 1.5)(A − I).
        let l = LinearPtt { epsilon: 0.5 };
        assert!(close(l.strain(&a), Sym2::new(2.0, 1.0, 1.0)));
        assert!(close(l.relaxation(&a), Sym2::new(5.0, 2.5, 2.5)));
        // E-PTT, ε = 0.5: e^{1.5}(A − I).
        let e = ExponentialPtt { epsilon: 0.5 };
        let k = 1.5f64.exp();
        assert!(close(e.relaxation(&a), Sym2::new(2.0 * k, k, k)));
        // Giesekus, α = 0.25: 0.25A² + 0.5A − 0.75I.
        let g = Giesekus { alpha: 0.25 };
        assert!(close(
            g.relaxation(&a),
            Sym2::new(2.5 + 1.5 - 0.75, 1.25 + 0.5, 1.25 + 1.0 - 0.75)
        ));
        assert!(g.relaxation_coefficients(&a).is_none());
        assert!(close(OldroydB.relaxation(&a), Sym2::new(2.0, 1.0, 1.0)));
    }

    /// f_R = α_R(β_R A − I) reproduces f_R wherever the coefficients are offered.
    #[test]
    fn relaxation_coefficients_reproduce_the_relaxation_function() {
        let a = Sym2::new(4.0, -1.3, 1.5);
        let models: [&dyn Constitutive; 5] = [
            &OldroydB,
            &FeneP { l2: 50.0 },
            &FeneCr { l2: 50.0 },
            &LinearPtt { epsilon: 0.25 },
            &ExponentialPtt { epsilon: 0.25 },
        ];
        for m in models {
            let (alpha, beta) = m.relaxation_coefficients(&a).unwrap();
            let from_coefficients = (a * beta - Sym2::IDENTITY) * alpha;
            assert!(close(from_coefficients, m.relaxation(&a)));
        }
    }

    /// Each model is at rest (f_R = 0, no stress) in its rest conformation.
    #[test]
    fn rest_conformation_is_stress_free() {
        let models: [&dyn Constitutive; 6] = [
            &OldroydB,
            &FeneP { l2: 10.0 },
            &FeneCr { l2: 10.0 },
            &LinearPtt { epsilon: 0.25 },
            &ExponentialPtt { epsilon: 0.25 },
            &Giesekus { alpha: 0.3 },
        ];
        for m in models {
            let rest = m.rest_conformation();
            assert!(close(m.relaxation(&rest), Sym2::ZERO));
            assert!(close(m.strain(&rest), Sym2::ZERO));
        }
    }
}
