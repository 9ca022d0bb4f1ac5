//! The pressure stabilisation of the incremental projection: what makes its steady state
//! well posed and independent of δt.
//!
//! The incremental projection ([`crate::engine::projection`]) is steady when the increment
//! vanishes, i.e. when `D u = 0` with the corrected divergence (20) and `−Gp/ρ + ν∇²u + g = 0`
//! with the corrected gradient: the collocated saddle-point problem of the SPH operators. Its
//! gradient is nearly blind to pressure modes that alternate from particle to particle, which
//! the compact Laplacian (21) of the PPE sees, so that problem has no stable pressure: solved
//! directly on the confined cylinder (R/δr = 10, fixed particles) its pressure is a
//! checkerboard of amplitude 10⁶ and its drag K = 726. Each step moves p^n towards it at a rate
//! per *step*, so a time-stepped "steady" drag depended on the number of steps taken (K = 132.98,
//! 135.07, 140.81 at 361, 724 and 1 428 steps). The standard projection is stabilised by its
//! own splitting, `D u = δt (∇²_PPE − D G) p` at steady state, which is why its steady state
//! moves with δt instead.
//!
//! Here the continuity of the steady state is `D u + τ S p/ρ = 0` with a fixed time τ, and the
//! PPE of the increment gains the term that makes it so: its divergence is
//! `D u* + τ_δt S p^n/ρ`, with `τ_δt = τ δt/(τ + δt)`. S is the Laplacian defect of Rhie & Chow
//! in pair form over the fluid neighbours,
//!
//! ```text
//!     (S p)_i = Σ_j −w_ij [ (p_i − p_j) − r_ij·(g_i + g_j)/2 ],
//! ```
//!
//! with w_ij the PPE's weights (21) and g the Bonet–Lok gradient over the fluid neighbours
//! alone (exact for a linear pressure in a truncated support, where the mirrors' even pressure
//! is not). Each pair's bracket is O(|r_ij|³) for a smooth pressure, so the term is a
//! consistent O(h) perturbation of continuity even at walls; on a mode alternating from
//! particle to particle g ≈ 0 and S p = ρ A p with A the PPE's matrix, so the mode of p^n
//! decays by δt/(τ + δt) each step whatever δt is. τ = ρh²/η0, the viscous time over a
//! smoothing length: on the confined cylinder the steady drag changes by 0.01 % between
//! τ = 0.5 and 2 ρh²/η0 and falls off below 0.1 (the stabilisation too weak to hold the mode).
//! With implicit viscosity in creeping flow τ ≪ δt and τ_δt = τ to within a few per cent.

use crate::engine::dimension::{Dim, Dimension, Matrix, Vector};
use crate::engine::neighbourhood::Hood;
use rayon::prelude::*;

/// The stabilisation's time scale and buffers.
#[derive(Clone, Debug)]
pub struct PressureStabilisation<const D: usize = 2> {
    /// τ of the module docs (∞ for an inviscid fluid, when τ_δt = δt).
    time: f64,
    /// g: the pressure gradient over the fluid neighbours.
    gradient: Vec<Vector<D>>,
}

impl<const D: usize> PressureStabilisation<D>
where
    Dim<D>: Dimension<D>,
{
    /// τ = ρh²/η0 for smoothing length `h`.
    pub fn new(density: f64, viscosity: f64, h: f64) -> Self {
        let time = if viscosity > 0.0 {
            density * h * h / viscosity
        } else {
            f64::INFINITY
        };
        Self {
            time,
            gradient: Vec::new(),
        }
    }

    /// τ of the module docs.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// τ_δt = τ δt/(τ + δt).
    pub fn time_at(&self, dt: f64) -> f64 {
        Self::combined(self.time, dt)
    }

    /// τ δt/(τ + δt) of a time τ (δt for τ = ∞).
    fn combined(time: f64, dt: f64) -> f64 {
        if time.is_finite() {
            time * dt / (time + dt)
        } else {
            dt
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.gradient)
    }

    /// Adds `τ_δt (S p)_i / ρ` to each fluid particle's divergence (module docs).
    pub fn add(
        &mut self,
        hood: Hood<D>,
        pressure: &[f64],
        density: f64,
        dt: f64,
        divergence: &mut [f64],
    ) {
        let Hood { list, sums, .. } = hood;
        let n = pressure.len();
        self.gradient.resize(n, Vector::<D>::zeros());
        fluid_gradient(hood, pressure, &mut self.gradient);
        let g = &self.gradient;
        let uniform = self.time_at(dt) / density;
        let time = self.time;
        divergence.par_iter_mut().enumerate().for_each(|(i, d)| {
            // Under graded resolution τ_i = ρh_i²/η0, each row's own smoothing length.
            let scale = if sums.rows.is_empty() {
                uniform
            } else {
                Self::combined(time * sums.row_area_ratio(i), dt) / density
            };
            let mut defect = 0.0;
            for k in list.range(i) {
                let j = list.index[k] as usize;
                if j >= n {
                    continue;
                }
                let linear = list.rij[k].dot(&(g[i] + g[j])) * 0.5;
                defect -= sums.ppe_weight(list, k) * (pressure[i] - pressure[j] - linear);
            }
            *d += scale * defect;
        });
    }
}

