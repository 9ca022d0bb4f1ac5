//! Set-up: case files into validated settings, and the scenes that build the engine's types.
//!
//! [`case::parse`] reads a file's TOML, applies `--set` [`overrides`], reads the tables
//! ([`schema`]), lets the scene validate itself ([`scenes`]) and validates the rest
//! ([`validate`]) into a [`case::Case`]; a key that moved or went is refused
//! first, naming its new place ([`renamed`]); [`derived`] numbers follow from it.

pub mod case;
pub mod derived;
pub mod error;
pub mod experimental;
pub mod overrides;
pub mod renamed;
pub mod scenes;
pub mod schema;
pub mod validate;
