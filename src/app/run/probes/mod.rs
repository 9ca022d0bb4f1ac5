//! Run probes: what a scene records beside `series.csv` at every output time — a drop's
//! shape (`drop.csv`), a jet's buckling (`jet.csv`), a cylinder's drag, steady state and
//! wake (`centreline.csv`), a sphere's drag and steady state (3D) — each with its charts and
//! its entry in `summary.json`.
//!
//! To add a probe: a file here implementing [`Probe`], and one line in [`Probes::for_case`]
//! that decides when it applies ([`Probes::in_space`] in 3D).

pub mod cavity;
pub mod centreline;
pub mod cylinder;
pub mod disc;
pub mod drop;
pub mod jet;
pub mod meniscus;
pub mod rotation;
pub mod sphere;
pub mod steady;
pub mod tube;

use crate::app::io::SeriesRow;
use crate::app::plot::FigureFormat;
use crate::engine::dimension::Dim;
use crate::engine::step::{Simulation, StepDimension};
use crate::setup::case::Case;
use anyhow::Result;
use std::collections::BTreeMap;
use std::path::Path;

/// Something a run records at every output time.
pub trait Probe<const D: usize = 2>: Send
where
    Dim<D>: StepDimension<D>,
{
    /// Its name: the key of its entry in `summary.json` and in checkpoints.
    fn name(&self) -> &'static str;
    /// Fills its own columns of the series row of the current state.
    fn fill_row(&mut self, _sim: &mut Simulation<D>, _row: &mut SeriesRow) {}
    /// Records the current state (`rows` ends with its series row).
    fn record(&mut self, sim: &mut Simulation<D>, rows: &[SeriesRow]);
    /// After a regular output row: an earlier end time, if the run should stop (e.g. once a
    /// steady state has been averaged).
    fn end_time(&mut self, _sim: &mut Simulation<D>, _rows: &[SeriesRow]) -> Option<f64> {
        None
    }
    /// Its state for a checkpoint.
    fn checkpoint(&self) -> Option<serde_json::Value> {
        None
    }
    /// A resumed run: its rows up to time `t` (from its files in `dir`) and its checkpointed
    /// state.
    fn restore(&mut self, _dir: &Path, _t: f64, _state: Option<&serde_json::Value>) -> Result<()> {
        Ok(())
    }
    /// Writes its files beside `series.csv`, atomically.
    fn write(&self, _dir: &Path) -> Result<()> {
        Ok(())
    }
    /// At the end of the run: its final files and charts (in the format `charts` names, if
    /// any), and its summary.
    fn finish(
        &mut self,
        sim: &mut Simulation<D>,
        rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>>;
}

/// The probes of a run.
pub struct Probes<const D: usize = 2>(Vec<Box<dyn Probe<D>>>)
where
    Dim<D>: StepDimension<D>;

impl Probes {
    /// The probes that apply to a case.
    pub fn for_case(case: &Case) -> Self {
        let scene = &case.scene;
        let mut probes: Vec<Box<dyn Probe>> = Vec::new();
        if let Some(c) = scene.cylinder() {
            probes.push(Box::new(cylinder::CylinderProbe::new(case, c)));
        }
        if let Some(d) = scene.drop_shape() {
            let speed = scene.velocity_scale(&case.fluid);
            let mut probe = drop::DropProbe::new(d.diameter, speed);
            probe.free = !d.plate;
            probe.theory = (!d.plate)
                .then(|| drop::linear_mode(&case.fluid, d.diameter / 2.0))
                .flatten();
            probe.sessile = scene.contact_angle().is_some();
            probes.push(Box::new(probe));
        }
        if let Some(j) = scene.jet_shape() {
            probes.push(Box::new(jet::JetProbe::new(j.width)));
        }
        if let Some((u, regularised)) = scene.cavity() {
            let newtonian = !case.fluid.model.is_viscoelastic() && case.fluid.law.is_constant();
            let stokes = regularised && newtonian;
            probes.push(Box::new(cavity::CavityProbe::new(
                u,
                scene.length(),
                stokes,
            )));
        }
        if let Some(pool) = scene.pool() {
            probes.push(Box::new(meniscus::MeniscusProbe::new(pool, &case.fluid)));
        }
        if scene.discs() > 0 {
            probes.push(Box::new(disc::DiscProbe::new(scene.wall_shear_rate())));
        }
        Self(probes)
    }
}

/// The rows of a probe's own CSV file at `path` up to the checkpoint's time `t` (what a
/// resumed run keeps of it); `time` reads a row's t.
pub fn rows_until<R: serde::de::DeserializeOwned>(
    path: &Path,
    t: f64,
    time: fn(&R) -> f64,
) -> Result<Vec<R>> {
    let rows: Vec<R> = crate::app::table::read_rows(path)?;
    Ok(rows
        .into_iter()
        .filter(|r| time(r) <= t * (1.0 + 1e-9))
        .collect())
}

/// The names of the probes of `case`, in its dimension.
pub fn names(case: &Case) -> Vec<&'static str> {
    match case.scene.dimension() {
        3 => Probes::in_space(case).names().collect(),
        _ => Probes::for_case(case).names().collect(),
    }
}

