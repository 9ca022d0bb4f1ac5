//! The SPH engine: King & Lind's projection scheme and everything it is made of. Nothing here
//! imports the case files, runs, studies, plots or the command line.
//!
//! The time step is [`step::Simulation::step`]; its stages are the modules named after the
//! physical idea they implement.

pub mod bodies;
pub mod boundary;
pub mod dimension;
pub mod drive;
pub mod frame;
pub mod free_surface;
pub mod gravity;
pub mod kernel;
pub mod kinematics;
pub mod laplacian_matrix;
pub mod lattice;
pub mod math;
pub mod neighbourhood;
pub mod neighbours;
pub mod operators;
pub mod ordering;
pub mod predictor;
pub mod pressure;
pub mod projection;
pub mod reduce;
pub mod resolution;
pub mod rheology;
pub mod scheme;
pub mod second_order;
pub mod settings;
pub mod shifting;
pub mod stabilisation;
pub mod state;
pub mod step;
pub mod timing;
pub mod viscosity;
pub mod volume;
pub mod weakly_compressible;

/// Heap bytes reserved by a vector.
pub fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}
