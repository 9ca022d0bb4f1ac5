#!/bin/sh
# A freely rotating sphere between sliding plates in an Oldroyd-B fluid
# (cases/sphere-in-shear.toml in a box of 3a, a/dr = 8, gamma = 1): Omega/(-gamma/2) against
# De = gamma lambda at the polymer fractions eta_p/eta_0 = 0.385 and 0.9 of Vazquez-Quesada &
# Ellero (2017), i.e. fluid.beta = eta_s/eta_0 = 0.615 and 0.1. Each run lasts 6 lambda (the
# first normal stress difference of start-up shear is then within 2 % of its steady value);
# rotation.csv holds the spin against t. BETAS and DES choose a subset. Usage:
#   [BETAS="0.615 0.1"] [DES="0.5 1 2"] scripts/sphere_rotation.sh OUT_DIR [--set key=value ...]
set -eu
out=$1; shift
bin=${RHEOSPH:-target/release/rheosph}
box="--set scene.length=3 --set scene.height=3 --set scene.depth=3 --set scene.resolution=24"
box="$box --set scene.wall_velocity=[-1.5,1.5]"
for beta in ${BETAS:-0.615 0.1}; do
  for de in ${DES:-0.5 1 2}; do
    end=$(python3 -c "print(6 * $de)")
    # shellcheck disable=SC2086
    "$bin" run cases/sphere-in-shear.toml --out "$out/b$beta-de$de" -q --no-charts \
      --no-snapshots $box --set fluid.model=oldroyd-b --set fluid.beta="$beta" \
      --set fluid.relaxation_time="$de" --set run.end_time="$end" --set run.output_interval=0.1 \
      "$@" || true
  done
done
python3 scripts/sphere_rotation_table.py "$out" plots/three-d/sphere-in-shear/box3-r8
