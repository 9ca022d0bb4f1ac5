//! Homogeneous flows of a case's fluid: its material functions, computed by integrating the
//! solver's own constitutive update (log-conformation (29)–(33), or direct (10), with no
//! advection) under a prescribed uniform velocity gradient, beside the exact curves.
//!
//! * steady shear: η(γ̇) = η_s + τ_xy/γ̇, Ψ₁ = (τ_xx − τ_yy)/γ̇², Ψ₂ = (τ_yy − τ_zz)/γ̇²; the
//!   conformation is 2D, and τ_zz = 0 (A_zz at rest, exact for Oldroyd-B, UCM, Giesekus and
//!   the PTT models in planar flows); exact: the steady-shear conformation of every model
//!   ([`steady_shear_conformation`]);
//! * start-up of shear at λγ̇ = Wi: η⁺(t), Ψ₁⁺(t); exact for Oldroyd-B/UCM,
//!   η⁺ = η_s + η_p(1 − e^{−t/λ});
//! * start-up of planar extension ∇u = diag(ε̇, −ε̇): η_P⁺ = (σ_xx − σ_yy)/ε̇ (4η for a
//!   Newtonian fluid); exact for Oldroyd-B/UCM from the two decoupled linear equations of
//!   A_xx and A_yy (unbounded for λε̇ ≥ ½). Uniaxial extension needs A_zz, which the 2D
//!   model does not carry;
//! * small-amplitude oscillatory shear γ = γ₀ sin ωt: G′, G″ from the stress over the last of
//!   ten periods (after 10λ), exact Maxwell moduli plus η_sω for the models whose linear
//!   limit is Maxwell's (Oldroyd-B, UCM, Giesekus, PTT).
//!
//! The update is first order in δt (the splitting of (29)); δt = 10⁻³ of the flow's shortest
//! time (λ, 1/γ̇, 1/ε̇, 1/ω), so that the splitting error stays near 10⁻³.

use crate::analysis::analytic::steady_channel::steady_shear_stress;
use crate::engine::math::{Mat2, Sym2};
use crate::engine::rheology::{direct_step, log_conformation_step, ConformationScheme};
use crate::engine::rheology::{Fluid, Model};
use std::f64::consts::PI;

/// Steps per shortest time of the flow.
const STEPS_PER_TIME: f64 = 1000.0;

/// A fluid and the conformation update the solver would use for it.
pub struct Rheometer {
    pub fluid: Fluid,
    pub scheme: ConformationScheme,
}

/// One point of the steady-shear sweep (exact values NaN where there is none).
#[derive(Clone, Debug, PartialEq)]
pub struct SteadyShear {
    pub shear_rate: f64,
    pub viscosity: f64,
    pub psi1: f64,
    pub psi2: f64,
    pub viscosity_exact: f64,
    pub psi1_exact: f64,
    pub psi2_exact: f64,
}

/// One sample of a start-up flow.
#[derive(Clone, Debug, PartialEq)]
pub struct Transient {
    pub t: f64,
    /// η⁺ (shear) or η_P⁺ (planar extension).
    pub viscosity: f64,
    /// Ψ₁⁺ (shear; NaN in extension).
    pub psi1: f64,
    pub viscosity_exact: f64,
}

/// G′ and G″ at one frequency.
#[derive(Clone, Debug, PartialEq)]
pub struct Oscillatory {
    pub omega: f64,
    pub storage: f64,
    pub loss: f64,
    pub storage_exact: f64,
    pub loss_exact: f64,
}

impl Rheometer {
    fn lambda(&self) -> f64 {
        self.fluid.relaxation_time
    }

    fn viscoelastic(&self) -> bool {
        self.fluid.model.is_viscoelastic() && self.lambda() > 0.0
    }

    /// One update of A under the uniform gradient `grad` (∂u_a/∂x_b).
    fn step(&self, a: &Sym2, grad: &Mat2, dt: f64) -> Sym2 {
        let (model, lambda) = (&self.fluid.model, self.lambda());
        match self.scheme {
            ConformationScheme::Log => {
                log_conformation_step(model, a, &a.log(), &Sym2::ZERO, grad, dt, lambda)
            }
            ConformationScheme::Direct => direct_step(model, a, &Sym2::ZERO, grad, dt, lambda),
        }
    }

