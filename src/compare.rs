//! Overlaying the final profiles of several runs (their `profile.csv`) on one chart, each
//! with its analytic curve: e.g. Giesekus velocity profiles for several α.

use crate::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// A quantity of `profile.csv` with its analytic column.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Field {
    U,
    TauXy,
    TauXx,
    TauYy,
}

impl Field {
    fn columns(self) -> (&'static str, &'static str) {
        match self {
            Field::U => ("u", "u_exact"),
            Field::TauXy => ("tau_xy", "tau_xy_exact"),
            Field::TauXx => ("tau_xx", "tau_xx_exact"),
            Field::TauYy => ("tau_yy", "tau_yy_exact"),
        }
    }
}

/// (y, numeric value, analytic value) of one particle.
type ProfileRow = (f64, f64, Option<f64>);

/// One run's label and rows.
fn read_run(dir: &Path, field: Field) -> Result<(String, Vec<ProfileRow>)> {
    let text = std::fs::read_to_string(dir.join("profile.csv"))
        .with_context(|| format!("reading {}", dir.join("profile.csv").display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .context("empty profile.csv")?
        .split(',')
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .with_context(|| format!("no column {name}"))
    };
    let (num, ex) = field.columns();
    let (iy, inum, iex) = (col("y")?, col(num)?, col(ex)?);
    let mut rows = Vec::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let exact = f[iex].parse::<f64>().ok();
        rows.push((f[iy].parse::<f64>()?, f[inum].parse::<f64>()?, exact));
    }
    let summary: serde_json::Value = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default();
    let fluid = &summary["case"]["fluid"];
    let mut label = fluid["model"].as_str().unwrap_or("run").to_string();
    for key in ["alpha", "l2", "epsilon"] {
        if let Some(v) = fluid[key].as_f64() {
            label.push_str(&format!(" {key}={v}"));
        }
    }
    Ok((label, rows))
}

/// Draws `field` of every run against its analytic curve, scaled by `scale`.
pub fn compare_profiles(
    runs: &[PathBuf],
    field: Field,
    scale: f64,
    title: &str,
    out: &Path,
) -> Result<()> {
    let mut curves = Vec::new();
    for (k, dir) in runs.iter().enumerate() {
        let (label, mut rows) = read_run(dir, field)?;
        let color = PALETTE[k % PALETTE.len()];
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let exact: Vec<(f64, f64)> = rows
            .iter()
            .filter_map(|r| r.2.map(|e| (r.0, e / scale)))
            .collect();
        if !exact.is_empty() {
            curves.push(Curve {
                label: String::new(),
                points: exact,
                style: CurveStyle::Line,
                color,
            });
        }
        curves.push(Curve {
            label,
            points: rows.iter().map(|r| (r.0, r.1 / scale)).collect(),
            style: CurveStyle::Markers,
            color,
        });
    }
    plot::draw(
        out,
        &Chart {
            title: title.to_string(),
            x_label: "y".into(),
            y_label: format!("{:?} (lines: analytic)", field).to_lowercase(),
            ..Default::default()
        },
        &curves,
    )
}
