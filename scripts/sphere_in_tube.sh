#!/bin/sh
# The sphere falling in a tube (cases/sphere-in-tube.toml: a/R = 1/2, Re = 0.01, a = U = 1).
# Newtonian: the period 6a and 10a at a/dr = 8 (the images' effect), 6a at a/dr = 10 and 12
# (the resolution's) and 6a at a/dr = 8 with half the time-step factor (the step's). Oldroyd-B,
# beta = 1/2: Wi = lambda U / a from WIS (default 0.25 0.5 1)
# in the 6a period at a/dr = 8, each until its drag is steady (the drive's window one
# relaxation time long) or for 6 lambda; a run that breaks down stops and says why, and the
# sweep goes on. PARTS chooses "newtonian", "oldroyd-b" or both. Usage:
#   [PARTS="newtonian oldroyd-b"] [WIS="0.25 0.5 1"] scripts/sphere_in_tube.sh OUT_DIR [--set key=value ...]
set -eu
out=$1; shift
bin=${RHEOSPH:-target/release/rheosph}
case=cases/sphere-in-tube.toml
quiet="-q --no-charts --no-snapshots"
for part in ${PARTS:-newtonian oldroyd-b}; do
  if [ "$part" = newtonian ]; then
    # shellcheck disable=SC2086
    "$bin" run $case --out "$out/newtonian-l6-r8" $quiet "$@" || true
    # shellcheck disable=SC2086
    "$bin" run $case --out "$out/newtonian-l10-r8" $quiet --set scene.length=10 \
      --set scene.body_force=150 "$@" || true
    # shellcheck disable=SC2086
    "$bin" run $case --out "$out/newtonian-l6-r10" $quiet --set scene.resolution=40 "$@" || true
    # shellcheck disable=SC2086
    "$bin" run $case --out "$out/newtonian-l6-r12" $quiet --set scene.resolution=48 "$@" || true
    # shellcheck disable=SC2086
    "$bin" run $case --out "$out/newtonian-l6-r8-dt-half" $quiet \
      --set scheme.time_step.factor=0.1 "$@" || true
  else
    for wi in ${WIS:-0.25 0.5 1}; do
      end=$(python3 -c "print(max(3.0, 6 * $wi))")
      window=$(python3 -c "print(max(0.2, $wi))")
      # shellcheck disable=SC2086
      "$bin" run $case --out "$out/oldroyd-b-wi$wi" $quiet --set fluid.model=oldroyd-b \
        --set fluid.beta=0.5 --set fluid.relaxation_time="$wi" --set run.end_time="$end" \
        --set run.steady.window="$window" "$@" || true
    done
  fi
done
rm -f "$out"/*/final_state.bin "$out"/*/checkpoint.bin "$out"/*/profile.csv
python3 scripts/sphere_in_tube_table.py "$out"
