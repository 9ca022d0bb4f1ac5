//! Overlaying several runs on one chart: the final profiles of channel runs (their
//! `profile.csv`, each with its analytic curve: e.g. Giesekus velocity profiles for several
//! α), or the width and height histories of drops (their `drop.csv`).

use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::app::run::errors;
use crate::app::run::probes::centreline::CentrelineRow;
use crate::app::run::probes::drop::DropRow;
use crate::app::table;
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
    /// The numeric value of a particle and the analytic one at its height.
    fn of(self, r: &errors::ProfileRow) -> (f64, Option<f64>) {
        match self {
            Field::U => (r.u, r.u_exact),
            Field::TauXy => (r.tau_xy, r.tau_xy_exact),
            Field::TauXx => (r.tau_xx, r.tau_xx_exact),
            Field::TauYy => (r.tau_yy, r.tau_yy_exact),
        }
    }
}

/// (y, numeric value, analytic value) of one particle.
type ProfileRow = (f64, f64, Option<f64>);

/// A run's `summary.json`, or JSON null if it has none (labels then fall back).
fn read_summary(dir: &Path) -> serde_json::Value {
    std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default()
}

/// `--labels` is empty (defaults) or one per run.
fn check_labels(labels: &[String], runs: usize) -> Result<()> {
    anyhow::ensure!(
        labels.is_empty() || labels.len() == runs,
        "--labels: {} labels for {runs} runs",
        labels.len()
    );
    Ok(())
}

/// One run's label and rows.
fn read_run(dir: &Path, field: Field) -> Result<(String, Vec<ProfileRow>)> {
    let profile: Vec<errors::ProfileRow> = table::read_rows(&dir.join("profile.csv"))?;
    let rows = profile
        .iter()
        .map(|r| {
            let (value, exact) = field.of(r);
            (r.y, value, exact)
        })
        .collect();
    let summary = read_summary(dir);
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
        FigureFormat::of_path(out),
        &Chart {
            title: title.to_string(),
            x_label: "y".into(),
            y_label: format!("{:?} (lines: analytic)", field).to_lowercase(),
            ..Default::default()
        },
        &curves,
    )
}

/// (t*, W*, H*) rows of a run's `drop.csv`.
fn read_drop(dir: &Path) -> Result<Vec<(f64, f64, f64)>> {
    let rows: Vec<DropRow> = table::read_rows(&dir.join("drop.csv"))?;
    Ok(rows.iter().map(|r| (r.t_star, r.width, r.height)).collect())
}

/// W* (solid) and H* (dashed) against t* for each run, one colour per run.
pub fn compare_drops(runs: &[PathBuf], labels: &[String], title: &str, out: &Path) -> Result<()> {
    check_labels(labels, runs.len())?;
    let mut curves = Vec::new();
    for (k, dir) in runs.iter().enumerate() {
        let rows = read_drop(dir)?;
        let label = labels.get(k).cloned().unwrap_or_else(|| {
            dir.file_name()
                .map_or_else(|| dir.display().to_string(), |n| n.to_string_lossy().into())
        });
        let color = PALETTE[k % PALETTE.len()];
        curves.push(Curve {
            label,
            points: rows.iter().map(|r| (r.0, r.1)).collect(),
            style: CurveStyle::Line,
            color,
        });
        curves.push(Curve {
            label: String::new(),
            points: rows.iter().map(|r| (r.0, r.2)).collect(),
            style: CurveStyle::Dashed,
            color,
        });
    }
    plot::draw(
        out,
        FigureFormat::of_path(out),
        &Chart {
            title: title.into(),
            x_label: "t* = tU/W".into(),
            y_label: "W* (solid), H* (dashed)".into(),
            ..Default::default()
        },
        &curves,
    )
}

/// The centre-line charts of several cylinder runs overlaid (their `centreline.csv`; the
/// paper's Fig. 11 from runs of any length, e.g. long runs resumed outside a study), into
/// `out` (a directory). Labels default to "Wi = λU/R" from each run's `summary.json`.
pub fn compare_centrelines(runs: &[PathBuf], labels: &[String], out: &Path) -> Result<()> {
    check_labels(labels, runs.len())?;
    let mut profiles = Vec::new();
    for (k, dir) in runs.iter().enumerate() {
        let path = dir.join("centreline.csv");
        let rows: Vec<CentrelineRow> = table::read_rows(&path)?;
        anyhow::ensure!(!rows.is_empty(), "{}: no centre-line rows", path.display());
        let label = match labels.get(k) {
            Some(l) => l.clone(),
            None => read_summary(dir)["derived"]["weissenberg"]
                .as_f64()
                .map_or_else(|| dir.display().to_string(), |wi| format!("Wi = {wi}")),
        };
        profiles.push((label, rows));
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    crate::app::study::cylinder::centreline_charts(out, FigureFormat::Png, &profiles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two fake cylinder runs overlaid: the three charts are written; a directory without
    /// `centreline.csv` is refused with the file named, and so are mismatched labels.
    #[test]
    fn centrelines_of_several_runs_are_overlaid() {
        let root = std::env::temp_dir().join(format!("rheosph-cc-{}", std::process::id()));
        let run = |name: &str, wi: f64| {
            let dir = root.join(name);
            std::fs::create_dir_all(&dir).unwrap();
            let mut csv = String::from("s,u_over_umean,tau_xx_scaled,det_a\n");
            for k in 0..=16 {
                let s = 0.25 * k as f64;
                csv.push_str(&format!("{s},{},{},{}\n", 0.1 * s, wi * s, 1.0 + wi * s));
            }
            std::fs::write(dir.join("centreline.csv"), csv).unwrap();
            let summary = format!("{{\"derived\": {{\"weissenberg\": {wi}}}}}");
            std::fs::write(dir.join("summary.json"), summary).unwrap();
            dir
        };
        let runs = [run("a", 2.0), run("b", 8.0)];
        let out = root.join("charts");
        compare_centrelines(&runs, &[], &out).unwrap();
        for name in ["centreline_u", "centreline_tau_xx", "centreline_det_a"] {
            assert!(out.join(format!("{name}.png")).is_file(), "{name}");
        }
        let missing = compare_centrelines(&[root.join("none")], &[], &out).unwrap_err();
        assert!(
            format!("{missing:#}").contains("centreline.csv"),
            "{missing:#}"
        );
        let labels = ["one".to_string()];
        assert!(compare_centrelines(&runs, &labels, &out).is_err());
        std::fs::remove_dir_all(&root).unwrap();
    }
}
