//! The viscous term (β + α_V)η0∇²u of the predictor (24), and the time-step limit that goes
//! with each way of integrating it. The limits of (28) are written here once; the set-up's
//! derived numbers and the time step both use them.
//!
//! * [`Viscosity::Explicit`], as in the paper: the Morris Laplacian (21) of u^n, and
//!   δt ≤ f·min(h/max|u|, ρh²/η0), eq. (28).
//! * [`Viscosity::Implicit`] ([`implicit`]): the term at the new level (backward Euler), one
//!   sparse solve per velocity component, and δt ≤ f·h/max(max|u|, U), U the scene's velocity
//!   scale (which bounds the first steps from rest).
//! * [`Viscosity::CrankNicolson`]: the same solve with the term taken half at the old level
//!   and half at the new, ½ν(∇²u^n + ∇²u*), and the same limit. The trapezoidal rule is
//!   second order and centred on n + ½, where step 3 puts the polymer stress; with the
//!   Strang conformation update (`ConformationIntegrator::Strang`, paired by `auto`) every
//!   term of (24) but the ALE advection is then centred. Both first-order parts cost the large
//!   step δt ∝ h accuracy in a start-up. Start-up Poiseuille, Re = Wi = 1, β = 0.1,
//!   H/δr = 60, L2 error at t = 1 (t = 2): backward Euler with the paper's Euler update
//!   1.55e-2 (3.5e-3), Crank–Nicolson with it 1.73e-2 (5.0e-3), backward Euler with Strang
//!   6.9e-3 (2.3e-3), Crank–Nicolson with Strang 5.2e-3 (1.3e-3), the explicit step 4.2e-3
//!   (1.2e-3).
//!
//! Both also keep the capillary limit of a surface tension
//! ([`capillary_limit`]) and the elastic limit of the explicitly coupled polymer stress,
//! [`elastic_limit`]: steps 3 and 4 advance A with ∇u^n and put ∇·τ_p^{n+½} into the predictor,
//! a staggered explicit scheme for elastic shear waves whose speed is that of the *stretched*
//! polymer, c² = (G + τ_max)/ρ with G = η_p/λ and τ_max the largest principal polymer stress
//! (for Oldroyd-B, c² = Gλ_max(A)/ρ). The speed at rest, √(G/ρ), is too small by √λ_max(A):
//! ~70 at the wall of the Wi = 16 channel, where the old rule broke down.

pub mod implicit;
pub mod shear_dependent;

use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::free_surface::tension::capillary_limit;
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use crate::engine::rheology::Fluid;
use crate::engine::settings::{positive, Invalid};
use implicit::Accuracy;
pub use implicit::{Diffusion, ImplicitViscosity};
use rheosph_solver::{SolveError, SolveReport};
use serde::{Deserialize, Serialize};
pub use shear_dependent::ShearDependentViscosity;

/// How the viscous term of the predictor is integrated.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Viscosity {
    /// Explicit, as in the paper: δt ≤ 0.2ρh²/η0.
    Explicit,
    /// Implicit (β + α_V)η0∇²u (backward Euler): δt set by the advective CFL and the elastic
    /// wave speed.
    Implicit,
    /// Crank–Nicolson: half the term at u^n, half at u*; δt as for `Implicit`.
    CrankNicolson,
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

/// The elastic limit C·h/c (before the factor 0.2 of (28), so divided by it):
/// c² = (G + τ_max)/ρ the shear-wave speed of the stretched polymer (module docs; infinite
/// without polymer), and C = 0.8·min(2.3 + 4ν̃, 8), ν̃ = ν/(c h) the damping of the implicit
/// solvent viscosity ν (0 when it is explicit).
///
/// 2.3 is the leapfrog limit 2/(h max|s(k)|) of the explicit ∇u → τ → ∇·τ coupling, with s(k)
/// the symbol of the Bonet–Lok corrected first derivative (quintic kernel, h = 1.3δr: largest,
/// 0.865/h, at a wavelength of 5.8δr). Measured on start-up Poiseuille (Re = 1, β = 0.1,
/// H/δr = 15 and 30, Wi = 8–64, Lagrangian and Eulerian): every run whose δt c/h passed
/// 2.86–3.40 broke down, through a v-wave of wavelength 5δr in the first wall layers, and none
/// below 2.88 did. Implicit solvent viscosity damps the mode: at Re = 0.01 (ν̃ ≈ 1–2) the
/// onset moved to 9–12, which 2.3 + 4ν̃ (capped at 8) stays below. 0.8 is the margin.
pub fn elastic_limit(fluid: &Fluid, h: f64, max_polymer_stress: f64, implicit_nu: f64) -> f64 {
    if !fluid.model.is_viscoelastic() || fluid.polymer_viscosity() <= 0.0 {
        return f64::INFINITY;
    }
    let c = elastic_wave_speed(fluid, max_polymer_stress);
    let damping = implicit_nu / (c * h);
    let courant = ELASTIC_MARGIN * (LEAPFROG_LIMIT + DAMPING_GAIN * damping).min(DAMPED_LIMIT);
    courant / DT_FACTOR_OF_28 * h / c
}

