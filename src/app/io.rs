//! Output files: every file is written to a temporary name in the same directory and renamed
//! over the target, so a run killed at any moment leaves only whole files.

use anyhow::{Context, Result};
use serde::Serialize;
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

/// One row of `series.csv`.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct SeriesRow {
    pub t: f64,
    pub dt: f64,
    pub step: u64,
    /// Centre-line velocity (quadratic fit through the particles near y = H/2).
    pub u_centre: f64,
    /// Analytic centre-line velocity.
    pub u_centre_exact: f64,
    /// Relative L2 error of the streamwise velocity against the analytic solution.
    pub l2_error: f64,
    /// Mean BiCGStab iterations per step since the previous row.
    pub ppe_iterations: f64,
    /// Largest PPE relative residual since the previous row.
    pub ppe_residual: f64,
    /// Sparse-LU fallbacks since the previous row.
    pub ppe_fallbacks: u32,
    pub kinetic_energy: f64,
    pub max_speed: f64,
    pub max_trace_a: f64,
    pub min_det_a: f64,
    /// Bulk velocity Q/H = Σ u_x V / (L H): the mean of u_x over the whole box with the
    /// solid counted as at rest (King & Lind's ⟨u⟩ of the cylinder array).
    pub u_mean: f64,
    /// Drag coefficient K = F_x/(η0 ⟨u⟩) on the cylinder and its pressure, solvent and
    /// polymer parts (NaN without a cylinder).
    pub drag_k: f64,
    pub k_pressure: f64,
    pub k_solvent: f64,
    pub k_polymer: f64,
    /// The body force g_x driving the flow (constant, or held by `scene.mean_flow`).
    pub body_force: f64,
    /// The largest δt c/h since the previous row, c the shear-wave speed of the stretched
    /// polymer (the elastic limit keeps it below ≈ 1.8 at Re = 1).
    pub elastic_courant: f64,
    /// Where det A is smallest (the particle's position).
    pub min_det_a_x: f64,
    pub min_det_a_y: f64,
    /// Where tr A is largest.
    pub max_trace_a_x: f64,
    pub max_trace_a_y: f64,
    /// Particle-scale noise of ln tr A ([`crate::analysis::diagnostics::conformation_noise`]).
    pub conformation_noise: f64,
}

pub const SERIES_HEADER: &str = "t,dt,step,u_centre,u_centre_exact,l2_error,ppe_iterations,ppe_residual,ppe_fallbacks,kinetic_energy,max_speed,max_trace_a,min_det_a,u_mean,drag_k,k_pressure,k_solvent,k_polymer,body_force,elastic_courant,min_det_a_x,min_det_a_y,max_trace_a_x,max_trace_a_y,conformation_noise";

/// The series as CSV text.
pub fn series_csv(rows: &[SeriesRow]) -> String {
    let mut s = String::with_capacity(64 + rows.len() * 160);
    s.push_str(SERIES_HEADER);
    s.push('\n');
    for r in rows {
        s.push_str(&format!(
            "{:.8e},{:.6e},{},{:.8e},{:.8e},{:.6e},{:.2},{:.3e},{},{:.8e},{:.6e},{:.8e},{:.8e},{:.8e},{:.6e},{:.6e},{:.6e},{:.6e},{:.8e},{:.4e},{:.6e},{:.6e},{:.6e},{:.6e},{:.4e}\n",
            r.t,
            r.dt,
            r.step,
            r.u_centre,
            r.u_centre_exact,
            r.l2_error,
            r.ppe_iterations,
            r.ppe_residual,
            r.ppe_fallbacks,
            r.kinetic_energy,
            r.max_speed,
            r.max_trace_a,
            r.min_det_a,
            r.u_mean,
            r.drag_k,
            r.k_pressure,
            r.k_solvent,
            r.k_polymer,
            r.body_force,
            r.elastic_courant,
            r.min_det_a_x,
            r.min_det_a_y,
            r.max_trace_a_x,
            r.max_trace_a_y,
            r.conformation_noise
        ));
    }
    s
}

/// Reads a `series.csv` back (for tests and studies).
pub fn read_series(path: &Path) -> Result<Vec<SeriesRow>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header = lines.next().context("empty series")?;
    anyhow::ensure!(
        header == SERIES_HEADER,
        "unexpected series header: {header}"
    );
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            anyhow::ensure!(f.len() == 25, "bad series line: {line}");
            let x = |k: usize| -> Result<f64> { Ok(f[k].parse::<f64>()?) };
            Ok(SeriesRow {
                t: x(0)?,
                dt: x(1)?,
                step: f[2].parse()?,
                u_centre: x(3)?,
                u_centre_exact: x(4)?,
                l2_error: x(5)?,
                ppe_iterations: x(6)?,
                ppe_residual: x(7)?,
                ppe_fallbacks: f[8].parse()?,
                kinetic_energy: x(9)?,
                max_speed: x(10)?,
                max_trace_a: x(11)?,
                min_det_a: x(12)?,
                u_mean: x(13)?,
                drag_k: x(14)?,
                k_pressure: x(15)?,
                k_solvent: x(16)?,
                k_polymer: x(17)?,
                body_force: x(18)?,
                elastic_courant: x(19)?,
                min_det_a_x: x(20)?,
                min_det_a_y: x(21)?,
                max_trace_a_x: x(22)?,
                max_trace_a_y: x(23)?,
                conformation_noise: x(24)?,
            })
        })
        .collect()
}
