//! Run diagnostics: L2 errors, centre-line velocity, field statistics.

use crate::engine::dimension::{Dim, Dimension, Sym, SymTensor, Vector};
use rayon::prelude::*;

pub use crate::engine::reduce::blocked_sum;

/// Centre-line velocity: a least-squares quadratic u(y) through the particles within 2.5δr
/// of the centre-line, evaluated at y = H/2. Unbiased for the parabolic profile, unlike the
/// mean of the two nearest rows (which sit δr/2 off the centre-line).
pub fn centre_line_velocity<const D: usize>(
    positions: &[Vector<D>],
    velocity: &[Vector<D>],
    centre: f64,
    spacing: f64,
) -> f64 {
    let band = 2.5 * spacing;
    // Normal equations for u = a + b s + c s², s = (y − centre)/spacing.
    let mut m = [[0.0f64; 3]; 3];
    let mut rhs = [0.0f64; 3];
    for (p, u) in positions.iter().zip(velocity) {
        let d = p[1] - centre;
        if d.abs() <= band {
            let s = d / spacing;
            let basis = [1.0, s, s * s];
            for a in 0..3 {
                rhs[a] += basis[a] * u[0];
                for b in 0..3 {
                    m[a][b] += basis[a] * basis[b];
                }
            }
        }
    }
    let m = nalgebra::Matrix3::from_fn(|a, b| m[a][b]);
    match m.lu().solve(&nalgebra::Vector3::from(rhs)) {
        Some(x) if x[0].is_finite() => x[0],
        _ => f64::NAN,
    }
}

/// Field statistics of one instant.
#[derive(Clone, Copy, Debug, Default)]
pub struct FieldStats {
    /// Σ ½ρ|u|² δV.
    pub kinetic_energy: f64,
    pub max_speed: f64,
    /// Largest tr A (D at rest, and for a Newtonian fluid, which has no A).
    pub max_trace: f64,
    /// Smallest det A (≥ 1 for Oldroyd-B in shear; must stay > 0).
    pub min_det: f64,
}

pub fn field_stats<const D: usize>(
    velocity: &[Vector<D>],
    conformation: &[Sym<D>],
    density: f64,
    volume: f64,
) -> FieldStats
where
    Dim<D>: Dimension<D>,
{
    let kinetic_energy =
        0.5 * density * volume * blocked_sum(velocity.len(), |i| velocity[i].norm_squared());
    let max_speed = velocity
        .par_iter()
        .map(|u| u.norm())
        .reduce(|| 0.0, f64::max);
    let (max_trace, min_det) = if conformation.is_empty() {
        (D as f64, 1.0)
    } else {
        (
            conformation
                .par_iter()
                .map(|a| a.trace())
                .reduce(|| f64::MIN, f64::max),
            conformation
                .par_iter()
                .map(|a| a.det())
                .reduce(|| f64::MAX, f64::min),
        )
    };
    FieldStats {
        kinetic_energy,
        max_speed,
        max_trace,
        min_det,
    }
}

/// Where det A is smallest: the position of the first particle holding the minimum (NaN
/// without a conformation). Tells a breakdown's place, e.g. the first particle layer at a
/// wall.
pub fn min_det_location<const D: usize>(
    position: &[Vector<D>],
    conformation: &[Sym<D>],
) -> Vector<D>
where
    Dim<D>: Dimension<D>,
{
    extreme_location(position, conformation, |a| a.det())
}

/// Where tr A is largest, in the same way: where the polymer is stretched most.
pub fn max_trace_location<const D: usize>(
    position: &[Vector<D>],
    conformation: &[Sym<D>],
) -> Vector<D>
where
    Dim<D>: Dimension<D>,
{
    extreme_location(position, conformation, |a| -a.trace())
}

/// The position of the particle where `key` of its conformation is smallest.
fn extreme_location<const D: usize>(
    position: &[Vector<D>],
    conformation: &[Sym<D>],
    key: impl Fn(&Sym<D>) -> f64 + Sync,
) -> Vector<D>
where
    Dim<D>: Dimension<D>,
{
    let best = conformation
        .par_iter()
        .enumerate()
        .map(|(i, a)| (key(a), i))
        .reduce(
            || (f64::INFINITY, usize::MAX),
            |x, y| {
                if y.0 < x.0 || (y.0 == x.0 && y.1 < x.1) {
                    y
                } else {
                    x
                }
            },
        );
    position
        .get(best.1)
        .copied()
        .unwrap_or(Vector::<D>::repeat(f64::NAN))
}

