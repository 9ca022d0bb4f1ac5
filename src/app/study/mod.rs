//! Studies: many runs of one case, with CSV data and PNG figures a paper could use.
//!
//! * [`convergence`]: L2 error against time and against δr, with the observed order;
//! * [`stability`]: where methods fail, over Wi and scheme variants;
//! * [`speed_accuracy`]: wall time against L2 error, with the Pareto front;
//! * [`cylinder`]: a cylinder in a channel over Wi: drag, centre-line profiles.
//!
//! Every `--set` of the base case applies to every run. Runs may execute concurrently
//! (`--jobs`); a run's results do not depend on its thread count (blocked reductions, fixed
//! neighbour order), so neither do the study's.

pub mod cli;
pub mod convergence;
pub mod cylinder;
mod members;
pub mod speed_accuracy;
pub mod stability;

pub use members::Incomplete;

use crate::app::io::SeriesRow;
use crate::app::run::{self, RunOptions, Summary};
use crate::setup::case::{self, Case, CaseError};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// One run of a study: its label, its overrides on top of the base case, and tags for the
/// CSV (e.g. `frame = eulerian`).
#[derive(Clone, Debug, Default)]
pub struct Variant {
    pub label: String,
    pub overrides: Vec<String>,
    pub tags: Vec<(String, String)>,
    /// Start from this finished run's final state (`run --from`), e.g. a coarser resolution's.
    pub from: Option<PathBuf>,
}

/// A finished run of a study.
pub struct Finished {
    pub variant: Variant,
    pub case: Case,
    pub summary: Summary,
    pub series: Vec<SeriesRow>,
    pub dir: PathBuf,
}

/// A member of a study without a finished run, as `--collect` finds it: `failed` if its run
/// stopped on an error (`rheosph run` wrote it to the directory's `error.txt`), else `lost`
/// (never run, or its worker ended before the run did). Its row in the study's table carries
/// this outcome and no numbers; rerunning the member (the emitted scripts, `study()` again)
/// fills it.
pub struct Missing {
    pub variant: Variant,
    pub case: Case,
    pub dir: PathBuf,
    /// Its line in `members.txt`, from 0 (the Slurm array index).
    pub index: usize,
    /// The error that stopped its run, if it failed.
    pub error: Option<String>,
}

impl Missing {
    /// The outcome column of its row: `failed` or `lost`.
    pub fn outcome(&self) -> &'static str {
        match self.error {
            Some(_) => "failed",
            None => "lost",
        }
    }
}

/// The members of a study: the finished runs in order and the members without one (a run
/// here that stopped on an error; from `--collect`, also those never run or lost).
pub struct Members {
    pub finished: Vec<Finished>,
    pub missing: Vec<Missing>,
    /// Where they ran, for the resume advice of [`Incomplete`].
    pub executor: Executor,
}

impl Members {
    /// Ok when every member finished; else [`Incomplete`], naming the others (after the
    /// study has written its table with their rows).
    pub fn check_complete(&self, out: &Path) -> Result<()> {
        let total = self.finished.len() + self.missing.len();
        Incomplete::check(&self.missing, total, out, self.executor)
    }
}

/// The base case of a study: its file and the `--set` overrides of every run.
#[derive(Clone, Debug)]
pub struct Base {
    pub path: PathBuf,
    pub sets: Vec<String>,
    /// Reuse finished runs: a run directory that holds a `summary.json` and whose `case.toml`
    /// is this run's case is read instead of run again (a long study resumed after an
    /// interruption; `--reuse`).
    pub reuse: bool,
    /// Where the members run: here, or elsewhere (`--emit`, then `--collect`).
    pub executor: Executor,
}

/// Where a study's members run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Executor {
    /// In this process, `--jobs` at a time.
    #[default]
    Here,
    /// Nowhere yet: write each member's case and the scripts that run them (`--emit`).
    Emit,
    /// Read the finished members; run none (`--collect`).
    Collect,
}

impl Base {
    /// The validated case of one variant.
    pub fn case(&self, extra: &[String]) -> Result<Case, CaseError> {
        let mut all = self.sets.clone();
        all.extend(extra.iter().cloned());
        case::load(&self.path, &all)
    }
}

