//! The `rheosph` binary: run directory contents, bad input, breakdown as a result.

use std::path::Path;
use std::process::Command;

const POISEUILLE: &str = include_str!("../cases/poiseuille.toml");

fn rheosph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rheosph"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn write_case(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path)
        .map(|b| b.starts_with(b"\x89PNG\r\n\x1a\n"))
        .unwrap_or(false)
}

#[test]
fn run_writes_series_summary_and_charts() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), "p.toml", POISEUILLE);
    let out = dir.path().join("run");
    let o = rheosph(&[
        "run",
        &case,
        "-q",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "scene.resolution=12",
        "--set",
        "run.end_time=0.2",
        "--set",
        "run.output_interval=0.01",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = rheosph::app::io::read_series(&out.join("series.csv")).unwrap();
    assert!(rows.len() > 10);
    assert!(rows
        .iter()
        .all(|r| r.l2_error.is_finite() && r.u_centre.is_finite()));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "finished");
    assert!(summary["reason"].is_null());
    for key in [
        "t_reached",
        "particles",
        "steps",
        "wall_seconds",
        "particle_steps_per_second",
    ] {
        assert!(summary[key].as_f64().is_some(), "summary lacks {key}");
    }
    for stage in [
        "neighbours",
        "constitutive",
        "ppe_assembly",
        "ppe_solve",
        "projection",
    ] {
        assert!(summary["stage_seconds"][stage].as_f64().unwrap() >= 0.0);
    }
    for png in [
        "centre_velocity.png",
        "l2_error.png",
        "profile_velocity.png",
        "profile_tau_xy.png",
    ] {
        assert!(is_png(&out.join(png)), "{png}");
    }
    // No temporary files left behind by the atomic writers.
    for entry in std::fs::read_dir(&out).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.contains(".tmp"), "leftover {name}");
    }
}

