//! rheosph: incompressible SPH for viscoelastic flows, after King & Lind (2021), *High
//! Weissenberg number simulations with incompressible SPH and the log-conformation
//! formulation*. Equation numbers in doc comments refer to that paper.
//!
//! Four layers, each importing only those before it (see `ARCHITECTURE.md`):
//!
//! * [`engine`]: the SPH method — kernel, neighbours, boundaries, operators, rheology, free
//!   surface, shifting, pressure, the time step. Knows nothing of case files or runs.
//! * [`analysis`]: analytic references, diagnostics, forces and profiles; reads the engine.
//! * [`setup`]: case files (schema, overrides, validation, derived numbers) and the scenes
//!   that build the engine's types from them.
//! * `app` (feature `app`, on by default): the command line, the run loop and its output
//!   files, studies, benchmarks, VTK and charts.

pub mod analysis;
#[cfg(feature = "app")]
pub mod app;
pub mod engine;
pub mod setup;
