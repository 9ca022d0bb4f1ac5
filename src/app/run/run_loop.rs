//! The time loop of a run: step the simulation, and at the [`Cadence`]'s times write series
//! rows, probe records, snapshots and checkpoints; stop at the end time or a breakdown.

use super::cadence::Cadence;
use super::charts;
use super::checkpoint::{LoopState, CHECKPOINT_FILE, FINAL_STATE_FILE};
use super::dimension::RunDimension;
use super::errors;
use super::probes::Probes;
use super::series;
use super::summary::{self, Outcome, PpeSummary, PpeWindow, Summary};
use super::{RunOptions, CASE_FILE};
use crate::analysis::reference::Reference;
use crate::app::io::{self, SeriesRow};
use crate::app::vtk;
use crate::engine::dimension::Dim;
use crate::engine::step::Simulation;
use crate::engine::timing::Stage;
use crate::setup::case::Case;
use anyhow::{Context, Result};
use indicatif::ProgressBar;
use std::time::{Duration, Instant};

/// Series rows are flushed to disk at most this often (and at the end).
const FLUSH_INTERVAL: Duration = Duration::from_secs(2);

/// A run in progress (the command line's loop, or a simulation stepped from Python).
pub struct Run<const D: usize = 2>
where
    Dim<D>: RunDimension<D>,
{
    case: Case,
    options: RunOptions,
    pub sim: Simulation<D>,
    reference: Result<Reference, String>,
    rows: Vec<SeriesRow>,
    cadence: Cadence,
    /// PPE statistics since the last row, and over the run.
    window: PpeWindow,
    totals: PpeWindow,
    last_dt: f64,
    probes: Probes<D>,
    snapshots: Option<vtk::Series>,
    breakdown: Option<String>,
    progress: ProgressBar,
    start: Instant,
    /// Wall seconds of the segments before this one (a resumed run).
    wall_before: f64,
    last_flush: Instant,
}

/// How a run starts.
pub enum Start<const D: usize = 2>
where
    Dim<D>: RunDimension<D>,
{
    /// From the case's initial state.
    Fresh,
    /// Continued from its own checkpoint.
    Resumed(Box<Resumed<D>>),
    /// From another run's final state (`run --from DIR`), with this case's parameters; the
    /// clock starts at t = 0.
    Continued(Box<Simulation<D>>),
}

/// A run continued from its checkpoint.
pub struct Resumed<const D: usize = 2>
where
    Dim<D>: RunDimension<D>,
{
    pub sim: Simulation<D>,
    pub state: LoopState,
    pub rows: Vec<SeriesRow>,
}

