//! `rheosph study stability`: each scheme variant over a range of Weissenberg numbers, run to
//! the end time or breakdown. The outcome is data: `stability.csv` and a map.
//!
//! Outcomes: `stable` (finished, time-mean L2 error against the reference within the
//! accuracy threshold), `inaccurate` (finished, but left the analytic solution: time-mean L2
//! above the threshold), `broke_down` (stopped: non-finite values, runaway energy or
//! conformation, a failed solve; the time and reason are recorded); and, for a member
//! `--collect` finds without a finished run, `lost` or `failed` (its error as the reason, no
//! numbers; not drawn on the map). The default threshold,
//! 10 % of U, is about ten times the error of a resolved run at H/δr = 30 (0.9 %) and far
//! below the O(1) errors of a run that has left the solution.

use super::{run_all, Base, Variant};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, style, Chart, Curve, CurveStyle};
use crate::app::run::Outcome;
use crate::app::table::{self, fmt};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Classification of one run (the `outcome` column).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Result3 {
    #[default]
    Stable,
    Inaccurate,
    BrokeDown,
    /// Not run, or its worker ended before the run did (`--collect`).
    Lost,
    /// Its run stopped on an error (`--collect`).
    Failed,
}

impl Result3 {
    pub fn name(self) -> &'static str {
        match self {
            Result3::Stable => "stable",
            Result3::Inaccurate => "inaccurate",
            Result3::BrokeDown => "broke_down",
            Result3::Lost => "lost",
            Result3::Failed => "failed",
        }
    }

    /// Whether the member ran to a result (its row has numbers).
    pub fn ran(self) -> bool {
        !matches!(self, Result3::Lost | Result3::Failed)
    }
}

/// One line of `stability.csv`. Its `reason` is always in double quotes (its own quotes made
/// single), as the file has always had it, so it is written by
/// [`table::write_rows_verbatim`]; the variant labels hold no commas.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Row {
    pub variant: String,
    #[serde(serialize_with = "fmt::plain")]
    pub wi: f64,
    pub outcome: Result3,
    #[serde(serialize_with = "fmt::opt_sci6")]
    pub t_breakdown: Option<f64>,
    #[serde(serialize_with = "fmt::quoted")]
    pub reason: Option<String>,
    #[serde(serialize_with = "fmt::opt_sci6")]
    pub l2_mean: Option<f64>,
    #[serde(serialize_with = "fmt::opt_sci6")]
    pub l2_final: Option<f64>,
    pub steps: u64,
    #[serde(serialize_with = "fmt::fixed3")]
    pub wall_seconds: f64,
}

impl Row {
    /// The row of a member with its variant's name and Wi (from its label and tag), and
    /// nothing measured yet.
    fn of(variant: &Variant) -> Self {
        let wi = variant
            .tags
            .iter()
            .find(|(k, _)| k == "wi")
            .and_then(|(_, v)| v.parse().ok())
            .unwrap_or(f64::NAN);
        let name = variant
            .label
            .rsplit_once(" Wi=")
            .map_or(String::new(), |(a, _)| a.to_string());
        Row {
            variant: if name.is_empty() { "base".into() } else { name },
            wi,
            ..Default::default()
        }
    }
}

/// Runs every variant at every Wi (λ = Wi·H/U) and writes `stability.csv` and
/// `stability_map.png`. Returns the rows.
// The study's grid (Wi × variants), its accuracy threshold and where and how it writes.
#[allow(clippy::too_many_arguments)]
pub fn run(
    base: &Base,
    wis: &[f64],
    schemes: &[Variant],
    accuracy: f64,
    out: &Path,
    format: FigureFormat,
    jobs: usize,
    quiet: bool,
) -> Result<Vec<Row>> {
    let scale = base.case(&[])?;
    let d = scale.derived();
    let mut variants = Vec::new();
    for v in schemes {
        for &wi in wis {
            let lambda = wi * scale.scene.length_scale() / d.velocity_scale;
            let mut w: Variant = v.clone();
            w.overrides.push(format!("fluid.relaxation_time={lambda}"));
            w.tags.push(("wi".into(), format!("{wi}")));
            w.label = format!("{} Wi={wi}", v.label).trim().to_string();
            variants.push(w);
        }
    }
    let members = run_all(base, variants, out, jobs, quiet)?;
    let mut rows: Vec<Row> = members
        .finished
        .iter()
        .map(|f| {
            let s = &f.summary;
            let outcome = match (s.outcome, s.errors.l2_time_mean) {
                (Outcome::BrokeDown, _) => Result3::BrokeDown,
                (Outcome::Finished, Some(l2)) if l2 <= accuracy => Result3::Stable,
                (Outcome::Finished, _) => Result3::Inaccurate,
            };
            Row {
                outcome,
                t_breakdown: (s.outcome == Outcome::BrokeDown).then_some(s.t_reached),
                reason: s.reason.clone(),
                l2_mean: s.errors.l2_time_mean,
                l2_final: s.errors.l2_final,
                steps: s.steps,
                wall_seconds: s.wall_seconds,
                ..Row::of(&f.variant)
            }
        })
        .collect();
    rows.extend(members.missing.iter().map(|m| Row {
        outcome: match m.error {
            Some(_) => Result3::Failed,
            None => Result3::Lost,
        },
        reason: m.error.clone(),
        wall_seconds: f64::NAN,
        ..Row::of(&m.variant)
    }));
    let csv = table::write_rows_verbatim(&rows);
    crate::app::io::write_atomic(&out.join("stability.csv"), csv.as_bytes())?;
    map(&rows, accuracy, out, format)?;
    members.check_complete(out)?;
    Ok(rows)
}

