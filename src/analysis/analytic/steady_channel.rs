//! Steady, fully developed channel flow of the Table I models with a Newtonian solvent.
//!
//! In steady simple shear at Wi_γ = λγ̇ the conformation solves `∇u·A + A·∇uᵀ = f_R(A)/λ`:
//!
//! * f_R = α_R(β_R A − I): A_yy = 1/β_R, A_xy = Wi_γ/(α_R β_R²), A_xx = (1 + 2Wi_γ A_xy/α_R)/β_R,
//!   with tr A closing a scalar equation — FENE-P: L²b³ − (L² + 2)b² − 2Wi_γ² = 0 (b = β_R);
//!   FENE-CR: (1 − 2/L²)c² − c − 2Wi_γ²/L² = 0 (c = α_R, closed form); L-PTT:
//!   a³ − a² − 2εWi_γ² = 0; E-PTT: ln a = 2εWi_γ²/a² (a = α_R);
//! * Giesekus: with s = 1 − A_yy the yy equation gives A_xy² = s(1 − αs)/α, the xy equation
//!   A_xx, and the xx equation one scalar equation for s ∈ (0, 1).
//!
//! The channel (walls at y = 0 and H, driven by ρg) has the exact total shear stress
//! τ(y) = ρg(H/2 − y) = η_s γ̇ + τ_p,xy(γ̇). At each height γ̇ is found by a bracketed root
//! solve (τ_p,xy is increasing in γ̇ for every model here, Giesekus up to α = ½), and
//! u(y) = ∫₀^y γ̇ dy by 4-point Gauss–Legendre quadrature on a fine grid, interpolated with
//! cubic Hermite polynomials that use γ̇ as the derivative. No tables from the literature.
//!
//! A generalised Newtonian fluid is the same problem with the solvent stress η(γ̇)γ̇ of its
//! law and no polymer: the power law, Carreau–Yasuda, Cross and (regularised) Bingham and
//! Herschel–Bulkley channels, exactly for the law as the solver uses it (its cut at η0 and
//! Papanastasiou's regularisation included).

use super::roots::{brent, solve_increasing};
use crate::engine::math::Sym2;
use crate::engine::rheology::{Fluid, Model};

/// The conformation tensor in steady simple shear at Wi_γ = λγ̇ (γ̇ ≥ 0).
pub fn steady_shear_conformation(model: &Model, wi: f64) -> Result<Sym2, String> {
    if wi == 0.0 {
        return Ok(model.rest_conformation());
    }
    let from_coefficients = |alpha: f64, beta: f64| {
        let a_yy = 1.0 / beta;
        let a_xy = wi / (alpha * beta * beta);
        let a_xx = (1.0 + 2.0 * wi * a_xy / alpha) / beta;
        Sym2::new(a_xx, a_xy, a_yy)
    };
    let w2 = wi * wi;
    Ok(match model {
        Model::Newtonian => Sym2::IDENTITY,
        Model::OldroydB | Model::Ucm => from_coefficients(1.0, 1.0),
        Model::FeneP(m) => {
            let l2 = m.l2;
            let b0 = (l2 + 2.0) / l2;
            let b = solve_increasing(
                |b| l2 * b * b * b - (l2 + 2.0) * b * b - 2.0 * w2,
                b0,
                b0 + 1.0,
                0.0,
            )?;
            from_coefficients(1.0, b)
        }
        Model::FeneCr(m) => {
            let k = 1.0 - 2.0 / m.l2;
            let c = (1.0 + (1.0 + 8.0 * k * w2 / m.l2).sqrt()) / (2.0 * k);
            from_coefficients(c, 1.0)
        }
        Model::LinearPtt(m) => {
            let e = m.epsilon;
            let a = solve_increasing(|a| a * a * a - a * a - 2.0 * e * w2, 1.0, 2.0, 0.0)?;
            from_coefficients(a, 1.0)
        }
        Model::ExponentialPtt(m) => {
            let e = m.epsilon;
            let a = solve_increasing(|a| a.ln() - 2.0 * e * w2 / (a * a), 1.0, 2.0, 0.0)?;
            from_coefficients(a, 1.0)
        }
        Model::Giesekus(g) if g.alpha == 0.0 => from_coefficients(1.0, 1.0),
        Model::Giesekus(g) => giesekus_shear(g.alpha, wi)?,
        // A model added later has no exact steady solution until one is written here.
        #[allow(unreachable_patterns)]
        _ => {
            return Err(format!(
                "no exact steady shear solution for {}",
                model.name()
            ))
        }
    })
}

