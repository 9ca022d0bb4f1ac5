//! FENE-P (King & Lind Table I): the Peterlin factor 1/(1 − tr A/L²) on A in f_S and f_R.

use super::{Constitutive, Model, ModelEntry, Parameter};
use crate::engine::dimension::SymTensor;

/// FENE-P with extensibility L² (> d, the trace at rest in d dimensions). The Peterlin
/// factor 1/(1 − tr A/L²) multiplies A in both functions; the rest state is
/// A = L²/(L² + d) I.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeneP {
    pub l2: f64,
}

impl FeneP {
    /// 1/(1 − tr A/L²); infinite when tr A reaches L² (the chains' full extension).
    fn peterlin<S: SymTensor>(&self, a: &S) -> f64 {
        1.0 / (1.0 - a.trace() / self.l2)
    }
}

impl<S: SymTensor> Constitutive<S> for FeneP {
    fn strain(&self, a: &S) -> S {
        *a * self.peterlin(a) - S::IDENTITY
    }
    fn relaxation(&self, a: &S) -> S {
        self.strain(a)
    }
    fn extensibility(&self) -> Option<f64> {
        Some(self.l2)
    }
    fn relaxation_coefficients(&self, a: &S) -> Option<(f64, f64)> {
        Some((1.0, self.peterlin(a)))
    }
    fn rest_conformation(&self) -> S {
        S::IDENTITY * (self.l2 / (self.l2 + S::DIM as f64))
    }
    fn conformation_from_strain(&self, strain: &S, trace: f64) -> S {
        (*strain + S::IDENTITY) * (1.0 - trace / self.l2)
    }
}

/// L² > 2, the trace at rest in 2D.
pub const EXTENSIBILITY: Parameter = Parameter {
    key: "l2",
    meaning: "L², the dumbbells' squared maximum extension (> 2; tr A < L²)",
    check: |l2| {
        if l2.is_finite() && l2 > 2.0 {
            Ok(l2)
        } else {
            Err(format!(
                "must exceed 2 (tr A of the fluid at rest in 2D), got {l2}"
            ))
        }
    },
};

pub const ENTRY: ModelEntry = ModelEntry {
    name: "fene-p",
    meaning: "FENE-P, Table I: finitely extensible dumbbells, Peterlin's closure (tr A < L²)",
    parameters: &[EXTENSIBILITY],
    solvent: super::Solvent::Ratio,
    build: |p| Model::FeneP(FeneP { l2: p[0] }),
};
