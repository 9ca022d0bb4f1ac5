//! A solid cylinder in the flow (the periodic array, the confined cylinder): its drag K =
//! F_x/(η0⟨u⟩) and parts in every series row, the steady state of ⟨u⟩ and the averages after
//! it (`[run.steady]`, King & Lind §IV B), `centreline.csv` and the cylinder charts.

use super::centreline::CentrelineRow;
use super::steady::{Averages, SteadySummary, SteadyWindows};
use super::Probe;
use crate::analysis::centreline::Centreline;
use crate::analysis::forces;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::FigureFormat;
use crate::app::run::charts;
use crate::app::table;
use crate::engine::boundary::Circle;
use crate::engine::step::Simulation;
use crate::engine::timing::Stage;
use crate::setup::case::{Case, SteadyCriterion};
use anyhow::Result;
use std::path::Path;
use std::time::Instant;

/// The cylinder probe.
pub struct CylinderProbe {
    circle: Circle,
    /// Surface points of the force integral: about two per particle spacing of arc.
    samples: usize,
    centreline: Centreline,
    criterion: Option<SteadyCriterion>,
    /// The case's end time: a run that never becomes steady averages its last `average` units.
    run_end: f64,
    state: SteadyState,
}

/// What a checkpoint keeps: when the flow became steady and the averages since, and the
/// averages over the run's last `average` time units while it is not steady.
type SteadyState = SteadyWindows<Averages>;

impl CylinderProbe {
    pub fn new(case: &Case, circle: Circle) -> Self {
        let arc = 2.0 * std::f64::consts::PI * circle.radius / case.scene.spacing();
        let centre = [circle.centre.x, circle.centre.y];
        Self {
            circle,
            samples: ((2.0 * arc).ceil() as usize).max(64),
            centreline: Centreline::new(centre, circle.radius, case.scene.length(), 161),
            criterion: case.steady,
            run_end: case.end_time,
            state: SteadyState::default(),
        }
    }

    /// The averages of the steady window; without one, those of the run's last `average`
    /// time units; without those (no criterion), the final state alone.
    fn averages(&mut self, sim: &mut Simulation, rows: &[SeriesRow]) -> Averages {
        let steady = self.state.averages.take().filter(|a| a.samples > 0);
        match steady.or_else(|| self.state.tail.take().filter(|a| a.samples > 0)) {
            Some(a) => a,
            None => {
                let mut a = Averages::new(sim.state.time);
                if let Some(last) = rows.last() {
                    add_sample(&mut a, &self.centreline, &self.circle, sim, last);
                }
                a
            }
        }
    }
}

/// Adds `row`, the centre-line profile and the momentum balance's drag of the current state
/// to `avg` (diagnostics time).
fn add_sample(
    avg: &mut Averages,
    centreline: &Centreline,
    circle: &Circle,
    sim: &mut Simulation,
    row: &SeriesRow,
) {
    let t0 = Instant::now();
    let profile = centreline.sample(sim, &sim.polymer_stress());
    avg.add(row, &profile, forces::balance_drag(sim, circle, row.u_mean));
    sim.timers
        .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
}

impl Probe for CylinderProbe {
    fn name(&self) -> &'static str {
        "steady"
    }

    /// K from the surface integral and its pressure, solvent and polymer parts; the pressure
    /// part includes the driving gradient's ([`forces::displaced`]).
    fn fill_row(&mut self, sim: &mut Simulation, row: &mut SeriesRow) {
        let t0 = Instant::now();
        let f = forces::on_cylinder(sim, &self.circle, self.samples);
        let scale = 1.0 / (sim.fluid.viscosity * row.u_mean);
        let displaced = forces::displaced(sim, &self.circle);
        row.drag_k = (f.total().x + displaced) * scale;
        row.k_pressure = (f.pressure[0] + displaced) * scale;
        row.k_solvent = f.solvent[0] * scale;
        row.k_polymer = f.polymer[0] * scale;
        sim.timers
            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
    }

    fn record(&mut self, _sim: &mut Simulation, _rows: &[SeriesRow]) {}

    /// Once steady, averages each row; when ⟨u⟩ first meets the criterion, ends the run
    /// after the averaging time.
    fn end_time(&mut self, sim: &mut Simulation, rows: &[SeriesRow]) -> Option<f64> {
        let criterion = self.criterion?;
        let last = &rows[rows.len() - 1];
        let (line, circle) = (&self.centreline, &self.circle);
        self.state
            .observe(&criterion, self.run_end, rows, Averages::new, |avg| {
                add_sample(avg, line, circle, sim, last)
            })
    }

    fn checkpoint(&self) -> Option<serde_json::Value> {
        self.state.to_json()
    }

    fn restore(&mut self, _dir: &Path, _t: f64, state: Option<&serde_json::Value>) -> Result<()> {
        Ok(self.state.restore(state)?)
    }

    /// `centreline.csv` and the cylinder charts; the `steady` summary.
    fn finish(
        &mut self,
        sim: &mut Simulation,
        rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        let avg = self.averages(sim, rows);
        let eta_s = sim.fluid.solvent_viscosity();
        let radius = self.circle.radius;
        let mut summary = avg.summary(self.state.steady_at, eta_s, radius, &self.centreline.s);
        let balance = forces::momentum_balance(sim, &self.circle, self.samples, summary.u_mean);
        summary.momentum_balance = Some(balance);
        let centreline = centreline_rows(&self.centreline, &avg, &summary, eta_s, radius);
        let csv = table::write_rows(&centreline);
        io::write_atomic(&dir.join("centreline.csv"), csv.as_bytes())?;
        if let Some(format) = charts {
            let c = self.circle.centre;
            charts::cylinder(
                dir,
                format,
                sim,
                rows,
                // The charts show the file's values, as a later `compare-centrelines` does.
                &table::parse_rows::<CentrelineRow>(&csv, "centreline.csv")?,
                ((c.x, c.y), radius),
            )?;
        }
        Ok(Some(serde_json::to_value(summary)?))
    }
}

/// The rows of `centreline.csv`.
fn centreline_rows(
    line: &Centreline,
    avg: &Averages,
    summary: &SteadySummary,
    eta_s: f64,
    radius: f64,
) -> Vec<CentrelineRow> {
    let profile = avg.profile();
    let u = summary.u_mean;
    let tau_scale = eta_s * u / radius;
    (0..line.s.len())
        .map(|k| CentrelineRow {
            s: line.s[k],
            u_over_umean: profile.u[k] / u,
            tau_xx_scaled: profile.tau_xx[k] / tau_scale,
            det_a: profile.det_a[k],
        })
        .collect()
}
