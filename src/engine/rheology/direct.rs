//! Direct integration of the conformation tensor (King & Lind eq. (10)): first-order Euler on
//! A itself, not positive definite by construction (the comparison the paper draws with the
//! log-conformation).

use super::{relax, Model};
use crate::engine::math::{Mat2, Sym2};

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
    *a + (*advection_a + upper_convected(grad_u, a) - model.relaxation(a) * (1.0 / lambda)) * dt
}

/// ∇u·A + A·∇uᵀ.
fn upper_convected(grad_u: &Mat2, a: &Sym2) -> Sym2 {
    let stretch = grad_u * a.to_mat();
    Sym2::sym_part(&(stretch + stretch.transpose()))
}

/// The second-order direct update ([`super::ConformationIntegrator::Strang`]): Strang
/// splitting of the source step (quasi-analytic (32) where it applies) around the explicit
/// midpoint rule for `u_ps·∇A + ∇u·A + A·∇uᵀ`, ∇u and the advection term held.
pub fn direct_step_strang(
    model: &Model,
    a: &Sym2,
    advection_a: &Sym2,
    grad_u: &Mat2,
    dt: f64,
    lambda: f64,
) -> Sym2 {
    let relaxed = relax(model, a, 0.5 * dt, lambda);
    let rate = |a: &Sym2| *advection_a + upper_convected(grad_u, a);
    let midpoint = relaxed + rate(&relaxed) * (0.5 * dt);
    relax(model, &(relaxed + rate(&midpoint) * dt), 0.5 * dt, lambda)
}
