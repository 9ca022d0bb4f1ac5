#!/bin/sh
# The whole test suite, as CI runs it: the Rust workspace, then the Python package installed
# by pip into a fresh virtual environment and its unittest suite. Needs only a Rust toolchain
# and python3 (pip fetches maturin, numpy and dask.distributed from PyPI).
set -eu
cd "$(dirname "$0")/.."
# The default members (rheosph and its solver); the extension is built by pip below.
cargo test --release
venv=target/python-test-venv
rm -rf "$venv"
python3 -m venv "$venv"
# The extension reuses the release artefacts cargo test just built (python/Cargo.toml says
# how): pip compiles pyo3 and the extension crate only.
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}" "$venv/bin/pip" install --quiet "./python[dask]"
"$venv/bin/python" -m unittest discover -s python/tests -v
