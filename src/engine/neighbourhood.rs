//! Step 2's particle configuration: the positions r*, the wall mirrors, the CSR neighbour
//! lists and the kernel sums (pair factors and Bonet–Lok L_i, eq. (22)) every operator reads.
//! Updated every step when the particles move, once when they do not.
//!
//! The cell search runs only now and then (Verlet 1967's skin): it lists as candidates every
//! point within support + skin, with the mirrors of every particle within that reach of a
//! wall, and each step keeps the candidates within the support. That is exact while no point
//! (nor wall) has moved more than skin/2 since the search: a pair within the support now was
//! within support + skin then. Candidate rows are sorted by index, so the lists are the same
//! whatever the (non-zero) skin and whenever the search last ran (and after a restart).
//! Without a skin the search runs every step and its rows keep its cell order: the same
//! pairs, summed in another order (results differ from a skinned run's in round-off).

use crate::engine::boundary::continuation::PairKernel;
use crate::engine::boundary::Ghosts;
use crate::engine::dimension::{Dim, Dimension};
use crate::engine::kernel::QuinticSpline;
use crate::engine::neighbours::{moved_less_than, Domain, NeighbourList, NeighbourSearch};
use crate::engine::operators::KernelSums;
use crate::engine::ordering::Reorder;
use crate::engine::resolution::{Graded, Local, Resolution};
use crate::engine::settings::{in_range, Invalid};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// A step's neighbourhood as the operators read it: the pair lists, their kernel sums and the
/// ghosts that extend the fields beyond walls.
pub struct Hood<'a, const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub list: &'a NeighbourList<D>,
    pub sums: &'a KernelSums<D>,
    pub ghosts: &'a Ghosts<D>,
}

impl<const D: usize> Clone for Hood<'_, D>
where
    Dim<D>: Dimension<D>,
{
    fn clone(&self) -> Self {
        *self
    }
}

impl<const D: usize> Copy for Hood<'_, D> where Dim<D>: Dimension<D> {}

/// Where the particles are searched and summed: the domain, the kernel and the lattice
/// spacing δr.
#[derive(Clone, Copy)]
pub struct Geometry<'a, const D: usize = 2> {
    pub domain: &'a Domain<D>,
    pub kernel: &'a QuinticSpline,
    pub spacing: f64,
}

#[cfg(test)]
impl<'a> Hood<'a> {
    /// The lists and sums of a particle set without walls, for unit tests.
    pub fn without_walls(list: &'a NeighbourList, sums: &'a KernelSums) -> Self {
        static NONE: std::sync::LazyLock<Ghosts> = std::sync::LazyLock::new(Ghosts::default);
        Self {
            list,
            sums,
            ghosts: &NONE,
        }
    }
}

/// `[scheme.neighbours]`: the neighbour search and the particles' order in memory. Results do
/// not depend on them, only the time per step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct NeighbourSettings {
    /// The Verlet skin in units of δr (0: a cell search every step; unset: [`default_skin`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skin: Option<f64>,
    /// Periodically sort particles along a Morton curve for memory locality.
    pub reorder: bool,
}

impl Default for NeighbourSettings {
    fn default() -> Self {
        Self {
            skin: None,
            reorder: true,
        }
    }
}

impl NeighbourSettings {
    /// The table's own checks (keys relative to `[scheme.neighbours]`).
    pub fn validate(&self) -> Result<(), Invalid> {
        self.skin
            .map(|v| in_range("skin", v, 0.0, 4.0))
            .transpose()?;
        Ok(())
    }
}

/// δr^D, a particle's volume on a lattice of spacing δr.
pub fn cell_volume<const D: usize>(spacing: f64) -> f64 {
    (0..D).fold(1.0, |v, _| v * spacing)
}

/// The skin `scheme.neighbours.skin` defaults to, in units of δr, when it pays: the cell search
/// costs 2–3 filterings of its candidates (`rheosph bench`), and 0.5δr lets the particles of
/// the default explicit case move ~15 steps between searches.
pub const SKIN: f64 = 0.5;

