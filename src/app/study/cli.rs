//! `rheosph study ...`: its arguments, and their dispatch into a [`Base`] and the study's
//! settings.

use super::{
    convergence, cylinder, members::Emitted, parse_variant, parse_vary, speed_accuracy, stability,
    variants, Base, Executor, Variant,
};
use crate::app::cli::args::CaseArgs;
use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Subcommand, Debug)]
pub enum StudyCommand {
    /// L2 error against time and resolution, with the observed order.
    Convergence(ConvergenceArgs),
    /// Largest stable Wi of scheme variants; outcome per (variant, Wi).
    Stability(StabilityArgs),
    /// Wall time against L2 error with the Pareto front.
    SpeedAccuracy(SpeedAccuracyArgs),
    /// A cylinder in a channel over Wi: steady drag and centre-line profiles overlaid.
    Cylinder(CylinderArgs),
}

#[derive(Args, Debug)]
pub struct CylinderArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    /// Weissenberg numbers Wi = ⟨u⟩λ/R (λ is set for each; 0 runs the Newtonian fluid).
    #[arg(long, value_delimiter = ',', required = true)]
    pub wi: Vec<f64>,
    /// Published drag values to draw beside ours: a CSV with columns `wi,k`.
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// Grid sequencing: coarser `scene.resolution`s (coarsest first) run first at each Wi,
    /// each run starting from the previous one's final state interpolated onto its particles;
    /// `36:60` also sets that stage's `run.end_time`.
    #[arg(long, value_delimiter = ',', value_parser = cylinder::parse_stage)]
    pub sequence: Vec<cylinder::Stage>,
}

#[derive(Args, Debug)]
pub struct StudyCommon {
    #[command(flatten)]
    pub case: CaseArgs,
    /// Output directory (default: runs/<study>-<case name>).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["emit", "collect"])]
    pub out: Option<PathBuf>,
    /// Run nothing: write each member's case into DIR/runs/<member>/case.toml, the list
    /// DIR/members.txt and the scripts that run them elsewhere (DIR/job-array.slurm for a
    /// Slurm job array, DIR/run-members.sh for `xargs` here); then `--collect DIR`.
    #[arg(long, value_name = "DIR", conflicts_with = "collect")]
    pub emit: Option<PathBuf>,
    /// Run nothing: assemble the study in DIR from its finished members (run after
    /// `--emit DIR` by any means), or list the members not finished.
    #[arg(long, value_name = "DIR")]
    pub collect: Option<PathBuf>,
    /// Runs executed concurrently (each with its share of the threads); results do not
    /// depend on it.
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// Do not rerun a run whose directory already holds the finished run of the same case
    /// (resuming an interrupted study).
    #[arg(long)]
    pub reuse: bool,
    /// The charts' file format.
    #[arg(long, value_enum, default_value = "png")]
    pub figure_format: crate::app::plot::FigureFormat,
}

#[derive(Args, Debug)]
pub struct ConvergenceArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    #[arg(long, value_delimiter = ',', default_value = "15,30,60")]
    pub resolutions: Vec<usize>,
    #[arg(long, value_delimiter = ',', default_value = "lagrangian")]
    pub frames: Vec<String>,
}

#[derive(Args, Debug)]
pub struct StabilityArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    /// Weissenberg numbers (λ = Wi·H/U is set for each).
    #[arg(long, value_delimiter = ',', required = true)]
    pub wi: Vec<f64>,
    /// A scheme variant dimension, `key=v1,v2` (repeatable; all combinations run).
    #[arg(long = "vary", value_name = "KEY=V1,V2")]
    pub vary: Vec<String>,
    /// One variant, `key=v;key=v` (repeatable): studies of variants that are not a product,
    /// e.g. `--variant scheme.method=isph --variant 'scheme.method=wcsph;scheme.wcsph.density_diffusion=0.1'`.
    /// Each is combined with every `--vary` combination.
    #[arg(long = "variant", value_name = "KEY=V;KEY=V")]
    pub variant: Vec<String>,
    /// Largest time-mean L2 error (in U) of a run counted as accurate.
    #[arg(long, default_value_t = 0.1)]
    pub accuracy: f64,
    /// Redraw `stability_map.png` from the study's `stability.csv` without running anything.
    #[arg(long)]
    pub replot: bool,
}

