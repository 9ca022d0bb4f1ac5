//! `rheosph._native`: the compiled half of the Python package. Thin: every function parses a
//! case with the same code and error lines as the command line, runs with the same run loop,
//! and hands arrays over as little-endian f64 bytes that `rheosph/__init__.py` views with
//! numpy. The Python API itself (cases as files or dicts, results, studies) is in Python.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rheosph::analysis::grid;
use rheosph::app::plot::FigureFormat;
use rheosph::app::run::run_loop::{Run, Start};
use rheosph::app::run::{self as runs, checkpoint, ProgressHook, RunOptions, CASE_FILE};
use rheosph::engine::step::Simulation;
use rheosph::setup::case::{self, Case};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

pyo3::create_exception!(
    _native,
    CaseError,
    PyValueError,
    "A case that does not validate; the message is the command line's one line (file, field, why)."
);

fn case_error(e: case::CaseError) -> PyErr {
    CaseError::new_err(e.to_string())
}

fn runtime_error(e: anyhow::Error) -> PyErr {
    PyRuntimeError::new_err(format!("{e:#}"))
}

/// An array as the bytes of little-endian f64.
fn f64_bytes<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    PyBytes::new(py, &bytes)
}

/// TOML text of a case given as JSON (a Python dict dumped by `json.dumps`).
#[pyfunction]
fn toml_from_json(json: &str) -> PyResult<String> {
    let table: toml::Table =
        serde_json::from_str(json).map_err(|e| CaseError::new_err(format!("case dict: {e}")))?;
    toml::to_string(&table).map_err(|e| CaseError::new_err(format!("case dict: {e}")))
}

/// Validates case text with overrides; returns the derived numbers as JSON.
#[pyfunction]
fn check(text: &str, file: &str, name: &str, overrides: Vec<String>) -> PyResult<String> {
    let case = case::parse(text, file, name, &overrides).map_err(case_error)?;
    serde_json::to_string(&case.derived()).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// Runs a case into `out`; returns 0 (finished) or 3 (broke down), as the command line does.
/// `progress(t, end_time)` is called at every series row; an exception it raises is re-raised
/// when the run has ended (the run itself is not interrupted).
#[pyfunction]
#[pyo3(signature = (text, file, name, overrides, out, progress=None, figure_format=None, snapshots=false, from_dir=None))]
#[allow(clippy::too_many_arguments)] // one Python call's keyword arguments
fn run(
    py: Python<'_>,
    text: &str,
    file: &str,
    name: &str,
    overrides: Vec<String>,
    out: PathBuf,
    progress: Option<Py<PyAny>>,
    figure_format: Option<&str>,
    snapshots: bool,
    from_dir: Option<PathBuf>,
) -> PyResult<u8> {
    let case = case::parse(text, file, name, &overrides).map_err(case_error)?;
    let charts = match figure_format {
        None => None,
        Some("png") => Some(FigureFormat::Png),
        Some("svg") => Some(FigureFormat::Svg),
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "figure_format: expected \"png\", \"svg\" or None, got {other:?}"
            )))
        }
    };
    let failure: Arc<Mutex<Option<PyErr>>> = Arc::default();
    let hook = progress.map(|callback| {
        let failure = Arc::clone(&failure);
        ProgressHook(Arc::new(move |t: f64, end: f64| {
            Python::attach(|py| {
                if let Err(e) = callback.call1(py, (t, end)) {
                    failure.lock().unwrap().get_or_insert(e);
                }
            })
        }))
    });
    let options = RunOptions {
        out_dir: out,
        quiet: true,
        charts,
        snapshots,
        progress: hook,
    };
    let summary = py
        .detach(|| {
            runs::on_pool_worker(|| match &from_dir {
                Some(dir) => runs::continue_from(&case, &options, dir),
                None => runs::run(&case, &options),
            })
        })
        .map_err(runtime_error)?;
    if let Some(e) = failure.lock().unwrap().take() {
        return Err(e);
    }
    Ok(match summary.outcome {
        runs::Outcome::Finished => 0,
        runs::Outcome::BrokeDown => 3,
    })
}

