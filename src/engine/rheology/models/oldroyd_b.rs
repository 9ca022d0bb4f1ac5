//! Oldroyd-B (and UCM, its β = 0 limit): f_S = f_R = A − I (King & Lind Table I).

use super::{deviation, Constitutive, Model, ModelEntry};
use crate::engine::dimension::SymTensor;

/// Oldroyd-B.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OldroydB;

impl<S: SymTensor> Constitutive<S> for OldroydB {
    fn strain(&self, a: &S) -> S {
        deviation(a)
    }
    fn relaxation(&self, a: &S) -> S {
        deviation(a)
    }
    fn relaxation_coefficients(&self, _a: &S) -> Option<(f64, f64)> {
        Some((1.0, 1.0))
    }
}

/// `oldroyd-b`: needs β ∈ [0, 1].
pub const ENTRY: ModelEntry = ModelEntry {
    name: "oldroyd-b",
    meaning: "Oldroyd-B, Table I: a Hookean dumbbell in a Newtonian solvent (`fluid.beta` η_s/η0)",
    parameters: &[],
    solvent: super::Solvent::Ratio,
    build: |_| Model::OldroydB,
};

/// `ucm`: Oldroyd-B without solvent (β = 0).
pub const UCM: ModelEntry = ModelEntry {
    name: "ucm",
    meaning: "the upper-convected Maxwell model: Oldroyd-B without solvent (β = 0)",
    parameters: &[],
    solvent: super::Solvent::None,
    build: |_| Model::Ucm,
};
