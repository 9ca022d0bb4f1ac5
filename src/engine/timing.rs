//! Wall-clock time per stage of the time step, reported in every run's summary.

use serde::Serialize;
use std::time::Instant;

/// The stages of one step (DESIGN.md "One time step as stages") plus the run's own work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Step 1 and 7: moving particles.
    Advection,
    /// Step 2: mirrors, cell lists, neighbour lists, kernel sums and L_i.
    Neighbours,
    /// Step 2: velocity gradient and shifting velocity.
    Kinematics,
    /// Step 3: conformation update and EVSS Φ.
    Constitutive,
    /// Step 4: predictor u*.
    Predictor,
    /// Step 4: the implicit viscous solve (implicit viscosity only).
    Viscous,
    /// Step 5: PPE assembly.
    PpeAssembly,
    /// Step 5: PPE solve.
    PpeSolve,
    /// Step 6: projection.
    Projection,
    /// After step 7: the rigid discs' loads and motion.
    Bodies,
    /// Breakdown checks, analytic comparison, series rows.
    Diagnostics,
    /// Writing files.
    Output,
}

/// Accumulated seconds per stage.
#[derive(Clone, Copy, Debug, Default, Serialize, serde::Deserialize)]
pub struct StageSeconds {
    pub advection: f64,
    pub neighbours: f64,
    pub kinematics: f64,
    pub constitutive: f64,
    pub predictor: f64,
    pub viscous: f64,
    pub ppe_assembly: f64,
    pub ppe_solve: f64,
    pub projection: f64,
    pub bodies: f64,
    pub diagnostics: f64,
    pub output: f64,
}

impl StageSeconds {
    fn slot(&mut self, stage: Stage) -> &mut f64 {
        match stage {
            Stage::Advection => &mut self.advection,
            Stage::Neighbours => &mut self.neighbours,
            Stage::Kinematics => &mut self.kinematics,
            Stage::Constitutive => &mut self.constitutive,
            Stage::Predictor => &mut self.predictor,
            Stage::Viscous => &mut self.viscous,
            Stage::PpeAssembly => &mut self.ppe_assembly,
            Stage::PpeSolve => &mut self.ppe_solve,
            Stage::Projection => &mut self.projection,
            Stage::Bodies => &mut self.bodies,
            Stage::Diagnostics => &mut self.diagnostics,
            Stage::Output => &mut self.output,
        }
    }

    /// Runs `f`, adding its wall time to `stage`.
    pub fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        *self.slot(stage) += start.elapsed().as_secs_f64();
        out
    }

    pub fn add(&mut self, stage: Stage, seconds: f64) {
        *self.slot(stage) += seconds;
    }

    pub fn total(&self) -> f64 {
        self.advection
            + self.neighbours
            + self.kinematics
            + self.constitutive
            + self.predictor
            + self.viscous
            + self.ppe_assembly
            + self.ppe_solve
            + self.projection
            + self.bodies
            + self.diagnostics
            + self.output
    }
}
