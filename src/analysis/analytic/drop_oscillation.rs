//! Small oscillations of a 2D liquid cylinder (a free drop without gravity) in its mode n,
//! weakly damped by a Newtonian or a linear viscoelastic (Maxwell) liquid.
//!
//! Inviscid (Rayleigh; Lamb 1932, §275): ω0² = n(n² − 1)σ/(ρR³).
//!
//! Weak viscosity (Lamb 1932, §355, the dissipation method applied to the 2D potential
//! φ = A rⁿ cos nθ): the mean dissipation 2πηn²(n − 1)R^{2n−2}A² over twice the energy
//! (ρ/2)nπA²R^{2n} gives the amplitude decay rate γ = 2n(n − 1)η/(ρR²); the mode is the
//! damped oscillator a'' + 2γa' + ω0²a = 0, whose damping force is c η a' with
//! c = 4n(n − 1)/(ρR²).
//!
//! Viscoelastic liquid. Linearised about rest (A = I), Oldroyd-B's polymer stress obeys
//! τ_p + λ ∂τ_p/∂t = 2η_p D, so for a mode ∝ e^{st} it is 2η_p/(1 + λs) D: the linear
//! problem is the Newtonian one with the complex viscosity η*(s) = η_s + η_p/(1 + λs) (the
//! correspondence principle; Bird, Armstrong & Hassager 1987, §5.2; at s = iω this is the
//! dynamic viscosity η' − iη''). The damping force c η a' becomes the convolution with the
//! relaxation modulus, c η*(s) s a in the transform, so s solves
//!
//! ```text
//!     s² + c η*(s) s + ω0² = 0,   c = 4n(n − 1)/(ρR²),
//! ```
//!
//! a cubic: (1 + λs)(s² + ω0²) + c(η_s(1 + λs) + η_p)s = 0. Its complex pair is the
//! oscillation, s = −γ ± iω (to first order γ = 2n(n − 1)/(ρR²)·(η_s + η_p/(1 + De²)),
//! De = ω0λ: the polymer's damping falls off as De², and its elastic modulus G = η_p/λ
//! stiffens the mode, ω² → ω0² + cG as λ → ∞); the real root is the slow creep of the
//! polymer's memory. Models whose linear response about A = I is Oldroyd-B's (UCM, PTT,
//! Giesekus: their nonlinear terms are quadratic in τ_p) share it.
//!
//! Valid while the damping is weak, γ ≪ ω0 (Ohnesorge number η/√(ρσR) ≪ 1): the
//! oscillatory boundary layer at the surface, of relative thickness √(ν/(ωR²)), is left out.
//!
//! Exact linear theory ([`DropMode::root`]), the boundary layer included. The linearised
//! Stokes problem with u = ∇φ + ∇×(ψẑ), p = −ρsφ: φ = A rⁿ cos nθ (∇²φ = 0) and
//! ψ = B I_n(kr) sin nθ ((∇² − k²)ψ = 0, k² = ρs/η*(s)); at r = R, zero shear stress
//! (r ∂_r(u_θ/r) + r⁻¹∂_θu_r = 0) and the normal-stress balance −p + 2η*∂_ru_r = −σκ', with
//! κ' = (n² − 1)ζ/R² for the surface r = R + ζ cos nθ and sζ = u_r (kinematic). A nonzero
//! (A, B) needs the determinant of
//!
//! ```text
//!   [ ρsRⁿ + 2η*n(n−1)R^{n−2} + σn(n²−1)R^{n−3}/s    n(2η*(kI_n'/R − I_n/R²) + σ(n²−1)I_n/(R³s)) ]
//!   [ −2n(n−1)R^{n−2}                               2kI_n'/R − (k² + 2n²/R²)I_n               ]
//! ```
//!
//! (I_n at kR; divided by I_n, only I_n'/I_n enters) to vanish. As η* → 0 (k → ∞) it reduces to s² = −ω0², and for small η* its
//! root approaches the weak-damping one ([`DropMode::weak_root`]).

use nalgebra::Complex;

/// The liquid and the drop of one mode.
#[derive(Clone, Copy, Debug)]
pub struct DropMode {
    /// Mode number n ≥ 2.
    pub n: u32,
    pub surface_tension: f64,
    pub density: f64,
    pub radius: f64,
    /// η_s (the whole viscosity of a Newtonian liquid).
    pub solvent_viscosity: f64,
    /// η_p (0: Newtonian).
    pub polymer_viscosity: f64,
    /// λ (0: Newtonian).
    pub relaxation_time: f64,
}