/// Giesekus in steady shear, by the scalar equation in s = 1 − A_yy (module docs).
fn giesekus_shear(alpha: f64, wi: f64) -> Result<Sym2, String> {
    let parts = |s: f64| {
        let a_xy = (s * (1.0 - alpha * s) / alpha).sqrt();
        let a_yy = 1.0 - s;
        let a_xx = (wi * a_yy / a_xy - (1.0 - 2.0 * alpha)) / alpha - a_yy;
        (a_xx, a_xy, a_yy)
    };
    let residual = |s: f64| {
        let (a_xx, a_xy, _) = parts(s);
        alpha * (a_xx * a_xx + a_xy * a_xy) + (1.0 - 2.0 * alpha) * a_xx
            - (1.0 - alpha)
            - 2.0 * wi * a_xy
    };
    // The residual → +∞ as s → 0 and equals −2Wi·A_xy < 0 at s = 1; the root is ≈ αWi² for
    // small Wi, so start the bracket six decades below that.
    let small = alpha * wi * wi / (1.0 + alpha * wi * wi);
    let s = brent(residual, 1e-6 * small, 1.0, 0.0)?;
    let (a_xx, a_xy, a_yy) = parts(s);
    Ok(Sym2::new(a_xx, a_xy, a_yy))
}

/// Polymer stress τ_p in steady shear at shear rate γ̇ (sign follows γ̇).
pub fn steady_shear_stress(fluid: &Fluid, shear_rate: f64) -> Result<Sym2, String> {
    if !fluid.model.is_viscoelastic() {
        return Ok(Sym2::ZERO);
    }
    let wi = fluid.relaxation_time * shear_rate.abs();
    let a = steady_shear_conformation(&fluid.model, wi)?;
    let tau = fluid.polymer_stress(&a);
    Ok(Sym2::new(tau.xx, tau.xy.copysign(shear_rate), tau.yy))
}

/// The steady channel solution of one fluid.
#[derive(Clone, Debug)]
pub struct SteadyChannel {
    fluid: Fluid,
    /// ρ g_x.
    drive: f64,
    height: f64,
    /// Grid over the lower half [0, H/2]: heights, shear rates, velocities.
    y: Vec<f64>,
    shear: Vec<f64>,
    u: Vec<f64>,
}

/// Intervals of the half-channel grid.
const INTERVALS: usize = 1000;

impl SteadyChannel {
    /// Solves the channel driven by body force `g` (along x) between walls `height` apart.
    pub fn new(fluid: &Fluid, g: f64, height: f64) -> Result<Self, String> {
        let mut s = Self {
            fluid: *fluid,
            drive: fluid.density * g,
            height,
            y: Vec::with_capacity(INTERVALS + 1),
            shear: Vec::with_capacity(INTERVALS + 1),
            u: Vec::with_capacity(INTERVALS + 1),
        };
        let half = 0.5 * height;
        let dy = half / INTERVALS as f64;
        // 4-point Gauss–Legendre nodes and weights on [−1, 1].
        let nodes = [
            -0.861_136_311_594_053,
            -0.339_981_043_584_856,
            0.339_981_043_584_856,
            0.861_136_311_594_053,
        ];
        let weights = [
            0.347_854_845_137_454,
            0.652_145_154_862_546,
            0.652_145_154_862_546,
            0.347_854_845_137_454,
        ];
        let mut u = 0.0;
        for k in 0..=INTERVALS {
            let y = k as f64 * dy;
            if k > 0 {
                let mid = y - 0.5 * dy;
                for (x, w) in nodes.iter().zip(&weights) {
                    u += 0.5 * dy * w * s.shear_rate(mid + 0.5 * dy * x)?;
                }
            }
            s.y.push(y);
            s.shear.push(s.shear_rate(y)?);
            s.u.push(u);
        }
        Ok(s)
    }

    /// Total shear stress ρg(H/2 − y).
    pub fn total_shear_stress(&self, y: f64) -> f64 {
        self.drive * (0.5 * self.height - y)
    }