/// The shear-wave speed of the stretched polymer, c² = (G + τ_max)/ρ with G = η_p/λ (0
/// without polymer).
pub fn elastic_wave_speed(fluid: &Fluid, max_polymer_stress: f64) -> f64 {
    if !fluid.model.is_viscoelastic() || fluid.polymer_viscosity() <= 0.0 {
        return 0.0;
    }
    let modulus = fluid.polymer_viscosity() / fluid.relaxation_time;
    ((modulus + max_polymer_stress.max(0.0)) / fluid.density).sqrt()
}

/// The constants of [`elastic_limit`].
const LEAPFROG_LIMIT: f64 = 2.3;
const DAMPING_GAIN: f64 = 4.0;
const DAMPED_LIMIT: f64 = 8.0;
const ELASTIC_MARGIN: f64 = 0.8;
/// The factor 0.2 of (28): every limit here is given before it (`scheme.time_step.factor`).
const DT_FACTOR_OF_28: f64 = 0.2;

/// `[scheme.time_step]`: the stability rules' factor, or a fixed step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct TimeStepSettings {
    /// The factor 0.2 of the time-step rule (28), applied to every limit.
    pub factor: f64,
    /// A fixed time step instead of the stability rules (either method; 0 or unset: the
    /// rules, so that `--set` can undo a case file's fixed step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixed: Option<f64>,
}

impl Default for TimeStepSettings {
    fn default() -> Self {
        Self {
            factor: DT_FACTOR_OF_28,
            fixed: None,
        }
    }
}

impl TimeStepSettings {
    /// The table's own checks (keys relative to `[scheme.time_step]`): the fixed step, if any.
    pub fn validate(&self) -> Result<Option<f64>, Invalid> {
        positive("factor", self.factor)?;
        self.fixed
            .filter(|&dt| dt != 0.0)
            .map(|dt| positive("fixed", dt))
            .transpose()
    }
}

/// What the time-step limits depend on.
#[derive(Clone, Copy, Debug)]
pub struct DtInputs {
    pub h: f64,
    /// The largest particle speed.
    pub max_speed: f64,
    /// The scene's velocity scale U.
    pub velocity_scale: f64,
    /// The largest principal polymer stress over the particles (0 at rest or without
    /// polymer).
    pub max_polymer_stress: f64,
}

impl Viscosity {
    /// θ, the weight of the new level: 0 explicit, 1 backward Euler, ½ Crank–Nicolson.
    pub fn theta(self) -> f64 {
        match self {
            Viscosity::Explicit => 0.0,
            Viscosity::Implicit => 1.0,
            Viscosity::CrankNicolson => 0.5,
        }
    }

    /// Whether a sparse solve takes (part of) the term, freeing δt from ρh²/η0.
    pub fn is_implicit(self) -> bool {
        self != Viscosity::Explicit
    }

    /// The time-step limit before the factor of (28). The elastic limit counts the damping
    /// of the implicit part θν only: Crank–Nicolson's explicit half does not damp.
    pub fn dt_limit(self, fluid: &Fluid, nu: f64, d: &DtInputs) -> f64 {
        if self.is_implicit() {
            advective_limit(d.h, d.max_speed.max(d.velocity_scale)).min(elastic_limit(
                fluid,
                d.h,
                d.max_polymer_stress,
                self.theta() * nu,
            ))
        } else {
            viscous_limit(fluid, d.h)
                .min(advective_limit(d.h, d.max_speed))
                .min(elastic_limit(fluid, d.h, d.max_polymer_stress, 0.0))
        }
        .min(capillary_limit(fluid.density, fluid.surface_tension, d.h))
    }

