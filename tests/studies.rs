//! Studies end to end at a coarse, short scale: their CSV and PNG files exist and parse, and
//! a forced breakdown is a row of data, not a crash.

use rheosph::app::plot::FigureFormat;
use rheosph::app::study::{self, Base, Executor};
use std::path::PathBuf;

fn base(sets: &[&str]) -> Base {
    Base {
        path: PathBuf::from("cases/poiseuille.toml"),
        sets: sets.iter().map(|s| s.to_string()).collect(),
        reuse: false,
        executor: Executor::Here,
    }
}

fn is_png(path: &std::path::Path) -> bool {
    std::fs::read(path)
        .map(|b| b.starts_with(b"\x89PNG"))
        .unwrap_or(false)
}

#[test]
fn convergence_study_writes_its_table_and_figures() {
    let out = tempfile::tempdir().unwrap();
    let rows = study::convergence::run(
        &base(&["run.end_time=0.3"]),
        &[12, 24],
        &["lagrangian".to_string(), "eulerian".to_string()],
        out.path(),
        FigureFormat::Png,
        2,
        true,
    )
    .unwrap();
    assert_eq!(rows.len(), 4);
    // Second order at these resolutions (measured 2.1 in both frames).
    for r in rows.iter().filter(|r| r.resolution == 24) {
        let order = r.order.unwrap();
        assert!(order > 1.6, "{} order {order}", r.frame);
    }
    let csv = std::fs::read_to_string(out.path().join("convergence.csv")).unwrap();
    assert!(csv.starts_with(
        "frame,resolution,spacing,particles,steps,wall_seconds,l2_mean,l2_final,order"
    ));
    assert_eq!(csv.lines().count(), 5);
    assert!(is_png(&out.path().join("l2_vs_time.png")));
    assert!(is_png(&out.path().join("l2_vs_resolution.png")));
}

/// δt eight times the viscous limit of (28) blows up: recorded as `broke_down` with its time
/// and reason, beside a stable variant.
#[test]
fn stability_study_records_a_forced_breakdown() {
    let out = tempfile::tempdir().unwrap();
    let varies = study::product(&[study::parse_vary("scheme.time_step.factor=0.2,8").unwrap()]);
    let rows = study::stability::run(
        &base(&["scene.resolution=12", "run.end_time=2"]),
        &[1.0],
        &varies,
        0.1,
        out.path(),
        FigureFormat::Png,
        1,
        true,
    )
    .unwrap();
    assert_eq!(rows.len(), 2);
    let ok = rows
        .iter()
        .find(|r| r.variant == "time_step.factor=0.2")
        .unwrap();
    let bad = rows
        .iter()
        .find(|r| r.variant == "time_step.factor=8")
        .unwrap();
    assert_eq!(ok.outcome, study::stability::Result3::Stable);
    assert_eq!(bad.outcome, study::stability::Result3::BrokeDown);
    assert!(bad.t_breakdown.unwrap() < 2.0 && bad.reason.is_some());
    let csv = std::fs::read_to_string(out.path().join("stability.csv")).unwrap();
    assert!(csv.contains("broke_down"));
    assert!(is_png(&out.path().join("stability_map.png")));
}

#[test]
fn speed_accuracy_study_marks_a_pareto_front() {
    let out = tempfile::tempdir().unwrap();
    let varies =
        study::product(&[study::parse_vary("scheme.viscosity=explicit,implicit").unwrap()]);
    let points = study::speed_accuracy::run(
        &base(&["run.end_time=0.3"]),
        &[12, 24],
        &varies,
        out.path(),
        FigureFormat::Png,
        1,
        true,
    )
    .unwrap();
    assert_eq!(points.len(), 4);
    assert!(points.iter().any(|p| p.pareto));
    assert!(is_png(&out.path().join("speed_accuracy.png")));
    assert!(
        std::fs::read_to_string(out.path().join("speed_accuracy.csv"))
            .unwrap()
            .lines()
            .count()
            == 5
    );
}

