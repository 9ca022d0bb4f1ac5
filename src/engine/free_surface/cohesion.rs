//! Surface tension as a pairwise cohesion force (Wróblewski, Boryczko & Kopeć 2008, eq. (9)),
//! the variant `scheme.surface_tension.form = "cohesion"` beside the capillary jump σκ of the
//! normal-stress balance ([`super::tension`]).
//!
//! Every pair of fluid particles attracts with a force that acts only beyond the kernel's
//! support r_c, on [r_c, 2r_c]: a kernel-shaped bump b(r) = W(|r − 3r_c/2|) of a quintic
//! spline with support r_c/2 (the seed's F_ij = −A·W; its authors found that an attraction
//! inside the SPH range binds particles in pairs, and that the bump's exact form does not
//! matter once it is negative on [r_c, 2r_c]). The acceleration of particle i is
//!
//! ```text
//!     a_i = −(S/ρ) Σ_j δV b(r_ij) r̂_ij,
//! ```
//!
//! a force density S b(r) between two volume elements. Its surface tension follows from the
//! work of parting two half-planes of uniform liquid (mean field): σ = −∫₀^∞ r² φ(r) dr for
//! the pair energy density φ with −φ' = −S b, that is
//!
//! ```text
//!     σ = (S/3) ∫₀^∞ r³ b(r) dr,
//! ```
//!
//! which sets S from `fluid.surface_tension`. The discrete sum over a disordered particle
//! cloud is not the integral, so the σ the scheme actually has is measured by the Laplace
//! test (drops of three radii, p_in = p_0 + σ_eff/R; validation pages). The same force pulls the
//! particles near a free surface inward with a cohesive pressure that a flat surface
//! already has, K = (π/2) S ∫₀^∞ r² b(r) dr (the mean field's a n²). The force is
//! conservative, f = −∇U with U = S∫B(|x − y|)dy (B' = b), so a drop's interior carries
//! p_in = p_s + K + σ/R to first order in r_c/R. K is some 16 times σ/R, and the
//! projection's Dirichlet surface rows cannot hold it (validation pages): the variant is for the
//! weakly compressible scheme, as in the seed.
//!
//! Wetting (the seed's fluid–wall attraction). The cohesion sum runs over fluid particles
//! only, so a wall is a vacuum to it: alone it would not wet at all (θ = 180°). A flat
//! wall attracts with the same bump of strength S_w, integrated over the half-plane of a
//! uniform solid behind it: at distance d the pull toward the wall is (S_w/ρ) g(d),
//! g(d) = ∫_{y>d} b(r) y/r dA (tabulated at set-up). Parting liquid from the solid costs
//! 2σ S_w/S per unit length, so Young–Dupré, σ(1 + cos θ) = 2σ S_w/S, gives
//! S_w = S(1 + cos θ)/2: `scene.contact_angle` chooses S_w.

use crate::engine::boundary::Shape;
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::Vec2;
use crate::engine::neighbours::{moved_less_than, Domain, NeighbourList, NeighbourSearch};
use rayon::prelude::*;

/// Simpson intervals of the set-up quadratures (the bump spans [r_c, 2r_c]).
const QUADRATURE: usize = 2000;
/// The Verlet skin of the pair search in units of δr (as the kernel's, [`SKIN`]).
const SKIN: f64 = crate::engine::neighbourhood::SKIN;
/// Entries of the wall table g(d) over d ∈ [0, 2r_c].
const WALL_TABLE: usize = 400;

/// The cohesion force of a fluid with surface tension σ, and its walls' attraction.
pub struct Cohesion {
    /// The bump's kernel (support r_c/2) and centre 3r_c/2.
    bump: QuinticSpline,
    centre: f64,
    /// 2r_c, the force's reach.
    reach: f64,
    /// S/ρ times the particle volume δV.
    scale: f64,
    /// The attracting flat walls and the half-plane's pull g(d)·S_w/ρ, tabulated.
    walls: Vec<Shape>,
    wall_pull: Vec<f64>,
    /// The cohesive pressure K of a flat surface (see the module's comment).
    pub flat_pressure: f64,
    search: NeighbourSearch,
    list: NeighbourList,
    acceleration: Vec<Vec2>,
    /// The Verlet skin of the pair search (a length) and the candidates within
    /// reach + skin of the points at the last search, `reference`.
    skin: f64,
    candidates: NeighbourList,
    reference: Vec<Vec2>,
}