    /// A after `t_end` of `grad(t)` from rest, in steps of about `dt` (a whole number of them),
    /// calling `sample(t, δt, A)` after every step.
    fn integrate(
        &self,
        grad: impl Fn(f64) -> Mat2,
        t_end: f64,
        dt: f64,
        mut sample: impl FnMut(f64, f64, &Sym2),
    ) -> Result<Sym2, String> {
        let steps = (t_end / dt).ceil().max(1.0) as usize;
        let dt = t_end / steps as f64;
        let mut a = self.fluid.model.rest_conformation();
        for k in 0..steps {
            let t = k as f64 * dt;
            a = self.step(&a, &grad(t + 0.5 * dt), dt);
            if !(a.xx.is_finite() && a.xy.is_finite() && a.yy.is_finite()) {
                return Err(format!("the conformation diverged at t = {:.4e}", t + dt));
            }
            sample(t + dt, dt, &a);
        }
        Ok(a)
    }

    /// η, Ψ₁, Ψ₂ at each shear rate after 20λ of steady shear.
    pub fn steady_shear(&self, rates: &[f64]) -> Result<Vec<SteadyShear>, String> {
        let f = &self.fluid;
        rates
            .iter()
            .map(|&rate| {
                let tau = if self.viscoelastic() {
                    let lambda = self.lambda();
                    let dt = lambda.min(1.0 / rate) / STEPS_PER_TIME;
                    let a = self.integrate(|_| shear(rate), 20.0 * lambda, dt, |_, _, _| {})?;
                    f.polymer_stress(&a)
                } else {
                    Sym2::ZERO
                };
                let exact = steady_shear_stress(f, rate).ok();
                let (eta_s, g2) = (self.solvent(), rate * rate);
                Ok(SteadyShear {
                    shear_rate: rate,
                    viscosity: eta_s + tau.xy / rate,
                    psi1: (tau.xx - tau.yy) / g2,
                    psi2: tau.yy / g2,
                    viscosity_exact: exact.map_or(f64::NAN, |s| eta_s + s.xy / rate),
                    psi1_exact: exact.map_or(f64::NAN, |s| (s.xx - s.yy) / g2),
                    psi2_exact: exact.map_or(f64::NAN, |s| s.yy / g2),
                })
            })
            .collect()
    }

    /// The solvent viscosity (η0 for a Newtonian fluid, whose β is 1).
    fn solvent(&self) -> f64 {
        self.fluid.solvent_viscosity()
    }

    /// Start-up of shear at `rate` to `t_end`, `samples` samples.
    pub fn startup_shear(
        &self,
        rate: f64,
        t_end: f64,
        samples: usize,
    ) -> Result<Vec<Transient>, String> {
        let exact = |t: f64| match self.fluid.model {
            Model::OldroydB | Model::Ucm => {
                self.solvent() + self.fluid.polymer_viscosity() * (1.0 - (-t / self.lambda()).exp())
            }
            Model::Newtonian => self.solvent(),
            _ => f64::NAN,
        };
        let record = |t: f64, tau: &Sym2| Transient {
            t,
            viscosity: self.solvent() + tau.xy / rate,
            psi1: (tau.xx - tau.yy) / (rate * rate),
            viscosity_exact: exact(t),
        };
        self.transient(|_| shear(rate), rate, t_end, samples, record)
    }

    /// Start-up of planar extension at `rate` to `t_end`.
    pub fn planar_extension(
        &self,
        rate: f64,
        t_end: f64,
        samples: usize,
    ) -> Result<Vec<Transient>, String> {
        let grad = Mat2::new(rate, 0.0, 0.0, -rate);
        let record = |t: f64, tau: &Sym2| Transient {
            t,
            viscosity: 4.0 * self.solvent() + (tau.xx - tau.yy) / rate,
            psi1: f64::NAN,
            viscosity_exact: self.planar_exact(rate, t),
        };
        self.transient(|_| grad, rate, t_end, samples, record)
    }

