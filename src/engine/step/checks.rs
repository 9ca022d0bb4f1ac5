//! Breakdown detection after every step: the invariants the scheme does not keep by
//! construction, checked and reported, never assumed.

use super::{Breakdown, Features, Simulation, StepDimension};
use crate::engine::bodies::contact::narrowest_gap;
use crate::engine::bodies::Bodies;
use crate::engine::dimension::{Dim, SymTensor};
use crate::engine::neighbours::Domain;
use crate::engine::reduce::blocked_sum;
use rayon::prelude::*;

/// Kinetic energy per unit mass above which a run has run away: an r.m.s. speed of 100 U.
const RUNAWAY_SPEED_FACTOR: f64 = 100.0;
/// tr A beyond which the conformation has run away (polymer stretch ~10⁶ of rest length).
const RUNAWAY_TRACE: f64 = 1e12;

impl<const D: usize> Simulation<D>
where
    Dim<D>: StepDimension<D>,
{
    /// Breakdown detection: non-finite values, runaway kinetic energy or conformation, lost
    /// positive definiteness (direct integration), particles out of the box or through a
    /// wall.
    pub fn check(&self) -> Result<(), Breakdown> {
        let s = &self.state;
        let fail = |reason: String| Err(Breakdown { reason });
        if !s
            .velocity
            .par_iter()
            .all(|u| u.iter().all(|c| c.is_finite()))
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
        let features = &self.stages.features;
        features.check_particles(s, &self.domain).or_else(fail)?;
        let walls = &self.stages.hood.ghosts.walls;
        if let Some(p) = s
            .position
            .par_iter()
            .find_any(|p| walls.iter().any(|w| w.distance_in(p, &self.domain) <= 0.0))
        {
            return fail(format!("a particle crossed a wall at {}", point(p)));
        }
        features
            .check_bodies(&self.domain, self.kernel.support())
            .or_else(fail)
    }
}

/// A point as `(x, y)` or `(x, y, z)`, four decimals.
fn point<const D: usize>(p: &nalgebra::SVector<f64, D>) -> String {
    let c: Vec<String> = p.iter().map(|v| format!("{v:.4}")).collect();
    format!("({})", c.join(", "))
}

/// The discs stay one kernel support from the walls and from each other, or, under a
/// contact model meant for closer gaps (lubrication, the exponential repulsion), do not
/// overlap them ([`crate::engine::bodies::contact::Contact::smallest_gap`]); across periodic ends they pass.
pub(super) fn check_discs(bodies: &Bodies, domain: &Domain, support: f64) -> Result<(), String> {
    let smallest = bodies.contact.map_or(support, |c| c.smallest_gap(support));
    for (k, disc) in bodies.discs.iter().enumerate() {
        let gap = narrowest_gap(&bodies.discs, k, domain);
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
