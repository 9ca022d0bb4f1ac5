//! Phan-Thien–Tanner, linear and exponential (King & Lind Table I): f_S = A − I,
//! f_R = Y(tr A)(A − I).

use super::{deviation, excess_trace, Constitutive, Model, ModelEntry, Parameter};
use crate::engine::dimension::SymTensor;

/// Linear Phan-Thien–Tanner with extensibility parameter ε.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearPtt {
    pub epsilon: f64,
}

impl LinearPtt {
    fn factor<S: SymTensor>(&self, a: &S) -> f64 {
        1.0 + self.epsilon * excess_trace(a)
    }
}

impl<S: SymTensor> Constitutive<S> for LinearPtt {
    fn strain(&self, a: &S) -> S {
        deviation(a)
    }
    fn relaxation(&self, a: &S) -> S {
        deviation(a) * self.factor(a)
    }
    fn relaxation_coefficients(&self, a: &S) -> Option<(f64, f64)> {
        Some((self.factor(a), 1.0))
    }
}

/// Exponential Phan-Thien–Tanner with extensibility parameter ε.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExponentialPtt {
    pub epsilon: f64,
}

impl ExponentialPtt {
    fn factor<S: SymTensor>(&self, a: &S) -> f64 {
        (self.epsilon * excess_trace(a)).exp()
    }
}

impl<S: SymTensor> Constitutive<S> for ExponentialPtt {
    fn strain(&self, a: &S) -> S {
        deviation(a)
    }
    fn relaxation(&self, a: &S) -> S {
        deviation(a) * self.factor(a)
    }
    fn relaxation_coefficients(&self, a: &S) -> Option<(f64, f64)> {
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
