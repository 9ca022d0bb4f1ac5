//! The free-surface pressure (King & Lind §III C, eqs. (34)–(35)): the Dirichlet value of the
//! PPE rows of free-surface (FS) particles. A rule is a type implementing
//! [`SurfacePressureRule`]; the case file names one through [`SurfacePressure`].
//!
//! * [`NormalStress`], eq. (35a): `p = 2η_s n·D·n + n·τ_p·n`, the normal component of
//!   σ·n = 0 (34), evaluated with the predictor's velocity gradient ∇u* and τ_p^{n+½}.
//! * [`Zero`]: the usual ISPH condition p = 0.

use crate::engine::free_surface::FreeSurface;
use crate::engine::math::{Mat2, Sym2, Vec2};
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use crate::engine::rheology::Fluid;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Fewest neighbours (a quarter of a full support's ~48) for which a free-surface particle's
/// velocity gradient, and so its normal-stress pressure (35a), is trusted. Measured: the
/// Oldroyd-B jet at Wi = 5/3 broke down at t = 0.30 s after a surface particle with 7
/// neighbours carried p = 912 Pa from (35a). A sparser one takes p = 0, or with
/// [`SurfacePressure::NormalStressNeighbours`] the kernel-weighted mean of its trusted surface
/// neighbours' values ([`sparse_surface_pressure`]; p = 0 where it has none).
pub(crate) const MIN_SURFACE_NEIGHBOURS: usize = 12;

/// The rule named in a case file (`scheme.free_surface.pressure`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum SurfacePressure {
    /// King & Lind's normal-stress balance (35a): p = 2η_s n·D·n + n·τ_p·n; p = 0 on sparse
    /// surface particles.
    #[default]
    NormalStress,
    /// (35a), with sparse surface particles taking their trusted surface neighbours' mean.
    NormalStressNeighbours,
    /// The usual ISPH condition p = 0.
    Zero,
}

/// Which neighbours the velocity gradient of (35a) is taken over (`experimental.surface_gradient`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceGradient {
    /// The corrected gradient (20) over the whole support, as everywhere else (the paper's).
    #[default]
    Full,
    /// Only the neighbours on the particle's own side of its surface, those less than
    /// [`OWN_SIDE_REACH`]·δr out along its normal, with the Bonet–Lok correction of that
    /// subset ([`own_side_gradient`]). At a true free surface nothing lies further out and
    /// the two agree to the correction's consistency; at a crack or a peeling skin narrower
    /// than the support they differ, and only this one is the surface's own strain rate.
    OwnSide,
}

/// How far out along its normal (in δr) a neighbour may lie and still count as on a surface
/// particle's own side ([`SurfaceGradient::OwnSide`]): a rough surface's own row lies within
/// about ±0.3δr of the tangent.
pub const OWN_SIDE_REACH: f64 = 0.5;

impl SurfacePressure {
    /// The rule, with (35a)'s velocity gradient taken as `gradient` says.
    pub fn rule(self, gradient: SurfaceGradient) -> Box<dyn SurfacePressureRule> {
        match self {
            SurfacePressure::NormalStress => Box::new(NormalStress {
                gradient,
                ..Default::default()
            }),
            SurfacePressure::NormalStressNeighbours => Box::new(NormalStress {
                sparse_from_neighbours: true,
                gradient,
                ..Default::default()
            }),
            SurfacePressure::Zero => Box::new(Zero),
        }
    }
}

/// What a free-surface pressure may depend on.
pub struct SurfaceInputs<'a> {
    pub list: &'a NeighbourList,
    pub sums: &'a KernelSums,
    pub surface: &'a FreeSurface,
    /// φ = η(γ̇)/η0 per row of a generalised Newtonian fluid (empty: a uniform viscosity).
    pub viscosity_factor: &'a [f64],
    /// The predictor's velocity u*, fluid values followed by the ghosts'.
    pub velocity_star: &'a [Vec2],
    pub fluid: &'a Fluid,
    /// A^{n+½} (empty for a Newtonian fluid).
    pub conformation: &'a [Sym2],
    /// Rows whose pressure is prescribed elsewhere (an inflow buffer: p = 0).
    pub prescribed: &'a [bool],
}

/// A free-surface pressure condition.
pub trait SurfacePressureRule: Send + Sync {
    /// Writes the Dirichlet pressure of the FS particles into `out` (zero on entry; values
    /// of other rows are not read).
    fn pressure(&mut self, inputs: &SurfaceInputs, out: &mut [f64]);
    /// Heap bytes held.
    fn heap_bytes(&self) -> usize {
        0
    }
}

