//! The log-conformation integration of King & Lind §III B (Fattal & Kupferman 2004): the
//! decomposition (14)–(19) of the velocity gradient about the eigenvectors of A, the update
//! of Ψ = ln A (29a)–(31) and the source step (29b), quasi-analytic (32) or explicit (33).

use super::Model;
use crate::engine::math::{Mat2, Sym2};

/// The convective part of the log-conformation equation (30a) without advection,
/// `ΩΨ − ΨΩ + 2B`, from the decomposition (14)–(19) of the velocity gradient
/// `grad_u[(a, b)] = ∂u_a/∂x_b` about the eigenvectors of A.
///
/// Evaluated in the eigenbasis, where with m = Rᵀ∇uR and ψ_k = ln Λ_k it reads
/// `diag(2m11, 2m22)` plus the off-diagonal `ω(ψ2 − ψ1)`, ω from eq. (19). We compute the
/// product `ω(ψ2 − ψ1) = (Λ2 m12 + Λ1 m21)·(ln Λ2 − ln Λ1)/(Λ2 − Λ1)` directly: it stays
/// finite as Λ1 → Λ2, where ω alone diverges, and tends to m12 + m21 there (the limit in
/// which B = D and Ω = 0, Fattal & Kupferman 2004).
pub fn log_convective_term(a: &Sym2, grad_u: &Mat2) -> Sym2 {
    let e = a.eigen();
    let r = e.rotation();
    let m = r.transpose() * grad_u * r;
    let [l1, l2] = e.values;
    let off = (l2 * m[(0, 1)] + l1 * m[(1, 0)]) * log_difference_quotient(l1, l2);
    let in_eigenbasis = Sym2::new(2.0 * m[(0, 0)], off, 2.0 * m[(1, 1)]);
    in_eigenbasis.congruence(&r)
}

/// `(ln a − ln b)/(a − b)`, stable as a → b (where it tends to 1/b).
fn log_difference_quotient(a: f64, b: f64) -> f64 {
    let d = (a - b) / b;
    if d.abs() < 1e-6 {
        (1.0 - 0.5 * d + d * d / 3.0) / b
    } else {
        d.ln_1p() / (a - b)
    }
}

/// Source step (29b) over δt: quasi-analytic (32) where f_R = α_R(β_R A − I), explicit Euler
/// (33) otherwise; for the FENE models (32) with the Peterlin factor at the end of the step
/// ([`relax_extensible`]).
pub fn relax(model: &Model, a: &Sym2, dt: f64, lambda: f64) -> Sym2 {
    if let Some(l2) = model.extensibility() {
        return relax_extensible(model, a, dt / lambda, l2);
    }
    match model.relaxation_coefficients(a) {
        Some(coefficients) => quasi_analytic(a, coefficients, dt / lambda),
        None => *a - model.relaxation(a) * (dt / lambda),
    }
}

/// Eq. (32): `A e^{−α_R β_R δt/λ} + I (1 − e^{−α_R β_R δt/λ})/β_R`, the exact solution of
/// Ȧ = −α_R(β_R A − I)/λ with the coefficients held.
fn quasi_analytic(a: &Sym2, (alpha, beta): (f64, f64), dt_over_lambda: f64) -> Sym2 {
    let decay = (-alpha * beta * dt_over_lambda).exp();
    *a * decay + Sym2::IDENTITY * ((1.0 - decay) / beta)
}

/// Eq. (32) for a FENE model with the Peterlin factor f = 1/(1 − tr A/L²) taken at the end of
/// the step: the coefficients at the trace s the step ends with, s = tr A_new(s), found by
/// bisection on [0, L²) (at s → L² f → ∞ and the relaxed trace falls to 2 (FENE-CR) or 0
/// (FENE-P), below s; at s = 0 it is above).
///
/// The paper holds f at the convected A*, which the convective step can take past L² where
/// the chains would have to be longer than fully extended; f is then negative and (32) grows
/// A instead of relaxing it (the FENE-CR jet, L² = 10, reached tr A = 818). Taken at the end
/// of the step (the backward-Euler choice for a stiff factor), the relaxed tr A < L² for any
/// A*, and for tr A* well below L² the two differ by O(δt²) a step.
fn relax_extensible(model: &Model, a: &Sym2, dt_over_lambda: f64, l2: f64) -> Sym2 {
    let at_trace = |s: f64| model.relaxation_coefficients(&(Sym2::IDENTITY * (0.5 * s)));
    let relaxed = |s: f64| at_trace(s).map(|c| quasi_analytic(a, c, dt_over_lambda));
    let (mut low, mut high) = (0.0, l2);
    // 60 halvings: the bracket shrinks to L²·2⁻⁶⁰, below round-off.
    for _ in 0..60 {
        let s = 0.5 * (low + high);
        match relaxed(s) {
            Some(r) if r.trace() > s => low = s,
            _ => high = s,
        }
    }
    relaxed(low).unwrap_or(*a)
}

