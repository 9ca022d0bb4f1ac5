//! Analytic reference solutions.

pub mod drop_oscillation;
pub mod pipe;
pub mod roots;
pub mod startup_couette;
pub mod steady_channel;
pub mod stokes_cavity;
pub mod taylor_green;
pub mod waters_king;

pub use drop_oscillation::DropMode;
pub use pipe::StartupPipe;
pub use startup_couette::StartupCouette;
pub use steady_channel::SteadyChannel;
pub use waters_king::StartupPoiseuille;