/// Redraws the map of a finished study from its `stability.csv`.
pub fn replot(out: &Path, format: FigureFormat, accuracy: f64) -> Result<()> {
    let rows: Vec<Row> = table::read_rows(&out.join("stability.csv"))?;
    map(&rows, accuracy, out, format)
}

/// Wi on a log axis, one row per variant named on the axis, the outcome as colour and marker;
/// the legend gives each row's largest stable Wi. Members that did not run (`lost`, `failed`)
/// are left off.
fn map(rows: &[Row], accuracy: f64, out: &Path, format: FigureFormat) -> Result<()> {
    let rows: Vec<&Row> = rows.iter().filter(|r| r.outcome.ran()).collect();
    let mut names: Vec<String> = Vec::new();
    for r in &rows {
        if !names.contains(&r.variant) {
            names.push(r.variant.clone());
        }
    }
    let level = |name: &str| names.iter().position(|n| n == name).unwrap_or(0) as f64;
    let mut curves = Vec::new();
    for (outcome, color, marker) in [
        (Result3::Stable, style::GOOD, CurveStyle::Markers),
        (Result3::Inaccurate, style::BETWEEN, CurveStyle::Triangles),
        (Result3::BrokeDown, style::BAD, CurveStyle::Crosses),
    ] {
        curves.push(Curve {
            label: match outcome {
                Result3::Stable => format!("stable (L2 ≤ {accuracy})"),
                other => other.name().to_string(),
            },
            points: rows
                .iter()
                .filter(|r| r.outcome == outcome)
                .map(|r| (r.wi, level(&r.variant)))
                .collect(),
            style: marker,
            color,
        });
    }
    for (k, name) in names.iter().enumerate() {
        // Stable up to the first Wi that is not, and any stable Wi above it (stability need not
        // be monotone in Wi within a fixed end time).
        let mut runs: Vec<&Row> = rows
            .iter()
            .copied()
            .filter(|r| &r.variant == name)
            .collect();
        runs.sort_by(|a, b| a.wi.total_cmp(&b.wi));
        let first_failure = runs.iter().position(|r| r.outcome != Result3::Stable);
        let upto = match first_failure {
            None => format!(
                "stable at every Wi to {}",
                runs.last().map_or(f64::NAN, |r| r.wi)
            ),
            Some(0) => "not stable at any Wi".into(),
            Some(k) => format!("stable to Wi {}", runs[k - 1].wi),
        };
        let again: Vec<String> = first_failure
            .map(|k| {
                runs[k..]
                    .iter()
                    .filter(|r| r.outcome == Result3::Stable)
                    .map(|r| r.wi.to_string())
                    .collect()
            })
            .unwrap_or_default();
        let again = if again.is_empty() {
            String::new()
        } else {
            format!(", again at {}", again.join(", "))
        };
        curves.push(Curve {
            label: format!("{}: {upto}{again}", display(name, k)),
            points: Vec::new(),
            style: CurveStyle::Line,
            color: style::PALETTE[7],
        });
    }
    // Room above the rows for the legend (three outcomes and one line per row).
    let n = names.len() as f64;
    let y_range = Some((-0.5, (n - 0.5) + 0.25 * (n + 3.0) + 0.5));
    plot::draw(
        &out.join("stability_map.png"),
        format,
        &Chart {
            title: "Stability map".into(),
            x_label: "Wi".into(),
            y_label: "variant".into(),
            log_x: true,
            y_range,
            y_categories: names
                .iter()
                .enumerate()
                .map(|(k, n)| display(n, k))
                .collect(),
            ..Default::default()
        },
        &curves,
    )
}

/// A variant's name on the map (the base case has none).
fn display(name: &str, k: usize) -> String {
    if name.is_empty() {
        format!("variant {k}")
    } else {
        name.to_string()
    }
}
