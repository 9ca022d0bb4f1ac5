//! Particle volume relaxation: the density-invariant source of the PPE (Asai et al. 2012,
//! after Hu & Adams 2007), an option beside the paper's divergence-free projection (25).
//!
//! The projection keeps ∇·u = 0, but the discrete divergence is not exactly the rate of
//! change of a particle's volume, and nothing restores a volume once it has drifted: in a
//! pool near rest the free-surface shift (41) is proportional to the speed, so it stops
//! too. With `experimental.volume_relaxation` = α > 0, row i of the PPE asks for a divergence
//! that removes a fraction α of the particle concentration's error per step,
//!
//! ```text
//!     ∇·u^{n+1}_i = (α/δt) (C_i/C_0 − 1),   so that   Σ_j c_ij (p_i − p_j) = −(∇·u*)_i/δt + α (C_i/C_0 − 1)/δt²,
//! ```
//!
//! with `C_i = Σ_j W_ij δV` (self and wall mirrors included) and C_0 its value on the square
//! lattice of spacing δr. A compressed patch (C_i > C_0) takes a positive source: its
//! pressure rises and the projection spreads it. Rows with a full support take the whole
//! source. NS rows (within a kernel support of the free surface) take its compressive part
//! alone, α max(C_i/C_0 − 1, 0)/δt²: their truncated C reads low, so an expansion there is
//! not to be trusted (taken as such it would pull the rows outwards), but C_i > C_0 is
//! compression beyond doubt, and at least as much as it reads. FS rows are Dirichlet rows and
//! keep their value.
//!
//! Measured in `cases/capillary-rise.toml` (θ = 120°, d/δr = 10), continued from a column at
//! rest whose particles were compressed by up to 5 % (C at the 99th percentile 1.049): with
//! α = 0.05 the 99th percentile fell to 1.002 within 500 steps. Where the compression sits is
//! the sinking column's surface layer: the reverse fountain under it closes its particles up
//! along the surface (at t = 6, 18 particles in the top row across 10 columns, 0.4δr apart at
//! the centre, C/C_0 = 1.17 on FS particles), the Fickian shift moves the surface region's
//! particles only along the surface, and the rows under it read C/C_0 = 1.03–1.10 in spite of
//! their truncation. With full rows alone the column held 6–7 % more particles than its surface
//! encloses and `gap_mean_rise` stood 15 % short of Jurin's depth while the surface stood 5 %
//! short; with NS rows taking the compressive part the two measures agree within 2.5 %
//! (validation pages, *Capillarity*).

use crate::engine::dimension::{Dim, Dimension};
use crate::engine::kernel::QuinticSpline;
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use rayon::prelude::*;

/// How a PPE row's particle concentration can be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowSupport {
    /// A full kernel support: C_i/C_0 − 1 is the volume error.
    Full,
    /// A support the free surface truncates (NS): only C_i > C_0 is certain.
    Truncated,
    /// A Dirichlet row (FS): no source.
    Dirichlet,
}

/// The relaxation of the particle concentration towards the lattice's, chosen at set-up
/// (`experimental.volume_relaxation` > 0).
#[derive(Clone, Copy, Debug)]
pub struct VolumeRelaxation {
    /// α: the fraction of the concentration error the PPE removes per step.
    alpha: f64,
    /// C_0: Σ W δV over a square lattice of spacing δr (self included).
    reference: f64,
    /// W(0) δV: a particle's own part of C.
    self_weight: f64,
}

impl VolumeRelaxation {
    /// None for α = 0 (the paper's projection).
    pub fn new(alpha: f64, kernel: &QuinticSpline, spacing: f64) -> Option<Self> {
        (alpha > 0.0).then(|| Self {
            alpha,
            reference: lattice_concentration(kernel, spacing),
            self_weight: kernel.value(0.0) * spacing * spacing,
        })
    }

    /// C_0.
    pub fn reference(&self) -> f64 {
        self.reference
    }

    /// C_i of fluid particle i (self and mirrors included).
    pub fn concentration<const D: usize>(
        &self,
        list: &NeighbourList<D>,
        sums: &KernelSums<D>,
        i: usize,
    ) -> f64
    where
        Dim<D>: Dimension<D>,
    {
        self.self_weight + list.range(i).map(|k| sums.value[k]).sum::<f64>() * sums.dv
    }

    /// Adds `α (C_i/C_0 − 1)/δt²` to the right-hand side of each row as `support` reads it
    /// (its compressive part alone on a truncated support, nothing on a Dirichlet row).
    pub fn add_source<const D: usize>(
        &self,
        hood: Hood<D>,
        support: impl Fn(usize) -> RowSupport + Sync,
        dt: f64,
        rhs: &mut [f64],
    ) where
        Dim<D>: Dimension<D>,
    {
        let Hood { list, sums, .. } = hood;
        let scale = self.alpha / (dt * dt);
        rhs.par_iter_mut().enumerate().for_each(|(i, b)| {
            let error = || self.concentration(list, sums, i) / self.reference - 1.0;
            *b += scale
                * match support(i) {
                    RowSupport::Full => error(),
                    RowSupport::Truncated => error().max(0.0),
                    RowSupport::Dirichlet => return,
                };
        });
    }
}

