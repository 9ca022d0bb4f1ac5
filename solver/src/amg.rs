//! Smoothed-aggregation algebraic multigrid (Vaněk, Mandel & Brezina 1996) as a
//! preconditioner: one V(1,1)-cycle with damped Jacobi smoothing per application.
//!
//! Set-up, from the matrix alone:
//! * strength: j is a strong neighbour of i when |a_ij| ≥ θ √|a_ii a_jj| (θ = 0.08);
//! * aggregation in three passes (roots whose strong neighbours are all free take them;
//!   the rest join a neighbouring aggregate; leftovers form their own); a node without strong
//!   neighbours (a Dirichlet row) is left out, the smoother solves it;
//! * the tentative prolongator P₀ (1 on each aggregate: the constant near-null space of a
//!   Laplacian) smoothed once, P = (I − ω_P D⁻¹A) P₀ with ω_P = 4/(3ρ), ρ ≈ ρ(D⁻¹A) by
//!   power iteration;
//! * the coarse matrix P ᵀA P (Galerkin), down to ≤ [`COARSEST`] unknowns, which a dense LU
//!   solves (with the rank-one term c11ᵀ when the matrix has the constant null space).
//!
//! Every kernel is deterministic (sequential set-up, fixed-order reductions), so the
//! preconditioner does not depend on the number of threads.

use crate::vector::{for_each_mut, spmv};
use sprs::{CsMat, TriMat};

/// Strength threshold θ.
const STRENGTH: f64 = 0.08;
/// Damping of the Jacobi smoother (2/3: the optimal smoothing factor for a Laplacian).
const SMOOTHING: f64 = 2.0 / 3.0;
/// Largest matrix solved directly.
const COARSEST: usize = 200;
const MAX_LEVELS: usize = 12;
/// Power iterations of the spectral radius estimate.
const POWER_ITERATIONS: usize = 15;

struct Level {
    a: CsMat<f64>,
    inv_diag: Vec<f64>,
    /// Prolongation from the next level, and its transpose.
    p: CsMat<f64>,
    r: CsMat<f64>,
    /// Work vectors: right-hand side, solution, residual.
    b: Vec<f64>,
    x: Vec<f64>,
    res: Vec<f64>,
}

/// A smoothed-aggregation hierarchy.
pub struct Amg {
    levels: Vec<Level>,
    coarse: Coarsest,
    coarse_b: Vec<f64>,
    coarse_x: Vec<f64>,
}

impl Amg {
    /// The hierarchy of `a`; `singular`: `a` has the constant null space (a closed-domain
    /// PPE), which the coarsest solve then removes with a rank-one term.
    pub fn setup(a: &CsMat<f64>, singular: bool) -> Self {
        let mut levels = Vec::new();
        let mut current = a.to_owned();
        while current.rows() > COARSEST && levels.len() < MAX_LEVELS {
            let inv_diag = inverse_diagonal(&current);
            let p = prolongator(&current, &inv_diag);
            if p.cols() == 0 || p.cols() as f64 > 0.8 * current.rows() as f64 {
                break;
            }
            let r: CsMat<f64> = p.transpose_view().to_csr();
            let coarse = &r * &(&current * &p);
            let n = current.rows();
            levels.push(Level {
                a: current,
                inv_diag,
                p,
                r,
                b: vec![0.0; n],
                x: vec![0.0; n],
                res: vec![0.0; n],
            });
            current = coarse.to_csr();
        }
        let n = current.rows();
        // Coarsening stalls on a strongly diagonally dominant matrix (an implicit viscous
        // system at a small δtν/h²: no strong connections); its last level is then too large
        // for a dense LU, and damped Jacobi, which already converges fast there, replaces it.
        let coarse = if n <= COARSEST {
            Coarsest::Dense(DenseLu::new(&current, singular))
        } else {
            Coarsest::Jacobi {
                inv_diag: inverse_diagonal(&current),
                a: current,
                scratch: vec![0.0; n],
            }
        };
        Self {
            levels,
            coarse,
            coarse_b: vec![0.0; n],
            coarse_x: vec![0.0; n],
        }
    }

