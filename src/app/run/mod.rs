//! A run: the time loop around [`Simulation`], the analytic comparison, and the run
//! directory (`series.csv`, `summary.json`, PNG charts).

mod charts;
mod drop;
mod errors;
mod jet;
mod steady;

pub use drop::DropSummary;
pub use errors::{Errors, Peak};
pub use steady::{Averages, SteadyCriterion, SteadySummary};

use crate::analysis::centreline::Centreline;
use crate::analysis::diagnostics;
use crate::analysis::reference::{self, Reference};
use crate::app::io::{self, SeriesRow};
use crate::engine::boundary::Circle;
use crate::engine::math::Vec2;
use crate::engine::step::Simulation;
use crate::engine::timing::{Stage, StageSeconds};
use crate::setup::case::{Case, Derived};
use crate::setup::scene;
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Options of a run that are not physics.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// No progress bar, no start-up report.
    pub quiet: bool,
    /// Skip the PNG charts (studies draw their own).
    pub charts: bool,
    /// Write `.vtu` snapshots every `run.snapshot_interval`.
    pub snapshots: bool,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    Finished,
    BrokeDown,
}

#[derive(Clone, Debug, Serialize)]
pub struct PpeSummary {
    pub mean_iterations: f64,
    pub max_iterations: usize,
    pub lu_fallbacks: u64,
    /// Solves by each method, and LU factorisations (a fixed-particle run factorises once).
    pub bicgstab_solves: u64,
    pub lu_solves: u64,
    pub lu_factorisations: usize,
    /// Largest relative residual ‖b − Ap‖/‖b‖ of any solve.
    pub max_relative_residual: f64,
    /// Solves that stopped on the divergence tolerance (`scheme.ppe_divergence_tolerance`) before
    /// reaching the relative tolerance; for these ‖b‖ is near round-off and the relative
    /// residual can be O(1) by design.
    pub absolute_floor_stops: u64,
    pub matrix_nonzeros: usize,
}

/// `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub outcome: Outcome,
    pub reason: Option<String>,
    pub t_reached: f64,
    pub end_time: f64,
    pub particles: usize,
    pub steps: u64,
    pub wall_seconds: f64,
    pub particle_steps_per_second: f64,
    pub stage_seconds: StageSeconds,
    pub threads: usize,
    pub derived: Derived,
    pub errors: Errors,
    pub ppe: PpeSummary,
    pub neighbour_pairs_per_particle: f64,
    /// Channels with a cylinder: steady state, time averages, drag and centre-line values.
    pub steady: Option<SteadySummary>,
    /// Drops: the largest width, the final shape, and the area drift.
    pub drop: Option<DropSummary>,
    /// Jets: impact, buckling onset and folding frequency.
    pub jet: Option<jet::JetSummary>,
    pub version: &'static str,
    pub case: crate::setup::case::CaseFile,
}

/// Series rows are flushed to disk at most this often (and at the end).
const FLUSH_INTERVAL: Duration = Duration::from_secs(2);

/// Runs a case to its end time or breakdown and writes the run directory.
pub fn run(case: &Case, options: &RunOptions) -> Result<Summary> {
    run_from(case, options, None)
}

