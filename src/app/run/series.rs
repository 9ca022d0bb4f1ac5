//! One row of `series.csv`: the state at an output time against the analytic reference.

use super::summary::PpeWindow;
use crate::analysis::diagnostics;
use crate::analysis::plane::InPlane;
use crate::analysis::reference::Reference;
use crate::app::io::SeriesRow;
use crate::engine::dimension::Dim;
use crate::engine::step::{Simulation, StepDimension};
use crate::setup::scenes::Scene;

/// The series row of the current state (the probes' columns NaN until they fill them);
/// `window` holds the PPE statistics since the last row, `dt` the last step.
pub fn row<const D: usize>(
    sim: &Simulation<D>,
    scene: &dyn Scene,
    reference: Option<&mut Reference>,
    window: &PpeWindow,
    dt: f64,
) -> SeriesRow
where
    Dim<D>: StepDimension<D> + InPlane<D>,
{
    let s = &sim.state;
    let stats = diagnostics::field_stats(
        &s.velocity,
        &s.conformation,
        sim.fluid.density,
        sim.particle_volume(),
    );
    let where_min_det = diagnostics::min_det_location(&s.position, &s.conformation);
    let where_max_trace = diagnostics::max_trace_location(&s.position, &s.conformation);
    let map = scene.plane();
    let (position, velocity) = (
        Dim::<D>::positions(map, &s.position),
        Dim::<D>::velocities(map, &s.position, &s.velocity),
    );
    let (u_centre_exact, l2_error) = match reference {
        Some(r) => (
            r.characteristic_velocity(s.time),
            r.l2_error(&position, &velocity, s.time),
        ),
        None => (f64::NAN, f64::NAN),
    };
    SeriesRow {
        t: s.time,
        dt,
        step: s.steps,
        u_centre: scene.characteristic_velocity(&position, &velocity),
        u_centre_exact,
        l2_error,
        ppe_iterations: window.mean_iterations(),
        ppe_residual: window.max_residual,
        ppe_fallbacks: window.fallbacks as u32,
        kinetic_energy: stats.kinetic_energy,
        max_speed: stats.max_speed,
        max_trace_a: stats.max_trace,
        min_det_a: stats.min_det,
        u_mean: sim.bulk_velocity(),
        drag_k: f64::NAN,
        k_pressure: f64::NAN,
        k_solvent: f64::NAN,
        k_polymer: f64::NAN,
        body_force: s.body_force[0],
        elastic_courant: window.max_elastic_courant,
        min_det_a_x: where_min_det[0],
        min_det_a_y: where_min_det[1],
        max_trace_a_x: where_max_trace[0],
        max_trace_a_y: where_max_trace[1],
        conformation_noise: diagnostics::conformation_noise(
            &sim.domain,
            &s.position,
            &s.conformation,
            sim.spacing,
        ),
    }
}
