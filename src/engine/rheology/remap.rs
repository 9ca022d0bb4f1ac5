//! The ALE remap of the conformation: the term δt u_ps·∇Ψ of (30a)/(31) (δt u_ps·∇A of (10)),
//! which carries a shifted particle's tensor to its new position (King & Lind §III E; in the
//! Eulerian frame, u_ps = −u, it is the whole transport).
//!
//! The paper evaluates it with the corrected gradient (20), a central first-order Taylor
//! extrapolation. Where the tensor has a sharp minimum that extrapolation can leave the range
//! of the values around it: measured at P2 (cylinder array, R/δr = 36, Wi = 0.8, ⟨u⟩ held at
//! 1), the particle at the front stagnation point, 0.46δr from the cylinder, shifted by
//! 0.005δr a step towards the wall, was the minimum of its neighbourhood (tr Ψ ≈ 0; det A 4
//! at 1.4δr and 13 at 2δr, the stagnation point's stress layer) and still lost 2.8·10⁻³ of
//! tr Ψ = ln det A every step to the remap, step after step: det A fell to 0.86 while the rest of the update keeps it ≥ 1 by construction (a traceless
//! gradient, the relaxation a convex combination with I).
//!
//! [`Remap::Limited`] (default) keeps exactly that invariant: it scales a particle's
//! increment by the largest φ ∈ [0, 1] that keeps its tr Ψ (= ln det A) at or above the
//! smallest tr Ψ of its neighbours (mirrors included) and itself. Then tr Ψ* ≥ min_j tr Ψ_j, so
//! det A ≥ 1 for Oldroyd-B holds by induction; only a particle at a minimum of tr Ψ whose
//! increment would deepen it is touched.
//!
//! A first version bounded all of Ψ_xx, Ψ_xy, Ψ_yy and tr Ψ to the neighbours' range, the
//! limiter of Barth & Jespersen (1989). That range limiter clips at every extremum, and in a
//! channel every particle of the first wall layer is one: its even mirrors copy its Ψ, so it
//! is the largest tr Ψ of its neighbourhood, and every shift towards the wall had its
//! increment cut to zero while its neighbours' went through. Measured on start-up Poiseuille
//! (Re = 1, β = 0.1, Wi = 128, H/δr = 30, implicit viscosity, t = 15): time-mean L2 error 90 %
//! (the noise of ln tr A from 0.03 to 0.64, u_c leaving the series from t ≈ 5) against 2.8 %
//! with the central increment and 2.8 % with this floor; UCM (β = 0, α_V = 0.01) broke down
//! at t = 2.3 (Wi = 16) and 1.8 (Wi = 32) against 13.1 and 9.3 with the floor. [`Remap::Upwind`]
//! keeps the range limiter (its one-sided increment damps what the clipping leaves).

use crate::engine::dimension::SymTensor;
use crate::engine::neighbours::NeighbourList;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the remap increment is formed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Remap {
    /// The paper's: the corrected-gradient Taylor increment as it is.
    Central,
    /// That increment, scaled where it would take tr Ψ below the neighbours' smallest
    /// (module docs): det A ≥ 1 for Oldroyd-B.
    #[default]
    Limited,
    /// The increment from the one-sided corrected gradient of the neighbours the particle
    /// moves towards ([`KernelSums::advective_tensor_upwind`]), limited to the neighbours'
    /// range of Ψ_xx, Ψ_xy, Ψ_yy and tr Ψ (Barth & Jespersen 1989; [`limit_increments`]).
    ///
    /// For the Eulerian frame, where the remap is the whole transport of Ψ. A central
    /// gradient with the explicit step has no dissipation for pure transport, and nothing
    /// damps an odd–even mode faster than the relaxation 1/λ. Measured in the lid-driven
    /// cavity (Oldroyd-B, β = 0.5, Wi = 1, L/δr = 40, fixed particles): from t ≈ 2 the
    /// velocity in the second row under the lid alternated from particle to particle near
    /// the upstream corner (u = 0.16, 0.13, 0.05 at x = 0.06–0.11, then negative). The
    /// noise spread along the lid, and tr A grew without bound (1 190 at t = 13). Lagrangian
    /// particles, whose remap is only the shift, keep tr A at 65–92 with the largest under
    /// the lid at x ≈ 0.42, where an independent finite-volume solution has it. The
    /// one-sided gradient is the SPH counterpart of first-order upwinding.
    ///
    /// [`KernelSums::advective_tensor_upwind`]: crate::engine::operators::KernelSums::advective_tensor_upwind
    Upwind,
    /// The limited increment with the second-order term of its Taylor series (Lax &
    /// Wendroff 1960): with L = u_ps·∇ (frozen over the step), Ψ + δt LΨ + ½δt² L²Ψ, the
    /// rate `LΨ + ½δt L(LΨ)`, then the trace floor of [`Remap::Limited`].
    ///
    /// For the Eulerian frame. The first-order increment with a central gradient is forward
    /// Euler on a transport whose symbol is imaginary, i s(k)·u: each step multiplies a
    /// mode by |1 + iz| = √(1 + z²), z = δt|u| s(k), a growth rate ½δt u² s² per unit time.
    /// With δt = f·h/U and s ≤ 0.865/h (the corrected gradient's largest symbol) that is
    /// ≈ 0.37 f U/h, against the relaxation 1/λ that damps it: it rises as f/h. Measured on
    /// start-up Poiseuille (Re = Wi = 1, β = 0.1, Crank–Nicolson, Eulerian): the conformation
    /// noise grew from t ≈ 6 and the run broke down at t = 9.1 at H/δr = 60 with f = 0.4
    /// and at 9.7 at H/δr = 120 with f = 0.2 (the same f/h), while 60 with 0.2 and 120 with
    /// 0.1 ran through. With the second-order term the factor is |1 + iz − z²/2| =
    /// √(1 + z⁴/4): the growth rate falls by z²/4 (1/130 at f = 0.2). In the Lagrangian frame
    /// δt u_ps is the shift, z ≪ 1, and the term is the second-order Taylor remap.
    SecondOrder,
}