    /// The stage that integrates the term; its implicit solves stop at the relative residual
    /// `tolerance`.
    pub fn stage<const D: usize>(self, tolerance: f64) -> ViscousStage<D> {
        ViscousStage {
            theta: self.theta(),
            tolerance,
            laplacian: Vec::new(),
            implicit: self.is_implicit().then(Box::default),
        }
    }
}

/// The viscous part of step 4 with its buffers: the θ-scheme
/// u* = … + δt ν [(1 − θ)∇²u^n + θ∇²u*].
pub struct ViscousStage<const D: usize = 2> {
    /// The weight of the new level ([`Viscosity::theta`]).
    theta: f64,
    /// Relative residual at which the implicit solves stop (`scheme.viscous_tolerance`).
    tolerance: f64,
    /// ∇²u^n of the explicit part (θ < 1).
    laplacian: Vec<Vector<D>>,
    /// The solve of the implicit part (θ > 0).
    implicit: Option<Box<ImplicitViscosity<D>>>,
}

/// The rows held at a prescribed velocity (identity rows: an inflow buffer; empty: none)
/// and that velocity.
#[derive(Clone, Copy)]
pub struct Prescribed<'a, const D: usize = 2> {
    pub rows: &'a [bool],
    pub value: Vector<D>,
}

impl<const D: usize> ViscousStage<D>
where
    Dim<D>: Dimension<D>,
{
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.laplacian)
            + self.implicit.as_ref().map_or(0, |m| m.heap_bytes())
    }

    /// Drops the implicit solve's preconditioner.
    pub fn invalidate_preconditioner(&mut self) {
        if let Some(m) = self.implicit.as_mut() {
            m.invalidate_preconditioner();
        }
    }

    /// The explicit part's ∇²u^n (eq. (21), from the extended velocity), or ∇·(φ∇u^n) for
    /// a variable viscosity φ = η/η0 (`factor`, fluid then ghosts; empty: uniform), with its
    /// weight 1 − θ; None when the term is taken wholly implicitly.
    pub fn explicit_laplacian(
        &mut self,
        list: &NeighbourList<D>,
        sums: &KernelSums<D>,
        velocity_ext: &[Vector<D>],
        factor: &[f64],
    ) -> Option<(&[Vector<D>], f64)> {
        if self.theta >= 1.0 {
            return None;
        }
        let laplacian = &mut self.laplacian;
        laplacian.resize(list.rows(), Vector::<D>::zeros());
        if factor.is_empty() {
            sums.laplacian_vector(list, velocity_ext, laplacian);
        } else {
            sums.variable_laplacian_vector(list, velocity_ext, factor, laplacian);
        }
        Some((laplacian, 1.0 - self.theta))
    }

    /// The implicit solve `(I − θ δt ν L) u* = rhs`, overwriting `velocity` (the rest of (24)
    /// on entry) with u*; `warm_start` is u^n; the `prescribed` rows take its velocity
    /// (identity rows); `diffusion` is δt ν with the variable viscosity's factor, of which
    /// the solve takes θ. Nothing for the explicit term.
    pub fn solve(
        &mut self,
        hood: Hood<D>,
        diffusion: Diffusion,
        warm_start: &[Vector<D>],
        velocity: &mut [Vector<D>],
        prescribed: Prescribed<D>,
        preconditioner: rheosph_solver::Preconditioner,
    ) -> Result<Option<[SolveReport; D]>, SolveError> {
        let (theta, tolerance) = (self.theta, self.tolerance);
        let Prescribed { rows, value } = prescribed;
        let Some(m) = self.implicit.as_mut() else {
            return Ok(None);
        };
        for (u, _) in velocity.iter_mut().zip(rows).filter(|(_, &b)| b) {
            *u = value;
        }
        let diffusion = Diffusion {
            nu_dt: theta * diffusion.nu_dt,
            ..diffusion
        };
        let accuracy = Accuracy {
            tolerance,
            preconditioner,
        };
        m.solve(hood, diffusion, warm_start, velocity, rows, accuracy)
            .map(Some)
    }
}