/// The default skin (a length) for particles moving up to `displacement` per step: [`SKIN`]δr
/// when that leaves at least four steps between searches, none otherwise (a large implicit
/// step moves particles ~0.26δr: every step would search anyway, and a search with a skin
/// costs more than one without).
pub fn default_skin(spacing: f64, displacement: f64) -> f64 {
    let skin = SKIN * spacing;
    if displacement <= skin / 8.0 {
        skin
    } else {
        0.0
    }
}

/// Points (fluid then ghosts), neighbour lists and kernel sums of one configuration, in D
/// dimensions (the default 2).
pub struct Neighbourhood<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    /// r* of the fluid particles followed by the ghosts' positions.
    pub points: Vec<SVector<f64, D>>,
    pub ghosts: Ghosts<D>,
    pub list: NeighbourList<D>,
    pub sums: KernelSums<D>,
    search: NeighbourSearch<D>,
    /// Point volumes relative to δV (empty: all 1).
    volumes: Vec<f64>,
    /// The lists describe the current particles (false after a reordering or restore).
    valid: bool,
    reorder: Reorder<D>,
    /// Every point within support + skin at the last search, rows sorted by index.
    candidates: NeighbourList<D>,
    /// The points (fluid and ghosts) at the last search.
    reference: Vec<SVector<f64, D>>,
    /// The candidates describe the current particles and ghosts.
    candidates_valid: bool,
    /// The skin, a length (zero: a search every step).
    skin: f64,
    /// Cell searches run so far.
    searches: usize,
    /// The particles' layout ([`crate::engine::resolution`]).
    resolution: Resolution<D>,
    /// Under graded resolution, each fluid particle's spacing and volume (empty: uniform).
    local: Vec<Local>,
    /// Under graded resolution, each row's spacing and support.
    row_spacing: Vec<f64>,
    row_support: Vec<f64>,
}

impl<const D: usize> Default for Neighbourhood<D>
where
    Dim<D>: Dimension<D>,
{
    fn default() -> Self {
        Self::new(Ghosts::default())
    }
}

