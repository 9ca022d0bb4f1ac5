#!/bin/sh
# Two free discs in shear (cases/disc-pair.toml) at several initial lateral offsets
# z = (y1 - y2)/2R: each run's outcome (pass, tumble, or swap: the confined cell's reversing
# trajectory), its closest approach and final offsets, as a CSV table; each run's disc.csv is
# kept under OUT_DIR/zZ. Runs go two at a time, one thread each. Usage:
#   scripts/disc_pair.sh OUT_DIR "0.1 0.2 0.3" [--set key=value ...]
set -eu
out=$1; offsets=$2; shift 2
bin=${RHEOSPH:-target/release/rheosph}
mkdir -p "$out"
run_one() { # offset extra-args
  z=$1; shift
  d="$out/z$z"; mkdir -p "$d"
  python3 - "$z" "$d/case.toml" <<'PY'
import re, sys
z, path = float(sys.argv[1]), sys.argv[2]
text = open("cases/disc-pair.toml").read()
centres = iter([f"centre = [6.0, {8.0 + z:.6f}]", f"centre = [10.0, {8.0 - z:.6f}]"])
open(path, "w").write(re.sub(r"centre = \[[^\]]*\]", lambda m: next(centres), text))
PY
  RAYON_NUM_THREADS=1 "$bin" run "$d/case.toml" --out "$d" -q --no-charts --no-snapshots "$@" \
    > "$d/log" 2>&1 || true
}
for z in $offsets; do
  run_one "$z" "$@" &
  while [ "$(jobs -p | wc -l)" -ge 2 ]; do sleep 5; done
done
wait
python3 - "$out" $offsets <<'PY'
import csv, json, math, sys
out, offsets = sys.argv[1], sys.argv[2:]
print("z,outcome,closest_gap_over_R,final_dx_over_R,final_dy_over_R,strain,wall_seconds")
for z in offsets:
    d = f"{out}/z{z}"
    case = open(f"{d}/case.toml").read()
    length = float(case.split("length = ")[1].split()[0])
    height = float(case.split("height = ")[1].split()[0])
    rows = list(csv.DictReader(open(f"{d}/disc.csv")))
    a = [r for r in rows if r["disc"] == "0"]
    b = [r for r in rows if r["disc"] == "1"]
    rel = []
    for ra, rb in zip(a, b):
        dx = float(ra["x"]) - float(rb["x"])
        dx -= length * round(dx / length)      # the nearest periodic image
        rel.append((float(ra["t"]), dx, float(ra["y"]) - float(rb["y"])))
    gap = min(math.hypot(dx, dy) for _, dx, dy in rel) - 2.0
    crossed_x = any(dx > 0 for _, dx, _ in rel)
    crossed_y = any(dy < 0 for _, _, dy in rel)
    # pass: the upper disc overtakes and stays above; tumble: it overtakes and goes below
    # (the doublet turns); swap: it goes below without overtaking and the pair recedes.
    outcome = {(True, False): "pass", (True, True): "tumble", (False, True): "swap"}.get(
        (crossed_x, crossed_y), "approaching")
    s = json.load(open(f"{d}/summary.json"))
    t, dx, dy = rel[-1]
    print(f"{z},{outcome},{gap:.3f},{dx:.3f},{dy:.3f},{2 * t / height:.1f},{s['wall_seconds']:.0f}")
PY
