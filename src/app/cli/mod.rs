//! The command line: argument types and dispatch. Each subcommand converts its raw arguments
//! into typed settings once (a validated [`Case`](crate::setup::case::Case)) and calls the library.

pub mod args;

use crate::app::keys::KeyPage;
use crate::app::run::{self, Outcome, RunOptions};
use crate::app::study::{cli::StudyCommand, Incomplete};
use crate::setup::case::{self, CaseError};
use args::{
    BenchArgs, CaseArgs, CompareArgs, CompareCentrelinesArgs, CompareDropsArgs, RheometryArgs,
    RunArgs,
};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

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
    /// Overlay the centre-line profiles (u, tau_xx, det A) of several cylinder runs (their
    /// centreline.csv), e.g. long runs at several Wi: the paper's Fig. 11.
    CompareCentrelines(CompareCentrelinesArgs),
    /// Time each stage of the step side by side for several sizes of the Poiseuille scene.
    Bench(BenchArgs),
    /// The case's fluid in homogeneous flows: steady shear, start-up of shear and planar
    /// extension, oscillatory shear, with the exact curves (CSV and PNG).
    Rheometry(RheometryArgs),
    /// Run many variants of a case: convergence, stability map, speed against accuracy.
    #[command(subcommand)]
    Study(StudyCommand),
    /// Every key of a case file with its meaning, values and default, from the code.
    Keys {
        /// As the Markdown page `docs/src/reference/scheme-keys.md` (`--page case`:
        /// `case-keys.md`); else `key = default`.
        #[arg(long)]
        markdown: bool,
        /// `scheme`: `[scheme]`, `[run]` and `[experimental]`; `case`: `[scene]` and `[fluid]`.
        #[arg(long, value_enum, default_value = "scheme")]
        page: KeyPage,
    },
    /// Regenerate the validation pages' marked tables from the run outputs under `plots/`
    /// and list every committed number that changed (run from the repository's root).
    Gallery {
        /// Write nothing; exit with an error if a committed number contradicts its source
        /// or a result is typed outside the generated tables.
        #[arg(long)]
        check: bool,
        /// The directory of the pages, or one page.
        #[arg(long, default_value = "docs/src/validation")]
        pages: PathBuf,
    },
}

/// Exit code of a command that did what it was asked.
pub const EXIT_FINISHED: u8 = 0;
/// Exit code for other errors (e.g. an unwritable output directory).
pub const EXIT_FAILURE: u8 = 1;
/// Exit code for a run that broke down (a result, not a crash).
pub const EXIT_BROKE_DOWN: u8 = 3;
/// Exit code for bad input.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit code of `study --collect` with members not finished: the table is written, with a
/// `lost` or `failed` row for each.
pub const EXIT_INCOMPLETE: u8 = 4;

/// Runs the parsed command line.
pub fn main(cli: Cli) -> std::process::ExitCode {
    std::process::ExitCode::from(exit_code(cli))
}

/// Runs the parsed command line and returns its exit code (0 finished; see the constants).
pub fn exit_code(cli: Cli) -> u8 {
    match crate::app::run::on_pool_worker(|| dispatch(cli)) {
        Ok(code) => code,
        Err(e) => {
            if let Some(ce) = e.downcast_ref::<CaseError>() {
                eprintln!("error: {ce}");
                EXIT_BAD_INPUT
            } else {
                eprintln!("error: {e:#}");
                if e.is::<Incomplete>() {
                    EXIT_INCOMPLETE
                } else {
                    EXIT_FAILURE
                }
            }
        }
    }
}

