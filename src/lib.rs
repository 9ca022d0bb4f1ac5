//! rheosph: incompressible SPH for viscoelastic flows (King & Lind 2021).
pub mod analytic;
pub mod boundary;
pub mod kernel;
pub mod math;
pub mod neighbours;
pub mod operators;
pub mod pressure;
pub mod rheology;
pub mod shifting;