impl DropMode {
    /// ω0 = √(n(n² − 1)σ/(ρR³)).
    pub fn inviscid_frequency(&self) -> f64 {
        let n = f64::from(self.n);
        (n * (n * n - 1.0) * self.surface_tension / (self.density * self.radius.powi(3))).sqrt()
    }

    /// c = 4n(n − 1)/(ρR²): the damping coefficient per unit viscosity (twice Lamb's γ/η).
    fn damping_per_viscosity(&self) -> f64 {
        let n = f64::from(self.n);
        4.0 * n * (n - 1.0) / (self.density * self.radius * self.radius)
    }

    /// η*(s) = η_s + η_p/(1 + λs).
    fn complex_viscosity(&self, s: Complex<f64>) -> Complex<f64> {
        let one = Complex::new(1.0, 0.0);
        Complex::new(self.solvent_viscosity, 0.0)
            + Complex::new(self.polymer_viscosity, 0.0) / (one + s * self.relaxation_time)
    }

    /// The oscillatory root s = −γ + iω of the exact linear theory (the determinant in the
    /// module's comment; Newton's method from [`DropMode::weak_root`]). None if it fails.
    pub fn root(&self) -> Option<Complex<f64>> {
        let start = self.weak_root()?;
        newton(|s| self.determinant(s), start).filter(|s| s.im > 0.0)
    }

    /// The normal-stress row times the shear row minus the cross terms, over I_n(kR).
    fn determinant(&self, s: Complex<f64>) -> Complex<f64> {
        let (n, r, rho) = (f64::from(self.n), self.radius, self.density);
        let sigma = self.surface_tension;
        let eta = self.complex_viscosity(s);
        let k = (s * rho / eta).sqrt();
        let x = k * r;
        // I_n'(x)/I_n(x) = I_{n−1}(x)/I_n(x) − n/x.
        let ratio = Complex::new(1.0, 0.0) / bessel_i_ratio(self.n, x) - n / x;
        let m11 = s * rho * r.powi(self.n as i32)
            + eta * (2.0 * n * (n - 1.0) * r.powi(self.n as i32 - 2))
            + sigma * n * (n * n - 1.0) * r.powi(self.n as i32 - 3) / s;
        let m12 = (eta * 2.0 * (k * ratio / r - 1.0 / (r * r))
            + sigma * (n * n - 1.0) / (s * r.powi(3)))
            * n;
        // Both columns' B entries are over I_n(kR).
        let m21 = -2.0 * n * (n - 1.0) * r.powi(self.n as i32 - 2);
        let m22 = k * ratio * (2.0 / r) - k * k - 2.0 * n * n / (r * r);
        m11 * m22 - m12 * m21
    }

    /// The oscillatory root s = −γ + iω of the weak-damping relation s² + cη*(s)s + ω0² = 0
    /// (Newton's method from the Newtonian root), None if the mode is overdamped there or
    /// Newton fails.
    pub fn weak_root(&self) -> Option<Complex<f64>> {
        let w0 = self.inviscid_frequency();
        let c = self.damping_per_viscosity();
        let eta0 = self.solvent_viscosity + self.polymer_viscosity;
        let gamma0 = 0.5 * c * eta0;
        if gamma0 >= w0 {
            return None;
        }
        let s = Complex::new(-gamma0, (w0 * w0 - gamma0 * gamma0).sqrt());
        let f = |s: Complex<f64>| s * s + self.complex_viscosity(s) * s * c + w0 * w0;
        newton(f, s).filter(|s| s.im > 0.0)
    }

    /// The period 2π/ω of the oscillation.
    pub fn period(&self) -> Option<f64> {
        self.root().map(|s| 2.0 * std::f64::consts::PI / s.im)
    }

    /// The amplitude decay rate γ.
    pub fn decay_rate(&self) -> Option<f64> {
        self.root().map(|s| -s.re)
    }
}

