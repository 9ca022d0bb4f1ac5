//! The Morris Laplacian (21) as a sparse matrix over the fluid particles, with wall mirrors
//! folded into their parents' columns: `M = d I + c L`, where
//!
//! ```text
//!     (L φ)_i = Σ_j w_ij (φ_i − φ_j),   w_ij = 2 (r_ij·∇Ŵ_ij)/|r_ij|² δV   (< 0 in full support),
//! ```
//!
//! and a mirror j of fluid particle k carries φ_j = σ φ_k with σ the linear factor of its
//! wall's condition for the field ([`Field`], see [`crate::engine::boundary::condition`]):
//! +1 for the pressure (homogeneous Neumann), −1 for a no-slip velocity component. The PPE
//! (25) uses d = 0, c = −1/ρ; the implicit viscous predictor d = 1, c = −δt ν.
//!
//! Assembly is parallel over rows into buffers reused from step to step: each row is written
//! into a slot sized by its neighbour count, sorted and merged in place, then compacted into
//! CSR (sprs), whose buffers are handed back after every solve.

use crate::engine::boundary::{Field, Ghosts};
use crate::engine::dimension::{Dim, Dimension};
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::{NeighbourList, RowWriter};
use crate::engine::operators::pair_viscosity;
use rayon::prelude::*;
use rheosph_solver::{SolveError, SolveReport, Solver, SolverOptions};
use sprs::CsMat;
use std::cell::RefCell;

/// Reusable CSR buffers of `d I + c L` and a solver for it.
#[derive(Default)]
pub struct LaplacianMatrix {
    slot_offsets: Vec<usize>,
    row_len: Vec<usize>,
    indptr: Vec<usize>,
    indices: Vec<usize>,
    data: Vec<f64>,
    solver: Solver,
}

