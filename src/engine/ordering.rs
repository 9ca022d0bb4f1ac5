//! Particle ordering for memory locality: fluid particles are periodically sorted along a
//! Morton (Z-order) curve of their cells, so that the neighbours of a particle, and the
//! columns of its PPE row, sit close together in memory.
//!
//! Reordering permutes the particles only; physics is unchanged except for the order of
//! floating-point sums over neighbours (round-off; see `tests/reordering.rs`).

use crate::engine::math::{Sym2, Vec2};
use crate::engine::neighbours::Domain;

/// Steps between Morton reorderings of moving particles: they move a fraction of δr per
/// step, so locality decays slowly.
pub const REORDER_INTERVAL: u64 = 50;

/// When the particles are sorted, chosen at set-up from the frame and the scheme's switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reordering {
    Never,
    /// Once, before the first step (fixed particles).
    Once,
    /// Every [`REORDER_INTERVAL`] steps (moving particles).
    Periodic,
}

impl Reordering {
    pub fn new(enabled: bool, moving: bool) -> Self {
        match (enabled, moving) {
            (false, _) => Reordering::Never,
            (true, false) => Reordering::Once,
            (true, true) => Reordering::Periodic,
        }
    }

    /// Whether a reordering is due before step `steps`.
    pub fn due(self, steps: u64) -> bool {
        match self {
            Reordering::Never => false,
            Reordering::Once => steps == 0,
            Reordering::Periodic => steps.is_multiple_of(REORDER_INTERVAL),
        }
    }
}

/// Interleaves the bits of two 16-bit cell coordinates.
fn morton(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64 & 0xffff;
        v = (v | (v << 8)) & 0x00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333;
        v = (v | (v << 1)) & 0x5555_5555;
        v
    }
    spread(x) | (spread(y) << 1)
}

/// Reusable buffers of the reordering.
#[derive(Default)]
pub struct Reorder {
    keys: Vec<(u64, u32)>,
    vec2: Vec<Vec2>,
    scalar: Vec<f64>,
    sym: Vec<Sym2>,
    flags: Vec<bool>,
}

impl Reorder {
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.keys)
            + crate::engine::vec_bytes(&self.vec2)
            + crate::engine::vec_bytes(&self.scalar)
            + crate::engine::vec_bytes(&self.sym)
            + crate::engine::vec_bytes(&self.flags)
    }

    /// Computes the Morton order of `positions` over cells of width `cell`; returns false if
    /// the particles are already in that order (nothing to permute).
    pub fn compute(&mut self, domain: &Domain, positions: &[Vec2], cell: f64) -> bool {
        self.keys.clear();
        self.keys.extend(positions.iter().enumerate().map(|(i, p)| {
            let c = (p - domain.min) / cell;
            let cx = c.x.max(0.0) as u32;
            let cy = (c.y + 4.0).max(0.0) as u32; // walls' mirrors may sit below min.y
            (morton(cx, cy), i as u32)
        }));
        if self.keys.windows(2).all(|w| w[0] <= w[1]) {
            return false;
        }
        self.keys.sort_unstable();
        true
    }

    /// Applies the last computed order to one array.
    pub fn apply_vec2(&mut self, data: &mut [Vec2]) {
        permute(&self.keys, data, &mut self.vec2);
    }

    pub fn apply_scalar(&mut self, data: &mut [f64]) {
        permute(&self.keys, data, &mut self.scalar);
    }

    pub fn apply_bool(&mut self, data: &mut [bool]) {
        permute(&self.keys, data, &mut self.flags);
    }

    pub fn apply_sym(&mut self, data: &mut [Sym2]) {
        permute(&self.keys, data, &mut self.sym);
    }
}

fn permute<T: Copy>(keys: &[(u64, u32)], data: &mut [T], scratch: &mut Vec<T>) {
    if data.is_empty() {
        return;
    }
    scratch.clear();
    scratch.extend(keys.iter().map(|&(_, i)| data[i as usize]));
    data.copy_from_slice(scratch);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_order_interleaves_bits() {
        assert_eq!(morton(0, 0), 0);
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(3, 3), 15);
        assert_eq!(morton(2, 0), 4);
    }

    #[test]
    fn permutation_is_applied_consistently() {
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, false],
        };
        let pos = vec![
            Vec2::new(0.9, 0.9),
            Vec2::new(0.1, 0.1),
            Vec2::new(0.5, 0.1),
        ];
        let mut r = Reorder::default();
        assert!(r.compute(&domain, &pos, 0.25));
        let mut p = pos.clone();
        r.apply_vec2(&mut p);
        let mut ids = vec![0.0, 1.0, 2.0];
        r.apply_scalar(&mut ids);
        for (k, &id) in ids.iter().enumerate() {
            assert_eq!(p[k], pos[id as usize]);
        }
        assert_eq!(ids[0], 1.0);
        assert!(!r.compute(&domain, &p, 0.25), "already sorted");
    }
}
