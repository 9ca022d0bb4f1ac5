"""Collates scripts/sphere_rotation.sh's runs into OUT/rotation_against_de.csv: for each
polymer fraction and De, Omega/(-gamma/2) averaged over the second half of the run and at
its end, its change over the last relaxation time (how far from steady the run ended), min
det A over the run (>= 1 for Oldroyd-B), the outcome and the cost. The Newtonian
run of the same box (NEWTONIAN_DIR) is the De = 0 row of each fraction.
Usage: python3 scripts/sphere_rotation_table.py OUT NEWTONIAN_DIR"""
import csv
import json
import os
import sys

out, newtonian = sys.argv[1], sys.argv[2]


def row(run, polymer_fraction, de):
    summary = json.load(open(f"{run}/summary.json"))
    rotation = summary["rotation"]
    with open(f"{run}/rotation.csv") as f:
        spins = [(float(r["t"]), -2 * float(r["spin_z"]) / rotation["shear_rate"])
                 for r in csv.DictReader(f)]
    t_end, final = spins[-1]
    # The ratio one relaxation time before the end (Newtonian: a tenth of the run).
    span = summary["case"]["fluid"].get("relaxation_time") or t_end / 10
    before = min(spins, key=lambda s: abs(s[0] - (t_end - span)))[1]
    with open(f"{run}/series.csv") as f:
        min_det = min(float(r["min_det_a"]) for r in csv.DictReader(f))
    return {
        "polymer_fraction": polymer_fraction,
        "de": f"{de:g}",
        "rotation_ratio": f"{rotation['rotation_ratio']:.4f}",
        "final_ratio": f"{final:.4f}",
        "change_last_lambda": f"{final - before:.4f}",
        "min_det_a": f"{min_det:.6f}",
        "outcome": summary["outcome"],
        "t": f"{summary['t_reached']:.3g}",
        "steps": summary["steps"],
        "wall_seconds": f"{summary['wall_seconds']:.0f}",
    }


runs = []
for name in os.listdir(out):
    if name.startswith("b") and "-de" in name and os.path.exists(f"{out}/{name}/summary.json"):
        beta, de = name[1:].split("-de")
        runs.append((round(1 - float(beta), 3), float(de), f"{out}/{name}"))
rows = []
for fraction in sorted({f for f, _, _ in runs}):
    rows.append(row(newtonian, fraction, 0))
    rows += [row(d, f, de) for f, de, d in sorted(runs) if f == fraction]
tmp = f"{out}/rotation_against_de.csv.tmp"
with open(tmp, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
os.replace(tmp, f"{out}/rotation_against_de.csv")
print(open(f"{out}/rotation_against_de.csv").read(), end="")
