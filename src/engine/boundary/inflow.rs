//! Inflow through an orifice (King & Lind §III C: moving ghost particles with prescribed
//! velocity and polymer stress). A buffer of `rows` rows of particles above the orifice moves
//! rigidly at the inflow velocity; each step a buffer particle that has passed below the
//! orifice is released into the fluid, and a new row is added on top whenever the buffer has
//! moved down one spacing. Particles are removed nowhere.
//!
//! Buffer particles are rows of the step's systems with prescribed values: their velocity is
//! the inflow velocity (identity rows of the implicit viscous system), their conformation the
//! rest state (no polymer stress), they are not shifted, and their pressure is a Dirichlet
//! p = 0, the ambient pressure of a jet leaving an orifice open on three sides (where the
//! paper uses a Neumann condition on ghosts behind a wall; our buffer has none).

use crate::engine::math::{Sym2, Vec2};
use crate::engine::state::State;

/// Buffer rows: more than the kernel support (3.9δr), so a released particle has a full
/// neighbourhood above it.
pub const BUFFER_ROWS: usize = 5;

/// The inflow buffer's state.
#[derive(Clone, Debug)]
pub struct Inflow {
    /// Buffer membership per particle (same order as the particle state).
    pub flags: Vec<bool>,
    /// The prescribed velocity.
    pub velocity: Vec2,
    /// Buffer particles below this height are released.
    pub orifice_y: f64,
    /// y of the buffer's top row.
    pub top_y: f64,
    /// x of the buffer's columns.
    pub columns: Vec<f64>,
    pub spacing: f64,
}

impl Inflow {
    /// A buffer of width `width` centred on x = `centre_x` above the orifice at `orifice_y`,
    /// fed downwards at `speed`; returns it with the positions of its particles.
    pub fn new(
        centre_x: f64,
        width: f64,
        orifice_y: f64,
        speed: f64,
        dr: f64,
    ) -> (Self, Vec<Vec2>) {
        let n = (width / dr).round() as usize;
        let columns: Vec<f64> = (0..n)
            .map(|k| centre_x - 0.5 * width + (k as f64 + 0.5) * dr)
            .collect();
        let positions: Vec<Vec2> = (0..BUFFER_ROWS)
            .flat_map(|j| {
                let y = orifice_y + (j as f64 + 0.5) * dr;
                columns.iter().map(move |&x| Vec2::new(x, y))
            })
            .collect();
        let inflow = Self {
            flags: vec![true; positions.len()],
            velocity: Vec2::new(0.0, -speed),
            orifice_y,
            top_y: orifice_y + (BUFFER_ROWS as f64 - 0.5) * dr,
            columns,
            spacing: dr,
        };
        (inflow, positions)
    }

    /// After the buffer has moved for `dt`: releases buffer particles below the orifice and
    /// returns the positions of the rows to add on top (their flags are pushed here; the
    /// caller appends the particles).
    pub fn advance(&mut self, dt: f64, positions: &[Vec2]) -> Vec<Vec2> {
        self.top_y += dt * self.velocity.y;
        for (flag, p) in self.flags.iter_mut().zip(positions) {
            if *flag && p.y < self.orifice_y {
                *flag = false;
            }
        }
        let mut added = Vec::new();
        let ceiling = self.orifice_y + BUFFER_ROWS as f64 * self.spacing;
        while self.top_y + self.spacing < ceiling + 1e-9 * self.spacing {
            self.top_y += self.spacing;
            added.extend(self.columns.iter().map(|&x| Vec2::new(x, self.top_y)));
        }
        self.flags.extend(std::iter::repeat_n(true, added.len()));
        added
    }

    /// Sets the buffer particles' entries of `values` (a velocity or shift) to `value`.
    pub fn prescribe(&self, values: &mut [Vec2], value: Vec2) {
        for (v, _) in values.iter_mut().zip(&self.flags).filter(|(_, &b)| b) {
            *v = value;
        }
    }

    /// After step 7: buffer particles keep the rest conformation `rest` (no polymer stress
    /// enters), those below the orifice are released, and new rows join the buffer on top.
    pub fn feed(&mut self, rest: Sym2, dt: f64, state: &mut State) {
        let viscoelastic = !state.conformation.is_empty();
        if viscoelastic {
            for (a, _) in state
                .conformation
                .iter_mut()
                .zip(&self.flags)
                .filter(|(_, &b)| b)
            {
                *a = rest;
            }
        }
        let added = self.advance(dt, &state.position);
        for p in added {
            state.position.push(p);
            state.velocity.push(self.velocity);
            state.pressure.push(0.0);
            state.shift_velocity.push(Vec2::zeros());
            if viscoelastic {
                state.conformation.push(rest);
            }
        }
    }

    /// Particles in the buffer.
    pub fn count(&self) -> usize {
        self.flags.iter().filter(|&&f| f).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Moving the buffer down by exactly one spacing releases its bottom row and adds one on
    /// top: the buffer keeps its depth and the released particles sit just below the orifice.
    #[test]
    fn a_spacing_of_travel_releases_one_row_and_adds_one() {
        let dr = 0.1;
        let (mut inflow, mut pts) = Inflow::new(0.0, 1.0, 2.0, 1.0, dr);
        assert_eq!(pts.len(), 10 * BUFFER_ROWS);
        let mut released = 0;
        for _ in 0..10 {
            let dt = 0.01;
            for p in pts.iter_mut() {
                *p += dt * inflow.velocity;
            }
            let added = inflow.advance(dt, &pts);
            pts.extend(added);
        }
        released += inflow.flags.iter().filter(|&&f| !f).count();
        assert_eq!(released, 10, "one row of 10 released");
        assert_eq!(inflow.count(), 10 * BUFFER_ROWS, "buffer depth kept");
        assert_eq!(pts.len(), inflow.flags.len());
        let top = pts.iter().map(|p| p.y).fold(f64::MIN, f64::max);
        assert!((top - (2.0 + (BUFFER_ROWS as f64 - 0.5) * dr)).abs() < 1e-9);
    }
}
