//! The command line: argument types and dispatch. Each subcommand converts its raw arguments
//! into typed settings once (a validated [`Case`](crate::setup::case::Case)) and calls the library.

use crate::app::run::{self, Outcome, RunOptions};
use crate::setup::case::{self, CaseError};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "rheosph",
    version,
    about = "Incompressible SPH for viscoelastic flows (King & Lind 2021)"
)]
pub struct Cli {
    /// No progress bar or start-up report.
    #[arg(short, long, global = true)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run a case to its end time (or breakdown) and write a run directory.
    Run(RunArgs),
    /// Validate a case file and print its derived numbers without running it.
    Check(CaseArgs),
    /// Overlay the final profiles of several run directories, each with its analytic curve.
    CompareProfiles(CompareArgs),
    /// Overlay drop width W* and height H* against t* of several drop runs (their drop.csv).
    CompareDrops(CompareDropsArgs),
    /// Time each stage of the step side by side for several sizes of the Poiseuille scene.
    Bench(BenchArgs),
    /// Run many variants of a case: convergence, stability map, speed against accuracy.
    #[command(subcommand)]
    Study(StudyCommand),
}

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
}

#[derive(Args, Debug)]
pub struct StudyCommon {
    #[command(flatten)]
    pub case: CaseArgs,
    /// Output directory (default: runs/<study>-<case name>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Runs executed concurrently (each with its share of the threads); results do not
    /// depend on it.
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
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
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Approximate particle counts (the unit square holds resolution² particles).
    #[arg(long, value_delimiter = ',', default_value = "1000,4000,16000,64000")]
    pub sizes: Vec<usize>,
    /// Whole steps timed per size.
    #[arg(long, default_value_t = 20)]
    pub steps: usize,
    /// Largest system the sparse LU is timed on.
    #[arg(long, default_value_t = 70_000)]
    pub lu_max: usize,
    /// Output directory for bench.csv and bench.txt.
    #[arg(long, default_value = "runs/bench")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Run directories (each with profile.csv and summary.json).
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// The output PNG.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[arg(long, value_enum, default_value = "u")]
    pub field: crate::app::compare::Field,
    /// Divide values by this scale (e.g. the velocity scale U).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    #[arg(long, default_value = "Final profiles")]
    pub title: String,
}

#[derive(Args, Debug)]
pub struct CompareDropsArgs {
    /// Run directories of drop cases (each with drop.csv).
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// Curve labels, one per run (default: the directory names).
    #[arg(long, value_delimiter = ',')]
    pub labels: Vec<String>,
    /// The output PNG.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[arg(long, default_value = "Drop width and height")]
    pub title: String,
}

#[derive(Args, Debug)]
pub struct CaseArgs {
    /// The case file (TOML).
    pub case: PathBuf,
    /// Override any dotted key of the case file, e.g. `--set fluid.beta=0.2`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

#[derive(Args, Debug)]
pub struct RunArgs {
    /// The case file (TOML); not with --resume.
    #[arg(required_unless_present = "resume", conflicts_with = "resume")]
    pub case: Option<PathBuf>,
    /// Override any dotted key of the case file, e.g. `--set fluid.beta=0.2`.
    #[arg(long = "set", value_name = "KEY=VALUE", conflicts_with = "resume")]
    pub set: Vec<String>,
    /// Continue the run in DIR from its last checkpoint (the case and options it ran with).
    #[arg(long, value_name = "DIR")]
    pub resume: Option<PathBuf>,
    /// Output directory (default: runs/<case name>).
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub out: Option<PathBuf>,
    /// Skip the PNG charts.
    #[arg(long)]
    pub no_charts: bool,
    /// Skip the .vtu snapshots.
    #[arg(long)]
    pub no_snapshots: bool,
}

/// Exit code for a run that broke down (a result, not a crash).
pub const EXIT_BROKE_DOWN: u8 = 3;
/// Exit code for bad input.
pub const EXIT_BAD_INPUT: u8 = 2;

/// Runs the parsed command line.
pub fn main(cli: Cli) -> ExitCode {
    match dispatch(cli) {
        Ok(code) => code,
        Err(e) => {
            if let Some(ce) = e.downcast_ref::<CaseError>() {
                eprintln!("error: {ce}");
                ExitCode::from(EXIT_BAD_INPUT)
            } else {
                eprintln!("error: {e:#}");
                ExitCode::FAILURE
            }
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Run(args) => {
            let options = |out_dir: PathBuf| RunOptions {
                out_dir,
                quiet: cli.quiet,
                charts: !args.no_charts,
                snapshots: !args.no_snapshots,
            };
            let summary = match (&args.resume, &args.case) {
                (Some(dir), _) => run::resume(&options(dir.clone()))?,
                (None, Some(path)) => {
                    let case = case::load(path, &args.set)?;
                    let out_dir = args
                        .out
                        .clone()
                        .unwrap_or_else(|| PathBuf::from("runs").join(&case.name));
                    run::run(&case, &options(out_dir))?
                }
                (None, None) => anyhow::bail!("a case file or --resume DIR is required"),
            };
            Ok(match summary.outcome {
                Outcome::Finished => ExitCode::SUCCESS,
                Outcome::BrokeDown => ExitCode::from(EXIT_BROKE_DOWN),
            })
        }
        Command::Study(study) => {
            crate::app::study::cli::dispatch(study, cli.quiet)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Bench(args) => {
            crate::app::bench::run(&args.sizes, args.steps, args.lu_max, &args.out, cli.quiet)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::CompareProfiles(args) => {
            crate::app::compare::compare_profiles(
                &args.runs,
                args.field,
                args.scale,
                &args.title,
                &args.out,
            )?;
            Ok(ExitCode::SUCCESS)
        }
        Command::CompareDrops(args) => {
            crate::app::compare::compare_drops(&args.runs, &args.labels, &args.title, &args.out)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Check(args) => {
            let case = case::load(&args.case, &args.set)?;
            println!("{}: valid", args.case.display());
            println!("{}", serde_json::to_string_pretty(&case.derived())?);
            Ok(ExitCode::SUCCESS)
        }
    }
}
