//! Step 2's particle configuration: the positions r*, the wall mirrors, the CSR neighbour
//! lists and the kernel sums (pair factors and Bonet–Lok L_i, eq. (22)) every operator reads.
//! Rebuilt every step when the particles move, once when they do not.

use crate::engine::boundary::Ghosts;
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::Vec2;
use crate::engine::neighbours::{Domain, NeighbourList, NeighbourSearch};
use crate::engine::operators::KernelSums;
use crate::engine::ordering::Reorder;

/// Points (fluid then ghosts), neighbour lists and kernel sums of one configuration.
#[derive(Default)]
pub struct Neighbourhood {
    /// r* of the fluid particles followed by the ghosts' positions.
    pub points: Vec<Vec2>,
    pub ghosts: Ghosts,
    pub list: NeighbourList,
    pub sums: KernelSums,
    search: NeighbourSearch,
    /// Point volumes relative to δV (empty: all 1).
    volumes: Vec<f64>,
    /// The lists describe the current particles (false after a reordering or restore).
    valid: bool,
    reorder: Reorder,
}

impl Neighbourhood {
    pub fn new(ghosts: Ghosts) -> Self {
        Self {
            ghosts,
            ..Default::default()
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.points)
            + self.ghosts.heap_bytes()
            + self.search.heap_bytes()
            + self.list.heap_bytes()
            + self.sums.heap_bytes()
            + crate::engine::vec_bytes(&self.volumes)
            + self.reorder.heap_bytes()
    }

    /// The three parts every operator takes.
    pub fn parts(&self) -> (&NeighbourList, &KernelSums, &Ghosts) {
        (&self.list, &self.sums, &self.ghosts)
    }

    /// The lists no longer describe the particles.
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// Mirrors, lists and kernel sums for the first `n` points (the fluid particles at r*),
    /// when `moving` or not yet built. Returns whether the configuration was rebuilt.
    pub fn update(
        &mut self,
        moving: bool,
        (domain, kernel, spacing): (&Domain, &QuinticSpline, f64),
        n: usize,
    ) -> bool {
        if !moving && self.valid {
            return false;
        }
        self.ghosts.domain = Some(*domain);
        self.ghosts.build(kernel.support(), &mut self.points);
        self.search
            .build(domain, &self.points, n, kernel.support(), &mut self.list);
        if self.ghosts.has_volume_ratios() {
            self.ghosts.point_volumes(n, &mut self.volumes);
        } else {
            self.volumes.clear();
        }
        self.sums
            .update_with_volumes(&self.list, kernel, spacing * spacing, &self.volumes);
        self.valid = true;
        true
    }

    /// The Morton order of `positions` (see [`crate::engine::ordering`]), to permute every
    /// per-particle array with; None when they are in that order already.
    pub fn reorder(
        &mut self,
        domain: &Domain,
        positions: &[Vec2],
        cell: f64,
    ) -> Option<&mut Reorder> {
        if self.reorder.compute(domain, positions, cell) {
            self.valid = false;
            Some(&mut self.reorder)
        } else {
            None
        }
    }
}
