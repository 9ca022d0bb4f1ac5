#!/bin/sh
# Each stage's wall time with one and two threads, and what Amdahl's law makes of them: a
# stage that takes t1 on one thread and t2 on two has the parallel fraction p = 2(1 − t2/t1),
# and on N threads would take t1((1 − p) + p/N). Two points fix p only roughly (a stage bound
# by memory bandwidth shares it between the cores), so the projection to N = 64 is an upper
# bound on how far a stage scales, not a measurement. Writes OUT/threads-1, OUT/threads-2
# and OUT/serial_fraction.csv. Run it on a quiet machine. Usage:
#   scripts/serial_fraction.sh OUT CASE [--set key=value ...]
set -eu
out=$1 case=$2; shift 2
bin=${RHEOSPH:-target/release/rheosph}
for threads in 1 2; do
  RAYON_NUM_THREADS=$threads "$bin" run "$case" --out "$out/threads-$threads" -q --no-charts \
    --no-snapshots "$@"
done
python3 - "$out" <<'PY'
import csv, json, os, sys
out = sys.argv[1]
one, two = (json.load(open(f"{out}/threads-{n}/summary.json")) for n in (1, 2))
assert one["threads"] == 1 and two["threads"] == 2, "RAYON_NUM_THREADS was not honoured"
rows = [(s, t, two["stage_seconds"][s]) for s, t in one["stage_seconds"].items()]
def projected(t1, t2, n=64):
    p = min(max(2 * (1 - t2 / t1), 0.0), 1.0)
    return t1 * ((1 - p) + p / n)
# The whole run at 64 threads: the stages' projections, and the time outside every stage
# (start-up, the loop's own work) taken as serial.
staged = sum(t for _, t, _ in rows)
whole_64 = sum(projected(t1, t2) for _, t1, t2 in rows if t1 > 0 and t2 > 0)
whole_64 += one["wall_seconds"] - staged
tmp = f"{out}/serial_fraction.csv.tmp"
with open(tmp, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["stage", "share_1", "seconds_1", "seconds_2", "speedup", "parallel_fraction",
                "seconds_64"])
    def row(stage, t1, t2, t64):
        w.writerow([stage, f"{t1 / one['wall_seconds']:.3f}", f"{t1:.3f}", f"{t2:.3f}",
                    f"{t1 / t2:.2f}", f"{2 * (1 - t2 / t1):.2f}", f"{t64:.3f}"])
    for stage, t1, t2 in rows:
        if t1 >= 1e-3:  # stages the case does not use
            row(stage, t1, t2, projected(t1, t2))
    row("whole run", one["wall_seconds"], two["wall_seconds"], whole_64)
os.replace(tmp, f"{out}/serial_fraction.csv")
print(open(f"{out}/serial_fraction.csv").read(), end="")
PY
