//! Constitutive models as strain and relaxation functions (King & Lind Table I, eqs. (9)–(10))
//! and the integration of the conformation tensor: log-conformation (eqs. (12)–(19),
//! (29)–(32)) or direct first-order Euler on A (eq. (10)).

pub mod models;

use crate::engine::math::{Mat2, Sym2};
pub use models::{Constitutive, ExponentialPtt, FeneCr, FeneP, Giesekus, LinearPtt, OldroydB};

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

impl Model {
    pub fn name(&self) -> &'static str {
        match self {
            Model::Newtonian => "newtonian",
            Model::OldroydB => "oldroyd-b",
            Model::Ucm => "ucm",
            Model::FeneP(_) => "fene-p",
            Model::FeneCr(_) => "fene-cr",
            Model::LinearPtt(_) => "lptt",
            Model::ExponentialPtt(_) => "eptt",
            Model::Giesekus(_) => "giesekus",
        }
    }

    pub fn is_viscoelastic(&self) -> bool {
        !matches!(self, Model::Newtonian)
    }

    /// The Table I functions of a viscoelastic model.
    #[inline]
    pub fn constitutive(&self) -> Option<&dyn Constitutive> {
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

    /// Strain function f_S(A), eq. (9) (zero for a Newtonian fluid).
    pub fn strain(&self, a: &Sym2) -> Sym2 {
        self.constitutive().map_or(Sym2::ZERO, |m| m.strain(a))
    }

    /// Relaxation function f_R(A), eq. (10).
    pub fn relaxation(&self, a: &Sym2) -> Sym2 {
        self.constitutive().map_or(Sym2::ZERO, |m| m.relaxation(a))
    }

    /// `(α_R, β_R)` with f_R = α_R(β_R A − I), for the quasi-analytic source step (32).
    pub fn relaxation_coefficients(&self, a: &Sym2) -> Option<(f64, f64)> {
        self.constitutive()
            .and_then(|m| m.relaxation_coefficients(a))
    }

    /// Conformation of the fluid at rest.
    pub fn rest_conformation(&self) -> Sym2 {
        self.constitutive()
            .map_or(Sym2::IDENTITY, |m| m.rest_conformation())
    }

    /// Inverts f_S (§III B, Step 1): the conformation whose strain function is `strain`
    /// (= λτ_p/η_p), given tr A where f_S depends on it (the paper stores tr A for this).
    pub fn conformation_from_strain(&self, strain: &Sym2, trace: f64) -> Sym2 {
        match self {
            Model::FeneP(m) => (*strain + Sym2::IDENTITY) * (1.0 - trace / m.l2),
            Model::FeneCr(m) => *strain * (1.0 - trace / m.l2) + Sym2::IDENTITY,
            _ => *strain + Sym2::IDENTITY,
        }
    }
}

/// How the conformation tensor is integrated in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConformationScheme {
    /// Log-conformation with source splitting, §III B.
    Log,
    /// First-order Euler on A itself, eq. (10): not positive-definite by construction.
    Direct,
}

/// Material constants of the fluid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fluid {
    pub model: Model,
    /// Density ρ.
    pub density: f64,
    /// Total viscosity η0 = η_s + η_p.
    pub viscosity: f64,
    /// Viscosity ratio β = η_s/η0 (1 for a Newtonian fluid).
    pub beta: f64,
    /// Relaxation time λ (0 for a Newtonian fluid).
    pub relaxation_time: f64,
}

impl Fluid {
    pub fn solvent_viscosity(&self) -> f64 {
        self.beta * self.viscosity
    }

    pub fn polymer_viscosity(&self) -> f64 {
        (1.0 - self.beta) * self.viscosity
    }

    /// Polymer stress τ_p = (η_p/λ) f_S(A), eq. (9).
    pub fn polymer_stress(&self, a: &Sym2) -> Sym2 {
        if !self.model.is_viscoelastic() {
            return Sym2::ZERO;
        }
        self.model.strain(a) * (self.polymer_viscosity() / self.relaxation_time)
    }
}

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