#[derive(Args, Debug)]
pub struct SpeedAccuracyArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    #[arg(long, value_delimiter = ',', default_value = "15,30,60")]
    pub resolutions: Vec<usize>,
    /// A configuration dimension, `key=v1,v2` (repeatable; all combinations run).
    #[arg(long = "vary", value_name = "KEY=V1,V2")]
    pub vary: Vec<String>,
    /// One configuration, `key=v;key=v` (repeatable), combined with every `--vary` combination.
    #[arg(long = "variant", value_name = "KEY=V;KEY=V")]
    pub variant: Vec<String>,
}

fn base_and_out(common: &StudyCommon, study: &str) -> Result<(Base, PathBuf)> {
    let base = Base {
        path: common.case.case.clone(),
        sets: common.case.set.clone(),
        reuse: common.reuse,
        executor: match (&common.emit, &common.collect) {
            (Some(_), _) => Executor::Emit,
            (_, Some(_)) => Executor::Collect,
            _ => Executor::Here,
        },
    };
    let case = base.case(&[])?;
    let out = common
        .out
        .clone()
        .or_else(|| common.emit.clone())
        .or_else(|| common.collect.clone())
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{study}-{}", case.name)));
    Ok((base, out))
}

/// The variants of a study from its `--variant` and `--vary` arguments.
fn parse_variants(explicit: &[String], vary: &[String]) -> Result<Vec<Variant>> {
    let varies = vary
        .iter()
        .map(|v| parse_vary(v))
        .collect::<Result<Vec<_>, _>>()?;
    let explicit = explicit
        .iter()
        .map(|v| parse_variant(v))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(variants(&explicit, &varies))
}

/// Runs the study (or, with `--emit`, writes its members and says how to run them).
pub fn dispatch(command: StudyCommand, quiet: bool) -> Result<()> {
    match run_study(command, quiet) {
        Err(e) if e.is::<Emitted>() => {
            if !quiet {
                eprintln!("{e}");
            }
            Ok(())
        }
        result => result,
    }
}

fn run_study(command: StudyCommand, quiet: bool) -> Result<()> {
    match command {
        StudyCommand::Convergence(a) => {
            let (base, out) = base_and_out(&a.common, "convergence")?;
            let rows = convergence::run(
                &base,
                &a.resolutions,
                &a.frames,
                &out,
                a.common.figure_format,
                a.common.jobs,
                quiet,
            )?;
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
                stability::replot(&out, a.common.figure_format, a.accuracy)?;
                return Ok(());
            }
            let schemes = parse_variants(&a.variant, &a.vary)?;
            let rows = stability::run(
                &base,
                &a.wi,
                &schemes,
                a.accuracy,
                &out,
                a.common.figure_format,
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
            let schemes = parse_variants(&a.variant, &a.vary)?;
            let points = speed_accuracy::run(
                &base,
                &a.resolutions,
                &schemes,
                &out,
                a.common.figure_format,
                a.common.jobs,
                quiet,
            )?;
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
                &a.sequence,
                reference.as_deref(),
                &out,
                a.common.figure_format,
                a.common.jobs,
                quiet,
            )?;
            if !quiet {
                for r in &rows {
                    eprintln!(
                        "Wi = {:>6}, R/dr = {:.1}: {} at t = {:.3} (steady at {}), <u> = {:.4}, K = {:.3}, peak tau_xx = {:.3}, min det A = {:.4} (run {:.4}), {:.1} s",
                        r.wi,
                        r.radius_over_dr,
                        r.outcome,
                        r.t_reached,
                        r.steady_at.map_or("-".into(), |t| format!("{t:.3}")),
                        r.u_mean,
                        r.drag_k,
                        r.peak_tau_xx,
                        r.min_det_a,
                        r.min_det_a_run,
                        r.wall_seconds
                    );
                }
                eprintln!("output in {}", out.display());
            }
        }
    }
    Ok(())
}
