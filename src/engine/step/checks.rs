//! Breakdown detection after every step: the invariants the scheme does not keep by
//! construction, checked and reported, never assumed.

use super::{Breakdown, Simulation};
use crate::engine::bodies::contact::narrowest_gap;
use crate::engine::reduce::blocked_sum;
use rayon::prelude::*;

/// Kinetic energy per unit mass above which a run has run away: an r.m.s. speed of 100 U.
const RUNAWAY_SPEED_FACTOR: f64 = 100.0;
/// tr A beyond which the conformation has run away (polymer stretch ~10⁶ of rest length).
const RUNAWAY_TRACE: f64 = 1e12;

impl Simulation {
    /// Breakdown detection: non-finite values, runaway kinetic energy or conformation, lost
    /// positive definiteness (direct integration), particles out of the box or through a
    /// wall.
    pub fn check(&self) -> Result<(), Breakdown> {
        let s = &self.state;
        let fail = |reason: String| Err(Breakdown { reason });
        if !s
            .velocity
            .par_iter()
            .all(|u| u.x.is_finite() && u.y.is_finite())
        {
            return fail("non-finite velocity".into());
        }
        if !s.pressure.par_iter().all(|p| p.is_finite()) {
            return fail("non-finite pressure".into());
        }
        let mean_square = blocked_sum(s.velocity.len(), |i| s.velocity[i].norm_squared())
            / s.velocity.len() as f64;
        let limit = RUNAWAY_SPEED_FACTOR * self.scales.velocity;
        if mean_square.sqrt() > limit {
            return fail(format!(
                "runaway kinetic energy: r.m.s. speed {:.3e} exceeds {RUNAWAY_SPEED_FACTOR} U",
                mean_square.sqrt()
            ));
        }
        if let Some(bad) = s.conformation.par_iter().find_any(|a| !a.is_finite()) {
            return fail(format!("non-finite conformation tensor {bad:?}"));
        }
        if s.conformation.par_iter().any(|a| a.trace() > RUNAWAY_TRACE) {
            return fail(format!("runaway conformation: tr A > {RUNAWAY_TRACE:e}"));
        }
        if let Some(stage) = self.stages.conformation.as_ref() {
            stage.check(&s.conformation).or_else(fail)?;
        }
        self.stages.integrator.check().or_else(fail)?;
        if self.stages.free_surface.is_some() {
            let d = &self.domain;
            if let Some(p) = s.position.par_iter().find_any(|p| {
                (0..2).any(|a| !d.periodic[a] && (p[a] < d.min[a] || p[a] > d.max[a]))
            }) {
                return fail(format!(
                    "a particle left the domain at ({:.4}, {:.4})",
                    p.x, p.y
                ));
            }
        }
        let walls = &self.stages.hood.ghosts.walls;
        if let Some(p) = s
            .position
            .par_iter()
            .find_any(|p| walls.iter().any(|w| w.distance_in(p, &self.domain) <= 0.0))
        {
            return fail(format!(
                "a particle crossed a wall at ({:.4}, {:.4})",
                p.x, p.y
            ));
        }
        self.check_discs().or_else(fail)
    }

    /// The discs stay one kernel support from the walls and from each other, or, under a
    /// contact model meant for closer gaps (lubrication, the exponential repulsion), do not
    /// overlap them ([`crate::engine::bodies::contact::Contact::smallest_gap`]); across periodic ends they pass.
    fn check_discs(&self) -> Result<(), String> {
        let bodies = &self.stages.bodies;
        let support = self.kernel.support();
        let smallest = bodies.contact.map_or(support, |c| c.smallest_gap(support));
        for (k, disc) in bodies.discs.iter().enumerate() {
            let gap = narrowest_gap(&bodies.discs, k, &self.domain);
            if gap < smallest {
                let c = disc.circle.centre;
                return Err(format!(
                    "disc {k} at ({:.4}, {:.4}) came within {smallest:.4} of a wall or another disc (gap {gap:.4})",
                    c.x, c.y
                ));
            }
        }
        Ok(())
    }
}
