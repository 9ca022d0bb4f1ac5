//! `rheosph rheometry <case>`: the fluid of a case in homogeneous flows (see
//! [`crate::analysis::rheometry`]), to CSV and PNG in one directory:
//! `steady_shear.csv` (`shear_rate, viscosity, psi1, psi2` and their exact values),
//! `startup_shear.csv`, `planar_extension.csv` (at λγ̇, λε̇ = 0.1, 1, 10 and 0.1, 0.25, 1)
//! and `saos.csv` (`omega, g_storage, g_loss` and exact).

use crate::analysis::rheometry::{log_space, Oscillatory, Rheometer, SteadyShear, Transient};
use crate::app::io::write_atomic;
use crate::app::plot::FigureFormat;
use crate::app::plot::{draw, Chart, Curve, CurveStyle, PALETTE};
use crate::app::table::{self, fmt};
use crate::setup::case::Case;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Wi = λγ̇ of the start-up shear runs and λε̇ of the planar extension runs.
const SHEAR_WI: [f64; 3] = [0.1, 1.0, 10.0];
const EXTENSION_WI: [f64; 3] = [0.1, 0.25, 1.0];

/// Runs every homogeneous flow of `case`'s fluid into `out`.
pub fn run(case: &Case, out: &Path, format: FigureFormat, quiet: bool) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let r = Rheometer {
        fluid: case.fluid,
        scheme: case.scheme.conformation,
    };
    // Rates in units of 1/λ (of 1/s for a Newtonian fluid: λ = 0).
    let time = if case.fluid.relaxation_time > 0.0 {
        case.fluid.relaxation_time
    } else {
        1.0
    };
    let err = |e: String| anyhow::anyhow!("{e}");
    let rates: Vec<f64> = log_space(1e-2, 1e2, 25).iter().map(|w| w / time).collect();
    let steady = r.steady_shear(&rates).map_err(err)?;
    write_steady(out, format, &steady)?;
    let mut startup = Vec::new();
    for wi in SHEAR_WI {
        startup.push((
            wi,
            r.startup_shear(wi / time, 5.0 * time, 200).map_err(err)?,
        ));
    }
    write_transients(
        out,
        format,
        "startup_shear",
        &startup,
        "Start-up of shear",
        "η⁺",
    )?;
    let mut extension = Vec::new();
    for wi in EXTENSION_WI {
        // λε̇ ≥ ½ grows without bound for Oldroyd-B: a shorter window keeps it finite.
        let t_end = if wi >= 0.5 { 2.0 * time } else { 5.0 * time };
        let samples = r.planar_extension(wi / time, t_end, 200).map_err(err)?;
        extension.push((wi, samples));
    }
    write_transients(
        out,
        format,
        "planar_extension",
        &extension,
        "Start-up of planar extension",
        "η_P⁺",
    )?;
    let omegas: Vec<f64> = log_space(1e-2, 1e2, 17).iter().map(|w| w / time).collect();
    let saos = r.oscillatory(&omegas, 1e-3).map_err(err)?;
    write_saos(out, format, &saos)?;
    if !quiet {
        eprintln!("rheometry of `{}` written to {}", case.name, out.display());
    }
    Ok(())
}

/// One row of `steady_shear.csv` (the analysis layer's [`SteadyShear`], to 9 digits).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct SteadyShearRow {
    #[serde(serialize_with = "fmt::sci8")]
    pub shear_rate: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub viscosity: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub psi1: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub psi2: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub viscosity_exact: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub psi1_exact: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub psi2_exact: f64,
}

/// One row of `startup_shear.csv` or `planar_extension.csv`: a [`Transient`] sample of the
/// run at `wi`.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct TransientRow {
    #[serde(serialize_with = "fmt::plain")]
    pub wi: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub t: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub viscosity: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub psi1: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub viscosity_exact: f64,
}

/// One row of `saos.csv`: G′ and G″ at ω ([`Oscillatory`]) and their exact values.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct SaosRow {
    #[serde(serialize_with = "fmt::sci8")]
    pub omega: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub g_storage: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub g_loss: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub g_storage_exact: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub g_loss_exact: f64,
}

fn curve(label: &str, points: Vec<(f64, f64)>, style: CurveStyle, k: usize) -> Curve {
    Curve {
        label: label.to_string(),
        points,
        style,
        color: PALETTE[k % PALETTE.len()],
    }
}

