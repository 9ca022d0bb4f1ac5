//! A run: the time loop around the [`Simulation`](crate::engine::step::Simulation), the
//! analytic comparison, and the run directory (`series.csv`, `summary.json`, probe files,
//! PNG charts, snapshots, checkpoints).
//!
//! [`run_loop`] is the loop, [`cadence`] says when each output is due, [`checkpoint`] owns
//! the checkpoint format, [`summary`] builds `summary.json`, [`probes`] are what a scene
//! records beside the series.

pub mod cadence;
pub mod charts;
pub mod checkpoint;
pub mod dimension;
pub mod errors;
pub mod probes;
pub mod run_loop;
pub mod series;
pub mod summary;
pub mod transfer;

pub use errors::{Errors, Peak};
pub use probes::drop::DropSummary;
pub use probes::steady::{Averages, SteadySummary};
pub use summary::{Outcome, PpeSummary, Summary};

use crate::app::io;
use crate::setup::case::Case;
use anyhow::{Context, Result};
use checkpoint::LoopState;
use run_loop::{Resumed, Run, Start};
use std::path::{Path, PathBuf};

/// Options of a run that are not physics.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// No progress bar, no start-up report.
    pub quiet: bool,
    /// The charts' format; None: no charts (studies draw their own).
    pub charts: Option<crate::app::plot::FigureFormat>,
    /// Write `.vtu` snapshots every `run.snapshot_interval`.
    pub snapshots: bool,
    /// Told the time at every series row (a caller's progress display, e.g. Python's).
    pub progress: Option<ProgressHook>,
}

/// A function called with (t, end time) as a run advances.
#[derive(Clone)]
pub struct ProgressHook(pub std::sync::Arc<dyn Fn(f64, f64) + Send + Sync>);

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressHook")
    }
}

/// The case as run (after `--set`), for `--resume`.
pub const CASE_FILE: &str = "case.toml";
pub use checkpoint::CHECKPOINT_FILE;
/// The error that stopped a run (`rheosph run --out DIR` that failed: not a breakdown, which
/// is a result and writes `summary.json`), one line; a new run in the directory removes it.
pub const ERROR_FILE: &str = "error.txt";

/// Records in `dir` the error that stopped its run (best effort: the error itself is the
/// report, and the directory may be what failed).
pub fn record_error(dir: &Path, error: &anyhow::Error) {
    let line = format!("{error:#}").replace('\n', " ");
    let _ = crate::app::io::write_atomic(&dir.join(ERROR_FILE), (line + "\n").as_bytes());
}

/// Runs `f` on a thread of a new rayon pool (or here, on a thread of one already): every
/// parallel loop of a step then starts from a worker, instead of handing its job to the pool
/// and sleeping on a lock until it is done (measured at 900 particles: 455k → 538k
/// particle-steps/s, system time 5.8 → 0.9 s in a 10 s run). The command line and the Python
/// package run through it.
pub fn on_pool_worker<T: Send>(f: impl FnOnce() -> Result<T> + Send) -> Result<T> {
    if rayon::current_thread_index().is_some() {
        return f();
    }
    rayon::ThreadPoolBuilder::new().build()?.install(f)
}

/// Runs a case to its end time or breakdown and writes the run directory.
pub fn run(case: &Case, options: &RunOptions) -> Result<Summary> {
    match case.scene.dimension() {
        3 => run_from::<3>(case, options, Start::Fresh),
        _ => run_from::<2>(case, options, Start::Fresh),
    }
}

/// Runs `case` from the final state of the run in `from` (its `final_state.bin`): positions,
/// velocities, pressure and conformation carried over, this case's parameters (e.g. a new
/// λ for a Wi ramp) and a clock from t = 0. The scenes must match particle for particle
/// (count, spacing, frame, viscoelastic or not); a constant body force is this case's, a
/// mean-flow controller keeps the force it had reached. When the particle spacing differs
/// (`from` ran at another `scene.resolution`), the state is interpolated onto this case's
/// particles instead ([`transfer`]).
pub fn continue_from(case: &Case, options: &RunOptions, from: &Path) -> Result<Summary> {
    anyhow::ensure!(
        case.scene.dimension() == 2,
        "`run --from` continues 2D runs only (the interpolation onto another case's particles is 2D)"
    );
    let path = from.join(checkpoint::FINAL_STATE_FILE);
    anyhow::ensure!(
        path.exists(),
        "{} has no {} (a run that finished writes one)",
        from.display(),
        checkpoint::FINAL_STATE_FILE
    );
    let mut sim = crate::engine::step::Simulation::new(case.setup().map_err(anyhow::Error::msg)?);
    let stored = stored_case(from)?;
    if stored.scene.spacing().to_bits() == case.scene.spacing().to_bits() {
        checkpoint::read(&path, &mut sim)
            .map_err(|e| anyhow::anyhow!("continuing from {}: {e}", path.display()))?;
    } else {
        let mut source =
            crate::engine::step::Simulation::new(stored.setup().map_err(anyhow::Error::msg)?);
        checkpoint::read(&path, &mut source)
            .map_err(|e| anyhow::anyhow!("reading {}: {e}", path.display()))?;
        transfer::transfer(&source, &mut sim)
            .with_context(|| format!("interpolating the state of {}", from.display()))?;
    }
    sim.state.time = 0.0;
    sim.state.steps = 0;
    if !case.scene.holds_mean_flow() {
        sim.state.body_force = case.scene.body_force();
    }
    run_from(case, options, Start::Continued(Box::new(sim)))
}