/// The Bonet–Lok gradient of `p` over each particle's fluid neighbours only, with the
/// correction of that subset: `B⁻¹ Σ_j (p_j − p_i) ∇W_ij δV`, `B = Σ_j r_ji ⊗ ∇W_ij δV`
/// (zero where B is singular).
pub fn fluid_gradient<const D: usize>(hood: Hood<D>, p: &[f64], out: &mut [Vector<D>])
where
    Dim<D>: Dimension<D>,
{
    let Hood { list, sums, .. } = hood;
    let n = p.len();
    out.par_iter_mut().enumerate().for_each(|(i, g)| {
        let mut b = Matrix::<D>::zeros();
        let mut sum = Vector::<D>::zeros();
        for k in list.range(i) {
            let j = list.index[k] as usize;
            if j >= n {
                continue;
            }
            let grad_w = sums.grad_w(list, k);
            b -= grad_w * list.rij[k].transpose();
            sum += (p[j] - p[i]) * grad_w;
        }
        *g = Dim::<D>::try_inverse(&b).map_or(Vector::<D>::zeros(), |inverse| inverse * sum);
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::kernel::QuinticSpline;
    use crate::engine::math::Vec2;
    use crate::engine::neighbours::{Domain, NeighbourList, NeighbourSearch};
    use crate::engine::operators::KernelSums;

    /// A lattice of `m × m` particles of spacing δr, not periodic (truncated supports at its
    /// edges), with its lists and kernel sums.
    fn lattice(m: usize) -> (Vec<Vec2>, NeighbourList, KernelSums) {
        let dr = 0.1;
        let kernel = QuinticSpline::for_spacing(dr);
        let points: Vec<Vec2> = (0..m * m)
            .map(|k| Vec2::new((k % m) as f64 * dr, (k / m) as f64 * dr))
            .collect();
        let domain = Domain {
            min: Vec2::new(-1.0, -1.0),
            max: Vec2::new(m as f64 * dr + 1.0, m as f64 * dr + 1.0),
            periodic: [false, false],
        };
        let mut list = NeighbourList::default();
        let mut search = NeighbourSearch::default();
        search.build(&domain, &points, points.len(), kernel.support(), &mut list);
        let mut sums = KernelSums::default();
        sums.update(&list, &kernel, dr * dr);
        (points, list, sums)
    }

    /// The fluid gradient is exact for a linear pressure, at the edges too.
    #[test]
    fn fluid_gradient_is_exact_for_linear_pressure() {
        let (points, list, sums) = lattice(12);
        let p: Vec<f64> = points.iter().map(|r| 3.0 * r.x - 2.0 * r.y + 1.0).collect();
        let mut g = vec![Vec2::zeros(); p.len()];
        fluid_gradient(Hood::without_walls(&list, &sums), &p, &mut g);
        for gi in &g {
            assert!((gi - Vec2::new(3.0, -2.0)).norm() < 1e-10, "{gi}");
        }
    }

    /// A linear pressure has no defect anywhere; a checkerboard has the defect of the PPE's
    /// own Laplacian (its gradient is nearly zero in full support).
    #[test]
    fn defect_vanishes_for_linear_pressure_and_not_for_a_checkerboard() {
        let (points, list, sums) = lattice(16);
        let n = points.len();
        let mut stab = PressureStabilisation::new(1.0, 1.0, 0.13);
        let linear: Vec<f64> = points.iter().map(|r| 5.0 * r.x + r.y).collect();
        let mut d = vec![0.0; n];
        stab.add(Hood::without_walls(&list, &sums), &linear, 1.0, 1.0, &mut d);
        assert!(d.iter().all(|x| x.abs() < 1e-9), "{:?}", &d[..4]);
        let board: Vec<f64> = (0..n)
            .map(|k| {
                if (k % 16 + k / 16) % 2 == 0 {
                    1.0
                } else {
                    -1.0
                }
            })
            .collect();
        let mut d = vec![0.0; n];
        stab.add(Hood::without_walls(&list, &sums), &board, 1.0, 1.0, &mut d);
        // The middle particle, in full support: the defect equals the PPE's row times p.
        let i = 8 * 16 + 8;
        let row: f64 = list
            .range(i)
            .map(|k| -sums.ppe_weight(&list, k) * (board[i] - board[list.index[k] as usize]))
            .sum();
        let tau = stab.time_at(1.0);
        assert!(row.abs() > 1.0);
        assert!(
            (d[i] - tau * row).abs() < 0.05 * (tau * row).abs(),
            "{} {}",
            d[i],
            row
        );
    }
}
