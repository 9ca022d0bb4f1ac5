//! Hourglass control of the polymer stress (`scheme.conformation.hourglass_control`, ξ; 0 = off).
//!
//! The polymer force of eq. (24) is nested: ∇u^n by eq. (20), the conformation from it
//! (Step 3), then ∇·Φ by eq. (20) again. A relative velocity between neighbours that no
//! linear field explains (the particle-scale, "hourglass" part) barely enters either
//! gradient, so the stress never resists it; in a strongly stretched layer the only
//! restoring force at that scale is the EVSS difference α_V η0 (∇² − ∇·2D), whose coefficient
//! does not grow with the stretch. The start-up of a UCM liquid (β = 0, α_V = 0.01,
//! H/δr = 30, Wi = 32) grows such a mode in the sheared wall layers (validation pages, *High
//! Weissenberg number*) and breaks down at t ≈ 9.
//!
//! Following Wu, Zhang, Tang & Hu (2024) and Zhang, Wu, Lourenço & Hu (2024), who control
//! the hourglass modes of SPH elastic solids with a pair penalty on the part of v_ij that the
//! gradients do not predict, each fluid pair adds
//!
//! a_i = Σ_j ν_ij 2F_ij δV [u_i − u_j − ½(∇u_i + ∇u_j) r_ij],   ν_ij = ξ h c_ij,
//!
//! (F_ij = W'(r)/r, so the sum is Morris's Laplacian of the residual) with c_ij the speed of a
//! wave on the pair's axis e in the stretched polymer: c² = (max(e·τ̄_ij·e, 0) + G)/ρ, τ̄ the
//! pair's mean polymer stress and G = η_p/λ its modulus. The residual vanishes for a linear
//! field and is O(δr³) for a smooth one (the mean gradient cancels the quadratic term), so
//! the term is O(ξ h² c ∇³u): consistent, and zero for the resolved shear of a channel. Pairs
//! with wall mirrors are left out (their gradients are not formed).
//!
//! It is explicit: ν δt/h² = ξ (c δt/h), ξ times the elastic Courant number that the step
//! rule bounds (`elastic_courant` in `series.csv`). In the UCM channel that number stays
//! under 1.9 (ν δt/h² ≤ 0.38 at the case's ξ = 0.2); where a large implicit viscosity lets
//! the rule reach 6.4 (the cylinder array) it is 1.3 at ξ = 0.2, which the array at Wi = 4
//! ran through with the same stress noise as without the control (validation pages).

use crate::engine::dimension::{Dim, Dimension, Matrix, Sym, SymTensor, Vector};
use crate::engine::neighbourhood::Hood;
use crate::engine::rheology::Fluid;
use rayon::prelude::*;

/// The fields the control reads: u^n, ∇u^n and the conformation at n + ½.
#[derive(Clone, Copy)]
pub struct HourglassFields<'a, const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub velocity: &'a [Vector<D>],
    pub grad_u: &'a [Matrix<D>],
    pub conformation: &'a [Sym<D>],
}

/// The pair penalty on the unresolved relative velocity (module docs), of strength ξ.
#[derive(Clone, Debug)]
pub struct HourglassControl<const D: usize = 2> {
    xi: f64,
    /// The smoothing length h.
    h: f64,
    /// The polymer stress of each fluid particle (scratch).
    stress: Vec<Matrix<D>>,
}