/// Continues the run in `options.out_dir` from its last checkpoint (`checkpoint.bin`, with the
/// case as run in `case.toml`). The continued run writes what the uninterrupted one would
/// have: the series is cut back to the checkpoint and extended bit for bit.
pub fn resume(options: &RunOptions) -> Result<Summary> {
    let dir = &options.out_dir;
    let bytes = std::fs::read(dir.join(CHECKPOINT_FILE))
        .with_context(|| format!("reading {}", dir.join(CHECKPOINT_FILE).display()))?;
    anyhow::ensure!(bytes.len() >= 8, "{}: truncated", CHECKPOINT_FILE);
    let json_len = u64::from_le_bytes(bytes[..8].try_into()?) as usize;
    anyhow::ensure!(
        bytes.len() >= 8 + json_len,
        "{}: truncated",
        CHECKPOINT_FILE
    );
    let state: LoopState = serde_json::from_slice(&bytes[8..8 + json_len])
        .with_context(|| format!("{}: bad run state", CHECKPOINT_FILE))?;
    let text = std::fs::read_to_string(dir.join(CASE_FILE))
        .with_context(|| format!("reading {}", dir.join(CASE_FILE).display()))?;
    let case = crate::setup::case::parse(&text, CASE_FILE, &state.case_name, &[])?;
    anyhow::ensure!(
        case.scene.jet.is_none(),
        "a jet cannot be resumed: its particle count grows and checkpoints do not record the inflow buffer"
    );
    let mut sim = Simulation::new(scene::build(&case));
    crate::app::checkpoint::restore(&mut sim, &bytes[8 + json_len..])
        .with_context(|| format!("restoring {}", CHECKPOINT_FILE))?;
    let t = sim.state.time;
    let rows: Vec<SeriesRow> = io::read_series(&dir.join("series.csv"))?
        .into_iter()
        .filter(|r| r.step <= sim.state.steps && r.t <= t)
        .collect();
    run_from(&case, options, Some(Resumed { sim, state, rows }))
}

/// The checkpoint of a run directory: the run loop's state (JSON, length-prefixed) followed
/// by [`crate::app::checkpoint::encode`] of the simulation, in one atomically written file.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// The case as run (after `--set`), for `--resume`.
pub const CASE_FILE: &str = "case.toml";

/// The run loop's own state, saved with each checkpoint.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
struct LoopState {
    case_name: String,
    next_output: f64,
    next_snapshot: f64,
    next_checkpoint: f64,
    end_time: f64,
    steady_at: Option<f64>,
    averages: Option<Averages>,
    window: PpeWindow,
    totals: PpeWindow,
    last_dt: f64,
    snapshots: Vec<(f64, String)>,
}

struct Resumed {
    sim: Simulation,
    state: LoopState,
    rows: Vec<SeriesRow>,
}

