//! The declared minimum Rust version is true of the dependencies: no crate this workspace
//! builds on the host (normal, build and dev dependencies, after platform filtering, so
//! `cfg(loom)`-only crates do not count) declares a newer `rust-version` than the workspace
//! does. The workspace's own code is held to the same version by clippy's `incompatible_msrv`
//! lint, which reads `rust-version` (`cargo clippy -- -D warnings`). Only one toolchain can be
//! installed here, so building with the declared one is left to a machine that has it.

use std::process::Command;

/// (major, minor, patch), a missing patch being 0.
fn version(v: &str) -> [u64; 3] {
    let mut parts = v.split('.').map(|p| p.parse().unwrap_or(0));
    [0; 3].map(|_| parts.next().unwrap_or(0))
}

#[test]
fn declared_rust_version_covers_every_dependency() {
    let manifest = std::fs::read_to_string("Cargo.toml").unwrap();
    let manifest: toml::Value = toml::from_str(&manifest).unwrap();
    let declared = manifest["workspace"]["package"]["rust-version"]
        .as_str()
        .unwrap()
        .to_string();

    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let host = Command::new(std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into()))
        .arg("-vV")
        .output()
        .expect("rustc runs");
    let host = String::from_utf8(host.stdout).unwrap();
    let host = host
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .expect("rustc -vV names the host")
        .to_string();
    let out = Command::new(cargo)
        // Not `--offline`: the Python extension's crates (pyo3) are workspace dependencies
        // that `cargo test` does not build, so a fresh machine has not downloaded them yet.
        .args(["metadata", "--format-version", "1", "--locked"])
        .args(["--filter-platform", &host])
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let built: std::collections::HashSet<&str> = meta["resolve"]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["id"].as_str().unwrap())
        .collect();
    let mut newer = Vec::new();
    let mut newest = ([0; 3], String::new());
    for p in meta["packages"].as_array().unwrap() {
        // Workspace members (no registry source) are what the declaration is about.
        if !built.contains(p["id"].as_str().unwrap()) || p["source"].is_null() {
            continue;
        }
        let Some(rv) = p["rust_version"].as_str() else {
            continue;
        };
        let name = format!("{} {} (rust-version {rv})", p["name"], p["version"]);
        if version(rv) > version(&declared) {
            newer.push(name.clone());
        }
        if version(rv) > newest.0 {
            newest = (version(rv), name);
        }
    }
    eprintln!("declared {declared}; the newest requirement: {}", newest.1);
    assert!(
        newer.is_empty(),
        "rust-version {declared} is below: {newer:?}"
    );
    assert!(built.len() > 50, "{} packages resolved", built.len());
}