    /// γ̇(y) from η_s γ̇ + τ_p,xy(γ̇) = ρg(H/2 − y), solved at y.
    pub fn shear_rate(&self, y: f64) -> Result<f64, String> {
        let tau = self.total_shear_stress(y);
        if tau == 0.0 {
            return Ok(0.0);
        }
        let target = tau.abs();
        let eta_s = self.fluid.solvent_viscosity();
        let law = self.fluid.law;
        let excess = |g: f64| -> f64 {
            let polymer = steady_shear_stress(&self.fluid, g)
                .map(|t| t.xy)
                .unwrap_or(f64::NAN);
            law.shear_stress(eta_s, g) + polymer - target
        };
        // Upper bracket: τ/η0 is the Newtonian shear rate, exceeded by any shear-thinning
        // model; with a constant solvent viscosity, τ/η_s bounds it. Without one, or with a
        // generalised Newtonian law (η ≤ η0), expand.
        let start = target / self.fluid.viscosity;
        let g = if eta_s > 0.0 && law.is_constant() {
            brent(excess, 0.0, (target / eta_s).max(start), 0.0)?
        } else {
            solve_increasing(excess, 0.0, start, 0.0).map_err(|e| {
                format!("no steady solution: the wall stress exceeds the model's largest shear stress ({e})")
            })?
        };
        Ok(g.copysign(tau))
    }

    /// Polymer stress at height y.
    pub fn polymer_stress(&self, y: f64) -> Result<Sym2, String> {
        steady_shear_stress(&self.fluid, self.shear_rate(y)?)
    }

