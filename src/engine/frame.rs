//! The frame of the ALE formulation (King & Lind §III A): particles that move with the fluid
//! and the shifting velocity (Lagrangian), or particles held fixed (Eulerian, u_ps = −u).
//! Steps 1 and 7 of the time step are the frame's; the Eulerian frame omits both and builds
//! its neighbour lists, kernel sums and PPE matrix once. Written for D = 2 or 3 dimensions.

use crate::engine::neighbours::Domain;
use nalgebra::SVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How particles move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Frame {
    /// Particles move with u + u_ps (u_ps from shifting, or 0).
    Lagrangian,
    /// Particles fixed, u_ps = −u; steps 1 and 7 omitted.
    Eulerian,
}

/// The velocities that move a particle over a step, eq. (27).
#[derive(Clone, Copy)]
pub struct StepVelocities<'a, const D: usize = 2> {
    /// u^n.
    pub old: &'a [SVector<f64, D>],
    /// u^{n+1}.
    pub new: &'a [SVector<f64, D>],
    /// The shift velocity u_ps.
    pub shift: &'a [SVector<f64, D>],
}

impl Frame {
    /// Whether the particle configuration changes from step to step (and with it the
    /// neighbour lists, kernel sums and the PPE matrix).
    pub fn moves_particles(self) -> bool {
        self == Frame::Lagrangian
    }

    /// Step 1, eq. (23): the positions r* at which step 2 builds its neighbourhoods,
    /// r^n + δt u^n, or r^n for fixed particles.
    pub fn intermediate_positions<const D: usize>(
        self,
        domain: &Domain<D>,
        position: &[SVector<f64, D>],
        velocity: &[SVector<f64, D>],
        dt: f64,
        out: &mut Vec<SVector<f64, D>>,
    ) {
        out.clear();
        match self {
            Frame::Lagrangian => out.extend(
                position
                    .iter()
                    .zip(velocity)
                    .map(|(r, u)| domain.wrap(r + dt * u)),
            ),
            Frame::Eulerian => out.extend_from_slice(position),
        }
    }

    /// Step 7, eq. (27): r^{n+1} = r^n + δt/2 (u^n + u^{n+1} + 2u_ps) (nothing for fixed
    /// particles).
    pub fn advance_positions<const D: usize>(
        self,
        domain: &Domain<D>,
        position: &mut [SVector<f64, D>],
        u: StepVelocities<D>,
        dt: f64,
    ) {
        if self == Frame::Eulerian {
            return;
        }
        let StepVelocities { old, new, shift } = u;
        position.par_iter_mut().enumerate().for_each(|(i, r)| {
            *r = domain.wrap(*r + 0.5 * dt * (old[i] + new[i] + 2.0 * shift[i]));
        });
    }
}
