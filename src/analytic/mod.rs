//! Analytic reference solutions.

pub mod waters_king;

pub use waters_king::StartupPoiseuille;
