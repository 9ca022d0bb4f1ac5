//! Analytic reference solutions.

pub mod roots;
pub mod steady_channel;
pub mod taylor_green;
pub mod waters_king;

pub use steady_channel::SteadyChannel;
pub use waters_king::StartupPoiseuille;
