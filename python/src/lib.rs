//! `rheosph._native`: the compiled half of the Python package. Thin: every function parses a
//! case with the same code and error lines as the command line, runs with the same run loop,
//! and hands arrays over as little-endian f64 bytes that `rheosph/__init__.py` views with
//! numpy. The Python API itself (cases as files or dicts, results, studies) is in Python.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rheosph::analysis::grid;
use rheosph::app::plot::FigureFormat;
use rheosph::app::run::dimension::RunDimension;
use rheosph::app::run::run_loop::{Run, Start};
use rheosph::app::run::{self as runs, checkpoint, ProgressHook, RunOptions, CASE_FILE};
use rheosph::engine::dimension::{Dim, SymTensor};
use rheosph::engine::step::{Simulation, StepDimension};
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

/// The case of the finished run in `dir` (its `case.toml`) and its `final_state.bin`.
fn finished_case(dir: &Path) -> PyResult<(Case, PathBuf)> {
    let path = dir.join(checkpoint::FINAL_STATE_FILE);
    if !path.exists() {
        return Err(PyRuntimeError::new_err(format!(
            "{} has no {} (finished runs write one; jets and runs that broke down do not)",
            dir.display(),
            checkpoint::FINAL_STATE_FILE
        )));
    }
    let case: Case = case::load(&dir.join(CASE_FILE), &[]).map_err(case_error)?;
    Ok((case, path))
}

/// The final state of a finished run in D dimensions.
fn final_state_in<const D: usize>(dir: &Path) -> PyResult<Simulation<D>>
where
    Dim<D>: RunDimension<D>,
{
    let (case, path) = finished_case(dir)?;
    let mut sim = Dim::<D>::simulation(&case).map_err(runtime_error)?;
    checkpoint::read(&path, &mut sim)
        .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", path.display())))?;
    Ok(sim)
}

/// The final state of a finished 2D run.
fn final_state(dir: &Path) -> PyResult<Simulation> {
    final_state_in::<2>(dir)
}

/// (name, values) of the particles of `sim` in D dimensions: the coordinates x, y (z), the
/// velocity u, v (w), the pressure, the polymer stress τ_ab (a ≤ b) and, viscoelastic, the
/// conformation A_ab with tr A and det A.
fn particle_arrays<const D: usize>(sim: &Simulation<D>) -> Vec<(String, Vec<f64>)>
where
    Dim<D>: StepDimension<D>,
{
    const AXES: [&str; 3] = ["x", "y", "z"];
    const VELOCITY: [&str; 3] = ["u", "v", "w"];
    let s = &sim.state;
    let mut fields: Vec<(String, Vec<f64>)> = Vec::new();
    for a in 0..D {
        fields.push((AXES[a].into(), s.position.iter().map(|p| p[a]).collect()));
    }
    for a in 0..D {
        fields.push((
            VELOCITY[a].into(),
            s.velocity.iter().map(|u| u[a]).collect(),
        ));
    }
    fields.push(("pressure".into(), s.pressure.clone()));
    let tensors = |name: &str, t: &[rheosph::engine::dimension::Sym<D>]| {
        let mut out = Vec::new();
        for (a, first) in AXES.iter().enumerate().take(D) {
            for (b, second) in AXES.iter().enumerate().take(D).skip(a) {
                let values = t.iter().map(|t| t.entry(a, b)).collect();
                out.push((format!("{name}_{first}{second}"), values));
            }
        }
        out
    };
    fields.extend(tensors("tau", &sim.polymer_stress()));
    if !s.conformation.is_empty() {
        fields.extend(tensors("A", &s.conformation));
        fields.push((
            "trace_A".into(),
            s.conformation.iter().map(|a| a.trace()).collect(),
        ));
        fields.push((
            "det_A".into(),
            s.conformation.iter().map(|a| a.det()).collect(),
        ));
    }
    fields
}

fn to_bytes(py: Python<'_>, fields: &[(String, Vec<f64>)]) -> Vec<(String, Py<PyBytes>)> {
    fields
        .iter()
        .map(|(n, v)| (n.clone(), f64_bytes(py, v).unbind()))
        .collect()
}

