//! Parallel vector kernels with thread-count-independent results.
//!
//! Reductions split the vectors into fixed blocks of [`BLOCK`] entries, reduce each block
//! sequentially (in parallel across blocks) and add the block sums in order. The rounding is
//! therefore the same whatever the number of threads, which keeps whole simulations
//! bit-reproducible.

use rayon::prelude::*;
use sprs::CsMat;

/// Entries per reduction block.
pub const BLOCK: usize = 4096;

/// Below this many entries the kernels run sequentially: rayon's overhead would dominate.
const PARALLEL_MIN: usize = 2 * BLOCK;

/// Deterministic dot product. `partials` is scratch space (reused, never shrunk).
pub fn dot(a: &[f64], b: &[f64], partials: &mut Vec<f64>) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    if a.len() < PARALLEL_MIN {
        return a
            .chunks(BLOCK)
            .zip(b.chunks(BLOCK))
            .map(|(x, y)| block_dot(x, y))
            .sum();
    }
    a.par_chunks(BLOCK)
        .zip(b.par_chunks(BLOCK))
        .map(|(x, y)| block_dot(x, y))
        .collect_into_vec(partials);
    partials.iter().sum()
}

fn block_dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Deterministic Euclidean norm.
pub fn norm(a: &[f64], partials: &mut Vec<f64>) -> f64 {
    dot(a, a, partials).sqrt()
}

/// Deterministic sum of the entries.
pub fn sum(a: &[f64], partials: &mut Vec<f64>) -> f64 {
    if a.len() < PARALLEL_MIN {
        return a.chunks(BLOCK).map(|x| x.iter().sum::<f64>()).sum();
    }
    a.par_chunks(BLOCK)
        .map(|x| x.iter().sum::<f64>())
        .collect_into_vec(partials);
    partials.iter().sum()
}

/// `y = A x` for a CSR matrix, parallel over rows.
pub fn spmv(a: &CsMat<f64>, x: &[f64], y: &mut [f64]) {
    let indptr = a.indptr();
    let indptr = indptr.raw_storage();
    let indices = a.indices();
    let data = a.data();
    let row = |i: usize| {
        let (start, end) = (indptr[i], indptr[i + 1]);
        let mut acc = 0.0;
        for k in start..end {
            acc += data[k] * x[indices[k]];
        }
        acc
    };
    if y.len() < PARALLEL_MIN {
        y.iter_mut().enumerate().for_each(|(i, yi)| *yi = row(i));
    } else {
        y.par_chunks_mut(1024).enumerate().for_each(|(c, chunk)| {
            for (k, yi) in chunk.iter_mut().enumerate() {
                *yi = row(c * 1024 + k);
            }
        });
    }
}

/// `y_m = A x_m` for the requested pairs (x_m, y_m) of one CSR matrix, in one pass over it:
/// each row's entries are read once and multiply every x_m. Each product is summed as
/// [`spmv`] sums it, bit for bit. `scratch` holds the x_m and the products interleaved by
/// row, so that an entry's column reads one short run of memory for all of them.
pub fn spmv_many(
    a: &CsMat<f64>,
    requests: &mut [Option<(&[f64], &mut [f64])>],
    scratch: &mut Interleaved,
) {
    let count = requests.iter().flatten().count();
    match count {
        0 => {}
        1 | 4.. => {
            for (x, y) in requests.iter_mut().flatten() {
                spmv(a, x, y);
            }
        }
        2 => interleaved_product::<2>(a, requests, scratch),
        _ => interleaved_product::<3>(a, requests, scratch),
    }
}

/// The vectors of [`spmv_many`] and their products, interleaved by row.
#[derive(Default)]
pub struct Interleaved {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl Interleaved {
    pub fn heap_bytes(&self) -> usize {
        (self.x.capacity() + self.y.capacity()) * std::mem::size_of::<f64>()
    }
}

/// [`spmv_many`] for M requests.
fn interleaved_product<const M: usize>(
    a: &CsMat<f64>,
    requests: &mut [Option<(&[f64], &mut [f64])>],
    scratch: &mut Interleaved,
) {
    let n = a.rows();
    scratch.x.resize(n * M, 0.0);
    scratch.y.resize(n * M, 0.0);
    for (m, (x, _)) in requests.iter().flatten().enumerate() {
        for (xi, v) in scratch.x.iter_mut().skip(m).step_by(M).zip(x.iter()) {
            *xi = *v;
        }
    }
    let indptr = a.indptr();
    let indptr = indptr.raw_storage();
    let (indices, data) = (a.indices(), a.data());
    let (x, _) = scratch.x.as_chunks::<M>();
    let row = |i: usize, out: &mut [f64; M]| {
        let (start, end) = (indptr[i], indptr[i + 1]);
        let mut acc = [0.0; M];
        for (v, j) in data[start..end].iter().zip(&indices[start..end]) {
            let xj = &x[*j];
            for m in 0..M {
                acc[m] += v * xj[m];
            }
        }
        *out = acc;
    };
    let (y, _) = scratch.y.as_chunks_mut::<M>();
    if n < PARALLEL_MIN {
        y.iter_mut().enumerate().for_each(|(i, out)| row(i, out));
    } else {
        y.par_chunks_mut(1024).enumerate().for_each(|(c, chunk)| {
            for (k, out) in chunk.iter_mut().enumerate() {
                row(c * 1024 + k, out);
            }
        });
    }
    let y = &*y;
    for (m, (_, out)) in requests.iter_mut().flatten().enumerate() {
        for_each_mut(out, |i, v| *v = y[i][m]);
    }
}

/// Applies `f(i, &mut y[i])` to every entry, in parallel for long vectors.
pub fn for_each_mut(y: &mut [f64], f: impl Fn(usize, &mut f64) + Sync + Send) {
    if y.len() < PARALLEL_MIN {
        y.iter_mut().enumerate().for_each(|(i, v)| f(i, v));
    } else {
        y.par_iter_mut().enumerate().for_each(|(i, v)| f(i, v));
    }
}