/// Increments below this fraction of the tensor's size are round-off and are not limited
/// (they can move tr Ψ, hence det A, by no more than that).
const ROUND_OFF: f64 = 1e-12;

/// The most components a limited remap keeps in range (in space: six and the trace).
const MAX_COMPONENTS: usize = 7;

/// The components a limited remap keeps in range: Ψ_ab (a ≤ b, row by row: Ψ_xx, Ψ_xy, Ψ_yy
/// in the plane) and tr Ψ (= ln det A), in the first `count` of the array.
fn components<S: SymTensor>(t: &S) -> ([f64; MAX_COMPONENTS], usize) {
    let mut out = [0.0; MAX_COMPONENTS];
    let mut count = 0;
    for a in 0..S::DIM {
        for b in a..S::DIM {
            out[count] = t.entry(a, b);
            count += 1;
        }
    }
    out[count] = t.trace();
    (out, count + 1)
}

/// The largest φ ∈ [0, 1] with `value + φ·increment` within `[low, high]` (`low ≤ value ≤
/// high`).
fn limit(value: f64, increment: f64, low: f64, high: f64) -> f64 {
    if increment > 0.0 && value + increment > high {
        ((high - value) / increment).max(0.0)
    } else if increment < 0.0 && value + increment < low {
        ((low - value) / increment).max(0.0)
    } else {
        1.0
    }
}

/// Scales each particle's remap rate `rate[i]` (its increment is `dt·rate[i]`) so that its
/// tr Ψ stays at or above the smallest tr Ψ of `ext` (the tensors of particles and ghosts)
/// over its neighbours and itself ([`Remap::Limited`]).
pub fn keep_trace_floor<S: SymTensor, const D: usize>(
    list: &NeighbourList<D>,
    ext: &[S],
    dt: f64,
    rate: &mut [S],
) {
    rate.par_iter_mut().enumerate().for_each(|(i, r)| {
        let own = ext[i].trace();
        let low = list
            .range(i)
            .map(|k| ext[list.index[k] as usize].trace())
            .fold(own, f64::min);
        let step = r.trace() * dt;
        let negligible = ROUND_OFF * (1.0 + own.abs());
        if step < -negligible {
            let phi = limit(own, step, low, f64::INFINITY);
            if phi < 1.0 {
                *r = *r * phi;
            }
        }
    });
}

