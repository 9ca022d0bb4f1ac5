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
        Some((alpha, beta)) => quasi_analytic(a, alpha, beta, dt / lambda),
        None => *a - model.relaxation(a) * (dt / lambda),
    }
}

/// Eq. (32): `A e^{−α_R β_R δt/λ} + I (1 − e^{−α_R β_R δt/λ})/β_R`, the exact solution of
/// Ȧ = −α_R(β_R A − I)/λ with the coefficients held.
fn quasi_analytic(a: &Sym2, alpha: f64, beta: f64, dt_over_lambda: f64) -> Sym2 {
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
    let relaxed =
        |s: f64| at_trace(s).map(|(alpha, beta)| quasi_analytic(a, alpha, beta, dt_over_lambda));
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

/// The local part of the unsplit rate ([`super::ConformationIntegrator::Unsplit`]): the
/// convective term (30a) without advection plus the source of (29b) in log form,
/// `ΩΨ − ΨΩ + 2B − f_R(A)A⁻¹/λ` (f_R an isotropic function of A for every model of Table I,
/// so f_R(A)A⁻¹ is symmetric and its eigenvalues are f_R(Λ_k)/Λ_k).
pub fn log_local_rate(model: &Model, a: &Sym2, grad_u: &Mat2, lambda: f64) -> Sym2 {
    let e = a.eigen();
    let source = log_source(model, e.values, lambda);
    let source = Sym2::new(source[0], 0.0, source[1]).congruence(&e.rotation());
    log_convective_term(a, grad_u) + source
}

/// The eigenvalues −f_R(Λ_k)/(λΛ_k) of the log-form source, for A with eigenvalues `values`.
fn log_source(model: &Model, [l1, l2]: [f64; 2], lambda: f64) -> [f64; 2] {
    let f = model.relaxation(&Sym2::new(l1, 0.0, l2));
    [-f.xx / (lambda * l1), -f.yy / (lambda * l2)]
}

/// The unsplit log-conformation update: `Ψⁿ⁺¹ = Ψⁿ + δt (I − δt J)⁻¹ R`, R the whole rate
/// (advection, convective term and source: [`log_local_rate`] plus u_ps·∇Ψ) and J the
/// source's Jacobian ∂S/∂Ψ in the eigenbasis of A (a linearly implicit Euler step).
///
/// A fixed point has R = 0 whatever J and δt: its steady states are those of the spatial
/// discretisation. The split updates' are not: the fixed point of e^{δtS}e^{δtC} satisfies
/// S + C = O(δt) (Lie) or O(δt²) (Strang) in units of the stiffer of the two, and at a small
/// Weissenberg number the source is stiff (δt/λ ≈ 1). Measured on the confined cylinder
/// (R/δr = 10, Eulerian, ⟨u⟩ = 1): at Wi = 0.005 Strang gives K = 123.35 where the Newtonian
/// limit is 132.20.
///
/// S is an isotropic function of Ψ, so a perturbation's eigen-components respond one by one
/// (Daleckii & Krein): the divided difference (s_1 − s_2)/(ψ_1 − ψ_2) off the diagonal, and on
/// it the steeper of the tangent ∂s_k/∂ψ_k (a one-sided difference, FENE's coupling of the
/// eigenvalues through tr A left out) and the secant s_k/(ψ_k − ψ_0) to the rest state ψ_0.
/// In Ψ the source is far from linear (Oldroyd-B: s = (e^{−ψ} − 1)/λ, flat for ψ ≫ 0), and
/// the tangent alone overshoots the rest state (A = diag(30, 0.2) at δt/λ = 50 went to
/// ψ = −14.9); the steeper slope of a convex s never does. Both diagonal components take the
/// steeper of their two slopes, and any positive part is dropped. J only weights the step:
/// none of these choices moves a steady state.
pub fn log_unsplit_step(model: &Model, a: &Sym2, rate: &Sym2, dt: f64, lambda: f64) -> Sym2 {
    let e = a.eigen();
    let r = e.rotation();
    let [l1, l2] = e.values;
    let psi = [l1.ln(), l2.ln()];
    let rest = model.rest_conformation().xx.ln();
    let s = log_source(model, e.values, lambda);
    const STEP: f64 = 1e-6;
    let grown = STEP.exp();
    let tangent = [
        (log_source(model, [l1 * grown, l2], lambda)[0] - s[0]) / STEP,
        (log_source(model, [l1, l2 * grown], lambda)[1] - s[1]) / STEP,
    ];
    let slope = |k: usize| {
        let gap = psi[k] - rest;
        let secant = if gap.abs() > STEP {
            s[k] / gap
        } else {
            tangent[k]
        };
        secant.min(tangent[k])
    };
    // One weight for both eigen-components: the convective term is then trace-free after
    // weighting as before it (∇u solenoidal), so tr Ψ = ln det A moves only by the
    // transport and the source, as in the split updates.
    let diagonal = slope(0).min(slope(1));
    let j12 = if (psi[0] - psi[1]).abs() > STEP {
        (s[0] - s[1]) / (psi[0] - psi[1])
    } else {
        0.5 * (tangent[0] + tangent[1])
    };
    let weight = |j: f64| dt / (1.0 - dt * j.min(0.0));
    let m = rate.congruence(&r.transpose());
    let next = Sym2::new(
        psi[0] + m.xx * weight(diagonal),
        m.xy * weight(j12),
        psi[1] + m.yy * weight(diagonal),
    );
    next.exp().congruence(&r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::rheology::{FeneCr, FeneP, Giesekus};

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
            let (alpha, beta) = model.relaxation_coefficients(&r).unwrap();
            let again = quasi_analytic(&a, alpha, beta, 0.01);
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
            let (alpha, beta) = model.relaxation_coefficients(&a).unwrap();
            let held = quasi_analytic(&a, alpha, beta, dt);
            (relax(&model, &a, dt, 1.0) - held).trace().abs()
        };
        let ratio = difference(0.02) / difference(0.01);
        assert!((ratio - 4.0).abs() < 0.1, "ratio {ratio}");
    }

    /// Oldroyd-B in steady simple shear, A = [[1 + 2(λγ̇)², λγ̇], [λγ̇, 1]], is a fixed point of
    /// the unsplit step at any δt/λ, and not of the Lie-split step (29)–(33): it drifts by
    /// O(δt/λ) a step there.
    #[test]
    fn steady_shear_is_a_fixed_point_of_the_unsplit_step_at_any_step() {
        let (lambda, shear) = (0.1, 3.0);
        let wi = lambda * shear;
        let a = Sym2::new(1.0 + 2.0 * wi * wi, wi, 1.0);
        let grad = Mat2::new(0.0, shear, 0.0, 0.0);
        let local = log_local_rate(&Model::OldroydB, &a, &grad, lambda);
        assert!(local.contract(&local).sqrt() < 1e-12, "{local:?}");
        for dt_over_lambda in [0.01, 1.0, 10.0] {
            let dt = dt_over_lambda * lambda;
            let next = log_unsplit_step(&Model::OldroydB, &a, &local, dt, lambda);
            let moved = (next - a).contract(&(next - a)).sqrt();
            assert!(moved < 1e-12, "δt/λ = {dt_over_lambda}: moved {moved}");
            let split = log_conformation_step(
                &Model::OldroydB,
                &a,
                &a.log(),
                &Sym2::ZERO,
                &grad,
                dt,
                lambda,
            );
            let drift = (split - a).contract(&(split - a)).sqrt();
            assert!(drift > 1e-4 * dt_over_lambda.min(1.0), "Lie: {drift}");
        }
    }

    /// At rest the unsplit step relaxes a stretched A towards I without overshoot however
    /// large δt/λ (the implicit source: explicit Euler in Ψ overshoots past δt/λ ≈ 2), for a
    /// model with the quasi-analytic coefficients and for Giesekus, which has none.
    #[test]
    fn the_unsplit_step_relaxes_monotonically_at_a_large_step() {
        let models = [Model::OldroydB, Model::Giesekus(Giesekus { alpha: 0.3 })];
        for model in models {
            let mut a = Sym2::new(30.0, 2.0, 0.2);
            let mut distance = a.log().contract(&a.log()).sqrt();
            for _ in 0..40 {
                let rate = log_local_rate(&model, &a, &Mat2::zeros(), 1.0);
                a = log_unsplit_step(&model, &a, &rate, 50.0, 1.0);
                let now = a.log().contract(&a.log()).sqrt();
                assert!(
                    now < distance || now < 1e-12,
                    "{model:?}: {now} after {distance}"
                );
                distance = now;
            }
            assert!(distance < 1e-3, "{model:?}: {distance}");
        }
    }

    /// For a small step the unsplit and the Lie-split updates agree to O(δt²) a step, and the
    /// difference falls 4× when δt halves (both first-order consistent with (30a)).
    #[test]
    fn the_unsplit_step_is_consistent_with_the_split_one() {
        let a = Sym2::new(2.5, 0.7, 0.8);
        let grad = Mat2::new(0.3, 1.1, -0.4, -0.3);
        let model = Model::FeneP(FeneP { l2: 100.0 });
        let difference = |dt: f64| {
            let rate = log_local_rate(&model, &a, &grad, 1.0);
            let unsplit = log_unsplit_step(&model, &a, &rate, dt, 1.0);
            let split = log_conformation_step(&model, &a, &a.log(), &Sym2::ZERO, &grad, dt, 1.0);
            let d = unsplit - split;
            d.contract(&d).sqrt()
        };
        let ratio = difference(0.002) / difference(0.001);
        assert!((ratio - 4.0).abs() < 0.2, "ratio {ratio}");
    }
}
