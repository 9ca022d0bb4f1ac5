//! Start-up plane Couette flow of a Newtonian, Oldroyd-B or UCM fluid between walls at y = 0
//! and y = H moving at u_b and u_t from rest (t = 0), derived as Waters & King (1970) derive
//! start-up Poiseuille flow.
//!
//! In simple shear the Oldroyd-B shear stress obeys the linear equation
//! λ ∂τ/∂t + τ = η_p ∂u/∂y exactly (τ_yy stays 0 from rest), so with
//!
//! ```text
//!     u = u_b + Δ y/H + Σ_n a_n(t) sin(k_n y),   τ = τ_0(t) + Σ_n c_n(t) cos(k_n y),
//!     Δ = u_t − u_b,  k_n = nπ/H,
//! ```
//!
//! momentum ρ ∂u/∂t = η_s ∂²u/∂y² + ∂τ/∂y separates into one linear 2×2 system per mode,
//!
//! ```text
//!     ρ a_n' = −η_s k_n² a_n − k_n c_n,     λ c_n' = −c_n + η_p k_n a_n,
//! ```
//!
//! with a_n(0) = −(2/nπ)[u_b(1 − (−1)ⁿ) + Δ(−1)ⁿ⁺¹] (the fluid at rest) and c_n(0) = 0;
//! τ_0 = η_p (Δ/H)(1 − e^{−t/λ}). Each mode is advanced by the closed-form exponential of
//! its 2×2 matrix (real or complex eigenvalues: over- or under-damped elastic modes).
//! Newtonian: η_s = η0 and no stress. The normal stress follows from
//! λ ∂τ_xx/∂t + τ_xx = 2λ τ_xy ∂u/∂y, which this module does not integrate.

use std::f64::consts::PI;

/// Modes summed: the coefficients fall like 1/n and, with solvent, like e^{−νk²t}.
const MODES: usize = 2000;

/// The start-up Couette solution in dimensional units.
#[derive(Clone, Debug)]
pub struct StartupCouette {
    pub density: f64,
    /// Solvent and polymer viscosities (η_p = 0: Newtonian).
    pub solvent_viscosity: f64,
    pub polymer_viscosity: f64,
    pub relaxation_time: f64,
    pub height: f64,
    /// Wall velocities (x-components) at y = 0 and y = H.
    pub wall_velocity: [f64; 2],
}

impl StartupCouette {
    fn wavenumber(&self, n: usize) -> f64 {
        n as f64 * PI / self.height
    }

    /// (a_n, c_n) at time t.
    fn mode(&self, n: usize, t: f64) -> (f64, f64) {
        let [ub, ut] = self.wall_velocity;
        let delta = ut - ub;
        let sign = if n.is_multiple_of(2) { 1.0 } else { -1.0 }; // (−1)ⁿ
        let a0 = -2.0 / (n as f64 * PI) * (ub * (1.0 - sign) - delta * sign);
        let k = self.wavenumber(n);
        let rho = self.density;
        if self.polymer_viscosity == 0.0 || self.relaxation_time == 0.0 {
            let nu = self.solvent_viscosity / rho;
            return (a0 * (-nu * k * k * t).exp(), 0.0);
        }
        let lambda = self.relaxation_time;
        // M = [[m11, m12], [m21, m22]] acting on (a, c).
        let (m11, m12) = (-self.solvent_viscosity * k * k / rho, -k / rho);
        let (m21, m22) = (self.polymer_viscosity * k / lambda, -1.0 / lambda);
        let mu = 0.5 * (m11 + m22);
        let det = m11 * m22 - m12 * m21;
        let disc = mu * mu - det;
        // exp(Mt) = c₀ I + c₁ (M − μI), overflow-safe for large δt.
        let (c0, c1) = if disc > 0.0 {
            let d = disc.sqrt();
            let (plus, minus) = (((mu + d) * t).exp(), ((mu - d) * t).exp());
            (0.5 * (plus + minus), 0.5 * (plus - minus) / d)
        } else if disc < 0.0 {
            let w = (-disc).sqrt();
            let e = (mu * t).exp();
            (e * (w * t).cos(), e * (w * t).sin() / w)
        } else {
            let e = (mu * t).exp();
            (e, e * t)
        };
        // Applied to (a0, 0).
        (c0 * a0 + c1 * (m11 - mu) * a0, c1 * m21 * a0)
    }

    /// u(y, t).
    pub fn velocity(&self, y: f64, t: f64) -> f64 {
        let mut u = Vec::with_capacity(1);
        self.velocity_profile(&[y], t, &mut u);
        u[0]
    }