impl<const D: usize> HourglassControl<D>
where
    Dim<D>: Dimension<D>,
{
    /// ξ > 0 and the smoothing length h.
    pub fn new(xi: f64, h: f64) -> Self {
        Self {
            xi,
            h,
            stress: Vec::new(),
        }
    }

    /// The control of strength ξ for a fluid with a polymer stress (None: ξ = 0 or none).
    pub fn chosen(xi: f64, viscoelastic: bool, h: f64) -> Option<Self> {
        (xi > 0.0 && viscoelastic).then(|| Self::new(xi, h))
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.stress)
    }

    /// Adds ρ a_i to `div_phi` (∇·Φ, which the predictor divides by ρ), from u^n, ∇u^n and
    /// the conformation at n + ½.
    pub fn add(
        &mut self,
        hood: Hood<D>,
        fluid: &Fluid,
        fields: HourglassFields<D>,
        div_phi: &mut [Vector<D>],
    ) {
        let HourglassFields {
            velocity,
            grad_u,
            conformation,
        } = fields;
        let Hood { list, sums, .. } = hood;
        let n = velocity.len();
        self.stress.resize(n, Matrix::zeros());
        self.stress
            .par_iter_mut()
            .zip(conformation.par_iter())
            .for_each(|(t, a)| *t = fluid.polymer_stress(a).to_mat());
        let rho = fluid.density;
        let modulus = fluid.viscosity * (1.0 - fluid.beta) / fluid.relaxation_time;
        let scale = 2.0 * sums.dv * self.xi * self.h * rho;
        let stress = &self.stress;
        div_phi.par_iter_mut().enumerate().for_each(|(i, d)| {
            let mut acc = Vector::<D>::zeros();
            for k in list.range(i) {
                let j = list.index[k] as usize;
                if j >= n {
                    continue;
                }
                let r = list.rij[k];
                let e = r / r.norm();
                let mean = (stress[i] + stress[j]) * 0.5;
                let c2 = (e.dot(&(mean * e)).max(0.0) + modulus) / rho;
                let residual = (velocity[i] - velocity[j]) - (grad_u[i] + grad_u[j]) * r * 0.5;
                acc += residual * (sums.factor[k] * c2.sqrt());
            }
            *d += acc * scale;
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::kernel::QuinticSpline;
    use crate::engine::math::{Mat2, Sym2, Vec2};
    use crate::engine::neighbours::{Domain, NeighbourList, NeighbourSearch};
    use crate::engine::operators::KernelSums;
    use crate::engine::rheology::{Model, ViscosityLaw};

    /// A periodic unit box of n × n particles, each displaced pseudo-randomly by up to
    /// `jitter`·δr.
    fn box_of(n: usize, jitter: f64) -> (Domain, Vec<Vec2>, NeighbourList, KernelSums) {
        let dr = 1.0 / n as f64;
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, true],
        };
        let pts: Vec<Vec2> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                let dx = ((k as f64 * 0.754_877_666).fract() - 0.5) * 2.0 * jitter * dr;
                let dy = ((k as f64 * 0.569_840_290).fract() - 0.5) * 2.0 * jitter * dr;
                domain.wrap(Vec2::new(
                    (i as f64 + 0.5) * dr + dx,
                    (j as f64 + 0.5) * dr + dy,
                ))
            })
            .collect();
        let kernel = QuinticSpline::for_spacing(dr);
        let mut list = NeighbourList::default();
        NeighbourSearch::new().build(&domain, &pts, pts.len(), kernel.support(), &mut list);
        let mut sums = KernelSums::default();
        sums.update(&list, &kernel, dr * dr);
        (domain, pts, list, sums)
    }

    /// UCM with G = η/λ = 1/32, the liquid of the breakdown in the module docs.
    fn ucm() -> Fluid {
        Fluid {
            model: Model::Ucm,
            density: 1.0,
            viscosity: 1.0,
            beta: 0.0,
            relaxation_time: 32.0,
            surface_tension: 0.0,
            law: ViscosityLaw::Constant,
        }
    }

    /// Consistency: a velocity field linear over each neighbourhood (linear in the
    /// minimum-image offset from one particle p, so exact near p) with its own gradient gets no
    /// acceleration on disordered particles, however stretched the polymer: the term leaves
    /// every resolved shear alone. Bound: round-off of sums of ~50 terms of size c·|u|/δr.
    #[test]
    fn a_linear_field_is_left_alone() {
        let (domain, pts, list, sums) = box_of(30, 0.3);
        let h = QuinticSpline::for_spacing(1.0 / 30.0).h();
        let p = pts[465];
        let (a, b) = (Vec2::new(1.7, -0.4), Mat2::new(0.3, -1.1, 2.0, 0.5));
        let u: Vec<Vec2> = pts
            .iter()
            .map(|x| a + b * domain.min_image(*x - p))
            .collect();
        let grad = vec![b; pts.len()];
        let stretched = vec![Sym2::new(1600.0, 40.0, 1.0); pts.len()];
        let mut control = HourglassControl::new(0.5, h);
        let mut acc = vec![Vec2::zeros(); pts.len()];
        control.add(
            Hood::without_walls(&list, &sums),
            &ucm(),
            HourglassFields {
                velocity: &u,
                grad_u: &grad,
                conformation: &stretched,
            },
            &mut acc,
        );
        for (x, a) in pts.iter().zip(&acc) {
            if domain.min_image(*x - p).norm() < 0.2 {
                assert!(a.norm() < 1e-9, "{a:?} at {x:?}");
            }
        }
    }

    /// The odd–even mode the nested operator cannot see: on a regular lattice the corrected
    /// gradient of u_x = (−1)^(i+j) is zero, so neither ∇u nor the stress resists it. The
    /// control opposes it at every particle, and the harder the more the polymer is stretched
    /// (A_xx = 1 600, the wall layers at the breakdown: measured 21.6× faster; pairs along x
    /// gain the ratio of the wave speeds, √A_xx = 40, pairs along y nothing). Bound 10×.
    #[test]
    fn the_odd_even_mode_is_damped_and_more_so_when_stretched() {
        let n = 30;
        let (_, _, list, sums) = box_of(n, 0.0);
        let h = QuinticSpline::for_spacing(1.0 / n as f64).h();
        let u: Vec<Vec2> = (0..n * n)
            .map(|k| Vec2::new(if (k / n + k % n) % 2 == 0 { 1.0 } else { -1.0 }, 0.0))
            .collect();
        let mut grad = vec![Mat2::zeros(); u.len()];
        sums.gradient_vector(&list, &u, &mut grad);
        assert!(grad.iter().all(|g| g.norm() < 1e-10));
        let rate = |a: Sym2| {
            let mut control = HourglassControl::new(0.1, h);
            let mut acc = vec![Vec2::zeros(); u.len()];
            let conformation = vec![a; u.len()];
            control.add(
                Hood::without_walls(&list, &sums),
                &ucm(),
                HourglassFields {
                    velocity: &u,
                    grad_u: &grad,
                    conformation: &conformation,
                },
                &mut acc,
            );
            let rates: Vec<f64> = acc.iter().zip(&u).map(|(a, u)| a.dot(u)).collect();
            assert!(rates.iter().all(|&r| r < 0.0));
            -rates.iter().sum::<f64>() / rates.len() as f64
        };
        let at_rest = rate(Sym2::new(1.0, 0.0, 1.0));
        let stretched = rate(Sym2::new(1600.0, 0.0, 1.0 / 1600.0));
        assert!(stretched > 10.0 * at_rest, "{stretched} against {at_rest}");
    }
}
