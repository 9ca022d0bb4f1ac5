//! Particle ordering for memory locality: fluid particles are periodically sorted along a
//! Morton (Z-order) curve of their cells, so that the neighbours of a particle, and the
//! columns of its PPE row, sit close together in memory.
//!
//! Reordering permutes the particles only; physics is unchanged except for the order of
//! floating-point sums over neighbours (round-off; see `tests/reordering.rs`).

use crate::engine::dimension::{Dim, Dimension};
use crate::engine::neighbours::Domain;
use nalgebra::SVector;

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

/// Interleaves the low 16 bits of D cell coordinates, the first axis in the lowest bit.
fn morton<const D: usize>(cells: [u32; D]) -> u64 {
    let mut key = 0;
    for bit in 0..16 {
        for (a, &c) in cells.iter().enumerate() {
            key |= ((c as u64 >> bit) & 1) << (bit * D + a);
        }
    }
    key
}

/// Reusable buffers of the reordering.
pub struct Reorder<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    keys: Vec<(u64, u32)>,
    vectors: Vec<SVector<f64, D>>,
    scalar: Vec<f64>,
    sym: Vec<<Dim<D> as Dimension<D>>::Sym>,
    flags: Vec<bool>,
}

impl<const D: usize> Default for Reorder<D>
where
    Dim<D>: Dimension<D>,
{
    fn default() -> Self {
        Self {
            keys: Vec::new(),
            vectors: Vec::new(),
            scalar: Vec::new(),
            sym: Vec::new(),
            flags: Vec::new(),
        }
    }
}

impl<const D: usize> Reorder<D>
where
    Dim<D>: Dimension<D>,
{
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.keys)
            + crate::engine::vec_bytes(&self.vectors)
            + crate::engine::vec_bytes(&self.scalar)
            + crate::engine::vec_bytes(&self.sym)
            + crate::engine::vec_bytes(&self.flags)
    }

    /// Computes the Morton order of `positions` over cells of width `cell`; returns false if
    /// the particles are already in that order (nothing to permute).
    pub fn compute(
        &mut self,
        domain: &Domain<D>,
        positions: &[SVector<f64, D>],
        cell: f64,
    ) -> bool {
        self.keys.clear();
        self.keys.extend(positions.iter().enumerate().map(|(i, p)| {
            let c = (p - domain.min) / cell;
            // Walls' mirrors may sit below the box along the axes after the first.
            let cells = std::array::from_fn(|a| {
                let margin = if a == 0 { 0.0 } else { 4.0 };
                (c[a] + margin).max(0.0) as u32
            });
            (morton::<D>(cells), i as u32)
        }));
        if self.keys.windows(2).all(|w| w[0] <= w[1]) {
            return false;
        }
        self.keys.sort_unstable();
        true
    }

    /// Applies the last computed order to one array.
    pub fn apply_vec2(&mut self, data: &mut [SVector<f64, D>]) {
        permute(&self.keys, data, &mut self.vectors);
    }

    pub fn apply_scalar(&mut self, data: &mut [f64]) {
        permute(&self.keys, data, &mut self.scalar);
    }

    pub fn apply_bool(&mut self, data: &mut [bool]) {
        permute(&self.keys, data, &mut self.flags);
    }

    pub fn apply_sym(&mut self, data: &mut [<Dim<D> as Dimension<D>>::Sym]) {
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
    use crate::engine::math::Vec2;

    #[test]
    fn morton_order_interleaves_bits() {
        assert_eq!(morton([0, 0]), 0);
        assert_eq!(morton([1, 0]), 1);
        assert_eq!(morton([0, 1]), 2);
        assert_eq!(morton([3, 3]), 15);
        assert_eq!(morton([2, 0]), 4);
        assert_eq!(morton([0xffff, 0]), 0x5555_5555);
        assert_eq!(morton([0x1_0000, 0]), 0, "16 bits per axis");
        // In space: x in bit 0, y in bit 1, z in bit 2 of each triple.
        assert_eq!(morton([1, 0, 0]), 1);
        assert_eq!(morton([0, 1, 0]), 2);
        assert_eq!(morton([0, 0, 1]), 4);
        assert_eq!(morton([2, 1, 3]), 0b101_110);
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