impl LaplacianMatrix {
    /// The CSR slot of each row: the diagonal and one entry per neighbour, or for a
    /// continued ghost's velocity ([`Ghosts::velocity_stencil`]) one per point of its stencil.
    fn size_slots<const D: usize>(
        &mut self,
        list: &NeighbourList<D>,
        ghosts: &Ghosts<D>,
        field: Field,
    ) where
        Dim<D>: Dimension<D>,
    {
        let n = list.rows();
        self.slot_offsets.clear();
        let stencils = field == Field::Velocity
            && (0..ghosts.len()).any(|g| ghosts.velocity_stencil(g).is_some());
        if !stencils {
            self.slot_offsets
                .extend(list.offsets.iter().enumerate().map(|(i, o)| o + i));
            return;
        }
        self.row_len.resize(n, 0);
        self.row_len
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, len)| {
                *len = 1 + list
                    .range(i)
                    .map(|k| {
                        let j = list.index[k] as usize;
                        let stencil = j.checked_sub(n).and_then(|g| ghosts.velocity_stencil(g));
                        stencil.map_or(1, |(points, _)| points.len())
                    })
                    .sum::<usize>();
            });
        self.slot_offsets.push(0);
        let mut total = 0;
        for len in &self.row_len {
            total += len;
            self.slot_offsets.push(total);
        }
    }

    /// Assembles the operator `op` with mirrors of its field folded into their parents'
    /// columns; rows flagged in `identity_rows` (empty: none) are replaced by identity rows,
    /// the Dirichlet rows of free-surface particles.
    pub fn assemble<const D: usize>(&mut self, hood: Hood<D>, op: Operator, identity_rows: &[bool])
    where
        Dim<D>: Dimension<D>,
    {
        let Hood { list, ghosts, .. } = hood;
        let field = op.field;
        let n = list.rows();
        // Each row is written into a slot of the CSR arrays sized by its neighbour count plus
        // the diagonal, sorted and merged there, then the rows are shifted down in place.
        self.size_slots(list, ghosts, field);
        let upper = self.slot_offsets[n];
        self.indices.resize(upper, 0);
        self.data.resize(upper, 0.0);
        self.row_len.resize(n, 0);
        let slot_offsets = &self.slot_offsets;
        let (indices, data) = (
            RowWriter::new(&mut self.indices),
            RowWriter::new(&mut self.data),
        );
        self.row_len
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, len)| {
                // SAFETY: each task writes only its own row slot of both arrays.
                let (cols, vals) =
                    unsafe { (indices.row(slot_offsets, i), data.row(slot_offsets, i)) };
                *len = if identity_rows.get(i).copied().unwrap_or(false) {
                    cols[0] = i;
                    vals[0] = 1.0;
                    1
                } else {
                    assemble_row(i, n, hood, op, cols, vals)
                };
            });

        self.indptr.clear();
        self.indptr.push(0);
        let mut total = 0;
        for i in 0..n {
            let start = self.slot_offsets[i];
            let len = self.row_len[i];
            // total ≤ start: moving left never overwrites a row not yet moved.
            self.indices.copy_within(start..start + len, total);
            self.data.copy_within(start..start + len, total);
            total += len;
            self.indptr.push(total);
        }
        self.indices.truncate(total);
        self.data.truncate(total);
    }

    /// Row i of the last assembly becomes `(1 − s)·(row i) + s·D·e_i`, D its diagonal, which
    /// it returns: a Poisson row blended with a Dirichlet row scaled like it.
    pub fn blend_with_identity(&mut self, i: usize, s: f64) -> f64 {
        let row = self.indptr[i]..self.indptr[i + 1];
        let at = row.start
            + self.indices[row.clone()]
                .binary_search(&i)
                .expect("every assembled row holds its diagonal");
        let diagonal = self.data[at];
        self.data[row].iter_mut().for_each(|v| *v *= 1.0 - s);
        self.data[at] += s * diagonal;
        diagonal
    }

    /// Heap bytes held by the matrix buffers and the solver workspace.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.slot_offsets.capacity()
            + self.row_len.capacity()
            + self.indptr.capacity()
            + self.indices.capacity())
            * size_of::<usize>()
            + self.data.capacity() * size_of::<f64>()
            + self.solver.heap_bytes()
    }

    /// Stored entries of the last assembly.
    pub fn nnz(&self) -> usize {
        self.indices.len()
    }

    /// A copy of the last assembled matrix (for benchmarks and diagnostics).
    pub fn to_csr(&self) -> CsMat<f64> {
        let n = self.indptr.len().saturating_sub(1);
        CsMat::new(
            (n, n),
            self.indptr.clone(),
            self.indices.clone(),
            self.data.clone(),
        )
    }

    /// Drops the solver's preconditioner (the unknowns were reordered, or a checkpoint was
    /// written).
    pub fn invalidate_preconditioner(&mut self) {
        self.solver.invalidate_preconditioner();
    }

    /// LU factorisations computed so far.
    pub fn factorisations(&self) -> usize {
        self.solver.factorisations()
    }

    /// Solves `M x = rhs`; `x` is the warm start on entry.
    pub fn solve(
        &mut self,
        rhs: &[f64],
        x: &mut [f64],
        options: &SolverOptions,
    ) -> Result<SolveReport, SolveError> {
        self.with_matrix(rhs.len(), |solver, matrix| {
            solver.solve(matrix, rhs, x, options)
        })
    }

    /// Solves `M x_m = rhs_m` for several right-hand sides (the velocity components):
    /// bit for bit [`Self::solve`] on each in turn, sharing the passes over the matrix
    /// where the solver can ([`Solver::solve_many`]).
    pub fn solve_many<const M: usize>(
        &mut self,
        rhs: [&[f64]; M],
        x: [&mut [f64]; M],
        options: &SolverOptions,
    ) -> Result<[SolveReport; M], SolveError> {
        let n = rhs.first().map_or(0, |r| r.len());
        self.with_matrix(n, |solver, matrix| {
            solver.solve_many(matrix, rhs, x, options)
        })
    }

    /// Lends the assembled n × n matrix, as sprs's CSR type, to `f` with the solver.
    fn with_matrix<T>(&mut self, n: usize, f: impl FnOnce(&mut Solver, &CsMat<f64>) -> T) -> T {
        // SAFETY: `assemble` writes every row sorted by column without duplicates, all
        // columns < n, and `indptr` non-decreasing from 0 to nnz (what sprs would check, one
        // sequential pass over every entry that cost as much as the solve itself: 4 ms of
        // a warm 16k-particle solve; `to_csr` keeps the check for tests and benchmarks).
        let matrix = unsafe {
            CsMat::new_unchecked(
                sprs::CompressedStorage::CSR,
                (n, n),
                std::mem::take(&mut self.indptr),
                std::mem::take(&mut self.indices),
                std::mem::take(&mut self.data),
            )
        };
        let result = f(&mut self.solver, &matrix);
        let (indptr, indices, data) = matrix.into_raw_storage();
        self.indptr = indptr;
        self.indices = indices;
        self.data = data;
        result
    }
}

