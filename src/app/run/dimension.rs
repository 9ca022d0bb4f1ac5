//! What a run does differently in the plane and in space, chosen once by the case's
//! `scene.dimension`: how the simulation is built, which probes apply, the snapshot and
//! checkpoint formats. The run loop is written once over [`RunDimension`].

use super::checkpoint::{self, LoopState};
use super::probes::Probes;
use crate::analysis::plane::InPlane;
use crate::app::plot::FigureFormat;
use crate::app::vtk::Series;
use crate::engine::dimension::Dim;
use crate::engine::step::{Simulation, StepDimension};
use crate::setup::case::Case;
use anyhow::Result;
use std::path::Path;

/// A dimension a run can be made in.
pub trait RunDimension<const D: usize>: StepDimension<D> + InPlane<D>
where
    Dim<D>: StepDimension<D>,
{
    /// The simulation of `case` at t = 0.
    fn simulation(case: &Case) -> Result<Simulation<D>>;

    /// The probes that apply to `case`.
    fn probes(case: &Case) -> Probes<D>;

    /// The `.vtu` document of the current state.
    fn snapshot(sim: &Simulation<D>) -> Vec<u8>;

    /// Adds the current state to a run's snapshot series.
    fn write_snapshot(series: &mut Series, sim: &Simulation<D>) -> Result<()>;

    /// A free surface's tr A chart beside a snapshot (2D scenes only have free surfaces).
    fn free_surface_chart(
        dir: &Path,
        format: FigureFormat,
        sim: &Simulation<D>,
        title: &str,
        name: &str,
    ) -> Result<()>;

    /// Writes `checkpoint.bin` (false where checkpoints are not written).
    fn save_checkpoint(dir: &Path, state: &LoopState, sim: &Simulation<D>) -> Result<bool>;

    /// Writes the state another run can start from (`run --from`).
    fn write_final_state(path: &Path, sim: &Simulation<D>) -> Result<()>;
}

impl RunDimension<2> for Dim<2> {
    fn simulation(case: &Case) -> Result<Simulation> {
        anyhow::ensure!(
            case.scene.dimension() == 2,
            "scene.dimension = {}: a live simulation (Python's `Simulation`) and `run --from` take 2D cases",
            case.scene.dimension()
        );
        Ok(Simulation::new(case.setup().map_err(anyhow::Error::msg)?))
    }

    fn probes(case: &Case) -> Probes {
        Probes::for_case(case)
    }

    fn snapshot(sim: &Simulation) -> Vec<u8> {
        crate::app::vtk::snapshot(sim)
    }

    fn write_snapshot(series: &mut Series, sim: &Simulation) -> Result<()> {
        series.write(sim)
    }

    fn free_surface_chart(
        dir: &Path,
        format: FigureFormat,
        sim: &Simulation,
        title: &str,
        name: &str,
    ) -> Result<()> {
        super::charts::free_surface_snapshot(dir, format, sim, title, name)
    }

    fn save_checkpoint(dir: &Path, state: &LoopState, sim: &Simulation) -> Result<bool> {
        checkpoint::save(dir, state, sim)?;
        Ok(true)
    }

    fn write_final_state(path: &Path, sim: &Simulation) -> Result<()> {
        Ok(checkpoint::write(path, sim)?)
    }
}

impl RunDimension<3> for Dim<3> {
    fn simulation(case: &Case) -> Result<Simulation<3>> {
        let setup = case.setup_in_space().map_err(anyhow::Error::msg)?;
        Simulation::in_space(setup).map_err(anyhow::Error::msg)
    }

    fn probes(case: &Case) -> Probes<3> {
        Probes::in_space(case)
    }

    fn snapshot(sim: &Simulation<3>) -> Vec<u8> {
        crate::app::vtk::particles(sim)
    }

    /// The particles only: grid snapshots (`.vti`) are 2D.
    fn write_snapshot(series: &mut Series, sim: &Simulation<3>) -> Result<()> {
        let (t, steps) = (sim.state.time, sim.state.steps);
        series.write_particles(t, steps, &Self::snapshot(sim))?;
        Ok(())
    }

    fn free_surface_chart(
        _dir: &Path,
        _format: FigureFormat,
        _sim: &Simulation<3>,
        _title: &str,
        _name: &str,
    ) -> Result<()> {
        Ok(())
    }

    fn save_checkpoint(dir: &Path, state: &LoopState, sim: &Simulation<3>) -> Result<bool> {
        checkpoint::save(dir, state, sim)?;
        Ok(true)
    }

    fn write_final_state(path: &Path, sim: &Simulation<3>) -> Result<()> {
        Ok(checkpoint::write(path, sim)?)
    }
}
