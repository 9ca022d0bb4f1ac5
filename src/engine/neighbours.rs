//! Cell-linked-list neighbour search with periodic wrap, producing CSR neighbour lists.
//!
//! Rows are the fluid particles (the first `n_rows` points); columns are all points, fluid and
//! ghost. Each row lists every point j ≠ i with |r_ij| < support, in a deterministic order
//! (cells scanned in a fixed order, points within a cell by index), together with the
//! minimum-image separation r_ij = r_i − r_j.
//!
//! Written once for D = 2 or 3 dimensions (the default 2): cells, the stencil and the box
//! are D-dimensional, visited with the first axis slowest.

use nalgebra::SVector;
use rayon::prelude::*;

/// A point or separation in D dimensions.
type Point<const D: usize> = SVector<f64, D>;

/// An axis-aligned box, periodic or not along each axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain<const D: usize = 2> {
    pub min: Point<D>,
    pub max: Point<D>,
    pub periodic: [bool; D],
}

impl<const D: usize> Domain<D> {
    pub fn size(&self) -> Point<D> {
        self.max - self.min
    }

    /// Wraps a position into the box along periodic axes.
    pub fn wrap(&self, mut p: Point<D>) -> Point<D> {
        for a in 0..D {
            if self.periodic[a] {
                let length = self.max[a] - self.min[a];
                p[a] = self.min[a] + (p[a] - self.min[a]).rem_euclid(length);
                if p[a] >= self.max[a] {
                    p[a] = self.min[a]; // rem_euclid can round up to `length`
                }
            }
        }
        p
    }

    /// Minimum-image separation along periodic axes.
    pub fn min_image(&self, mut d: Point<D>) -> Point<D> {
        for a in 0..D {
            if self.periodic[a] {
                let length = self.max[a] - self.min[a];
                if d[a] > 0.5 * length {
                    d[a] -= length;
                } else if d[a] < -0.5 * length {
                    d[a] += length;
                }
            }
        }
        d
    }
}

/// CSR neighbour lists: row i spans `offsets[i]..offsets[i + 1]` of `index` and `rij`.
#[derive(Clone, Debug, Default)]
pub struct NeighbourList<const D: usize = 2> {
    pub offsets: Vec<usize>,
    pub index: Vec<u32>,
    /// r_i − r_j (minimum image).
    pub rij: Vec<Point<D>>,
}

impl<const D: usize> NeighbourList<D> {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.offsets)
            + crate::engine::vec_bytes(&self.index)
            + crate::engine::vec_bytes(&self.rij)
    }

    pub fn rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i]..self.offsets[i + 1]
    }

    pub fn pairs(&self) -> usize {
        self.index.len()
    }

    /// Keeps in row i only the pairs closer than `radius[i]` (a per-row support; the rows
    /// were searched with the largest), in their order.
    pub fn retain_within(&mut self, radius: &[f64]) {
        let mut kept = 0;
        let mut start = 0;
        for (i, &r) in radius.iter().enumerate() {
            let end = self.offsets[i + 1];
            let r2 = r * r;
            for k in start..end {
                if self.rij[k].norm_squared() < r2 {
                    self.index[kept] = self.index[k];
                    self.rij[kept] = self.rij[k];
                    kept += 1;
                }
            }
            start = end;
            self.offsets[i + 1] = kept;
        }
        self.index.truncate(kept);
        self.rij.truncate(kept);
    }

    /// CSR offsets from the rows' `counts` (prefix sum), with `index` and (with
    /// `separations`) `rij` sized to match; without, `rij` is left empty.
    fn set_offsets(&mut self, counts: &[usize], separations: bool) {
        self.offsets.clear();
        self.offsets.reserve(counts.len() + 1);
        self.offsets.push(0);
        let mut total = 0;
        for c in counts {
            total += c;
            self.offsets.push(total);
        }
        self.index.resize(total, 0);
        self.rij
            .resize(if separations { total } else { 0 }, Point::<D>::zeros());
    }
}

