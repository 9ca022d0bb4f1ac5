//! A pipe's wall shear stress from its particles: the total shear stress
//! σ_xr = η_s ∂u/∂r + τ_p,xr extrapolated to the wall r = R.
//!
//! Both parts are read off least-squares fits over every particle in the meridional plane,
//! in powers of ρ = r/R that keep the fields regular on the axis: u = Σ c_k ρ^{2k}
//! (k = 0..3) and τ_xr = Σ d_k ρ^{2k+1} (k = 0..2). The start-up series (`analytic::pipe`) is
//! of this form with infinitely many terms; once the fast modes have decayed (t ≳ Wi) its
//! profile is within the fit's reach, and at steady state (u = 1 − ρ², σ_xr = −2ρ in the
//! series' units) the fit is exact. A local measurement, unlike the global balance
//! σ_w = −ρ(g − dŪ/dt)R/2, it tests the stress the scheme carries next to a curved wall.

use crate::engine::math::Vec2;
use nalgebra::{SMatrix, SVector};

/// The least-squares coefficients of `values` in the `N` basis functions `basis(ρ)`.
fn fit<const N: usize>(
    rho: &[f64],
    values: &[f64],
    basis: impl Fn(f64) -> SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    let mut normal = SMatrix::<f64, N, N>::zeros();
    let mut rhs = SVector::<f64, N>::zeros();
    for (&r, &v) in rho.iter().zip(values) {
        let b = basis(r);
        normal += b * b.transpose();
        rhs += b * v;
    }
    normal.cholesky().map(|c| c.solve(&rhs))
}

/// The fitted total shear stress at the wall of a pipe of `radius`: `plane` holds the
/// particles' (x, r), `axial` their u_x, `tau_xr` their polymer τ_xr, `eta_s` the solvent
/// viscosity. None when the particles cannot fix the fits (fewer than four distinct radii).
pub fn wall_shear_stress(
    plane: &[Vec2],
    axial: &[f64],
    tau_xr: &[f64],
    eta_s: f64,
    radius: f64,
) -> Option<f64> {
    let rho: Vec<f64> = plane.iter().map(|p| p.y / radius).collect();
    let u = fit(&rho, axial, |r| {
        let s = r * r;
        SVector::<f64, 4>::new(1.0, s, s * s, s * s * s)
    })?;
    let tau = fit(&rho, tau_xr, |r| {
        let s = r * r;
        SVector::<f64, 3>::new(r, r * s, r * s * s)
    })?;
    // ∂u/∂r at ρ = 1: (2c1 + 4c2 + 6c3)/R.
    let shear_rate = (2.0 * u[1] + 4.0 * u[2] + 6.0 * u[3]) / radius;
    Some(eta_s * shear_rate + tau.sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The steady Oldroyd-B profile (u = U(1 − ρ²), τ_xr = −2η_p U ρ/R) gives σ_w = −2η0U/R
    /// to round-off from scattered radii, whatever the split between solvent and polymer.
    #[test]
    fn the_steady_profile_gives_the_balance() {
        let (radius, speed, eta_s, eta_p) = (0.5, 3.0, 0.1, 0.9);
        let plane: Vec<Vec2> = (0..200)
            .map(|k| Vec2::new(0.0, radius * ((k as f64 * 0.618_034) % 1.0)))
            .collect();
        let axial: Vec<f64> = plane
            .iter()
            .map(|p| speed * (1.0 - (p.y / radius).powi(2)))
            .collect();
        let tau: Vec<f64> = plane
            .iter()
            .map(|p| -2.0 * eta_p * speed * p.y / radius.powi(2))
            .collect();
        let sigma = wall_shear_stress(&plane, &axial, &tau, eta_s, radius).unwrap();
        let exact = -2.0 * (eta_s + eta_p) * speed / radius;
        assert!(
            (sigma - exact).abs() < 1e-10 * exact.abs(),
            "{sigma} vs {exact}"
        );
    }
}
