//! Free-surface detection (King & Lind §III D, eqs. (36)–(39)): which particles lie on the
//! surface and which way it faces.
//!
//! * Detection, eqs. (36)–(37): particle i is on the free surface (set FS) when
//!   `⟨∇·r⟩_i ≤ 1.4 + 0.5 max(Ĉ_i − 1, −0.2)`, with `⟨∇·r⟩_i = Σ_j (r_j − r_i)·∇W_ij δV`
//!   (2 in full support in 2D), `C_i = Σ_j V_j W_ij` (self included) and
//!   `Ĉ_i = N_FP C_i / Σ_k C_k` the concentration relative to the fluid's mean. The relaxation
//!   keeps particles of a compressed surface (a stagnation point) from being lost to FS.
//! * Normals, eqs. (38)–(39): `n*_i = −(1/h) Σ_j V_j ∇W_ij` (our ∇W_ij points from i towards j,
//!   so the minus sign makes n* point out of the fluid), smoothed as
//!   `n_i = Σ_j V_j n*_j W_ij / C_j` over fluid neighbours and self, then normalised.
//! * Near-surface set NS: particles with at least one FS neighbour.
//! * Exposed particles: an NS particle with a well-defined normal and no neighbour at all in
//!   the scan region of Marrone et al. (2010) about its normal (a cone of half-angle 45° out
//!   to √2 δr, and the disc of radius δr centred δr out) joins FS, and NS and the normals are
//!   evaluated again; not within about 1.5δr of a wall (see [`WALL_CLEARANCE`]). (36) alone
//!   misses a
//!   particle at the bottom of a dent: the surface curving up on both sides fills its support
//!   enough to pass for interior. Its PPE row then has no Dirichlet value, and a pressure
//!   spike follows. Measured between the plates of `cases/capillary-rise.toml`: the fountain
//!   flow under the rising meniscus spread its surface particles 1.7δr apart by t = 2.25, and
//!   at t = 2.5 an unlabelled particle 0.6δr under the surface carried p = 1.92 against −0.6
//!   around it; the meniscus broke up at t = 4.5.
//!   A particle outside FS and NS whose own support is truncated (|n*| h² above
//!   [`UNSEEN_STRENGTH`]) takes the same test about its raw normal n*: where a stretch of
//!   surface is bunched, (36) can miss all of it, and then none of it is NS. Measured in
//!   the 120° column of `cases/capillary-rise.toml`: the top row, 16 particles across a gap
//!   of 10δr, had ⟨∇·r⟩ = 1.37–1.54 against thresholds near 1.3 (its concentration is below
//!   the mean), and (36) took none of it. The exposure of NS particles recovered it only
//!   from the FS particles the contact corners provide: 5 of its 16 particles, a run with no
//!   FS neighbour, stayed interior, the capillary pressure acted on a surface with a gap in
//!   it, and the column stood pinned at 89 % of Jurin's depth (t = 14 to 40).
//!
//! Mirror particles of a plate count as neighbours (a wall is not a free surface), but their
//! own normals are not smoothed into a fluid particle's.

use crate::engine::dimension::Vector;
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::Vec2;
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use rayon::prelude::*;

