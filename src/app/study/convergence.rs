//! `rheosph study convergence`: the case at several resolutions (and frames), the L2 error
//! against time for every run on one chart, the time-mean and final L2 error against δr on
//! log–log axes with the fitted order, and `convergence.csv`.

use super::{fitted_order, run_all, Base, Finished, Missing, Variant};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::app::table::{self, fmt};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One line of `convergence.csv`.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Row {
    pub frame: String,
    pub resolution: usize,
    #[serde(serialize_with = "fmt::sci6")]
    pub spacing: f64,
    pub particles: usize,
    pub steps: u64,
    #[serde(serialize_with = "fmt::fixed3")]
    pub wall_seconds: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub l2_mean: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub l2_final: f64,
    /// Order of l2_mean against the next coarser resolution of the same frame.
    #[serde(serialize_with = "fmt::opt_fixed3")]
    pub order: Option<f64>,
    /// `finished` or `broke_down` (the run's), or `lost` / `failed` for a member `--collect`
    /// found without a finished run (no numbers).
    #[serde(default)]
    pub outcome: String,
    /// A pipe's wall shear stress at the end, fitted from the particles, and the series'
    /// (empty for other scenes).
    #[serde(serialize_with = "fmt::opt_sci6", default)]
    pub wall_shear_stress: Option<f64>,
    #[serde(serialize_with = "fmt::opt_sci6", default)]
    pub wall_shear_stress_exact: Option<f64>,
    /// fitted/series − 1.
    #[serde(serialize_with = "fmt::opt_sci3", default)]
    pub wall_shear_stress_error: Option<f64>,
}

impl Row {
    /// The row of a member without a finished run: its frame and resolution, no numbers.
    fn missing(m: &Missing) -> Self {
        Row {
            frame: tag(&m.variant, "frame"),
            resolution: m.case.scene.resolution(),
            spacing: m.case.scene.spacing(),
            wall_seconds: f64::NAN,
            l2_mean: f64::NAN,
            l2_final: f64::NAN,
            outcome: m.outcome().into(),
            ..Default::default()
        }
    }
}

/// The value of a variant's tag (empty if it has none).
fn tag(variant: &Variant, key: &str) -> String {
    variant
        .tags
        .iter()
        .find(|(k, _)| k == key)
        .map_or(String::new(), |(_, v)| v.clone())
}

/// Runs the study and writes `convergence.csv`, `l2_vs_time.png`, `l2_vs_resolution.png`.
pub fn run(
    base: &Base,
    resolutions: &[usize],
    frames: &[String],
    out: &Path,
    format: FigureFormat,
    jobs: usize,
    quiet: bool,
) -> Result<Vec<Row>> {
    let mut variants = Vec::new();
    for frame in frames {
        for r in resolutions {
            variants.push(Variant {
                label: format!("{frame} {r}"),
                overrides: vec![
                    format!("scheme.frame={frame}"),
                    format!("scene.resolution={r}"),
                ],
                tags: vec![("frame".into(), frame.clone())],
                from: None,
            });
        }
    }
    let members = run_all(base, variants, out, jobs, quiet)?;
    let mut rows = table(&members.finished, frames);
    let ran = rows.len();
    rows.extend(members.missing.iter().map(Row::missing));
    let csv = table::write_rows(&rows);
    crate::app::io::write_atomic(&out.join("convergence.csv"), csv.as_bytes())?;
    // The charts show the members that ran.
    charts(&members.finished, &rows[..ran], frames, out, format)?;
    members.check_complete(out)?;
    Ok(rows)
}

fn table(finished: &[Finished], frames: &[String]) -> Vec<Row> {
    let mut rows = Vec::new();
    for frame in frames {
        let mut previous: Option<(f64, f64)> = None;
        let mut runs: Vec<&Finished> = finished
            .iter()
            .filter(|f| {
                f.variant
                    .tags
                    .iter()
                    .any(|(k, v)| k == "frame" && v == frame)
            })
            .collect();
        runs.sort_by_key(|f| f.case.scene.resolution());
        for f in runs {
            let s = &f.summary;
            let spacing = f.case.scene.spacing();
            let l2_mean = s.errors.l2_time_mean.unwrap_or(f64::NAN);
            let order = previous.map(|(dr, l2)| (l2 / l2_mean).ln() / (dr / spacing).ln());
            previous = Some((spacing, l2_mean));
            rows.push(Row {
                frame: frame.clone(),
                resolution: f.case.scene.resolution(),
                spacing,
                particles: s.particles,
                steps: s.steps,
                wall_seconds: s.wall_seconds,
                l2_mean,
                l2_final: s.errors.l2_final.unwrap_or(f64::NAN),
                order,
                outcome: s.outcome.name().into(),
                wall_shear_stress: s.errors.wall_shear_stress,
                wall_shear_stress_exact: s.errors.wall_shear_stress_exact,
                wall_shear_stress_error: s
                    .errors
                    .wall_shear_stress
                    .zip(s.errors.wall_shear_stress_exact)
                    .map(|(fitted, exact)| fitted / exact - 1.0),
            });
        }
    }
    rows
}

fn charts(
    finished: &[Finished],
    rows: &[Row],
    frames: &[String],
    out: &Path,
    format: FigureFormat,
) -> Result<()> {
    super::draw_l2_histories(finished, out, format)?;
    let mut curves = Vec::new();
    for (k, frame) in frames.iter().enumerate() {
        let pts: Vec<&Row> = rows.iter().filter(|r| &r.frame == frame).collect();
        let mean: Vec<(f64, f64)> = pts.iter().map(|r| (r.spacing, r.l2_mean)).collect();
        let last: Vec<(f64, f64)> = pts.iter().map(|r| (r.spacing, r.l2_final)).collect();
        let order =
            |p: &[(f64, f64)]| fitted_order(p).map_or("-".to_string(), |o| format!("{o:.2}"));
        curves.push(Curve {
            label: format!("{frame}, time mean: order {}", order(&mean)),
            points: mean,
            style: CurveStyle::Line,
            color: PALETTE[2 * k % PALETTE.len()],
        });
        curves.push(Curve {
            label: format!("{frame}, final: order {}", order(&last)),
            points: last,
            style: CurveStyle::Dashed,
            color: PALETTE[(2 * k + 1) % PALETTE.len()],
        });
    }
    plot::draw(
        &out.join("l2_vs_resolution.png"),
        format,
        &Chart {
            title: "Convergence of the velocity L2 error".into(),
            x_label: "dr / H".into(),
            y_label: "L2 error / U".into(),
            log_x: true,
            log_y: true,
            ..Default::default()
        },
        &curves,
    )
}
