#!/bin/sh
# Wi ramp on the periodic cylinder array: 0.2 -> 0.6 -> 0.8, each started from the previous
# converged state (`rheosph run --from`), against independent starts from rest. Prints the
# steady <u>, K, time to steady and wall time of each run. Usage:
#   scripts/wi_ramp.sh OUT_DIR [--set key=value ...]
set -eu
out=$1; shift
bin=${RHEOSPH:-target/release/rheosph}
case=cases/cylinder-array.toml
prev=""
for wi in 0.2 0.6 0.8; do
  "$bin" run "$case" --out "$out/fresh-$wi" -q --no-charts --no-snapshots \
    --set fluid.relaxation_time=$wi "$@" || true
  if [ -z "$prev" ]; then
    ramp="$out/fresh-$wi"
  else
    ramp="$out/ramp-$wi"
    "$bin" run "$case" --out "$ramp" -q --no-charts --no-snapshots --from "$prev" \
      --set fluid.relaxation_time=$wi "$@" || true
  fi
  prev=$ramp
done
python3 - "$out" <<'PY'
import json, sys, pathlib
root = pathlib.Path(sys.argv[1])
print(f"{'run':<12} {'outcome':<10} {'t_reached':>9} {'wall_s':>8} {'<u>':>8} {'K':>9}")
for d in sorted(root.iterdir()):
    s = json.loads((d / "summary.json").read_text())
    st = s.get("steady") or {}
    print(f"{d.name:<12} {s['outcome']:<10} {s['t_reached']:9.3f} {s['wall_seconds']:8.1f} "
          f"{st.get('u_mean', float('nan')):8.4f} {st.get('drag_k', float('nan')):9.3f}")
PY
