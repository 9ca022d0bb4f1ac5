//! Shared helpers of the integration tests.
#![allow(dead_code)]

use rheosph::app::run::{self, RunOptions, Summary};
use rheosph::setup::case::{self, Case};
use std::path::{Path, PathBuf};

pub const POISEUILLE: &str = include_str!("../../cases/poiseuille.toml");

/// The shipped Poiseuille case with overrides.
pub fn poiseuille(overrides: &[&str]) -> Case {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    case::parse(POISEUILLE, "cases/poiseuille.toml", "poiseuille", &o).expect("valid case")
}

/// Runs a case quietly into a fresh temporary directory; returns the summary and the dir.
pub fn run_quiet(case: &Case, charts: bool) -> (Summary, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let summary = run::run(
        case,
        &RunOptions {
            out_dir: PathBuf::from(dir.path()),
            quiet: true,
            charts: charts.then_some(rheosph::app::plot::FigureFormat::Png),
            snapshots: false,
            progress: None,
        },
    )
    .expect("run completes");
    (summary, dir)
}

/// A shipped case file (`cases/<file>`) with overrides.
pub fn shipped(file: &str, overrides: &[&str]) -> Case {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(file);
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    case::load(&path, &o).expect("valid case")
}

/// Section `name` of a run directory's `summary.json` (Null if absent).
pub fn summary_section(dir: &Path, name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    summary[name].clone()
}