impl Cohesion {
    /// The cohesion of a fluid of density ρ and surface tension σ on particles spaced δr
    /// with kernel support r_c; with `contact_angle` θ, the flat faces of `shapes` attract it
    /// with S_w = S(1 + cos θ)/2.
    pub fn new(
        surface_tension: f64,
        density: f64,
        spacing: f64,
        support: f64,
        shapes: &[Shape],
        contact_angle: Option<f64>,
    ) -> Self {
        let bump = QuinticSpline::new(support / 6.0);
        let centre = 1.5 * support;
        let b = |r: f64| bump.value((r - centre).abs());
        let moment = |k: i32| simpson(|r| r.powi(k) * b(r), support, 2.0 * support);
        let strength = 3.0 * surface_tension / moment(3);
        let (walls, wall_pull) = match contact_angle {
            Some(theta) => {
                let pull = 0.5 * strength * (1.0 + theta.cos()) / density;
                let reach = 2.0 * support;
                let table = (0..=WALL_TABLE)
                    .map(|k| {
                        let d = reach * k as f64 / WALL_TABLE as f64;
                        pull * half_plane_pull(&b, support, reach, d)
                    })
                    .collect();
                let flat = shapes
                    .iter()
                    .copied()
                    .filter(|s| matches!(s, Shape::Plane(_) | Shape::Plate(_)));
                (flat.collect(), table)
            }
            None => (Vec::new(), Vec::new()),
        };
        Self {
            bump,
            centre,
            reach: 2.0 * support,
            scale: strength / density * spacing * spacing,
            walls,
            wall_pull,
            flat_pressure: 0.5 * std::f64::consts::PI * strength * moment(2),
            search: NeighbourSearch::new(),
            list: NeighbourList::default(),
            acceleration: Vec::new(),
            skin: SKIN * spacing,
            candidates: NeighbourList::default(),
            reference: Vec::new(),
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        self.search.heap_bytes()
            + self.list.heap_bytes()
            + self.candidates.heap_bytes()
            + crate::engine::vec_bytes(&self.reference)
            + crate::engine::vec_bytes(&self.acceleration)
            + crate::engine::vec_bytes(&self.wall_pull)
    }

    /// The cohesion and wall accelerations of the fluid particles at `points` (one list of
    /// pairs within 2r_c).
    pub fn accelerations(&mut self, domain: &Domain, points: &[Vec2]) -> &[Vec2] {
        let reach = self.reach;
        let n = points.len();
        self.pairs(domain, points);
        self.acceleration.resize(n, Vec2::zeros());
        let (list, bump, centre, scale) = (&self.list, &self.bump, self.centre, self.scale);
        let (walls, table) = (&self.walls, &self.wall_pull);
        self.acceleration
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, a)| {
                let mut sum = Vec2::zeros();
                for k in list.range(i) {
                    let d = list.rij[k];
                    let r = d.norm();
                    sum -= bump.value((r - centre).abs()) / r * d;
                }
                *a = scale * sum;
                for wall in walls {
                    if let Some((distance, normal)) = wall.face(&points[i]) {
                        *a -= lookup(table, distance, reach) * normal;
                    }
                }
            });
        &self.acceleration
    }

    /// The pairs within 2r_c at `points`, filtered from Verlet candidates: 2r_c holds about
    /// four times the kernel's pairs, and a cell search for them every step took over a
    /// quarter of a weakly compressible drop's run. The candidates (within 2r_c + skin) hold
    /// while no point has moved more than half the skin since they were found, whatever the
    /// points' order (the test is per index).
    fn pairs(&mut self, domain: &Domain, points: &[Vec2]) {
        if !moved_less_than(domain, points, &self.reference, 0.5 * self.skin) {
            let (n, radius) = (points.len(), self.reach + self.skin);
            let candidates = &mut self.candidates;
            self.search
                .build_candidates(domain, points, n, radius, candidates);
            self.reference.clear();
            self.reference.extend_from_slice(points);
        }
        let list = &mut self.list;
        self.search
            .filter(&self.candidates, domain, points, self.reach, list);
    }
}

/// The table's value at `d` ∈ [0, reach] (linear; 0 beyond).
fn lookup(table: &[f64], d: f64, reach: f64) -> f64 {
    if table.is_empty() || d >= reach {
        return 0.0;
    }
    let x = d.max(0.0) / reach * (table.len() - 1) as f64;
    let k = (x as usize).min(table.len() - 2);
    let f = x - k as f64;
    table[k] * (1.0 - f) + table[k + 1] * f
}