/// Scales each particle's remap rate `rate[i]` (its increment is `dt·rate[i]`) so that the
/// remapped tensor stays within the range of `ext` (the tensors of particles and ghosts)
/// over its neighbours and itself ([`Remap::Upwind`]).
pub fn limit_increments<S: SymTensor, const D: usize>(
    list: &NeighbourList<D>,
    ext: &[S],
    dt: f64,
    rate: &mut [S],
) {
    rate.par_iter_mut().enumerate().for_each(|(i, r)| {
        let (own, count) = components(&ext[i]);
        let own = &own[..count];
        let (mut low, mut high) = ([0.0; MAX_COMPONENTS], [0.0; MAX_COMPONENTS]);
        low[..count].copy_from_slice(own);
        high[..count].copy_from_slice(own);
        for k in list.range(i) {
            let (c, _) = components(&ext[list.index[k] as usize]);
            for q in 0..count {
                low[q] = low[q].min(c[q]);
                high[q] = high[q].max(c[q]);
            }
        }
        let (step, _) = components(&(*r * dt));
        // A component whose increment is at round-off level (e.g. Ψ_xy on a channel's
        // centre-line, where the range is round-off too) does not limit the others: the
        // ratio of two round-off numbers would switch them on and off at random.
        let negligible = ROUND_OFF * (1.0 + own.iter().fold(0.0_f64, |m, v| m.max(v.abs())));
        let phi = (0..count)
            .filter(|&q| step[q].abs() > negligible)
            .map(|q| limit(own[q], step[q], low[q], high[q]))
            .fold(1.0, f64::min);
        if phi < 1.0 {
            *r = *r * phi;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Sym2;

    fn list(rows: &[&[u32]]) -> NeighbourList {
        let mut offsets = vec![0];
        let mut index = Vec::new();
        for row in rows {
            index.extend_from_slice(row);
            offsets.push(index.len());
        }
        NeighbourList {
            offsets,
            index,
            rij: Vec::new(),
        }
    }

    fn diag(v: f64) -> Sym2 {
        Sym2::new(v, 0.0, v)
    }

    #[test]
    fn an_increment_inside_the_range_is_kept_bit_for_bit() {
        let ext = [
            diag(1.0),
            Sym2::new(0.0, -0.5, 0.0),
            Sym2::new(2.0, 0.5, 2.0),
        ];
        let mut rate = [Sym2::new(0.3, -0.1, 0.2), Sym2::ZERO, Sym2::ZERO];
        let before = rate[0];
        limit_increments(&list(&[&[1, 2], &[0], &[0]]), &ext, 1.0, &mut rate);
        assert_eq!(rate[0], before);
    }

    #[test]
    fn the_floor_keeps_a_maximum_s_increment_and_stops_a_minimum_from_deepening() {
        // Particle 0 is the largest tr Ψ of its neighbourhood (a channel's first wall layer,
        // its even mirror a copy of it): a rising increment goes through whole, which the
        // range limiter cut to zero.
        let rows = [&[1u32, 2][..], &[0][..], &[0][..]];
        let ext = [diag(1.0), diag(1.0), diag(0.5)];
        let mut rate = [Sym2::new(0.3, 0.1, 0.2), Sym2::ZERO, Sym2::ZERO];
        keep_trace_floor(&list(&rows), &ext, 1.0, &mut rate);
        assert_eq!(rate[0], Sym2::new(0.3, 0.1, 0.2));
        let mut ranged = rate;
        limit_increments(&list(&rows), &ext, 1.0, &mut ranged);
        assert_eq!(ranged[0], Sym2::ZERO);
        // At the minimum (tr Ψ = 0, det A = 1) a falling trace is stopped at the floor.
        let ext = [Sym2::ZERO, diag(0.5), Sym2::new(1.0, 0.2, 0.0)];
        let mut rate = [Sym2::new(-0.01, 0.3, 0.0), Sym2::ZERO, Sym2::ZERO];
        keep_trace_floor(&list(&rows), &ext, 1.0, &mut rate);
        assert_eq!(rate[0], Sym2::ZERO);
        // Above the floor a falling trace may fall to it, not past it.
        let ext = [diag(0.1), diag(0.5), diag(0.05)];
        let mut rate = [diag(-0.1), Sym2::ZERO, Sym2::ZERO];
        keep_trace_floor(&list(&rows), &ext, 1.0, &mut rate);
        let after = ext[0] + rate[0];
        assert!((after.xx + after.yy - 0.1).abs() < 1e-15);
    }

    #[test]
    fn a_minimum_is_not_deepened_and_the_trace_stays_in_range() {
        // Particle 0 is its neighbourhood's minimum (tr Ψ = 0, as at det A = 1): a negative
        // increment is removed whole; a positive one overshooting the largest neighbour
        // is cut to reach it exactly.
        let ext = [Sym2::ZERO, diag(0.5), Sym2::new(1.0, 0.2, 0.0)];
        let rows = [&[1u32, 2][..], &[0][..], &[0][..]];
        let mut rate = [diag(-0.01), Sym2::ZERO, Sym2::ZERO];
        limit_increments(&list(&rows), &ext, 1.0, &mut rate);
        assert_eq!(rate[0], Sym2::ZERO);
        let mut rate = [Sym2::new(2.0, 0.0, 0.0), Sym2::ZERO, Sym2::ZERO];
        limit_increments(&list(&rows), &ext, 0.5, &mut rate);
        // xx may rise to 1.0 (φ = 1), the trace to 1.0 (φ = 1): unchanged; at dt = 1 the
        // step 2.0 is cut to 1.0.
        assert_eq!(rate[0], Sym2::new(2.0, 0.0, 0.0));
        limit_increments(&list(&rows), &ext, 1.0, &mut rate);
        assert!((rate[0].xx - 1.0).abs() < 1e-15);
    }
}
