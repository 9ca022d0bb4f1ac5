//! Start-up of planar Poiseuille flow from rest for Oldroyd-B, UCM (β = 0) and Newtonian
//! (Wi = 0) fluids: the series solution of Waters & King (1970).
//!
//! Non-dimensional form: walls at y = 0 and 1 (lengths in H), velocity in
//! U = ρgH²/(8η0) (the steady centre-line velocity), time in H/U, stress in η0U/H;
//! Re = ρUH/η0, Wi = λU/H, El = Wi/Re, N_n = (2n − 1)π. The equations
//!
//! ```text
//!     Re ∂u/∂t = 8 + β ∂²u/∂y² + ∂τ/∂y,      Wi ∂τ/∂t + τ = (1 − β) ∂u/∂y,
//! ```
//!
//! with u = τ = 0 at t = 0 give, mode by mode,
//!
//! ```text
//!     u(y,t)    = 4y(1 − y)        − 32 Σ sin(N_n y)/N_n³ G_n(t)
//!     τ_xy(y,t) = 4(1 − β)(1 − 2y) − 32 Σ cos(N_n y)/N_n² H_n(t)
//!     G_n = e^{−at/2Wi} [cosh(bt/2Wi) + (a − 2El N²)/b · sinh(bt/2Wi)]
//!     H_n = (1 − β) e^{−at/2Wi} [cosh(bt/2Wi) + a/b · sinh(bt/2Wi)]
//!     a = 1 + β El N²,  b = √(a² − 4El N²)
//! ```
//!
//! (H_n solves the same second-order equation with H(0) = 1 − β, H'(0) = 0.) For imaginary b
//! the hyperbolic functions become trigonometric. Each product is evaluated overflow-free:
//! for large real b the growing exponent is combined with the decaying one through
//! `b − a = −4El N²/(a + b)`. For the Newtonian limit G_n = exp(−N² t/Re).
//!
//! τ_xx follows from `Wi(∂τxx/∂t − 2 τ_xy ∂u/∂y) + τxx = 0`, integrated in time with an
//! exponential integrator (steady limit 2Wi(1 − β)(∂u/∂y)²).

use rayon::prelude::*;
use std::f64::consts::PI;

/// Start-up Poiseuille flow of one fluid (see module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct StartupPoiseuille {
    re: f64,
    wi: f64,
    beta: f64,
    terms: usize,
}

/// Time-dependent mode amplitudes at one instant, pre-multiplied by their series factors:
/// `u_coeff[n] = 32 G_n/N³`, `tau_coeff[n] = 32 H_n/N²`. Trailing modes whose summed
/// magnitudes fall below [`TAIL_TOLERANCE`] are dropped: once the short-lived high modes have
/// decayed (t ≫ βWi) a handful of terms suffice.
#[derive(Clone, Debug, Default)]
pub struct Modes {
    pub u_coeff: Vec<f64>,
    pub tau_coeff: Vec<f64>,
}

/// Largest number of series terms used by default (UCM at its shear-wave cusps).
pub const MAX_TERMS: usize = 20_000;
/// Default bound on the velocity series truncation error.
const VELOCITY_TOLERANCE: f64 = 1e-6;
/// Series terms used in the forcing of the τ_xx integration.
pub const NORMAL_STRESS_TERMS: usize = 2000;
/// Modes are dropped from the end while the sum of their |coefficients| (a rigorous bound on
/// their contribution, |sin|, |cos| ≤ 1) stays below this.
pub const TAIL_TOLERANCE: f64 = 1e-10;

impl StartupPoiseuille {
    /// `wi = 0` is the Newtonian fluid (β is then irrelevant and taken as 1).
    pub fn new(re: f64, wi: f64, beta: f64) -> Self {
        let beta = if wi == 0.0 { 1.0 } else { beta };
        let mut s = Self {
            re,
            wi,
            beta,
            terms: 0,
        };
        s.terms = s.default_terms();
        s
    }

    /// Overrides the number of series terms.
    pub fn with_terms(mut self, terms: usize) -> Self {
        self.terms = terms.max(1);
        self
    }

    pub fn terms(&self) -> usize {
        self.terms
    }

