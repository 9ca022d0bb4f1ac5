#!/usr/bin/env bash
# Fingerprints of short runs of every shipped case (and scheme variants covering each code
# path), and of a stability study: sha256 of series.csv, profile.csv and the probe CSVs.
# A refactoring that claims "no result changed" must print the same lines before and after.
#
#   scripts/fingerprint.sh [BIN] > fingerprints.txt
#
# BIN defaults to target/release/rheosph (build it first). Runs go to a temporary directory.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/rheosph}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run() { # label case [--set k=v]...
  local label=$1 case=$2
  shift 2
  local out="$work/$label"
  "$bin" run "cases/$case.toml" --out "$out" -q --no-charts --no-snapshots "$@" >/dev/null 2>&1 || true
  for f in series.csv profile.csv drop.csv jet.csv centreline.csv; do
    [ -f "$out/$f" ] && printf '%-34s %-15s %s\n' "$label" "$f" "$(sha256sum "$out/$f" | cut -c1-16)"
  done
  outcome=$(grep -o '"outcome": *"[a-z_]*"' "$out/summary.json" 2>/dev/null | head -1 | sed 's/.*: *//')
  printf '%-34s %-15s %s\n' "$label" outcome "${outcome:-none}"
}

S="--set run.end_time=0.5 --set run.output_interval=0.05"
run poiseuille poiseuille $S
run poiseuille-eulerian poiseuille $S --set scheme.frame=eulerian
run poiseuille-direct poiseuille $S --set scheme.conformation.form=direct
run poiseuille-implicit poiseuille $S --set scheme.viscosity=implicit
run poiseuille-implicit-standard poiseuille $S --set scheme.viscosity=implicit --set scheme.projection=standard
run poiseuille-incremental-explicit poiseuille $S --set scheme.projection=incremental
run poiseuille-lu poiseuille $S --set scheme.ppe.solver=lu --set scheme.frame=eulerian --set scheme.viscosity=implicit
run poiseuille-bicgstab-cold poiseuille $S --set scheme.ppe.solver=bicgstab --set scheme.ppe.warm_start=false
run poiseuille-reflected poiseuille $S --set scheme.walls.conformation=reflected
run poiseuille-noshift-noreorder poiseuille $S --set scheme.shifting=false --set scheme.neighbours.reorder=false
run poiseuille-ucm-evss poiseuille $S --set fluid.model=ucm --set fluid.beta=0 --set scheme.conformation.evss_alpha=0.01 --set scheme.viscosity=implicit
run poiseuille-newtonian poiseuille $S --set fluid.model=newtonian --set fluid.beta=1 --set fluid.relaxation_time=0
run taylor-green taylor-green --set run.end_time=0.2
run taylor-green-eulerian taylor-green --set run.end_time=0.2 --set scheme.frame=eulerian
for m in fene-p fene-cr lptt eptt; do run "$m" "$m" --set run.end_time=0.3; done
run giesekus giesekus --set run.end_time=0.1 --set scene.resolution=30
run cylinder-array-p2 cylinder-array --set run.end_time=0.03 --set run.output_interval=0.01
run cylinder-array-r13 cylinder-array --set scene.resolution=54 --set run.end_time=0.5
run confined-cylinder confined-cylinder --set run.end_time=0.3
run drop-impact drop-impact --set scene.resolution=40 --set run.end_time=0.03
run drop-impact-zero drop-impact --set scene.resolution=40 --set run.end_time=0.03 --set scheme.free_surface.pressure=zero --set scheme.free_surface.repulsion=false
run drop-impact-explicit drop-impact --set scene.resolution=20 --set run.end_time=0.02 --set scheme.viscosity=explicit
run drop-fang drop-fang --set scene.resolution=40 --set run.end_time=0.04
run jet-buckling jet-buckling --set run.end_time=0.25
run jet-buckling-fene-cr jet-buckling --set run.end_time=0.22 --set fluid.model=fene-cr --set fluid.l2=10

# A study: stability.csv without its wall-time column.
"$bin" -q study stability cases/poiseuille.toml --wi 1,4 --vary scheme.conformation.form=log,direct \
  --set scene.resolution=15 --set run.end_time=1 --out "$work/study" >/dev/null 2>&1 || true
printf '%-34s %-15s %s\n' study-stability stability.csv \
  "$(cut -d, -f1-8 "$work/study/stability.csv" | sha256sum | cut -c1-16)"