/// Reusable cell-linked-list search. Buffers grow to the largest problem seen and are reused.
#[derive(Default)]
pub struct NeighbourSearch<const D: usize = 2> {
    cell_start: Vec<usize>,
    cell_points: Vec<u32>,
    point_cell: Vec<u32>,
    next: Vec<usize>,
    rows: RowBlocks<D>,
}

/// Rows gathered in blocks of [`FILTER_BLOCK`], each block into its own scratch (reused step
/// after step), then copied into place in the CSR arrays once the offsets are known.
#[derive(Default)]
struct RowBlocks<const D: usize> {
    counts: Vec<usize>,
    /// Each block's pairs (indices, separations).
    scratch: Vec<(Vec<u32>, Vec<Point<D>>)>,
    /// The CSR position where each block of rows starts (and the end).
    block_start: Vec<usize>,
}

impl<const D: usize> RowBlocks<D> {
    fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.counts)
            + crate::engine::vec_bytes(&self.block_start)
            + self
                .scratch
                .iter()
                .map(|(i, r)| crate::engine::vec_bytes(i) + crate::engine::vec_bytes(r))
                .sum::<usize>()
    }

    /// Fills `out` with rows `0..n_rows`, row i's pairs pushed by `row(i, indices,
    /// separations)` (separations kept only with `separations`).
    fn gather(
        &mut self,
        n_rows: usize,
        separations: bool,
        out: &mut NeighbourList<D>,
        row: impl Fn(usize, &mut Vec<u32>, &mut Vec<Point<D>>) + Sync,
    ) {
        let blocks = n_rows.div_ceil(FILTER_BLOCK);
        self.scratch.resize_with(blocks, Default::default);
        self.counts.resize(n_rows, 0);
        self.scratch
            .par_iter_mut()
            .zip(self.counts.par_chunks_mut(FILTER_BLOCK))
            .enumerate()
            .for_each(|(b, ((idx, rij), counts))| {
                idx.clear();
                rij.clear();
                for (i, c) in (b * FILTER_BLOCK..).zip(counts.iter_mut()) {
                    let before = idx.len();
                    row(i, idx, rij);
                    *c = idx.len() - before;
                }
            });
        out.set_offsets(&self.counts[..n_rows], separations);
        self.block_start.clear();
        self.block_start
            .extend((0..=blocks).map(|b| out.offsets[(b * FILTER_BLOCK).min(n_rows)]));
        let block_start = &self.block_start;
        let index = RowWriter::new(&mut out.index);
        let rij = separations.then(|| RowWriter::new(&mut out.rij));
        self.scratch[..blocks]
            .par_iter()
            .enumerate()
            .for_each(|(b, (idx, d))| {
                // SAFETY: the blocks' ranges of the CSR arrays are disjoint.
                unsafe { index.row(block_start, b) }.copy_from_slice(idx);
                if let Some(rij) = rij.as_ref() {
                    unsafe { rij.row(block_start, b) }.copy_from_slice(d);
                }
            });
    }
}

/// Whether every point of `points` lies within `limit` of the one of the same index in
/// `reference` (a Verlet list's test: its candidates still hold).
pub fn moved_less_than<const D: usize>(
    domain: &Domain<D>,
    points: &[Point<D>],
    reference: &[Point<D>],
    limit: f64,
) -> bool {
    points.len() == reference.len()
        && points
            .par_iter()
            .zip(reference)
            .all(|(p, r)| domain.min_image(p - r).norm_squared() <= limit * limit)
}

/// Rows per block of the filter: enough to make a block's scratch and copy cheap beside
/// its distance tests, few enough to share the rows of a small run between the threads.
const FILTER_BLOCK: usize = 128;

/// Cells per kernel support: cells of width support/2 and a 5×5 stencil cover the support
/// disc with 6.25 support² of candidates instead of the 9 support² of a 3×3 stencil of
/// support-wide cells (measured in 2D: ~30 % less time in the search; in 3D 15.6 support³
/// against 27).
const SUBDIVISION: usize = 2;
const STENCIL: usize = 2 * SUBDIVISION + 1;
/// The most cells per point a grid may have (a compact fluid needs about one; the empty
/// cells around a free surface a few).
const MAX_CELLS_PER_POINT: usize = 16;

