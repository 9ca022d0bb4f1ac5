//! rheosph: incompressible SPH for viscoelastic flows, after King & Lind (2021), *High
//! Weissenberg number simulations with incompressible SPH and the log-conformation
//! formulation*. Equation numbers in doc comments refer to that paper.
//!
//! One module per physical idea: [`kernel`], [`neighbours`], [`boundary`], [`operators`],
//! [`rheology`], [`shifting`], [`pressure`], [`step`]; the run around them in [`run`], with
//! [`case`] files, [`scene`] builders, [`analytic`] references, [`diagnostics`], [`io`] and
//! [`plot`].

pub mod analytic;
pub mod bench;
pub mod boundary;
pub mod case;
pub mod centreline;
pub mod checkpoint;
pub mod cli;
pub mod compare;
pub mod diagnostics;
pub mod forces;
pub mod inflow;
pub mod io;
pub mod kernel;
pub mod laplacian_matrix;
pub mod math;
pub mod neighbours;
pub mod operators;
pub mod ordering;
pub mod plot;
pub mod pressure;
pub mod reference;
pub mod rheology;
pub mod run;
pub mod scene;
pub mod shifting;
pub mod step;
pub mod study;
pub mod surface;
pub mod timing;
pub mod viscosity;
pub mod vtk;

/// Heap bytes reserved by a vector.
pub fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}