    /// Steady velocity u(y), by Hermite interpolation of the quadrature grid (mirrored about
    /// the centre-line).
    pub fn velocity(&self, y: f64) -> f64 {
        let half = 0.5 * self.height;
        let y = y.clamp(0.0, self.height);
        let y = if y > half { self.height - y } else { y };
        let dy = self.y[1] - self.y[0];
        let k = ((y / dy).floor() as usize).min(INTERVALS - 1);
        let t = (y - self.y[k]) / dy;
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * t) * (1.0 - t) * (1.0 - t),
            t * (1.0 - t) * (1.0 - t),
            t * t * (3.0 - 2.0 * t),
            t * t * (t - 1.0),
        );
        h00 * self.u[k]
            + h10 * dy * self.shear[k]
            + h01 * self.u[k + 1]
            + h11 * dy * self.shear[k + 1]
    }

    pub fn centre_velocity(&self) -> f64 {
        self.u[INTERVALS]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Mat2;
    use crate::engine::rheology::{ExponentialPtt, FeneCr, FeneP, Giesekus, LinearPtt};

    /// Re = Wi = 1 in the channel below (ρ = η0 = H = 1, g = 8, U = 1); Giesekus at the
    /// paper's Wi = 0.25 (without solvent its shear stress saturates at
    /// (η_p/λ)√((1 − α)/α), below the wall stress 4 when λ = 1).
    fn fluid(model: Model, beta: f64) -> Fluid {
        Fluid {
            model,
            density: 1.0,
            viscosity: 1.0,
            beta,
            relaxation_time: if matches!(model, Model::Giesekus(_)) {
                0.25
            } else {
                1.0
            },
            surface_tension: 0.0,
            law: crate::engine::rheology::ViscosityLaw::Constant,
        }
    }

    fn models() -> Vec<(Model, f64)> {
        vec![
            (Model::OldroydB, 0.1),
            (Model::FeneP(FeneP { l2: 100.0 }), 0.1),
            (Model::FeneP(FeneP { l2: 10.0 }), 0.1),
            (Model::FeneCr(FeneCr { l2: 10.0 }), 0.1),
            (Model::LinearPtt(LinearPtt { epsilon: 0.25 }), 0.1),
            (Model::ExponentialPtt(ExponentialPtt { epsilon: 0.25 }), 0.1),
            (Model::Giesekus(Giesekus { alpha: 0.1 }), 0.0),
            (Model::Giesekus(Giesekus { alpha: 0.3 }), 0.0),
            (Model::Giesekus(Giesekus { alpha: 0.45 }), 0.0),
            (Model::Giesekus(Giesekus { alpha: 0.5 }), 0.1),
        ]
    }

    /// The steady-shear conformation satisfies the constitutive equation
    /// ∇u·A + A·∇uᵀ = f_R(A)/λ to 1e-10 (relative), over four decades of Wi.
    #[test]
    fn steady_shear_satisfies_the_constitutive_equation() {
        for (model, _) in models() {
            for wi in [1e-2, 0.3, 1.0, 7.0, 50.0] {
                let a = steady_shear_conformation(&model, wi).unwrap();
                let grad = Mat2::new(0.0, wi, 0.0, 0.0);
                let s = grad * a.to_mat();
                let stretch = Sym2::sym_part(&(s + s.transpose()));
                let r = stretch - model.relaxation(&a);
                let scale = 1.0 + a.contract(&a).sqrt();
                assert!(
                    r.contract(&r).sqrt() < 1e-10 * scale,
                    "{} at Wi {wi}: {r:?}",
                    model.name()
                );
                assert!(a.det() > 0.0 && a.trace() > 0.0, "A not SPD");
            }
        }
    }

    /// Every channel solution satisfies the momentum balance η_s γ̇ + τ_p,xy = ρg(H/2 − y)
    /// to 1e-10 at sampled heights, has no slip at the walls and is symmetric.
    #[test]
    fn steady_channels_satisfy_the_momentum_balance() {
        for (model, beta) in models() {
            let f = fluid(model, beta);
            let ch = SteadyChannel::new(&f, 8.0, 1.0).unwrap();
            for y in [0.0, 0.013, 0.2, 0.37, 0.5, 0.81, 0.999] {
                let g = ch.shear_rate(y).unwrap();
                let tau = ch.polymer_stress(y).unwrap();
                let balance = f.solvent_viscosity() * g + tau.xy - ch.total_shear_stress(y);
                assert!(
                    balance.abs() < 1e-10 * (1.0 + ch.total_shear_stress(y).abs()),
                    "{} y={y}",
                    model.name()
                );
            }
            assert!(ch.velocity(0.0).abs() < 1e-14 && ch.velocity(1.0).abs() < 1e-14);
            assert!((ch.velocity(0.3) - ch.velocity(0.7)).abs() < 1e-12);
        }
    }

    /// Oldroyd-B (and FENE-CR, whose shear viscosity is constant) give the parabola 4y(1 − y)
    /// to quadrature accuracy; the Oldroyd-B normal stress is 2Wi(1 − β)(∂u/∂y)².
    #[test]
    fn constant_viscosity_models_give_the_parabola() {
        for model in [Model::OldroydB, Model::FeneCr(FeneCr { l2: 10.0 })] {
            let ch = SteadyChannel::new(&fluid(model, 0.1), 8.0, 1.0).unwrap();
            for y in [0.05, 0.25, 0.5, 0.9] {
                assert!(
                    (ch.velocity(y) - 4.0 * y * (1.0 - y)).abs() < 1e-12,
                    "{}",
                    model.name()
                );
            }
        }
        let ch = SteadyChannel::new(&fluid(Model::OldroydB, 0.1), 8.0, 1.0).unwrap();
        let y = 0.2;
        let rate = 4.0 * (1.0 - 2.0 * y);
        assert!((ch.polymer_stress(y).unwrap().xx - 2.0 * 0.9 * rate * rate).abs() < 1e-10);
    }

    /// Shear thinning raises the centre-line velocity above the Oldroyd-B value, more for
    /// smaller L² and larger ε (King & Lind Fig. 7).
    #[test]
    fn shear_thinning_models_flow_faster() {
        let uc = |m: Model| {
            SteadyChannel::new(&fluid(m, 0.1), 8.0, 1.0)
                .unwrap()
                .centre_velocity()
        };
        let ob = uc(Model::OldroydB);
        let p100 = uc(Model::FeneP(FeneP { l2: 100.0 }));
        let p10 = uc(Model::FeneP(FeneP { l2: 10.0 }));
        assert!((ob - 1.0).abs() < 1e-12);
        assert!(ob < p100 && p100 < p10, "{ob} {p100} {p10}");
        assert!(
            uc(Model::LinearPtt(LinearPtt { epsilon: 0.25 }))
                > uc(Model::LinearPtt(LinearPtt { epsilon: 0.05 }))
        );
    }

    /// Without solvent, Giesekus at α = ½ has a bounded shear stress: a wall stress above it
    /// has no steady solution, reported as an error (not a panic or NaN profile).
    #[test]
    fn giesekus_half_without_solvent_reports_missing_steady_state() {
        let mut f = fluid(Model::Giesekus(Giesekus { alpha: 0.5 }), 0.0);
        f.relaxation_time = 4.0;
        assert!(SteadyChannel::new(&f, 8.0, 1.0).is_err());
    }
}