/// `key=v1,v2,...` of a `--vary` argument.
pub fn parse_vary(arg: &str) -> Result<(String, Vec<String>), CaseError> {
    let bad = |m: &str| CaseError {
        file: "--vary".into(),
        field: String::new(),
        message: format!("{arg:?}: {m}"),
    };
    let (key, values) = arg
        .split_once('=')
        .ok_or_else(|| bad("expected key=value1,value2,..."))?;
    let values: Vec<String> = values
        .split(',')
        .map(|v| v.trim().to_string())
        .filter(|v| !v.is_empty())
        .collect();
    if key.trim().is_empty() || values.is_empty() {
        return Err(bad("expected key=value1,value2,..."));
    }
    Ok((key.trim().to_string(), values))
}

/// One explicit variant from a `--variant` argument: `key=value` pairs separated by `;`
/// (e.g. `scheme.method=wcsph;scheme.wcsph.density_diffusion=0.1`), labelled by its pairs.
pub fn parse_variant(arg: &str) -> Result<Variant, CaseError> {
    let mut v = Variant::default();
    for pair in arg.split(';').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = pair.split_once('=').ok_or_else(|| CaseError {
            file: "--variant".into(),
            field: String::new(),
            message: format!("{arg:?}: expected key=value;key=value"),
        })?;
        let (key, value) = (key.trim(), value.trim());
        let short = short_key(key);
        if !v.label.is_empty() {
            v.label.push(' ');
        }
        v.label.push_str(&format!("{short}={value}"));
        v.overrides.push(format!("{key}={value}"));
        v.tags.push((key.to_string(), value.to_string()));
    }
    Ok(v)
}

/// The variants of a study: each `--variant` (or one empty variant when there are none),
/// each combined with every combination of the `--vary` dimensions.
pub fn variants(explicit: &[Variant], varies: &[(String, Vec<String>)]) -> Vec<Variant> {
    let empty = [Variant::default()];
    let explicit = if explicit.is_empty() {
        &empty[..]
    } else {
        explicit
    };
    let mut out = Vec::new();
    for e in explicit {
        for v in product(varies) {
            let label = format!("{} {}", e.label, v.label).trim().to_string();
            let mut overrides = e.overrides.clone();
            overrides.extend(v.overrides);
            let mut tags = e.tags.clone();
            tags.extend(v.tags);
            out.push(Variant {
                label,
                overrides,
                tags,
                from: None,
            });
        }
    }
    out
}

/// The Cartesian product of the `--vary` arguments (one empty variant when there are none).
pub fn product(varies: &[(String, Vec<String>)]) -> Vec<Variant> {
    let mut out = vec![Variant::default()];
    for (key, values) in varies {
        let short = short_key(key);
        out = out
            .into_iter()
            .flat_map(|v| {
                values.iter().map(move |value| {
                    let mut w = v.clone();
                    if !w.label.is_empty() {
                        w.label.push(' ');
                    }
                    w.label.push_str(&format!("{short}={value}"));
                    w.overrides.push(format!("{key}={value}"));
                    w.tags.push((key.clone(), value.clone()));
                    w
                })
            })
            .collect();
    }
    out
}

/// A key as a label names it: without its top-level table (`frame`, `conformation.form`).
fn short_key(key: &str) -> &str {
    key.split_once('.').map_or(key, |(_, rest)| rest)
}

/// A file-system-safe directory name for a label.
fn slug(label: &str) -> String {
    let s: String = label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "run".into()
    } else {
        s
    }
}

/// Runs every variant (validated first, so a bad variant fails before any run starts), `jobs`
/// at a time, each into `out/runs/<label>`. Progress goes to stderr unless `quiet`. With
/// `--collect` it runs none: it reads the finished members back and returns the others as
/// missing, for the study to write their rows and then report them.
pub fn run_all(
    base: &Base,
    variants: Vec<Variant>,
    out: &Path,
    jobs: usize,
    quiet: bool,
) -> Result<Members> {
    let cases: Vec<Case> = variants
        .iter()
        .map(|v| base.case(&v.overrides))
        .collect::<Result<_, _>>()?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    match base.executor {
        Executor::Here => {}
        Executor::Emit => return Err(members::emit(&variants, &cases, out)?.into()),
        Executor::Collect => return members::collect(variants, cases, out),
    }
    let mut members = Members {
        finished: Vec::new(),
        missing: Vec::new(),
        executor: Executor::Here,
    };
    for member in run_here(base, variants, cases, out, jobs, quiet) {
        match member {
            Ran::Finished(done) => members.finished.push(*done),
            Ran::Failed(missing) => members.missing.push(*missing),
        }
    }
    Ok(members)
}