impl<const D: usize> Neighbourhood<D>
where
    Dim<D>: Dimension<D>,
{
    /// A configuration with mirrors by `ghosts`, searched every step until [`Self::set_skin`].
    pub fn new(ghosts: Ghosts<D>) -> Self {
        Self {
            points: Vec::new(),
            ghosts,
            list: NeighbourList::default(),
            sums: KernelSums::default(),
            search: NeighbourSearch::new(),
            volumes: Vec::new(),
            valid: false,
            reorder: Reorder::default(),
            candidates: NeighbourList::default(),
            reference: Vec::new(),
            candidates_valid: false,
            skin: 0.0,
            searches: 0,
            resolution: Resolution::Uniform,
            local: Vec::new(),
            row_spacing: Vec::new(),
            row_support: Vec::new(),
        }
    }

    /// Sets the Verlet skin to `skin` (a length), narrowed so that no mirror can be placed
    /// through a circle into the fluid beyond; the next update searches.
    pub fn set_skin(&mut self, skin: f64, support: f64) {
        let deepest = self
            .ghosts
            .walls
            .iter()
            .map(|w| w.shape.mirror_depth())
            .fold(f64::INFINITY, f64::min);
        self.skin = skin.min(deepest - support).max(0.0);
        self.invalidate();
    }

    /// Grades the particles' resolution (fixed particles only: the lists are built once).
    pub fn set_resolution(&mut self, resolution: Resolution<D>) {
        self.resolution = resolution;
        self.invalidate();
    }

    /// Each fluid particle's spacing and volume under graded resolution (empty: uniform).
    pub fn local(&self) -> &[Local] {
        &self.local
    }

    /// Cell searches run so far (a step that reuses the candidates runs none).
    pub fn searches(&self) -> usize {
        self.searches
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.points)
            + self.ghosts.heap_bytes()
            + self.search.heap_bytes()
            + self.list.heap_bytes()
            + self.sums.heap_bytes()
            + crate::engine::vec_bytes(&self.volumes)
            + self.reorder.heap_bytes()
            + self.candidates.heap_bytes()
            + crate::engine::vec_bytes(&self.reference)
    }

    /// The three parts every operator takes.
    pub fn parts(&self) -> Hood<'_, D> {
        Hood {
            list: &self.list,
            sums: &self.sums,
            ghosts: &self.ghosts,
        }
    }

    /// The lists no longer describe the particles.
    pub fn invalidate(&mut self) {
        self.valid = false;
        self.candidates_valid = false;
    }

    /// Mirrors, lists and kernel sums for the first `n` points (the fluid particles at r*),
    /// when `moving` or not yet built. Returns whether the configuration was rebuilt.
    pub fn update(&mut self, moving: bool, geometry: Geometry<D>, n: usize) -> bool {
        let Geometry {
            domain,
            kernel,
            spacing,
        } = geometry;
        if !moving && self.valid {
            return false;
        }
        self.ghosts.domain = Some(*domain);
        let support = kernel.support();
        if let Resolution::Graded(graded) = std::mem::take(&mut self.resolution) {
            self.update_graded(&graded, geometry, n);
            self.resolution = Resolution::Graded(graded);
            return true;
        }
        if self.skin == 0.0 || !self.ghosts.can_refresh() {
            // No skin (or ghosts a search must place anew, the fixed lattice's): the cell
            // search every step, rows in its cell order.
            self.cell_search(domain, n, support, false);
        } else {
            if !self.candidates_hold(domain, n) {
                self.cell_search(domain, n, support + self.skin, true);
            }
            self.search.filter(
                &self.candidates,
                domain,
                &self.points,
                support,
                &mut self.list,
            );
        }
        if self.ghosts.has_volume_ratios() {
            self.ghosts.point_volumes(n, &mut self.volumes);
        } else {
            self.volumes.clear();
        }
        self.sums
            .update_with_volumes(&self.list, kernel, cell_volume::<D>(spacing), &self.volumes);
        self.prepare_continuation(n, support);
        true
    }

    /// [`Self::update`] under graded resolution: the search with the bulk's support, each
    /// row then cut to its own (3h_i), and the kernel sums with each row's kernel and each
    /// point's volume (a mirror's its parent's, times its wall's ratio).
    fn update_graded(&mut self, graded: &Graded<D>, geometry: Geometry<D>, n: usize) {
        let Geometry {
            domain,
            kernel,
            spacing,
        } = geometry;
        let support = kernel.support();
        self.local.clear();
        self.local
            .extend(self.points[..n].iter().map(|p| graded.at(p, domain)));
        self.cell_search(domain, n, support, false);
        self.row_spacing.clear();
        self.row_spacing
            .extend(self.local.iter().map(|l| l.spacing));
        self.row_support.clear();
        self.row_support.extend(
            self.row_spacing
                .iter()
                .map(|&s| QuinticSpline::for_spacing(s).support()),
        );
        self.list.retain_within(&self.row_support);
        let dv = cell_volume::<D>(spacing);
        self.ghosts.point_volumes(n, &mut self.volumes);
        for (v, l) in self.volumes.iter_mut().zip(&self.local) {
            *v = l.volume / dv;
        }
        for (g, &parent) in self.ghosts.parent.iter().enumerate() {
            self.volumes[n + g] *= self.local[parent as usize].volume / dv;
        }
        self.sums
            .update_graded(&self.list, kernel, &self.row_spacing, dv, &self.volumes);
        self.prepare_continuation(n, support);
    }

    /// The walls' continuations from the new lists and kernel sums; the lists are then valid.
    fn prepare_continuation(&mut self, n: usize, support: f64) {
        let pairs = PairKernel {
            list: &self.list,
            value: &self.sums.value,
            factor: &self.sums.factor,
        };
        self.ghosts.prepare_continuation(pairs, n, support);
        self.valid = true;
    }

    /// Mirrors of the particles within `reach` of a wall and the cell search for the pairs
    /// within `reach`: the step's lists, or (`candidates`) the skin's candidates.
    fn cell_search(&mut self, domain: &Domain<D>, n: usize, reach: f64, candidates: bool) {
        self.points.truncate(n);
        self.ghosts.build(reach, &mut self.points);
        if candidates {
            self.search
                .build_candidates(domain, &self.points, n, reach, &mut self.candidates);
            self.reference.clone_from(&self.points);
            self.candidates_valid = true;
        } else {
            self.search
                .build(domain, &self.points, n, reach, &mut self.list);
        }
        self.searches += 1;
    }

    /// Moves the mirrors of the last search to the particles at r* (the first `n` points)
    /// and says whether its candidates still hold: the same particles, no point and no wall
    /// moved more than half the skin since.
    fn candidates_hold(&mut self, domain: &Domain<D>, n: usize) -> bool {
        if !self.candidates_valid || self.candidates.rows() != n {
            return false;
        }
        self.ghosts.refresh(&mut self.points);
        let half = 0.5 * self.skin;
        self.ghosts.drift() <= half && moved_less_than(domain, &self.points, &self.reference, half)
    }

    /// The Morton order of `positions` (see [`crate::engine::ordering`]), to permute every
    /// per-particle array with; None when they are in that order already.
    pub fn reorder(
        &mut self,
        domain: &Domain<D>,
        positions: &[SVector<f64, D>],
        cell: f64,
    ) -> Option<&mut Reorder<D>> {
        if self.reorder.compute(domain, positions, cell) {
            self.invalidate();
            Some(&mut self.reorder)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::{Plane, Shape, TensorMirror, Tube, Wall};
    use crate::engine::kernel::H_OVER_DR;
    use crate::engine::math::{Sym3, Vec3};

    /// A 3D channel between plates at y = 0 and 1, periodic in x and z, δr = 1/8: the
    /// neighbourhood of its lattice with mirrors, through [`Neighbourhood::update`].
    fn plates_3d() -> (Neighbourhood<3>, usize) {
        let m = 8;
        let dr = 1.0 / m as f64;
        let points: Vec<Vec3> = (0..m * m * m)
            .map(|k| Vec3::new((k / (m * m)) as f64, ((k / m) % m) as f64, (k % m) as f64))
            .map(|c| (c.add_scalar(0.5)) * dr)
            .collect();
        let n = points.len();
        let plane = |position, fluid_side| Plane {
            axis: 1,
            position,
            fluid_side,
        };
        let walls = [plane(0.0, 1.0), plane(1.0, -1.0)]
            .map(|p| Wall::<3>::no_slip(Shape::Plane(p), TensorMirror::Linear));
        let domain = Domain::<3> {
            min: Vec3::new(0.0, -1.0, 0.0),
            max: Vec3::new(1.0, 2.0, 1.0),
            periodic: [true, false, true],
        };
        (built(walls.to_vec(), points, &domain, dr), n)
    }

    /// The neighbourhood of `points` (all fluid) with `walls`' mirrors, spacing `dr`.
    fn built(
        walls: Vec<Wall<3>>,
        points: Vec<Vec3>,
        domain: &Domain<3>,
        dr: f64,
    ) -> Neighbourhood<3> {
        let n = points.len();
        let mut hood = Neighbourhood::<3>::new(Ghosts::new(walls));
        hood.points = points;
        let kernel = QuinticSpline::in_dimension::<3>(H_OVER_DR * dr);
        let geometry = Geometry {
            domain,
            kernel: &kernel,
            spacing: dr,
        };
        assert!(hood.update(true, geometry, n));
        hood
    }

    /// Between 3D plates the mirrors fill every wall particle's support: each row sees as
    /// many points as a bulk row (the lattice is symmetric about each wall), and Morris's
    /// Laplacian (21) of the Poiseuille profile u = 4y(1 − y) x̂, read through the quadratic
    /// continuation, is −8 in every row, wall rows as bulk ones, to round-off (measured
    /// 1.1e-13 on this lattice; bound 1e-9). The odd mirror misses the curvature (the first
    /// layer reads −4.9: bound, off by more than 1), which is why the continuation exists.
    /// The linear tensor continuation carries T = T₀ + y T₁ exactly onto every ghost.
    #[test]
    fn mirrors_and_continuations_fill_the_support_between_3d_plates() {
        let (hood, n) = plates_3d();
        let (list, sums, ghosts) = (&hood.list, &hood.sums, &hood.ghosts);
        let bulk = list.range(4 * 64 + 4 * 8 + 4).len();
        for i in 0..n {
            assert_eq!(list.range(i).len(), bulk, "row {i}");
        }
        let u = |r: &Vec3| Vec3::new(4.0 * r.y * (1.0 - r.y), 0.0, 0.0);
        let fluid: Vec<Vec3> = hood.points[..n].iter().map(u).collect();
        let mut ext = Vec::new();
        ghosts.continue_velocity(&fluid, &mut ext);
        for g in 0..ghosts.len() {
            assert!((ext[n + g] - u(&hood.points[n + g])).norm() < 1e-9);
        }
        let mut lap = vec![Vec3::zeros(); n];
        sums.laplacian_vector(list, &ext, &mut lap);
        for (i, l) in lap.iter().enumerate() {
            assert!((l.x + 8.0).abs() < 1e-9, "row {i}: {}", l.x);
            assert!(l.y.abs() < 1e-9 && l.z.abs() < 1e-9);
        }
        let mut mirrored = Vec::new();
        ghosts.extend_velocity(&fluid, &mut mirrored);
        sums.laplacian_vector(list, &mirrored, &mut lap);
        let worst = lap.iter().map(|l| (l.x + 8.0).abs()).fold(0.0, f64::max);
        assert!(worst > 1.0, "the odd mirror misses the curvature: {worst}");
        let t0 = Sym3::new(1.0, 0.2, -0.3, 0.5, 0.7, -1.1);
        let t1 = Sym3::new(-0.4, 0.9, 0.1, 0.3, -0.2, 0.6);
        let t = |r: &Vec3| t0 + t1 * r.y;
        let fluid: Vec<Sym3> = hood.points[..n].iter().map(t).collect();
        let mut ext = Vec::new();
        ghosts.continue_tensor(&fluid, &mut ext);
        for g in 0..ghosts.len() {
            let d = ext[n + g] - t(&hood.points[n + g]);
            assert!(d.contract(&d).sqrt() < 1e-9, "ghost {g}: {d:?}");
        }
    }

    /// Rings of a circle of `rings` δr radius about the origin: ring k at (k + ½)δr from the
    /// wall, round(2πρ/δr) points on it, the innermost ring's half spacing at the centre.
    fn ring_section(rings: usize, dr: f64) -> Vec<crate::engine::math::Vec2> {
        let radius = rings as f64 * dr;
        let mut points = Vec::new();
        for k in 0..rings {
            let rho = radius - (k as f64 + 0.5) * dr;
            let count = (std::f64::consts::TAU * rho / dr).round().max(1.0) as usize;
            let offset = 0.5 * (k % 2) as f64;
            points.extend((0..count).map(|j| {
                let angle = std::f64::consts::TAU * (j as f64 + offset) / count as f64;
                crate::engine::math::Vec2::new(rho * angle.cos(), rho * angle.sin())
            }));
        }
        points
    }

    /// The inside of a 3D pipe of radius ½ along x (periodic over 10 δr), δr = 1/16: rings
    /// of particles in each cross-section, their mirrors across the tube's wall.
    fn pipe_3d() -> (Neighbourhood<3>, usize, Tube<3>) {
        let m = 16;
        let dr = 1.0 / m as f64;
        let tube = Tube::<3> {
            centre: Vec3::new(0.0, 0.5, 0.5),
            radius: 0.5,
            axis: Some(0),
        };
        // Ten layers along the axis (a periodic length above two supports); in each, rings
        // at (k + ½)δr inside the wall, as a pipe scene lays its particles out.
        let rings = ring_section(m / 2, dr);
        let points: Vec<Vec3> = (0..10)
            .flat_map(|layer| {
                let x = (layer as f64 + 0.5) * dr;
                rings
                    .iter()
                    .map(move |q| Vec3::new(x, 0.5 + q.x, 0.5 + q.y))
            })
            .collect();
        let n = points.len();
        let wall = Wall::<3>::no_slip(Shape::Tube(tube), TensorMirror::Linear);
        let domain = Domain::<3> {
            min: Vec3::new(0.0, -0.5, -0.5),
            max: Vec3::new(10.0 * dr, 1.5, 1.5),
            periodic: [true, false, false],
        };
        (built(vec![wall], points, &domain, dr), n, tube)
    }

    /// Inside a 3D pipe every mirror lies outside the wall, as deep behind it as its parent
    /// is in front, on the parent's radius; the quadratic continuation carries the pipe's
    /// Poiseuille profile u = (1 − 4ρ²) x̂ (ρ from the axis, R = ½) exactly onto the mirrors.
    /// Morris's Laplacian (21) of it, −16, is not exact on rings of particles anywhere (the
    /// lattice is not a cubic one): measured worst 0.50 in the bulk and 0.44 in the rows
    /// within a support of the wall, so the mirrors fill the wall rows' supports as well as
    /// the fluid fills the bulk's; bound 0.8 (5 %) for both. The odd mirror misses the
    /// curvature there (worst 3.7; bound: more than 2). On a Cartesian lattice cut by the
    /// wall the first layer's distance from it ranges from 0 to δr and no mirror fills those
    /// supports (wall rows off by up to 11 of 16): a pipe scene lays its particles in rings.
    #[test]
    fn mirrors_across_the_inside_of_a_3d_pipe() {
        let (hood, n, tube) = pipe_3d();
        let (list, sums, ghosts) = (&hood.list, &hood.sums, &hood.ghosts);
        assert!(
            ghosts.len() > n / 2,
            "{} ghosts for {n} particles",
            ghosts.len()
        );
        for g in 0..ghosts.len() {
            let (ghost, parent) = (hood.points[n + g], hood.points[ghosts.parent[g] as usize]);
            let behind = -tube.distance(&ghost);
            assert!((behind - tube.distance(&parent)).abs() < 1e-12, "ghost {g}");
            assert!((ghost.x - parent.x).abs() < 1e-12);
            let (a, b) = (tube.normal(&ghost), tube.normal(&parent));
            assert!((a - b).norm() < 1e-12, "ghost {g} off its parent's radius");
        }
        let u = |r: &Vec3| {
            let rho2 = (r.y - 0.5).powi(2) + (r.z - 0.5).powi(2);
            Vec3::new(1.0 - 4.0 * rho2, 0.0, 0.0)
        };
        let fluid: Vec<Vec3> = hood.points[..n].iter().map(u).collect();
        let mut ext = Vec::new();
        ghosts.continue_velocity(&fluid, &mut ext);
        for g in 0..ghosts.len() {
            assert!(
                (ext[n + g] - u(&hood.points[n + g])).norm() < 1e-9,
                "ghost {g}"
            );
        }
        let mut lap = vec![Vec3::zeros(); n];
        sums.laplacian_vector(list, &ext, &mut lap);
        let support = QuinticSpline::in_dimension::<3>(H_OVER_DR / 16.0).support();
        let worst = |lap: &[Vec3], near_wall: bool| {
            let rows = lap.iter().zip(&hood.points[..n]);
            rows.filter(|(_, p)| (tube.distance(p) < support) == near_wall)
                .map(|(l, _)| (l.x + 16.0).abs())
                .fold(0.0, f64::max)
        };
        let (bulk, wall) = (worst(&lap, false), worst(&lap, true));
        assert!(
            bulk < 0.8 && wall < 0.8,
            "bulk {bulk:.3}, wall rows {wall:.3}"
        );
        let mut mirrored = Vec::new();
        ghosts.extend_velocity(&fluid, &mut mirrored);
        sums.laplacian_vector(list, &mirrored, &mut lap);
        let odd = worst(&lap, true);
        assert!(odd > 2.0, "the odd mirror misses the curvature: {odd:.3}");
    }
}