/// The final state of a finished run (its `final_state.bin`, with its `case.toml`).
fn final_state(dir: &Path) -> PyResult<Simulation> {
    let path = dir.join(checkpoint::FINAL_STATE_FILE);
    if !path.exists() {
        return Err(PyRuntimeError::new_err(format!(
            "{} has no {} (finished runs write one; jets and runs that broke down do not)",
            dir.display(),
            checkpoint::FINAL_STATE_FILE
        )));
    }
    let case: Case = case::load(&dir.join(CASE_FILE), &[]).map_err(case_error)?;
    let mut sim = Simulation::new(case.setup());
    checkpoint::read(&path, &mut sim)
        .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", path.display())))?;
    Ok(sim)
}

/// The particles of a finished run: (name, bytes) pairs for x, y and the grid fields (the
/// vorticity is zero: it needs a step's velocity gradient, which the state does not keep).
#[pyfunction]
fn particles(py: Python<'_>, run_dir: PathBuf) -> PyResult<Vec<(String, Py<PyBytes>)>> {
    let sim = final_state(&run_dir)?;
    let x: Vec<f64> = sim.state.position.iter().map(|p| p.x).collect();
    let y: Vec<f64> = sim.state.position.iter().map(|p| p.y).collect();
    let mut fields = vec![("x", x), ("y", y)];
    fields.extend(grid::particle_fields(&sim));
    Ok(fields
        .iter()
        .map(|(n, v)| (n.to_string(), f64_bytes(py, v).unbind()))
        .collect())
}

/// A finished run's final state on a grid (as in the `.vti` snapshots): (origin, spacing,
/// dims, fields), fields as (name, bytes) with x fastest and NaN outside the fluid, plus
/// `fluid` (1.0 inside).
#[pyfunction]
#[pyo3(signature = (run_dir, spacing=None))]
#[allow(clippy::type_complexity)] // the tuple Python receives
fn grid_fields(
    py: Python<'_>,
    run_dir: PathBuf,
    spacing: Option<f64>,
) -> PyResult<(
    (f64, f64),
    (f64, f64),
    (usize, usize),
    Vec<(String, Py<PyBytes>)>,
)> {
    let sim = final_state(&run_dir)?;
    let spacing = spacing.unwrap_or(sim.spacing);
    if spacing.is_nan() || spacing <= 0.0 {
        return Err(PyValueError::new_err(format!(
            "spacing: must be positive, got {spacing}"
        )));
    }
    let g = py.detach(|| grid::interpolate(&sim, spacing));
    let fluid: Vec<f64> = g.fluid.iter().map(|&f| f64::from(f)).collect();
    let mut fields: Vec<(String, Py<PyBytes>)> = g
        .fields
        .iter()
        .map(|(n, v)| (n.to_string(), f64_bytes(py, v).unbind()))
        .collect();
    fields.push(("fluid".into(), f64_bytes(py, &fluid).unbind()));
    let s = g.spec;
    Ok((
        (s.origin.x, s.origin.y),
        (s.spacing.x, s.spacing.y),
        (s.dims[0], s.dims[1]),
        fields,
    ))
}

fn over() -> PyErr {
    PyRuntimeError::new_err("the simulation's outputs are written; it is over")
}

/// A live simulation: the command line's run loop (`Run`), stepped from Python one step at
/// a time. Every step and every output is the command line's own, so a simulation stepped
/// to the end writes the same files, bit for bit, as `rheosph run`.
#[pyclass(unsendable, module = "rheosph._native")]
struct LiveRun {
    /// None once the outputs have been written.
    run: Option<Run>,
    /// The steps run on a worker of this pool, as the command line's do
    /// (`runs::on_pool_worker`): a parallel loop started from a worker does not sleep on a
    /// lock while the pool works.
    pool: rayon::ThreadPool,
}

