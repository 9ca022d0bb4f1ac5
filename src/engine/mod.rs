//! The SPH engine: King & Lind's projection scheme and everything it is made of. Nothing here
//! imports the case files, runs, studies, plots or the command line.

pub mod boundary;
pub mod kernel;
pub mod laplacian_matrix;
pub mod math;
pub mod neighbours;
pub mod operators;
pub mod ordering;
pub mod pressure;
pub mod rheology;
pub mod shifting;
pub mod step;
pub mod surface;
pub mod timing;
pub mod viscosity;

/// Heap bytes reserved by a vector.
pub fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}
