#!/usr/bin/env bash
# Regenerates the figures of plots/ (the paper's Poiseuille studies and the default case).
# Release build, 2 cores: a few hours with the explicit viscosity of the paper.
#   plots/regenerate.sh            # everything
#   plots/regenerate.sh quick      # the implicit-viscosity versions only (minutes)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release
R=target/release/rheosph
C=cases/poiseuille.toml

if [ "${1:-}" != "quick" ]; then
  # Start-up Poiseuille, Re = Wi = 1, beta = 0.1 (King & Lind Fig. 2): both frames.
  $R run $C --out plots/poiseuille
  $R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian --out plots/convergence
  # beta = 0 (UCM) with alpha_V = 0.01 (Fig. 3).
  $R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian \
    --set fluid.model=ucm --set fluid.beta=0 --set scheme.evss_alpha=0.01 --out plots/convergence-ucm
  # Where methods fail (Section IV A 3): H/dr = 30, Re = 1, beta = 0.1.
  $R study stability $C --wi 1,2,4,8,16,32,64,85,128 \
    --vary scheme.conformation=log,direct --vary scheme.frame=lagrangian,eulerian \
    --vary scheme.shifting=true,false --out plots/stability
fi
# What accuracy each second buys: resolutions x viscosity treatment x frame.
$R study speed-accuracy $C --resolutions 15,30,60 --vary scheme.viscosity=explicit,implicit \
  --vary scheme.frame=lagrangian,eulerian --set run.end_time=5 --out plots/speed-accuracy
$R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian \
  --set scheme.viscosity=implicit --out plots/convergence-implicit