    /// Terms for a velocity truncation error below [`VELOCITY_TOLERANCE`]: for β > 0 the
    /// amplitudes |G_n| approach (1 − β)/β, so the tail is ≈ 32A/(8π³M²). For β = 0 the
    /// amplitudes grow like N (shear waves) and the tail decays only like 1/M: use the cap.
    fn default_terms(&self) -> usize {
        if self.wi > 0.0 && self.beta == 0.0 {
            return MAX_TERMS;
        }
        let amplitude = if self.wi > 0.0 {
            ((1.0 - self.beta) / self.beta).max(1.0)
        } else {
            1.0
        };
        let m = (32.0 * amplitude / (8.0 * PI.powi(3) * VELOCITY_TOLERANCE)).sqrt();
        (m.ceil() as usize).clamp(16, MAX_TERMS)
    }

    /// Mode amplitudes at time t, into reused buffers.
    pub fn modes_into(&self, t: f64, modes: &mut Modes) {
        modes.u_coeff.resize(self.terms, 0.0);
        modes.tau_coeff.resize(self.terms, 0.0);
        for n in 0..self.terms {
            let big_n = (2 * n + 1) as f64 * PI;
            let (g, h) = self.mode(big_n, t);
            modes.u_coeff[n] = 32.0 * g / big_n.powi(3);
            modes.tau_coeff[n] = 32.0 * h / (big_n * big_n);
        }
        let mut tail = 0.0;
        let mut keep = self.terms;
        while keep > 1 {
            // Both series: the τ coefficients carry one power of N less, so bound them too
            // (the shear rate uses N·u_coeff, the same magnitude).
            let c = modes.u_coeff[keep - 1]
                .abs()
                .max(modes.tau_coeff[keep - 1].abs());
            if tail + c > TAIL_TOLERANCE {
                break;
            }
            tail += c;
            keep -= 1;
        }
        modes.u_coeff.truncate(keep);
        modes.tau_coeff.truncate(keep);
    }

    pub fn modes(&self, t: f64) -> Modes {
        let mut m = Modes::default();
        self.modes_into(t, &mut m);
        m
    }

    /// (G_n(t), H_n(t)) for wavenumber N.
    fn mode(&self, big_n: f64, t: f64) -> (f64, f64) {
        mode_amplitudes(self.re, self.wi, self.beta, big_n, t)
    }

    /// u(y, t).
    pub fn velocity(&self, y: f64, t: f64) -> f64 {
        let m = self.modes(t);
        velocity_from_modes(&m, y)
    }

    /// τ_p,xy(y, t).
    pub fn shear_stress(&self, y: f64, t: f64) -> f64 {
        let m = self.modes(t);
        self.shear_stress_from_modes(&m, y)
    }

    fn shear_stress_from_modes(&self, m: &Modes, y: f64) -> f64 {
        let (_, cos_sum) = sums(&m.tau_coeff, y);
        if self.wi == 0.0 {
            return 0.0;
        }
        4.0 * (1.0 - self.beta) * (1.0 - 2.0 * y) - cos_sum
    }

    /// Shear rate ∂u/∂y(y, t), from the differentiated velocity series.
    fn shear_rate_from_modes(&self, m: &Modes, y: f64) -> f64 {
        // d/dy sin(Ny)/N³ = cos(Ny)/N²: reuse the u coefficients times N.
        let mut sum = 0.0;
        let (c, s) = ((PI * y).cos(), (PI * y).sin());
        let (c2, s2) = ((2.0 * PI * y).cos(), (2.0 * PI * y).sin());
        let (mut cn, mut sn) = (c, s);
        for (n, coeff) in m.u_coeff.iter().enumerate() {
            let big_n = (2 * n + 1) as f64 * PI;
            sum += coeff * big_n * cn;
            (cn, sn) = (cn * c2 - sn * s2, sn * c2 + cn * s2);
        }
        4.0 * (1.0 - 2.0 * y) - sum
    }

    /// Velocity at many heights (parallel), with reused mode buffers.
    pub fn velocity_profile(&self, ys: &[f64], t: f64, modes: &mut Modes, out: &mut [f64]) {
        self.modes_into(t, modes);
        let m = &*modes;
        out.par_iter_mut()
            .zip(ys.par_iter())
            .for_each(|(u, &y)| *u = velocity_from_modes(m, y));
    }

