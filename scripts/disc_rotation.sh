#!/bin/sh
# A freely rotating disc in plane Couette flow (cases/disc-in-shear.toml): Ω/(−γ̇/2) against
# De = γ̇λ for an Oldroyd-B matrix at two β, beside the Newtonian value. γ̇ = 0.25, so
# λ = 4 De; each run lasts 10 λ (at least 10). Prints a CSV table. Usage:
#   scripts/disc_rotation.sh OUT_DIR [--set key=value ...]
set -eu
out=$1; shift
bin=${RHEOSPH:-target/release/rheosph}
echo "model,beta,de,rotation_ratio,outcome,wall_seconds"
row() { # label model beta de extra-args
  d="$out/$1"; shift
  model=$1 beta=$2 de=$3; shift 3
  "$bin" run cases/disc-in-shear.toml --out "$d" -q --no-charts --no-snapshots "$@" || true
  python3 - "$d" "$model" "$beta" "$de" <<'PY'
import json, sys
d, model, beta, de = sys.argv[1:]
s = json.load(open(f"{d}/summary.json"))
print(f"{model},{beta},{de},{s['discs'][0]['rotation_ratio']},{s['outcome']},{s['wall_seconds']:.1f}")
PY
}
row newtonian newtonian 1 0 --set run.end_time=10 "$@"
for beta in 0.5 0.2; do
  for de in 0.25 0.5 1 2; do
    lambda=$(python3 -c "print(4 * $de)")
    end=$(python3 -c "print(max(10.0, 10 * 4 * $de))")
    row "ob-b$beta-de$de" oldroyd-b "$beta" "$de" --set fluid.model=oldroyd-b \
      --set fluid.beta=$beta --set fluid.relaxation_time=$lambda --set run.end_time=$end "$@"
  done
done
