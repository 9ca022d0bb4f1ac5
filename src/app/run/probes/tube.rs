//! A fixed sphere in a pipe whose wall slides past it at U (the sphere falling in a tube):
//! its drag coefficient K = F_x/(6πη0 aU) in every series row (`drag_k`), the steady state
//! of the drive (`[run.steady]`), the averages after it, and the Newtonian benchmark value
//! where the radius ratio has one.
//!
//! The wall carries part of the load, so the body force alone (the array's drag,
//! [`crate::analysis::forces::sphere_drag`]) does not give the sphere's: each row reads it
//! from the pipe's momentum balance with the wall's share fitted on the wall
//! ([`tube_load`]), and the final state also off control spheres around the body
//! ([`sphere_load::on_control_sphere`]), whose fits reach neither the sphere nor, at
//! a/δr = 8 and R = 2a, the wall from a + 4δr. Both hold once the flow is steady; the
//! validation pages compare them.

use super::steady::{DragWindow, SteadyWindows};
use super::Probe;
use crate::analysis::sphere_load;
use crate::analysis::tube_load::{self, PipeWall};
use crate::app::io::SeriesRow;
use crate::app::plot::FigureFormat;
use crate::engine::boundary::Sphere;
use crate::engine::step::Simulation;
use crate::engine::timing::Stage;
use crate::setup::case::{Case, SteadyCriterion};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::Path;
use std::time::Instant;

/// The Newtonian drag coefficient of a sphere on the axis of a tube with a/R = 1/2, in
/// creeping flow: 5.94716, the Wi = 0 entry of the falling-sphere benchmark, on which its
/// converged computations agree to the digits given.
pub const NEWTONIAN_K_HALF: f64 = 5.94716;

/// The control spheres' distances from the body, in spacings.
const CONTROL: [f64; 3] = [3.0, 4.0, 5.0];

/// The sphere-in-a-tube probe.
pub struct TubeProbe {
    sphere: Sphere,
    /// The pipe's wall.
    wall: PipeWall,
    criterion: Option<SteadyCriterion>,
    run_end: f64,
    state: SteadyWindows<DragWindow>,
}

/// `summary.json`'s `sphere_in_tube` entry.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TubeSummary {
    /// When the criterion was met (None: not met before the end time; the averages are then
    /// over the last `average` time units, or the final row, and are not steady values).
    pub reached_at: Option<f64>,
    pub averaged_from: f64,
    pub averaged_to: f64,
    pub samples: usize,
    /// U: the wall's speed past the sphere (the velocity scale).
    pub speed: f64,
    /// a/R.
    pub radius_ratio: f64,
    /// K = F_x/(6πη0 aU) from the pipe's momentum balance, the window's mean.
    pub drag_k: f64,
    /// K of the final state on the control spheres a + 3δr, a + 4δr, a + 5δr (None where a
    /// fit fails).
    pub drag_k_contour: [Option<f64>; 3],
    /// The wall's axial force on the fluid over the sphere's drag, W_x/F_x, at the end
    /// (negative: the fluid squeezed past the sphere outruns the wall, which holds it back).
    pub wall_share: Option<f64>,
    /// The Newtonian benchmark's K at this radius ratio (None: no value for it, or a
    /// non-Newtonian fluid).
    pub drag_k_newtonian: Option<f64>,
    /// (K − K_Newtonian)/K_Newtonian.
    pub drag_k_error: Option<f64>,
}

impl TubeProbe {
    pub fn new(case: &Case, sphere: Sphere, wall: PipeWall) -> Self {
        Self {
            sphere,
            wall,
            criterion: case.steady,
            run_end: case.end_time,
            state: SteadyWindows::default(),
        }
    }

    /// 6πη0 aU.
    fn stokes(&self, sim: &Simulation<3>) -> f64 {
        6.0 * PI * sim.fluid.viscosity * self.sphere.radius * sim.scales.velocity
    }

    /// The drag from the pipe's balance and the wall's share of it (None where a wall fit
    /// fails).
    fn balance(&self, sim: &Simulation<3>) -> Option<(f64, f64)> {
        let solid = 4.0 / 3.0 * PI * self.sphere.radius.powi(3);
        let wall = tube_load::axial_load(sim, self.wall)?;
        Some((tube_load::body_drag(sim, wall, solid), wall))
    }

    /// K on the control sphere `m` spacings from the body.
    fn contour_k(&self, sim: &Simulation<3>, m: f64) -> Option<f64> {
        let (a, dr) = (self.sphere.radius, sim.spacing);
        let r = a + m * dr;
        let samples = (4.0 * PI * (r / dr).powi(2)).ceil() as usize;
        sphere_load::on_control_sphere(sim, &self.sphere, r, samples)
            .map(|f| f[0] / self.stokes(sim))
    }

    fn summary(&self, sim: &Simulation<3>, avg: &DragWindow) -> TubeSummary {
        let drag_k = avg.drag_k();
        let radius_ratio = self.sphere.radius / self.wall.radius;
        let newtonian = !sim.fluid.model.is_viscoelastic() && sim.fluid.law.is_constant();
        let reference =
            ((radius_ratio - 0.5).abs() < 1e-9 && newtonian).then_some(NEWTONIAN_K_HALF);
        TubeSummary {
            reached_at: self.state.steady_at,
            averaged_from: avg.from,
            averaged_to: avg.to,
            samples: avg.samples,
            speed: sim.scales.velocity,
            radius_ratio,
            drag_k,
            drag_k_contour: CONTROL.map(|m| self.contour_k(sim, m)),
            wall_share: self.balance(sim).map(|(f, w)| w / f),
            drag_k_newtonian: reference,
            drag_k_error: reference.map(|k| (drag_k - k) / k),
        }
    }
}

impl Probe<3> for TubeProbe {
    fn name(&self) -> &'static str {
        "sphere_in_tube"
    }

    fn fill_row(&mut self, sim: &mut Simulation<3>, row: &mut SeriesRow) {
        let t0 = Instant::now();
        row.drag_k = self
            .balance(sim)
            .map_or(f64::NAN, |(f, _)| f / self.stokes(sim));
        sim.timers
            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
    }

    fn record(&mut self, _sim: &mut Simulation<3>, _rows: &[SeriesRow]) {}

    /// Once steady, averages each row; when the drive first meets the criterion, ends the
    /// run after the averaging time.
    fn end_time(&mut self, _sim: &mut Simulation<3>, rows: &[SeriesRow]) -> Option<f64> {
        let criterion = self.criterion?;
        self.state.observe_rows(&criterion, self.run_end, rows)
    }

    fn checkpoint(&self) -> Option<serde_json::Value> {
        self.state.to_json()
    }

    fn restore(&mut self, _dir: &Path, _t: f64, state: Option<&serde_json::Value>) -> Result<()> {
        Ok(self.state.restore(state)?)
    }

    /// The summary: the steady window's means, else the last `average` units', else the
    /// final row's.
    fn finish(
        &mut self,
        sim: &mut Simulation<3>,
        rows: &[SeriesRow],
        _dir: &Path,
        _charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        let avg = self.state.reported(sim.state.time, rows);
        let t0 = Instant::now();
        let summary = self.summary(sim, &avg);
        sim.timers
            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
        Ok(Some(serde_json::to_value(summary)?))
    }
}
