//! The layers import one way only (ARCHITECTURE.md): the engine nothing outside itself,
//! analysis only the engine, set-up the engine and analysis, and only the application (behind
//! the `app` feature) the command line, plots, VTK and progress bars. Checked on the source
//! text: a `crate::<layer>` path in a file of a lower layer fails the test. Within a layer no
//! files import each other in a circle (`scripts/module_cycles.py`, which leaves out
//! `#[cfg(test)]` modules): a circle means a stage reaches back into the code that configures
//! it, where each stage should own its settings.

use std::path::Path;

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The files of `layer` that mention a path of a layer it must not import.
fn violations(layer: &str, forbidden: &[&str]) -> Vec<String> {
    let mut files = Vec::new();
    sources(&Path::new("src").join(layer), &mut files);
    assert!(!files.is_empty(), "no sources in src/{layer}");
    let mut found = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            for other in forbidden {
                let crate_path = format!("crate::{other}");
                let external = ["clap", "plotters", "indicatif", "vtkio"];
                let uses_app_crate = *other == "app"
                    && external.iter().any(|c| {
                        line.contains(&format!("{c}::")) || line.contains(&format!("use {c}"))
                    });
                if line.contains(&crate_path) || uses_app_crate {
                    found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                }
            }
        }
    }
    found
}

#[test]
fn the_engine_imports_no_other_layer() {
    let v = violations("engine", &["analysis", "setup", "app"]);
    assert!(v.is_empty(), "{}", v.join("\n"));
}

#[test]
fn analysis_imports_only_the_engine() {
    let v = violations("analysis", &["setup", "app"]);
    assert!(v.is_empty(), "{}", v.join("\n"));
}

#[test]
fn setup_imports_no_application() {
    let v = violations("setup", &["app"]);
    assert!(v.is_empty(), "{}", v.join("\n"));
}

/// Fails with the circles `scripts/module_cycles.py` finds among the files under `src`.
fn no_circles_in(src: &str) {
    let out = std::process::Command::new("python3")
        .args(["scripts/module_cycles.py", src])
        .output()
        .expect("python3 runs scripts/module_cycles.py");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "import circles in {src}:\n{report}");
}

#[test]
fn no_file_imports_itself_through_others() {
    no_circles_in("src");
    no_circles_in("solver/src");
}
