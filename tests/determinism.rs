//! Reproducibility: the same case gives bit-identical series with one and with two threads
//! (all reductions are blocked and summed in order; neighbour lists are built in a fixed order).

mod common;
use common::poiseuille;
use rheosph::app::run::{run, RunOptions};

fn series_with_threads(threads: usize, extra: &[&str]) -> String {
    let mut overrides = vec![
        "scene.resolution=12",
        "run.end_time=0.3",
        "run.output_interval=0.01",
    ];
    overrides.extend_from_slice(extra);
    let case = poiseuille(&overrides);
    let dir = tempfile::tempdir().unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        run(
            &case,
            &RunOptions {
                out_dir: dir.path().to_path_buf(),
                quiet: true,
                charts: None,
                snapshots: false,
                progress: None,
            },
        )
        .unwrap()
    });
    std::fs::read_to_string(dir.path().join("series.csv")).unwrap()
}

/// Lagrangian with BiCGStab, Eulerian with the cached LU, and implicit viscosity.
#[test]
fn series_is_identical_with_one_and_two_threads() {
    for extra in [
        &[][..],
        &["scheme.frame=eulerian"],
        &["scheme.viscosity=implicit"],
    ] {
        let one = series_with_threads(1, extra);
        let two = series_with_threads(2, extra);
        assert!(one.lines().count() > 20);
        assert_eq!(one, two, "{extra:?}");
    }
}

/// The series of a shipped case (`cases/<name>.toml`) run to `end` with `overrides`, and the
/// number of cell searches it made.
fn series_of(name: &str, end: f64, overrides: &[&str]) -> (String, usize, u64) {
    let path = format!("{}/cases/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    let mut o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    o.push(format!("run.end_time={end}"));
    o.push(format!("run.output_interval={}", end / 20.0));
    let case = rheosph::setup::case::parse(&text, &path, name, &o).unwrap();
    let (summary, dir) = common::run_quiet(&case, false);
    let series = std::fs::read_to_string(dir.path().join("series.csv")).unwrap();
    (series, summary.neighbour_searches, summary.steps)
}

/// The Verlet skin changes which steps search for neighbours, never the lists a step uses:
/// two skins give bit-identical series, past plane walls (the channel, explicit step), the
/// mirrors of a circle with their volume ratios (the cylinder array) and a free disc that
/// translates and turns between sliding walls (its mirrors move with it), the last two at the
/// implicit step, which moves particles ~0.3δr per step.
#[test]
fn the_neighbour_skin_changes_no_bit_of_the_results() {
    for (name, end, resolution, skins) in [
        ("poiseuille", 0.3, "scene.resolution=15", ["0.3", "1.0"]),
        ("cylinder-array", 0.6, "scene.resolution=36", ["0.8", "2.0"]),
        ("disc-migration", 2.0, "scene.resolution=64", ["0.8", "2.0"]),
    ] {
        let run = |skin: &str| {
            let skin = format!("scheme.neighbours.skin={skin}");
            series_of(name, end, &[resolution, &skin])
        };
        let (thin, thin_searches, steps) = run(skins[0]);
        let (thick, thick_searches, _) = run(skins[1]);
        eprintln!("{name}: {steps} steps, {thin_searches} and {thick_searches} searches");
        assert!(thin.lines().count() > 15, "{name}: too few outputs");
        assert!(
            thick_searches < thin_searches && (thin_searches as u64) <= steps,
            "{name}: the thicker skin must save searches ({thin_searches}, {thick_searches} of {steps})"
        );
        assert_eq!(thin, thick, "{name}");
    }
}