/// The case the finished run in `dir` ran (its `case.toml`).
fn stored_case(dir: &Path) -> Result<Case> {
    let text = std::fs::read_to_string(dir.join(CASE_FILE))
        .with_context(|| format!("reading {}", dir.join(CASE_FILE).display()))?;
    Ok(crate::setup::case::parse(&text, CASE_FILE, "stored", &[])?)
}

/// Continues the run in `options.out_dir` from its last checkpoint (`checkpoint.bin`, with the
/// case as run in `case.toml`). The continued run writes what the uninterrupted one would
/// have: the series is cut back to the checkpoint and extended bit for bit.
pub fn resume(options: &RunOptions) -> Result<Summary> {
    if checkpointed_dimension(options)? == 3 {
        let (case, start) = resumed_in::<3>(options)?;
        return run_from(&case, options, start);
    }
    let (case, start) = resumed(options)?;
    run_from(&case, options, start)
}

/// The case and the loop state of the run in `options.out_dir`, from its last checkpoint.
fn checkpointed_case(options: &RunOptions) -> Result<(Case, (LoopState, Vec<u8>))> {
    let dir = &options.out_dir;
    let (state, bytes) = checkpoint::load(dir)?;
    let text = std::fs::read_to_string(dir.join(CASE_FILE))
        .with_context(|| format!("reading {}", dir.join(CASE_FILE).display()))?;
    let case = crate::setup::case::parse(&text, CASE_FILE, &state.case_name, &[])?;
    Ok((case, (state, bytes)))
}

/// The case and the start of the 2D run in `options.out_dir`, from its last checkpoint.
pub fn resumed(options: &RunOptions) -> Result<(Case, Start)> {
    resumed_in::<2>(options)
}

/// The space dimensions of the run checkpointed in `options.out_dir` (its case's).
pub fn checkpointed_dimension(options: &RunOptions) -> Result<usize> {
    Ok(checkpointed_case(options)?.0.scene.dimension())
}

/// The case and the start of the run in `options.out_dir`, from its last checkpoint.
pub fn resumed_in<const D: usize>(options: &RunOptions) -> Result<(Case, Start<D>)>
where
    crate::engine::dimension::Dim<D>: dimension::RunDimension<D>,
{
    let dir = &options.out_dir;
    let (case, (state, bytes)) = checkpointed_case(options)?;
    anyhow::ensure!(
        case.scene.jet_shape().is_none(),
        "a jet cannot be resumed: its particle count grows and checkpoints do not record the inflow buffer"
    );
    let mut sim =
        <crate::engine::dimension::Dim<D> as dimension::RunDimension<D>>::simulation(&case)?;
    checkpoint::restore(&mut sim, &bytes)
        .with_context(|| format!("restoring {CHECKPOINT_FILE}"))?;
    // By step, which is exact: the times in the file are rounded to 9 digits, and a row at the
    // checkpoint's own time can read back a hair later than it.
    let rows = io::read_series(&dir.join("series.csv"))?
        .into_iter()
        .filter(|r| r.step <= sim.state.steps)
        .collect();
    Ok((case, Start::Resumed(Box::new(Resumed { sim, state, rows }))))
}

fn run_from<const D: usize>(case: &Case, options: &RunOptions, start: Start<D>) -> Result<Summary>
where
    crate::engine::dimension::Dim<D>: dimension::RunDimension<D>,
{
    if !options.quiet {
        summary::report_start(case, &case.derived());
    }
    let mut run = Run::<D>::new(case, options, start)?;
    run.time_loop()?;
    run.finish()
}