/// A member run here: finished (or broken down, a result too), or failed on an error.
enum Ran {
    Finished(Box<Finished>),
    Failed(Box<Missing>),
}

/// Runs the members in this process, `jobs` at a time. A member whose run stops on an error
/// is recorded (its directory's `error.txt`) and returned as `failed`; the others go on.
fn run_here(
    base: &Base,
    variants: Vec<Variant>,
    cases: Vec<Case>,
    out: &Path,
    jobs: usize,
    quiet: bool,
) -> Vec<Ran> {
    let jobs = jobs.clamp(1, variants.len().max(1));
    let threads = (rayon::current_num_threads() / jobs).max(1);
    let total = variants.len();
    let done = AtomicUsize::new(0);
    let run_one = |index: usize, (variant, case): (Variant, Case)| {
        let dir = member_dir(out, &variant);
        let result = run_member(base, variant.clone(), case.clone(), &dir, threads);
        let k = done.fetch_add(1, Ordering::SeqCst) + 1;
        let label = match variant.label.is_empty() {
            true => "base",
            false => &variant.label,
        };
        match result {
            Ok(finished) => {
                if !quiet {
                    report(k, total, label, &finished.summary);
                }
                Ran::Finished(Box::new(finished))
            }
            Err(e) => {
                run::record_error(&dir, &e);
                if !quiet {
                    eprintln!("[{k}/{total}] {label}: failed: {e:#}");
                }
                Ran::Failed(Box::new(Missing {
                    variant,
                    case,
                    dir,
                    index,
                    error: Some(format!("{e:#}").replace('\n', " ")),
                }))
            }
        }
    };
    let work: Vec<(Variant, Case)> = variants.into_iter().zip(cases).collect();
    if jobs == 1 {
        return work
            .into_iter()
            .enumerate()
            .map(|(i, w)| run_one(i, w))
            .collect();
    }
    // `jobs` plain threads taking the runs in order, each run on its own pool. (An outer
    // rayon pool would not bound the concurrency: a worker waiting for a run's pool steals
    // the next run, and all of them ran at once.)
    let slots: Vec<std::sync::Mutex<Option<(Variant, Case)>>> = work
        .into_iter()
        .map(|w| std::sync::Mutex::new(Some(w)))
        .collect();
    let results: Vec<std::sync::Mutex<Option<Ran>>> =
        slots.iter().map(|_| std::sync::Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(slot) = slots.get(k) else { break };
                let item = slot.lock().map(|mut s| s.take()).ok().flatten();
                if let Some(item) = item {
                    let result = run_one(k, item);
                    if let Ok(mut r) = results[k].lock() {
                        *r = Some(result);
                    }
                }
            });
        }
    });
    // Every slot is filled: a thread that panics ends the scope with its panic.
    results
        .into_iter()
        .filter_map(|r| r.into_inner().ok().flatten())
        .collect()
}