impl LiveRun {
    fn run(&mut self) -> PyResult<&mut Run> {
        self.run.as_mut().ok_or_else(over)
    }

    fn with_pool(run: Run) -> PyResult<Self> {
        let pool = rayon::ThreadPoolBuilder::new()
            .build()
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(Self {
            run: Some(run),
            pool,
        })
    }

    /// One step on the pool, without the GIL.
    fn step_once(&mut self, py: Python<'_>) -> PyResult<bool> {
        let pool = &self.pool;
        let run = self.run.as_mut().ok_or_else(over)?;
        py.detach(|| pool.install(|| run.step()))
            .map_err(runtime_error)
    }

    fn options(out: PathBuf, snapshots: bool) -> RunOptions {
        RunOptions {
            out_dir: out,
            quiet: true,
            charts: Some(FigureFormat::Png),
            snapshots,
            progress: None,
        }
    }
}

#[pymethods]
impl LiveRun {
    #[new]
    #[pyo3(signature = (text, file, name, overrides, out, snapshots=false))]
    fn new(
        text: &str,
        file: &str,
        name: &str,
        overrides: Vec<String>,
        out: PathBuf,
        snapshots: bool,
    ) -> PyResult<Self> {
        let case = case::parse(text, file, name, &overrides).map_err(case_error)?;
        let options = Self::options(out, snapshots);
        let run = Run::new(&case, &options, Start::Fresh).map_err(runtime_error)?;
        Self::with_pool(run)
    }

    /// The simulation checkpointed in `out` (`checkpoint.bin` and its `case.toml`).
    #[staticmethod]
    #[pyo3(signature = (out, snapshots=false))]
    fn resume(out: PathBuf, snapshots: bool) -> PyResult<Self> {
        let options = Self::options(out, snapshots);
        let (case, start) = runs::resumed(&options).map_err(runtime_error)?;
        let run = Run::new(&case, &options, start).map_err(runtime_error)?;
        Self::with_pool(run)
    }

    /// One step; false when the run is at its end time or has broken down.
    fn step(&mut self, py: Python<'_>) -> PyResult<bool> {
        self.step_once(py)
    }

    /// Steps until the time reaches `t` (whole steps of the run's own size, so the last one
    /// may pass it), the end time or a breakdown; Ctrl-C stops between two steps.
    /// `progress(t, target)` is called after every step. False once the run is over.
    #[pyo3(signature = (t, progress=None))]
    fn advance(&mut self, py: Python<'_>, t: f64, progress: Option<Py<PyAny>>) -> PyResult<bool> {
        while self.run()?.sim.state.time < t {
            if !self.step_once(py)? {
                return Ok(false);
            }
            py.check_signals()?;
            if let Some(callback) = &progress {
                callback.call1(py, (self.run()?.sim.state.time, t))?;
            }
        }
        Ok(true)
    }

    #[getter]
    fn t(&mut self) -> PyResult<f64> {
        Ok(self.run()?.sim.state.time)
    }

    #[getter]
    fn dt(&mut self) -> PyResult<f64> {
        Ok(self.run()?.last_dt())
    }

    #[getter]
    fn steps(&mut self) -> PyResult<u64> {
        Ok(self.run()?.sim.state.steps)
    }

    #[getter]
    fn end_time(&mut self) -> PyResult<f64> {
        Ok(self.run()?.end_time())
    }

    #[getter]
    fn breakdown(&mut self) -> PyResult<Option<String>> {
        Ok(self.run()?.breakdown().map(str::to_string))
    }

