//! The constitutive models of King & Lind Table I, one type each, as a strain function f_S and
//! a relaxation function f_R of the conformation tensor A (tr I = d, the dimension: 2 or 3):
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
//!
//! Each model is a file here: its type, its `impl Constitutive` and its [`ModelEntry`] (the
//! name in case files and its parameters). To add one: that file, and here a variant of
//! [`Model`] with its arms in [`Model::constitutive`] and [`Model::entry`], and its entry in
//! [`MODELS`].

pub mod fene_cr;
pub mod fene_p;
pub mod giesekus;
pub mod oldroyd_b;
pub mod ptt;

pub use fene_cr::FeneCr;
pub use fene_p::FeneP;
pub use giesekus::Giesekus;
pub use oldroyd_b::OldroydB;
pub use ptt::{ExponentialPtt, LinearPtt};

use crate::engine::dimension::SymTensor;
use crate::engine::math::Sym2;

/// A model in the strain/relaxation form of Table I, for a conformation tensor `S` of either
/// dimension.
pub trait Constitutive<S: SymTensor> {
    /// f_S(A), eq. (9): τ_p = (η_p/λ) f_S(A).
    fn strain(&self, a: &S) -> S;
    /// f_R(A), eq. (10).
    fn relaxation(&self, a: &S) -> S;
    /// `(α_R, β_R)` with f_R = α_R(β_R A − I), or `None` (then the source step is (33)).
    fn relaxation_coefficients(&self, a: &S) -> Option<(f64, f64)>;
    /// L², the bound tr A < L² of a finitely extensible model (FENE), or `None`.
    fn extensibility(&self) -> Option<f64> {
        None
    }
    /// The conformation of the fluid at rest, f_R(A) = 0 (I for all but FENE-P).
    fn rest_conformation(&self) -> S {
        S::IDENTITY
    }
    /// Inverts f_S (§III B, Step 1): the conformation whose strain function is `strain`
    /// (= λτ_p/η_p), given tr A where f_S depends on it (the paper stores tr A for this).
    fn conformation_from_strain(&self, strain: &S, _trace: f64) -> S {
        *strain + S::IDENTITY
    }
}

fn deviation<S: SymTensor>(a: &S) -> S {
    *a - S::IDENTITY
}

/// tr A − d: the trace's excess over the fluid's at rest (A = I).
fn excess_trace<S: SymTensor>(a: &S) -> f64 {
    a.trace() - S::DIM as f64
}

/// The fluid's constitutive model: a Newtonian fluid or one of the types of Table I.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// No polymer: τ = 2η0 D. No conformation tensor is stored or integrated.
    Newtonian,
    OldroydB,
    /// Upper-convected Maxwell: Oldroyd-B with β = 0.
    Ucm,
    FeneP(FeneP),
    FeneCr(FeneCr),
    LinearPtt(LinearPtt),
    ExponentialPtt(ExponentialPtt),
    Giesekus(Giesekus),
}

/// How a model's viscosity splits between solvent and polymer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solvent {
    /// All solvent, no polymer and no relaxation time (β = 1).
    All,
    /// No solvent (β = 0).
    None,
    /// A viscosity ratio β ∈ [0, 1] given in the case.
    Ratio,
}

/// A scalar parameter of a model, with its check.
#[derive(Clone, Copy, Debug)]
pub struct Parameter {
    /// The key in the case file's `[fluid]` table.
    pub key: &'static str,
    /// What it is and its range, for the key reference.
    pub meaning: &'static str,
    /// The value, or why it is out of range.
    pub check: fn(f64) -> Result<f64, String>,
}

/// A model as named in case files.
#[derive(Clone, Copy, Debug)]
pub struct ModelEntry {
    pub name: &'static str,
    /// What the model is, for the key reference.
    pub meaning: &'static str,
    pub parameters: &'static [Parameter],
    pub solvent: Solvent,
    /// The model from its parameters' values, in the order of `parameters`.
    pub build: fn(&[f64]) -> Model,
}

