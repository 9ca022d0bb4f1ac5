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
//!
//! * [`Projection::Rotational`]: the incremental projection in the rotational form of
//!   Timmermans, Minev & van de Vosse (1996). With implicit viscosity at νδt/h² ≫ 1 the
//!   increment lags: for a pressure error of wave number k the viscous solve absorbs most of
//!   its gradient, and only 1/(1 + θνδtk²) of the error is corrected per step (θ the implicit
//!   weight), so the pressure between a body and a wall a few spacings away settles over
//!   hundreds of steps. The rotational form adds −ρθν D̄ to the pressure,
//!   `p^{n+1} = p^n + φ − ρθν D̄`, D̄ the PPE's divergence D u* + τ_δt S p^n/ρ averaged over
//!   each particle's fluid neighbours with the kernel's weights (Shepard), which cancels that
//!   lag on smooth modes. D̄ vanishes at a steady state, so the steady state is the
//!   incremental one's. The average matters: on the particle-to-particle mode S p is ρ times
//!   the PPE's matrix, which the term would amplify without it (decision log).

use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::neighbourhood::Hood;
use crate::engine::stabilisation::PressureStabilisation;
use rayon::prelude::*;

/// The pressure projection in use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    Standard,
    Incremental,
    /// The incremental projection in rotational form (module docs).
    Rotational,
}

impl Projection {
    /// Whether the PPE solves for the increment (incremental, in either form).
    pub fn is_incremental(self) -> bool {
        self != Projection::Standard
    }
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
    /// ρθν of the rotational form (0: off; module docs).
    rotational: f64,
    /// W(0), the particle's own weight in the average.
    self_weight: f64,
    /// The PPE's divergence of this step averaged over the neighbours, for the rotational form.
    divergence: Vec<f64>,
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
            stabilisation: kind.is_incremental().then_some(stabilisation),
            rotational: 0.0,
            self_weight: 0.0,
            divergence: Vec::new(),
        }
    }

    /// The rotational form's ρθν (module docs), with the kernel's W(0) for the average
    /// (nothing unless the projection is [`Projection::Rotational`]).
    pub fn with_rotational(mut self, coefficient: f64, self_weight: f64) -> Self {
        if self.kind == Projection::Rotational {
            self.rotational = coefficient;
            self.self_weight = self_weight;
        }
        self
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.increment)
            + b(&self.pressure_ext)
            + b(&self.old_gradient)
            + b(&self.divergence)
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
        if self.rotational > 0.0 {
            self.average(hood, divergence);
        }
    }

    /// The Shepard average of `divergence` over each particle and its fluid neighbours.
    fn average(&mut self, hood: Hood<D>, divergence: &[f64]) {
        let (list, w) = (hood.list, &hood.sums.value);
        let (n, w0) = (divergence.len(), self.self_weight);
        self.divergence.resize(n, 0.0);
        self.divergence
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, out)| {
                let (mut sum, mut weight) = (w0 * divergence[i], w0);
                for k in list.range(i) {
                    let j = list.index[k] as usize;
                    if j < n {
                        sum += w[k] * divergence[j];
                        weight += w[k];
                    }
                }
                *out = sum / weight;
            });
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
            Projection::Incremental | Projection::Rotational => {
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
        if self.kind.is_incremental() {
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
            Projection::Incremental | Projection::Rotational => {
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
            Projection::Incremental | Projection::Rotational => {
                pressure
                    .par_iter_mut()
                    .zip(self.increment.par_iter())
                    .for_each(|(p, dp)| *p += dp);
                if self.rotational > 0.0 {
                    let c = self.rotational;
                    pressure
                        .par_iter_mut()
                        .zip(self.divergence.par_iter())
                        .for_each(|(p, d)| *p -= c * d);
                }
                &self.increment
            }
        }
    }
}