/// A root of the analytic `f` by Newton's method with a central-difference derivative.
fn newton(f: impl Fn(Complex<f64>) -> Complex<f64>, mut s: Complex<f64>) -> Option<Complex<f64>> {
    for _ in 0..100 {
        let h = 1e-6 * s.norm().max(1e-12);
        let df = (f(s + h) - f(s - h)) / (2.0 * h);
        let step = f(s) / df;
        if !step.re.is_finite() || !step.im.is_finite() {
            return None;
        }
        s -= step;
        if step.norm() <= 1e-13 * s.norm() {
            return Some(s);
        }
    }
    None
}

/// I_n(z)/I_{n−1}(z) for complex z ≠ 0 from its continued fraction (Gauss):
/// 1/(2n/z + 1/(2(n+1)/z + 1/(2(n+2)/z + …))), evaluated from the tail; it converges for
/// every z, after about |z| terms, with no overflow where I_n itself would (|kR| runs to
/// thousands as η → 0).
fn bessel_i_ratio(n: u32, z: Complex<f64>) -> Complex<f64> {
    let terms = 60 + 2 * z.norm().ceil() as u32;
    let mut tail = Complex::new(0.0, 0.0);
    for m in (n..n + terms).rev() {
        tail = Complex::new(1.0, 0.0) / (Complex::new(2.0 * f64::from(m), 0.0) / z + tail);
    }
    tail
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(eta_s: f64, eta_p: f64, lambda: f64) -> DropMode {
        DropMode {
            n: 2,
            surface_tension: 1.0,
            density: 1.0,
            radius: 1.0,
            solvent_viscosity: eta_s,
            polymer_viscosity: eta_p,
            relaxation_time: lambda,
        }
    }

    /// Newtonian: the damped oscillator's root exactly, γ = 4η/(ρR²), ω² = 6 − γ².
    #[test]
    fn newtonian_weak_root_is_lamb_damped_oscillator() {
        let s = mode(0.05, 0.0, 0.0).weak_root().unwrap();
        assert!((-s.re - 0.2).abs() < 1e-12);
        assert!((s.im - (6.0f64 - 0.04).sqrt()).abs() < 1e-12);
    }

    /// The viscoelastic root's limits: λ → 0 is the Newtonian liquid of η0 = η_s + η_p;
    /// λ → ∞ damps with η_s alone and is stiffened by G = η_p/λ → 0; in between the
    /// first-order decay η_s + η_p/(1 + De²) holds to O(γλ) (η* taken at iω0, not at s;
    /// here γλ = 0.005).
    #[test]
    fn viscoelastic_root_has_the_maxwell_limits() {
        for root in [DropMode::weak_root, DropMode::root] {
            let newtonian = root(&mode(0.05, 0.0, 0.0)).unwrap();
            let fast = root(&mode(0.01, 0.04, 1e-9)).unwrap();
            assert!((fast - newtonian).norm() < 1e-6);
            let slow = root(&mode(0.01, 0.04, 1e9)).unwrap();
            let solvent = root(&mode(0.01, 0.0, 0.0)).unwrap();
            assert!((slow - solvent).norm() < 1e-6);
        }
        let m = mode(0.001, 0.004, 0.4);
        let de = m.inviscid_frequency() * 0.4;
        let first_order = 4.0 * (0.001 + 0.004 / (1.0 + de * de));
        let gamma = -m.weak_root().unwrap().re;
        assert!(
            (gamma / first_order - 1.0).abs() < 5e-3,
            "{gamma} vs {first_order}"
        );
    }

    /// The exact root tends to the weak-damping one as η → 0, its relative difference
    /// falling like the boundary layer's thickness √(ν/(ω0R²)) (order ½ in η), and to the
    /// inviscid ω0.
    #[test]
    fn exact_root_tends_to_the_weak_damping_root() {
        let gap = |eta: f64| {
            let m = mode(eta, 0.0, 0.0);
            let (exact, weak) = (m.root().unwrap(), m.weak_root().unwrap());
            (-exact.re / -weak.re - 1.0).abs()
        };
        let (coarse, fine) = (gap(1e-3), gap(1e-5));
        let order = (coarse / fine).log10() / 2.0;
        assert!(
            fine < 0.01 && (0.4..0.7).contains(&order),
            "{coarse} {fine} {order}"
        );
        let s = mode(1e-6, 0.0, 0.0).root().unwrap();
        assert!((s.im / 6.0f64.sqrt() - 1.0).abs() < 1e-4);
    }
}
