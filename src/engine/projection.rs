//! The pressure projection, steps 4–6 (King & Lind eqs. (24)–(26)): which pressure the PPE
//! solves for, and what the predictor carries of the old one.
//!
//! * [`Projection::Standard`], the paper's: the predictor has no pressure gradient and the
//!   PPE gives p^{n+1}, warm-started from p^n. Its splitting error is O(νδt/L²) wherever
//!   ∇p ≠ 0: negligible at the explicit viscous limit δt ≤ 0.2h²/ν, O(1) with implicit
//!   viscosity in creeping flow.
//! * [`Projection::Incremental`] (pressure correction): the predictor carries −∇p^n/ρ and the
//!   PPE gives the increment p^{n+1} − p^n, started from zero (it vanishes as the flow
//!   settles). Its PPE carries the [`PressureStabilisation`] of p^n, without which its steady
//!   state has no stable pressure; with it the steady state does not depend on δt.

use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::neighbourhood::Hood;
use crate::engine::stabilisation::PressureStabilisation;
use rayon::prelude::*;

/// The pressure projection in use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    Standard,
    Incremental,
}

/// The projection's buffers.
#[derive(Clone, Debug)]
pub struct ProjectionStage<const D: usize = 2> {
    pub kind: Projection,
    /// p^{n+1} − p^n (incremental).
    increment: Vec<f64>,
    pressure_ext: Vec<f64>,
    old_gradient: Vec<Vector<D>>,
    /// The incremental projection's stabilisation (None for the standard one).
    stabilisation: Option<PressureStabilisation<D>>,
}

impl<const D: usize> ProjectionStage<D>
where
    Dim<D>: Dimension<D>,
{
    /// The projection `kind`; `stabilisation` is the incremental one's
    /// ([`PressureStabilisation::new`]), dropped by the standard one.
    pub fn new(kind: Projection, stabilisation: PressureStabilisation<D>) -> Self {
        Self {
            kind,
            increment: Vec::new(),
            pressure_ext: Vec::new(),
            old_gradient: Vec::new(),
            stabilisation: (kind == Projection::Incremental).then_some(stabilisation),
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.increment)
            + b(&self.pressure_ext)
            + b(&self.old_gradient)
            + self
                .stabilisation
                .as_ref()
                .map_or(0, PressureStabilisation::heap_bytes)
    }

    /// Step 5, incremental projection: the stabilisation of p^n added to the PPE's
    /// divergence ∇·u* (nothing for the standard projection).
    pub fn stabilise(
        &mut self,
        hood: Hood<D>,
        pressure: &[f64],
        density: f64,
        dt: f64,
        divergence: &mut [f64],
    ) {
        if let Some(stabilisation) = self.stabilisation.as_mut() {
            stabilisation.add(hood, pressure, density, dt, divergence);
        }
    }

    /// Step 4: ∇p^n for the predictor's −∇p^n/ρ (incremental), or None.
    pub fn old_pressure_gradient(
        &mut self,
        hood: Hood<D>,
        pressure: &[f64],
    ) -> Option<&[Vector<D>]> {
        let Hood { list, sums, ghosts } = hood;
        match self.kind {
            Projection::Standard => None,
            Projection::Incremental => {
                self.old_gradient
                    .resize(pressure.len(), Vector::<D>::zeros());
                ghosts.extend_pressure(pressure, &mut self.pressure_ext);
                sums.gradient_scalar(list, &self.pressure_ext, &mut self.old_gradient);
                Some(&self.old_gradient)
            }
        }
    }

    /// Step 5: Dirichlet values of p^{n+1} turned into values of the unknown.
    pub fn dirichlet_for_unknown(&self, dirichlet: &mut [f64], pressure: &[f64]) {
        if self.kind == Projection::Incremental {
            dirichlet
                .par_iter_mut()
                .zip(pressure.par_iter())
                .for_each(|(p, old)| *p -= old);
        }
    }

    /// Step 5: the PPE's unknown with its initial guess: p^{n+1} from p^n (or from zero
    /// without `warm_start`), or the increment from zero.
    pub fn unknown<'a>(&'a mut self, pressure: &'a mut [f64], warm_start: bool) -> &'a mut [f64] {
        match self.kind {
            Projection::Standard => {
                if !warm_start {
                    pressure.iter_mut().for_each(|p| *p = 0.0);
                }
                pressure
            }
            Projection::Incremental => {
                self.increment.clear();
                self.increment.resize(pressure.len(), 0.0);
                &mut self.increment
            }
        }
    }

    /// Step 6: p^{n+1} from the solved unknown; returns the field whose gradient corrects u*
    /// (p^{n+1}, or the increment).
    pub fn update_pressure<'a>(&'a self, pressure: &'a mut [f64]) -> &'a [f64] {
        match self.kind {
            Projection::Standard => pressure,
            Projection::Incremental => {
                pressure
                    .par_iter_mut()
                    .zip(self.increment.par_iter())
                    .for_each(|(p, dp)| *p += dp);
                &self.increment
            }
        }
    }
}
