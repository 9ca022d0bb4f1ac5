#!/usr/bin/env bash
# Regenerates the figures of plots/ (the paper's Poiseuille studies, the cylinder array).
# Release build, 2 cores. The Poiseuille studies use implicit viscosity with the paper's
# standard projection (the channel has no pressure gradient, so the two projections agree;
# implicit viscosity is 10-20x cheaper at the same L2, see the README).
#   plots/regenerate.sh            # everything (a few hours)
#   plots/regenerate.sh poiseuille # the Poiseuille studies only (about 1.5 h)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release
R=target/release/rheosph
C=cases/poiseuille.toml
I="--set scheme.viscosity=implicit --set scheme.projection=standard"

# Start-up Poiseuille, Re = Wi = 1, beta = 0.1 (King & Lind Fig. 2), paper's explicit viscosity.
$R run $C --out plots/poiseuille
# Convergence, both frames (Fig. 4), and beta = 0 with alpha_V = 0.01 (UCM).
$R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian $I --out plots/convergence
$R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian $I \
  --set fluid.model=ucm --set fluid.beta=0 --set scheme.evss_alpha=0.01 --out plots/convergence-ucm
# Where methods fail (Section IV A 3): H/dr = 30, Re = 1, beta = 0.1.
$R study stability $C --wi 0.1,1,4,8,16,32,64,85,128 \
  --vary scheme.conformation=log,direct --vary scheme.frame=lagrangian,eulerian $I --out plots/stability
$R study stability $C --wi 0.1,1,2,4,8 --vary scheme.shifting=false $I --out plots/stability-noshift
# Re = 0.01 (rho = 0.01, g = 800 keeps U = 1).
$R study stability $C --wi 1,4,16,32,40,64 --vary scheme.conformation=log,direct $I \
  --set fluid.density=0.01 --set 'scene.body_force=[800.0,0.0]' --set run.end_time=20 --out plots/stability-re0.01
# What accuracy each second buys: resolutions x viscosity treatment x frame.
$R study speed-accuracy $C --resolutions 15,30,60 --vary scheme.viscosity=explicit,implicit \
  --vary scheme.frame=lagrangian,eulerian --set run.end_time=5 --out plots/speed-accuracy
[ "${1:-}" = "poiseuille" ] && exit 0

# Cylinder array (Section IV B): Stokes drag over three resolutions, then Wi = 0.2, 0.6, 0.8.
for r in 36 54 72; do
  $R run cases/cylinder-array.toml --no-snapshots --set scene.resolution=$r --set fluid.model=newtonian \
    --set fluid.relaxation_time=0 --set fluid.beta=1 --set run.steady.average=1 \
    --out plots/cylinder-array/stokes/res$r
done
$R study cylinder cases/cylinder-array.toml --set scene.resolution=54 --wi 0.2,0.6,0.8 \
  --out plots/cylinder-array/study-54
