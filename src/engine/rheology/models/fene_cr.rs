//! FENE-CR (King & Lind Table I): the Peterlin factor on A − I.

use super::{deviation, Constitutive, Model, ModelEntry};
use crate::engine::dimension::SymTensor;

/// FENE-CR with extensibility L²: constant shear viscosity, extension-limited normal stress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeneCr {
    pub l2: f64,
}

impl FeneCr {
    fn peterlin<S: SymTensor>(&self, a: &S) -> f64 {
        1.0 / (1.0 - a.trace() / self.l2)
    }
}

impl<S: SymTensor> Constitutive<S> for FeneCr {
    fn strain(&self, a: &S) -> S {
        deviation(a) * self.peterlin(a)
    }
    fn relaxation(&self, a: &S) -> S {
        self.strain(a)
    }
    fn extensibility(&self) -> Option<f64> {
        Some(self.l2)
    }
    fn relaxation_coefficients(&self, a: &S) -> Option<(f64, f64)> {
        Some((self.peterlin(a), 1.0))
    }
    fn conformation_from_strain(&self, strain: &S, trace: f64) -> S {
        *strain * (1.0 - trace / self.l2) + S::IDENTITY
    }
}

pub const ENTRY: ModelEntry = ModelEntry {
    name: "fene-cr",
    meaning:
        "FENE-CR, Table I (Chilcott & Rallison): finite extension with a constant shear viscosity",
    parameters: &[super::fene_p::EXTENSIBILITY],
    solvent: super::Solvent::Ratio,
    build: |p| Model::FeneCr(FeneCr { l2: p[0] }),
};
