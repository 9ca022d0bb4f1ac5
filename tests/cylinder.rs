//! The cylinder array: Stokes-limit drag against a finer resolution, and a run continued from
//! a checkpoint against the same run uninterrupted. The confined cylinder: the Newtonian drag
//! against the finite-volume value, its independence of the time step and of where the
//! cylinder sits on the lattice.

use std::path::Path;
use std::process::Command;

fn rheosph() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rheosph"))
}

fn run(dir: &Path, sets: &[&str]) {
    run_case("cases/cylinder-array.toml", dir, sets);
}

fn run_case(case: &str, dir: &Path, sets: &[&str]) {
    let mut c = rheosph();
    c.args(["-q", "run", case, "--no-snapshots", "--no-charts"]);
    c.arg("--out").arg(dir);
    for s in sets {
        c.args(["--set", s]);
    }
    let status = c.status().unwrap();
    assert!(status.success(), "run failed: {status}");
}

/// The wall seconds recorded in a run directory's checkpoint (its JSON header).
fn checkpoint_wall_seconds(dir: &Path) -> f64 {
    let bytes = std::fs::read(dir.join("checkpoint.bin")).unwrap();
    let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
    header["wall_seconds"].as_f64().unwrap_or(0.0)
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
    let before = checkpoint_wall_seconds(&b);
    assert!(before > 0.0, "the checkpoint records no wall time");
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
    // The resumed run's wall time covers the segment before the checkpoint (80 % of the run
    // here), not only its own; so does its per-stage breakdown.
    let wall = sb["wall_seconds"].as_f64().unwrap();
    assert!(
        wall >= before,
        "wall {wall} s < {before} s before the checkpoint"
    );
    let staged: f64 = sb["stage_seconds"]
        .as_object()
        .unwrap()
        .values()
        .filter_map(|v| v.as_f64())
        .sum();
    assert!(
        staged >= 0.5 * before,
        "stages {staged} s, {before} s before"
    );
    assert_eq!(
        std::fs::read_to_string(a.join("centreline.csv")).unwrap(),
        std::fs::read_to_string(b.join("centreline.csv")).unwrap()
    );
}

/// Stokes-limit drag (Newtonian fluid of the array, Re = 0.024) on a coarse array,
/// R/δr = 9, against our finer runs: K = 121.06, 117.32, 114.67 and ⟨u⟩ = 0.8781, 0.8756,
/// 0.8792 at R/δr = 9, 13.5, 18 with the incremental projection's pressure stabilisation
/// (without it K crept up with the steps taken, and the runs stopped at 116.31, 114.20,
/// 112.63 when ⟨u⟩ met the 2 % criterion). The sequence falls by 3.1 % and 2.3 % per
/// refinement, no asymptotic order yet, so no extrapolation is claimed; the coarse K must be
/// within 7 % of the R/δr = 18 value (measured +5.6 %) and ⟨u⟩ within 1 % (measured −0.1 %).
/// A broken force integral, mirror or projection misses by far more: the standard
/// projection with implicit viscosity gave ⟨u⟩ = 1.69 and a force above the total body
/// force. The force on the cylinder must also be below the total body force on the fluid (the
/// walls take the rest).
#[test]
fn stokes_drag_on_a_coarse_array_is_near_the_resolved_value() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("stokes");
    run(
        &dir,
        &[
            "scene.resolution=36",
            "fluid.model=newtonian",
            "fluid.relaxation_time=0",
            "fluid.beta=1",
            "run.steady.average=1",
        ],
    );
    let s = summary(&dir);
    let st = &s["steady"];
    assert!(st["reached_at"].as_f64().is_some(), "no steady state: {st}");
    let (k, u) = (
        st["drag_k"].as_f64().unwrap(),
        st["u_mean"].as_f64().unwrap(),
    );
    assert!((k / 114.67 - 1.0).abs() < 0.07, "K = {k}");
    assert!((u / 0.8792 - 1.0).abs() < 0.01, "<u> = {u}");
    let particles = s["particles"].as_f64().unwrap();
    let body = 300.0 * particles * (4.0f64 / 36.0).powi(2);
    let drag = k * 41.66 * u;
    assert!(
        drag < body,
        "cylinder force {drag} above the body force {body}"
    );
}

/// A run that never meets the steady criterion (a tolerance no run meets) reports its
/// averages over the last `run.steady.average` time units, as `summary.json` says, not the
/// final state alone: outputs every 0.05 over the last 0.2 of 0.5 time units are five samples
/// from t = 0.3.
#[test]
fn an_unsteady_run_averages_its_last_time_units() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("tail");
    run(
        &dir,
        &[
            "scene.resolution=36",
            "scene.mean_flow=1.0",
            "fluid.relaxation_time=1",
            "run.end_time=0.5",
            "run.output_interval=0.05",
            "run.steady.tolerance=1e-12",
            "run.steady.average=0.2",
        ],
    );
    let st = &summary(&dir)["steady"];
    assert!(st["reached_at"].is_null(), "{st}");
    assert_eq!(st["samples"].as_u64(), Some(5), "{st}");
    let from = st["averaged_from"].as_f64().unwrap();
    assert!((from - 0.3).abs() < 0.01, "{st}");
}

