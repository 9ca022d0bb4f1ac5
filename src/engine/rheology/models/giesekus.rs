//! Giesekus (King & Lind Table I): f_R = αA² + (1 − 2α)A − (1 − α)I.

use super::{deviation, Constitutive, Model, ModelEntry, Parameter};
use crate::engine::dimension::SymTensor;

/// Giesekus with mobility α ∈ [0, ½]. f_R is quadratic in A, so the source step is explicit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Giesekus {
    pub alpha: f64,
}

impl<S: SymTensor> Constitutive<S> for Giesekus {
    fn strain(&self, a: &S) -> S {
        deviation(a)
    }
    fn relaxation(&self, a: &S) -> S {
        let m = a.to_mat();
        let a2 = S::sym_part(&(m * m));
        a2 * self.alpha + *a * (1.0 - 2.0 * self.alpha) - S::IDENTITY * (1.0 - self.alpha)
    }
    fn relaxation_coefficients(&self, _a: &S) -> Option<(f64, f64)> {
        None
    }
}

/// Mobility α ∈ [0, ½].
pub const MOBILITY: Parameter = Parameter {
    key: "alpha",
    meaning: "α ∈ [0, ½], the Giesekus mobility factor",
    check: |a| {
        if a.is_finite() && (0.0..=0.5).contains(&a) {
            Ok(a)
        } else {
            Err(format!("must be in [0, 0.5], got {a}"))
        }
    },
};

pub const ENTRY: ModelEntry = ModelEntry {
    name: "giesekus",
    meaning: "Giesekus, Table I: an anisotropic drag on the dumbbells",
    parameters: &[MOBILITY],
    solvent: super::Solvent::Ratio,
    build: |p| Model::Giesekus(Giesekus { alpha: p[0] }),
};
