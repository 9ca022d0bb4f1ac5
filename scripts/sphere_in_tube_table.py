"""Collates scripts/sphere_in_tube.sh's runs into OUT/drag_against_wi.csv: for the Newtonian
run of the 6a period at a/dr = 8 (Wi = 0) and each Oldroyd-B Wi, the drag coefficient K from
the pipe's momentum balance (the steady window's mean, else the run's last rows'), on the
control spheres a + 3dr and a + 5dr at the end, the wall's share, when the drive became steady,
min det A over t > 0 (>= 1 for Oldroyd-B) and at the end (1 wherever the fluid has relaxed),
max tr A at the end, the outcome and the cost.
Usage: python3 scripts/sphere_in_tube_table.py OUT"""
import csv
import json
import os
import sys

out = sys.argv[1]


def fmt(v, spec):
    return "–" if v is None else format(v, spec)


def row(run, wi):
    summary = json.load(open(f"{run}/summary.json"))
    tube = summary["sphere_in_tube"]
    with open(f"{run}/series.csv") as f:
        rows = [r for r in csv.DictReader(f)]
    dets = [float(r["min_det_a"]) for r in rows if float(r["t"]) > 0]
    contour = tube["drag_k_contour"]
    return {
        "wi": f"{wi:g}",
        "drag_k": f"{tube['drag_k']:.4f}",
        "k_3dr": fmt(contour[0], ".4f"),
        "k_5dr": fmt(contour[2], ".4f"),
        "wall_share": fmt(tube["wall_share"], ".3f"),
        "steady_at": fmt(tube["reached_at"], ".3g"),
        "min_det_a": f"{min(dets):.6f}" if wi > 0 else "–",
        "min_det_a_end": f"{float(rows[-1]['min_det_a']):.4f}" if wi > 0 else "–",
        "max_trace_a": f"{float(rows[-1]['max_trace_a']):.4g}" if wi > 0 else "–",
        "outcome": summary["outcome"],
        "t": f"{summary['t_reached']:.3g}",
        "steps": summary["steps"],
        "wall_seconds": f"{summary['wall_seconds']:.0f}",
    }


runs = [(0.0, f"{out}/newtonian-l6-r8")]
for name in os.listdir(out):
    if name.startswith("oldroyd-b-wi") and os.path.exists(f"{out}/{name}/summary.json"):
        runs.append((float(name[len("oldroyd-b-wi"):]), f"{out}/{name}"))
rows = [row(d, wi) for wi, d in sorted(runs)]
tmp = f"{out}/drag_against_wi.csv.tmp"
with open(tmp, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
os.replace(tmp, f"{out}/drag_against_wi.csv")
print(open(f"{out}/drag_against_wi.csv").read(), end="")
