//! `rheosph study cylinder`: a channel with a cylinder over a range of Weissenberg numbers
//! (λ = Wi·R/⟨u⟩), each run to steady state and averaged (`[run.steady]`). Writes
//! `cylinder.csv` (one line per Wi), the centre-line profiles of all runs overlaid
//! (u/⟨u⟩, τ_xx/(η_s⟨u⟩/R), det A) and K against Wi, beside published values if given.
//! A member `--collect` finds without a finished run is a `lost` or `failed` line, not drawn.

use super::{member_dir, run_all, Base, Missing, Variant};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::app::run::probes::centreline::{CentrelineColumn, CentrelineRow};
use crate::app::table::{self, fmt};
use anyhow::Result;
use plotters::style::RGBColor;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One line of `cylinder.csv`.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Row {
    #[serde(serialize_with = "fmt::plain")]
    pub wi: f64,
    /// R/δr.
    #[serde(default = "table::nan", serialize_with = "fmt::fixed4")]
    pub radius_over_dr: f64,
    pub outcome: String,
    #[serde(serialize_with = "fmt::sci6")]
    pub t_reached: f64,
    #[serde(serialize_with = "fmt::opt_sci6")]
    pub steady_at: Option<f64>,
    #[serde(serialize_with = "fmt::sci8")]
    pub u_mean: f64,
    /// K from the momentum balance; the surface integral's K and its pressure, solvent and
    /// polymer parts.
    #[serde(serialize_with = "fmt::sci8")]
    pub drag_k: f64,
    #[serde(default = "table::nan", serialize_with = "fmt::sci8")]
    pub drag_k_surface: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub k_pressure: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub k_solvent: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub k_polymer: f64,
    #[serde(rename = "peak_tau_xx_centreline", serialize_with = "fmt::sci6")]
    pub peak_tau_xx: f64,
    /// Smallest det A over the averaging window, and over every output of the run.
    #[serde(serialize_with = "fmt::sci6")]
    pub min_det_a: f64,
    #[serde(default = "table::nan", serialize_with = "fmt::sci6")]
    pub min_det_a_run: f64,
    pub particles: usize,
    pub steps: u64,
    #[serde(serialize_with = "fmt::fixed3")]
    pub wall_seconds: f64,
}

/// A row of a published drag table (`--reference`): Wi and K, by name (other columns are
/// ignored).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct ReferenceRow {
    pub wi: f64,
    pub k: f64,
}

/// Published (Wi, K) pairs from a CSV with a header and columns `wi,k` (extra columns and
/// `#` comment lines are ignored).
pub fn read_reference(path: &Path) -> Result<Vec<(f64, f64)>> {
    let rows: Vec<ReferenceRow> = table::read_rows_commented(path)?;
    Ok(rows.iter().map(|r| (r.wi, r.k)).collect())
}

fn colour(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// A coarser stage of grid sequencing: its `scene.resolution` and, if given, its end time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stage {
    pub resolution: usize,
    pub end_time: Option<f64>,
}

/// `resolution` or `resolution:end_time`, e.g. `36:60`.
pub fn parse_stage(arg: &str) -> Result<Stage, String> {
    let (r, t) = match arg.split_once(':') {
        Some((r, t)) => (r, Some(t)),
        None => (arg, None),
    };
    let resolution = r
        .trim()
        .parse()
        .map_err(|_| format!("{arg:?}: expected a resolution, or resolution:end_time"))?;
    let end_time = t
        .map(|t| t.trim().parse::<f64>())
        .transpose()
        .ok()
        .flatten()
        .filter(|t| *t > 0.0);
    if t.is_some() && end_time.is_none() {
        return Err(format!("{arg:?}: the end time must be a positive number"));
    }
    Ok(Stage {
        resolution,
        end_time,
    })
}