/// `rheosph run`: a case (or `--resume DIR`) run into its directory; its exit code.
fn run_command(args: &RunArgs, quiet: bool) -> anyhow::Result<u8> {
    let options = |out_dir: PathBuf| RunOptions {
        out_dir,
        quiet,
        charts: (!args.no_charts).then_some(args.figure_format),
        snapshots: !args.no_snapshots,
        progress: None,
    };
    let summary = match (&args.resume, &args.case) {
        (Some(dir), _) => run::resume(&options(dir.clone()))?,
        (None, Some(path)) => {
            let case = case::load(path, &args.set)?;
            let out_dir = args
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("runs").join(&case.name));
            match &args.from {
                Some(from) => run::continue_from(&case, &options(out_dir), from)?,
                None => run::run(&case, &options(out_dir))?,
            }
        }
        (None, None) => anyhow::bail!("a case file or --resume DIR is required"),
    };
    Ok(match summary.outcome {
        Outcome::Finished => EXIT_FINISHED,
        Outcome::BrokeDown => EXIT_BROKE_DOWN,
    })
}

fn dispatch(cli: Cli) -> anyhow::Result<u8> {
    match cli.command {
        Command::Run(args) => {
            let result = run_command(&args, cli.quiet);
            // A run directory named on the command line keeps the error that stopped it, so
            // that a study collecting it can tell a failed member from a lost one.
            if let (Err(e), Some(dir)) = (&result, args.out.as_ref().or(args.resume.as_ref())) {
                run::record_error(dir, e);
            }
            result
        }
        Command::Study(study) => {
            crate::app::study::cli::dispatch(study, cli.quiet)?;
            Ok(EXIT_FINISHED)
        }
        Command::Rheometry(args) => {
            let case = case::load(&args.case, &args.set)?;
            let out = args
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("runs").join(format!("rheometry-{}", case.name)));
            crate::app::rheometry::run(&case, &out, args.figure_format, cli.quiet)?;
            Ok(EXIT_FINISHED)
        }
        Command::Bench(args) if args.solvers => {
            crate::app::bench_solvers::run(&args.sizes, &args.out, cli.quiet)?;
            Ok(EXIT_FINISHED)
        }
        Command::Bench(args) => {
            crate::app::bench::run(&args.sizes, args.steps, args.lu_max, &args.out, cli.quiet)?;
            Ok(EXIT_FINISHED)
        }
        Command::CompareProfiles(args) => {
            crate::app::compare::compare_profiles(
                &args.runs,
                args.field,
                args.scale,
                &args.title,
                &args.out,
            )?;
            Ok(EXIT_FINISHED)
        }
        Command::CompareDrops(args) => {
            crate::app::compare::compare_drops(&args.runs, &args.labels, &args.title, &args.out)?;
            Ok(EXIT_FINISHED)
        }
        Command::CompareCentrelines(args) => {
            crate::app::compare::compare_centrelines(&args.runs, &args.labels, &args.out)?;
            Ok(EXIT_FINISHED)
        }
        Command::Keys { markdown, page } => {
            use crate::app::keys;
            let text = match (markdown, page) {
                (true, KeyPage::Scheme) => keys::markdown(),
                (true, KeyPage::Case) => keys::case_markdown(),
                (false, _) => page
                    .rows()
                    .iter()
                    .map(|r| format!("{} = {}\n", r.key, r.default))
                    .collect(),
            };
            print!("{text}");
            Ok(EXIT_FINISHED)
        }
        Command::Gallery { check, pages } => {
            let found = crate::app::gallery::regenerate(std::path::Path::new("."), &pages, check)?;
            for c in &found.contradictions {
                println!("{c}");
            }
            for t in &found.typed {
                println!("{t}: a result typed outside the generated tables");
            }
            let (n, typed) = (found.contradictions.len(), found.typed.len());
            match check && n + typed > 0 {
                true => anyhow::bail!(
                    "{n} committed numbers contradict their sources, {typed} results are typed (above)"
                ),
                false => Ok(EXIT_FINISHED),
            }
        }
        Command::Check(args) => {
            let case = case::load(&args.case, &args.set)?;
            if let Some(line) = case.experimental_line() {
                eprintln!("{}: {line}", args.case.display());
            }
            let text = format!(
                "{}: valid\n{}\n",
                args.case.display(),
                serde_json::to_string_pretty(&case.derived())?
            );
            // A reader that stops early (`rheosph check … | head`) is not an error.
            match std::io::Write::write_all(&mut std::io::stdout().lock(), text.as_bytes()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
                _ => Ok(EXIT_FINISHED),
            }
        }
    }
}
