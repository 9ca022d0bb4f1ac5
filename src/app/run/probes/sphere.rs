//! A fixed sphere in a box periodic along every axis (the simple cubic array): its drag
//! coefficient K = F_x/(6πη0 a⟨u⟩) in every series row (`drag_k`), from the box's momentum
//! balance ([`forces::sphere_drag`]), the steady state of the drive (`[run.steady]`), the
//! averages after it, Zick & Homsy's K at the array's solid fraction where their table
//! has it, and the final state's K from control spheres around the body.

use super::steady::{DragWindow, SteadyWindows};
use super::Probe;
use crate::analysis::{forces, sphere_load};
use crate::app::io::SeriesRow;
use crate::app::plot::FigureFormat;
use crate::engine::boundary::Sphere;
use crate::engine::step::Simulation;
use crate::engine::timing::Stage;
use crate::setup::case::{Case, SteadyCriterion};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// The sphere probe.
pub struct SphereProbe {
    sphere: Sphere,
    criterion: Option<SteadyCriterion>,
    /// The case's end time: a run that never becomes steady averages its last `average` units.
    run_end: f64,
    /// When the drive became steady and the averages since (or over the run's last
    /// `average` time units while it is not): what a checkpoint keeps.
    state: SteadyWindows<DragWindow>,
}

/// `summary.json`'s `sphere` entry.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SphereSummary {
    /// When the criterion was met (None: not met before the end time; the averages are then
    /// over the last `average` time units, or the final row, and are not steady values).
    pub reached_at: Option<f64>,
    pub averaged_from: f64,
    pub averaged_to: f64,
    pub samples: usize,
    /// ⟨u⟩, the superficial velocity Q/(L_y L_z).
    pub u_mean: f64,
    /// K = F_x/(6πη0 a⟨u⟩), the window's mean.
    pub drag_k: f64,
    pub radius: f64,
    /// The simple cubic array's solid fraction (4/3)πa³/L³.
    pub solid_fraction: f64,
    /// Zick & Homsy's K at this solid fraction (None where their Table 2 has no entry).
    pub drag_k_zick_homsy: Option<f64>,
    /// (K − K_ZH)/K_ZH.
    pub drag_k_error: Option<f64>,
    /// The particles' volume NδV against the box's less the sphere's, relative: the lattice
    /// cut's volume error, which the drive's body force acts on.
    pub volume_deficit: f64,
    /// K of the final state from control spheres 3, 4 and 5 spacings out
    /// ([`sphere_load::on_control_sphere`]): the same drag without the box's balance; None
    /// where the control sphere's fits would reach the sphere's periodic images.
    pub drag_k_contour: [Option<f64>; 3],
}

impl SphereProbe {
    pub fn new(case: &Case, sphere: Sphere) -> Self {
        Self {
            sphere,
            criterion: case.steady,
            run_end: case.end_time,
            state: SteadyWindows::default(),
        }
    }

    /// The summary of `avg` in `sim`'s box.
    fn summary(&self, sim: &Simulation<3>, avg: &DragWindow) -> SphereSummary {
        let c = crate::setup::scenes::sphere::solid_fraction(&self.sphere, &sim.domain);
        let box_volume = crate::engine::drive::box_volume(&sim.domain);
        let fluid = box_volume * (1.0 - c);
        let drag_k = avg.drag_k();
        let reference = forces::zick_homsy(c);
        SphereSummary {
            reached_at: self.state.steady_at,
            averaged_from: avg.from,
            averaged_to: avg.to,
            samples: avg.samples,
            u_mean: avg.u_mean(),
            drag_k,
            radius: self.sphere.radius,
            solid_fraction: c,
            drag_k_zick_homsy: reference,
            drag_k_error: reference.map(|k| (drag_k - k) / k),
            volume_deficit: (sim.fluid_volume() - fluid) / fluid,
            drag_k_contour: self.contour(sim),
        }
    }

    /// K from the control spheres a + 3δr, a + 4δr, a + 5δr of the current state, with its
    /// mean velocity; a surface point per δr² of each.
    fn contour(&self, sim: &Simulation<3>) -> [Option<f64>; 3] {
        let (a, dr, u_mean) = (self.sphere.radius, sim.spacing, sim.bulk_velocity());
        let extent = sim.domain.max - sim.domain.min;
        let clearance = extent.min() - a - sim.kernel.support();
        let stokes = 6.0 * std::f64::consts::PI * sim.fluid.viscosity * a * u_mean;
        [3.0, 4.0, 5.0].map(|m| {
            let r = a + m * dr;
            if r > clearance {
                return None;
            }
            let samples = (4.0 * std::f64::consts::PI * (r / dr).powi(2)).ceil() as usize;
            sphere_load::on_control_sphere(sim, &self.sphere, r, samples).map(|f| f[0] / stokes)
        })
    }
}

impl Probe<3> for SphereProbe {
    fn name(&self) -> &'static str {
        "sphere"
    }

    fn fill_row(&mut self, sim: &mut Simulation<3>, row: &mut SeriesRow) {
        let stokes = 6.0 * std::f64::consts::PI * sim.fluid.viscosity * self.sphere.radius;
        row.drag_k = forces::sphere_drag(sim, &self.sphere) / (stokes * row.u_mean);
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

    /// The `sphere` summary: the steady window's means, else the last `average` units',
    /// else the final row's.
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