/// p = 0 on the free surface.
pub struct Zero;

impl SurfacePressureRule for Zero {
    fn pressure(&mut self, _inputs: &SurfaceInputs, _out: &mut [f64]) {}
}

/// The normal-stress balance (35a), with ∇u* of the predictor and, for a generalised
/// Newtonian fluid, its viscosity η(γ̇^n) at each particle in place of η_s.
#[derive(Default)]
pub struct NormalStress {
    grad_u_star: Vec<Mat2>,
    /// Sparse surface particles take their trusted neighbours' mean (else p = 0).
    sparse_from_neighbours: bool,
    gradient: SurfaceGradient,
    /// Scratch of [`sparse_surface_pressure`], kept from step to step.
    sparse_values: Vec<(usize, f64)>,
}

impl SurfacePressureRule for NormalStress {
    fn pressure(&mut self, inputs: &SurfaceInputs, out: &mut [f64]) {
        let n = out.len();
        self.grad_u_star.resize(n, Mat2::zeros());
        inputs
            .sums
            .gradient_vector(inputs.list, inputs.velocity_star, &mut self.grad_u_star);
        let fluid = inputs.fluid;
        let eta_s = fluid.solvent_viscosity();
        let (fs, normal, grad) = (
            &inputs.surface.on_surface,
            &inputs.surface.normal,
            &self.grad_u_star,
        );
        let (conformation, list, prescribed) =
            (inputs.conformation, inputs.list, inputs.prescribed);
        let factor = inputs.viscosity_factor;
        let surface = |i: usize| fs[i] && !prescribed.get(i).copied().unwrap_or(false);
        let trusted =
            |i: usize| i < n && surface(i) && list.range(i).len() >= MIN_SURFACE_NEIGHBOURS;
        let (own_side, sums, u) = (
            self.gradient == SurfaceGradient::OwnSide,
            inputs.sums,
            inputs.velocity_star,
        );
        out.par_iter_mut()
            .enumerate()
            .filter(|(i, _)| trusted(*i))
            .for_each(|(i, p)| {
                let grad_i = if own_side {
                    own_side_gradient(list, sums, u, i, normal[i]).unwrap_or(grad[i])
                } else {
                    grad[i]
                };
                let tau = if conformation.is_empty() {
                    Sym2::ZERO
                } else {
                    fluid.polymer_stress(&conformation[i])
                };
                // A shear-dependent viscosity's own η(γ̇) at the particle.
                let eta = factor.get(i).map_or(eta_s, |phi| phi * eta_s);
                *p = normal_stress_pressure(normal[i], &grad_i, &tau, eta);
            });
        if self.sparse_from_neighbours {
            let sparse = |i: usize| surface(i) && !trusted(i);
            let scratch = &mut self.sparse_values;
            sparse_surface_pressure(out, list, &inputs.sums.value, trusted, sparse, scratch);
        }
    }

    fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.grad_u_star) + crate::engine::vec_bytes(&self.sparse_values)
    }
}

/// ∇u at surface particle i from the neighbours on its own side of the surface only (those
/// less than [`OWN_SIDE_REACH`]·δr out along its unit normal `n`), with the Bonet–Lok
/// correction of that subset: ∇u = G M⁻¹, G = Σ_j V_j (u_j − u_i) ⊗ ∇W_ij,
/// M = Σ_j V_j (r_j − r_i) ⊗ ∇W_ij (eqs. (20), (22) on the subset). None when the subset's M
/// is singular (|det M| < 1e-3 against ≈ 1 in full support).
///
/// Why: at a crack or a peeling skin narrower than the support the full gradient takes in the
/// other face. Measured on the Oldroyd-B jet at Wi = 1/3 (`normal-stress-neighbours`, `held`,
/// t ≈ 0.2 s): a two-row skin peeling off the buckling pile left the faces of the opening gap
/// with (35a) values of +450 to +640 Pa (2η_s n·D·n ≈ +660 to +930 Pa), against 200–300 Pa in
/// the pile, because the skin on the other side was moving away at 0.2–0.6 m/s; these
/// Dirichlet values pushed the skin off (a 9-particle splash at 1.04 m/s, 5 U0, which later
/// left the box).
pub fn own_side_gradient(
    list: &NeighbourList,
    sums: &KernelSums,
    u: &[Vec2],
    i: usize,
    n: Vec2,
) -> Option<Mat2> {
    let reach = OWN_SIDE_REACH * sums.dv.sqrt();
    let (mut g, mut m) = (Mat2::zeros(), Mat2::zeros());
    for k in list.range(i) {
        // r_ij = r_i − r_j, ∇W_ij = F r_ij.
        let rij = list.rij[k];
        if -rij.dot(&n) >= reach {
            continue;
        }
        let grad_w = rij * sums.factor[k];
        g += (u[list.index[k] as usize] - u[i]) * grad_w.transpose();
        m += -rij * grad_w.transpose();
    }
    let (g, m) = (g * sums.dv, m * sums.dv);
    if m.determinant().abs() < 1e-3 {
        return None;
    }
    m.try_inverse().map(|inv| g * inv)
}

