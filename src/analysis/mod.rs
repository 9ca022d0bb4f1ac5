//! Analysis: analytic reference solutions, diagnostics of a particle state, forces on bodies,
//! centre-line profiles. Reads the engine; knows nothing of runs or output formats.

pub mod analytic;
pub mod centreline;
pub mod diagnostics;
pub mod forces;
pub mod grid;
pub mod pipe_wall;
pub mod plane;
pub mod reference;
pub mod rheometry;
pub mod sphere_load;
pub mod tube_load;