/// Σ_k W(|k|δr) δr² over the square lattice (self included): C of a particle in full
/// support at rest on the initial lattice.
fn lattice_concentration(kernel: &QuinticSpline, spacing: f64) -> f64 {
    let reach = (kernel.support() / spacing).ceil() as i64;
    let mut sum = 0.0;
    for a in -reach..=reach {
        for b in -reach..=reach {
            sum += kernel.value(spacing * ((a * a + b * b) as f64).sqrt());
        }
    }
    sum * spacing * spacing
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Vec2;
    use crate::engine::neighbours::Domain;

    /// The lattice sum is the kernel's normalisation to within its discretisation (the
    /// quintic spline at h = 1.3δr sums to 1 within 0.1 %).
    #[test]
    fn the_lattice_concentration_is_one() {
        let dr = 0.01;
        let kernel = QuinticSpline::for_spacing(dr);
        let c0 = lattice_concentration(&kernel, dr);
        assert!((c0 - 1.0).abs() < 1e-3, "{c0}");
    }

    /// In a periodic lattice the source is zero; squeezing the lattice by 2 % along x gives
    /// every row the source α (1/0.98 − 1)/δt² within the kernel's lattice error; rows the
    /// mask refuses keep their value.
    #[test]
    fn a_compressed_lattice_takes_a_positive_source() {
        let (m, dr) = (20usize, 0.05);
        let kernel = QuinticSpline::for_spacing(dr);
        let relax = VolumeRelaxation::new(0.1, &kernel, dr).unwrap();
        let source = |squeeze: f64| -> Vec<f64> {
            let domain = Domain {
                min: Vec2::zeros(),
                max: Vec2::new(m as f64 * dr * squeeze, m as f64 * dr),
                periodic: [true, true],
            };
            let points: Vec<Vec2> = (0..m * m)
                .map(|k| Vec2::new((k / m) as f64 * dr * squeeze, (k % m) as f64 * dr))
                .collect();
            let (list, sums, _) = crate::engine::free_surface::surface_of(&domain, &points, dr);
            let mut rhs = vec![7.0; points.len()];
            let rows = |i| match i {
                0 => RowSupport::Dirichlet,
                _ => RowSupport::Full,
            };
            relax.add_source(Hood::without_walls(&list, &sums), rows, 0.1, &mut rhs);
            rhs
        };
        let at_rest = source(1.0);
        assert_eq!(at_rest[0], 7.0);
        assert!(
            at_rest[1..].iter().all(|b| (b - 7.0).abs() < 1e-9),
            "{:?}",
            &at_rest[..3]
        );
        let squeezed = source(0.98);
        let expected = 7.0 + 0.1 * (1.0 / 0.98 - 1.0) / 0.01;
        assert_eq!(squeezed[0], 7.0);
        for b in &squeezed[1..] {
            assert!(
                (b - expected).abs() < 0.01 * (expected - 7.0),
                "{b} against {expected}"
            );
        }
    }

    /// Under a free surface the rows near it (NS) read a truncated C below C_0: at rest they
    /// take no source (the two-sided error would have sucked them outwards); with the block's
    /// top ten rows squeezed to 0.9δr apart they take a positive one, and FS rows keep their
    /// value either way.
    #[test]
    fn near_surface_rows_take_only_compression() {
        let (m, dr) = (30usize, 0.01);
        let kernel = QuinticSpline::for_spacing(dr);
        let relax = VolumeRelaxation::new(0.1, &kernel, dr).unwrap();
        let domain = Domain {
            min: Vec2::new(-1.0, -1.0),
            max: Vec2::new(2.0, 2.0),
            periodic: [false, false],
        };
        let source = |squeeze: f64| {
            let y = |j: usize| match j {
                j if j < m - 10 => j as f64 * dr,
                j => (m - 10) as f64 * dr + (j + 10 - m) as f64 * dr * squeeze,
            };
            let points: Vec<Vec2> = (0..m * m)
                .map(|k| Vec2::new((k / m) as f64 * dr, y(k % m)))
                .collect();
            let (list, sums, surface) =
                crate::engine::free_surface::surface_of(&domain, &points, dr);
            let mut rhs = vec![0.0; points.len()];
            let rows = |i| surface.row_support(i);
            relax.add_source(Hood::without_walls(&list, &sums), rows, 0.1, &mut rhs);
            (rhs, surface)
        };
        // The middle column, one and two rows under the top.
        let (first, second) = (15 * m + m - 2, 15 * m + m - 3);
        let (at_rest, surface) = source(1.0);
        assert!(surface.near_surface[first] && surface.near_surface[second]);
        assert_eq!((at_rest[first], at_rest[second]), (0.0, 0.0));
        let (squeezed, surface) = source(0.9);
        assert!(surface.near_surface[second]);
        assert!(squeezed[second] > 0.0, "{}", squeezed[second]);
        assert!((0..m * m)
            .filter(|&i| surface.on_surface[i])
            .all(|i| squeezed[i] == 0.0));
    }
}