/// The particles of a finished run: (name, bytes) pairs. In 2D x, y and the grid fields
/// (the vorticity is zero: it needs a step's velocity gradient, which the state does not
/// keep); in 3D [`particle_arrays`].
#[pyfunction]
fn particles(py: Python<'_>, run_dir: PathBuf) -> PyResult<Vec<(String, Py<PyBytes>)>> {
    if finished_case(&run_dir)?.0.scene.dimension() == 3 {
        let sim = final_state_in::<3>(&run_dir)?;
        return Ok(to_bytes(py, &particle_arrays(&sim)));
    }
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
    if finished_case(&run_dir)?.0.scene.dimension() == 3 {
        return Err(PyRuntimeError::new_err(
            "grid fields are 2D: a 3D run's state is its particles() and its .vtu snapshots",
        ));
    }
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

/// The command line's run loop in the case's dimension.
enum AnyRun {
    Plane(Box<Run<2>>),
    Space(Box<Run<3>>),
}

/// `$body` with `$r` bound to the run of `$run` (an `AnyRun`), whichever its dimension.
macro_rules! each {
    ($run:expr, |$r:ident| $body:expr) => {
        match $run {
            AnyRun::Plane($r) => $body,
            AnyRun::Space($r) => $body,
        }
    };
}

impl AnyRun {
    fn new(case: &Case, options: &RunOptions) -> anyhow::Result<Self> {
        Ok(if case.scene.dimension() == 3 {
            AnyRun::Space(Box::new(Run::new(case, options, Start::Fresh)?))
        } else {
            AnyRun::Plane(Box::new(Run::new(case, options, Start::Fresh)?))
        })
    }

    fn resume(options: &RunOptions) -> anyhow::Result<Self> {
        Ok(if runs::checkpointed_dimension(options)? == 3 {
            let (case, start) = runs::resumed_in::<3>(options)?;
            AnyRun::Space(Box::new(Run::new(&case, options, start)?))
        } else {
            let (case, start) = runs::resumed(options)?;
            AnyRun::Plane(Box::new(Run::new(&case, options, start)?))
        })
    }

    fn time(&self) -> f64 {
        each!(self, |r| r.sim.state.time)
    }
}

/// A live simulation: the command line's run loop (`Run`), stepped from Python one step at
/// a time, in the case's dimension. Every step and every output is the command line's own,
/// so a simulation stepped to the end writes the same files, bit for bit, as `rheosph run`.
#[pyclass(unsendable, module = "rheosph._native")]
struct LiveRun {
    /// None once the outputs have been written.
    run: Option<AnyRun>,
    /// The steps run on a worker of this pool, as the command line's do
    /// (`runs::on_pool_worker`): a parallel loop started from a worker does not sleep on a
    /// lock while the pool works.
    pool: rayon::ThreadPool,
}

impl LiveRun {
    fn run(&mut self) -> PyResult<&mut AnyRun> {
        self.run.as_mut().ok_or_else(over)
    }

    fn with_pool(run: AnyRun) -> PyResult<Self> {
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
        py.detach(|| pool.install(|| each!(run, |r| r.step())))
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

/// The particles of a live 2D simulation: x, y, the grid fields, the conformation's
/// components and the free-surface flags.
fn plane_particles(sim: &Simulation) -> Vec<(String, Vec<f64>)> {
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
    fields
        .into_iter()
        .map(|(n, v)| (n.to_string(), v))
        .collect()
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
        Self::with_pool(AnyRun::new(&case, &options).map_err(runtime_error)?)
    }

    /// The simulation checkpointed in `out` (`checkpoint.bin` and its `case.toml`).
    #[staticmethod]
    #[pyo3(signature = (out, snapshots=false))]
    fn resume(out: PathBuf, snapshots: bool) -> PyResult<Self> {
        let options = Self::options(out, snapshots);
        Self::with_pool(AnyRun::resume(&options).map_err(runtime_error)?)
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
        while self.run()?.time() < t {
            if !self.step_once(py)? {
                return Ok(false);
            }
            py.check_signals()?;
            if let Some(callback) = &progress {
                callback.call1(py, (self.run()?.time(), t))?;
            }
        }
        Ok(true)
    }

    #[getter]
    fn t(&mut self) -> PyResult<f64> {
        Ok(self.run()?.time())
    }

    #[getter]
    fn dt(&mut self) -> PyResult<f64> {
        Ok(each!(self.run()?, |r| r.last_dt()))
    }

    #[getter]
    fn steps(&mut self) -> PyResult<u64> {
        Ok(each!(self.run()?, |r| r.sim.state.steps))
    }

    #[getter]
    fn end_time(&mut self) -> PyResult<f64> {
        Ok(each!(self.run()?, |r| r.end_time()))
    }

    #[getter]
    fn breakdown(&mut self) -> PyResult<Option<String>> {
        Ok(each!(self.run()?, |r| r.breakdown().map(str::to_string)))
    }

    /// The space dimensions, 2 or 3.
    #[getter]
    fn dimension(&mut self) -> PyResult<usize> {
        Ok(match self.run()? {
            AnyRun::Plane(_) => 2,
            AnyRun::Space(_) => 3,
        })
    }

    /// The particles now, (name, little-endian f64 bytes): in 2D x, y, the fields of the
    /// snapshots, the conformation's components and the free-surface flags; in 3D
    /// [`particle_arrays`].
    fn particles(&mut self, py: Python<'_>) -> PyResult<Vec<(String, Py<PyBytes>)>> {
        let fields = match self.run()? {
            AnyRun::Plane(r) => plane_particles(&r.sim),
            AnyRun::Space(r) => particle_arrays(&r.sim),
        };
        Ok(to_bytes(py, &fields))
    }

    /// Sets the body force (per unit mass) for the steps that follow; `fz` in 3D only.
    #[pyo3(signature = (fx, fy, fz=None))]
    fn set_body_force(&mut self, fx: f64, fy: f64, fz: Option<f64>) -> PyResult<()> {
        let g = [fx, fy, fz.unwrap_or(0.0)];
        if !g.iter().all(|v| v.is_finite()) {
            return Err(CaseError::new_err(format!(
                "scene.body_force: must be finite, got {g:?}"
            )));
        }
        match self.run()? {
            AnyRun::Plane(_) if fz.is_some() => Err(CaseError::new_err(
                "scene.body_force: a 2D simulation takes two components",
            )),
            AnyRun::Plane(r) => {
                r.sim.state.body_force = rheosph::engine::math::Vec2::new(fx, fy);
                Ok(())
            }
            AnyRun::Space(r) => {
                r.sim.state.body_force = rheosph::engine::dimension::Vector::<3>::from(g);
                Ok(())
            }
        }
    }

    /// Sets prescribed disc `k`'s velocity and spin for the steps that follow (2D).
    fn set_disc_motion(&mut self, k: usize, vx: f64, vy: f64, spin: f64) -> PyResult<()> {
        let AnyRun::Plane(run) = self.run()? else {
            return Err(CaseError::new_err("scene.discs: discs are 2D only"));
        };
        run.sim
            .set_disc_motion(k, rheosph::engine::math::Vec2::new(vx, vy), spin)
            .map_err(|e| CaseError::new_err(format!("scene.discs[{k}]: {e}")))
    }

    /// Writes series.csv, the probes' files, profile.csv and state.vtu of the state now
    /// into `dir`; the run goes on.
    fn write_outputs(&mut self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        let run = self.run()?;
        py.detach(|| each!(run, |r| r.write_outputs(&dir)))
            .map_err(runtime_error)
    }

    /// Writes `checkpoint.bin` now; `LiveRun.resume(out)` continues from it.
    fn checkpoint(&mut self) -> PyResult<()> {
        each!(self.run()?, |r| r.checkpoint()).map_err(runtime_error)
    }

    /// Writes the run's final files (series, profile, charts, summary.json) and ends it:
    /// 0 if it reached its end time, 3 if it broke down, 4 if it stopped before either.
    fn finish(&mut self) -> PyResult<u8> {
        let run = self
            .run
            .take()
            .ok_or_else(|| PyRuntimeError::new_err("already finished"))?;
        let over = each!(&run, |r| r.breakdown().is_some()
            || r.sim.state.time >= r.end_time());
        let summary = each!(run, |r| r.finish()).map_err(runtime_error)?;
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