/// Threshold of (36) in full support and the weight and floor of its concentration term.
const DIVERGENCE_THRESHOLD: f64 = 1.4;
const CONCENTRATION_WEIGHT: f64 = 0.5;
const CONCENTRATION_FLOOR: f64 = -0.2;
/// Normal strength (|n| h², see [`FreeSurface::normal_strength`]) above which an NS particle
/// belongs to the surface region: 15 % of a flat surface's.
pub const NEAR_SURFACE_STRENGTH: f64 = 0.05;
/// Raw normal strength |n*_i| h² (38) above which a particle outside FS and NS takes the
/// exposure test ([`FreeSurface::exposure_normal`]). Measured in the pool of
/// `cases/capillary-rise.toml`: 0.41–0.53 on the missed surface row, at most 0.107 (99 %
/// below 0.031) on particles with ⟨∇·r⟩ > 1.9; the scan region itself rejects any particle
/// with a neighbour outside it.
const UNSEEN_STRENGTH: f64 = 0.15;
/// The exposure scan region (Marrone et al. 2010) in particle spacings: a cone of half-angle
/// 45° (cosine below) about the normal out to √2 δr, with the disc of radius δr centred δr
/// out along the normal.
const CONE_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// Particles with a mirror nearer than this many spacings (within about 1.5δr of a wall) are
/// not tested: beside a wall the test flagged particles under a meniscus at rest, 0.7δr and
/// 1.8δr from a plate and two spacings under the surface, whose Dirichlet values then kicked
/// the pool (`cases/capillary-rise.toml`, θ = 60°, t = 15.9: speeds 0.02 → 0.68).
const WALL_CLEARANCE: f64 = 3.0;

/// The free-surface sets and normals of one particle configuration, with buffers reused from
/// step to step. The sets are written for D dimensions (the default 2); their detection is
/// planar (a 3D set-up refuses free surfaces).
#[derive(Clone, Debug)]
pub struct FreeSurface<const D: usize = 2> {
    /// C_i of (37).
    pub concentration: Vec<f64>,
    /// ⟨∇·r⟩_i of (36).
    pub position_divergence: Vec<f64>,
    /// Membership of FS.
    pub on_surface: Vec<bool>,
    /// How far inside FS each particle lies: (36)'s threshold less ⟨∇·r⟩_i (positive on FS
    /// by (36), +∞ on particles the exposure test or an inflow buffer put there).
    pub margin: Vec<f64>,
    /// Width of [`Self::weight`]'s ramp in ⟨∇·r⟩ (0: every FS particle weighs 1).
    pub blend_width: f64,
    /// Membership of NS (a neighbour in FS, not itself in FS).
    pub near_surface: Vec<bool>,
    /// Unit outward normal n_i of (39) for FS and NS particles, zero elsewhere.
    pub normal: Vec<Vector<D>>,
    /// |n_i| of (39) before normalisation, times h² (dimensionless): 0.34 on a flat
    /// surface, 0.24, 0.07 and 0.01 on the next rows in, and near 0 wherever the surface is
    /// on both sides (the middle of a thin jet).
    pub normal_strength: Vec<f64>,
    raw_normal: Vec<Vector<D>>,
    /// Scratch of the exposure test: which particles it adds to FS.
    exposed: Vec<bool>,
}

impl<const D: usize> Default for FreeSurface<D> {
    fn default() -> Self {
        Self {
            concentration: Vec::new(),
            position_divergence: Vec::new(),
            on_surface: Vec::new(),
            margin: Vec::new(),
            blend_width: 0.0,
            near_surface: Vec::new(),
            normal: Vec::new(),
            normal_strength: Vec::new(),
            raw_normal: Vec::new(),
            exposed: Vec::new(),
        }
    }
}

impl<const D: usize> FreeSurface<D> {
    /// Row i's support for the density-invariant source: FS rows are Dirichlet, NS rows
    /// truncated, the rest full.
    pub fn row_support(&self, i: usize) -> crate::engine::volume::RowSupport {
        use crate::engine::volume::RowSupport;
        if self.on_surface[i] {
            RowSupport::Dirichlet
        } else if self.near_surface[i] {
            RowSupport::Truncated
        } else {
            RowSupport::Full
        }
    }

    /// Empty sets whose FS weights ramp over `blend_width` ([`Self::weight`]).
    pub fn with_blend_width(blend_width: f64) -> Self {
        Self {
            blend_width,
            ..Self::default()
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.concentration)
            + b(&self.position_divergence)
            + b(&self.on_surface)
            + b(&self.margin)
            + b(&self.near_surface)
            + b(&self.normal)
            + b(&self.normal_strength)
            + b(&self.raw_normal)
            + b(&self.exposed)
    }