    /// Unknowns of the finest level.
    pub fn rows(&self) -> usize {
        self.levels
            .first()
            .map_or(self.coarse_b.len(), |l| l.a.rows())
    }

    /// Levels, the finest first (the coarsest, solved directly, included).
    pub fn sizes(&self) -> Vec<usize> {
        let mut s: Vec<usize> = self.levels.iter().map(|l| l.a.rows()).collect();
        s.push(self.coarse_b.len());
        s
    }

    /// Operator complexity: the non-zeros of every level's matrix over the finest one's.
    pub fn complexity(&self) -> f64 {
        let coarse = self.coarse.nnz();
        let fine = self.levels.first().map_or(coarse, |l| l.a.nnz()).max(1);
        let total: usize = self.levels.iter().map(|l| l.a.nnz()).sum::<usize>() + coarse;
        total as f64 / fine as f64
    }

    /// Non-zeros per level, the finest first.
    pub fn nonzeros(&self) -> Vec<usize> {
        self.levels.iter().map(|l| l.a.nnz()).collect()
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        let csr = |m: &CsMat<f64>| m.nnz() * 16 + (m.rows() + 1) * 8;
        self.levels
            .iter()
            .map(|l| csr(&l.a) + csr(&l.p) + csr(&l.r) + 8 * (4 * l.b.len()))
            .sum::<usize>()
            + self.coarse.heap_bytes()
    }

    /// y = M⁻¹x: one V-cycle from zero.
    pub fn apply(&mut self, x: &[f64], y: &mut [f64]) {
        if self.levels.is_empty() {
            self.coarse.solve(x, y);
            return;
        }
        self.levels[0].b.copy_from_slice(x);
        self.cycle(0);
        y.copy_from_slice(&self.levels[0].x);
    }

    fn cycle(&mut self, k: usize) {
        let (here, rest) = self.levels.split_at_mut(k + 1);
        let level = &mut here[k];
        // Pre-smoothing from zero: x = ω D⁻¹ b.
        {
            let (b, d) = (&level.b, &level.inv_diag);
            for_each_mut(&mut level.x, |i, xi| *xi = SMOOTHING * d[i] * b[i]);
        }
        residual(level);
        let coarse_b = match rest.first_mut() {
            Some(next) => &mut next.b,
            None => &mut self.coarse_b,
        };
        spmv(&level.r, &level.res, coarse_b);
        if rest.is_empty() {
            self.coarse.solve(&self.coarse_b, &mut self.coarse_x);
        } else {
            self.cycle(k + 1);
        }
        let (here, rest) = self.levels.split_at_mut(k + 1);
        let level = &mut here[k];
        let correction = match rest.first() {
            Some(next) => &next.x,
            None => &self.coarse_x,
        };
        // x += P x_coarse (into res as scratch), then post-smoothing.
        spmv(&level.p, correction, &mut level.res);
        {
            let res = &level.res;
            for_each_mut(&mut level.x, |i, xi| *xi += res[i]);
        }
        residual(level);
        let (res, d) = (&level.res, &level.inv_diag);
        for_each_mut(&mut level.x, |i, xi| *xi += SMOOTHING * d[i] * res[i]);
    }
}

/// res = b − A x.
fn residual(level: &mut Level) {
    spmv(&level.a, &level.x, &mut level.res);
    let b = &level.b;
    for_each_mut(&mut level.res, |i, ri| *ri = b[i] - *ri);
}

/// 1/a_ii (1 where the diagonal vanishes).
fn inverse_diagonal(a: &CsMat<f64>) -> Vec<f64> {
    (0..a.rows())
        .map(|i| match a.get(i, i) {
            Some(&d) if d != 0.0 && d.is_finite() => 1.0 / d,
            _ => 1.0,
        })
        .collect()
}