/// Pairs closer than this fraction of the support are coincident points: they carry no
/// gradient information and would divide by zero in the Laplacian, so they are skipped.
const COINCIDENT: f64 = 1e-9;

/// Cell layout: `n[a]` cells of width `width[a]` starting at `origin[a]`, numbered with the
/// first axis slowest.
#[derive(Clone, Copy, Debug)]
struct Grid<const D: usize> {
    origin: Point<D>,
    width: Point<D>,
    n: [usize; D],
    periodic: [bool; D],
}

impl<const D: usize> Grid<D> {
    /// Cells of width support/[`SUBDIVISION`] over the box (periodic axes) or the points'
    /// extent; cells widen (never below that width, so the stencil still covers the support)
    /// where that extent would need more than [`MAX_CELLS_PER_POINT`] cells a point: a particle
    /// thrown far out in a breaking-down step must not make the grid allocate without bound
    /// before the breakdown check reports it.
    fn new(domain: &Domain<D>, points: &[Point<D>], support: f64) -> Self {
        let mut origin = domain.min;
        let cell = support / SUBDIVISION as f64;
        let mut width = Point::<D>::repeat(cell);
        let mut n = [1usize; D];
        let mut extent = [0.0; D];
        for a in 0..D {
            if domain.periodic[a] {
                let length = domain.max[a] - domain.min[a];
                n[a] = ((length / cell).floor() as usize).max(1);
                width[a] = length / n[a] as f64;
            } else {
                let (lo, hi) = points
                    .iter()
                    .filter(|p| p[a].is_finite())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(p[a]), hi.max(p[a]))
                    });
                let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) };
                origin[a] = lo;
                extent[a] = hi - lo;
            }
        }
        let cells = |width: f64, a: usize| ((extent[a] / width).floor() as usize).saturating_add(1);
        for a in (0..D).filter(|&a| !domain.periodic[a]) {
            n[a] = cells(width[a], a);
        }
        // Widen the free axis with the most cells until the count fits.
        let limit = (MAX_CELLS_PER_POINT * points.len()).max(64);
        let total = |n: &[usize; D]| n.iter().fold(1usize, |t, &k| t.saturating_mul(k));
        while total(&n) > limit {
            let Some(a) = (0..D)
                .filter(|&a| !domain.periodic[a] && n[a] > 1)
                .max_by_key(|&a| n[a])
            else {
                break;
            };
            width[a] *= 2.0;
            n[a] = cells(width[a], a);
        }
        Self {
            origin,
            width,
            n,
            periodic: domain.periodic,
        }
    }

    fn coordinate(&self, p: &Point<D>, a: usize) -> usize {
        let c = ((p[a] - self.origin[a]) / self.width[a]).floor();
        (c.max(0.0) as usize).min(self.n[a] - 1)
    }

    fn cell(&self, p: &Point<D>) -> usize {
        (1..D).fold(self.coordinate(p, 0), |c, a| {
            c * self.n[a] + self.coordinate(p, a)
        })
    }

    /// The coordinates of cell `c` along each axis.
    fn coordinates(&self, mut c: usize) -> [usize; D] {
        let mut out = [0; D];
        for a in (0..D).rev() {
            out[a] = c % self.n[a];
            c /= self.n[a];
        }
        out
    }

    fn count(&self) -> usize {
        self.n.iter().product()
    }

    /// Calls `f(cell)` for every cell of the stencil around cell `c`, the first axis
    /// slowest (an odometer over the axes' [`Self::adjacent`] lists).
    #[inline]
    fn for_each_adjacent(&self, c: usize, mut f: impl FnMut(usize)) {
        let home = self.coordinates(c);
        let lists: [([usize; STENCIL], usize); D] =
            std::array::from_fn(|a| self.adjacent(home[a], a));
        if lists.iter().any(|&(_, len)| len == 0) {
            return;
        }
        let mut at = [0usize; D];
        loop {
            let cell = (1..D).fold(lists[0].0[at[0]], |c, a| c * self.n[a] + lists[a].0[at[a]]);
            f(cell);
            let mut a = D;
            loop {
                if a == 0 {
                    return;
                }
                a -= 1;
                at[a] += 1;
                if at[a] < lists[a].1 {
                    break;
                }
                at[a] = 0;
            }
        }
    }

    /// The (up to [`STENCIL`]) cell coordinates within reach of `c` along axis `a`,
    /// deduplicated when a periodic axis has fewer cells than the stencil.
    fn adjacent(&self, c: usize, a: usize) -> ([usize; STENCIL], usize) {
        let n = self.n[a];
        let mut out = [0; STENCIL];
        let mut len = 0;
        let reach = SUBDIVISION as i64;
        for d in -reach..=reach {
            let k = c as i64 + d;
            let k = if self.periodic[a] {
                k.rem_euclid(n as i64) as usize
            } else if k < 0 || k >= n as i64 {
                continue;
            } else {
                k as usize
            };
            if !out[..len].contains(&k) {
                out[len] = k;
                len += 1;
            }
        }
        (out, len)
    }
}