/// The Newtonian confined cylinder (blockage 0.5, R/δr = 10, ⟨u⟩ held at 1) on fixed
/// particles, run to its steady state, then continued from it at half the time step. A
/// steady state of a consistent scheme does not depend on δt, so the drag must not move:
/// measured K = 132.336 (334 steps from rest to t = 3, the case's three rings), then 132.330
/// over the last 0.3 of 0.5 time units at half the step (−0.004 %; on the lattice without
/// rings 132.200 and 132.206).
/// Without the projection's pressure stabilisation the drag crept up with the number of
/// steps taken (132.98, 135.07, 140.81 from rest at δt factors 0.2, 0.1, 0.05: about +0.6 %
/// per hundred steps), which the bound of 0.05 % fails by far. Against the finite-volume
/// K = 132.36 (Alves, Pinho & Oliveira 2001; `cases/confined-cylinder-drag.csv`) the
/// measured −0.02 % (the lattice alone: −0.12 %, +2.4 % with the centre moved by ¼δr) is
/// bounded by 0.5 %. That bound holds for the surface integral (`drag_k`), which reads about
/// 3 % over the flow's own drag here (momentum balance: 128.2; README, *Confined cylinder*):
/// the agreement with 132.36 is a cancellation, and the test guards the number, not the
/// flow's accuracy.
#[test]
fn newtonian_confined_cylinder_drag_is_steady_and_independent_of_the_step() {
    let tmp = tempfile::tempdir().unwrap();
    let newtonian = [
        "fluid.model=newtonian",
        "fluid.relaxation_time=0",
        "fluid.beta=1",
        "scheme.frame=eulerian",
        "scene.mean_flow=1.0",
        "run.steady.tolerance=1e-12",
    ];
    let k = |dir: &Path, extra: &[&str], from: Option<&Path>| {
        let mut c = rheosph();
        c.args([
            "-q",
            "run",
            "cases/confined-cylinder.toml",
            "--no-snapshots",
            "--no-charts",
        ]);
        c.arg("--out").arg(dir);
        if let Some(from) = from {
            c.arg("--from").arg(from);
        }
        for s in newtonian.iter().chain(extra) {
            c.args(["--set", s]);
        }
        assert!(c.status().unwrap().success());
        summary(dir)["steady"]["drag_k"].as_f64().unwrap()
    };
    let (rest, half) = (tmp.path().join("rest"), tmp.path().join("half"));
    let steady = k(&rest, &["run.end_time=3", "run.steady.average=0.5"], None);
    let halved = &[
        "run.end_time=0.5",
        "run.steady.average=0.3",
        "scheme.dt_factor=0.1",
    ];
    let continued = k(&half, halved, Some(&rest));
    assert!(
        (continued / steady - 1.0).abs() < 5e-4,
        "K = {steady}, {continued}"
    );
    assert!((steady / 132.36 - 1.0).abs() < 0.005, "K = {steady}");
}

/// The Newtonian confined cylinder (R/δr = 10, fixed particles, ⟨u⟩ held at 1, to t = 3) with
/// its centre on a lattice node and a quarter spacing along the axis from it. With the case's
/// three body-conforming rings the drag is K = 132.336 and 132.386 (0.037 % apart, −0.02 %
/// and +0.02 % from the finite-volume 132.36 of Alves, Pinho & Oliveira 2001); the lattice cut
/// by the cylinder alone gives 132.20 and 135.56 (2.5 % apart; steady criterion of the case). Bounds: 0.2 % apart, each
/// within 0.3 % of 132.36 (the rings' spread five times over, and a tenth of the lattice's).
/// Like the test above it checks the surface integral; the flow's own drag from the momentum
/// balance does depend on the layout (128.2 with three rings, 124.0 on the lattice).
#[test]
fn newtonian_confined_cylinder_drag_does_not_depend_on_the_lattice_placement() {
    let tmp = tempfile::tempdir().unwrap();
    let k = |name: &str, centre: &str| {
        let dir = tmp.path().join(name);
        let sets = [
            "fluid.model=newtonian",
            "fluid.relaxation_time=0",
            "fluid.beta=1",
            "run.end_time=3",
            "run.steady.average=0.5",
            "run.steady.tolerance=1e-12",
            centre,
        ];
        run_case("cases/confined-cylinder.toml", &dir, &sets);
        summary(&dir)["steady"]["drag_k"].as_f64().unwrap()
    };
    let on_node = k("node", "scene.cylinder.centre=[15.0, 2.0]");
    let shifted = k("shifted", "scene.cylinder.centre=[15.025, 2.0]");
    assert!(
        (shifted / on_node - 1.0).abs() < 2e-3,
        "K = {on_node}, {shifted}"
    );
    for kk in [on_node, shifted] {
        assert!((kk / 132.36 - 1.0).abs() < 3e-3, "K = {kk}");
    }
}

/// The square array of cylinders (`cases/square-array.toml`: c = π/36, R/δr = 10, Newtonian,
/// ⟨u⟩ held at 1) against the series solution of Sangani & Acrivos (1982), K = 22.310 for a
/// mean pressure gradient, 20.363 for the body force on the fluid alone. The cylinder is the
/// only sink of momentum, so the body force measures the drag of the flow itself: measured
/// 20.067 (−1.45 %; −0.22 % at R/δr = 15 and −0.20 % at 20). Bound: 2.5 %, the coarse
/// resolution's error with a margin for the steady criterion. The case runs in about 12 s.
#[test]
fn newtonian_square_array_drag_matches_sangani_acrivos() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("square");
    run_case("cases/square-array.toml", &dir, &[]);
    let st = &summary(&dir)["steady"];
    let c = std::f64::consts::PI / 36.0;
    let series = 4.0 * std::f64::consts::PI
        / (-0.5 * c.ln() - 0.738 + c - 0.887 * c * c + 2.038 * c * c * c);
    let exact = series * (1.0 - c);
    assert!((exact - 20.363).abs() < 1e-3, "{exact}");
    let body = st["momentum_balance"]["body"].as_f64().unwrap();
    assert!(
        (body / exact - 1.0).abs() < 0.025,
        "K = {body} against {exact}: {st}"
    );
}