/// The smoothed prolongator of `a` (module docs).
fn prolongator(a: &CsMat<f64>, inv_diag: &[f64]) -> CsMat<f64> {
    let n = a.rows();
    let aggregate = aggregates(a, inv_diag);
    let count = aggregate.iter().flatten().max().map_or(0, |&m| m + 1);
    let rho = spectral_radius(a, inv_diag);
    let omega = 4.0 / (3.0 * rho);
    // P = P₀ − ω D⁻¹ A P₀: row i, column agg(j), for every j in row i of A.
    let mut triplets = TriMat::new((n, count));
    for i in 0..n {
        if let Some(c) = aggregate[i] {
            triplets.add_triplet(i, c, 1.0);
        }
        let row = a.outer_view(i).unwrap();
        for (j, v) in row.iter() {
            if let Some(c) = aggregate[j] {
                triplets.add_triplet(i, c, -omega * inv_diag[i] * v);
            }
        }
    }
    triplets.to_csr()
}

/// ρ(D⁻¹A) estimated by power iteration (a Gershgorin bound overestimates it by up to 2×
/// for SPH stencils, which under-smooths the prolongator), never above the Gershgorin bound.
fn spectral_radius(a: &CsMat<f64>, inv_diag: &[f64]) -> f64 {
    let n = a.rows();
    let gershgorin = (0..n)
        .map(|i| {
            let row = a.outer_view(i).unwrap();
            row.iter().map(|(_, v)| v.abs()).sum::<f64>() * inv_diag[i].abs()
        })
        .fold(1.0, f64::max);
    // A fixed, deterministic start with components along every mode.
    let mut x: Vec<f64> = (0..n)
        .map(|i| (i as f64 * 0.618_034).fract() - 0.5)
        .collect();
    let mut y = vec![0.0; n];
    let mut rho = 0.0;
    for _ in 0..POWER_ITERATIONS {
        spmv(a, &x, &mut y);
        y.iter_mut().zip(inv_diag).for_each(|(v, d)| *v *= d);
        let norm_x = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let norm_y = y.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm_x == 0.0 || norm_y == 0.0 {
            return gershgorin;
        }
        rho = norm_y / norm_x;
        x.iter_mut().zip(&y).for_each(|(a, b)| *a = b / norm_y);
    }
    // Power iteration approaches ρ from below: a 10 % margin keeps ω_P ρ ≤ 4/3.
    (1.1 * rho).min(gershgorin)
}

/// The aggregate of each node (None: no strong neighbour, left to the smoother).
fn aggregates(a: &CsMat<f64>, inv_diag: &[f64]) -> Vec<Option<usize>> {
    let n = a.rows();
    let strong: Vec<Vec<usize>> = (0..n)
        .map(|i| {
            let row = a.outer_view(i).unwrap();
            row.iter()
                .filter(|&(j, v)| {
                    j != i && v.abs() >= STRENGTH * (1.0 / (inv_diag[i] * inv_diag[j])).abs().sqrt()
                })
                .map(|(j, _)| j)
                .collect()
        })
        .collect();
    let mut agg: Vec<Option<usize>> = vec![None; n];
    let mut count = 0;
    // Pass 1: roots whose strong neighbours are all free.
    for i in 0..n {
        if agg[i].is_none() && !strong[i].is_empty() && strong[i].iter().all(|&j| agg[j].is_none())
        {
            agg[i] = Some(count);
            for &j in &strong[i] {
                agg[j] = Some(count);
            }
            count += 1;
        }
    }
    // Pass 2: join a neighbouring aggregate of pass 1.
    let first = agg.clone();
    for i in 0..n {
        if agg[i].is_none() {
            agg[i] = strong[i].iter().find_map(|&j| first[j]);
        }
    }
    // Pass 3: the leftovers with their free strong neighbours.
    for i in 0..n {
        if agg[i].is_none() && !strong[i].is_empty() {
            agg[i] = Some(count);
            for &j in &strong[i] {
                if agg[j].is_none() {
                    agg[j] = Some(count);
                }
            }
            count += 1;
        }
    }
    agg
}