impl<const D: usize> Run<D>
where
    Dim<D>: RunDimension<D>,
{
    /// Prepares the run directory and the run's state (fresh, or from a checkpoint).
    pub fn new(case: &Case, options: &RunOptions, start: Start<D>) -> Result<Self> {
        let dir = &options.out_dir;
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let reference = match (case.scene.reference(&case.fluid), &start) {
            (Ok(r), Start::Continued(_)) if !r.is_steady() => Err(
                "continued from another run's state: the start-up solution does not apply"
                    .to_string(),
            ),
            (r, _) => r,
        };
        if let (Err(why), false) = (&reference, options.quiet) {
            eprintln!("  no analytic reference: {why}");
        }
        // A previous run's summary must not survive to describe this one.
        let _ = std::fs::remove_file(dir.join("summary.json"));
        let _ = std::fs::remove_file(dir.join(super::ERROR_FILE));
        let sim = Dim::<D>::simulation(case)?;
        let snapshots = if options.snapshots {
            let grid_spacing = case.grid_spacing.unwrap_or(sim.spacing);
            Some(vtk::Series::new(dir, Some(grid_spacing))?)
        } else {
            None
        };
        let mut run = Self {
            case: case.clone(),
            options: options.clone(),
            sim,
            reference,
            rows: Vec::new(),
            cadence: Cadence::new(case),
            window: PpeWindow::default(),
            totals: PpeWindow::default(),
            last_dt: 0.0,
            probes: Dim::<D>::probes(case),
            snapshots,
            breakdown: None,
            progress: summary::progress_bar(options.quiet, case.end_time),
            start: Instant::now(),
            wall_before: 0.0,
            last_flush: Instant::now(),
        };
        match start {
            Start::Resumed(r) => run.resume(*r)?,
            Start::Fresh => run.begin()?,
            Start::Continued(sim) => {
                run.sim = *sim;
                run.begin()?;
            }
        }
        Ok(run)
    }

    /// A fresh run: the case as run, the first row and snapshot at t = 0.
    fn begin(&mut self) -> Result<()> {
        let dir = &self.options.out_dir;
        let _ = std::fs::remove_file(dir.join(CHECKPOINT_FILE));
        let _ = std::fs::remove_file(dir.join(FINAL_STATE_FILE));
        io::write_atomic(
            &dir.join(CASE_FILE),
            toml::to_string(&self.case.source)?.as_bytes(),
        )?;
        self.record();
        self.cadence.first_output();
        self.snapshot(true)
    }

    /// A resumed run: the loop's state and the probes' rows from the checkpoint.
    fn resume(&mut self, r: Resumed<D>) -> Result<()> {
        self.sim = r.sim;
        self.rows = r.rows;
        let st = r.state;
        self.cadence = st.cadence;
        self.window = st.window;
        self.totals = st.totals;
        self.last_dt = st.last_dt;
        self.wall_before = st.wall_seconds;
        self.sim.timers = st.stage_seconds;
        if let Some(series) = self.snapshots.as_mut() {
            series.restore_entries(st.snapshots);
        }
        self.probes
            .restore(&self.options.out_dir, self.sim.state.time, &st.probes)
    }

    /// Steps to the end time or a breakdown, writing at the cadence's times.
    pub fn time_loop(&mut self) -> Result<()> {
        while self.step()? {}
        Ok(())
    }

    /// One step, and the outputs due after it; false once the run has reached its end time
    /// or broken down (the step is then not taken, or its breakdown recorded).
    pub fn step(&mut self) -> Result<bool> {
        if self.breakdown.is_some() || !self.cadence.running(self.sim.state.time) {
            return Ok(false);
        }
        let dt_max = step_limit(
            &self.sim,
            self.cadence.end_time - self.sim.state.time,
            self.last_dt,
        );
        match self.sim.step(dt_max) {
            Ok(report) => {
                self.last_dt = report.dt;
                self.window.add(&report);
                self.totals.add(&report);
            }
            Err(b) => {
                self.breakdown = Some(b.reason);
                if self.window.steps > 0 {
                    self.record();
                }
                return Ok(false);
            }
        }
        let t = self.sim.state.time;
        if self.cadence.output_due(t) {
            self.record();
            if let Some(end) = self.probes.end_time(&mut self.sim, &self.rows) {
                self.cadence.end_by(end);
            }
            self.snapshot(false)?;
            self.checkpoint_if_due()?;
            self.progress
                .set_position((1000.0 * t / self.case.end_time) as u64);
            self.progress.set_message(format!("t = {t:.3}"));
            if let Some(hook) = &self.options.progress {
                (hook.0)(t, self.cadence.end_time);
            }
            if self.last_flush.elapsed() >= FLUSH_INTERVAL {
                self.flush()?;
            }
        }
        Ok(true)
    }

    /// The last step's δt (0 before the first).
    pub fn last_dt(&self) -> f64 {
        self.last_dt
    }

    /// The run's end time (a probe may have brought it forward).
    pub fn end_time(&self) -> f64 {
        self.cadence.end_time
    }

    /// Why the run broke down, if it did.
    pub fn breakdown(&self) -> Option<&str> {
        self.breakdown.as_deref()
    }

    /// Appends the series row of the current state, with the probes' records.
    fn record(&mut self) {
        let t0 = Instant::now();
        let mut row = series::row(
            &self.sim,
            self.case.scene.as_ref(),
            self.reference.as_mut().ok(),
            &self.window,
            self.last_dt,
        );
        self.window = PpeWindow::default();
        self.sim
            .timers
            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
        self.probes.fill_row(&mut self.sim, &mut row);
        self.rows.push(row);
        self.probes.record(&mut self.sim, &self.rows);
    }

    /// Writes a `.vtu` snapshot (and, for free surfaces with charts, a tr A PNG) when one is
    /// due, or `force`d and not yet written at this time.
    fn snapshot(&mut self, force: bool) -> Result<()> {
        let Some(series) = self.snapshots.as_mut() else {
            return Ok(());
        };
        let t = self.sim.state.time;
        if series.last_time() == Some(t) || !self.cadence.snapshot_due(t, force) {
            return Ok(());
        }
        let t0 = Instant::now();
        Dim::<D>::write_snapshot(series, &self.sim)?;
        if let (Some(format), true) = (self.options.charts, self.case.scene.has_free_surface()) {
            // Drops in t* = tU/W, jets in seconds.
            let (title, name) = match self.case.scene.drop_shape() {
                Some(d) => {
                    let ts = t * d.speed / d.diameter;
                    (
                        format!("tr A, t* = {ts:.2}"),
                        format!("trace_a_{ts:07.3}.png"),
                    )
                }
                None => (
                    format!("tr A, t = {t:.3} s"),
                    format!("trace_a_t{t:.4}.png"),
                ),
            };
            let dir = self.options.out_dir.join("snapshots");
            Dim::<D>::free_surface_chart(&dir, format, &self.sim, &title, &name)?;
        }
        self.sim
            .timers
            .add(Stage::Output, t0.elapsed().as_secs_f64());
        Ok(())
    }

    /// A checkpoint when one is due (a jet's growing particle count is not checkpointed).
    fn checkpoint_if_due(&mut self) -> Result<()> {
        if self.sim.grows() || !self.cadence.checkpoint_due(self.sim.state.time) {
            return Ok(());
        }
        self.checkpoint()
    }

    /// Writes `checkpoint.bin` (and the series so far) now: [`super::resumed`] continues from
    /// it bit for bit.
    pub fn checkpoint(&mut self) -> Result<()> {
        anyhow::ensure!(
            !self.sim.grows(),
            "a jet cannot be checkpointed: its particle count grows"
        );
        let t0 = Instant::now();
        self.write_series()?;
        let state = LoopState {
            case_name: self.case.name.clone(),
            cadence: self.cadence.clone(),
            window: self.window.clone(),
            totals: self.totals.clone(),
            last_dt: self.last_dt,
            snapshots: self
                .snapshots
                .as_ref()
                .map(|s| s.entries().to_vec())
                .unwrap_or_default(),
            probes: self.probes.checkpoint(),
            wall_seconds: self.wall_seconds(),
            stage_seconds: self.sim.timers,
        };
        if Dim::<D>::save_checkpoint(&self.options.out_dir, &state, &self.sim)? {
            self.sim.reset_preconditioners();
        }
        self.sim
            .timers
            .add(Stage::Output, t0.elapsed().as_secs_f64());
        Ok(())
    }

    /// The usual files of the state now, into `dir` (created if missing), the run going on:
    /// `series.csv` so far and the probes' files, `profile.csv` at the current time (with
    /// the analytic columns where the scene has a reference), and the particles as
    /// `state.vtu`.
    pub fn write_outputs(&mut self, dir: &std::path::Path) -> Result<()> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        io::write_atomic(
            &dir.join("series.csv"),
            io::series_csv(&self.rows).as_bytes(),
        )?;
        self.probes.write(dir)?;
        self.errors_and_profile(dir)?;
        io::write_atomic(&dir.join("state.vtu"), &Dim::<D>::snapshot(&self.sim))
    }

    /// The errors against the reference now, with `profile.csv` written into `dir`.
    fn errors_and_profile(
        &mut self,
        dir: &std::path::Path,
    ) -> Result<(errors::Errors, Option<errors::ExactStresses>)> {
        let map = self.case.scene.plane();
        let reference = self.reference.as_mut().map_err(|e| e.as_str());
        let (errors, stresses) =
            errors::final_errors(&self.sim, map, reference, &self.rows, self.last_dt);
        let profile = errors::profile_csv(
            &self.sim,
            map,
            self.reference.as_mut().ok(),
            stresses.as_ref(),
        );
        io::write_atomic(&dir.join("profile.csv"), profile.as_bytes())?;
        Ok((errors, stresses))
    }

    fn flush(&mut self) -> Result<()> {
        let t0 = Instant::now();
        self.write_series()?;
        self.sim
            .timers
            .add(Stage::Output, t0.elapsed().as_secs_f64());
        self.last_flush = Instant::now();
        Ok(())
    }

    /// `series.csv` and the probes' files, atomically.
    fn write_series(&self) -> Result<()> {
        let dir = &self.options.out_dir;
        io::write_atomic(
            &dir.join("series.csv"),
            io::series_csv(&self.rows).as_bytes(),
        )?;
        self.probes.write(dir)
    }

    /// The final files, charts and `summary.json`.
    pub fn finish(mut self) -> Result<Summary> {
        let dir = self.options.out_dir.clone();
        let charts = self.options.charts;
        self.snapshot(true)?;
        self.progress.finish_and_clear();
        let t0 = Instant::now();
        self.write_series()?;
        let probes = self
            .probes
            .finish(&mut self.sim, &self.rows, &dir, charts)?;
        let (errors, stresses) = self.errors_and_profile(&dir)?;
        let scene = self.case.scene.as_ref();
        let plain =
            scene.cylinder().is_none() && scene.sphere().is_none() && !scene.has_free_surface();
        if let (Some(format), true) = (charts, plain) {
            charts::draw(
                &dir,
                format,
                scene,
                &self.sim,
                self.reference.as_ref().ok(),
                &self.rows,
                stresses.as_ref(),
            )?;
        }
        self.sim
            .timers
            .add(Stage::Output, t0.elapsed().as_secs_f64());
        let summary = self.summary(errors, probes);
        if self.breakdown.is_none() && !self.sim.grows() {
            // The state another run can start from (`run --from DIR`).
            Dim::<D>::write_final_state(&dir.join(FINAL_STATE_FILE), &self.sim)?;
        }
        io::write_json(&dir.join("summary.json"), &summary)?;
        if !self.options.quiet {
            summary::report_end(&summary, &dir);
        }
        Ok(summary)
    }

    /// Wall seconds of the whole run so far, the segments before a resume included.
    fn wall_seconds(&self) -> f64 {
        self.wall_before + self.start.elapsed().as_secs_f64()
    }

    fn summary(
        &self,
        errors: errors::Errors,
        probes: std::collections::BTreeMap<&'static str, serde_json::Value>,
    ) -> Summary {
        let sim = &self.sim;
        let wall_seconds = self.wall_seconds();
        let (steps, particles) = (sim.state.steps, sim.particles());
        let totals = &self.totals;
        Summary {
            outcome: if self.breakdown.is_some() {
                Outcome::BrokeDown
            } else {
                Outcome::Finished
            },
            reason: self.breakdown.clone(),
            t_reached: sim.state.time,
            end_time: self.cadence.end_time,
            particles,
            steps,
            wall_seconds,
            particle_steps_per_second: particles as f64 * steps as f64 / wall_seconds.max(1e-9),
            stage_seconds: sim.timers,
            threads: rayon::current_num_threads(),
            derived: self.case.derived(),
            errors,
            ppe: PpeSummary {
                mean_iterations: totals.mean_iterations(),
                max_iterations: totals.max_iterations,
                lu_fallbacks: totals.fallbacks,
                bicgstab_solves: totals.solves - totals.lu_solves,
                lu_solves: totals.lu_solves,
                lu_factorisations: sim.ppe_factorisations(),
                max_relative_residual: totals.max_residual,
                absolute_floor_stops: totals.floor_stops,
                matrix_nonzeros: sim.ppe_nonzeros(),
                viscous_mean_iterations: totals.viscous_iterations as f64
                    / totals.steps.max(1) as f64,
            },
            max_density_deviation: totals.max_density_deviation,
            max_sound_speed: totals.max_sound_speed,
            neighbour_pairs_per_particle: sim.neighbour_pairs() as f64 / particles as f64,
            neighbour_searches: sim.neighbour_searches(),
            probes,
            version: env!("CARGO_PKG_VERSION"),
            case: self.case.source.clone(),
        }
    }
}

/// The largest step towards the end time: the remaining time, except that a remainder
/// between one and two stable steps is halved, so the last step is never a sliver. (The
/// projection pressure carries an O(1/δt) part from the divergence left by the previous
/// step; a tiny last step would make the final pressure, and the drag, spike.)
fn step_limit<const D: usize>(sim: &Simulation<D>, remaining: f64, last_dt: f64) -> f64
where
    Dim<D>: RunDimension<D>,
{
    if last_dt > 0.0 && remaining < 3.0 * last_dt {
        let stable = sim.stable_dt();
        if remaining > stable && remaining < 2.0 * stable {
            return 0.5 * remaining;
        }
    }
    remaining
}