    /// The particles now: (name, little-endian f64 bytes) of x, y, the fields of the
    /// snapshots and the conformation's components.
    fn particles(&mut self, py: Python<'_>) -> PyResult<Vec<(String, Py<PyBytes>)>> {
        let sim = &self.run()?.sim;
        let s = &sim.state;
        let mut fields: Vec<(&str, Vec<f64>)> = vec![
            ("x", s.position.iter().map(|p| p.x).collect()),
            ("y", s.position.iter().map(|p| p.y).collect()),
        ];
        fields.extend(grid::particle_fields(sim));
        if !s.conformation.is_empty() {
            fields.push(("A_xx", s.conformation.iter().map(|a| a.xx).collect()));
            fields.push(("A_xy", s.conformation.iter().map(|a| a.xy).collect()));
            fields.push(("A_yy", s.conformation.iter().map(|a| a.yy).collect()));
        }
        if let Some(surface) = sim.surface() {
            let flag = |b: &[bool]| b.iter().map(|&b| f64::from(u8::from(b))).collect();
            fields.push(("free_surface", flag(&surface.on_surface)));
            fields.push(("near_surface", flag(&surface.near_surface)));
        }
        Ok(fields
            .iter()
            .map(|(n, v)| (n.to_string(), f64_bytes(py, v).unbind()))
            .collect())
    }

    /// Sets the body force (per unit mass) for the steps that follow.
    fn set_body_force(&mut self, fx: f64, fy: f64) -> PyResult<()> {
        if !(fx.is_finite() && fy.is_finite()) {
            return Err(CaseError::new_err(format!(
                "scene.body_force: must be finite, got [{fx}, {fy}]"
            )));
        }
        let run = self.run()?;
        run.sim.state.body_force = rheosph::engine::math::Vec2::new(fx, fy);
        Ok(())
    }

    /// Sets prescribed disc `k`'s velocity and spin for the steps that follow.
    fn set_disc_motion(&mut self, k: usize, vx: f64, vy: f64, spin: f64) -> PyResult<()> {
        let run = self.run()?;
        run.sim
            .set_disc_motion(k, rheosph::engine::math::Vec2::new(vx, vy), spin)
            .map_err(|e| CaseError::new_err(format!("scene.discs[{k}]: {e}")))
    }

    /// Writes series.csv, the probes' files, profile.csv and state.vtu of the state now
    /// into `dir`; the run goes on.
    fn write_outputs(&mut self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        let run = self.run()?;
        py.detach(|| run.write_outputs(&dir)).map_err(runtime_error)
    }

    /// Writes `checkpoint.bin` now; `LiveRun.resume(out)` continues from it.
    fn checkpoint(&mut self) -> PyResult<()> {
        self.run()?.checkpoint().map_err(runtime_error)
    }

    /// Writes the run's final files (series, profile, charts, summary.json) and ends it:
    /// 0 if it reached its end time, 3 if it broke down, 4 if it stopped before either.
    fn finish(&mut self) -> PyResult<u8> {
        let run = self
            .run
            .take()
            .ok_or_else(|| PyRuntimeError::new_err("already finished"))?;
        let over = run.breakdown().is_some() || run.sim.state.time >= run.end_time();
        let summary = run.finish().map_err(runtime_error)?;
        Ok(match (summary.outcome, over) {
            (runs::Outcome::BrokeDown, _) => 3,
            (_, true) => 0,
            (_, false) => 4,
        })
    }
}

/// Runs the command line in this process (`argv[0]` is the program name): studies,
/// rheometry, anything `rheosph` does. Returns its exit code; bad arguments raise ValueError
/// with clap's message.
#[pyfunction]
fn cli(py: Python<'_>, argv: Vec<String>) -> PyResult<u8> {
    use clap::Parser;
    let parsed = rheosph::app::cli::Cli::try_parse_from(&argv)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(py.detach(|| rheosph::app::cli::exit_code(parsed)))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CaseError", m.py().get_type::<CaseError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(toml_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(particles, m)?)?;
    m.add_function(wrap_pyfunction!(grid_fields, m)?)?;
    m.add_function(wrap_pyfunction!(cli, m)?)?;
    m.add_class::<LiveRun>()?;
    Ok(())
}