    /// Whether particle i is NS with a well defined normal (strength above
    /// [`NEAR_SURFACE_STRENGTH`]: the first two rows in from a flat surface, not the middle of
    /// a thin jet, where opposite surfaces cancel and n is noise).
    pub fn is_near_with_normal(&self, i: usize) -> bool {
        self.near_surface[i] && self.normal_strength[i] > NEAR_SURFACE_STRENGTH
    }

    /// The surface region into `out`: FS, and the NS particles whose normal is well defined
    /// ([`Self::is_near_with_normal`]).
    pub fn region(&self, out: &mut Vec<bool>) {
        out.clear();
        out.extend(
            (0..self.on_surface.len()).map(|i| self.on_surface[i] || self.is_near_with_normal(i)),
        );
    }

    /// How much FS particle i counts as surface, in [0, 1] (0 off FS): 1 without a blend
    /// width; with one, the smooth step 3x² − 2x³ of x = margin/width, so that a particle
    /// that (36) has only just taken into FS joins it gradually as it moves further in
    /// ([`crate::engine::free_surface::SurfaceIndicator::Blended`]).
    pub fn weight(&self, i: usize) -> f64 {
        if !self.on_surface[i] {
            return 0.0;
        }
        if self.blend_width <= 0.0 {
            return 1.0;
        }
        let x = (self.margin[i] / self.blend_width).clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    }

    /// Particles in FS.
    pub fn count(&self) -> usize {
        self.on_surface.iter().filter(|&&s| s).count()
    }
}

