//! When a run writes what: series rows every `run.output_interval`, `.vtu` snapshots every
//! `run.snapshot_interval`, checkpoints every `run.checkpoint_interval`, and the end time
//! (shortened when a probe asks, e.g. once a steady state has been averaged).

use crate::setup::case::Case;
use serde::{Deserialize, Serialize};

/// The next time of each kind of output, and the end.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Cadence {
    pub next_output: f64,
    pub next_snapshot: f64,
    pub next_checkpoint: f64,
    pub end_time: f64,
    output_interval: f64,
    snapshot_interval: f64,
    checkpoint_interval: f64,
    /// Times closer than this count as equal (1e-9 of the case's end time).
    tolerance: f64,
}

impl Cadence {
    /// The cadence of a run starting at t = 0 (its first row is written there).
    pub fn new(case: &Case) -> Self {
        Self {
            next_output: 0.0,
            next_snapshot: 0.0,
            next_checkpoint: case.checkpoint_interval,
            end_time: case.end_time,
            output_interval: case.output_interval,
            snapshot_interval: case.snapshot_interval,
            checkpoint_interval: case.checkpoint_interval,
            tolerance: 1e-9 * case.end_time,
        }
    }

    /// Whether the run goes on at time t.
    pub fn running(&self, t: f64) -> bool {
        t < self.end_time - self.tolerance
    }

    /// Whether a series row is due at t (an output time or the end); if so, the next output
    /// time moves past t.
    pub fn output_due(&mut self, t: f64) -> bool {
        let due = t >= self.next_output - self.tolerance || t >= self.end_time - self.tolerance;
        if due {
            self.next_output = advance(self.next_output, self.output_interval, t + self.tolerance);
        }
        due
    }

    /// The first row, at t = 0.
    pub fn first_output(&mut self) {
        self.next_output += self.output_interval;
    }

    /// Whether a snapshot is due at t (or `force`d); if so, the next one moves past t.
    pub fn snapshot_due(&mut self, t: f64, force: bool) -> bool {
        let due = force || t >= self.next_snapshot - self.tolerance;
        if due {
            self.next_snapshot = advance(
                self.next_snapshot,
                self.snapshot_interval,
                t + self.tolerance,
            );
        }
        due
    }

    /// Whether a checkpoint is due at t; if so, the next one moves past t.
    pub fn checkpoint_due(&mut self, t: f64) -> bool {
        let due = t >= self.next_checkpoint - self.tolerance;
        if due {
            self.next_checkpoint = advance(
                self.next_checkpoint,
                self.checkpoint_interval,
                t + self.tolerance,
            );
        }
        due
    }

    /// Ends the run at `t` if that is earlier.
    pub fn end_by(&mut self, t: f64) {
        self.end_time = self.end_time.min(t);
    }
}

/// `next` advanced by whole `interval`s until it passes `limit`.
fn advance(mut next: f64, interval: f64, limit: f64) -> f64 {
    while next <= limit {
        next += interval;
    }
    next
}