/// The matrix `d I + c L` of `field`; a non-empty `factor` (fluid then ghosts) weights each
/// pair by the harmonic mean of its values, the variable viscosity of
/// [`KernelSums::variable_laplacian_vector`].
#[derive(Clone, Copy)]
pub struct Operator<'a> {
    pub field: Field,
    pub d: f64,
    pub c: f64,
    pub factor: &'a [f64],
}

/// Writes row i of `op` into its slot (diagonal first, then one entry per neighbour
/// column), sorts it by column, merges duplicates, and returns the number of entries kept.
fn assemble_row<const D: usize>(
    i: usize,
    n_fluid: usize,
    hood: Hood<D>,
    op: Operator,
    cols: &mut [usize],
    vals: &mut [f64],
) -> usize
where
    Dim<D>: Dimension<D>,
{
    let Hood { list, sums, ghosts } = hood;
    let Operator {
        field,
        d,
        c,
        factor,
    } = op;
    let mut len = 1;
    let mut diagonal = d;
    for k in list.range(i) {
        let j = list.index[k] as usize;
        let mut w = c * match field {
            Field::Pressure => sums.ppe_weight(list, k),
            Field::Velocity => sums.laplacian_weight(list, k),
        };
        if !factor.is_empty() {
            w *= pair_viscosity(factor[i], factor[j]);
        }
        diagonal += w;
        let mut push = |col: usize, coefficient: f64| {
            if col == i {
                diagonal += coefficient; // own ghost
            } else {
                cols[len] = col;
                vals[len] = coefficient;
                len += 1;
            }
        };
        if j < n_fluid {
            push(j, -w);
            continue;
        }
        let g = j - n_fluid;
        match ghosts
            .velocity_stencil(g)
            .filter(|_| field == Field::Velocity)
        {
            // u_g = Σ_m c_m u_m + (the offset's part, on the right-hand side).
            Some((points, c)) => {
                for (&m, &c) in points.iter().zip(c) {
                    push(m as usize, -w * c);
                }
            }
            None => push(ghosts.parent[g] as usize, -ghosts.sign(field, g) * w),
        }
    }
    // Neighbour rows are sorted by index, fluid before ghosts: without ghosts' parents or
    // stencils after them the row is one ascending run, whose repeated columns merge in
    // place with the diagonal put in its place; otherwise the row is gathered.
    let ascending = cols[1..len].windows(2).all(|w| w[0] <= w[1]);
    if !ascending {
        return gather_row(i, diagonal, cols, vals, len);
    }
    let place = 1 + cols[1..len].partition_point(|&c| c < i);
    cols.copy_within(1..place, 0);
    vals.copy_within(1..place, 0);
    cols[place - 1] = i;
    vals[place - 1] = diagonal;
    let mut kept = 0;
    for k in 0..len {
        if kept > 0 && cols[kept - 1] == cols[k] {
            vals[kept - 1] += vals[k];
        } else {
            cols[kept] = cols[k];
            vals[kept] = vals[k];
            kept += 1;
        }
    }
    kept
}

/// Per worker thread: a row's value by column while it is gathered, and the columns seen.
#[derive(Default)]
struct RowAccumulator {
    value: Vec<f64>,
    /// `stamp[c] == generation`: column c is in the row being gathered.
    stamp: Vec<u32>,
    generation: u32,
    touched: Vec<usize>,
}