/// The Dirichlet pressure of the `sparse` surface particles: the kernel-weighted mean
/// Σ_j W_ij p_j / Σ_j W_ij of their `trusted` neighbours' values in `out` (p = 0 with none).
/// The traction a surface carries varies along it on the flow's scale, so a neighbour's
/// (35a) is a fair value where the particle's own velocity gradient is not; p = 0 instead
/// broke the FENE-CR jet (L² = 10): a surface particle that fell to 11 neighbours went from
/// 161 Pa to 0 beside neighbours at 150–370 Pa, was kicked from 0.2 to 0.29 m/s in one
/// output interval, and its tr A jumped from 5 to 9.8 (L² = 10). Not the default: the
/// Oldroyd-B jet at Wi = 1/3, which finishes with p = 0, shot a particle out of the box
/// with it (validation pages, *Jets*).
pub fn sparse_surface_pressure(
    out: &mut [f64],
    list: &NeighbourList,
    kernel_value: &[f64],
    trusted: impl Fn(usize) -> bool + Sync,
    sparse: impl Fn(usize) -> bool + Sync,
    values: &mut Vec<(usize, f64)>,
) {
    values.clear();
    let found = (0..out.len())
        .into_par_iter()
        .filter(|&i| sparse(i))
        .map(|i| {
            let (mut sum, mut weight) = (0.0, 0.0);
            for k in list.range(i) {
                let j = list.index[k] as usize;
                if trusted(j) {
                    sum += kernel_value[k] * out[j];
                    weight += kernel_value[k];
                }
            }
            (i, if weight > 0.0 { sum / weight } else { 0.0 })
        });
    values.par_extend(found);
    for &(i, p) in values.iter() {
        out[i] = p;
    }
}

