//! The pressure Poisson equation (25), `∇·(∇p/ρ) = ∇·u*/δt`, assembled every step as a CSR
//! matrix and handed to `rheosph-solver`.
//!
//! Row i discretises `−∇²p/ρ` with the Laplacian (21): `Σ_j c_ij (p_i − p_j) = −(∇·u*)_i/δt`,
//! with `c_ij = −2 (r_ij·∇Ŵ_ij)/(ρ|r_ij|²) δV` (positive in full support, so the diagonal is
//! positive). A wall mirror's pressure is its parent's (homogeneous Neumann), so its
//! coefficient is added to the parent's column; a particle's own mirror cancels out. Rows
//! sum to zero: on a closed domain the matrix is singular with the constant null space, which
//! the solver removes (zero-mean pressure).
//!
//! Assembly is parallel over rows into buffers reused from step to step: each row is written
//! into a slot sized by its neighbour count, sorted and merged in place, then compacted.

use crate::boundary::Ghosts;
use crate::neighbours::{NeighbourList, RowWriter};
use crate::operators::KernelSums;
use rayon::prelude::*;
use rheosph_solver::{SolveError, SolveReport, Solver, SolverOptions};
use sprs::CsMat;

/// Reusable PPE assembly buffers and linear solver.
#[derive(Default)]
pub struct PressureSystem {
    slot_offsets: Vec<usize>,
    slots: Vec<(u32, f64)>,
    row_len: Vec<usize>,
    indptr: Vec<usize>,
    indices: Vec<usize>,
    data: Vec<f64>,
    rhs: Vec<f64>,
    solver: Solver,
}

impl PressureSystem {
    pub fn new() -> Self {
        Self::default()
    }

    /// The right-hand side `−∇·u*/δt`.
    pub fn assemble_rhs(&mut self, divergence: &[f64], dt: f64) {
        self.rhs.clear();
        self.rhs.extend(divergence.iter().map(|d| -d / dt));
    }

    /// Assembles the matrix rows for the fluid particles.
    pub fn assemble_matrix(
        &mut self,
        list: &NeighbourList,
        sums: &KernelSums,
        ghosts: &Ghosts,
        density: f64,
    ) {
        let n = list.rows();
        // Row slots: the neighbours plus the diagonal.
        self.slot_offsets.clear();
        self.slot_offsets
            .extend(list.offsets.iter().enumerate().map(|(i, o)| o + i));
        self.slots.resize(self.slot_offsets[n], (0, 0.0));
        self.row_len.resize(n, 0);
        let slot_offsets = &self.slot_offsets;
        let slots = RowWriter::new(&mut self.slots);
        self.row_len
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, len)| {
                // SAFETY: each task writes only its own row slot.
                let row = unsafe { slots.row(slot_offsets, i) };
                *len = assemble_row(i, n, list, sums, ghosts, density, row);
            });

        self.indptr.clear();
        self.indptr.push(0);
        let mut total = 0;
        for &len in &self.row_len {
            total += len;
            self.indptr.push(total);
        }
        self.indices.resize(total, 0);
        self.data.resize(total, 0.0);
        for i in 0..n {
            let src = &self.slots[self.slot_offsets[i]..self.slot_offsets[i] + self.row_len[i]];
            let dst = self.indptr[i]..self.indptr[i + 1];
            for ((col, val), (c, v)) in src.iter().zip(
                self.indices[dst.clone()]
                    .iter_mut()
                    .zip(&mut self.data[dst]),
            ) {
                *c = *col as usize;
                *v = *val;
            }
        }
    }

    /// Number of stored matrix entries of the last assembly.
    pub fn nnz(&self) -> usize {
        self.indices.len()
    }

    /// LU factorisations computed so far.
    pub fn factorisations(&self) -> usize {
        self.solver.factorisations()
    }

    /// Solves the assembled system; `pressure` is the warm start on entry.
    pub fn solve(
        &mut self,
        pressure: &mut [f64],
        options: &SolverOptions,
    ) -> Result<SolveReport, SolveError> {
        let n = self.rhs.len();
        let matrix = CsMat::try_new(
            (n, n),
            std::mem::take(&mut self.indptr),
            std::mem::take(&mut self.indices),
            std::mem::take(&mut self.data),
        )
        .map_err(|(indptr, indices, data, e)| {
            self.indptr = indptr;
            self.indices = indices;
            self.data = data;
            SolveError::Lu(format!("PPE matrix structure: {e}"))
        })?;
        let result = self.solver.solve(&matrix, &self.rhs, pressure, options);
        let (indptr, indices, data) = matrix.into_raw_storage();
        self.indptr = indptr;
        self.indices = indices;
        self.data = data;
        result
    }
}

/// Writes row i into `row` (diagonal first, then one entry per distinct neighbour column),
/// sorts it by column, merges duplicates, and returns the number of entries kept.
fn assemble_row(
    i: usize,
    n_fluid: usize,
    list: &NeighbourList,
    sums: &KernelSums,
    ghosts: &Ghosts,
    density: f64,
    row: &mut [(u32, f64)],
) -> usize {
    let mut len = 1;
    let mut diagonal = 0.0;
    for k in list.range(i) {
        let col = ghosts.owner(list.index[k] as usize, n_fluid);
        if col == i {
            continue; // own mirror: p_j = p_i contributes nothing
        }
        let c = -sums.laplacian_weight(list, k) / density;
        diagonal += c;
        row[len] = (col as u32, -c);
        len += 1;
    }
    row[0] = (i as u32, diagonal);
    let entries = &mut row[..len];
    entries.sort_unstable_by_key(|e| e.0);
    let mut kept = 0;
    for k in 0..len {
        if kept > 0 && entries[kept - 1].0 == entries[k].0 {
            entries[kept - 1].1 += entries[k].1;
        } else {
            entries[kept] = entries[k];
            kept += 1;
        }
    }
    kept
}