thread_local! {
    static ROW: RefCell<RowAccumulator> = RefCell::new(RowAccumulator::default());
}

/// Sums the row's entries `cols[1..len]`, `vals[1..len]` (in any order, columns repeated)
/// and the diagonal `diagonal` at column `i` into distinct ascending columns at the front of
/// the slot; returns their count. Each column's sum takes its entries in their order in the
/// row, which the neighbour rows' own order fixes, so the matrix is the same bit for bit on
/// any thread count. A dense accumulator makes it O(m + k log k) for m entries in k columns:
/// next to a continued wall in space a row's velocity stencils bring thousands of entries
/// into a few hundred columns, and placing each by bisection took most of the implicit
/// viscous step.
fn gather_row(i: usize, diagonal: f64, cols: &mut [usize], vals: &mut [f64], len: usize) -> usize {
    ROW.with_borrow_mut(|row| {
        let width = cols[1..len].iter().copied().fold(i, usize::max) + 1;
        if row.stamp.len() < width {
            row.stamp.resize(width, 0);
            row.value.resize(width, 0.0);
        }
        row.generation = row.generation.wrapping_add(1);
        if row.generation == 0 {
            row.stamp.iter_mut().for_each(|s| *s = 0);
            row.generation = 1;
        }
        let generation = row.generation;
        row.touched.clear();
        row.stamp[i] = generation;
        row.value[i] = diagonal;
        row.touched.push(i);
        for (&col, &val) in cols[1..len].iter().zip(&vals[1..len]) {
            if row.stamp[col] == generation {
                row.value[col] += val;
            } else {
                row.stamp[col] = generation;
                row.value[col] = val;
                row.touched.push(col);
            }
        }
        row.touched.sort_unstable();
        for (k, &col) in row.touched.iter().enumerate() {
            cols[k] = col;
            vals[k] = row.value[col];
        }
        row.touched.len()
    })
}

/// A test lattice between two plane walls, periodic along them, with its mirrors,
/// neighbour list and kernel sums.
#[cfg(test)]
pub(crate) mod fixture {
    use crate::engine::boundary::{Ghosts, Plane, Shape, TensorMirror, Wall};
    use crate::engine::kernel::QuinticSpline;
    use crate::engine::math::Vec2;
    use crate::engine::neighbours::{Domain, NeighbourList, NeighbourSearch};
    use crate::engine::operators::KernelSums;

    pub struct WalledLattice {
        /// Fluid particles.
        pub n: usize,
        pub ghosts: Ghosts,
        pub list: NeighbourList,
        pub sums: KernelSums,
    }