fn log_chart(title: &str, x: &str, y: &str) -> Chart {
    Chart {
        title: title.into(),
        x_label: x.into(),
        y_label: y.into(),
        log_x: true,
        log_y: true,
        ..Default::default()
    }
}

fn write_steady(out: &Path, format: FigureFormat, rows: &[SteadyShear]) -> Result<()> {
    let table_rows: Vec<SteadyShearRow> = rows
        .iter()
        .map(|p| SteadyShearRow {
            shear_rate: p.shear_rate,
            viscosity: p.viscosity,
            psi1: p.psi1,
            psi2: p.psi2,
            viscosity_exact: p.viscosity_exact,
            psi1_exact: p.psi1_exact,
            psi2_exact: p.psi2_exact,
        })
        .collect();
    let csv = table::write_rows(&table_rows);
    write_atomic(&out.join("steady_shear.csv"), csv.as_bytes())?;
    let series = |f: fn(&SteadyShear) -> f64| -> Vec<(f64, f64)> {
        rows.iter().map(|p| (p.shear_rate, f(p))).collect()
    };
    let curves = [
        curve("η", series(|p| p.viscosity), CurveStyle::Markers, 0),
        curve(
            "η exact",
            series(|p| p.viscosity_exact),
            CurveStyle::Line,
            0,
        ),
        curve("Ψ₁", series(|p| p.psi1), CurveStyle::Markers, 1),
        curve("Ψ₁ exact", series(|p| p.psi1_exact), CurveStyle::Line, 1),
    ];
    let chart = log_chart("Steady shear", "shear rate", "η, Ψ₁");
    draw(&out.join("steady_shear.png"), format, &chart, &curves)
}

fn write_transients(
    out: &Path,
    format: FigureFormat,
    name: &str,
    runs: &[(f64, Vec<Transient>)],
    title: &str,
    symbol: &str,
) -> Result<()> {
    let mut table_rows = Vec::new();
    let mut curves = Vec::new();
    for (k, (wi, samples)) in runs.iter().enumerate() {
        table_rows.extend(samples.iter().map(|s| TransientRow {
            wi: *wi,
            t: s.t,
            viscosity: s.viscosity,
            psi1: s.psi1,
            viscosity_exact: s.viscosity_exact,
        }));
        let points = |f: fn(&Transient) -> f64| samples.iter().map(|s| (s.t, f(s))).collect();
        let label = format!("{symbol}, Wi = {wi}");
        curves.push(curve(&label, points(|s| s.viscosity), CurveStyle::Line, k));
        curves.push(curve(
            "exact",
            points(|s| s.viscosity_exact),
            CurveStyle::Dashed,
            k,
        ));
    }
    let csv = table::write_rows(&table_rows);
    write_atomic(&out.join(format!("{name}.csv")), csv.as_bytes())?;
    let chart = Chart {
        log_x: false,
        ..log_chart(title, "t", symbol)
    };
    draw(&out.join(format!("{name}.png")), format, &chart, &curves)
}

fn write_saos(out: &Path, format: FigureFormat, rows: &[Oscillatory]) -> Result<()> {
    let table_rows: Vec<SaosRow> = rows
        .iter()
        .map(|o| SaosRow {
            omega: o.omega,
            g_storage: o.storage,
            g_loss: o.loss,
            g_storage_exact: o.storage_exact,
            g_loss_exact: o.loss_exact,
        })
        .collect();
    let csv = table::write_rows(&table_rows);
    write_atomic(&out.join("saos.csv"), csv.as_bytes())?;
    let series = |f: fn(&Oscillatory) -> f64| -> Vec<(f64, f64)> {
        rows.iter().map(|o| (o.omega, f(o))).collect()
    };
    let curves = [
        curve("G′", series(|o| o.storage), CurveStyle::Markers, 1),
        curve("G′ exact", series(|o| o.storage_exact), CurveStyle::Line, 1),
        curve("G″", series(|o| o.loss), CurveStyle::Markers, 2),
        curve("G″ exact", series(|o| o.loss_exact), CurveStyle::Line, 2),
    ];
    let chart = log_chart("Small-amplitude oscillatory shear", "ω", "G′, G″");
    draw(&out.join("saos.png"), format, &chart, &curves)
}
