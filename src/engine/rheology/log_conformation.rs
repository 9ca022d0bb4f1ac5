//! The log-conformation integration of King & Lind §III B (Fattal & Kupferman 2004): the
//! decomposition (14)–(19) of the velocity gradient about the eigenvectors of A, the update
//! of Ψ = ln A (29a)–(31) and the source step (29b), quasi-analytic (32) or explicit (33).
//!
//! Written once for a conformation tensor of either dimension ([`SymTensor`]): in 3D each
//! pair of eigenvectors contributes its own rotation rate, eq. (19) for that pair.

use super::Model;
use crate::engine::dimension::SymTensor;

/// The convective part of the log-conformation equation (30a) without advection,
/// `ΩΨ − ΨΩ + 2B`, from the decomposition (14)–(19) of the velocity gradient
/// `grad_u[(a, b)] = ∂u_a/∂x_b` about the eigenvectors of A.
///
/// Evaluated in the eigenbasis, where with m = Rᵀ∇uR and ψ_k = ln Λ_k it reads
/// `diag(2m_kk)` plus, for each pair k < l, the off-diagonal `ω_kl(ψ_l − ψ_k)`, ω_kl from
/// eq. (19). We compute the product
/// `ω_kl(ψ_l − ψ_k) = (Λ_l m_kl + Λ_k m_lk)·(ln Λ_l − ln Λ_k)/(Λ_l − Λ_k)` directly: it stays
/// finite as Λ_k → Λ_l, where ω alone diverges, and tends to m_kl + m_lk there (the limit in
/// which B = D and Ω = 0, Fattal & Kupferman 2004).
pub fn log_convective_term<S: SymTensor>(a: &S, grad_u: &S::Matrix) -> S {
    let (l, r) = a.eigen_decomposition();
    let m = S::transpose(&r) * *grad_u * r;
    let in_eigenbasis = S::from_entries(|k, j| {
        if k == j {
            2.0 * m[(k, k)]
        } else {
            (l[j] * m[(k, j)] + l[k] * m[(j, k)]) * log_difference_quotient(l[k], l[j])
        }
    });
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
pub fn relax<S: SymTensor>(model: &Model, a: &S, dt: f64, lambda: f64) -> S {
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
fn quasi_analytic<S: SymTensor>(a: &S, alpha: f64, beta: f64, dt_over_lambda: f64) -> S {
    let decay = (-alpha * beta * dt_over_lambda).exp();
    *a * decay + S::IDENTITY * ((1.0 - decay) / beta)
}

/// Eq. (32) for a FENE model with the Peterlin factor f = 1/(1 − tr A/L²) taken at the end of
/// the step: the coefficients at the trace s the step ends with, s = tr A_new(s), found by
/// bisection on [0, L²) (at s → L² f → ∞ and the relaxed trace falls to d (FENE-CR) or 0
/// (FENE-P), below s; at s = 0 it is above).
///
/// The paper holds f at the convected A*, which the convective step can take past L² where
/// the chains would have to be longer than fully extended; f is then negative and (32) grows
/// A instead of relaxing it (the FENE-CR jet, L² = 10, reached tr A = 818). Taken at the end
/// of the step (the backward-Euler choice for a stiff factor), the relaxed tr A < L² for any
/// A*, and for tr A* well below L² the two differ by O(δt²) a step.
fn relax_extensible<S: SymTensor>(model: &Model, a: &S, dt_over_lambda: f64, l2: f64) -> S {
    // The coefficients depend on A only through its trace: an isotropic A of trace s.
    let at_trace = |s: f64| model.relaxation_coefficients(&(S::IDENTITY * (s / S::DIM as f64)));
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
pub fn log_conformation_step<S: SymTensor>(
    model: &Model,
    a: &S,
    psi: &S,
    advection_psi: &S,
    grad_u: &S::Matrix,
    dt: f64,
    lambda: f64,
) -> S {
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
pub fn log_conformation_step_strang<S: SymTensor>(
    model: &Model,
    a: &S,
    advection_psi: &S,
    grad_u: &S::Matrix,
    dt: f64,
    lambda: f64,
) -> S {
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
pub fn log_local_rate<S: SymTensor>(model: &Model, a: &S, grad_u: &S::Matrix, lambda: f64) -> S {
    let (values, r) = a.eigen_decomposition();
    let source = log_source::<S>(model, &values, lambda);
    let source = S::diagonal(&source).congruence(&r);
    log_convective_term(a, grad_u) + source
}

/// The eigenvalues −f_R(Λ_k)/(λΛ_k) of the log-form source, for A with eigenvalues `values`.
fn log_source<S: SymTensor>(model: &Model, values: &S::Values, lambda: f64) -> S::Values {
    let f = model.relaxation(&S::diagonal(values));
    S::values_from(|k| -f.entry(k, k) / (lambda * values[k]))
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
/// (Daleckii & Krein): the divided difference (s_k − s_l)/(ψ_k − ψ_l) off the diagonal, and on
/// it the steeper of the tangent ∂s_k/∂ψ_k (a one-sided difference, FENE's coupling of the
/// eigenvalues through tr A left out) and the secant s_k/(ψ_k − ψ_0) to the rest state ψ_0.
/// In Ψ the source is far from linear (Oldroyd-B: s = (e^{−ψ} − 1)/λ, flat for ψ ≫ 0), and
/// the tangent alone overshoots the rest state (A = diag(30, 0.2) at δt/λ = 50 went to
/// ψ = −14.9); the steeper slope of a convex s never does. Every diagonal component takes the
/// steepest of their slopes, and any positive part is dropped. J only weights the step:
/// none of these choices moves a steady state.
pub fn log_unsplit_step<S: SymTensor>(model: &Model, a: &S, rate: &S, dt: f64, lambda: f64) -> S {
    let (l, r) = a.eigen_decomposition();
    let psi = S::values_from(|k| l[k].ln());
    let rest = model.rest_conformation::<S>().entry(0, 0).ln();
    let s = log_source::<S>(model, &l, lambda);
    const STEP: f64 = 1e-6;
    let grown = STEP.exp();
    let tangent = S::values_from(|k| {
        let mut stretched = l;
        stretched[k] *= grown;
        (log_source::<S>(model, &stretched, lambda)[k] - s[k]) / STEP
    });
    let slope = |k: usize| {
        let gap = psi[k] - rest;
        let secant = if gap.abs() > STEP {
            s[k] / gap
        } else {
            tangent[k]
        };
        secant.min(tangent[k])
    };
    // One weight for every eigen-component: the convective term is then trace-free after
    // weighting as before it (∇u solenoidal), so tr Ψ = ln det A moves only by the
    // transport and the source, as in the split updates.
    let diagonal = (1..S::DIM).fold(slope(0), |m, k| m.min(slope(k)));
    let coupling = |k: usize, j: usize| {
        if (psi[k] - psi[j]).abs() > STEP {
            (s[k] - s[j]) / (psi[k] - psi[j])
        } else {
            0.5 * (tangent[k] + tangent[j])
        }
    };
    let weight = |j: f64| dt / (1.0 - dt * j.min(0.0));
    let m = rate.congruence(&S::transpose(&r));
    let next = S::from_entries(|k, j| {
        if k == j {
            psi[k] + m.entry(k, k) * weight(diagonal)
        } else {
            m.entry(k, j) * weight(coupling(k, j))
        }
    });
    next.exp().congruence(&r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::{Mat2, Mat3, Sym2, Sym3};
    use crate::engine::rheology::{
        direct_step, ExponentialPtt, FeneCr, FeneP, Giesekus, LinearPtt,
    };

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

    /// The planar tensor as a 3D one with A_zz = 1 (no stretch across the plane).
    fn embedded(a: &Sym2) -> Sym3 {
        Sym3::new(a.xx, a.xy, 0.0, a.yy, 0.0, 1.0)
    }

    /// A planar flow in 3D is the 2D flow: for every model whose functions depend on A only
    /// through A − I and tr(A − I) (all but FENE, whose tr A < L² counts the third
    /// direction), each update of a 3D A with A_zz = 1 under an in-plane ∇u keeps A_zz = 1
    /// and the out-of-plane components zero, and its in-plane components are the 2D
    /// update's. Not bit for bit: the 3D eigen-decomposition is Jacobi's, the 2D one the
    /// closed form, so the two differ by round-off, amplified over 40 steps by at most the
    /// stretch (1e-12 relative).
    #[test]
    fn the_3d_update_is_the_2d_one_on_a_planar_flow() {
        let grad2 = Mat2::new(0.4, 1.3, -0.2, -0.4);
        let mut grad3 = Mat3::zeros();
        grad3.fixed_view_mut::<2, 2>(0, 0).copy_from(&grad2);
        let models = [
            Model::OldroydB,
            Model::Ucm,
            Model::LinearPtt(LinearPtt { epsilon: 0.3 }),
            Model::ExponentialPtt(ExponentialPtt { epsilon: 0.3 }),
            Model::Giesekus(Giesekus { alpha: 0.2 }),
        ];
        let (dt, lambda) = (0.02, 0.7);
        for model in models {
            for update in 0..4 {
                let (mut a2, mut a3) = (Sym2::IDENTITY, Sym3::IDENTITY);
                for _ in 0..40 {
                    (a2, a3) = match update {
                        0 => (
                            log_conformation_step(
                                &model,
                                &a2,
                                &a2.log(),
                                &Sym2::ZERO,
                                &grad2,
                                dt,
                                lambda,
                            ),
                            log_conformation_step(
                                &model,
                                &a3,
                                &a3.log(),
                                &Sym3::ZERO,
                                &grad3,
                                dt,
                                lambda,
                            ),
                        ),
                        1 => (
                            log_conformation_step_strang(
                                &model,
                                &a2,
                                &Sym2::ZERO,
                                &grad2,
                                dt,
                                lambda,
                            ),
                            log_conformation_step_strang(
                                &model,
                                &a3,
                                &Sym3::ZERO,
                                &grad3,
                                dt,
                                lambda,
                            ),
                        ),
                        2 => (
                            log_unsplit_step(
                                &model,
                                &a2,
                                &log_local_rate(&model, &a2, &grad2, lambda),
                                dt,
                                lambda,
                            ),
                            log_unsplit_step(
                                &model,
                                &a3,
                                &log_local_rate(&model, &a3, &grad3, lambda),
                                dt,
                                lambda,
                            ),
                        ),
                        _ => (
                            direct_step(&model, &a2, &Sym2::ZERO, &grad2, dt, lambda),
                            direct_step(&model, &a3, &Sym3::ZERO, &grad3, dt, lambda),
                        ),
                    };
                }
                let d = a3 - embedded(&a2);
                let scale = a3.contract(&a3).sqrt();
                assert!(
                    d.contract(&d).sqrt() < 1e-12 * scale,
                    "{model:?}, update {update}: {a3:?} against {a2:?}"
                );
                assert!(a2.xx > 1.5, "{model:?}: the flow must stretch A ({a2:?})");
            }
        }
    }

    /// That the decomposition reproduces d(ln A)/dt for dA/dt = ∇u·A + A·∇uᵀ: against a
    /// central difference of the matrix logarithm along the exact flow, ε = 1e-6, within
    /// 1e-6 relative.
    fn assert_convective_term_is_the_derivative_of_log_a<S: SymTensor>(
        grad: S::Matrix,
        cases: &[S],
    ) {
        for &a in cases {
            let rate = |a: &S| {
                let s = grad * a.to_mat();
                S::sym_part(&(s + S::transpose(&s)))
            };
            let eps = 1e-6;
            let plus = (a + rate(&a) * eps).log();
            let minus = (a - rate(&a) * eps).log();
            let fd = (plus - minus) * (0.5 / eps);
            let exact = log_convective_term(&a, &grad);
            let err = (fd - exact).contract(&(fd - exact)).sqrt();
            assert!(
                err < 1e-6 * (1.0 + exact.contract(&exact).sqrt()),
                "A = {a:?}: {fd:?} vs {exact:?}"
            );
        }
    }

    /// In 2D, including the degenerate A = I and a strongly stretched A.
    #[test]
    fn log_convective_term_is_the_derivative_of_log_a() {
        let grad = Mat2::new(0.3, 1.7, -0.4, -0.3);
        let cases = [
            Sym2::IDENTITY,
            Sym2::new(2.0, 0.5, 1.0),
            Sym2::new(1.0 + 1e-9, 0.0, 1.0),
            Sym2::new(5e4, 220.0, 1.0),
        ];
        assert_convective_term_is_the_derivative_of_log_a(grad, &cases);
    }

    /// In 3D under a fully 3D ∇u (truncation O(ε²) ≈ 1e-12 times the third derivative;
    /// round-off, the entries' 1e-16 relative error over the smallest eigenvalue and ε,
    /// 1e-16·500/0.2/1e-6 ≈ 3e-7 for the stretched A, under the bound), for A = I, a double
    /// eigenvalue, a near-triple one and a stretched, rotated A.
    #[test]
    fn the_3d_convective_term_is_the_derivative_of_log_a() {
        let grad = Mat3::new(0.3, 1.7, -0.2, -0.4, -0.5, 0.6, 0.9, 0.1, 0.2);
        let r = nalgebra::Rotation3::from_euler_angles(0.4, -0.8, 1.1);
        let stretched = Mat3::from_diagonal(&nalgebra::Vector3::new(500.0, 3.0, 0.2));
        let cases = [
            Sym3::IDENTITY,
            Sym3::new(2.0, 0.0, 0.0, 2.0, 0.0, 1.0),
            Sym3::new(1.0 + 1e-9, 0.0, 1e-10, 1.0, 0.0, 1.0),
            Sym3::sym_part(&(r.matrix() * stretched * r.matrix().transpose())),
        ];
        assert_convective_term_is_the_derivative_of_log_a(grad, &cases);
    }

    /// Start-up of uniaxial extension, ∇u = ε̇ diag(1, −½, −½), of an Oldroyd-B fluid in 3D,
    /// with no planar counterpart: A_xx = s_x + (1 − s_x)e^{−(1 − 2λε̇)t/λ}, s_x = 1/(1 − 2λε̇),
    /// and A_yy = A_zz = s_y + (1 − s_y)e^{−(1 + λε̇)t/λ}, s_y = 1/(1 + λε̇) (λε̇ = 0.4 < ½).
    /// The Strang update is second order: the error falls 4× (3.6–4.4) when δt halves.
    #[test]
    fn uniaxial_extension_in_3d_converges_at_second_order() {
        let (lambda, rate, t_end) = (1.0, 0.4, 1.5);
        let grad = Mat3::from_diagonal(&nalgebra::Vector3::new(rate, -0.5 * rate, -0.5 * rate));
        let exact = |k: f64| {
            let s = 1.0 / (1.0 - k * lambda * rate);
            s + (1.0 - s) * (-(1.0 - k * lambda * rate) * t_end / lambda).exp()
        };
        let (xx, yy) = (exact(2.0), exact(-1.0));
        let error = |steps: usize| {
            let dt = t_end / steps as f64;
            let mut a = Sym3::IDENTITY;
            for _ in 0..steps {
                a = log_conformation_step_strang(
                    &Model::OldroydB,
                    &a,
                    &Sym3::ZERO,
                    &grad,
                    dt,
                    lambda,
                );
            }
            assert!(
                a.xy == 0.0 && a.xz == 0.0 && a.yz == 0.0 && a.yy == a.zz,
                "{a:?}"
            );
            (a.xx - xx).abs().max((a.yy - yy).abs())
        };
        let (coarse, fine) = (error(50), error(100));
        assert!(coarse < 1e-3, "error {coarse}");
        let ratio = coarse / fine;
        assert!((3.6..4.4).contains(&ratio), "ratio {ratio}");
    }

    /// The FENE bounds in 3D: the rest state L²/(L² + 3) I of FENE-P is stress-free, and a
    /// strong 3D extension under either FENE model keeps tr A < L² at every step.
    #[test]
    fn the_fene_bounds_hold_in_3d() {
        let rest: Sym3 = Model::FeneP(FeneP { l2: 10.0 }).rest_conformation();
        assert!((rest.xx - 10.0 / 13.0).abs() < 1e-15 && rest.xy == 0.0);
        let strain = Model::FeneP(FeneP { l2: 10.0 }).strain(&rest);
        assert!(strain.contract(&strain) < 1e-28, "{strain:?}");
        let grad = Mat3::new(4.0, 0.5, 0.0, 0.0, -2.0, 0.3, 0.0, 0.0, -2.0);
        for model in [
            Model::FeneP(FeneP { l2: 10.0 }),
            Model::FeneCr(FeneCr { l2: 10.0 }),
        ] {
            let mut a: Sym3 = model.rest_conformation();
            for _ in 0..200 {
                a = log_conformation_step(&model, &a, &a.log(), &Sym3::ZERO, &grad, 0.05, 1.0);
                assert!(a.trace() < 10.0 && a.det() > 0.0, "{model:?}: {a:?}");
            }
            assert!(
                a.trace() > 8.0,
                "{model:?}: the flow must approach the bound ({a:?})"
            );
        }
    }
}
