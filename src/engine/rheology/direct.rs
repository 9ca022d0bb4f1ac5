//! Direct integration of the conformation tensor (King & Lind eq. (10)): first-order Euler on
//! A itself, not positive definite by construction (the comparison the paper draws with the
//! log-conformation).

use super::{relax, Model};
use crate::engine::dimension::SymTensor;

/// One direct first-order Euler update of A, eq. (10) with (11):
/// `A + δt[u_ps·∇A + ∇u·A + A·∇uᵀ − f_R(A)/λ]`.
pub fn direct_step<S: SymTensor>(
    model: &Model,
    a: &S,
    advection_a: &S,
    grad_u: &S::Matrix,
    dt: f64,
    lambda: f64,
) -> S {
    *a + (*advection_a + upper_convected(grad_u, a) - model.relaxation(a) * (1.0 / lambda)) * dt
}

/// ∇u·A + A·∇uᵀ.
fn upper_convected<S: SymTensor>(grad_u: &S::Matrix, a: &S) -> S {
    let stretch = *grad_u * a.to_mat();
    S::sym_part(&(stretch + S::transpose(&stretch)))
}

/// The second-order direct update ([`super::ConformationIntegrator::Strang`]): Strang
/// splitting of the source step (quasi-analytic (32) where it applies) around the explicit
/// midpoint rule for `u_ps·∇A + ∇u·A + A·∇uᵀ`, ∇u and the advection term held.
pub fn direct_step_strang<S: SymTensor>(
    model: &Model,
    a: &S,
    advection_a: &S,
    grad_u: &S::Matrix,
    dt: f64,
    lambda: f64,
) -> S {
    let relaxed = relax(model, a, 0.5 * dt, lambda);
    let rate = |a: &S| *advection_a + upper_convected(grad_u, a);
    let midpoint = relaxed + rate(&relaxed) * (0.5 * dt);
    relax(model, &(relaxed + rate(&midpoint) * dt), 0.5 * dt, lambda)
}
