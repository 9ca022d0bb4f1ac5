//! Output files: every file is written to a temporary name in the same directory and renamed
//! over the target, so a run killed at any moment leaves only whole files.

use crate::app::table::{self, fmt};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file, fsync, rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let name = path
        .file_name()
        .context("output path has no file name")?
        .to_string_lossy();
    let tmp = path.with_file_name(format!(".{name}.tmp"));
    let mut f =
        std::fs::File::create(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
    f.write_all(bytes)
        .with_context(|| format!("writing {}", tmp.display()))?;
    f.sync_all().ok();
    drop(f);
    std::fs::rename(&tmp, path).with_context(|| format!("renaming to {}", path.display()))?;
    Ok(())
}

/// Serialises `value` as pretty JSON and writes it atomically.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// One row of `series.csv`; its fields are the file's columns, in order, each written in the
/// format it has always had ([`table::fmt`]).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct SeriesRow {
    #[serde(serialize_with = "fmt::sci8")]
    pub t: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub dt: f64,
    pub step: u64,
    /// Centre-line velocity (quadratic fit through the particles near y = H/2).
    #[serde(serialize_with = "fmt::sci8")]
    pub u_centre: f64,
    /// Analytic centre-line velocity.
    #[serde(serialize_with = "fmt::sci8")]
    pub u_centre_exact: f64,
    /// Relative L2 error of the streamwise velocity against the analytic solution.
    #[serde(serialize_with = "fmt::sci6")]
    pub l2_error: f64,
    /// Mean BiCGStab iterations per step since the previous row.
    #[serde(serialize_with = "fmt::fixed2")]
    pub ppe_iterations: f64,
    /// Largest PPE relative residual since the previous row.
    #[serde(serialize_with = "fmt::sci3")]
    pub ppe_residual: f64,
    /// Sparse-LU fallbacks since the previous row.
    pub ppe_fallbacks: u32,
    #[serde(serialize_with = "fmt::sci8")]
    pub kinetic_energy: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub max_speed: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub max_trace_a: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub min_det_a: f64,
    /// Bulk velocity Q/H = Σ u_x V / (L H): the mean of u_x over the whole box with the
    /// solid counted as at rest (King & Lind's ⟨u⟩ of the cylinder array).
    #[serde(serialize_with = "fmt::sci8")]
    pub u_mean: f64,
    /// Drag coefficient K = F_x/(η0 ⟨u⟩) on the cylinder and its pressure, solvent and
    /// polymer parts (NaN without a cylinder).
    #[serde(serialize_with = "fmt::sci6")]
    pub drag_k: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub k_pressure: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub k_solvent: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub k_polymer: f64,
    /// The body force g_x driving the flow (constant, or held by `scene.mean_flow`).
    #[serde(serialize_with = "fmt::sci8")]
    pub body_force: f64,
    /// The largest δt c/h since the previous row, c the shear-wave speed of the stretched
    /// polymer (the elastic limit keeps it below ≈ 1.8 at Re = 1).
    #[serde(serialize_with = "fmt::sci4")]
    pub elastic_courant: f64,
    /// Where det A is smallest (the particle's position).
    #[serde(serialize_with = "fmt::sci6")]
    pub min_det_a_x: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub min_det_a_y: f64,
    /// Where tr A is largest.
    #[serde(serialize_with = "fmt::sci6")]
    pub max_trace_a_x: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub max_trace_a_y: f64,
    /// Particle-scale noise of ln tr A ([`crate::analysis::diagnostics::conformation_noise`]).
    #[serde(serialize_with = "fmt::sci4")]
    pub conformation_noise: f64,
}

/// The series as CSV text.
pub fn series_csv(rows: &[SeriesRow]) -> String {
    table::write_rows(rows)
}

/// Reads a `series.csv` back (for tests and studies), its columns by name.
pub fn read_series(path: &Path) -> Result<Vec<SeriesRow>> {
    table::read_rows(path)
}