impl FreeSurface {
    /// Evaluates (36)–(39) for the fluid particles (the rows of `list`).
    pub fn detect(&mut self, list: &NeighbourList, sums: &KernelSums, kernel: &QuinticSpline) {
        let n = list.rows();
        let dv = sums.dv;
        let self_weight = kernel.value(0.0) * dv;
        self.concentration.resize(n, 0.0);
        self.position_divergence.resize(n, 0.0);
        self.raw_normal.resize(n, Vec2::zeros());
        let inv_h = 1.0 / kernel.h();
        self.concentration
            .par_iter_mut()
            .zip(self.position_divergence.par_iter_mut())
            .zip(self.raw_normal.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((c, div), raw))| {
                let (mut sum_w, mut sum_div, mut sum_grad) = (self_weight, 0.0, Vec2::zeros());
                for k in list.range(i) {
                    let r = list.rij[k];
                    let grad = sums.grad_w(list, k);
                    sum_w += sums.value[k] * dv;
                    // (r_j − r_i)·∇W_ij = −r_ij·∇W_ij.
                    sum_div -= r.dot(&grad) * dv;
                    sum_grad += grad * dv;
                }
                *c = sum_w;
                *div = sum_div;
                *raw = -sum_grad * inv_h;
            });
        let mean_c = crate::engine::reduce::blocked_sum(n, |i| self.concentration[i]) / n as f64;
        let (c, div) = (&self.concentration, &self.position_divergence);
        self.on_surface.resize(n, false);
        self.margin.resize(n, 0.0);
        self.on_surface
            .par_iter_mut()
            .zip(self.margin.par_iter_mut())
            .enumerate()
            .for_each(|(i, (s, margin))| {
                let relative = c[i] / mean_c;
                let threshold = DIVERGENCE_THRESHOLD
                    + CONCENTRATION_WEIGHT * (relative - 1.0).max(CONCENTRATION_FLOOR);
                *s = div[i] <= threshold;
                *margin = threshold - div[i];
            });
        self.near_and_normals(list, sums, kernel);
        if self.expose(list, kernel) {
            self.near_and_normals(list, sums, kernel);
        }
    }

    /// NS and the normals (39) of FS and NS, from the current FS.
    fn near_and_normals(
        &mut self,
        list: &NeighbourList,
        sums: &KernelSums,
        kernel: &QuinticSpline,
    ) {
        let n = list.rows();
        let dv = sums.dv;
        let self_weight = kernel.value(0.0) * dv;
        let fs = &self.on_surface;
        self.near_surface.resize(n, false);
        self.near_surface
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, near)| {
                *near = !fs[i]
                    && list
                        .range(i)
                        .any(|k| (list.index[k] as usize) < n && fs[list.index[k] as usize]);
            });
        let (raw, near, c) = (&self.raw_normal, &self.near_surface, &self.concentration);
        let h2 = kernel.h() * kernel.h();
        self.normal.resize(n, Vec2::zeros());
        self.normal_strength.resize(n, 0.0);
        self.normal
            .par_iter_mut()
            .zip(self.normal_strength.par_iter_mut())
            .enumerate()
            .for_each(|(i, (out, strength))| {
                *out = Vec2::zeros();
                *strength = 0.0;
                if !(fs[i] || near[i]) {
                    return;
                }
                let mut acc = raw[i] * (self_weight / c[i]);
                for k in list.range(i) {
                    let j = list.index[k] as usize;
                    if j < n {
                        acc += raw[j] * (sums.value[k] * dv / c[j]);
                    }
                }
                let norm = acc.norm();
                *strength = norm * h2;
                if norm > 0.0 {
                    *out = acc / norm;
                }
            });
    }

    /// Adds the exposed NS particles to FS (module docs); whether any was added.
    fn expose(&mut self, list: &NeighbourList, kernel: &QuinticSpline) -> bool {
        let dr = kernel.h() / crate::engine::kernel::H_OVER_DR;
        let n = list.rows();
        let wall_reach2 = (WALL_CLEARANCE * dr).powi(2);
        let by_wall = |i: usize| {
            list.range(i)
                .any(|k| list.index[k] as usize >= n && list.rij[k].norm_squared() < wall_reach2)
        };
        let mut exposed = std::mem::take(&mut self.exposed);
        exposed.resize(n, false);
        let this = &*self;
        let h2 = kernel.h() * kernel.h();
        exposed.par_iter_mut().enumerate().for_each(|(i, e)| {
            *e = this
                .exposure_normal(i, h2)
                .is_some_and(|normal| !by_wall(i) && scan_region_empty(list, i, normal, dr));
        });
        let any = self.join(&exposed);
        self.exposed = exposed;
        any
    }

    /// The normal the exposure test scans about for particle i, if it takes the test: an NS
    /// particle's with a well-defined normal ([`Self::is_near_with_normal`]), or, for a
    /// particle outside FS and NS whose own support is truncated (|n*_i| h² above
    /// [`UNSEEN_STRENGTH`]), its raw normal n*_i (38). The second kind is a stretch of surface
    /// (36) missed entirely, so that no particle of it is NS.
    fn exposure_normal(&self, i: usize, h2: f64) -> Option<Vec2> {
        if self.is_near_with_normal(i) {
            return Some(self.normal[i]);
        }
        let raw = self.raw_normal[i];
        (!self.on_surface[i] && !self.near_surface[i] && raw.norm() * h2 > UNSEEN_STRENGTH)
            .then(|| raw.normalize())
    }

    /// Puts the particles `flags` marks into FS (margin +∞); whether any was added.
    fn join(&mut self, flags: &[bool]) -> bool {
        let mut any = false;
        for ((s, &e), margin) in self.on_surface.iter_mut().zip(flags).zip(&mut self.margin) {
            if e && !*s {
                *s = true;
                *margin = f64::INFINITY;
                any = true;
            }
        }
        any
    }

    /// Takes the particles `flags` marks out of FS (their margin set to −∞) and evaluates NS
    /// and the normals again; whether any was taken out (a hollow under a wall's contact line,
    /// [`crate::engine::free_surface::wetting`]).
    pub fn remove(
        &mut self,
        flags: &[bool],
        list: &NeighbourList,
        sums: &KernelSums,
        kernel: &QuinticSpline,
    ) -> bool {
        let mut any = false;
        for ((s, &e), margin) in self.on_surface.iter_mut().zip(flags).zip(&mut self.margin) {
            if e && *s {
                *s = false;
                *margin = f64::NEG_INFINITY;
                any = true;
            }
        }
        if any {
            self.near_and_normals(list, sums, kernel);
        }
        any
    }

    /// Adds the particles `flags` marks to FS and evaluates NS and the normals again
    /// (a wall's contact corner, [`crate::engine::free_surface::wetting`]).
    pub fn add(
        &mut self,
        flags: &[bool],
        list: &NeighbourList,
        sums: &KernelSums,
        kernel: &QuinticSpline,
    ) {
        if self.join(flags) {
            self.near_and_normals(list, sums, kernel);
        }
    }
}

