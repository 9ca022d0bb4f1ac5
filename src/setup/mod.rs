//! Set-up: case files into validated settings, and the scenes that build the engine's types.

pub mod case;
pub mod scene;