/// One direct first-order Euler update of A, eq. (10) with (11):
/// `A + δt[u_ps·∇A + ∇u·A + A·∇uᵀ − f_R(A)/λ]`.
pub fn direct_step(
    model: &Model,
    a: &Sym2,
    advection_a: &Sym2,
    grad_u: &Mat2,
    dt: f64,
    lambda: f64,
) -> Sym2 {
    let stretch = grad_u * a.to_mat();
    let upper_convected = Sym2::sym_part(&(stretch + stretch.transpose()));
    *a + (*advection_a + upper_convected - model.relaxation(a) * (1.0 / lambda)) * dt
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decomposition must reproduce d(ln A)/dt for dA/dt = ∇u·A + A·∇uᵀ: compare with a
    /// central difference of the matrix logarithm along the exact flow, including the
    /// degenerate A = I and a strongly stretched A.
    #[test]
    fn log_convective_term_is_the_derivative_of_log_a() {
        let grad = Mat2::new(0.3, 1.7, -0.4, -0.3);
        for a in [
            Sym2::IDENTITY,
            Sym2::new(2.0, 0.5, 1.0),
            Sym2::new(1.0 + 1e-9, 0.0, 1.0),
            Sym2::new(5e4, 220.0, 1.0),
        ] {
            let rate = |a: &Sym2| {
                let s = grad * a.to_mat();
                Sym2::sym_part(&(s + s.transpose()))
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

    /// The quasi-analytic source step is the exact relaxation of a uniform A.
    #[test]
    fn source_step_is_exact_relaxation() {
        let a0 = Sym2::new(3.0, 0.7, 1.5);
        let lambda = 0.8;
        let mut a = a0;
        for _ in 0..10 {
            a = relax(&Model::OldroydB, &a, 0.1, lambda);
        }
        let decay = (-1.0f64 / lambda).exp();
        let exact = Sym2::IDENTITY + (a0 - Sym2::IDENTITY) * decay;
        assert!((a - exact).contract(&(a - exact)).sqrt() < 1e-13);
    }

    /// Start-up of homogeneous simple shear u = γ̇ y, Oldroyd-B, has the closed form
    /// A_xy = λγ̇(1 − e^{−t/λ}), A_xx = 1 + 2(λγ̇)²[1 − e^{−t/λ}(1 + t/λ)].
    /// Both integrators must converge to it at first order in δt (splitting error).
    #[test]
    fn integrators_converge_to_simple_shear_start_up() {
        let (lambda, shear, t_end): (f64, f64, f64) = (1.0, 2.0, 2.0);
        let grad = Mat2::new(0.0, shear, 0.0, 0.0);
        let e = (-t_end / lambda).exp();
        let exact = Sym2::new(
            1.0 + 2.0 * (lambda * shear).powi(2) * (1.0 - e * (1.0 + t_end / lambda)),
            lambda * shear * (1.0 - e),
            1.0,
        );
        let run = |steps: usize, log: bool| {
            let dt = t_end / steps as f64;
            let mut a = Sym2::IDENTITY;
            for _ in 0..steps {
                a = if log {
                    log_conformation_step(
                        &Model::OldroydB,
                        &a,
                        &a.log(),
                        &Sym2::ZERO,
                        &grad,
                        dt,
                        lambda,
                    )
                } else {
                    direct_step(&Model::OldroydB, &a, &Sym2::ZERO, &grad, dt, lambda)
                };
            }
            let d = a - exact;
            d.contract(&d).sqrt() / exact.contract(&exact).sqrt()
        };
        for log in [true, false] {
            let (e1, e2) = (run(400, log), run(800, log));
            let order = (e1 / e2).log2();
            // δt = 2.5e-3 with first-order splitting: a few 1e-3 relative error.
            assert!(e2 < 5e-3, "log={log}: relative error {e2}");
            assert!((order - 1.0).abs() < 0.15, "log={log}: order {order}");
        }
    }

    #[test]
    fn polymer_stress_of_oldroyd_b() {
        let fluid = Fluid {
            model: Model::OldroydB,
            density: 1.0,
            viscosity: 2.0,
            beta: 0.25,
            relaxation_time: 0.5,
        };
        let tau = fluid.polymer_stress(&Sym2::new(3.0, 1.0, 1.0));
        // η_p/λ = 1.5/0.5 = 3.
        assert_eq!(tau, Sym2::new(6.0, 3.0, 0.0));
    }

    fn all_models() -> Vec<Model> {
        vec![
            Model::OldroydB,
            Model::Ucm,
            Model::FeneP(FeneP { l2: 10.0 }),
            Model::FeneP(FeneP { l2: 100.0 }),
            Model::FeneCr(FeneCr { l2: 10.0 }),
            Model::LinearPtt(LinearPtt { epsilon: 0.25 }),
            Model::ExponentialPtt(ExponentialPtt { epsilon: 0.25 }),
            Model::Giesekus(Giesekus { alpha: 0.3 }),
        ]
    }

    /// Step 1 of §III B: f_S inverted with the stored tr A returns the conformation.
    #[test]
    fn strain_function_inverts() {
        for model in all_models() {
            for a in [
                Sym2::new(3.0, 1.0, 2.0),
                Sym2::new(1.2, -0.3, 0.9),
                model.rest_conformation(),
            ] {
                let back = model.conformation_from_strain(&model.strain(&a), a.trace());
                let d = back - a;
                assert!(
                    d.contract(&d).sqrt() < 1e-12,
                    "{}: {a:?} -> {back:?}",
                    model.name()
                );
            }
        }
    }

    /// ln then exp returns the tensor and keeps it symmetric positive definite, from rest
    /// to the stretch of Wi = 85 Poiseuille flow (A_xx ~ 1e5) and a strongly rotated case.
    #[test]
    fn log_exp_round_trip_keeps_a_spd() {
        for a in [
            Sym2::IDENTITY,
            Sym2::new(1.0 + 2.0 * 85.0f64.powi(2) * 16.0, 85.0 * 4.0, 1.0),
            Sym2::new(50.0, 49.9, 50.0),
            Sym2::new(1e-3, 0.0, 1e3),
        ] {
            let back = a.log().exp();
            let d = back - a;
            assert!(
                d.contract(&d).sqrt() < 1e-10 * a.contract(&a).sqrt(),
                "{a:?} -> {back:?}"
            );
            let e = back.eigen();
            assert!(e.values[1] > 0.0, "lost positive definiteness: {back:?}");
        }
    }

    /// The source step (29b) of a uniform A, against an RK4 solution of dA/dt = −f_R(A)/λ
    /// with 10⁴ steps: the quasi-analytic step (32), which freezes tr A over a step, and the
    /// explicit step (33) (Giesekus) are first order in δt.
    #[test]
    fn source_step_matches_exact_relaxation() {
        let lambda = 0.7;
        let t_end = 0.7;
        let a0 = Sym2::new(4.0, 1.5, 1.5);
        for model in all_models() {
            let rate = |a: &Sym2| model.relaxation(a) * (-1.0 / lambda);
            let mut exact = a0;
            let n = 10_000;
            let h = t_end / n as f64;
            for _ in 0..n {
                let k1 = rate(&exact);
                let k2 = rate(&(exact + k1 * (h / 2.0)));
                let k3 = rate(&(exact + k2 * (h / 2.0)));
                let k4 = rate(&(exact + k3 * h));
                exact += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
            }
            let error = |steps: usize| {
                let mut a = a0;
                for _ in 0..steps {
                    a = relax(&model, &a, t_end / steps as f64, lambda);
                }
                let d = a - exact;
                d.contract(&d).sqrt() / exact.contract(&exact).sqrt()
            };
            let (coarse, fine) = (error(100), error(200));
            if matches!(model, Model::OldroydB | Model::Ucm) {
                assert!(fine < 1e-13, "Oldroyd-B relaxation is exact, error {fine}");
                continue;
            }
            assert!(fine < 5e-3, "{}: error {fine}", model.name());
            let order = (coarse / fine).log2();
            assert!((order - 1.0).abs() < 0.2, "{}: order {order}", model.name());
        }
    }
}
