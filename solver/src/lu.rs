//! Direct path: faer sparse LU with partial pivoting, with the factorisation kept for reuse
//! while the caller promises the matrix has not changed.

use crate::bicgstab::mean_abs_diagonal;
use crate::{NullSpace, SolveError};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Lu;
use faer::sparse::{SparseColMat, Triplet};
use sprs::CsMat;

/// A factorisation and what it factorised.
pub(crate) struct Factorisation {
    lu: Lu<usize, f64>,
    n: usize,
    null_space: NullSpace,
}

impl Factorisation {
    /// Factorises `A`, or for a constant null space the bordered matrix `[A s1; s1ᵀ 0]`
    /// (s the mean diagonal magnitude, for balanced pivots), whose solution with right-hand
    /// side `[b; 0]` is `A x + μ1 = b, Σx = 0` (μ = s·x_n).
    pub(crate) fn new(a: &CsMat<f64>, null_space: NullSpace) -> Result<Self, SolveError> {
        let n = a.rows();
        let bordered = null_space == NullSpace::Constant;
        let size = if bordered { n + 1 } else { n };
        let mut triplets = Vec::with_capacity(a.nnz() + if bordered { 2 * n } else { 0 });
        for (value, (i, j)) in a.iter() {
            triplets.push(Triplet::new(i, j, *value));
        }
        if bordered {
            let s = mean_abs_diagonal(a);
            for i in 0..n {
                triplets.push(Triplet::new(i, n, s));
                triplets.push(Triplet::new(n, i, s));
            }
        }
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(size, size, &triplets)
            .map_err(|e| SolveError::Lu(format!("{e:?}")))?;
        let lu = matrix
            .sp_lu()
            .map_err(|e| SolveError::Lu(format!("{e:?}")))?;
        Ok(Self { lu, n, null_space })
    }

    /// Whether this factorisation belongs to a matrix of this size and null space.
    pub(crate) fn fits(&self, n: usize, null_space: NullSpace) -> bool {
        self.n == n && self.null_space == null_space
    }

    pub(crate) fn solve(&self, b: &[f64], x: &mut [f64]) -> Result<(), SolveError> {
        let n = self.n;
        let size = if self.null_space == NullSpace::Constant {
            n + 1
        } else {
            n
        };
        let rhs = faer::Col::<f64>::from_fn(size, |i| if i < n { b[i] } else { 0.0 });
        let solution = self.lu.solve(&rhs);
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = solution[i];
        }
        if !x.iter().all(|v| v.is_finite()) {
            return Err(SolveError::Lu(
                "solution is not finite (singular matrix?)".into(),
            ));
        }
        Ok(())
    }
}
