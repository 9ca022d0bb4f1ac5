//! Reproducibility: the same case gives bit-identical series with one and with two threads
//! (all reductions are blocked and summed in order; neighbour lists are built in a fixed order).

mod common;
use common::poiseuille;
use rheosph::run::{run, RunOptions};

fn series_with_threads(threads: usize) -> String {
    let case = poiseuille(&[
        "scene.resolution=12",
        "run.end_time=0.3",
        "run.output_interval=0.01",
    ]);
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
                charts: false,
            },
        )
        .unwrap()
    });
    std::fs::read_to_string(dir.path().join("series.csv")).unwrap()
}

#[test]
fn series_is_identical_with_one_and_two_threads() {
    let one = series_with_threads(1);
    let two = series_with_threads(2);
    assert!(one.lines().count() > 20);
    assert_eq!(one, two);
}