/// The Newtonian fluid.
const NEWTONIAN: ModelEntry = ModelEntry {
    name: "newtonian",
    meaning: "constant viscosity η0",
    parameters: &[],
    solvent: Solvent::All,
    build: |_| Model::Newtonian,
};

/// Every model, as case files name them.
pub const MODELS: &[ModelEntry] = &[
    NEWTONIAN,
    oldroyd_b::ENTRY,
    oldroyd_b::UCM,
    fene_p::ENTRY,
    fene_cr::ENTRY,
    ptt::LINEAR,
    ptt::EXPONENTIAL,
    giesekus::ENTRY,
];

impl Model {
    /// The model's entry in [`MODELS`].
    pub fn entry(&self) -> &'static ModelEntry {
        match self {
            Model::Newtonian => &NEWTONIAN,
            Model::OldroydB => &oldroyd_b::ENTRY,
            Model::Ucm => &oldroyd_b::UCM,
            Model::FeneP(_) => &fene_p::ENTRY,
            Model::FeneCr(_) => &fene_cr::ENTRY,
            Model::LinearPtt(_) => &ptt::LINEAR,
            Model::ExponentialPtt(_) => &ptt::EXPONENTIAL,
            Model::Giesekus(_) => &giesekus::ENTRY,
        }
    }

    /// The Table I functions of a viscoelastic model.
    #[inline]
    pub fn constitutive<S: SymTensor>(&self) -> Option<&dyn Constitutive<S>> {
        match self {
            Model::Newtonian => None,
            Model::OldroydB | Model::Ucm => Some(&OldroydB),
            Model::FeneP(m) => Some(m),
            Model::FeneCr(m) => Some(m),
            Model::LinearPtt(m) => Some(m),
            Model::ExponentialPtt(m) => Some(m),
            Model::Giesekus(m) => Some(m),
        }
    }

    /// The name in case files.
    pub fn name(&self) -> &'static str {
        self.entry().name
    }

    /// The entry named `name`.
    pub fn named(name: &str) -> Option<&'static ModelEntry> {
        MODELS.iter().find(|m| m.name == name)
    }

    pub fn is_viscoelastic(&self) -> bool {
        !matches!(self, Model::Newtonian)
    }

    /// Strain function f_S(A), eq. (9) (zero for a Newtonian fluid).
    pub fn strain<S: SymTensor>(&self, a: &S) -> S {
        self.constitutive().map_or(S::ZERO, |m| m.strain(a))
    }

    /// Relaxation function f_R(A), eq. (10).
    pub fn relaxation<S: SymTensor>(&self, a: &S) -> S {
        self.constitutive().map_or(S::ZERO, |m| m.relaxation(a))
    }

    /// `(α_R, β_R)` with f_R = α_R(β_R A − I), for the quasi-analytic source step (32).
    pub fn relaxation_coefficients<S: SymTensor>(&self, a: &S) -> Option<(f64, f64)> {
        self.constitutive()
            .and_then(|m| m.relaxation_coefficients(a))
    }

    /// L² of a finitely extensible model (see [`Constitutive::extensibility`]); the same in
    /// either dimension.
    pub fn extensibility(&self) -> Option<f64> {
        self.constitutive::<Sym2>().and_then(|m| m.extensibility())
    }

    /// Conformation of the fluid at rest.
    pub fn rest_conformation<S: SymTensor>(&self) -> S {
        self.constitutive()
            .map_or(S::IDENTITY, |m| m.rest_conformation())
    }

    /// Inverts f_S (see [`Constitutive::conformation_from_strain`]).
    pub fn conformation_from_strain<S: SymTensor>(&self, strain: &S, trace: f64) -> S {
        match self.constitutive() {
            Some(m) => m.conformation_from_strain(strain, trace),
            None => *strain + S::IDENTITY,
        }
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
        let models: [&dyn Constitutive<Sym2>; 5] = [
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
        let models: [&dyn Constitutive<Sym2>; 6] = [
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