fn run_from(case: &Case, options: &RunOptions, resumed: Option<Resumed>) -> Result<Summary> {
    std::fs::create_dir_all(&options.out_dir)
        .with_context(|| format!("creating {}", options.out_dir.display()))?;
    let derived = case.derived();
    if !options.quiet {
        report_start(case, &derived);
    }
    let is_resumed = resumed.is_some();
    let (mut sim, saved, mut rows) = match resumed {
        Some(r) => (r.sim, Some(r.state), r.rows),
        None => (Simulation::new(scene::build(case)), None, Vec::new()),
    };
    let mut reference = Reference::for_case(case);
    if let (Err(why), false) = (&reference, options.quiet) {
        eprintln!("  no analytic reference: {why}");
    }
    let series_path = options.out_dir.join("series.csv");
    let summary_path = options.out_dir.join("summary.json");
    // A previous run's summary must not survive to describe this one.
    let _ = std::fs::remove_file(&summary_path);
    if !is_resumed {
        let _ = std::fs::remove_file(options.out_dir.join(CHECKPOINT_FILE));
        io::write_atomic(
            &options.out_dir.join(CASE_FILE),
            toml::to_string(&case.source)?.as_bytes(),
        )?;
    }

    let progress = progress_bar(options.quiet, case.end_time);
    let start = Instant::now();
    let mut last_flush = Instant::now();
    let mut window = PpeWindow::default();
    let mut totals = PpeWindow::default();
    let mut next_output = 0.0;
    let mut snapshots = if options.snapshots {
        Some(crate::app::vtk::Series::new(&options.out_dir)?)
    } else {
        None
    };
    let mut next_snapshot = 0.0;
    let mut next_checkpoint = case.checkpoint_interval;
    let mut breakdown = None;
    let mut last_dt = 0.0;
    let tolerance = 1e-9 * case.end_time;
    let body = Body::for_case(case);
    let mut probes = Probes::for_case(case);
    if is_resumed {
        probes.restore(&options.out_dir, sim.state.time)?;
    }
    // Where free-surface scenes draw their tr A snapshots (with the charts only).
    let pngs =
        (options.charts && case.scene.has_free_surface()).then_some(options.out_dir.as_path());
    // Shortened to the end of the averaging window once the flow is steady.
    let mut end_time = case.end_time;
    let mut steady_at = None;
    let mut averages: Option<Averages> = None;

    match saved {
        Some(st) => {
            next_output = st.next_output;
            next_snapshot = st.next_snapshot;
            next_checkpoint = st.next_checkpoint;
            end_time = st.end_time;
            steady_at = st.steady_at;
            averages = st.averages;
            window = st.window;
            totals = st.totals;
            last_dt = st.last_dt;
            if let Some(series) = snapshots.as_mut() {
                series.restore_entries(st.snapshots);
            }
        }
        None => {
            record(
                &mut sim,
                reference.as_mut().ok(),
                case,
                body.as_ref(),
                &mut window,
                0.0,
                &mut rows,
            );
            probes.record(&sim);
            next_output += case.output_interval;
        }
    }
    if !is_resumed {
        snapshot_due(
            &mut snapshots,
            &mut next_snapshot,
            case,
            &mut sim,
            true,
            pngs,
        )?;
    }
    while sim.state.time < end_time - tolerance {
        let dt_max = step_limit(&sim, end_time - sim.state.time, last_dt);
        match sim.step(dt_max) {
            Ok(report) => {
                last_dt = report.dt;
                window.add(&report.ppe);
                totals.add(&report.ppe);
            }
            Err(b) => {
                breakdown = Some(b.reason);
                break;
            }
        }
        if sim.state.time >= next_output - tolerance || sim.state.time >= end_time - tolerance {
            record(
                &mut sim,
                reference.as_mut().ok(),
                case,
                body.as_ref(),
                &mut window,
                last_dt,
                &mut rows,
            );
            probes.record(&sim);
            if let (Some(b), Some(criterion)) = (body.as_ref(), case.steady) {
                match averages.as_mut() {
                    Some(avg) => {
                        let t0 = Instant::now();
                        let profile = b.centreline.sample(&sim, &sim.polymer_stress());
                        avg.add(&rows[rows.len() - 1], &profile);
                        sim.timers
                            .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
                    }
                    None => {
                        if let Some(t) = criterion.reached(&rows) {
                            steady_at = Some(t);
                            averages = Some(Averages::new(t));
                            end_time = end_time.min(t + criterion.average);
                        }
                    }
                }
            }
            while next_output <= sim.state.time + tolerance {
                next_output += case.output_interval;
            }
            snapshot_due(
                &mut snapshots,
                &mut next_snapshot,
                case,
                &mut sim,
                false,
                (options.charts && case.scene.has_free_surface())
                    .then_some(options.out_dir.as_path()),
            )?;
            // A jet's particle count grows: its checkpoints are not supported (yet).
            if sim.inflow.is_none() && sim.state.time >= next_checkpoint - tolerance {
                while next_checkpoint <= sim.state.time + tolerance {
                    next_checkpoint += case.checkpoint_interval;
                }
                let t0 = Instant::now();
                io::write_atomic(&series_path, io::series_csv(&rows).as_bytes())?;
                probes.write(&options.out_dir)?;
                let state = LoopState {
                    case_name: case.name.clone(),
                    next_output,
                    next_snapshot,
                    next_checkpoint,
                    end_time,
                    steady_at,
                    averages: averages.clone(),
                    window: window.clone(),
                    totals: totals.clone(),
                    last_dt,
                    snapshots: snapshots
                        .as_ref()
                        .map(|s| s.entries().to_vec())
                        .unwrap_or_default(),
                };
                let json = serde_json::to_vec(&state)?;
                let mut bytes = (json.len() as u64).to_le_bytes().to_vec();
                bytes.extend_from_slice(&json);
                bytes.extend_from_slice(&crate::app::checkpoint::encode(&sim));
                io::write_atomic(&options.out_dir.join(CHECKPOINT_FILE), &bytes)?;
                sim.timers.add(Stage::Output, t0.elapsed().as_secs_f64());
            }
            progress.set_position((1000.0 * sim.state.time / case.end_time) as u64);
            progress.set_message(format!("t = {:.3}", sim.state.time));
            if last_flush.elapsed() >= FLUSH_INTERVAL {
                let t0 = Instant::now();
                io::write_atomic(&series_path, io::series_csv(&rows).as_bytes())?;
                probes.write(&options.out_dir)?;
                sim.timers.add(Stage::Output, t0.elapsed().as_secs_f64());
                last_flush = Instant::now();
            }
        }
    }
    if breakdown.is_some() && window.steps > 0 {
        record(
            &mut sim,
            reference.as_mut().ok(),
            case,
            body.as_ref(),
            &mut window,
            last_dt,
            &mut rows,
        );
        probes.record(&sim);
    }
    // Without a steady state the "averages" are the final state alone.
    let steady = body.as_ref().map(|b| {
        let avg = match averages.take() {
            Some(a) if a.samples > 0 => a,
            _ => {
                let mut a = Averages::new(sim.state.time);
                let profile = b.centreline.sample(&sim, &sim.polymer_stress());
                if let Some(last) = rows.last() {
                    a.add(last, &profile);
                }
                a
            }
        };
        (
            avg.summary(
                steady_at,
                sim.fluid.solvent_viscosity(),
                b.circle.radius,
                &b.centreline.s,
            ),
            avg,
        )
    });
    snapshot_due(
        &mut snapshots,
        &mut next_snapshot,
        case,
        &mut sim,
        true,
        pngs,
    )?;
    progress.finish_and_clear();

    let t0 = Instant::now();
    io::write_atomic(&series_path, io::series_csv(&rows).as_bytes())?;
    probes.write(&options.out_dir)?;
    if options.charts {
        probes.charts(&options.out_dir)?;
    }
    let drop_summary = probes.drop.as_ref().and_then(|d| d.summary());
    let jet_summary = probes.jet.as_ref().map(|j| j.summary(sim.spacing));
    let (errors, stresses) = errors::final_errors(
        &sim,
        reference.as_mut().map_err(|e| e.as_str()),
        &rows,
        last_dt,
    );
    io::write_atomic(
        &options.out_dir.join("profile.csv"),
        errors::profile_csv(&sim, reference.as_mut().ok(), stresses.as_ref()).as_bytes(),
    )?;
    if let (Some(b), Some((summary, avg))) = (body.as_ref(), steady.as_ref()) {
        let csv = centreline_csv(
            &b.centreline,
            avg,
            summary,
            sim.fluid.solvent_viscosity(),
            b.circle.radius,
        );
        io::write_atomic(&options.out_dir.join("centreline.csv"), csv.as_bytes())?;
        if options.charts {
            let c = b.circle.centre;
            charts::cylinder(
                &options.out_dir,
                &sim,
                &rows,
                &crate::analysis::centreline::parse_csv(&csv),
                ((c.x, c.y), b.circle.radius),
            )?;
        }
    }
    if options.charts && body.is_none() && !case.scene.has_free_surface() {
        charts::draw(
            &options.out_dir,
            case.scene.kind,
            &sim,
            reference.as_ref().ok(),
            &rows,
            stresses.as_ref(),
        )?;
    }
    sim.timers.add(Stage::Output, t0.elapsed().as_secs_f64());
    let wall_seconds = start.elapsed().as_secs_f64();
    let steps = sim.state.steps;
    let summary = Summary {
        outcome: if breakdown.is_some() {
            Outcome::BrokeDown
        } else {
            Outcome::Finished
        },
        reason: breakdown,
        t_reached: sim.state.time,
        end_time,
        particles: sim.particles(),
        steps,
        wall_seconds,
        particle_steps_per_second: sim.particles() as f64 * steps as f64 / wall_seconds.max(1e-9),
        stage_seconds: sim.timers,
        threads: rayon::current_num_threads(),
        derived,
        errors,
        ppe: PpeSummary {
            mean_iterations: totals.mean_iterations(),
            max_iterations: totals.max_iterations,
            lu_fallbacks: totals.fallbacks,
            bicgstab_solves: totals.steps - totals.lu_solves,
            lu_solves: totals.lu_solves,
            lu_factorisations: sim.ppe_factorisations(),
            max_relative_residual: totals.max_residual,
            absolute_floor_stops: totals.floor_stops,
            matrix_nonzeros: sim.ppe_nonzeros(),
        },
        neighbour_pairs_per_particle: sim.neighbour_pairs() as f64 / sim.particles() as f64,
        steady: steady.map(|(summary, _)| summary),
        drop: drop_summary,
        jet: jet_summary,
        version: env!("CARGO_PKG_VERSION"),
        case: case.source.clone(),
    };
    io::write_json(&summary_path, &summary)?;
    if !options.quiet {
        report_end(&summary, &options.out_dir);
    }
    Ok(summary)
}

