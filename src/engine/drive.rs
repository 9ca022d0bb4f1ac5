//! The body force that drives the flow: constant (the paper's channels and cylinder array), or
//! adjusted every step so that the bulk velocity ⟨u⟩ = Q/H holds a target, as in reference
//! data computed at fixed flow rate (King & Lind attribute their Wi = 0.8 cylinder-array
//! discrepancies to the drift of ⟨u⟩ under a constant force).
//!
//! The control is integral: g ← g + (δt/τ) g₀ (U − ⟨u⟩)/U, with g₀ the case's force (the
//! initial guess, which sets the scale) and τ = ρL_y²/η0 the viscous time across the box, the
//! lag with which the bulk velocity answers a change of force. For a force-proportional drag
//! the error decays as e^{−t g₀/(τ g)}, on the time scale τ; at steady state ⟨u⟩ = U exactly.

use crate::engine::dimension::Vector;
use crate::engine::neighbours::Domain;

/// How the body force evolves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// The case's force, always.
    Constant,
    /// Adjusted to hold ⟨u⟩ = `target` (module docs): g_x changes by `gain`·δt·(U − ⟨u⟩).
    MeanFlow { target: f64, gain: f64 },
}

impl Drive {
    /// Integral control of ⟨u⟩ = `target` from the initial force `g0` in a box of height
    /// `height` (module docs).
    pub fn mean_flow(target: f64, g0: f64, density: f64, viscosity: f64, height: f64) -> Self {
        let tau = density * height * height / viscosity;
        Drive::MeanFlow {
            target,
            gain: g0 / (target * tau),
        }
    }

    /// After a step of `dt` that left the bulk velocity `bulk()`: the force of the next step.
    pub fn update<const D: usize>(
        &self,
        force: &mut Vector<D>,
        bulk: impl FnOnce() -> f64,
        dt: f64,
    ) {
        if let Drive::MeanFlow { target, gain } = *self {
            force[0] += gain * dt * (target - bulk());
        }
    }
}

/// The volume (2D: area) of the box.
pub fn box_volume<const D: usize>(domain: &Domain<D>) -> f64 {
    (domain.max - domain.min).iter().product()
}
