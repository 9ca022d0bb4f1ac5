//! Deterministic parallel reductions: results independent of the number of threads.

use rayon::prelude::*;

/// Sum of `f(i)` for i < n in fixed blocks added in order: the same rounding whatever the
/// number of threads (rayon's own `sum` splits adaptively). Allocation-free up to 64 blocks
/// (262 144 terms).
pub fn blocked_sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    const BLOCK: usize = 4096;
    const STACK_BLOCKS: usize = 64;
    let blocks = n.div_ceil(BLOCK);
    let block_sum = |b: usize| (b * BLOCK..((b + 1) * BLOCK).min(n)).map(&f).sum::<f64>();
    if blocks <= STACK_BLOCKS {
        let mut partial = [0.0f64; STACK_BLOCKS];
        partial[..blocks]
            .par_iter_mut()
            .enumerate()
            .for_each(|(b, p)| *p = block_sum(b));
        partial[..blocks].iter().sum()
    } else {
        let partial: Vec<f64> = (0..blocks).into_par_iter().map(block_sum).collect();
        partial.iter().sum()
    }
}