/// Grid sequencing: at each Wi the coarse stage runs first and the case's resolution starts
/// from its final state. The fine run's first row carries the coarse run's bulk velocity
/// (the quadratic fit reproduces the mean flow to the interpolation error: within 1 %,
/// measured 0.1 %), det A ≥ 1 holds through both runs (the Shepard average keeps it), and
/// `cylinder.csv` has a line per stage with its R/δr. Run again with `reuse`, the study reads
/// its runs back instead of running them.
#[test]
fn cylinder_study_runs_coarse_to_fine() {
    let out = tempfile::tempdir().unwrap();
    let base = Base {
        path: PathBuf::from("cases/cylinder-array.toml"),
        sets: [
            "scene.resolution=54",
            "run.end_time=0.2",
            "scene.mean_flow=1.0",
        ]
        .map(String::from)
        .to_vec(),
        reuse: false,
        executor: Executor::Here,
    };
    let stage = study::cylinder::parse_stage("36:0.5").unwrap();
    let run_study = |base: &Base| {
        let format = FigureFormat::Png;
        study::cylinder::run(base, &[1.0], &[stage], None, out.path(), format, 1, true).unwrap()
    };
    let rows = run_study(&base);
    let r_over_dr: Vec<f64> = rows.iter().map(|r| r.radius_over_dr).collect();
    assert_eq!(r_over_dr, [9.0, 13.5]);
    for r in &rows {
        assert!(
            r.min_det_a_run >= 1.0 - 1e-9,
            "R/dr {}: {}",
            r.radius_over_dr,
            r.min_det_a_run
        );
    }
    let series = |label: &str| {
        rheosph::app::io::read_series(&out.path().join("runs").join(label).join("series.csv"))
            .unwrap()
    };
    let coarse = series("Wi_1_resolution_36");
    let fine = series("Wi_1");
    let (end, start) = (coarse.last().unwrap().u_mean, fine[0].u_mean);
    assert!((start / end - 1.0).abs() < 0.01, "<u> {end} -> {start}");
    let csv = std::fs::read_to_string(out.path().join("cylinder.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3);
    assert!(is_png(&out.path().join("centreline_det_a.png")));
    // `--reuse`: the same study again reads its finished runs back (the same wall times,
    // which a rerun would not reproduce).
    let again = run_study(&Base {
        reuse: true,
        ..base
    });
    // (Equal to 1e-9, not bit for bit: the JSON float parser may miss the last ulp.)
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs();
    for (a, b) in rows.iter().zip(&again) {
        assert!(
            same(a.wall_seconds, b.wall_seconds),
            "{} {}",
            a.wall_seconds,
            b.wall_seconds
        );
        assert!(same(a.drag_k, b.drag_k), "{} {}", a.drag_k, b.drag_k);
    }
    let csv_again = std::fs::read_to_string(out.path().join("cylinder.csv")).unwrap();
    assert_eq!(csv.lines().count(), csv_again.lines().count());
}

/// `--collect` with no member run: every study kind still writes its table, one `lost` row
/// per member (in its `outcome` column), and its charts, and ends with `Incomplete`.
#[test]
fn every_study_kind_collects_missing_members_as_lost_rows() {
    let out = tempfile::tempdir().unwrap();
    let collect = |path: &str| Base {
        path: PathBuf::from(path),
        executor: Executor::Collect,
        ..base(&["run.end_time=0.3"])
    };
    let dir = |name: &str| out.path().join(name);
    let (png, poiseuille) = (FigureFormat::Png, collect("cases/poiseuille.toml"));
    let (frames, one) = (["lagrangian".to_string()], study::product(&[]));
    let results = [
        (
            "convergence.csv",
            study::convergence::run(&poiseuille, &[12, 24], &frames, &dir("c"), png, 1, true)
                .map(|_| ()),
            dir("c"),
        ),
        (
            "stability.csv",
            study::stability::run(&poiseuille, &[1.0, 2.0], &one, 0.1, &dir("s"), png, 1, true)
                .map(|_| ()),
            dir("s"),
        ),
        (
            "speed_accuracy.csv",
            study::speed_accuracy::run(&poiseuille, &[12, 24], &one, &dir("a"), png, 1, true)
                .map(|_| ()),
            dir("a"),
        ),
        (
            "cylinder.csv",
            study::cylinder::run(
                &collect("cases/cylinder-array.toml"),
                &[0.5, 1.0],
                &[],
                None,
                &dir("y"),
                png,
                1,
                true,
            )
            .map(|_| ()),
            dir("y"),
        ),
    ];
    for (table, result, dir) in results {
        let e = result.expect_err(table);
        assert!(e.is::<study::Incomplete>(), "{table}: {e}");
        assert!(e.to_string().contains("2 of 2 members"), "{e}");
        let text = std::fs::read_to_string(dir.join(table)).unwrap();
        let mut lines = text.lines().map(|l| l.split(',').collect::<Vec<_>>());
        let header = lines.next().unwrap();
        let outcome = header.iter().position(|&h| h == "outcome").unwrap();
        let rows: Vec<Vec<&str>> = lines.collect();
        assert_eq!(rows.len(), 2, "{table}");
        assert!(
            rows.iter().all(|r| r[outcome] == "lost"),
            "{table}: {rows:?}"
        );
    }
}

/// A member whose run stops on an error, in a study run here: the others finish, the table
/// holds a `failed` row for it, the study ends with `Incomplete`; rerun with reuse, only the
/// failed member runs again.
#[test]
fn a_failed_member_of_a_local_study_is_a_row_and_is_rerun_alone() {
    let out = tempfile::tempdir().unwrap();
    let reuse = Base {
        reuse: true,
        ..base(&["scene.resolution=12", "run.end_time=0.2"])
    };
    let study = |b: &Base| {
        let one = study::product(&[]);
        let png = FigureFormat::Png;
        study::stability::run(b, &[1.0, 2.0, 4.0], &one, 0.1, out.path(), png, 2, true)
    };
    // The run cannot write its series.csv: a directory stands in its place.
    let blocked = out.path().join("runs/Wi_2/series.csv");
    std::fs::create_dir_all(&blocked).unwrap();
    let e = study(&reuse).expect_err("a member failed");
    assert!(e.is::<study::Incomplete>(), "{e}");
    assert!(e.to_string().contains("1 of 3 members"), "{e}");
    assert!(e.to_string().contains("--reuse"), "{e}");
    let csv = std::fs::read_to_string(out.path().join("stability.csv")).unwrap();
    let failed: Vec<&str> = csv.lines().filter(|l| l.contains(",failed")).collect();
    assert_eq!(failed.len(), 1, "{csv}");
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(out.path().join("runs/Wi_2/error.txt").exists());
    let written = |wi: &str| {
        let path = out.path().join(format!("runs/{wi}/summary.json"));
        std::fs::metadata(path).unwrap().modified().unwrap()
    };
    let before = [written("Wi_1"), written("Wi_4")];
    std::fs::remove_dir(&blocked).unwrap();
    let rows = study(&reuse).expect("the rerun completes the study");
    assert_eq!(rows.len(), 3);
    assert_eq!(
        before,
        [written("Wi_1"), written("Wi_4")],
        "finished members rerun"
    );
    assert!(!out.path().join("runs/Wi_2/error.txt").exists());
}
