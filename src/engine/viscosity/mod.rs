//! The viscous term (β + α_V)η0∇²u of the predictor (24), and the time-step limit that goes
//! with each way of integrating it. The limits of (28) are written here once; the set-up's
//! derived numbers and the time step both use them.
//!
//! * [`Viscosity::Explicit`], as in the paper: the Morris Laplacian (21) of u^n, and
//!   δt ≤ f·min(h/max|u|, ρh²/η0), eq. (28).
//! * [`Viscosity::Implicit`] ([`implicit`]): the term at the new level, one sparse solve per
//!   velocity component, and δt ≤ f·min(h/max(max|u|, U), h/c) with c = √(η_p/(ρλ)) the
//!   elastic shear-wave speed (the polymer stress stays explicit) and U the scene's velocity
//!   scale (which bounds the first steps from rest).

pub mod implicit;

use crate::engine::boundary::Ghosts;
use crate::engine::math::Vec2;
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use crate::engine::rheology::Fluid;
pub use implicit::ImplicitViscosity;
use rheosph_solver::{SolveError, SolveReport};
use serde::{Deserialize, Serialize};

/// How the viscous term of the predictor is integrated.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Viscosity {
    /// Explicit, as in the paper: δt ≤ 0.2ρh²/η0.
    Explicit,
    /// Implicit (β + α_V)η0∇²u: δt set by the advective CFL and the elastic wave speed.
    Implicit,
}

/// The viscous limit of (28), ρh²/η0 (before the factor).
pub fn viscous_limit(fluid: &Fluid, h: f64) -> f64 {
    fluid.density * h * h / fluid.viscosity
}

/// The advective limit h/|u| (infinite at rest).
pub fn advective_limit(h: f64, speed: f64) -> f64 {
    if speed > 0.0 {
        h / speed
    } else {
        f64::INFINITY
    }
}

/// The elastic limit h/c, c = √(η_p/(ρλ)) the shear-wave speed of the polymer at rest
/// (infinite without polymer).
pub fn elastic_limit(fluid: &Fluid, h: f64) -> f64 {
    if fluid.model.is_viscoelastic() && fluid.polymer_viscosity() > 0.0 {
        h / (fluid.polymer_viscosity() / (fluid.density * fluid.relaxation_time)).sqrt()
    } else {
        f64::INFINITY
    }
}

impl Viscosity {
    /// The time-step limit before the factor of (28), for the largest particle speed
    /// `max_speed` and the scene's velocity scale.
    pub fn dt_limit(self, fluid: &Fluid, h: f64, max_speed: f64, velocity_scale: f64) -> f64 {
        match self {
            Viscosity::Explicit => viscous_limit(fluid, h).min(advective_limit(h, max_speed)),
            Viscosity::Implicit => {
                advective_limit(h, max_speed.max(velocity_scale)).min(elastic_limit(fluid, h))
            }
        }
    }

    /// The stage that integrates the term.
    pub fn stage(self) -> ViscousStage {
        match self {
            Viscosity::Explicit => ViscousStage::Explicit {
                laplacian: Vec::new(),
            },
            Viscosity::Implicit => ViscousStage::Implicit(Box::default()),
        }
    }
}

/// Relative residual of the implicit viscous solves: well below the O(δt) splitting error.
const VISCOUS_TOLERANCE: f64 = 1e-10;

/// The viscous part of step 4 with its buffers.
pub enum ViscousStage {
    Explicit { laplacian: Vec<Vec2> },
    Implicit(Box<ImplicitViscosity>),
}

impl ViscousStage {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        match self {
            ViscousStage::Explicit { laplacian } => crate::engine::vec_bytes(laplacian),
            ViscousStage::Implicit(m) => m.heap_bytes(),
        }
    }

    /// The explicit term's ∇²u^n (eq. (21), from the extended velocity), or None when the
    /// term is taken implicitly.
    pub fn explicit_laplacian(
        &mut self,
        list: &NeighbourList,
        sums: &KernelSums,
        velocity_ext: &[Vec2],
    ) -> Option<&[Vec2]> {
        match self {
            ViscousStage::Explicit { laplacian } => {
                laplacian.resize(list.rows(), Vec2::zeros());
                sums.laplacian_vector(list, velocity_ext, laplacian);
                Some(laplacian)
            }
            ViscousStage::Implicit(_) => None,
        }
    }

    /// The implicit solve `(I − δt ν L) u* = rhs`, overwriting `velocity` (the rest of (24)
    /// on entry) with u*; `warm_start` is u^n; rows flagged in `prescribed` take the
    /// velocity `value` (identity rows). Nothing for the explicit term.
    pub fn solve(
        &mut self,
        (list, sums, ghosts): (&NeighbourList, &KernelSums, &Ghosts),
        nu_dt: f64,
        warm_start: &[Vec2],
        velocity: &mut [Vec2],
        (prescribed, value): (&[bool], Vec2),
    ) -> Result<Option<[SolveReport; 2]>, SolveError> {
        match self {
            ViscousStage::Explicit { .. } => Ok(None),
            ViscousStage::Implicit(m) => {
                for (u, _) in velocity.iter_mut().zip(prescribed).filter(|(_, &b)| b) {
                    *u = value;
                }
                m.solve(
                    list,
                    sums,
                    ghosts,
                    nu_dt,
                    warm_start,
                    velocity,
                    prescribed,
                    VISCOUS_TOLERANCE,
                )
                .map(Some)
            }
        }
    }
}
