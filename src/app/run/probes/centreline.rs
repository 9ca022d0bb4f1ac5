//! The row type of `centreline.csv` (the cylinder probe's averaged centre-line profiles), in
//! a module of its own so that the charts, the cylinder study and `compare-centrelines` can
//! read it without importing the probe, which imports the charts.

use crate::app::table::fmt;
use serde::{Deserialize, Serialize};

/// One row of `centreline.csv`: s (0 at the cylinder's downstream edge), u/⟨u⟩,
/// τ_xx/(η_s⟨u⟩/R) and det A, time-averaged over the steady window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CentrelineRow {
    #[serde(serialize_with = "fmt::sci6")]
    pub s: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub u_over_umean: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub tau_xx_scaled: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub det_a: f64,
}

/// One column of the centre-line rows, for charts that draw each against s.
pub type CentrelineColumn = fn(&CentrelineRow) -> f64;