    /// Polymer shear stress at many heights.
    pub fn shear_stress_profile(&self, ys: &[f64], t: f64) -> Vec<f64> {
        let m = self.modes(t);
        ys.par_iter()
            .map(|&y| self.shear_stress_from_modes(&m, y))
            .collect()
    }

    /// Polymer normal stress τ_xx at many heights at time t: the exponential integrator with
    /// `steps` sub-steps, exact for a forcing 2τ_xy∂u/∂y linear within each sub-step.
    pub fn normal_stress_profile(&self, ys: &[f64], t: f64, steps: usize) -> Vec<f64> {
        let mut tau_xx = vec![0.0; ys.len()];
        if self.wi == 0.0 || t <= 0.0 {
            return tau_xx;
        }
        let dt = t / steps as f64;
        let step = ExponentialStep::new(dt, self.wi);
        // The forcing's series is truncated at NORMAL_STRESS_TERMS: τ_xx is an integral in time
        // that smooths the truncation error of the shear-wave cusps (UCM), while evaluating
        // the full 20 000 terms at every sub-step would cost minutes.
        let truncated = self.clone().with_terms(self.terms.min(NORMAL_STRESS_TERMS));
        let forcing = |time: f64| -> Vec<f64> {
            let m = truncated.modes(time);
            ys.par_iter()
                .map(|&y| {
                    2.0 * self.shear_stress_from_modes(&m, y) * self.shear_rate_from_modes(&m, y)
                })
                .collect()
        };
        let mut f0 = forcing(0.0);
        for k in 1..=steps {
            let f1 = forcing(k as f64 * dt);
            for (i, txx) in tau_xx.iter_mut().enumerate() {
                *txx = step.advance(*txx, f0[i], f1[i]);
            }
            f0 = f1;
        }
        tau_xx
    }

    /// Sub-steps for [`Self::normal_stress_profile`] at time t: one per Wi/700, from 200 to
    /// 2 000. The integrator is second order (the forcing linear within a sub-step); against
    /// 2 000 sub-steps at Re = Wi = 1, β = 0.1, the largest difference over the channel is
    /// 5.8·10⁻⁶ of max τ_xx at t = 0.3 (200 sub-steps) and below 2·10⁻⁶ at t = 1 (700), far below
    /// any SPH error it is compared with; a short run no longer spends 5 % of its wall time
    /// on 2 000 sub-steps of its reference.
    pub fn normal_stress_substeps(&self, t: f64) -> usize {
        const PER_WI: f64 = 700.0;
        let steps = if self.wi > 0.0 {
            (t / self.wi * PER_WI).ceil()
        } else {
            0.0
        };
        (steps as usize).clamp(200, 2000)
    }

    /// Steady velocity 4y(1 − y).
    pub fn steady_velocity(y: f64) -> f64 {
        4.0 * y * (1.0 - y)
    }

    /// Steady polymer shear stress 4(1 − β)(1 − 2y).
    pub fn steady_shear_stress(&self, y: f64) -> f64 {
        if self.wi == 0.0 {
            return 0.0;
        }
        4.0 * (1.0 - self.beta) * (1.0 - 2.0 * y)
    }

    /// Steady polymer normal stress 2Wi(1 − β)[4(1 − 2y)]².
    pub fn steady_normal_stress(&self, y: f64) -> f64 {
        2.0 * self.wi * (1.0 - self.beta) * (4.0 * (1.0 - 2.0 * y)).powi(2)
    }
}

/// u from precomputed modes.
pub fn velocity_from_modes(m: &Modes, y: f64) -> f64 {
    let (sin_sum, _) = sums(&m.u_coeff, y);
    StartupPoiseuille::steady_velocity(y) - sin_sum
}