impl Probes<3> {
    /// The probes that apply to a case in space: a sphere's drag in a periodic box (the
    /// box's momentum balance, which plates would share) or in a pipe (a control sphere),
    /// its rotation and torque between plates or when it turns.
    pub fn in_space(case: &Case) -> Self {
        let mut probes: Vec<Box<dyn Probe<3>>> = Vec::new();
        let scene = &case.scene;
        if let (Some(s), Some(wall)) = (scene.sphere(), scene.pipe_wall()) {
            probes.push(Box::new(tube::TubeProbe::new(case, s, wall)));
        } else if let Some(s) = scene.sphere() {
            let in_box = scene.periodic()[1];
            if in_box {
                probes.push(Box::new(sphere::SphereProbe::new(case, s)));
            }
            if !in_box || scene.sphere_turns() {
                let shear = scene.wall_shear_rate();
                probes.push(Box::new(rotation::RotationProbe::new(s, shear)));
            }
        }
        Self(probes)
    }
}

impl<const D: usize> Probes<D>
where
    Dim<D>: StepDimension<D>,
{
    /// The probes' names (their entries in `summary.json`).
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.0.iter().map(|p| p.name())
    }

    /// Fills the probes' columns of `row`.
    pub fn fill_row(&mut self, sim: &mut Simulation<D>, row: &mut SeriesRow) {
        self.0.iter_mut().for_each(|p| p.fill_row(sim, row));
    }

    pub fn record(&mut self, sim: &mut Simulation<D>, rows: &[SeriesRow]) {
        self.0.iter_mut().for_each(|p| p.record(sim, rows));
    }

    /// The earliest end time any probe asks for.
    pub fn end_time(&mut self, sim: &mut Simulation<D>, rows: &[SeriesRow]) -> Option<f64> {
        self.0
            .iter_mut()
            .filter_map(|p| p.end_time(sim, rows))
            .reduce(f64::min)
    }

    pub fn checkpoint(&self) -> BTreeMap<String, serde_json::Value> {
        self.0
            .iter()
            .filter_map(|p| p.checkpoint().map(|v| (p.name().to_string(), v)))
            .collect()
    }

    pub fn restore(
        &mut self,
        dir: &Path,
        t: f64,
        state: &BTreeMap<String, serde_json::Value>,
    ) -> Result<()> {
        self.0
            .iter_mut()
            .try_for_each(|p| p.restore(dir, t, state.get(p.name())))
    }

    pub fn write(&self, dir: &Path) -> Result<()> {
        self.0.iter().try_for_each(|p| p.write(dir))
    }

    /// Final files, charts and the summary entries by name.
    pub fn finish(
        &mut self,
        sim: &mut Simulation<D>,
        rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<BTreeMap<&'static str, serde_json::Value>> {
        let mut entries = BTreeMap::new();
        for p in self.0.iter_mut() {
            if let Some(v) = p.finish(sim, rows, dir, charts)? {
                entries.insert(p.name(), v);
            }
        }
        Ok(entries)
    }
}
