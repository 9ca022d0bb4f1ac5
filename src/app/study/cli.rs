//! Dispatch of `rheosph study ...`: arguments into a [`Base`] and the study's settings.

use super::{convergence, cylinder, parse_vary, speed_accuracy, stability, Base};
use crate::app::cli::{StudyCommand, StudyCommon};
use anyhow::Result;
use std::path::PathBuf;

fn base_and_out(common: &StudyCommon, study: &str) -> Result<(Base, PathBuf)> {
    let base = Base {
        path: common.case.case.clone(),
        sets: common.case.set.clone(),
    };
    let case = base.case(&[])?;
    let out = common
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{study}-{}", case.name)));
    Ok((base, out))
}

pub fn dispatch(command: StudyCommand, quiet: bool) -> Result<()> {
    match command {
        StudyCommand::Convergence(a) => {
            let (base, out) = base_and_out(&a.common, "convergence")?;
            let rows =
                convergence::run(&base, &a.resolutions, &a.frames, &out, a.common.jobs, quiet)?;
            if !quiet {
                for r in &rows {
                    eprintln!(
                        "{:>10} H/dr = {:>4}: L2 mean {:.3e}, final {:.3e}, order {}",
                        r.frame,
                        r.resolution,
                        r.l2_mean,
                        r.l2_final,
                        r.order.map_or("-".into(), |o| format!("{o:.2}"))
                    );
                }
                eprintln!("output in {}", out.display());
            }
        }
        StudyCommand::Stability(a) => {
            let (base, out) = base_and_out(&a.common, "stability")?;
            if a.replot {
                stability::replot(&out, a.accuracy)?;
                return Ok(());
            }
            let varies = a
                .vary
                .iter()
                .map(|v| parse_vary(v))
                .collect::<Result<Vec<_>, _>>()?;
            let rows = stability::run(
                &base,
                &a.wi,
                &varies,
                a.accuracy,
                &out,
                a.common.jobs,
                quiet,
            )?;
            if !quiet {
                for r in &rows {
                    eprintln!("{:>30} Wi = {:>7}: {}", r.variant, r.wi, r.outcome.name());
                }
                eprintln!("output in {}", out.display());
            }
        }
        StudyCommand::SpeedAccuracy(a) => {
            let (base, out) = base_and_out(&a.common, "speed-accuracy")?;
            let varies = a
                .vary
                .iter()
                .map(|v| parse_vary(v))
                .collect::<Result<Vec<_>, _>>()?;
            let points =
                speed_accuracy::run(&base, &a.resolutions, &varies, &out, a.common.jobs, quiet)?;
            if !quiet {
                for p in &points {
                    eprintln!(
                        "{:>40}: {:>8.1} s, L2 mean {:.3e}{}",
                        p.label,
                        p.wall_seconds,
                        p.l2_mean,
                        if p.pareto { "  (Pareto)" } else { "" }
                    );
                }
                eprintln!("output in {}", out.display());
            }
        }
        StudyCommand::Cylinder(a) => {
            let (base, out) = base_and_out(&a.common, "cylinder")?;
            let reference = a
                .reference
                .as_deref()
                .map(cylinder::read_reference)
                .transpose()?;
            let rows = cylinder::run(
                &base,
                &a.wi,
                reference.as_deref(),
                &out,
                a.common.jobs,
                quiet,
            )?;
            if !quiet {
                for r in &rows {
                    eprintln!(
                        "Wi = {:>6}: {} at t = {:.3} (steady at {}), <u> = {:.4}, K = {:.3}, peak tau_xx = {:.3}, min det A = {:.4}, {:.1} s",
                        r.wi,
                        r.outcome,
                        r.t_reached,
                        r.steady_at.map_or("-".into(), |t| format!("{t:.3}")),
                        r.u_mean,
                        r.drag_k,
                        r.peak_tau_xx,
                        r.min_det_a,
                        r.wall_seconds
                    );
                }
                eprintln!("output in {}", out.display());
            }
        }
    }
    Ok(())
}