/// `--figure-format svg` writes the same charts as the PNG run, as SVG documents with the
/// same titles and legends (text elements), and no PNG.
#[test]
fn figure_format_svg_writes_the_same_charts_as_svg() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), "p.toml", POISEUILLE);
    let charts = |format: &str| -> Vec<String> {
        let out = dir.path().join(format);
        let o = rheosph(&[
            "run",
            &case,
            "-q",
            "--no-snapshots",
            "--figure-format",
            format,
            "--out",
            out.to_str().unwrap(),
            "--set",
            "scene.resolution=12",
            "--set",
            "run.end_time=0.05",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "png" || e == "svg"))
            .map(|p| p.to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    let png = charts("png");
    let svg = charts("svg");
    assert!(png.len() >= 4 && png.iter().all(|p| p.ends_with(".png")));
    let stems = |v: &[String]| -> Vec<String> {
        v.iter()
            .map(|p| {
                Path::new(p)
                    .file_stem()
                    .unwrap()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect()
    };
    assert_eq!(stems(&png), stems(&svg));
    for file in &svg {
        let text = std::fs::read_to_string(file).unwrap();
        assert!(
            text.starts_with("<svg") && text.trim_end().ends_with("</svg>"),
            "{file}"
        );
    }
    let centre = std::fs::read_to_string(dir.path().join("svg/centre_velocity.svg")).unwrap();
    assert!(centre.contains("Centre-line velocity") && centre.contains("Waters"));
}

/// Each mistake is answered by exactly one line naming the file and the field, exit code 2.
#[test]
fn bad_input_is_one_clear_line_and_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let good = write_case(dir.path(), "good.toml", POISEUILLE);
    let edits: &[(&str, &str, &str)] = &[
        (
            "unknown_key.toml",
            "relaxation_time = 1.0",
            "relaxation_time = 1.0\ncolour = 3",
        ),
        ("unknown_table.toml", "[run]", "[extra]\nx = 1\n[run]"),
        ("missing_density.toml", "density = 1.0          # rho", ""),
        ("beta_high.toml", "beta = 0.1", "beta = 1.5"),
        ("beta_negative.toml", "beta = 0.1", "beta = -0.1"),
        ("density_zero.toml", "density = 1.0", "density = 0.0"),
        ("density_negative.toml", "density = 1.0", "density = -1.0"),
        ("viscosity_zero.toml", "viscosity = 1.0", "viscosity = 0.0"),
        ("resolution_zero.toml", "resolution = 30", "resolution = 0"),
        (
            "resolution_negative.toml",
            "resolution = 30",
            "resolution = -30",
        ),
        (
            "resolution_coarse.toml",
            "resolution = 30",
            "resolution = 5",
        ),
        (
            "model_unknown.toml",
            "model = \"oldroyd-b\"",
            "model = \"maxwell\"",
        ),
        (
            "frame_typo.toml",
            "frame = \"lagrangian\"",
            "frame = \"lagrange\"",
        ),
        ("not_toml.toml", "[fluid]", "[fluid"),
    ];
    let field_of = |name: &str| match name {
        "unknown_key.toml" => "colour",
        "unknown_table.toml" => "extra",
        "missing_density.toml" => "density",
        "beta_high.toml" | "beta_negative.toml" => "fluid.beta",
        "density_zero.toml" | "density_negative.toml" => "fluid.density",
        "viscosity_zero.toml" => "fluid.viscosity",
        n if n.starts_with("resolution") => "scene.resolution",
        "model_unknown.toml" => "fluid.model",
        "frame_typo.toml" => "scheme.frame",
        _ => "TOML",
    };
    for (name, from, to) in edits {
        assert!(POISEUILLE.contains(from), "{name}: pattern not in case");
        let path = write_case(dir.path(), name, &POISEUILLE.replacen(from, to, 1));
        let out_dir = dir.path().join("x");
        let out_dir = out_dir.to_str().unwrap();
        for args in [
            vec!["check", &path],
            vec!["run", &path, "-q", "--out", out_dir],
        ] {
            let sub = args[0];
            let o = rheosph(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{sub} {name}: {err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{sub} {name}: {err}");
            assert!(
                err.contains(name),
                "{sub} {name} does not name the file: {err}"
            );
            assert!(
                err.contains(field_of(name)),
                "{sub} {name} does not name the field: {err}"
            );
        }
    }
    let overrides: &[(&str, &str)] = &[
        ("fluid.beta", "fluid.beta"),
        ("=3", "--set"),
        ("fluid.beta=", "--set"),
        ("fluid.colour=2", "colour"),
        ("scene.resolution=abc", "scene.resolution"),
        ("fluid.viscosity=-2", "fluid.viscosity"),
        ("fluid.model=ucm", "fluid.beta"),
        ("fluid.model=fene-p", "fluid.l2"),
        ("fluid.l2=50", "fluid.l2"),
        ("fluid.alpha=0.2", "fluid.alpha"),
    ];
    let models: &[(&[&str], &str)] = &[
        (&["fluid.model=fene-p", "fluid.l2=2"], "fluid.l2"),
        (&["fluid.model=fene-cr", "fluid.l2=1.5"], "fluid.l2"),
        (&["fluid.model=lptt", "fluid.epsilon=-0.1"], "fluid.epsilon"),
        (&["fluid.model=eptt"], "fluid.epsilon"),
        (&["fluid.model=giesekus", "fluid.alpha=0.6"], "fluid.alpha"),
        (
            &["fluid.model=giesekus", "fluid.alpha=-0.01"],
            "fluid.alpha",
        ),
        (
            &["fluid.model=giesekus", "fluid.alpha=0.2", "fluid.l2=10"],
            "fluid.l2",
        ),
    ];
    for (sets, field) in models {
        let mut args = vec!["check", good.as_str()];
        for s in *sets {
            args.push("--set");
            args.push(s);
        }
        let o = rheosph(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{sets:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{sets:?}: {err}");
        assert!(err.contains(field), "{sets:?}: {err}");
    }
    for (set, field) in overrides {
        let o = rheosph(&["check", &good, "--set", set]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--set {set}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "--set {set}: {err}");
        assert!(
            err.contains("good.toml") && err.contains(field),
            "--set {set}: {err}"
        );
    }
    let o = rheosph(&["check", dir.path().join("absent.toml").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

/// `rheosph check` into a reader that has already gone (`… | head -1` after its line) exits
/// 0 without a panic: the pipe is closed before the binary writes, so its write fails with
/// EPIPE (the Rust runtime ignores SIGPIPE), which used to panic inside `println!`.
#[test]
fn check_into_a_closed_pipe_is_not_a_crash() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rheosph"))
        .args(["check", "cases/poiseuille.toml"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(out.status.code(), Some(0), "{err}");
}

/// A run forced to blow up (δt eight times the viscous limit of eq. (28)) stops cleanly:
/// outcome `broke_down` with time and reason, exit code 3, and its files intact.
#[test]
fn forced_blow_up_is_recorded_not_crashed() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), "p.toml", POISEUILLE);
    let out = dir.path().join("run");
    let o = rheosph(&[
        "run",
        &case,
        "-q",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "scene.resolution=12",
        "--set",
        "run.end_time=2",
        "--set",
        "scheme.time_step.factor=8",
    ]);
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "broke_down");
    assert!(summary["reason"].as_str().is_some_and(|r| !r.is_empty()));
    let t = summary["t_reached"].as_f64().unwrap();
    assert!(t > 0.0 && t < 2.0);
    let rows = rheosph::app::io::read_series(&out.join("series.csv")).unwrap();
    assert!(!rows.is_empty());
    assert!(is_png(&out.join("centre_velocity.png")));
}

/// `rheosph rheometry` writes the material functions of a case's fluid with the exact ones:
/// for the Oldroyd-B Poiseuille fluid (η0 = 1, β = 0.1, λ = 1), η = η0 and Ψ₁ = 2η_pλ = 1.8
/// at every rate, within 0.5 % (measured ≤ 0.1 %: the first-order splitting at δt = 10⁻³ of
/// the shortest time), and a bad key is one error naming it.
#[test]
fn rheometry_writes_material_functions() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rheo");
    let o = rheosph(&[
        "rheometry",
        "cases/poiseuille.toml",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(out.join("steady_shear.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (rate, eta, psi1) = (col("shear_rate"), col("viscosity"), col("psi1"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() >= 20);
    for r in &rows {
        assert!((r[eta] - 1.0).abs() < 5e-3, "η at {}: {}", r[rate], r[eta]);
        assert!(
            (r[psi1] - 1.8).abs() < 9e-3,
            "Ψ₁ at {}: {}",
            r[rate],
            r[psi1]
        );
    }
    for f in ["startup_shear", "planar_extension", "saos", "steady_shear"] {
        assert!(out.join(format!("{f}.csv")).exists(), "{f}.csv");
        assert!(is_png(&out.join(format!("{f}.png"))), "{f}.png");
    }
    let bad = rheosph(&[
        "rheometry",
        "cases/poiseuille.toml",
        "-q",
        "--set",
        "fluid.beta=2",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("fluid.beta"));
}

/// `run --from DIR` starts from DIR's final state with the new case's parameters: its first
/// row (t = 0) carries the finished run's last centre-line velocity bit for bit, the clock
/// restarts, the start-up reference is withdrawn (it describes a fluid at rest), and a scene
/// that does not match particle for particle is refused with the reason. At another
/// resolution of the same box the state is interpolated; a box of another size is refused.
#[test]
fn run_from_continues_another_runs_final_state() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    let run = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "run",
            "cases/poiseuille.toml",
            "-q",
            "--no-snapshots",
            "--no-charts",
            "--out",
            out.to_str().unwrap(),
            "--set",
            "run.end_time=0.3",
        ];
        args.extend_from_slice(extra);
        rheosph(&args)
    };
    let first = run(&a, &["--set", "scene.resolution=12"]);
    assert!(first.status.success());
    assert!(a.join("final_state.bin").exists());
    let from = a.to_str().unwrap();
    let next = run(
        &b,
        &[
            "--set",
            "scene.resolution=12",
            "--set",
            "fluid.relaxation_time=2",
            "--from",
            from,
        ],
    );
    assert!(
        next.status.success(),
        "{}",
        String::from_utf8_lossy(&next.stderr)
    );
    let field = |d: &Path, row: usize, col: usize| -> String {
        let text = std::fs::read_to_string(d.join("series.csv")).unwrap();
        let line = if row == usize::MAX {
            text.lines().last().unwrap().to_string()
        } else {
            text.lines().nth(row).unwrap().to_string()
        };
        line.split(',').nth(col).unwrap().to_string()
    };
    assert_eq!(
        field(&a, usize::MAX, 3),
        field(&b, 1, 3),
        "u_centre carried over"
    );
    assert_eq!(field(&b, 1, 0).parse::<f64>().unwrap(), 0.0);
    let summary = std::fs::read_to_string(b.join("summary.json")).unwrap();
    assert!(summary.contains("start-up solution does not apply"));
    // The same spacing in a longer box: the particles do not match.
    let wrong = run(
        &c,
        &[
            "--set",
            "scene.resolution=12",
            "--set",
            "scene.length=1.5",
            "--from",
            from,
        ],
    );
    assert!(!wrong.status.success());
    assert!(String::from_utf8_lossy(&wrong.stderr).contains("144 particles stored"));
    // Another resolution: the state is interpolated onto the finer lattice. The centre-line
    // velocity at t = 0 is the stored one within the interpolation's error at the centre,
    // where the profile is smooth (the quadratic fit over 12 particles across: < 1 %).
    let d = dir.path().join("d");
    let finer = run(&d, &["--set", "scene.resolution=18", "--from", from]);
    assert!(
        finer.status.success(),
        "{}",
        String::from_utf8_lossy(&finer.stderr)
    );
    let stored: f64 = field(&a, usize::MAX, 3).parse().unwrap();
    let started: f64 = field(&d, 1, 3).parse().unwrap();
    assert!(
        (started / stored - 1.0).abs() < 0.01,
        "u_centre {started} from {stored}"
    );
    // A box of another size cannot be interpolated onto.
    let e = dir.path().join("e");
    let other = run(
        &e,
        &[
            "--set",
            "scene.resolution=18",
            "--set",
            "scene.length=2",
            "--from",
            from,
        ],
    );
    assert!(!other.status.success());
    assert!(String::from_utf8_lossy(&other.stderr).contains("domains differ"));
}

/// The committed key references are what the code generates (`rheosph keys --markdown`, with
/// `--page case` for `[scene]` and `[fluid]`): a key added, renamed or re-documented without
/// regenerating its page fails here.
#[test]
fn the_key_reference_pages_are_what_the_code_generates() {
    for (page, file) in [
        ("scheme", "docs/src/reference/scheme-keys.md"),
        ("case", "docs/src/reference/case-keys.md"),
    ] {
        let o = rheosph(&["keys", "--markdown", "--page", page]);
        assert!(o.status.success());
        let generated = String::from_utf8(o.stdout).unwrap();
        let committed = std::fs::read_to_string(file).unwrap();
        assert!(
            generated == committed,
            "{file} is stale: rheosph keys --markdown --page {page} > {file}"
        );
    }
}

/// Every table of the validation pages marked `<!-- generated: ... -->` holds the numbers its
/// committed run outputs under `plots/` give (`rheosph gallery` regenerates them): a number
/// typed by hand into such a table, or a rerun whose page was not regenerated, fails here.
#[test]
fn the_validation_pages_generated_tables_match_their_runs() {
    let o = rheosph(&["gallery", "--check"]);
    assert!(
        o.status.success(),
        "committed numbers contradict their runs (rheosph gallery rewrites them):\n{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A study's members run elsewhere: `--emit` writes their cases and scripts and runs nothing;
/// `--collect` with a member not yet run writes the table with a `lost` row for it, lists it
/// and exits with status 4; after its run stopped on an error, the row is `failed` with that
/// error; once the emitted script has run it (skipping the one run by hand), `--collect`
/// assembles the same `stability.csv` as the study run here, wall times aside (runs are
/// deterministic whatever the thread count).
#[test]
fn emitted_members_run_elsewhere_collect_to_the_same_study() {
    let dir = tempfile::tempdir().unwrap();
    let (here, emit) = (dir.path().join("here"), dir.path().join("emit"));
    let study = |extra: &[&str]| {
        let mut args = vec![
            "study",
            "stability",
            "cases/poiseuille.toml",
            "--wi",
            "0.5,2",
            "--set",
            "scene.resolution=12",
            "--set",
            "run.end_time=0.5",
        ];
        args.extend_from_slice(extra);
        rheosph(&args)
    };
    assert!(study(&["--jobs", "2", "--out", here.to_str().unwrap()])
        .status
        .success());
    let out = study(&["--emit", emit.to_str().unwrap()]);
    assert!(out.status.success(), "{out:?}");
    let members = std::fs::read_to_string(emit.join("members.txt")).unwrap();
    let members: Vec<&str> = members.lines().collect();
    assert_eq!(members, ["runs/Wi_0.5", "runs/Wi_2"]);
    assert!(!emit.join("stability.csv").exists());
    let slurm = std::fs::read_to_string(emit.join("job-array.slurm")).unwrap();
    assert!(slurm.contains("#SBATCH --array=0-1"), "{slurm}");
    // One member by hand, as a scheduler would run it; the other is missing.
    let first = emit.join(members[0]);
    let case = first.join("case.toml");
    let ran = rheosph(&[
        "run",
        case.to_str().unwrap(),
        "--out",
        first.to_str().unwrap(),
    ]);
    assert!(ran.status.success(), "{ran:?}");
    let stamp = std::fs::metadata(first.join("summary.json"))
        .unwrap()
        .modified()
        .unwrap();
    let collect = || study(&["--collect", emit.to_str().unwrap()]);
    let row_of_wi_2 = || {
        let table = std::fs::read_to_string(emit.join("stability.csv")).unwrap();
        let row = table.lines().find(|l| l.starts_with("base,2,"));
        row.map(String::from).unwrap_or_default()
    };
    let out = collect();
    let text = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(4), "{text}");
    assert!(
        text.contains("1 of 2 members have not finished")
            && text.contains("Wi_2: lost")
            && text.contains("sbatch --array=1 job-array.slurm"),
        "{text}"
    );
    assert!(
        row_of_wi_2().starts_with("base,2,lost,"),
        "{}",
        row_of_wi_2()
    );
    assert!(emit.join("stability_map.png").exists());
    // The second member's run stops on an error (a bad value): a `failed` row, its reason
    // the error.
    let second = emit.join(members[1]);
    let bad = rheosph(&[
        "run",
        second.join("case.toml").to_str().unwrap(),
        "--out",
        second.to_str().unwrap(),
        "--set",
        "scene.resolution=many",
    ]);
    assert_eq!(bad.status.code(), Some(2), "{bad:?}");
    let out = collect();
    assert_eq!(out.status.code(), Some(4));
    let row = row_of_wi_2();
    assert!(
        row.starts_with("base,2,failed,") && row.contains("scene.resolution"),
        "{row}"
    );
    let script = Command::new("bash")
        .arg(emit.join("run-members.sh"))
        .env("RHEOSPH", env!("CARGO_BIN_EXE_rheosph"))
        .output()
        .unwrap();
    assert!(script.status.success(), "{script:?}");
    let again = std::fs::metadata(first.join("summary.json"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(stamp, again, "a finished member was run again");
    assert!(
        !second.join("error.txt").exists(),
        "a new run keeps an old error"
    );
    assert!(collect().status.success());
    let without_wall = |path: &Path| -> Vec<String> {
        let text = std::fs::read_to_string(path).unwrap();
        text.lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert_eq!(
        without_wall(&here.join("stability.csv")),
        without_wall(&emit.join("stability.csv"))
    );
}