/// (Σ c_n sin(N_n y), Σ c_n cos(N_n y)) with N_n = (2n + 1)π (n from 0), by the rotation
/// recurrence e^{iN_{n+1}y} = e^{iN_n y} e^{2iπy}.
fn sums(coeff: &[f64], y: f64) -> (f64, f64) {
    let (c2, s2) = ((2.0 * PI * y).cos(), (2.0 * PI * y).sin());
    let (mut cn, mut sn) = ((PI * y).cos(), (PI * y).sin());
    let (mut sin_sum, mut cos_sum) = (0.0, 0.0);
    for c in coeff {
        sin_sum += c * sn;
        cos_sum += c * cn;
        (cn, sn) = (cn * c2 - sn * s2, sn * c2 + cn * s2);
    }
    (sin_sum, cos_sum)
}

/// (G(t), H(t)) of the module docs for wavenumber N: the mode amplitudes of the velocity
/// and polymer shear stress deviations. Shared with the pipe series (`pipe`), whose modes
/// solve the same equations with N replaced by the zeros α_n of J0.
pub(super) fn mode_amplitudes(re: f64, wi: f64, beta: f64, big_n: f64, t: f64) -> (f64, f64) {
    if wi == 0.0 {
        return ((-big_n * big_n * t / re).exp(), 0.0);
    }
    let el = wi / re;
    let n2 = big_n * big_n;
    let a = 1.0 + beta * el * n2;
    let s = t / (2.0 * wi);
    let g = damped_combination(a, el * n2, a - 2.0 * el * n2, s);
    let h = (1.0 - beta) * damped_combination(a, el * n2, a, s);
    (g, h)
}

/// One sub-step of the exponential integrator of `Wi ∂τ/∂t + τ = Wi f`: exact for a forcing
/// f linear within the sub-step, `τ(dt) = e^{−dt/Wi} τ(0) + w0 f(0) + w1 f(dt)`.
pub(super) struct ExponentialStep {
    decay: f64,
    w0: f64,
    w1: f64,
}

impl ExponentialStep {
    pub(super) fn new(dt: f64, wi: f64) -> Self {
        let decay = (-dt / wi).exp();
        // ∫_0^dt e^{−(dt−s)/Wi} (f0 + (f1 − f0)s/dt) ds = w0 f0 + w1 f1.
        let q = dt / wi;
        let (w0, w1) = if q > 1e-4 {
            let e = decay;
            (wi * ((1.0 - e) / q - e), wi * (1.0 - (1.0 - e) / q))
        } else {
            (0.5 * dt * (1.0 - 2.0 * q / 3.0), 0.5 * dt * (1.0 - q / 3.0))
        };
        Self { decay, w0, w1 }
    }

    pub(super) fn advance(&self, tau: f64, f0: f64, f1: f64) -> f64 {
        tau * self.decay + self.w0 * f0 + self.w1 * f1
    }
}

/// `e^{−as}[cosh(bs) + c·s·sinh(bs)/(bs)]` with b² = a² − 4k (trigonometric for b² < 0),
/// evaluated without overflow.
fn damped_combination(a: f64, k: f64, c: f64, s: f64) -> f64 {
    let disc = a * a - 4.0 * k;
    if disc >= 0.0 {
        let b = disc.sqrt();
        let z = b * s;
        if z > 1.0 {
            // e^{−as}cosh(bs) = ½(e^{(b−a)s} + e^{−(a+b)s}), b − a = −4k/(a + b).
            let slow = (-4.0 * k / (a + b) * s).exp();
            let fast = (-(a + b) * s).exp();
            0.5 * (slow + fast) + c * (slow - fast) / (2.0 * b)
        } else {
            (-a * s).exp() * (z.cosh() + c * s * sinhc(z))
        }
    } else {
        let zeta = (-disc).sqrt() * s;
        (-a * s).exp() * (zeta.cos() + c * s * sinc(zeta))
    }
}

fn sinhc(z: f64) -> f64 {
    if z.abs() < 1e-4 {
        1.0 + z * z / 6.0
    } else {
        z.sinh() / z
    }
}

