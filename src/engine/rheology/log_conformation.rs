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
/// (33) otherwise.
pub fn relax(model: &Model, a: &Sym2, dt: f64, lambda: f64) -> Sym2 {
    match model.relaxation_coefficients(a) {
        Some((alpha, beta)) => {
            let decay = (-alpha * beta * dt / lambda).exp();
            *a * decay + Sym2::IDENTITY * ((1.0 - decay) / beta)
        }
        None => *a - model.relaxation(a) * (dt / lambda),
    }
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