/// Runs the case at every Wi and writes the study files. Returns the rows: with `sequence`
/// (coarser `scene.resolution`s, coarsest first), each Wi runs at those first, each run
/// starting from the previous one's final state (grid sequencing, `run --from`), and the
/// rows hold every stage; the charts show the case's own resolution.
#[allow(clippy::too_many_arguments)]
pub fn run(
    base: &Base,
    wis: &[f64],
    sequence: &[Stage],
    reference: Option<&[(f64, f64)]>,
    out: &Path,
    format: FigureFormat,
    jobs: usize,
    quiet: bool,
) -> Result<Vec<Row>> {
    let scale = base.case(&[])?;
    anyhow::ensure!(
        scale.scene.cylinder().is_some(),
        "{}: the cylinder study needs a case with [scene.cylinder]",
        base.path.display()
    );
    let radius = scale.scene.length_scale();
    let lambda_per_wi = radius / scale.derived().velocity_scale;
    let mut from: Vec<Option<std::path::PathBuf>> = vec![None; wis.len()];
    let (mut rows, mut missing, mut members) = (Vec::new(), Vec::new(), 0);
    let stages = sequence.iter().map(|&r| Some(r)).chain([None]);
    for stage in stages {
        let variants: Vec<Variant> = wis
            .iter()
            .zip(&from)
            .map(|(&wi, from)| variant(wi, wi * lambda_per_wi, stage, from.clone()))
            .collect();
        from = variants.iter().map(|v| Some(member_dir(out, v))).collect();
        let stage_members = run_all(base, variants, out, jobs, quiet)?;
        let finished = &stage_members.finished;
        rows.extend(finished.iter().map(|f| row(f, wi_of(&f.variant), radius)));
        rows.extend(stage_members.missing.iter().map(|m| missing_row(m, radius)));
        if stage.is_none() {
            // A run that broke down before its steady window has no centre-line file: no curve.
            let profiles: Vec<(f64, Vec<CentrelineRow>)> = finished
                .iter()
                .map(|f| {
                    let rows = table::read_rows(&f.dir.join("centreline.csv"));
                    (wi_of(&f.variant), rows.unwrap_or_default())
                })
                .collect();
            let finest: Vec<Row> = rows[rows.len() - wis.len()..].to_vec();
            charts(out, format, &finest, &profiles, reference)?;
        }
        members += finished.len() + stage_members.missing.len();
        missing.extend(stage_members.missing);
    }
    crate::app::io::write_atomic(
        &out.join("cylinder.csv"),
        table::write_rows(&rows).as_bytes(),
    )?;
    super::Incomplete::check(&missing, members, out, base.executor)?;
    Ok(rows)
}

/// The run at `wi` (relaxation time `lambda`), at a coarser `stage` (None: the case's
/// resolution), started from `from` if given.
fn variant(
    wi: f64,
    lambda: f64,
    stage: Option<Stage>,
    from: Option<std::path::PathBuf>,
) -> Variant {
    // Wi = 0 is the Newtonian limit of the same fluid (η0 unchanged).
    let mut overrides = if wi == 0.0 {
        [
            "fluid.model=newtonian",
            "fluid.relaxation_time=0",
            "fluid.beta=1",
        ]
        .map(String::from)
        .to_vec()
    } else {
        vec![format!("fluid.relaxation_time={lambda}")]
    };
    let mut label = format!("Wi={wi}");
    if let Some(stage) = stage {
        let r = stage.resolution;
        overrides.push(format!("scene.resolution={r}"));
        label.push_str(&format!(" resolution={r}"));
        if let Some(t) = stage.end_time {
            overrides.push(format!("run.end_time={t}"));
        }
    }
    Variant {
        label,
        overrides,
        tags: vec![("wi".into(), format!("{wi}"))],
        from,
    }
}

/// A member's Wi (its tag).
fn wi_of(variant: &Variant) -> f64 {
    variant
        .tags
        .iter()
        .find(|(k, _)| k == "wi")
        .and_then(|(_, v)| v.parse().ok())
        .unwrap_or(f64::NAN)
}

/// The `cylinder.csv` line of a member without a finished run (`lost` or `failed`): its Wi
/// and R/δr, no numbers.
fn missing_row(m: &Missing, radius: f64) -> Row {
    Row {
        wi: wi_of(&m.variant),
        radius_over_dr: radius / m.case.derived().particle_spacing,
        outcome: m.outcome().into(),
        t_reached: f64::NAN,
        steady_at: None,
        u_mean: f64::NAN,
        drag_k: f64::NAN,
        drag_k_surface: f64::NAN,
        k_pressure: f64::NAN,
        k_solvent: f64::NAN,
        k_polymer: f64::NAN,
        peak_tau_xx: f64::NAN,
        min_det_a: f64::NAN,
        min_det_a_run: f64::NAN,
        particles: 0,
        steps: 0,
        wall_seconds: f64::NAN,
    }
}