/// Whether the scan region of Marrone et al. (2010) about the unit normal `normal` of
/// particle i (module docs) holds no neighbour of i (fluid or mirror: a wall is not a
/// surface), for particles of spacing `dr`.
pub fn scan_region_empty(list: &NeighbourList, i: usize, normal: Vec2, dr: f64) -> bool {
    let reach2 = 2.0 * dr * dr;
    !list.range(i).any(|k| {
        // r_j − r_i.
        let r = -list.rij[k];
        let r2 = r.norm_squared();
        let along = r.dot(&normal);
        let in_cone = r2 < reach2 && along > 0.0 && along * along > CONE_COS * CONE_COS * r2;
        in_cone || (r - dr * normal).norm_squared() < 0.98 * dr * dr
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::neighbours::Domain;

    fn detect(points: &[Vec2], dr: f64) -> FreeSurface {
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [false, false],
        };
        crate::engine::free_surface::surface_of(&domain, points, dr).2
    }

    /// A square block of 30 × 30 particles at rest: FS is exactly its outer ring (the 116
    /// particles with a lattice neighbour missing), nothing inside.
    #[test]
    fn detection_flags_exactly_the_boundary_of_a_square() {
        let (m, dr) = (30usize, 0.01);
        let points: Vec<Vec2> = (0..m * m)
            .map(|k| Vec2::new((k / m) as f64 * dr, (k % m) as f64 * dr))
            .collect();
        let fs = detect(&points, dr);
        for (k, &flag) in fs.on_surface.iter().enumerate() {
            let (i, j) = (k / m, k % m);
            let edge = i == 0 || j == 0 || i == m - 1 || j == m - 1;
            assert_eq!(
                flag, edge,
                "particle ({i}, {j}): div r = {}",
                fs.position_divergence[k]
            );
        }
        assert_eq!(fs.count(), 4 * (m - 1));
        // The normal's strength falls off into the block: 0.34, 0.24, 0.07, 0.01 on the first
        // four rows of a flat side.
        let strength: Vec<f64> = (0..4)
            .map(|row| fs.normal_strength[row * m + m / 2])
            .collect();
        assert!(strength[0] > 0.3 && strength[1] > 0.2 && strength[2] > NEAR_SURFACE_STRENGTH);
        assert!(strength[3] < NEAR_SURFACE_STRENGTH, "{strength:?}");
    }

    /// A block with one particle missing from its top row: the particle under the hole,
    /// which (36) takes for interior, is exposed and joins FS; no other particle changes.
    #[test]
    fn a_particle_under_a_hole_in_the_surface_is_exposed() {
        let (m, dr) = (30usize, 0.01);
        let hole = (15usize, m - 1);
        let points: Vec<Vec2> = (0..m * m)
            .map(|k| (k / m, k % m))
            .filter(|&ij| ij != hole)
            .map(|(i, j)| Vec2::new(i as f64 * dr, j as f64 * dr))
            .collect();
        let fs = detect(&points, dr);
        let below = points
            .iter()
            .position(|p| (p - Vec2::new(0.15, 0.28)).norm() < 1e-9)
            .unwrap();
        assert!(fs.on_surface[below]);
        // (36) alone would not flag it.
        let div = fs.position_divergence[below];
        let second = points
            .iter()
            .position(|p| (p - Vec2::new(0.05, 0.28)).norm() < 1e-9)
            .unwrap();
        assert!(!fs.on_surface[second]);
        assert!(div > DIVERGENCE_THRESHOLD, "div r = {div}");
        // The outer ring less the hole, and the exposed particle.
        assert_eq!(fs.count(), 4 * (m - 1));
        // It counts in full under a blended indicator too; (36)'s own surface particles
        // by their margin, the interior not at all.
        let blended = FreeSurface {
            blend_width: 0.1,
            ..fs.clone()
        };
        assert_eq!(fs.margin[below], f64::INFINITY);
        assert_eq!(blended.weight(below), 1.0);
        assert_eq!(blended.weight(second), 0.0);
        for k in (0..points.len()).filter(|&k| fs.on_surface[k] && k != below) {
            let x = (fs.margin[k] / 0.1).clamp(0.0, 1.0);
            assert!(fs.margin[k] >= 0.0);
            assert_eq!(blended.weight(k), x * x * (3.0 - 2.0 * x));
            assert_eq!(fs.weight(k), 1.0);
        }
    }

    /// A block whose top row is bunched along the surface to 0.55δr (as a column's surface
    /// becomes when a receding contact line feeds it particles, `cases/capillary-rise.toml`
    /// at 120°): (36) misses the whole row, so that none of it is NS either, and the exposure
    /// test, scanning about the raw normal n* (38), puts it back into FS, the interior row
    /// under it not.
    #[test]
    fn a_bunched_surface_row_that_36_misses_is_exposed() {
        let (m, dr) = (30usize, 0.01);
        let mut points: Vec<Vec2> = (0..m * (m - 1))
            .map(|k| Vec2::new((k / (m - 1)) as f64 * dr, (k % (m - 1)) as f64 * dr))
            .collect();
        let top = points.len();
        let bunched = ((m - 1) as f64 / 0.55) as usize;
        points.extend((0..=bunched).map(|k| Vec2::new(k as f64 * 0.55 * dr, (m - 1) as f64 * dr)));
        let fs = detect(&points, dr);
        // The middle of the row, away from the block's corners.
        let middle: Vec<usize> = (top..points.len())
            .filter(|&k| (points[k].x - 0.145).abs() < 0.08)
            .collect();
        for &k in &middle {
            let div = fs.position_divergence[k];
            assert!(fs.on_surface[k], "{:?}: div r = {div}", points[k]);
            assert_eq!(fs.margin[k], f64::INFINITY, "{:?}: (36) took it", points[k]);
        }
        let under = (0..top)
            .filter(|&k| (points[k].y - 0.28).abs() < 1e-9 && (points[k].x - 0.145).abs() < 0.08);
        for k in under {
            assert!(!fs.on_surface[k], "{:?}", points[k]);
        }
    }

    /// A disc of radius 20 δr built of concentric rings (as drops are, [`crate::engine::lattice::disc`]):
    /// FS is exactly the outer ring, and its normals point along the radius within 2° (the
    /// ring's discreteness and the inner rings' offsets tilt the kernel-weighted normal only
    /// slightly).
    #[test]
    fn detection_and_normals_of_a_disc() {
        let (radius, dr) = (0.2, 0.01);
        let centre = Vec2::new(0.5, 0.5);
        let points = crate::engine::lattice::disc(centre, radius, dr);
        let fs = detect(&points, dr);
        let outer_radius = radius - 0.5 * dr;
        let mut worst: f64 = 0.0;
        for (k, p) in points.iter().enumerate() {
            let r = p - centre;
            let outer = (r.norm() - outer_radius).abs() < 1e-9;
            assert_eq!(
                fs.on_surface[k],
                outer,
                "particle at radius {:.4}: div r = {:.3}",
                r.norm(),
                fs.position_divergence[k]
            );
            if outer {
                let angle = fs.normal[k].dot(&(r / r.norm())).clamp(-1.0, 1.0).acos();
                worst = worst.max(angle.to_degrees());
            }
        }
        assert!(worst < 2.0, "worst normal deviation {worst:.3}°");
    }
}
