//! Phan-Thien–Tanner, linear and exponential (King & Lind Table I): f_S = A − I,
//! f_R = Y(tr A)(A − I).

use super::{deviation, Constitutive, Model, ModelEntry, Parameter};
use crate::engine::math::Sym2;

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

/// ε ≥ 0.
pub const EPSILON: Parameter = Parameter {
    key: "epsilon",
    meaning: "ε ≥ 0, the extensibility parameter of the Phan-Thien–Tanner models",
    check: |e| {
        if e.is_finite() && e >= 0.0 {
            Ok(e)
        } else {
            Err(format!("must be ≥ 0, got {e}"))
        }
    },
};

pub const LINEAR: ModelEntry = ModelEntry {
    name: "lptt",
    meaning: "linear Phan-Thien–Tanner, Table I",
    parameters: &[EPSILON],
    solvent: super::Solvent::Ratio,
    build: |p| Model::LinearPtt(LinearPtt { epsilon: p[0] }),
};

pub const EXPONENTIAL: ModelEntry = ModelEntry {
    name: "eptt",
    meaning: "exponential Phan-Thien–Tanner, Table I",
    parameters: &[EPSILON],
    solvent: super::Solvent::Ratio,
    build: |p| Model::ExponentialPtt(ExponentialPtt { epsilon: p[0] }),
};