/// One log-conformation update of a particle, §III B Steps 2–7:
/// `Ψ* = Ψ + δt[u_ps·∇Ψ + ΩΨ − ΨΩ + 2B]` (eq. (31); the paper's "−2B" there is a sign typo,
/// cf. (30a)), `A* = exp Ψ*`, then the source step (32)/(33).
pub fn log_conformation_step(
    model: &Model,
    a: &Sym2,
    psi: &Sym2,
    advection_psi: &Sym2,
    grad_u: &Mat2,
    dt: f64,
    lambda: f64,
) -> Sym2 {
    let psi_star = *psi + (*advection_psi + log_convective_term(a, grad_u)) * dt;
    relax(model, &psi_star.exp(), dt, lambda)
}

/// The second-order log-conformation update ([`super::ConformationIntegrator::Strang`]):
/// Strang splitting R(δt/2) C(δt) R(δt/2) of the source step R (29b) and the convective step
/// C (30a), C by the explicit midpoint rule with ∇u and the advection term held,
/// `Ψ* = Ψ' + δt F(Ψ' + ½δt F(Ψ'))`, `F(Ψ) = u_ps·∇Ψ + ΩΨ − ΨΩ + 2B`. R is exact for the
/// models whose relaxation is α_R(β_R A − I) with constant coefficients (Oldroyd-B, UCM,
/// FENE-CR's frozen f), so the step is second order in δt where (29)–(33)'s Lie splitting
/// with an Euler C is first order; it costs two eigen-decompositions instead of one.
pub fn log_conformation_step_strang(
    model: &Model,
    a: &Sym2,
    advection_psi: &Sym2,
    grad_u: &Mat2,
    dt: f64,
    lambda: f64,
) -> Sym2 {
    let relaxed = relax(model, a, 0.5 * dt, lambda);
    let psi = relaxed.log();
    let rate = *advection_psi + log_convective_term(&relaxed, grad_u);
    let midpoint = (psi + rate * (0.5 * dt)).exp();
    let rate = *advection_psi + log_convective_term(&midpoint, grad_u);
    relax(model, &(psi + rate * dt).exp(), 0.5 * dt, lambda)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::rheology::{FeneCr, FeneP};

    /// A convected A* beyond L² relaxes to tr A < L² (the frozen factor would be negative and
    /// grow it), and it is the fixed point s = tr A_new(f(s)) the docs describe.
    #[test]
    fn a_fene_step_from_beyond_the_extensibility_ends_below_it() {
        let a = Sym2::new(11.0, 2.0, 1.5);
        for model in [
            Model::FeneCr(FeneCr { l2: 10.0 }),
            Model::FeneP(FeneP { l2: 10.0 }),
        ] {
            let r = relax(&model, &a, 0.01, 1.0);
            assert!(r.trace() < 10.0 && r.det() > 0.0, "{model:?}: {r:?}");
            let f = model.relaxation_coefficients(&r).unwrap();
            let again = quasi_analytic(&a, f, 0.01);
            assert!((again.trace() - r.trace()).abs() < 1e-9 * r.trace());
        }
    }

    /// Far below L² the end-of-step factor differs from the paper's (held at A*) by O(δt²):
    /// the difference falls 4× when δt halves.
    #[test]
    fn far_below_the_extensibility_the_end_of_step_factor_is_the_held_one_to_second_order() {
        let a = Sym2::new(6.0, 1.0, 1.2);
        let model = Model::FeneCr(FeneCr { l2: 100.0 });
        let difference = |dt: f64| {
            let held = quasi_analytic(&a, model.relaxation_coefficients(&a).unwrap(), dt);
            (relax(&model, &a, dt, 1.0) - held).trace().abs()
        };
        let ratio = difference(0.02) / difference(0.01);
        assert!((ratio - 4.0).abs() < 0.1, "ratio {ratio}");
    }
}
