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
