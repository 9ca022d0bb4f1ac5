//! `rheosph study speed-accuracy`: wall time against L2 error, one point per configuration
//! (resolution × variant), with the Pareto front: the cheapest configuration for each
//! required accuracy.

use super::{run_all, Base, Variant};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

/// One configuration's cost and error.
pub struct Point {
    pub label: String,
    /// The `--vary` part of the label (without the resolution).
    pub variant: String,
    pub resolution: usize,
    pub wall_seconds: f64,
    pub l2_mean: f64,
    pub l2_final: f64,
    pub particles: usize,
    pub steps: u64,
    pub pareto: bool,
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
    let finished = run_all(base, variants, out, jobs, quiet)?;
    let mut points: Vec<Point> = finished
        .iter()
        .map(|f| Point {
            label: f.variant.label.clone(),
            variant: f
                .variant
                .tags
                .iter()
                .find(|(k, _)| k == "variant")
                .map_or(String::new(), |(_, v)| v.clone()),
            resolution: f.case.scene.resolution(),
            wall_seconds: f.summary.wall_seconds,
            l2_mean: f.summary.errors.l2_time_mean.unwrap_or(f64::NAN),
            l2_final: f.summary.errors.l2_final.unwrap_or(f64::NAN),
            particles: f.summary.particles,
            steps: f.summary.steps,
            pareto: false,
        })
        .collect();
    mark_pareto(&mut points);
    let mut csv =
        String::from("label,resolution,particles,steps,wall_seconds,l2_mean,l2_final,pareto\n");
    for p in &points {
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.3},{:.6e},{:.6e},{}",
            p.label,
            p.resolution,
            p.particles,
            p.steps,
            p.wall_seconds,
            p.l2_mean,
            p.l2_final,
            p.pareto
        );
    }
    crate::app::io::write_atomic(&out.join("speed_accuracy.csv"), csv.as_bytes())?;
    let mut front: Vec<(f64, f64)> = points
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
            points: points
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
        };
        let mut pts = vec![p(1.0, 0.1), p(2.0, 0.05), p(3.0, 0.2), p(4.0, 0.01)];
        mark_pareto(&mut pts);
        let front: Vec<bool> = pts.iter().map(|p| p.pareto).collect();
        assert_eq!(front, vec![true, true, false, true]);
    }
}
