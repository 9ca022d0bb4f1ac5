//! `rheosph study speed-accuracy`: wall time against L2 error, one point per configuration
//! (resolution × variant), with the Pareto front: the cheapest configuration for each
//! required accuracy; and each run's error at every output against the first variant's at
//! the same resolution (the largest ratio, `max_output_ratio`; `l2_vs_time.png`), since a
//! time-mean can hide a start-up that a cheaper scheme gets wrong.

use super::{run_all, Base, Missing, Variant};
use crate::app::io::SeriesRow;
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::app::table::{self, fmt};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One configuration's cost and error: a line of `speed_accuracy.csv`.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Point {
    pub label: String,
    /// The `--vary` part of the label (without the resolution); not a column.
    #[serde(skip)]
    pub variant: String,
    pub resolution: usize,
    pub particles: usize,
    pub steps: u64,
    #[serde(serialize_with = "fmt::fixed3")]
    pub wall_seconds: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub l2_mean: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub l2_final: f64,
    pub pareto: bool,
    /// The largest ratio of this run's L2 error to the first variant's at the same
    /// resolution, over the outputs (t > 0) within both runs, and the time it occurs (NaN:
    /// no common output).
    #[serde(default = "table::nan", serialize_with = "fmt::fixed4")]
    pub max_output_ratio: f64,
    #[serde(default = "table::nan", serialize_with = "fmt::fixed4")]
    pub ratio_at: f64,
    /// `finished` or `broke_down` (the run's), or `lost` / `failed` for a member `--collect`
    /// found without a finished run (no numbers, not drawn).
    #[serde(default)]
    pub outcome: String,
}

impl Point {
    /// The point of a member without a finished run: its label and resolution, no numbers.
    fn missing(m: &Missing) -> Self {
        Point {
            label: m.variant.label.clone(),
            variant: variant_of(&m.variant),
            resolution: m.case.scene.resolution(),
            wall_seconds: f64::NAN,
            l2_mean: f64::NAN,
            l2_final: f64::NAN,
            max_output_ratio: f64::NAN,
            ratio_at: f64::NAN,
            outcome: m.outcome().into(),
            ..Default::default()
        }
    }
}

/// The `--vary` part of a member's label (its `variant` tag).
fn variant_of(v: &Variant) -> String {
    v.tags
        .iter()
        .find(|(k, _)| k == "variant")
        .map_or(String::new(), |(_, v)| v.clone())
}

/// The largest ratio of `run`'s L2 error to `reference`'s, the reference interpolated
/// linearly in t to the run's outputs, over the outputs with t > 0 inside the reference's
/// span where both are finite and the reference positive; (ratio, t), NaN when none.
pub fn max_output_ratio(run: &[SeriesRow], reference: &[SeriesRow]) -> (f64, f64) {
    let rows: Vec<(f64, f64)> = reference
        .iter()
        .filter(|r| r.t > 0.0 && r.l2_error.is_finite())
        .map(|r| (r.t, r.l2_error))
        .collect();
    let at = |t: f64| {
        let k = rows.partition_point(|&(s, _)| s < t);
        match (rows.get(k.wrapping_sub(1)), rows.get(k)) {
            (_, Some(&(s, e))) if s == t => Some(e),
            (Some(&(s0, e0)), Some(&(s1, e1))) => Some(e0 + (e1 - e0) * (t - s0) / (s1 - s0)),
            _ => None,
        }
    };
    run.iter()
        .filter(|r| r.t > 0.0 && r.l2_error.is_finite())
        .filter_map(|r| at(r.t).filter(|&e| e > 0.0).map(|e| (r.l2_error / e, r.t)))
        .fold((f64::NAN, f64::NAN), |best, q| {
            if best.0.is_nan() || q.0 > best.0 {
                q
            } else {
                best
            }
        })
}

/// Marks the points no other point beats in both wall time and error.
fn mark_pareto(points: &mut [Point]) {
    for i in 0..points.len() {
        let (t, e) = (points[i].wall_seconds, points[i].l2_mean);
        points[i].pareto = e.is_finite()
            && !points.iter().any(|q| {
                q.wall_seconds <= t && q.l2_mean <= e && (q.wall_seconds < t || q.l2_mean < e)
            });
    }
}

