//! The application: command line, run loop and run directory, studies, benchmarks, output
//! formats and charts.

pub mod bench;
pub mod bench_solvers;
pub mod cli;
pub mod compare;
pub mod gallery;
pub mod io;
pub mod keys;
pub mod plot;
pub mod rheometry;
pub mod run;
pub mod study;
pub mod table;
pub mod vtk;