/// The solve on the last level.
enum Coarsest {
    Dense(DenseLu),
    /// [`COARSE_SWEEPS`] damped Jacobi sweeps from zero (coarsening stalled).
    Jacobi {
        a: CsMat<f64>,
        inv_diag: Vec<f64>,
        scratch: Vec<f64>,
    },
}

/// Jacobi sweeps of a stalled coarsest level.
const COARSE_SWEEPS: usize = 3;

impl Coarsest {
    /// Stored entries (the dense LU's n²).
    fn nnz(&self) -> usize {
        match self {
            Coarsest::Dense(lu) => lu.n * lu.n,
            Coarsest::Jacobi { a, .. } => a.nnz(),
        }
    }

    fn heap_bytes(&self) -> usize {
        match self {
            Coarsest::Dense(lu) => 8 * lu.lu.len(),
            Coarsest::Jacobi { a, .. } => a.nnz() * 16 + 16 * a.rows(),
        }
    }

    fn solve(&mut self, b: &[f64], x: &mut [f64]) {
        match self {
            Coarsest::Dense(lu) => lu.solve(b, x),
            Coarsest::Jacobi {
                a,
                inv_diag,
                scratch,
            } => {
                for_each_mut(x, |i, xi| *xi = SMOOTHING * inv_diag[i] * b[i]);
                for _ in 1..COARSE_SWEEPS {
                    spmv(a, x, scratch);
                    let (r, d) = (&*scratch, &*inv_diag);
                    for_each_mut(x, |i, xi| *xi += SMOOTHING * d[i] * (b[i] - r[i]));
                }
            }
        }
    }
}

/// Dense LU with partial pivoting of the coarsest matrix.
struct DenseLu {
    n: usize,
    lu: Vec<f64>,
    pivot: Vec<usize>,
}

impl DenseLu {
    fn new(a: &CsMat<f64>, singular: bool) -> Self {
        let n = a.rows();
        let mut lu = vec![0.0; n * n];
        for (v, (i, j)) in a.iter() {
            lu[i * n + j] += *v;
        }
        if singular && n > 0 {
            // + c 1 1ᵀ: the coarse null vector is the constant (P·1 = 1 for a Laplacian).
            let c = (0..n).map(|i| lu[i * n + i].abs()).sum::<f64>() / (n * n) as f64;
            lu.iter_mut().for_each(|v| *v += c);
        }
        let mut pivot = vec![0; n];
        for k in 0..n {
            let p = (k..n)
                .max_by(|&x, &y| lu[x * n + k].abs().total_cmp(&lu[y * n + k].abs()))
                .unwrap_or(k);
            pivot[k] = p;
            if p != k {
                for j in 0..n {
                    lu.swap(k * n + j, p * n + j);
                }
            }
            let d = lu[k * n + k];
            if d == 0.0 {
                continue;
            }
            for i in k + 1..n {
                let f = lu[i * n + k] / d;
                lu[i * n + k] = f;
                for j in k + 1..n {
                    lu[i * n + j] -= f * lu[k * n + j];
                }
            }
        }
        Self { n, lu, pivot }
    }

    fn solve(&self, b: &[f64], x: &mut [f64]) {
        let n = self.n;
        x.copy_from_slice(b);
        for k in 0..n {
            x.swap(k, self.pivot[k]);
        }
        for i in 0..n {
            let s: f64 = (0..i).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] -= s;
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|j| self.lu[i * n + j] * x[j]).sum();
            let d = self.lu[i * n + i];
            x[i] = if d != 0.0 { (x[i] - s) / d } else { 0.0 };
        }
    }
}