/// The separations a search keeps: min_distance² < r² < support² (min_distance² < 0: every
/// pair within the support, the points themselves aside).
#[derive(Clone, Copy)]
struct Band {
    support: f64,
    min_distance2: f64,
}

impl<const D: usize> NeighbourSearch<D> {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.cell_start)
            + crate::engine::vec_bytes(&self.cell_points)
            + crate::engine::vec_bytes(&self.point_cell)
            + crate::engine::vec_bytes(&self.next)
            + self.rows.heap_bytes()
    }

    pub fn new() -> Self {
        Self::default()
    }

    /// Builds neighbour lists for rows `0..n_rows` of `points` within `support`.
    ///
    /// Periodic axes need at least three cells of width ≥ support (checked when the case is
    /// validated); otherwise a pair could be found through two images.
    pub fn build(
        &mut self,
        domain: &Domain<D>,
        points: &[Point<D>],
        n_rows: usize,
        support: f64,
        out: &mut NeighbourList<D>,
    ) {
        let min_distance2 = (COINCIDENT * support).powi(2);
        let band = Band {
            support,
            min_distance2,
        };
        self.build_within(domain, points, n_rows, band, true, out);
    }

    /// Candidate lists for a Verlet skin: every point within `radius` (coincident ones
    /// included: they may part before the next build), each row sorted by index, the order
    /// [`Self::filter`] keeps. The separations are not kept (`rij` is left empty).
    pub fn build_candidates(
        &mut self,
        domain: &Domain<D>,
        points: &[Point<D>],
        n_rows: usize,
        radius: f64,
        out: &mut NeighbourList<D>,
    ) {
        // A negative squared distance: no pair is skipped.
        let band = Band {
            support: radius,
            min_distance2: -1.0,
        };
        self.build_within(domain, points, n_rows, band, false, out);
        let offsets = &out.offsets;
        let index = RowWriter::new(&mut out.index);
        (0..n_rows).into_par_iter().for_each(|i| {
            // SAFETY: CSR row ranges are disjoint and each row is visited by one task.
            unsafe { index.row(offsets, i) }.sort_unstable();
        });
    }

    /// The pairs of `candidates` closer than `support` at `points` (and not coincident),
    /// rows in the candidates' order: the lists [`Self::build`] would find, sorted by index.
    pub fn filter(
        &mut self,
        candidates: &NeighbourList<D>,
        domain: &Domain<D>,
        points: &[Point<D>],
        support: f64,
        out: &mut NeighbourList<D>,
    ) {
        let n_rows = candidates.rows();
        let (support2, coincident2) = (support * support, (COINCIDENT * support).powi(2));
        let within = |i: usize, j: u32| {
            let d = domain.min_image(points[i] - points[j as usize]);
            let r2 = d.norm_squared();
            (r2 < support2 && r2 > coincident2).then_some(d)
        };
        let mut rows = std::mem::take(&mut self.rows);
        rows.gather(n_rows, true, out, |i, idx, rij| {
            for &j in &candidates.index[candidates.range(i)] {
                if let Some(d) = within(i, j) {
                    idx.push(j);
                    rij.push(d);
                }
            }
        });
        self.rows = rows;
    }

    /// [`Self::build`] with pairs whose squared distance is at most `min_distance2` skipped,
    /// and the separations kept only with `separations`.
    fn build_within(
        &mut self,
        domain: &Domain<D>,
        points: &[Point<D>],
        n_rows: usize,
        band: Band,
        separations: bool,
        out: &mut NeighbourList<D>,
    ) {
        let grid = Grid::new(domain, points, band.support);
        self.bin(&grid, points);
        // One pass into [`RowBlocks`] (a count pass before a fill pass measured every
        // distance twice).
        let mut rows = std::mem::take(&mut self.rows);
        let this = &*self;
        rows.gather(n_rows, separations, out, |i, idx, rij| {
            this.visit(&grid, domain, points, i, band, |j, d| {
                idx.push(j);
                if separations {
                    rij.push(d);
                }
            });
        });
        self.rows = rows;
    }

    /// Calls `f(j, r_ij)` for every point j ≠ i of the cells adjacent to i's with
    /// r_ij in `band`, in cell order.
    #[inline]
    fn visit(
        &self,
        grid: &Grid<D>,
        domain: &Domain<D>,
        points: &[Point<D>],
        i: usize,
        band: Band,
        mut f: impl FnMut(u32, Point<D>),
    ) {
        let support2 = band.support * band.support;
        let min_distance2 = band.min_distance2;
        let pi = points[i];
        grid.for_each_adjacent(self.point_cell[i] as usize, |cell| {
            for &j in &self.cell_points[self.cell_start[cell]..self.cell_start[cell + 1]] {
                if j as usize == i {
                    continue;
                }
                let d = domain.min_image(pi - points[j as usize]);
                let r2 = d.norm_squared();
                if r2 < support2 && r2 > min_distance2 {
                    f(j, d);
                }
            }
        });
    }

    /// Counting sort of the points into cells (stable: points stay in index order).
    fn bin(&mut self, grid: &Grid<D>, points: &[Point<D>]) {
        let cells = grid.count();
        self.point_cell.clear();
        self.point_cell
            .extend(points.iter().map(|p| grid.cell(p) as u32));
        self.cell_start.clear();
        self.cell_start.resize(cells + 1, 0);
        for &c in &self.point_cell {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.cell_points.resize(points.len(), 0);
        self.next.clear();
        self.next.extend_from_slice(&self.cell_start);
        for (i, &c) in self.point_cell.iter().enumerate() {
            self.cell_points[self.next[c as usize]] = i as u32;
            self.next[c as usize] += 1;
        }
    }
}