    /// Oldroyd-B/UCM η_P⁺: A_kk = 1/(1 − 2s) + (1 − 1/(1 − 2s)) e^{−(1 − 2s)t/λ}, s = ±λε̇.
    fn planar_exact(&self, rate: f64, t: f64) -> f64 {
        match self.fluid.model {
            Model::Newtonian => 4.0 * self.solvent(),
            Model::OldroydB | Model::Ucm => {
                let lambda = self.lambda();
                let component = |s: f64| {
                    let k = 1.0 - 2.0 * s;
                    1.0 / k + (1.0 - 1.0 / k) * (-k * t / lambda).exp()
                };
                let g = self.fluid.polymer_viscosity() / lambda;
                let (xx, yy) = (component(lambda * rate), component(-lambda * rate));
                4.0 * self.solvent() + g * (xx - yy) / rate
            }
            _ => f64::NAN,
        }
    }

    /// A start-up flow sampled `samples` times, `record(t, τ_p)` per sample.
    fn transient(
        &self,
        grad: impl Fn(f64) -> Mat2,
        rate: f64,
        t_end: f64,
        samples: usize,
        record: impl Fn(f64, &Sym2) -> Transient,
    ) -> Result<Vec<Transient>, String> {
        if !self.viscoelastic() {
            let times = (1..=samples).map(|k| t_end * k as f64 / samples as f64);
            return Ok(times.map(|t| record(t, &Sym2::ZERO)).collect());
        }
        let dt = self.lambda().min(1.0 / rate) / STEPS_PER_TIME;
        let every = ((t_end / dt) as usize / samples.max(1)).max(1);
        let mut out = Vec::new();
        let mut k = 0;
        self.integrate(grad, t_end, dt, |t, _, a| {
            k += 1;
            if k % every == 0 {
                out.push(record(t, &self.fluid.polymer_stress(a)));
            }
        })?;
        Ok(out)
    }

    /// G′ and G″ at each frequency at strain amplitude `strain`.
    pub fn oscillatory(&self, omegas: &[f64], strain: f64) -> Result<Vec<Oscillatory>, String> {
        omegas
            .iter()
            .map(|&omega| self.oscillatory_point(omega, strain))
            .collect()
    }

    fn oscillatory_point(&self, omega: f64, strain: f64) -> Result<Oscillatory, String> {
        let period = 2.0 * PI / omega;
        let (storage, loss) = if self.viscoelastic() {
            let lambda = self.lambda();
            let periods = (10.0 * lambda / period).ceil().max(10.0);
            let t_end = periods * period;
            let dt = lambda.min(1.0 / omega) / STEPS_PER_TIME;
            // ∫ τ_xy sin ωt and ∫ τ_xy cos ωt over the last period (rectangle rule at the
            // step ends: exact to O(δt) for a periodic integrand).
            let (mut s, mut c) = (0.0, 0.0);
            let start = t_end - period;
            let rate = move |t: f64| strain * omega * (omega * t).cos();
            self.integrate(
                |t| shear(rate(t)),
                t_end,
                dt,
                |t, h, a| {
                    if t > start + 0.5 * h {
                        let tau = self.fluid.polymer_stress(a).xy;
                        s += tau * (omega * t).sin() * h;
                        c += tau * (omega * t).cos() * h;
                    }
                },
            )?;
            let scale = 2.0 / (strain * period);
            (s * scale, c * scale)
        } else {
            (0.0, 0.0)
        };
        let (g_exact, l_exact) = self.maxwell(omega);
        Ok(Oscillatory {
            omega,
            storage,
            loss: loss + self.solvent() * omega,
            storage_exact: g_exact,
            loss_exact: l_exact + self.solvent() * omega,
        })
    }

    /// The Maxwell moduli of the polymer, for the models whose linear limit is Maxwell's.
    fn maxwell(&self, omega: f64) -> (f64, f64) {
        match self.fluid.model {
            Model::Newtonian => (0.0, 0.0),
            Model::OldroydB
            | Model::Ucm
            | Model::Giesekus(_)
            | Model::LinearPtt(_)
            | Model::ExponentialPtt(_) => {
                let (lambda, eta_p) = (self.lambda(), self.fluid.polymer_viscosity());
                let w = lambda * omega;
                let d = 1.0 + w * w;
                (eta_p / lambda * w * w / d, eta_p * omega / d)
            }
            _ => (f64::NAN, f64::NAN),
        }
    }
}

