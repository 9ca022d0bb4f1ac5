//! Direct path: faer sparse LU with partial pivoting, with the factorisation kept for reuse
//! while the caller promises the matrix has not changed.

use crate::bicgstab::mean_abs_diagonal;
use crate::{NullSpace, SolveError};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Lu;
use faer::sparse::{SparseColMat, Triplet};
use sprs::CsMat;

/// A factorisation and what it factorised.
///
/// For a constant null space it factorises the sparse `B = A + s e_k e_kᵀ` (k the row of the
/// largest diagonal, s the mean diagonal magnitude), non-singular because the left null
/// vector of A has w_k ≠ 0, and keeps `z₂ = B⁻¹1`, `z₃ = B⁻¹e_k`. The bordered problem
/// `A x + μ1 = b, Σx = 0` then needs one solve `z₁ = B⁻¹b` per right-hand side: with
/// A = B − s e_k e_kᵀ, x = z₁ − μ z₂ + s x_k z₃, and x_k, μ follow from the 2×2 system
/// `x_k(1 − s z₃ₖ) + μ z₂ₖ = z₁ₖ`, `−s x_k Σz₃ + μ Σz₂ = Σz₁`. (Factorising the bordered
/// matrix itself, with its dense row and column, costs ~50× more fill.)
pub(crate) struct Factorisation {
    lu: Lu<usize, f64>,
    n: usize,
    null_space: NullSpace,
    /// (k, s, z₂, z₃) for a constant null space.
    deflation: Option<(usize, f64, Vec<f64>, Vec<f64>)>,
}

impl Factorisation {
    pub(crate) fn new(a: &CsMat<f64>, null_space: NullSpace) -> Result<Self, SolveError> {
        let n = a.rows();
        let mut triplets = Vec::with_capacity(a.nnz() + 1);
        let mut diagonal = vec![0.0; n];
        for (value, (i, j)) in a.iter() {
            triplets.push(Triplet::new(i, j, *value));
            if i == j {
                diagonal[i] += *value;
            }
        }
        let pin = if null_space == NullSpace::Constant {
            let k = (0..n)
                .max_by(|&p, &q| diagonal[p].abs().total_cmp(&diagonal[q].abs()))
                .unwrap_or(0);
            let s = mean_abs_diagonal(a);
            triplets.push(Triplet::new(k, k, s));
            Some((k, s))
        } else {
            None
        };
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| SolveError::Lu(format!("{e:?}")))?;
        let lu = matrix
            .sp_lu()
            .map_err(|e| SolveError::Lu(format!("{e:?}")))?;
        let mut f = Self {
            lu,
            n,
            null_space,
            deflation: None,
        };
        if let Some((k, s)) = pin {
            let mut z2 = vec![0.0; n];
            f.raw_solve(&vec![1.0; n], &mut z2);
            let mut unit = vec![0.0; n];
            unit[k] = 1.0;
            let mut z3 = vec![0.0; n];
            f.raw_solve(&unit, &mut z3);
            f.deflation = Some((k, s, z2, z3));
        }
        Ok(f)
    }

    /// Whether this factorisation belongs to a matrix of this size and null space.
    pub(crate) fn fits(&self, n: usize, null_space: NullSpace) -> bool {
        self.n == n && self.null_space == null_space
    }

    fn raw_solve(&self, b: &[f64], x: &mut [f64]) {
        let rhs = faer::Col::<f64>::from_fn(self.n, |i| b[i]);
        let solution = self.lu.solve(&rhs);
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = solution[i];
        }
    }

    pub(crate) fn solve(&self, b: &[f64], x: &mut [f64]) -> Result<(), SolveError> {
        self.raw_solve(b, x);
        if let Some((k, s, z2, z3)) = &self.deflation {
            let (k, s) = (*k, *s);
            let sum = |v: &[f64]| v.iter().sum::<f64>();
            // [1 − s z3_k, z2_k; −s Σz3, Σz2] [x_k, μ]ᵀ = [z1_k, Σz1]ᵀ
            let (a11, a12, a21, a22) = (1.0 - s * z3[k], z2[k], -s * sum(z3), sum(z2));
            let (r1, r2) = (x[k], sum(x));
            let det = a11 * a22 - a12 * a21;
            if det == 0.0 || !det.is_finite() {
                return Err(SolveError::Lu("singular deflation system".into()));
            }
            let xk = (r1 * a22 - a12 * r2) / det;
            let mu = (a11 * r2 - a21 * r1) / det;
            for i in 0..self.n {
                x[i] += -mu * z2[i] + s * xk * z3[i];
            }
        }
        if !x.iter().all(|v| v.is_finite()) {
            return Err(SolveError::Lu(
                "solution is not finite (singular matrix?)".into(),
            ));
        }
        Ok(())
    }
}