/// Particle-scale noise of the conformation: the median over fluid particles of
/// |ln tr A_i − ⟨ln tr A⟩_i|, with ⟨·⟩_i the kernel-weighted mean over i's fluid neighbours
/// (i itself left out). A smooth field contributes O(h²|∇² ln tr A|) (the symmetric mean
/// cancels its linear part); an odd–even pattern contributes its full amplitude. Under the
/// central remap it grows without bound at Wi ≥ 4 in the cylinder array and saturates with
/// the upwind one (validation pages, *High Weissenberg number*). NaN without a conformation (Newtonian
/// fluids) and 0 when no particle has a neighbour.
pub fn conformation_noise<const D: usize>(
    domain: &crate::engine::neighbours::Domain<D>,
    position: &[Vector<D>],
    conformation: &[Sym<D>],
    spacing: f64,
) -> f64
where
    Dim<D>: Dimension<D>,
{
    use crate::engine::kernel::QuinticSpline;
    use crate::engine::neighbours::{NeighbourList, NeighbourSearch};
    if conformation.len() != position.len() || position.is_empty() {
        return f64::NAN; // a Newtonian or generalised Newtonian fluid carries no conformation
    }
    let kernel = QuinticSpline::in_dimension::<D>(crate::engine::kernel::H_OVER_DR * spacing);
    let n = position.len();
    let mut list = NeighbourList::default();
    NeighbourSearch::new().build(domain, position, n, kernel.support(), &mut list);
    let log_trace: Vec<f64> = conformation.iter().map(|a| a.trace().ln()).collect();
    let mut deviation: Vec<f64> = (0..n)
        .into_par_iter()
        .filter_map(|i| {
            let (mut sum, mut weight) = (0.0, 0.0);
            for k in list.range(i) {
                let w = kernel.value(list.rij[k].norm());
                sum += w * log_trace[list.index[k] as usize];
                weight += w;
            }
            (weight > 0.0).then(|| (log_trace[i] - sum / weight).abs())
        })
        .collect();
    if deviation.is_empty() {
        return 0.0;
    }
    let mid = deviation.len() / 2;
    *deviation
        .select_nth_unstable_by(mid, |a, b| a.total_cmp(b))
        .1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::{Sym2, Vec2};

    #[test]
    fn centre_line_fit_is_exact_for_a_parabola() {
        let dr = 1.0 / 30.0;
        let pts: Vec<Vec2> = (0..30)
            .map(|j| Vec2::new(0.1, (j as f64 + 0.5) * dr))
            .collect();
        let vel: Vec<Vec2> = pts
            .iter()
            .map(|p| Vec2::new(4.0 * p.y * (1.0 - p.y), 0.0))
            .collect();
        let u = centre_line_velocity(&pts, &vel, 0.5, dr);
        assert!((u - 1.0).abs() < 1e-12, "{u}");
    }

    /// A smooth ln tr A (one period of a sine across a periodic 40 × 40 lattice) reads as
    /// O(h²) noise: the symmetric kernel mean cancels the linear part, the quadratic one is
    /// ~(kh)²/2 ≈ 0.02 of the amplitude here (measured 0.009); a checkerboard of ±0.3 in
    /// ln tr A, added to it, reads as nearly its amplitude (the neighbours' mean of a
    /// checkerboard is small but not zero, so it reads a little above; measured 0.37).
    #[test]
    fn conformation_noise_tells_a_checkerboard_from_a_smooth_field() {
        let n = 40;
        let dr = 1.0 / n as f64;
        let domain = crate::engine::neighbours::Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, true],
        };
        let mut pts = Vec::new();
        let (mut smooth, mut rough) = (Vec::new(), Vec::new());
        for i in 0..n {
            for j in 0..n {
                let p = Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr);
                let ln_tr = 2.0 + (2.0 * std::f64::consts::PI * p.x).sin();
                let sign = if (i + j) % 2 == 0 { 0.3 } else { -0.3 };
                let a = |l: f64| Sym2::new(0.5 * l.exp(), 0.0, 0.5 * l.exp());
                pts.push(p);
                smooth.push(a(ln_tr));
                rough.push(a(ln_tr + sign));
            }
        }
        let quiet = conformation_noise(&domain, &pts, &smooth, dr);
        let noisy = conformation_noise(&domain, &pts, &rough, dr);
        assert!(quiet < 0.02, "smooth: {quiet}");
        assert!(noisy > 0.2 && noisy < 0.45, "checkerboard: {noisy}");
    }
}