/// ∇u of simple shear u = (γ̇y, 0).
fn shear(rate: f64) -> Mat2 {
    Mat2::new(0.0, rate, 0.0, 0.0)
}

/// `count` values from `low` to `high`, evenly spaced in log.
pub fn log_space(low: f64, high: f64, count: usize) -> Vec<f64> {
    let n = count.max(2) - 1;
    (0..=n)
        .map(|k| low * (high / low).powf(k as f64 / n as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::rheology::{Giesekus, LinearPtt};

    fn fluid(model: Model) -> Fluid {
        Fluid {
            model,
            density: 1.0,
            viscosity: 1.0,
            beta: 0.1,
            relaxation_time: 1.0,
            surface_tension: 0.0,
            law: crate::engine::rheology::ViscosityLaw::Constant,
        }
    }

    fn rheometer(model: Model, scheme: ConformationScheme) -> Rheometer {
        Rheometer {
            fluid: fluid(model),
            scheme,
        }
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// Steady shear over Wi = 0.1 … 10 against the exact steady conformation: Oldroyd-B
    /// (η = η0, Ψ₁ = 2η_pλ), Giesekus α = 0.2 and L-PTT ε = 0.25 (shear-thinning), both
    /// integrators. Bound 1 %: the splitting error at δt = 10⁻³ of the shortest time is a few
    /// 10⁻³ (measured ≤ 2·10⁻³), while a wrong term of the update misses by tens of percent.
    #[test]
    fn steady_shear_matches_the_exact_material_functions() {
        let models = [
            Model::OldroydB,
            Model::Giesekus(Giesekus { alpha: 0.2 }),
            Model::LinearPtt(LinearPtt { epsilon: 0.25 }),
        ];
        for model in models {
            for scheme in [ConformationScheme::Log, ConformationScheme::Direct] {
                let r = rheometer(model, scheme);
                for p in r.steady_shear(&[0.1, 1.0, 10.0]).unwrap() {
                    let label = format!("{model:?} {scheme:?} at {}", p.shear_rate);
                    assert!(
                        relative(p.viscosity, p.viscosity_exact) < 0.01,
                        "{label}: {p:?}"
                    );
                    assert!(relative(p.psi1, p.psi1_exact) < 0.01, "{label}: {p:?}");
                }
            }
        }
        let p = &rheometer(Model::OldroydB, ConformationScheme::Log)
            .steady_shear(&[1.0])
            .unwrap()[0];
        assert!(relative(p.psi1_exact, 2.0 * 0.9).abs() < 1e-12);
        assert!(relative(p.viscosity_exact, 1.0).abs() < 1e-12);
    }

    /// Oldroyd-B start-up of shear (Wi = 2) and of planar extension (λε̇ = 0.25, bounded)
    /// against their closed forms, and SAOS at λω = 0.1, 1, 10 against the Maxwell moduli.
    /// Bounds 1 % as above; SAOS at γ₀ = 10⁻³ is linear to 10⁻⁶.
    #[test]
    fn transients_and_moduli_match_oldroyd_b() {
        let r = rheometer(Model::OldroydB, ConformationScheme::Log);
        for s in r.startup_shear(2.0, 5.0, 20).unwrap() {
            assert!(relative(s.viscosity, s.viscosity_exact) < 0.01, "{s:?}");
        }
        for s in r.planar_extension(0.25, 5.0, 20).unwrap() {
            assert!(relative(s.viscosity, s.viscosity_exact) < 0.01, "{s:?}");
        }
        for o in r.oscillatory(&[0.1, 1.0, 10.0], 1e-3).unwrap() {
            assert!(relative(o.storage, o.storage_exact) < 0.01, "{o:?}");
            assert!(relative(o.loss, o.loss_exact) < 0.01, "{o:?}");
        }
    }
}