/// The `cylinder.csv` line of a finished run; `radius` is R.
fn row(f: &super::Finished, wi: f64, radius: f64) -> Row {
    let s = &f.summary;
    let st = s.steady();
    let st = st.as_ref();
    Row {
        wi,
        radius_over_dr: radius / s.derived.particle_spacing,
        outcome: format!("{:?}", s.outcome),
        t_reached: s.t_reached,
        steady_at: st.and_then(|x| x.reached_at),
        u_mean: st.map_or(f64::NAN, |x| x.u_mean),
        drag_k: st.map_or(f64::NAN, |x| x.drag_k),
        drag_k_surface: st.map_or(f64::NAN, |x| x.drag_k_surface),
        k_pressure: st.map_or(f64::NAN, |x| x.k_pressure),
        k_solvent: st.map_or(f64::NAN, |x| x.k_solvent),
        k_polymer: st.map_or(f64::NAN, |x| x.k_polymer),
        peak_tau_xx: st.map_or(f64::NAN, |x| x.peak_tau_xx_centreline),
        min_det_a: st.map_or(f64::NAN, |x| x.min_det_a),
        min_det_a_run: f
            .series
            .iter()
            .map(|r| r.min_det_a)
            .fold(f64::NAN, f64::min),
        particles: s.particles,
        steps: s.steps,
        wall_seconds: s.wall_seconds,
    }
}

/// The study's charts: centre-line profiles at every Wi, and K against Wi beside the
/// published values.
fn charts(
    out: &Path,
    format: FigureFormat,
    rows: &[Row],
    profiles: &[(f64, Vec<CentrelineRow>)],
    reference: Option<&[(f64, f64)]>,
) -> Result<()> {
    let labelled: Vec<(String, Vec<CentrelineRow>)> = profiles
        .iter()
        .map(|(wi, p)| (format!("Wi = {wi}"), p.clone()))
        .collect();
    centreline_charts(out, format, &labelled)?;
    let mut curves = vec![Curve {
        label: "rheosph".into(),
        points: rows
            .iter()
            // A run that broke down has no steady drag to draw (the table keeps its row).
            .filter(|r| r.drag_k.is_finite() && r.outcome == "Finished")
            .map(|r| (r.wi, r.drag_k))
            .collect(),
        style: CurveStyle::Line,
        color: PALETTE[0],
    }];
    if let Some(reference) = reference {
        curves.push(Curve {
            label: "published".into(),
            points: reference.to_vec(),
            style: CurveStyle::Markers,
            color: PALETTE[1],
        });
    }
    plot::draw(
        &out.join("drag_vs_wi.png"),
        format,
        &Chart {
            title: "Drag coefficient K = F_x/(eta0 <u>)".into(),
            x_label: "Wi".into(),
            y_label: "K".into(),
            ..Default::default()
        },
        &curves,
    )?;
    Ok(())
}

/// The three centre-line charts (`centreline_u`, `centreline_tau_xx`, `centreline_det_a`)
/// of labelled profiles (the rows of each run's `centreline.csv`), one
/// curve each: the study's charts, and `compare-centrelines` for any set of runs.
pub fn centreline_charts(
    out: &Path,
    format: FigureFormat,
    profiles: &[(String, Vec<CentrelineRow>)],
) -> Result<()> {
    // det A spans orders of magnitude over Wi (≥ 1 for Oldroyd-B): a log axis.
    let columns: [(CentrelineColumn, &str, &str, bool); 3] = [
        (|r| r.u_over_umean, "centreline_u", "u/<u>", false),
        (
            |r| r.tau_xx_scaled,
            "centreline_tau_xx",
            "tau_xx/(eta_s <u>/R)",
            false,
        ),
        (|r| r.det_a, "centreline_det_a", "det A", true),
    ];
    for (value, name, y, log_y) in columns {
        let curves: Vec<Curve> = profiles
            .iter()
            .enumerate()
            .map(|(c, (label, p))| Curve {
                label: label.clone(),
                points: p.iter().map(|q| (q.s, value(q))).collect(),
                style: CurveStyle::Line,
                color: colour(c),
            })
            .collect();
        plot::draw(
            &out.join(format!("{name}.png")),
            format,
            &Chart {
                title: format!("Centre-line between cylinders: {y}"),
                x_label: "s (0: downstream edge of a cylinder)".into(),
                y_label: y.into(),
                log_y,
                ..Default::default()
            },
            &curves,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_is_a_resolution_with_an_optional_end_time() {
        let stage = |r, t| Stage {
            resolution: r,
            end_time: t,
        };
        assert_eq!(parse_stage("36"), Ok(stage(36, None)));
        assert_eq!(parse_stage("72:20"), Ok(stage(72, Some(20.0))));
        assert!(parse_stage("72:").is_err());
        assert!(parse_stage("72:-1").is_err());
        assert!(parse_stage("fine").is_err());
    }
}
