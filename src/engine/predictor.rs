//! Step 4, the predictor of eq. (24):
//!
//! ```text
//!     u* = u^n + δt [u_ps·∇u^n + ν∇²u^n + ∇·Φ/ρ + g − ∇p^n/ρ],
//! ```
//!
//! each term supplied by the stage that owns it: the ALE advection by the shift velocity
//! (step 2), the explicit viscous term (absent when viscosity is implicit, see
//! [`crate::engine::viscosity`]), the EVSS stress divergence (viscoelastic fluids, step 3),
//! the body force, a surface tension's cohesion force, and the old pressure gradient (incremental projection only, see
//! [`crate::engine::projection`]).

use crate::engine::dimension::{Matrix, Vector};
use rayon::prelude::*;

/// The terms of (24) besides u^n.
pub struct PredictorTerms<'a, const D: usize = 2> {
    /// ∇u^n.
    pub grad_u: &'a [Matrix<D>],
    /// The shift velocity u_ps.
    pub u_ps: &'a [Vector<D>],
    /// ∇²u^n and ν (explicit viscosity).
    pub viscous: Option<(&'a [Vector<D>], f64)>,
    /// ∇·Φ (viscoelastic fluids).
    pub stress: Option<&'a [Vector<D>]>,
    pub body_force: Vector<D>,
    /// ∇p^n (incremental projection).
    pub old_pressure_gradient: Option<&'a [Vector<D>]>,
    /// The weakly compressible scheme's pressure, polymer-stress, artificial viscosity and
    /// stress accelerations (see [`crate::engine::weakly_compressible`]).
    pub weak: Option<&'a [Vector<D>]>,
    /// A free surface's own accelerations: the cohesion force (surface tension as a pair
    /// force, [`crate::engine::free_surface::cohesion`]) or the shear-free flux of the
    /// viscous term ([`crate::engine::free_surface::shear_free`]).
    pub surface_force: Option<&'a [Vector<D>]>,
    /// 1/ρ.
    pub inv_rho: f64,
}

/// u* from u^n (`velocity`) over `dt`, into `out`.
pub fn predict<const D: usize>(
    terms: &PredictorTerms<D>,
    velocity: &[Vector<D>],
    dt: f64,
    out: &mut Vec<Vector<D>>,
) {
    let PredictorTerms {
        grad_u,
        u_ps,
        viscous,
        stress,
        body_force,
        old_pressure_gradient,
        weak,
        surface_force,
        inv_rho,
    } = *terms;
    out.resize(velocity.len(), Vector::<D>::zeros());
    out.par_iter_mut()
        .zip(velocity.par_iter())
        .enumerate()
        .for_each(|(i, (us, u))| {
            let mut a = grad_u[i] * u_ps[i];
            if let Some((laplacian, nu)) = viscous {
                a += nu * laplacian[i];
            }
            if let Some(div_phi) = stress {
                a += div_phi[i] * inv_rho;
            }
            a += body_force;
            if let Some(grad_p) = old_pressure_gradient {
                a -= inv_rho * grad_p[i];
            }
            if let Some(weak) = weak {
                a += weak[i];
            }
            if let Some(surface) = surface_force {
                a += surface[i];
            }
            *us = u + dt * a;
        });
}
