//! `rheosph study cylinder`: a channel with a cylinder over a range of Weissenberg numbers
//! (λ = Wi·R/⟨u⟩), each run to steady state and averaged (`[run.steady]`). Writes
//! `cylinder.csv` (one line per Wi), the centre-line profiles of all runs overlaid
//! (u/⟨u⟩, τ_xx/(η_s⟨u⟩/R), det A) and K against Wi, beside published values if given.

use super::{run_all, Base, Variant};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use anyhow::{Context, Result};
use plotters::style::RGBColor;
use std::fmt::Write as _;
use std::path::Path;

/// One line of `cylinder.csv`.
#[derive(Clone, Debug)]
pub struct Row {
    pub wi: f64,
    /// R/δr.
    pub radius_over_dr: f64,
    pub outcome: String,
    pub t_reached: f64,
    pub steady_at: Option<f64>,
    pub u_mean: f64,
    /// K from the momentum balance; the surface integral's K and its pressure, solvent and
    /// polymer parts.
    pub drag_k: f64,
    pub drag_k_surface: f64,
    pub k_parts: [f64; 3],
    pub peak_tau_xx: f64,
    /// Smallest det A over the averaging window, and over every output of the run.
    pub min_det_a: f64,
    pub min_det_a_run: f64,
    pub particles: usize,
    pub steps: u64,
    pub wall_seconds: f64,
}

/// Published (Wi, K) pairs from a CSV with a header and columns `wi,k` (extra columns and
/// `#` comment lines are ignored).
pub fn read_reference(path: &Path) -> Result<Vec<(f64, f64)>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut out = Vec::new();
    for (n, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#'))
        .skip(1)
    {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        let parse = |k: usize| -> Result<f64> {
            f.get(k)
                .and_then(|v| v.parse().ok())
                .with_context(|| format!("{}: line {}: expected wi,k", path.display(), n + 1))
        };
        out.push((parse(0)?, parse(1)?));
    }
    Ok(out)
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
    let mut rows = Vec::new();
    let stages = sequence.iter().map(|&r| Some(r)).chain([None]);
    for stage in stages {
        let variants = wis
            .iter()
            .zip(&from)
            .map(|(&wi, from)| variant(wi, wi * lambda_per_wi, stage, from.clone()))
            .collect();
        let finished = run_all(base, variants, out, jobs, quiet)?;
        rows.extend(finished.iter().zip(wis).map(|(f, &wi)| row(f, wi, radius)));
        from = finished.iter().map(|f| Some(f.dir.clone())).collect();
        if stage.is_none() {
            let profiles: Vec<(f64, Vec<[f64; 4]>)> = finished
                .iter()
                .zip(wis)
                .map(|(f, &wi)| {
                    let text = std::fs::read_to_string(f.dir.join("centreline.csv"));
                    let text = text.unwrap_or_default();
                    (wi, crate::analysis::centreline::parse_csv(&text))
                })
                .collect();
            let finest: Vec<Row> = rows[rows.len() - wis.len()..].to_vec();
            charts(out, format, &finest, &profiles, reference)?;
        }
    }
    crate::app::io::write_atomic(&out.join("cylinder.csv"), csv(&rows).as_bytes())?;
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
        k_parts: st.map_or([f64::NAN; 3], |x| [x.k_pressure, x.k_solvent, x.k_polymer]),
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
    profiles: &[(f64, Vec<[f64; 4]>)],
    reference: Option<&[(f64, f64)]>,
) -> Result<()> {
    let labelled: Vec<(String, Vec<[f64; 4]>)> = profiles
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
/// of labelled profiles (rows s, u/⟨u⟩, τ_xx/(η_s⟨u⟩/R), det A of `centreline.csv`), one
/// curve each: the study's charts, and `compare-centrelines` for any set of runs.
pub fn centreline_charts(
    out: &Path,
    format: FigureFormat,
    profiles: &[(String, Vec<[f64; 4]>)],
) -> Result<()> {
    // det A spans orders of magnitude over Wi (≥ 1 for Oldroyd-B): a log axis.
    for (k, name, y, log_y) in [
        (1, "centreline_u", "u/<u>", false),
        (2, "centreline_tau_xx", "tau_xx/(eta_s <u>/R)", false),
        (3, "centreline_det_a", "det A", true),
    ] {
        let curves: Vec<Curve> = profiles
            .iter()
            .enumerate()
            .map(|(c, (label, p))| Curve {
                label: label.clone(),
                points: p.iter().map(|q| (q[0], q[k])).collect(),
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

fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "wi,radius_over_dr,outcome,t_reached,steady_at,u_mean,drag_k,drag_k_surface,k_pressure,k_solvent,k_polymer,peak_tau_xx_centreline,min_det_a,min_det_a_run,particles,steps,wall_seconds\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{},{:.4},{},{:.6e},{},{:.8e},{:.8e},{:.8e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{},{},{:.3}",
            r.wi,
            r.radius_over_dr,
            r.outcome,
            r.t_reached,
            r.steady_at.map_or(String::new(), |t| format!("{t:.6e}")),
            r.u_mean,
            r.drag_k,
            r.drag_k_surface,
            r.k_parts[0],
            r.k_parts[1],
            r.k_parts[2],
            r.peak_tau_xx,
            r.min_det_a,
            r.min_det_a_run,
            r.particles,
            r.steps,
            r.wall_seconds
        );
    }
    s
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