/// One member run here (or read back, with `--reuse`) on a pool of `threads`.
fn run_member(
    base: &Base,
    variant: Variant,
    case: Case,
    dir: &Path,
    threads: usize,
) -> Result<Finished> {
    let (variant, case) = match base.reuse {
        true => match read_finished(variant, case, dir)? {
            Ok(done) => return Ok(done),
            Err(pending) => pending,
        },
        false => (variant, case),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let options = RunOptions {
        out_dir: dir.to_path_buf(),
        quiet: true,
        charts: None,
        snapshots: false,
        progress: None,
    };
    let summary = pool.install(|| match &variant.from {
        Some(from) => run::continue_from(&case, &options, from),
        None => run::run(&case, &options),
    })?;
    let series = crate::app::io::read_series(&dir.join("series.csv"))?;
    Ok(Finished {
        variant,
        case,
        summary,
        series,
        dir: dir.to_path_buf(),
    })
}

/// The progress line of a finished member.
fn report(k: usize, total: usize, label: &str, summary: &Summary) {
    let l2 = summary
        .errors
        .l2_time_mean
        .map_or("-".to_string(), |v| format!("{v:.3e}"));
    eprintln!(
        "[{k}/{total}] {label}: {:?} at t = {:.3}, L2 mean {l2}, {:.1} s",
        summary.outcome, summary.t_reached, summary.wall_seconds
    );
}

/// The directory of a member's run.
fn member_dir(out: &Path, variant: &Variant) -> PathBuf {
    out.join("runs").join(slug(&variant.label))
}

/// The finished run of a member in `dir` (the `--reuse` test), or the member back if it has
/// not finished there.
fn read_finished(
    variant: Variant,
    case: Case,
    dir: &Path,
) -> Result<Result<Finished, (Variant, Case)>> {
    let Some(summary) = finished_run(dir, &case) else {
        return Ok(Err((variant, case)));
    };
    let series = crate::app::io::read_series(&dir.join("series.csv"))?;
    Ok(Ok(Finished {
        variant,
        case,
        summary,
        series,
        dir: dir.to_path_buf(),
    }))
}

/// The summary of the finished run of `case` in `dir`, if there is one.
fn finished_run(dir: &Path, case: &Case) -> Option<Summary> {
    let ran = std::fs::read_to_string(dir.join(run::CASE_FILE)).ok()?;
    if ran != toml::to_string(&case.source).ok()? {
        return None;
    }
    let summary = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    Summary::read(&summary, case)
}

/// Least-squares slope of log y against log x (the observed order), over positive pairs.
pub fn fitted_order(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// `l2_vs_time.png`: every run's L2 error against time (dashed: the Eulerian frame).
fn draw_l2_histories(
    finished: &[Finished],
    out: &Path,
    format: crate::app::plot::FigureFormat,
) -> Result<()> {
    use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
    let curves: Vec<Curve> = finished
        .iter()
        .enumerate()
        .map(|(k, f)| Curve {
            label: f.variant.label.clone(),
            points: f
                .series
                .iter()
                .filter(|r| r.t > 0.0 && r.l2_error > 0.0)
                .map(|r| (r.t, r.l2_error))
                .collect(),
            style: if f.variant.tags.iter().any(|(_, v)| v == "eulerian") {
                CurveStyle::Dashed
            } else {
                CurveStyle::Line
            },
            color: PALETTE[k % PALETTE.len()],
        })
        .collect();
    plot::draw(
        &out.join("l2_vs_time.png"),
        format,
        &Chart {
            title: "Velocity L2 error against time".into(),
            x_label: "t".into(),
            y_label: "L2 error / U".into(),
            log_y: true,
            ..Default::default()
        },
        &curves,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_of_varies_labels_every_combination() {
        let v = product(&[
            parse_vary("scheme.frame=lagrangian,eulerian").unwrap(),
            parse_vary("scheme.conformation.form=log,direct").unwrap(),
        ]);
        assert_eq!(v.len(), 4);
        assert_eq!(v[3].label, "frame=eulerian conformation.form=direct");
        assert_eq!(
            v[3].overrides,
            vec!["scheme.frame=eulerian", "scheme.conformation.form=direct"]
        );
        assert!(parse_vary("scheme.frame").is_err());
        assert!(parse_vary("scheme.frame=").is_err());
    }

    #[test]
    fn explicit_variants_combine_with_every_vary() {
        let explicit = [
            parse_variant("scheme.method=isph").unwrap(),
            parse_variant("scheme.method=wcsph; scheme.wcsph.density_diffusion=0.1").unwrap(),
        ];
        let v = variants(&explicit, &[parse_vary("scene.resolution=15,30").unwrap()]);
        assert_eq!(v.len(), 4);
        assert_eq!(
            v[3].label,
            "method=wcsph wcsph.density_diffusion=0.1 resolution=30"
        );
        assert_eq!(
            v[3].overrides,
            vec![
                "scheme.method=wcsph",
                "scheme.wcsph.density_diffusion=0.1",
                "scene.resolution=30"
            ]
        );
        // No --variant: the product alone, as before.
        assert_eq!(variants(&[], &[]).len(), 1);
        assert!(parse_variant("scheme.method").is_err());
    }

    #[test]
    fn fitted_order_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [1.0, 0.5, 0.25]
            .iter()
            .map(|&h: &f64| (h, 3.0 * h * h))
            .collect();
        assert!((fitted_order(&pts).unwrap() - 2.0).abs() < 1e-12);
    }
}