/// Runs the study and writes `speed_accuracy.csv` and `speed_accuracy.png`.
pub fn run(
    base: &Base,
    resolutions: &[usize],
    schemes: &[Variant],
    out: &Path,
    format: FigureFormat,
    jobs: usize,
    quiet: bool,
) -> Result<Vec<Point>> {
    let mut variants = Vec::new();
    for v in schemes {
        for r in resolutions {
            let mut w: Variant = v.clone();
            w.overrides.push(format!("scene.resolution={r}"));
            w.label = format!("{} H/dr={r}", v.label).trim().to_string();
            w.tags.push(("variant".into(), v.label.clone()));
            variants.push(w);
        }
    }
    let members = run_all(base, variants, out, jobs, quiet)?;
    let finished = &members.finished;
    // The reference of the output ratio: the first variant's run (NaN if it is missing).
    let first = schemes.first().map_or(String::new(), |v| v.label.clone());
    let mut points: Vec<Point> = finished
        .iter()
        .map(|f| {
            let ratio = finished
                .iter()
                .filter(|g| variant_of(&g.variant) == first)
                .find(|g| g.case.scene.resolution() == f.case.scene.resolution())
                .map_or((f64::NAN, f64::NAN), |g| {
                    max_output_ratio(&f.series, &g.series)
                });
            Point {
                label: f.variant.label.clone(),
                variant: variant_of(&f.variant),
                resolution: f.case.scene.resolution(),
                wall_seconds: f.summary.wall_seconds,
                l2_mean: f.summary.errors.l2_time_mean.unwrap_or(f64::NAN),
                l2_final: f.summary.errors.l2_final.unwrap_or(f64::NAN),
                particles: f.summary.particles,
                steps: f.summary.steps,
                pareto: false,
                max_output_ratio: ratio.0,
                ratio_at: ratio.1,
                outcome: f.summary.outcome.name().into(),
            }
        })
        .collect();
    mark_pareto(&mut points);
    // Members without a run: rows of the table, after the Pareto marking and not drawn.
    let ran = points.len();
    points.extend(members.missing.iter().map(Point::missing));
    let csv = table::write_rows(&points);
    super::draw_l2_histories(finished, out, format)?;
    crate::app::io::write_atomic(&out.join("speed_accuracy.csv"), csv.as_bytes())?;
    let ran = &points[..ran];
    let mut front: Vec<(f64, f64)> = ran
        .iter()
        .filter(|p| p.pareto)
        .map(|p| (p.wall_seconds, p.l2_mean))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut curves = vec![Curve {
        label: "Pareto front".into(),
        points: front,
        style: CurveStyle::Line,
        color: PALETTE[0],
    }];
    for (k, v) in schemes.iter().enumerate() {
        curves.push(Curve {
            label: if v.label.is_empty() {
                "runs".into()
            } else {
                v.label.clone()
            },
            points: ran
                .iter()
                .filter(|p| p.variant == v.label)
                .map(|p| (p.wall_seconds, p.l2_mean))
                .collect(),
            style: CurveStyle::Markers,
            color: PALETTE[(k + 1) % PALETTE.len()],
        });
    }
    plot::draw(
        &out.join("speed_accuracy.png"),
        format,
        &Chart {
            title: "Wall time against accuracy".into(),
            x_label: "wall seconds".into(),
            y_label: "time-mean L2 error / U".into(),
            log_x: true,
            log_y: true,
            ..Default::default()
        },
        &curves,
    )?;
    members.check_complete(out)?;
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_keeps_undominated_points() {
        let p = |t: f64, e: f64| Point {
            label: String::new(),
            variant: String::new(),
            resolution: 0,
            wall_seconds: t,
            l2_mean: e,
            l2_final: e,
            particles: 0,
            steps: 0,
            pareto: false,
            max_output_ratio: f64::NAN,
            ratio_at: f64::NAN,
            outcome: String::new(),
        };
        let mut pts = vec![p(1.0, 0.1), p(2.0, 0.05), p(3.0, 0.2), p(4.0, 0.01)];
        mark_pareto(&mut pts);
        let front: Vec<bool> = pts.iter().map(|p| p.pareto).collect();
        assert_eq!(front, vec![true, true, false, true]);
    }

    /// The ratio is taken at the run's outputs against the reference interpolated there;
    /// t = 0, outputs past the reference's last and a zero reference are skipped.
    #[test]
    fn the_output_ratio_interpolates_the_reference_and_finds_the_largest() {
        let row = |t: f64, e: f64| SeriesRow {
            t,
            l2_error: e,
            ..Default::default()
        };
        let reference = [
            row(0.0, 0.0),
            row(1.0, 0.01),
            row(2.0, 0.03),
            row(3.0, 0.02),
        ];
        let run = [
            row(0.0, 0.0),
            row(0.5, 0.04),
            row(1.5, 0.03),
            row(2.0, 0.036),
            row(4.0, 1.0),
        ];
        let (ratio, at) = max_output_ratio(&run, &reference);
        // 0.5 lies before the reference's first positive output; 1.5: 0.03/0.02 = 1.5;
        // 2.0: 1.2; 4.0 is past the reference.
        assert!((ratio - 1.5).abs() < 1e-12 && at == 1.5, "{ratio} at {at}");
        assert!(max_output_ratio(&run, &[]).0.is_nan());
    }
}
