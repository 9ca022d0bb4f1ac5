//! Direct path: faer sparse LU with partial pivoting.

use crate::bicgstab::mean_abs_diagonal;
use crate::{NullSpace, SolveError};
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use sprs::CsMat;

/// Solves `A x = b` by sparse LU. For a constant null space it factorises the bordered matrix
/// `[A s1; s1ᵀ 0]` (s the mean diagonal magnitude, for balanced pivots) with right-hand side
/// `[b; 0]`, i.e. `A x + μ 1 = b, Σ x = 0` (μ = s·x_{n}).
pub(crate) fn solve(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    null_space: NullSpace,
) -> Result<(), SolveError> {
    let n = b.len();
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
    let rhs = faer::Col::<f64>::from_fn(size, |i| if i < n { b[i] } else { 0.0 });
    let solution = lu.solve(&rhs);
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
