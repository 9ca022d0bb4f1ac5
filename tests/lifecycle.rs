//! A run you can trust: every bad case file answered by one line, snapshots that a VTK reader
//! opens, files that survive being killed at any moment, case files that never panic.

mod common;
use common::poiseuille;
use rheosph::{engine::step::Simulation, setup::case};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

fn rheosph() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rheosph"))
}

/// Each file of `tests/bad_cases/` starts with `# expect: <field>`: `rheosph check` must
/// answer with exit code 2 and exactly one line naming the file and that field.
#[test]
fn bad_case_corpus_is_answered_by_one_line_each() {
    let mut files: Vec<PathBuf> = std::fs::read_dir("tests/bad_cases")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 30, "corpus has {} files", files.len());
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let field = text
            .lines()
            .next()
            .unwrap()
            .trim_start_matches("# expect: ")
            .trim();
        let o = rheosph().arg("check").arg(f).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let name = f.file_name().unwrap().to_string_lossy();
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains(&*name) && err.contains(field),
            "{name} (expect {field}): {err}"
        );
    }
}

/// A snapshot read back by vtkio's reader has every particle and the same values.
#[test]
fn vtu_snapshot_round_trips_through_a_vtk_reader() {
    use vtkio::model::{Attribute, DataSet, IOBuffer, Piece};
    let case = poiseuille(&["scene.resolution=12", "run.end_time=0.05"]);
    let mut sim = Simulation::new(case.setup().unwrap());
    for _ in 0..20 {
        sim.step(f64::INFINITY).unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.vtu");
    std::fs::write(&path, rheosph::app::vtk::snapshot(&sim)).unwrap();
    let vtk = vtkio::Vtk::import(&path).expect("vtkio reads our .vtu");
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline")
    };
    let n = sim.particles();
    assert_eq!(piece.num_points(), n);
    let array = |name: &str| -> Vec<f64> {
        piece
            .data
            .point
            .iter()
            .find_map(|a| match a {
                Attribute::DataArray(d) if d.name == name => match &d.data {
                    IOBuffer::F64(v) => Some(v.clone()),
                    _ => None,
                },
                _ => None,
            })
            .unwrap_or_else(|| panic!("no array {name}"))
    };
    let velocity = array("velocity");
    let pressure = array("pressure");
    let tau_xy = array("tau_xy");
    let tau = sim.polymer_stress();
    for i in 0..n {
        assert_eq!(velocity[3 * i], sim.state.velocity[i].x);
        assert_eq!(pressure[i], sim.state.pressure[i]);
        assert_eq!(tau_xy[i], tau[i].xy);
    }
    for name in ["tau_xx", "tau_yy", "trace_A", "det_A"] {
        assert_eq!(array(name).len(), n);
    }
}

/// Every file of a run directory parses: series.csv, summary.json (if present), every .vtu
/// listed in snapshots.pvd and every .vti in grid.pvd.
fn assert_readable(dir: &Path) {
    if dir.join("series.csv").exists() {
        rheosph::app::io::read_series(&dir.join("series.csv")).expect("series.csv parses");
    }
    if dir.join("summary.json").exists() {
        let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).expect("summary.json parses");
    }
    for collection in ["snapshots.pvd", "grid.pvd"] {
        if !dir.join(collection).exists() {
            continue;
        }
        let pvd = std::fs::read_to_string(dir.join(collection)).unwrap();
        assert!(pvd.trim_end().ends_with("</VTKFile>"), "truncated .pvd");
        for file in pvd
            .split("file=\"")
            .skip(1)
            .map(|s| s.split('"').next().unwrap())
        {
            vtkio::Vtk::import(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        }
    }
}

/// The run is killed (SIGKILL) at several moments while it writes series rows every 0.002
/// time units and a snapshot every 0.005; after each kill every file still parses.
#[test]
fn killed_runs_leave_readable_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    // Delays spread over the run, so kills land during steps, series flushes and snapshots.
    for delay_ms in [150u64, 420, 730, 1100, 1650, 2300] {
        let mut child = rheosph()
            .args(["run", "cases/poiseuille.toml", "-q", "--no-charts", "--out"])
            .arg(&out)
            .args([
                "--set",
                "scene.resolution=20",
                "--set",
                "run.end_time=1",
                "--set",
                "run.output_interval=0.002",
                "--set",
                "run.snapshot_interval=0.005",
            ])
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        child.wait().unwrap();
        assert_readable(&out);
    }
}

/// A tiny deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[(self.next() % items.len() as u64) as usize]
    }
}

/// Random mutations of every shipped case (values replaced by hostile ones, lines deleted or
/// duplicated): parsing never panics, and every mutation that validates runs three steps
/// without panicking (a breakdown is an allowed outcome).
#[test]
fn mutated_case_files_never_panic() {
    let values = [
        "0",
        "-1",
        "1e308",
        "-1e-300",
        "nan",
        "inf",
        "-inf",
        "\"abc\"",
        "true",
        "[1, 2]",
        "3.5",
        "2",
        "0.5",
        "1e6",
        "12",
        "[]",
        "{}",
        "\"lagrangian\"",
        "\"oldroyd-b\"",
        "0.0001",
    ];
    let mut rng = Rng(20261121);
    let mut validated = 0;
    let mut rejected = 0;
    for case_file in [
        "poiseuille",
        "fene-p",
        "fene-cr",
        "lptt",
        "eptt",
        "giesekus",
        "taylor-green",
    ] {
        let text = std::fs::read_to_string(format!("cases/{case_file}.toml")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for _ in 0..40 {
            let mut mutated: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            for _ in 0..(1 + rng.next() % 3) {
                let k = (rng.next() % mutated.len() as u64) as usize;
                match rng.next() % 4 {
                    0 | 1 => {
                        if let Some((key, _)) = mutated[k].split_once('=') {
                            mutated[k] = format!("{key}= {}", rng.pick(&values));
                        }
                    }
                    2 => mutated[k].clear(),
                    _ => {
                        let copy = mutated[k].clone();
                        mutated.insert(k, copy);
                    }
                }
            }
            let candidate = mutated.join("\n");
            let outcome = std::panic::catch_unwind(|| {
                let parsed = case::parse(&candidate, "fuzz.toml", "fuzz", &[]);
                if let Ok(c) = &parsed {
                    if c.scene.particles() <= 20_000 {
                        let mut sim = Simulation::new(c.setup().unwrap());
                        for _ in 0..3 {
                            if sim.step(c.end_time).is_err() {
                                break;
                            }
                        }
                    }
                }
                parsed.is_ok()
            });
            match outcome {
                Ok(true) => validated += 1,
                Ok(false) => rejected += 1,
                Err(_) => panic!("panic on mutated case:\n{candidate}"),
            }
        }
    }
    assert!(
        validated > 10 && rejected > 50,
        "validated {validated}, rejected {rejected}"
    );
}
