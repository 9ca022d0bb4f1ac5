//! The second-order gradient and Laplacian weights of the plane (`scheme.operators`): a 5 × 5
//! moment system per particle, eq. (22) carried one order further (Nasar et al. 2021). In 3D
//! the system would be 9 × 9; it is not written yet.

use crate::engine::math::Vec2;

/// Above this bound on the condition number of the 5 × 5 moment matrix (the product of the
/// entry-wise 1-norms of M and M⁻¹; a truncated or very irregular support) a particle keeps
/// the first-order gradient.
const MAX_MOMENT_CONDITION: f64 = 1e8;

/// Which of a particle's weights [`second_order_row`] overwrites.
#[derive(Clone, Copy, Debug)]
pub struct Second {
    pub gradient: bool,
    pub laplacian: bool,
}

/// Overwrites one particle's gradient and/or Laplacian weights with the second-order ones:
/// with x = r_j − r_i, test vector q_j = ∇W_ij ⊕ (−F/h)(x², xy, y²) (F = W'/r, so the first
/// two entries are ∇W_ij) and Taylor monomials p_j = (x, y, x²/2, xy, y²/2),
///
/// ```text
///     D_i = M_i⁻¹ Σ_j (φ_j − φ_i) q_j δV,   M_i = Σ_j q_j ⊗ p_j δV,
/// ```
///
/// is exact for quadratic φ (D = ∂x, ∂y, ∂xx, ∂xy, ∂yy); the gradient weights are the first
/// two rows of M⁻¹ q_j, the Laplacian's the sum of the third and fifth (with the sign of
/// (21)'s weights, which multiply φ_i − φ_j). M's leading 2 × 2 block is Bonet–Lok's moment
/// matrix, so this is eq. (22) carried one order further (Nasar et al. 2021). `factor` holds
/// F times the volume ratio. A particle whose M is too ill-conditioned keeps its weights.
pub fn second_order_row(
    grad: &mut [Vec2],
    laplacian: &mut [f64],
    factor: &[f64],
    rij: &[Vec2],
    h: f64,
    dv: f64,
    which: Second,
) {
    type M5 = nalgebra::SMatrix<f64, 5, 5>;
    type V5 = nalgebra::SVector<f64, 5>;
    let test = |f: f64, r: &Vec2| {
        let (x, y) = (-r.x, -r.y);
        let s = -f / h;
        V5::new(-f * x, -f * y, s * x * x, s * x * y, s * y * y)
    };
    let mut m = M5::zeros();
    for (f, r) in factor.iter().zip(rij) {
        let (x, y) = (-r.x, -r.y);
        let p = V5::new(x, y, 0.5 * x * x, x * y, 0.5 * y * y);
        m += (test(*f, r) * dv) * p.transpose();
    }
    let Some(inv) = m.try_inverse() else { return };
    if m.lp_norm(1) * inv.lp_norm(1) > MAX_MOMENT_CONDITION || !inv[(0, 0)].is_finite() {
        return;
    }
    let weights = grad
        .iter_mut()
        .zip(laplacian.iter_mut())
        .zip(factor)
        .zip(rij);
    for (((g, w), f), r) in weights {
        let d = inv * test(*f, r);
        if which.gradient {
            *g = Vec2::new(d[0], d[1]);
        }
        if which.laplacian {
            *w = -(d[2] + d[4]) * dv;
        }
    }
}
