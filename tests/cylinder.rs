//! The cylinder array: Stokes-limit drag against a finer resolution, and a run continued from
//! a checkpoint against the same run uninterrupted.

use std::path::Path;
use std::process::Command;

fn rheosph() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rheosph"))
}

fn run(dir: &Path, sets: &[&str]) {
    let mut c = rheosph();
    c.args([
        "-q",
        "run",
        "cases/cylinder-array.toml",
        "--no-snapshots",
        "--no-charts",
    ]);
    c.arg("--out").arg(dir);
    for s in sets {
        c.args(["--set", s]);
    }
    let status = c.status().unwrap();
    assert!(status.success(), "run failed: {status}");
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// A run killed after its last checkpoint and resumed writes the same series, bit for bit,
/// as the run that was never interrupted (the series.csv of the killed run may hold rows past
/// the checkpoint; resuming cuts them back).
#[test]
fn resumed_run_matches_uninterrupted() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let sets = [
        "scene.resolution=36",
        "fluid.relaxation_time=0.2",
        "run.end_time=0.3",
        "run.checkpoint_interval=0.12",
        "run.output_interval=0.02",
    ];
    run(&a, &sets);
    std::fs::create_dir_all(&b).unwrap();
    for f in ["case.toml", "checkpoint.bin", "series.csv"] {
        std::fs::copy(a.join(f), b.join(f)).unwrap();
    }
    let status = rheosph()
        .args(["-q", "run", "--no-snapshots", "--no-charts", "--resume"])
        .arg(&b)
        .status()
        .unwrap();
    assert!(status.success());
    let series = |d: &Path| std::fs::read_to_string(d.join("series.csv")).unwrap();
    assert_eq!(series(&a), series(&b));
    let (sa, sb) = (summary(&a), summary(&b));
    assert_eq!(sa["steps"], sb["steps"]);
    assert_eq!(sa["t_reached"], sb["t_reached"]);
    assert_eq!(
        std::fs::read_to_string(a.join("centreline.csv")).unwrap(),
        std::fs::read_to_string(b.join("centreline.csv")).unwrap()
    );
}
