//! The arguments of the subcommands other than `study` (whose live with it).

use clap::Args;
use std::path::PathBuf;

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
    /// Time the PPE solvers (Jacobi and AMG BiCGStab from zero) against N and the SpMV
    /// bandwidth bound instead, into solvers.csv and solvers.txt (try --sizes
    /// 1000,4000,16000,64000,256000).
    #[arg(long)]
    pub solvers: bool,
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
pub struct CompareCentrelinesArgs {
    /// Run directories of cylinder cases (each with centreline.csv).
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// Curve labels, one per run (default: "Wi = λU/R" of each run).
    #[arg(long, value_delimiter = ',')]
    pub labels: Vec<String>,
    /// The output directory (centreline_u.png, centreline_tau_xx.png, centreline_det_a.png).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
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
    /// Start from the final state of the finished run in DIR (its final_state.bin) with this
    /// case's parameters, e.g. `--from runs/wi1 --set fluid.relaxation_time=2` for a Wi ramp.
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub from: Option<PathBuf>,
    /// Output directory (default: runs/<case name>).
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub out: Option<PathBuf>,
    /// Skip the PNG charts.
    #[arg(long)]
    pub no_charts: bool,
    /// The charts' file format (the same content either way).
    #[arg(long, value_enum, default_value = "png")]
    pub figure_format: crate::app::plot::FigureFormat,
    /// Skip the .vtu snapshots.
    #[arg(long)]
    pub no_snapshots: bool,
}

#[derive(Args, Debug)]
pub struct RheometryArgs {
    /// The case file (TOML) whose fluid is measured.
    pub case: PathBuf,
    /// Override any dotted key of the case file, e.g. `--set fluid.relaxation_time=2`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Output directory (default: runs/rheometry-<case name>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The charts' file format.
    #[arg(long, value_enum, default_value = "png")]
    pub figure_format: crate::app::plot::FigureFormat,
}