/// g(d) = ∫_{y>d} b(r) y/r dA for b vanishing outside [inner, outer]: on the circle of
/// radius r the arc beyond the line y = d, weighted by y/r = sin φ, has
/// ∫ sin φ r dφ = 2√(r² − d²), so g(d) = ∫_{max(d, inner)}^{outer} b(r) 2√(r² − d²) dr.
fn half_plane_pull(b: &impl Fn(f64) -> f64, inner: f64, outer: f64, d: f64) -> f64 {
    let from = d.max(inner);
    if from >= outer {
        return 0.0;
    }
    simpson(
        |r| b(r) * 2.0 * (r * r - d * d).max(0.0).sqrt(),
        from,
        outer,
    )
}

/// ∫_a^b f by composite Simpson with [`QUADRATURE`] intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let h = (b - a) / QUADRATURE as f64;
    let inner: f64 = (1..QUADRATURE)
        .map(|k| f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::Plane;

    /// A slab of liquid on the square lattice (periodic in x, 10 r_c deep): the cohesion
    /// pulls its top layers down with a total force per unit length equal to the flat
    /// surface's cohesive pressure K (the mean field's integral), and deep particles feel
    /// nothing. The lattice sum differs from the integral by the quadrature of the bump on
    /// spacings of δr (a tenth of its width): bound 2 %.
    #[test]
    fn a_flat_surface_is_pulled_in_with_the_cohesive_pressure() {
        let (dr, sigma) = (0.05, 1.0);
        let support = QuinticSpline::for_spacing(dr).support();
        let mut c = Cohesion::new(sigma, 1.0, dr, support, &[], None);
        let (nx, ny) = (40, 40);
        let domain = Domain {
            min: Vec2::new(0.0, -(ny as f64) * dr - 1.0),
            max: Vec2::new(nx as f64 * dr, 1.0),
            periodic: [true, false],
        };
        let points: Vec<Vec2> = (0..ny)
            .flat_map(|j| {
                (0..nx).map(move |i| Vec2::new((i as f64 + 0.5) * dr, -(j as f64 + 0.5) * dr))
            })
            .collect();
        let a = c.accelerations(&domain, &points).to_vec();
        // ρ = 1: the force per unit length on the upper half of the slab (its lower surface,
        // 2 = 10 r_c below, pulls the lower half up by as much: the pair forces cancel).
        let upper = &a[..nx * ny / 2];
        let pull: f64 = upper.iter().map(|a| a.y * dr * dr).sum::<f64>() / (nx as f64 * dr);
        let k = c.flat_pressure;
        assert!((-pull / k - 1.0).abs() < 0.02, "pull {pull}, K {k}");
        let deep = a[(ny / 2) * nx].norm();
        assert!(deep < 1e-12 * k / dr, "deep particle {deep}");
    }

    /// The wall's tabulated pull g(d)·S_w/ρ against a lattice of wall particles of the same
    /// strength filling the half-plane beyond it (θ = 0: S_w = S): within 2 % (of the
    /// pull at contact) at distances across the bump's reach, and zero beyond 2r_c.
    #[test]
    fn the_wall_pull_is_the_half_plane_of_wall_particles() {
        let (dr, sigma) = (0.05, 1.0);
        let support = QuinticSpline::for_spacing(dr).support();
        let wall = Shape::Plane(Plane::floor());
        let c = Cohesion::new(sigma, 1.0, dr, support, &[wall], Some(0.0));
        let contact = lookup(&c.wall_pull, 0.0, c.reach);
        for d in [0.5 * dr, 1.5 * dr, 3.5 * dr, 6.5 * dr] {
            let p = Vec2::new(0.0, d);
            let mut sum = Vec2::zeros();
            for j in 0..40 {
                for i in -40..=40 {
                    let v = p - Vec2::new(i as f64 * dr, -(j as f64 + 0.5) * dr);
                    let r = v.norm();
                    sum -= c.bump.value((r - c.centre).abs()) / r * v;
                }
            }
            let lattice = c.scale * sum.y;
            let table = -lookup(&c.wall_pull, d, c.reach);
            assert!(
                (lattice - table).abs() < 0.02 * contact,
                "d = {d}: lattice {lattice}, table {table}"
            );
        }
        assert_eq!(lookup(&c.wall_pull, 2.0 * support, c.reach), 0.0);
    }
}
