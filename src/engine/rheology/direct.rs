//! Direct integration of the conformation tensor (King & Lind eq. (10)): first-order Euler on
//! A itself, not positive definite by construction (the comparison the paper draws with the
//! log-conformation).

use super::Model;
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
    let stretch = grad_u * a.to_mat();
    let upper_convected = Sym2::sym_part(&(stretch + stretch.transpose()));
    *a + (*advection_a + upper_convected - model.relaxation(a) * (1.0 / lambda)) * dt
}