/// Writes a `.vtu` snapshot when one is due (or `force`d and not yet written at this time).
fn snapshot_due(
    snapshots: &mut Option<crate::app::vtk::Series>,
    next_snapshot: &mut f64,
    case: &Case,
    sim: &mut Simulation,
    force: bool,
    pngs: Option<&Path>,
) -> Result<()> {
    let tolerance = 1e-9 * case.end_time;
    if let Some(series) = snapshots.as_mut() {
        let written = series.last_time() == Some(sim.state.time);
        if !written && (force || sim.state.time >= *next_snapshot - tolerance) {
            let t0 = Instant::now();
            series.write(sim)?;
            if let Some(dir) = pngs {
                // Drops in t* = tU/W, jets in seconds.
                let t = sim.state.time;
                let (title, name) = match case.scene.drop {
                    Some((_, w)) => {
                        let ts = t * case.scene.velocity / w;
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
                charts::free_surface_snapshot(&dir.join("snapshots"), sim, &title, &name)?;
            }
            sim.timers.add(Stage::Output, t0.elapsed().as_secs_f64());
            while *next_snapshot <= sim.state.time + tolerance {
                *next_snapshot += case.snapshot_interval;
            }
        }
    }
    Ok(())
}

/// The free-surface probes of a run: a drop's shape or a jet's buckling, recorded with every
/// series row and written beside `series.csv`.
struct Probes {
    drop: Option<drop::DropProbe>,
    jet: Option<jet::JetProbe>,
}

impl Probes {
    fn for_case(case: &Case) -> Self {
        Self {
            drop: case
                .scene
                .drop
                .map(|(_, w)| drop::DropProbe::new(w, case.scene.velocity)),
            jet: case.scene.jet.map(|(d, _)| jet::JetProbe::new(d)),
        }
    }

    /// A resumed run's rows up to time `t`.
    fn restore(&mut self, dir: &Path, t: f64) -> Result<()> {
        match self.drop.as_mut() {
            Some(d) => d.restore(dir, t),
            None => Ok(()),
        }
    }

    fn record(&mut self, sim: &Simulation) {
        if let Some(d) = self.drop.as_mut() {
            d.record(sim);
        }
        if let Some(j) = self.jet.as_mut() {
            j.record(sim);
        }
    }

    /// `drop.csv` / `jet.csv`, atomically.
    fn write(&self, dir: &Path) -> Result<()> {
        if let Some(d) = self.drop.as_ref() {
            io::write_atomic(&dir.join("drop.csv"), d.csv().as_bytes())?;
        }
        if let Some(j) = self.jet.as_ref() {
            io::write_atomic(&dir.join("jet.csv"), j.csv().as_bytes())?;
        }
        Ok(())
    }

    fn charts(&self, dir: &Path) -> Result<()> {
        if let Some(d) = self.drop.as_ref() {
            d.charts(dir)?;
        }
        if let Some(j) = self.jet.as_ref() {
            j.charts(dir)?;
        }
        Ok(())
    }
}

/// PPE statistics over a window of steps.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
struct PpeWindow {
    steps: u64,
    iterations: u64,
    max_iterations: usize,
    max_residual: f64,
    fallbacks: u64,
    floor_stops: u64,
    lu_solves: u64,
}

impl PpeWindow {
    fn add(&mut self, r: &rheosph_solver::SolveReport) {
        self.steps += 1;
        self.iterations += r.iterations as u64;
        self.max_iterations = self.max_iterations.max(r.iterations);
        self.max_residual = self.max_residual.max(r.relative_residual);
        self.floor_stops += r.on_absolute_floor as u64;
        self.lu_solves += (r.method == rheosph_solver::Method::SparseLu) as u64;
        self.fallbacks += r.fell_back as u64;
    }

    fn mean_iterations(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            self.iterations as f64 / self.steps as f64
        }
    }
}

/// Appends a series row for the current state and resets the PPE window.
fn record(
    sim: &mut Simulation,
    reference: Option<&mut Reference>,
    case: &Case,
    body: Option<&Body>,
    window: &mut PpeWindow,
    dt: f64,
    rows: &mut Vec<SeriesRow>,
) {
    let t0 = Instant::now();
    let s = &sim.state;
    let height = sim.domain.max.y - sim.domain.min.y;
    let stats = diagnostics::field_stats(
        &s.velocity,
        &s.conformation,
        sim.fluid.density,
        sim.particle_volume(),
    );
    let (u_centre_exact, l2_error) = match reference {
        Some(r) => (
            r.characteristic_velocity(s.time),
            r.l2_error(&s.position, &s.velocity, s.time),
        ),
        None => (f64::NAN, f64::NAN),
    };
    let u_mean = bulk_velocity(sim);
    let k = match body {
        Some(b) => {
            let f = crate::analysis::forces::on_cylinder(sim, &b.circle, b.samples);
            let scale = 1.0 / (sim.fluid.viscosity * u_mean);
            [
                f.total().x * scale,
                f.pressure[0] * scale,
                f.solvent[0] * scale,
                f.polymer[0] * scale,
            ]
        }
        None => [f64::NAN; 4],
    };
    let s = &sim.state;
    rows.push(SeriesRow {
        t: s.time,
        dt,
        step: s.steps,
        u_centre: reference::measured_velocity(
            case.scene.kind,
            &s.position,
            &s.velocity,
            case.scene.length,
            height,
            sim.spacing,
        ),
        u_centre_exact,
        l2_error,
        ppe_iterations: window.mean_iterations(),
        ppe_residual: window.max_residual,
        ppe_fallbacks: window.fallbacks as u32,
        kinetic_energy: stats.kinetic_energy,
        max_speed: stats.max_speed,
        max_trace_a: stats.max_trace,
        min_det_a: stats.min_det,
        u_mean,
        drag_k: k[0],
        k_pressure: k[1],
        k_solvent: k[2],
        k_polymer: k[3],
    });
    *window = PpeWindow::default();
    sim.timers
        .add(Stage::Diagnostics, t0.elapsed().as_secs_f64());
}

/// The largest step towards the end time: the remaining time, except that a remainder
/// between one and two stable steps is halved, so the last step is never a sliver. (The
/// projection pressure carries an O(1/δt) part from the divergence left by the previous
/// step; a tiny last step would make the final pressure, and the drag, spike.)
fn step_limit(sim: &Simulation, remaining: f64, last_dt: f64) -> f64 {
    if last_dt > 0.0 && remaining < 3.0 * last_dt {
        let stable = sim.stable_dt();
        if remaining > stable && remaining < 2.0 * stable {
            return 0.5 * remaining;
        }
    }
    remaining
}

/// The bulk velocity ⟨u⟩ = Q/H = Σ u_x V/(L H) (see [`SeriesRow::u_mean`]).
fn bulk_velocity(sim: &Simulation) -> f64 {
    let s = &sim.state;
    let sum = diagnostics::blocked_sum(s.velocity.len(), |i| s.velocity[i].x);
    let extent = sim.domain.max - sim.domain.min;
    sum * sim.particle_volume() / (extent.x * extent.y)
}

/// A solid cylinder in the scene: where forces are integrated and profiles taken.
struct Body {
    circle: Circle,
    /// Surface points of the force integral: about two per particle spacing of arc.
    samples: usize,
    centreline: Centreline,
}

impl Body {
    fn for_case(case: &Case) -> Option<Self> {
        let (centre, radius) = case.scene.cylinder?;
        let arc = 2.0 * std::f64::consts::PI * radius / case.scene.spacing();
        Some(Self {
            circle: Circle {
                centre: Vec2::new(centre[0], centre[1]),
                radius,
            },
            samples: ((2.0 * arc).ceil() as usize).max(64),
            centreline: Centreline::new(centre, radius, case.scene.length, 161),
        })
    }
}

/// `centreline.csv`: s (0 at the cylinder's downstream edge), u/⟨u⟩, τ_xx/(η_s⟨u⟩/R), det A,
/// time-averaged over the steady window.
fn centreline_csv(
    line: &Centreline,
    avg: &Averages,
    summary: &SteadySummary,
    eta_s: f64,
    radius: f64,
) -> String {
    let profile = avg.profile();
    let u = summary.u_mean;
    let tau_scale = eta_s * u / radius;
    let mut out = String::from("s,u_over_umean,tau_xx_scaled,det_a\n");
    for k in 0..line.s.len() {
        out.push_str(&format!(
            "{:.6e},{:.8e},{:.8e},{:.8e}\n",
            line.s[k],
            profile.u[k] / u,
            profile.tau_xx[k] / tau_scale,
            profile.det_a[k]
        ));
    }
    out
}

fn progress_bar(quiet: bool, end_time: f64) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40.cyan/blue} {percent:>3}% {msg} of {prefix} [{elapsed_precise}, ETA {eta}]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_prefix(format!("{end_time}"));
    bar
}