/// The free-surface pressure of the normal-stress condition (35a):
/// `p = 2η_s [n_x² ∂u/∂x + n_y² ∂v/∂y + n_x n_y (∂u/∂y + ∂v/∂x)] + n·τ_p·n`,
/// with `grad_u[(a, b)] = ∂u_a/∂x_b`.
pub fn normal_stress_pressure(normal: Vec2, grad_u: &Mat2, tau_p: &Sym2, eta_s: f64) -> f64 {
    let (nx, ny) = (normal.x, normal.y);
    let viscous = nx * nx * grad_u[(0, 0)]
        + ny * ny * grad_u[(1, 1)]
        + nx * ny * (grad_u[(0, 1)] + grad_u[(1, 0)]);
    let polymer = nx * nx * tau_p.xx + 2.0 * nx * ny * tau_p.xy + ny * ny * tau_p.yy;
    2.0 * eta_s * viscous + polymer
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::kernel::QuinticSpline;

    /// The kernel for spacing `dr` and the neighbour list of `pts` (all within [−2, 6]²,
    /// no periodicity).
    fn neighbours(pts: &[Vec2], dr: f64) -> (QuinticSpline, NeighbourList) {
        use crate::engine::neighbours::{Domain, NeighbourSearch};
        let domain = Domain {
            min: Vec2::new(-2.0, -2.0),
            max: Vec2::new(6.0, 6.0),
            periodic: [false, false],
        };
        let kernel = QuinticSpline::for_spacing(dr);
        let mut list = NeighbourList::default();
        NeighbourSearch::new().build(&domain, pts, pts.len(), kernel.support(), &mut list);
        (kernel, list)
    }

    /// (35a) for prescribed states: a flat surface facing +y under a pure polymer stress τ_yy
    /// carries p = τ_yy; facing +x under extension ∂u/∂x = a, p = 2η_s a; and for an oblique
    /// normal p equals n·(2η_s D + τ_p)·n, the normal component of σ·n = 0 with σ = τ − pI.
    /// A sparse surface particle takes its trusted neighbours' kernel-weighted mean, one
    /// without trusted neighbours p = 0; trusted values are left alone.
    #[test]
    fn a_sparse_surface_particle_takes_its_neighbours_pressure() {
        let dr = 0.1;
        // A row of five particles, and one far away.
        let mut pts: Vec<Vec2> = (0..5).map(|k| Vec2::new(k as f64 * dr, 0.0)).collect();
        pts.push(Vec2::new(5.0, 5.0));
        let (kernel, list) = neighbours(&pts, dr);
        let value: Vec<f64> = list.rij.iter().map(|r| kernel.value(r.norm())).collect();
        let mut out = vec![100.0, 200.0, 0.0, 400.0, 500.0, 0.0];
        let sparse = |i: usize| i == 2 || i == 5;
        let mut scratch = Vec::new();
        sparse_surface_pressure(
            &mut out,
            &list,
            &value,
            |j| !sparse(j),
            sparse,
            &mut scratch,
        );
        // Particle 2 between 1 and 3 (equal weights), 0 and 4 (equal weights): the mean 300.
        assert!((out[2] - 300.0).abs() < 1e-9, "{}", out[2]);
        assert_eq!(out[5], 0.0);
        assert_eq!(
            [out[0], out[1], out[3], out[4]],
            [100.0, 200.0, 400.0, 500.0]
        );
    }

    /// A surface particle on the lower face of a crack: fluid below (y ≤ 0) in a linear field
    /// u = (0.3x + 0.5y, −0.3y), a gap of 1.5δr, and a skin above it (two rows) moving up
    /// with u = (0, 1). The own-side gradient recovers the lower fluid's ∇u exactly (the subset's Bonet–Lok
    /// correction is first-order consistent, so to round-off); the full gradient takes in the
    /// skin and reads a normal strain rate ∂v/∂y of the wrong sign.
    #[test]
    fn the_own_side_gradient_ignores_the_far_face_of_a_crack() {
        let dr = 0.1;
        let mut pts = Vec::new();
        for ix in -8..=8 {
            for iy in -6..=0 {
                pts.push(Vec2::new(ix as f64 * dr, iy as f64 * dr));
            }
            for iy in 0..2 {
                pts.push(Vec2::new(ix as f64 * dr, (2.5 + iy as f64) * dr));
            }
        }
        let field = |r: Vec2| {
            if r.y > 0.0 {
                Vec2::new(0.0, 1.0)
            } else {
                Vec2::new(0.3 * r.x + 0.5 * r.y, -0.3 * r.y)
            }
        };
        let u: Vec<Vec2> = pts.iter().map(|&r| field(r)).collect();
        let (kernel, list) = neighbours(&pts, dr);
        let mut sums = KernelSums::default();
        sums.update(&list, &kernel, dr * dr);
        let i = pts
            .iter()
            .position(|r| r.x.abs() < 1e-12 && r.y.abs() < 1e-12)
            .unwrap();
        let own = own_side_gradient(&list, &sums, &u, i, Vec2::new(0.0, 1.0)).unwrap();
        let exact = Mat2::new(0.3, 0.5, 0.0, -0.3);
        assert!((own - exact).norm() < 1e-10, "{own}");
        let mut full = vec![Mat2::zeros(); pts.len()];
        sums.gradient_vector(&list, &u, &mut full);
        // Measured: +0.27, extension where the fluid is compressed at −0.3.
        assert!(full[i][(1, 1)] > 0.0, "{}", full[i]);
    }

    #[test]
    fn dirichlet_pressure_is_the_normal_stress_balance() {
        let tau = Sym2 {
            xx: 0.3,
            xy: -0.7,
            yy: 2.5,
        };
        assert!(
            (normal_stress_pressure(Vec2::new(0.0, 1.0), &Mat2::zeros(), &tau, 1.0) - 2.5).abs()
                < 1e-14
        );
        let stretch = Mat2::new(0.8, 0.0, 0.0, -0.8);
        assert!(
            (normal_stress_pressure(Vec2::new(1.0, 0.0), &stretch, &Sym2::ZERO, 3.0) - 4.8).abs()
                < 1e-14
        );
        let n = Vec2::new(0.6, -0.8);
        let g = Mat2::new(0.2, -1.1, 0.4, 0.5);
        let eta_s = 0.7;
        let d = (g + g.transpose()) * 0.5;
        let t = Mat2::new(tau.xx, tau.xy, tau.xy, tau.yy);
        let total = 2.0 * eta_s * d + t;
        let p = normal_stress_pressure(n, &g, &tau, eta_s);
        assert!((p - n.dot(&(total * n))).abs() < 1e-14);
        // With that p, σ·n = (τ_total − pI)·n has no normal component.
        let sigma_n = total * n - p * n;
        assert!(sigma_n.dot(&n).abs() < 1e-14);
    }
}