/// Parallel writes into the disjoint rows of a CSR array without splitting it into a vector
/// of slices (which would allocate every step).
pub struct RowWriter<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: a RowWriter only hands out rows through `row`, whose callers guarantee disjointness.
unsafe impl<T: Send> Send for RowWriter<T> {}
unsafe impl<T: Send> Sync for RowWriter<T> {}

impl<T> RowWriter<T> {
    pub fn new(data: &mut [T]) -> Self {
        Self {
            ptr: data.as_mut_ptr(),
            len: data.len(),
        }
    }

    /// The mutable slice of row `i`.
    ///
    /// # Safety
    /// No two live slices may overlap: call at most once per row at a time, with
    /// non-decreasing `offsets` within the written array.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn row(&self, offsets: &[usize], i: usize) -> &mut [T] {
        let (start, end) = (offsets[i], offsets[i + 1]);
        assert!(start <= end && end <= self.len);
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(start), end - start) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::{Vec2, Vec3};

    fn brute_force<const D: usize>(
        domain: &Domain<D>,
        points: &[Point<D>],
        n_rows: usize,
        support: f64,
    ) -> Vec<Vec<u32>> {
        (0..n_rows)
            .map(|i| {
                let mut v: Vec<u32> = (0..points.len())
                    .filter(|&j| j != i)
                    .filter(|&j| domain.min_image(points[i] - points[j]).norm() < support)
                    .map(|j| j as u32)
                    .collect();
                v.sort();
                v
            })
            .collect()
    }

    /// Pseudo-random but reproducible points (a Weyl sequence).
    fn points(n: usize, domain: &Domain, spill: f64) -> Vec<Vec2> {
        let size = domain.size();
        (0..n)
            .map(|k| {
                let u = (k as f64 * 0.754_877_666).fract();
                let v = (k as f64 * 0.569_840_290 + 0.1).fract();
                Vec2::new(
                    domain.min.x + u * size.x,
                    domain.min.y - spill + v * (size.y + 2.0 * spill),
                )
            })
            .collect()
    }

    fn check(domain: Domain, support: f64) {
        let pts = points(1500, &domain, if domain.periodic[1] { 0.0 } else { 0.2 });
        let n_rows = 1000;
        let mut list = NeighbourList::default();
        NeighbourSearch::new().build(&domain, &pts, n_rows, support, &mut list);
        let expected = brute_force(&domain, &pts, n_rows, support);
        for (i, exp) in expected.iter().enumerate() {
            let mut got: Vec<u32> = list.index[list.range(i)].to_vec();
            got.sort();
            assert_eq!(&got, exp, "row {i}");
            for k in list.range(i) {
                let j = list.index[k] as usize;
                let d = domain.min_image(pts[i] - pts[j]);
                assert!((list.rij[k] - d).norm() < 1e-14);
            }
        }
    }

    /// The unit square, periodic in x (a channel's box).
    fn unit_channel() -> Domain {
        Domain {
            min: Vec2::new(0.0, 0.0),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, false],
        }
    }

    /// Candidates within support + skin, filtered after every point moved less than half the
    /// skin, give exactly the pairs within the support, each row sorted by index.
    #[test]
    fn filtered_candidates_match_brute_force_after_small_moves() {
        let domain = unit_channel();
        let (support, skin) = (0.13, 0.04);
        let pts = points(1500, &domain, 0.2);
        let n_rows = 1000;
        let mut search = NeighbourSearch::new();
        let mut candidates = NeighbourList::default();
        search.build_candidates(&domain, &pts, n_rows, support + skin, &mut candidates);
        // Moves of up to 0.49 skin in pseudo-random directions, wrapped in x.
        let moved: Vec<Vec2> = pts
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let angle = (k as f64 * 0.618_034).fract() * std::f64::consts::TAU;
                domain.wrap(p + 0.49 * skin * Vec2::new(angle.cos(), angle.sin()))
            })
            .collect();
        let mut list = NeighbourList::default();
        search.filter(&candidates, &domain, &moved, support, &mut list);
        let expected = brute_force(&domain, &moved, n_rows, support);
        for (i, exp) in expected.iter().enumerate() {
            assert_eq!(&list.index[list.range(i)], &exp[..], "row {i}");
            for k in list.range(i) {
                let d = domain.min_image(moved[i] - moved[list.index[k] as usize]);
                assert_eq!(list.rij[k], d);
            }
        }
    }

    #[test]
    fn matches_brute_force_periodic_in_x() {
        let domain = unit_channel();
        check(domain, 0.13);
        // The smallest periodic box the search supports: exactly three cells.
        check(domain, 0.3333);
    }

    /// A particle thrown far out (as in a step that breaks down, before the check reports
    /// it) widens the cells instead of allocating a cell per support width of its distance
    /// (a jet run once asked for 3.7·10¹³ bytes); the lists stay exact.
    #[test]
    fn a_far_outlier_widens_the_cells_and_keeps_the_lists_exact() {
        for domain in [
            unit_channel(),
            Domain {
                min: Vec2::new(0.0, 0.0),
                max: Vec2::new(1.0, 1.0),
                periodic: [false, false],
            },
        ] {
            let mut pts = points(1500, &domain, 0.2);
            pts[7] = Vec2::new(0.5, 1.0e12);
            pts[11] = Vec2::new(f64::INFINITY, f64::NAN);
            let grid = Grid::new(&domain, &pts, 0.13);
            assert!(
                grid.count() <= MAX_CELLS_PER_POINT * pts.len(),
                "{:?}",
                grid.n
            );
            let mut list = NeighbourList::default();
            NeighbourSearch::new().build(&domain, &pts, 1000, 0.13, &mut list);
            let expected = brute_force(&domain, &pts, 1000, 0.13);
            for (i, exp) in expected.iter().enumerate().filter(|(i, _)| *i != 11) {
                let mut got: Vec<u32> = list.index[list.range(i)].to_vec();
                got.sort();
                assert_eq!(&got, exp, "row {i}");
            }
        }
    }

    #[test]
    fn matches_brute_force_doubly_periodic() {
        let domain = Domain {
            min: Vec2::new(-0.5, 2.0),
            max: Vec2::new(1.5, 3.0),
            periodic: [true, true],
        };
        check(domain, 0.17);
    }

    #[test]
    fn wrap_and_min_image() {
        let d = unit_channel();
        let w = d.wrap(Vec2::new(-0.25, 1.5));
        assert!((w.x - 0.75).abs() < 1e-15 && w.y == 1.5);
        let m = d.min_image(Vec2::new(0.9, 0.9));
        assert!((m.x + 0.1).abs() < 1e-15 && m.y == 0.9);
    }

    /// In 3D, a box periodic in x and z (a channel's, or a pipe's along x) with points
    /// spilling past the free y faces: the lists are the brute-force ones, the separations
    /// the minimum images, and after moves below half the skin the filtered candidates are
    /// the lists again, each row in index order.
    #[test]
    fn matches_brute_force_in_3d() {
        let domain = Domain::<3> {
            min: Vec3::new(0.0, 0.0, -0.5),
            max: Vec3::new(1.0, 0.6, 0.5),
            periodic: [true, false, true],
        };
        let weyl = |k: usize, a: f64| (k as f64 * a + 0.1).fract();
        let pts: Vec<Vec3> = (0..3000)
            .map(|k| {
                let u = Vec3::new(
                    weyl(k, 0.819_172_513),
                    weyl(k, 0.671_043_606),
                    weyl(k, 0.549_700_477),
                );
                Vec3::new(u.x, -0.1 + 0.8 * u.y, -0.5 + u.z)
            })
            .collect();
        let (n_rows, support, skin) = (2000, 0.17, 0.04);
        let mut search = NeighbourSearch::<3>::new();
        let mut list = NeighbourList::default();
        search.build(&domain, &pts, n_rows, support, &mut list);
        let expected = brute_force(&domain, &pts, n_rows, support);
        let pairs: usize = expected.iter().map(Vec::len).sum();
        assert!(
            pairs > 20 * n_rows,
            "{pairs} pairs: too sparse to test anything"
        );
        for (i, exp) in expected.iter().enumerate() {
            let mut got: Vec<u32> = list.index[list.range(i)].to_vec();
            got.sort();
            assert_eq!(&got, exp, "row {i}");
            for k in list.range(i) {
                let d = domain.min_image(pts[i] - pts[list.index[k] as usize]);
                assert_eq!(list.rij[k], d);
            }
        }
        let mut candidates = NeighbourList::default();
        search.build_candidates(&domain, &pts, n_rows, support + skin, &mut candidates);
        let moved: Vec<Vec3> = pts
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let direction =
                    Vec3::new(weyl(k, 0.31), weyl(k, 0.77), weyl(k, 0.53)).add_scalar(-0.5);
                domain.wrap(p + 0.49 * skin * direction.normalize())
            })
            .collect();
        assert!(moved_less_than(&domain, &moved, &pts, 0.5 * skin));
        search.filter(&candidates, &domain, &moved, support, &mut list);
        let expected = brute_force(&domain, &moved, n_rows, support);
        for (i, exp) in expected.iter().enumerate() {
            assert_eq!(&list.index[list.range(i)], &exp[..], "row {i}");
        }
    }
}