    /// The polymer shear stress τ_p,xy(y, t) (0 for a Newtonian fluid).
    pub fn shear_stress(&self, y: f64, t: f64) -> f64 {
        if self.polymer_viscosity == 0.0 || self.relaxation_time == 0.0 || t <= 0.0 {
            return 0.0;
        }
        let [ub, ut] = self.wall_velocity;
        let tau0 = self.polymer_viscosity * (ut - ub) / self.height
            * (1.0 - (-t / self.relaxation_time).exp());
        tau0 + (1..=MODES)
            .map(|n| self.mode(n, t).1 * (self.wavenumber(n) * y).cos())
            .sum::<f64>()
    }

    /// u at every height of `ys`: the modes are computed once.
    pub fn velocity_profile(&self, ys: &[f64], t: f64, out: &mut Vec<f64>) {
        let [ub, ut] = self.wall_velocity;
        out.clear();
        out.extend(ys.iter().map(|y| ub + (ut - ub) * y / self.height));
        if t <= 0.0 {
            for (o, &y) in out.iter_mut().zip(ys) {
                if y > 0.0 && y < self.height {
                    *o = 0.0;
                }
            }
            return;
        }
        for n in 1..=MODES {
            let (a, _) = self.mode(n, t);
            if a == 0.0 {
                continue;
            }
            let k = self.wavenumber(n);
            for (o, &y) in out.iter_mut().zip(ys) {
                *o += a * (k * y).sin();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn couette(eta_s: f64, eta_p: f64, lambda: f64) -> StartupCouette {
        StartupCouette {
            density: 1.0,
            solvent_viscosity: eta_s,
            polymer_viscosity: eta_p,
            relaxation_time: lambda,
            height: 1.0,
            wall_velocity: [0.0, 1.0],
        }
    }

    /// Long after the start the profile is the linear one, and the stress η_p Δ/H: to 1e-9
    /// (the transient decays at least like e^{−t/2λ}, here e^{−25}).
    #[test]
    fn tends_to_the_steady_linear_profile() {
        for c in [couette(1.0, 0.0, 0.0), couette(0.1, 0.9, 1.0)] {
            for y in [0.1, 0.5, 0.9] {
                assert!((c.velocity(y, 50.0) - y).abs() < 1e-9, "{c:?} at {y}");
            }
            let tau = c.shear_stress(0.3, 50.0);
            assert!((tau - c.polymer_viscosity).abs() < 1e-9, "tau {tau}");
        }
    }

    /// The Newtonian modes against the classical series (Stokes' first problem in a gap):
    /// u = y − (2/π) Σ (−1)^{n+1}/n e^{−n²π²t} sin(nπy), here with the first term of the
    /// numerical sum checked against the explicit formula at t = 0.05 to 1e-12.
    #[test]
    fn newtonian_matches_the_classical_series() {
        let c = couette(1.0, 0.0, 0.0);
        let t = 0.05;
        let exact = |y: f64| {
            y - (1..=200)
                .map(|n| {
                    let n = n as f64;
                    let s = if (n as usize) % 2 == 1 { 1.0 } else { -1.0 };
                    2.0 / PI * s / n * (-n * n * PI * PI * t).exp() * (n * PI * y).sin()
                })
                .sum::<f64>()
        };
        for y in [0.2, 0.5, 0.7] {
            assert!((c.velocity(y, t) - exact(y)).abs() < 1e-12);
        }
    }

    /// The modes satisfy their ODEs: a centred difference of (a, c) in time against the
    /// right-hand sides, to 1e-6 relative (the difference's O(δt²) error at δt = 1e-5), for
    /// an under-damped (UCM-like, β = 0.01) and an over-damped mode.
    #[test]
    fn modes_solve_their_equations() {
        let c = couette(0.01, 0.99, 2.0);
        for n in [1, 7] {
            let (t, dt) = (0.3, 1e-5);
            let (a, s) = c.mode(n, t);
            let (ap, sp) = c.mode(n, t + dt);
            let (am, sm) = c.mode(n, t - dt);
            let k = c.wavenumber(n);
            let da = -0.01 * k * k * a - k * s;
            let ds = (-s + 0.99 * k * a) / 2.0;
            let scale = da.abs().max(ds.abs()).max(1e-3);
            assert!(
                ((ap - am) / (2.0 * dt) - da).abs() < 1e-6 * scale,
                "n {n}: a'"
            );
            assert!(
                ((sp - sm) / (2.0 * dt) - ds).abs() < 1e-6 * scale,
                "n {n}: c'"
            );
        }
    }
}