fn sinc(z: f64) -> f64 {
    if z.abs() < 1e-4 {
        1.0 - z * z / 6.0
    } else {
        z.sin() / z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Method-of-lines finite differences (u at nodes, τ at mid-points, RK4) of the same
    /// equations: an independent check of the series, second order in Δy.
    fn finite_differences(
        re: f64,
        wi: f64,
        beta: f64,
        t_end: f64,
        cells: usize,
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let dy = 1.0 / cells as f64;
        let dt = 0.2 * (re * dy * dy / beta.max(1e-3)).min(dy * (re * wi / (1.0 - beta)).sqrt());
        let steps = (t_end / dt).ceil() as usize;
        let dt = t_end / steps as f64;
        let mut u = vec![0.0; cells + 1];
        let mut tau = vec![0.0; cells];
        let mut txx = vec![0.0; cells];
        let rhs = |u: &[f64], tau: &[f64], txx: &[f64]| {
            let mut du = vec![0.0; cells + 1];
            for j in 1..cells {
                du[j] = (8.0
                    + beta * (u[j + 1] - 2.0 * u[j] + u[j - 1]) / (dy * dy)
                    + (tau[j] - tau[j - 1]) / dy)
                    / re;
            }
            let mut dtau = vec![0.0; cells];
            let mut dtxx = vec![0.0; cells];
            for j in 0..cells {
                let shear = (u[j + 1] - u[j]) / dy;
                dtau[j] = ((1.0 - beta) * shear - tau[j]) / wi;
                dtxx[j] = 2.0 * tau[j] * shear - txx[j] / wi;
            }
            (du, dtau, dtxx)
        };
        let axpy = |x: &[f64], k: &[f64], h: f64| {
            x.iter().zip(k).map(|(a, b)| a + h * b).collect::<Vec<_>>()
        };
        for _ in 0..steps {
            let (a1, b1, c1) = rhs(&u, &tau, &txx);
            let (a2, b2, c2) = rhs(
                &axpy(&u, &a1, dt / 2.0),
                &axpy(&tau, &b1, dt / 2.0),
                &axpy(&txx, &c1, dt / 2.0),
            );
            let (a3, b3, c3) = rhs(
                &axpy(&u, &a2, dt / 2.0),
                &axpy(&tau, &b2, dt / 2.0),
                &axpy(&txx, &c2, dt / 2.0),
            );
            let (a4, b4, c4) = rhs(
                &axpy(&u, &a3, dt),
                &axpy(&tau, &b3, dt),
                &axpy(&txx, &c3, dt),
            );
            for j in 0..=cells {
                u[j] += dt / 6.0 * (a1[j] + 2.0 * a2[j] + 2.0 * a3[j] + a4[j]);
            }
            for j in 0..cells {
                tau[j] += dt / 6.0 * (b1[j] + 2.0 * b2[j] + 2.0 * b3[j] + b4[j]);
                txx[j] += dt / 6.0 * (c1[j] + 2.0 * c2[j] + 2.0 * c3[j] + c4[j]);
            }
        }
        (u, tau, txx)
    }

    /// Series against the independent finite-difference solution during the transient
    /// (overshoot at t ≈ 1, undershoot at t ≈ 3) for Re = Wi = 1, β = 0.1. The FD error is
    /// O(Δy²) ≈ 1e-4 with 200 cells, which sets the tolerances.
    #[test]
    fn series_matches_finite_differences_during_start_up() {
        let wk = StartupPoiseuille::new(1.0, 1.0, 0.1);
        let cells = 200;
        for &t in &[0.5, 1.2, 3.0] {
            let (u, tau, txx) = finite_differences(1.0, 1.0, 0.1, t, cells);
            let dy = 1.0 / cells as f64;
            let ys_mid: Vec<f64> = (0..cells).map(|j| (j as f64 + 0.5) * dy).collect();
            let txx_series = wk.normal_stress_profile(&ys_mid, t, 4000);
            for j in (10..cells).step_by(19) {
                let y = j as f64 * dy;
                assert!(
                    (wk.velocity(y, t) - u[j]).abs() < 2e-4,
                    "u at y={y}, t={t}: {} vs {}",
                    wk.velocity(y, t),
                    u[j]
                );
                let ym = ys_mid[j];
                assert!(
                    (wk.shear_stress(ym, t) - tau[j]).abs() < 2e-3,
                    "τxy at y={ym}, t={t}"
                );
                let scale = 1.0 + txx[j].abs();
                assert!(
                    (txx_series[j] - txx[j]).abs() < 5e-3 * scale,
                    "τxx at y={ym}, t={t}: {} vs {}",
                    txx_series[j],
                    txx[j]
                );
            }
        }
    }

    /// At t = 0 the series reproduces the fluid at rest; at late times its steady limit.
    #[test]
    fn series_starts_at_rest_and_reaches_its_steady_limit() {
        for (re, wi, beta) in [
            (1.0, 1.0, 0.1),
            (0.01, 1.0, 0.1),
            (1.0, 0.0, 1.0),
            (1.0, 1.0, 0.0),
        ] {
            let wk = StartupPoiseuille::new(re, wi, beta);
            // Truncation at t = 0: the tail of 32 Σ 1/N³ (β > 0) or the 1/M tail (UCM).
            let rest_tol = if beta == 0.0 { 1e-4 } else { 2e-6 };
            for &y in &[0.1, 0.3, 0.5, 0.77] {
                assert!(
                    wk.velocity(y, 0.0).abs() < rest_tol,
                    "u(y, 0) for {re},{wi},{beta}"
                );
                let late = 200.0 * wi.max(1.0) * re.max(1.0);
                let u = wk.velocity(y, late);
                assert!(
                    (u - StartupPoiseuille::steady_velocity(y)).abs() < 1e-6,
                    "steady u for {re},{wi},{beta}"
                );
                let tau = wk.shear_stress(y, late);
                assert!(
                    (tau - wk.steady_shear_stress(y)).abs() < 1e-3,
                    "steady τ for {re},{wi},{beta}"
                );
            }
            if wi > 0.0 {
                let ys = [0.1, 0.3];
                let txx = wk.normal_stress_profile(&ys, 40.0, 4000);
                for (y, t) in ys.iter().zip(&txx) {
                    let steady = wk.steady_normal_stress(*y);
                    assert!(
                        (t - steady).abs() < 2e-3 * steady,
                        "τxx({y}) {t} vs {steady}"
                    );
                }
            }
        }
    }

    /// Convergence of the series with the number of terms: fast (1/M², tail bound) for
    /// β = 0.1; slow (≈ 1/M) for UCM at the shear-wave cusp, which reaches the centre-line at
    /// t = 0.5 for Re = Wi = 1.
    #[test]
    fn series_truncation_converges() {
        let diff = |wk: &StartupPoiseuille, y: f64, t: f64, m: usize| {
            (wk.clone().with_terms(m).velocity(y, t) - wk.clone().with_terms(2 * m).velocity(y, t))
                .abs()
        };
        let ob = StartupPoiseuille::new(1.0, 1.0, 0.1);
        assert!(ob.terms() < 2000);
        let (d1, d2) = (diff(&ob, 0.3, 0.05, 100), diff(&ob, 0.3, 0.05, 200));
        assert!(d1 < 5e-4 && d2 < d1 / 2.5, "β = 0.1: {d1:.2e}, {d2:.2e}");
        let ucm = StartupPoiseuille::new(1.0, 1.0, 0.0);
        let (e1, e2, e3) = (
            diff(&ucm, 0.5, 0.5, 500),
            diff(&ucm, 0.5, 0.5, 1000),
            diff(&ucm, 0.5, 0.5, 2000),
        );
        assert!(e3 < 1e-3, "UCM cusp: {e1:.2e} {e2:.2e} {e3:.2e}");
        let order = (e1 / e3).log2() / 2.0;
        assert!(
            order > 0.5 && order < 1.6,
            "UCM cusp convergence order {order}"
        );
    }

    /// Known values of the Newtonian start-up: the lowest mode dominates late decay.
    #[test]
    fn newtonian_limit_decays_with_the_first_mode() {
        let wk = StartupPoiseuille::new(2.0, 0.0, 0.0);
        let t = 0.5;
        let expected = 1.0 - 32.0 / PI.powi(3) * (-PI * PI * t / 2.0).exp();
        // Higher modes at t = 0.5: 32/(27π³)·e^{−9π²/4} ≈ 8e-12.
        assert!((wk.velocity(0.5, t) - expected).abs() < 1e-9);
        assert_eq!(wk.shear_stress(0.5, t), 0.0);
    }
}