    /// `n_side`² particles on the unit square, walls at y = 0 and 1.
    pub fn walled_lattice(n_side: usize) -> WalledLattice {
        let dr = 1.0 / n_side as f64;
        let kernel = QuinticSpline::for_spacing(dr);
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, false],
        };
        let mut points: Vec<Vec2> = (0..n_side * n_side)
            .map(|k| Vec2::new((k / n_side) as f64 + 0.5, (k % n_side) as f64 + 0.5) * dr)
            .collect();
        let n = points.len();
        let plane = |position, fluid_side| {
            let shape = Shape::Plane(Plane {
                axis: 1,
                position,
                fluid_side,
            });
            Wall::no_slip(shape, TensorMirror::Even)
        };
        let mut ghosts = Ghosts::new(vec![plane(0.0, 1.0), plane(1.0, -1.0)]);
        ghosts.build(kernel.support(), &mut points);
        let mut list = NeighbourList::default();
        NeighbourSearch::new().build(&domain, &points, n, kernel.support(), &mut list);
        let mut sums = KernelSums::default();
        sums.update(&list, &kernel, dr * dr);
        WalledLattice {
            n,
            ghosts,
            list,
            sums,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Vec2;
    use sprs::CsMat;

    /// The assembled matrix applied to a field equals the operator form of (21) with the
    /// ghosts' values set by the mirror rule: the folding of mirrors is exact.
    #[test]
    fn matrix_matches_the_operator_with_mirrors() {
        let fixture::WalledLattice {
            n,
            ghosts,
            list,
            sums,
            ..
        } = fixture::walled_lattice(12);
        let field: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin()).collect();
        // A variable viscosity factor, even across the walls (as ShearDependentViscosity
        // extends it); empty: uniform.
        let fluid_factor: Vec<f64> = (0..n)
            .map(|k| 0.5 + (k as f64 * 0.11).cos().abs())
            .collect();
        let mut factor = Vec::new();
        ghosts.extend_scalar(&fluid_factor, &mut factor);
        for (kind, d, c, phi) in [
            (Field::Pressure, 0.0, -1.0, &[][..]),
            (Field::Velocity, 1.0, -0.01, &[][..]),
            (Field::Velocity, 1.0, -0.01, &factor[..]),
        ] {
            let mut m = LaplacianMatrix::default();
            let hood = Hood {
                list: &list,
                sums: &sums,
                ghosts: &ghosts,
            };
            let op = Operator {
                field: kind,
                d,
                c,
                factor: phi,
            };
            m.assemble(hood, op, &[]);
            let a = CsMat::new((n, n), m.indptr.clone(), m.indices.clone(), m.data.clone());
            let mut ax = vec![0.0; n];
            rheosph_solver::vector::spmv(&a, &field, &mut ax);
            // The operator form on a vector field whose x component is `field`.
            let velocity: Vec<Vec2> = field.iter().map(|&f| Vec2::new(f, 0.0)).collect();
            let mut ext = Vec::new();
            match kind {
                Field::Velocity => ghosts.extend_velocity(&velocity, &mut ext),
                Field::Pressure => {
                    let mut s = Vec::new();
                    ghosts.extend_pressure(&field, &mut s);
                    ext = s.iter().map(|&v| Vec2::new(v, 0.0)).collect();
                }
            }
            let mut lap = vec![Vec2::zeros(); n];
            if phi.is_empty() {
                sums.laplacian_vector(&list, &ext, &mut lap);
            } else {
                sums.variable_laplacian_vector(&list, &ext, phi, &mut lap);
            }
            for i in 0..n {
                let expected = d * field[i] + c * lap[i].x;
                assert!(
                    (ax[i] - expected).abs() < 1e-9 * (1.0 + expected.abs()),
                    "{kind:?} row {i}"
                );
            }
        }
    }

    /// A blended row is (1 − s) times the Poisson row plus s times its diagonal on the
    /// diagonal: every other row, and the row's sum's sign, unchanged; s = 1 leaves the
    /// diagonal alone (a scaled Dirichlet row).
    #[test]
    fn a_blended_row_mixes_the_poisson_row_with_its_scaled_identity() {
        let fixture::WalledLattice {
            list, sums, ghosts, ..
        } = fixture::walled_lattice(8);
        let assemble = || {
            let mut m = LaplacianMatrix::default();
            let hood = Hood {
                list: &list,
                sums: &sums,
                ghosts: &ghosts,
            };
            let op = Operator {
                field: Field::Pressure,
                d: 0.0,
                c: -1.0,
                factor: &[],
            };
            m.assemble(hood, op, &[]);
            m
        };
        let plain = assemble();
        let (i, s) = (5, 0.3);
        let mut blended = assemble();
        let diagonal = blended.blend_with_identity(i, s);
        let mut full = assemble();
        let full_diagonal = full.blend_with_identity(i, 1.0);
        assert_eq!(diagonal, full_diagonal);
        assert!(diagonal > 0.0);
        for (k, (&col, &value)) in plain.indices.iter().zip(&plain.data).enumerate() {
            let row = plain.indptr.partition_point(|&start| start <= k) - 1;
            let expected = match (row == i, col == i) {
                (false, _) => value,
                (true, false) => (1.0 - s) * value,
                (true, true) => (1.0 - s) * value + s * diagonal,
            };
            assert!(
                (blended.data[k] - expected).abs() <= 1e-15 * diagonal,
                "{row}, {col}"
            );
            let at_one = if row != i {
                value
            } else if col == i {
                diagonal
            } else {
                0.0
            };
            assert_eq!(full.data[k], at_one, "{row}, {col}");
        }
    }
}