fn report_start(case: &Case, d: &Derived) {
    let f = &case.fluid;
    eprintln!(
        "rheosph {}: case `{}`",
        env!("CARGO_PKG_VERSION"),
        case.name
    );
    eprintln!(
        "  model {}  Re = {:.4}  Wi = {:.4}  El = {:.4}  beta = {}  alpha_V = {}",
        f.model.name(),
        d.reynolds,
        d.weissenberg,
        d.elasticity,
        d.beta,
        case.scheme.evss_alpha
    );
    eprintln!(
        "  {} particles (~{:.0} MB), dr = {:.4e}, h = {:.4e}; U = {:.4e}; dt limits: viscous {:.3e}, advective {:.3e}, elastic {:.3e}; ~{:.0} steps",
        d.particles, d.estimated_memory_bytes / 1e6, d.particle_spacing, d.smoothing_length, d.velocity_scale, d.dt_viscous, d.dt_advective_at_u, d.dt_elastic, d.estimated_steps
    );
    eprintln!(
        "  frame {:?}, conformation {:?}, shifting {}, {} threads",
        case.scheme.frame,
        case.scheme.conformation,
        case.scheme.shifting,
        rayon::current_num_threads()
    );
}

fn report_end(s: &Summary, dir: &Path) {
    match s.outcome {
        Outcome::Finished => {
            eprintln!("finished at t = {:.4} after {} steps", s.t_reached, s.steps)
        }
        Outcome::BrokeDown => eprintln!(
            "broke down at t = {:.4} after {} steps: {}",
            s.t_reached,
            s.steps,
            s.reason.as_deref().unwrap_or("?")
        ),
    }
    if let (Some(mean), Some(last)) = (s.errors.l2_time_mean, s.errors.l2_final) {
        eprintln!(
            "  velocity L2 error against {}: time mean {mean:.3e}, final {last:.3e}",
            s.errors.reference.unwrap_or("?")
        );
    }
    eprintln!(
        "  {:.0} particle-steps/s ({:.1} s wall, PPE {:.1} iterations/step)",
        s.particle_steps_per_second, s.wall_seconds, s.ppe.mean_iterations
    );
    eprintln!("  output in {}", dir.display());
}
