#!/usr/bin/env bash
# Regenerates the figures of plots/ (the paper's Poiseuille studies, the cylinder array).
# Release build, 2 cores. The Poiseuille studies use implicit viscosity with the paper's
# standard projection (the channel has no pressure gradient, so the two projections agree;
# implicit viscosity is 10-20x cheaper at the same L2, see the validation pages).
#   plots/regenerate.sh            # everything (a few hours)
#   plots/regenerate.sh poiseuille # the Poiseuille studies only (about 1.5 h)
#   plots/regenerate.sh cylinders  # the cylinder array and the confined cylinder
#   plots/regenerate.sh surfaces   # drops and jets
#   plots/regenerate.sh models     # the models', Couette's, the cavity's and the GN channels' cases (10 min)
#   plots/regenerate.sh discs      # the free disc in shear, migration, near contact, sedimentation (30 min)
#   plots/regenerate.sh three-d    # the channel in 3D beside 2D at H/dr = 10, 15, 20; the pipe;
#                                  # the cubic array of spheres; the sphere in a tube; the
#                                  # sphere turning in shear
#   plots/regenerate.sh speed      # each stage with one thread and two (quiet machine, 5 min)
# Then `rheosph gallery` rewrites the validation pages' generated tables from the runs and
# lists every committed number that changed.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release
R=target/release/rheosph
C=cases/poiseuille.toml
I="--set scheme.viscosity=implicit --set scheme.projection=standard"

part=${1:-all}
if [ "$part" = all ] || [ "$part" = poiseuille ]; then
# Start-up Poiseuille, Re = Wi = 1, beta = 0.1 (King & Lind Fig. 2), paper's explicit viscosity.
$R run $C --out plots/poiseuille
# Convergence, both frames (Fig. 4), and beta = 0 with alpha_V = 0.01 (UCM).
$R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian $I --out plots/convergence
$R study convergence $C --resolutions 15,30,60 --frames lagrangian,eulerian $I \
  --set fluid.model=ucm --set fluid.beta=0 --set scheme.conformation.evss_alpha=0.01 --out plots/convergence-ucm
# The weakly compressible baseline beside the projection (one thread per run, as measured).
RAYON_NUM_THREADS=1 $R study speed-accuracy $C --set run.end_time=5 --vary scheme.method=isph,wcsph \
  --resolutions 15,30,60 --out plots/wcsph/sa-re1
RAYON_NUM_THREADS=1 $R study speed-accuracy cases/poiseuille-re0.01.toml --set run.end_time=5 \
  --vary scheme.method=isph,wcsph --resolutions 15,30 --out plots/wcsph/sa-re0.01
$R study stability $C --wi 1,4,16,64 --variant scheme.method=isph --variant scheme.method=wcsph \
  --variant 'scheme.method=wcsph;scheme.wcsph.density_diffusion=0.1' \
  --variant 'scheme.method=wcsph;scheme.conformation.form=direct;scheme.wcsph.artificial_stress=0.5' \
  --out plots/wcsph/stability
# Where methods fail (Section IV A 3): H/dr = 30, Re = 1, beta = 0.1.
$R study stability $C --wi 0.1,1,4,8,16,32,64,85,128 \
  --vary scheme.conformation.form=log,direct --vary scheme.frame=lagrangian,eulerian $I --out plots/stability
$R study stability $C --wi 0.1,1,2,4,8 --vary scheme.shifting=false $I --out plots/stability-noshift
# The same with a 4x smaller time step (0.05 h/U): the breakdowns at Wi = 16-64 above are the
# implicit scheme's large step, not the method.
$R study stability $C --wi 8,16,32,64,85,128 --vary scheme.conformation.form=log,direct $I \
  --set scheme.time_step.factor=0.05 --out plots/stability-dt0.05
# Re = 0.01 (rho = 0.01, g = 800 keeps U = 1).
$R study stability $C --wi 1,4,16,32,40,64 --vary scheme.conformation.form=log,direct $I \
  --set fluid.density=0.01 --set 'scene.body_force=[800.0,0.0]' --set run.end_time=20 --out plots/stability-re0.01
# UCM (beta = 0, alpha_V = 0.01): the shipped case with and without its hourglass control.
RAYON_NUM_THREADS=1 $R study stability cases/poiseuille-ucm.toml --wi 1,2,4,8,16,32 \
  --vary scheme.conformation.hourglass_control=0,0.2 --out plots/stability-elastic-rule/ucm-hourglass
# The elastic step rule with no tuning, t = 15: Re = 1 with the paper's explicit and with
# implicit viscosity (the explicit runs about 11 min each), and Re = 0.01.
$R study stability $C --wi 1,2,4,8,16,32,64,85,128 --vary scheme.viscosity=explicit,implicit \
  --out plots/stability-elastic-rule/re1
$R study stability cases/poiseuille-re0.01.toml --wi 1,4,8,16,32,40,64 \
  --out plots/stability-elastic-rule/re0.01
# What accuracy each second buys: resolutions x viscosity treatment x frame.
$R study speed-accuracy $C --resolutions 15,30,60 --vary scheme.viscosity=explicit,implicit \
  --vary scheme.frame=lagrangian,eulerian --set run.end_time=5 --out plots/speed-accuracy
# The second-order step (Crank-Nicolson with the Strang conformation update) beside
# backward Euler and the explicit step, t = 15 (the explicit H/dr = 60 run takes ~23 min).
$R study speed-accuracy $C --resolutions 15,30,60 --variant scheme.viscosity=crank-nicolson \
  --variant 'scheme.viscosity=crank-nicolson;scheme.frame=eulerian' \
  --variant scheme.viscosity=implicit --variant scheme.viscosity=explicit \
  --out plots/speed-accuracy-second-order
# Crank-Nicolson's step at H/dr = 60 (its default and larger) beside the explicit scheme,
# one thread per run (about 30 min).
RAYON_NUM_THREADS=1 $R study speed-accuracy $C --resolutions 60 --variant scheme.viscosity=explicit \
  --variant scheme.viscosity=crank-nicolson \
  --variant 'scheme.viscosity=crank-nicolson;scheme.time_step.factor=0.3' \
  --variant 'scheme.viscosity=crank-nicolson;scheme.time_step.factor=0.4' --out plots/speed-accuracy-step
# H/dr = 120 (14 400 particles; the explicit run alone takes about 6 h on 2 threads).
$R study speed-accuracy $C --resolutions 120 --variant scheme.viscosity=explicit \
  --variant scheme.viscosity=implicit --variant scheme.viscosity=crank-nicolson \
  --variant 'scheme.viscosity=crank-nicolson;scheme.frame=eulerian' \
  --variant 'scheme.viscosity=crank-nicolson;scheme.operators.gradient=second;scheme.operators.laplacian=second' \
  --out plots/speed-accuracy-120
fi

if [ "$part" = all ] || [ "$part" = cylinders ]; then

# Cylinder array (Section IV B): Stokes drag over three resolutions, then Wi = 0.2, 0.6, 0.8.
for r in 36 54 72; do
  $R run cases/cylinder-array.toml --no-snapshots --set scene.resolution=$r --set fluid.model=newtonian \
    --set fluid.relaxation_time=0 --set fluid.beta=1 --set run.steady.average=1 \
    --out plots/cylinder-array/stokes/res$r
done
$R study cylinder cases/cylinder-array.toml --set scene.resolution=54 --wi 0.2,0.6,0.8 \
  --out plots/cylinder-array/study-54
# P2 (R/dr = 36) from rest with <u> held at 1, Wi = 0.2 ... 0.8, run to steady state and
# averaged over three units (about 40 min a member on one thread).
$R study cylinder cases/cylinder-array.toml --wi 0.2,0.4,0.6,0.8 --set scene.mean_flow=1.0 \
  --jobs 2 --reuse --out runs/p2-low-wi
# The largest stable Wi, at R/dr = 9 and 13.5.
$R study cylinder cases/cylinder-array.toml --set scene.resolution=36 --wi 1,2,4,8,16 \
  --out plots/cylinder-array/study-36-high-wi
$R study cylinder cases/cylinder-array.toml --set scene.resolution=54 --wi 1,2,4,8,16 \
  --out plots/cylinder-array/study-54-high-wi
$R study cylinder cases/cylinder-array.toml --set scene.resolution=36 --set scheme.time_step.factor=0.05 \
  --wi 4,8,16 --out plots/cylinder-array/study-36-high-wi-dt0.05
# The paper's P2 (R/dr = 36) at Wi = 1 ... 16 with <u> held at 1, by grid sequencing: each Wi
# runs at R/dr = 9 to t = 40 and 18 to t = 15 first, each stage from the previous one's state
# (hours on a 2-core machine; --reuse resumes an interrupted study).
$R study cylinder cases/cylinder-array.toml --wi 1,2,4,8,16 --sequence 36:40,72:15 \
  --set scene.mean_flow=1.0 --set run.end_time=8 --jobs 2 --reuse \
  --out plots/cylinder-array/p2-high-wi
# Fig. 11 from developed runs: Wi = 1, 2, 4 to steady state and averaged at P2 (the same
# sequence, P2 up to t = 30; about an hour), then Wi = 16 run long, to t = 64 = 4 lambda, by
# hand (about 3 h at P2 on 2 threads; checkpointed, `run --resume DIR` continues it; the
# tolerance of 1e-12 keeps it from stopping at a quiet stretch), and the centre-lines overlaid.
$R study cylinder cases/cylinder-array.toml --wi 1,2,4 --sequence 36:40,72:15 \
  --set scene.mean_flow=1.0 --set run.end_time=30 --jobs 2 --reuse \
  --out plots/cylinder-array/p2-steady
# Wi = 4 and 8 at P2 by the same sequence, run longer: Wi = 4 to steady state and averaged,
# Wi = 8 to t = 24, not steady (about 1.5 h and 2.5 h at P2 on one thread).
$R study cylinder cases/cylinder-array.toml --wi 4 --sequence 36:40,72:15 \
  --set scene.mean_flow=1.0 --set run.end_time=30 --reuse --out plots/cylinder-array/p2-wi4
$R study cylinder cases/cylinder-array.toml --wi 8 --sequence 36:40,72:15 \
  --set scene.mean_flow=1.0 --set run.end_time=24 --reuse --out plots/cylinder-array/p2-wi8
W="--no-snapshots --set fluid.relaxation_time=16 --set scene.mean_flow=1.0 --set run.steady.tolerance=1e-12"
$R run cases/cylinder-array.toml $W --set scene.resolution=36 --set run.end_time=40 \
  --out runs/p2-wi16/s36
$R run cases/cylinder-array.toml $W --from runs/p2-wi16/s36 --set scene.resolution=72 \
  --set run.end_time=15 --out runs/p2-wi16/s72
$R run cases/cylinder-array.toml $W --from runs/p2-wi16/s72 --set run.end_time=64 \
  --set run.checkpoint_interval=0.5 --out runs/p2-wi16/s144
cp runs/p2-wi16/s144/{drag.png,centreline.csv,centreline_u.png,centreline_tau_xx.png,centreline_det_a.png} \
  plots/cylinder-array/p2-wi16/
S=plots/cylinder-array/p2-steady/runs
$R run $S/Wi_4/case.toml --from $S/Wi_4 --set run.end_time=10 --set run.steady.tolerance=1e-12 \
  --no-snapshots --out runs/p2-wi4-continued
$R compare-centrelines $S/Wi_1 $S/Wi_2 runs/p2-wi4-continued runs/p2-wi16/s144 \
  --labels "Wi = 1","Wi = 2","Wi = 4","Wi = 16" --out plots/cylinder-array/p2-fig11
# The confined cylinder (30R x 4R periodic, <u> held at 1, fixed particles) against the
# published drag: R/dr = 10 to Wi = 0.9, R/dr = 15 and 20 at Wi = 0.3 ... 0.7 (about 1 h
# and 2.5 h of one core).
$R study cylinder cases/confined-cylinder.toml --wi 0,0.1,0.3,0.5,0.7,0.9 \
  --reference cases/confined-cylinder-drag.csv --out plots/confined-cylinder
$R study cylinder cases/confined-cylinder.toml --wi 0,0.3,0.5,0.7 --set scene.resolution=60 \
  --reference cases/confined-cylinder-drag.csv --out plots/confined-cylinder/r15
$R study cylinder cases/confined-cylinder.toml --wi 0,0.5,0.7 --set scene.resolution=80 \
  --reference cases/confined-cylinder-drag.csv --out plots/confined-cylinder/r20
# The same at R/dr = 10 with the step halved twice (K may not move), and with graded walls
# (wall spacing R/40 and R/80; graded rows need the second-order gradient): about 1 h, then
# 4 h and 6 h of one core.
for f in 0.1 0.05; do
  $R study cylinder cases/confined-cylinder.toml --wi 0.1,0.5,0.7 --set scheme.time_step.factor=$f \
    --reference cases/confined-cylinder-drag.csv --out plots/confined-cylinder/dt$f
done
G="--set scheme.operators.gradient=second --reference cases/confined-cylinder-drag.csv"
$R study cylinder cases/confined-cylinder.toml --wi 0,0.1,0.3,0.5,0.7 --set scene.refine_walls=4 \
  --set scene.cylinder.rings=1 $G --out plots/confined-cylinder/graded40
$R study cylinder cases/confined-cylinder.toml --wi 0.3,0.5,0.7 --set scene.refine_walls=8 \
  --set scene.cylinder.rings=0 $G --out plots/confined-cylinder/graded80
fi

if [ "$part" = all ] || [ "$part" = surfaces ]; then
# Drop impact (Section IV C): Oldroyd-B, Re = 4, De = 1, beta = 0.1 at W/dr = 20, 40, 80, 120.
D=cases/drop-impact.toml
O=plots/drop-impact
N="--set fluid.model=newtonian --set fluid.beta=1 --set fluid.relaxation_time=0"
for r in 20 40 80; do $R run $D --no-snapshots --set scene.resolution=$r --out $O/res$r || true; done
$R run $D --out $O/res120 || true
# De from 0.5 to 1e5 (lambda = De W/U) and beta at De = 5, W/dr = 40 and 80; the breakdowns are data.
for de in 0.5 5 10 20 50 100 500 1000 5000 100000; do
  $R run $D --no-snapshots --set scene.resolution=40 --set fluid.relaxation_time=$(python3 -c "print($de*0.02)") \
    --out $O/de40/De_$de || true
done
$R run $D --no-snapshots --set scene.resolution=40 $N --out $O/de40/newtonian
for b in 0.2 0.05 0.02 0.01; do
  $R run $D --no-snapshots --set scene.resolution=40 --set fluid.relaxation_time=0.1 --set fluid.beta=$b \
    --out $O/beta40/beta_$b || true
done
for b in 0.05 0.02 0.01; do
  $R run $D --no-snapshots --set scene.resolution=80 --set fluid.relaxation_time=0.1 --set fluid.beta=$b \
    --out $O/beta80/beta_$b || true
done
# Normal-stress Dirichlet pressure (35a) against p = 0, and the Newtonian drop, at W/dr = 80.
$R run $D --no-snapshots --set scene.resolution=80 --set scheme.free_surface.pressure=zero --out $O/p-zero80
$R run $D --no-snapshots --set scene.resolution=80 $N --out $O/newtonian80
# Fang et al.'s drop (D/dr = 100), Oldroyd-B and Newtonian, with the projection ...
F=cases/drop-fang.toml
FI="--set scheme.method=isph --set scheme.shifting=true --set scheme.conformation.form=log
  --set scheme.viscosity=implicit --set scheme.time_step.fixed=0 --set scheme.walls.model=mirror"
$R run $F --no-snapshots $FI --out plots/drop-fang/oldroyd-b
$R run $F --no-snapshots $FI $N --out plots/drop-fang/newtonian
# ... and with their weakly compressible scheme as the case file ships it (eps = 0.5, fixed
# ghosts, their step), then eps = 0.2 and 0, the mirror wall, and the Newtonian drop (eps = 0.2,
# our step: theirs exceeds the explicit viscous limit at eta = 4 Pa s).
$R run $F --no-snapshots --out plots/drop-fang/wcsph-oldroyd-b
$R run $F --no-snapshots --set scheme.wcsph.artificial_stress=0.2 --out plots/drop-fang/wcsph-eps0.2 || true
$R run $F --no-snapshots --set scheme.wcsph.artificial_stress=0 --out plots/drop-fang/wcsph-eps0 || true
$R run $F --no-snapshots --set scheme.walls.model=mirror --out plots/drop-fang/wcsph-mirror || true
$R run $F --no-snapshots $N --set scheme.wcsph.artificial_stress=0.2 --set scheme.time_step.fixed=0 \
  --out plots/drop-fang/wcsph-newtonian
$R compare-drops $O/res20 $O/res40 $O/res80 $O/res120 --labels 'W/dr = 20,40,80,120' \
  --title 'Oldroyd-B drop, De = 1: resolution' --out $O/resolution.png
$R compare-drops $O/de40/newtonian $O/res40 $O/de40/De_5 $O/de40/De_20 $O/de40/De_100 $O/de40/De_1000 \
  --labels 'Newtonian,De = 1,De = 5,De = 20,De = 100,De = 1000' --title 'Drops, W/dr = 40: De' \
  --out $O/deborah.png
$R compare-drops $O/res80 $O/p-zero80 $O/newtonian80 --labels 'normal stress (35a),p = 0,Newtonian' \
  --title 'Free-surface pressure, W/dr = 80' --out $O/surface_pressure.png
$R compare-drops plots/drop-fang/newtonian plots/drop-fang/oldroyd-b --labels 'Newtonian,Oldroyd-B' \
  --title "Fang et al.'s drop (Re = 5, We = 1)" --out plots/drop-fang/width.png
G=plots/drop-fang
$R compare-drops $G/oldroyd-b $G/wcsph-oldroyd-b $G/wcsph-eps0.2 $G/wcsph-eps0 $G/wcsph-mirror \
  $G/newtonian $G/wcsph-newtonian --labels "ISPH,WCSPH eps = 0.5,WCSPH eps = 0.2,WCSPH eps = 0,\
WCSPH eps = 0.5 mirror wall,ISPH Newtonian,WCSPH Newtonian eps = 0.2" \
  --title "Fang et al.'s drop, D/dr = 100: projection and WCSPH" --out $G/wcsph_vs_isph.png
# Jets (Section IV D): Oldroyd-B at Wi = 1/3 ... 20/3 (lambda = Wi D/U0), the FENE models and
# Giesekus at Wi = 10/3.
J=cases/jet-buckling.toml
for w in 1/3 5/3 10/3 20/3; do
  $R run $J --set fluid.relaxation_time=$(python3 -c "print($w*0.006/0.2)") \
    --out plots/jet-buckling/oldroyd-b/Wi_$(echo $w | tr / _) || true
done
for l in 10 100; do
  $R run $J --set fluid.model=fene-p --set fluid.l2=$l --out plots/jet-buckling/fene-p/L2_$l || true
  $R run $J --set fluid.model=fene-cr --set fluid.l2=$l --out plots/jet-buckling/fene-cr/L2_$l || true
done
$R run $J --set fluid.model=giesekus --set fluid.alpha=0.3 --out plots/jet-buckling/giesekus/alpha_0.3 || true
# Capillarity (one thread each, about 40 min in all): the drop cut from the square lattice at
# R/dr = 10, 20, 40; the oscillating drop at R/dr = 10, 20, 40, with the paper's operators,
# over sigma (four periods each) and at Oh = 0.05 with and without the shear-free flux; the
# Oldroyd-B drop over lambda; the sessile drop over theta at R/dr = 10 and 20 (the breakdowns
# are data); the meniscus at 30 degrees (the angle held at the centres and at the surface), 60
# and 120; the pool at rest with g in the reduced pressure and in the predictor.
K=plots/capillarity
Q="--no-snapshots --no-charts"
for r in 20 40 80; do
  RAYON_NUM_THREADS=1 $R run cases/static-drop.toml $Q --set scene.resolution=$r \
    --set scene.drop.lattice=square --out $K/square-$r
done
OD=cases/oscillating-drop.toml
for r in 20 40; do RAYON_NUM_THREADS=1 $R run $OD $Q --set scene.resolution=$r --out $K/oscillating-$((r/2)); done
RAYON_NUM_THREADS=1 $R run $OD --no-snapshots --out $K/oscillating-40
RAYON_NUM_THREADS=1 $R run $OD $Q --set scene.resolution=40 --set scheme.operators.gradient=first \
  --set scheme.surface_tension.time_level=predicted --out $K/oscillating-20-paper-operators
for s in 0.25:21 4:5.25 16:2.625; do
  RAYON_NUM_THREADS=1 $R run $OD $Q --set scene.resolution=40 --set fluid.surface_tension=${s%:*} \
    --set run.end_time=${s#*:} --out $K/oscillating-20-sigma-${s%:*}
done
for r in 20 40 80; do
  RAYON_NUM_THREADS=1 $R run $OD $Q --set scene.resolution=$r --set fluid.viscosity=0.05 --out $K/oh0.05-$((r/2))
  RAYON_NUM_THREADS=1 $R run $OD $Q --set scene.resolution=$r --set fluid.viscosity=0.05 \
    --set experimental.surface_shear=shear-free --out $K/oh0.05-shear-free-$((r/2))
done
for l in 0.1 0.4 1 4; do
  RAYON_NUM_THREADS=1 $R run cases/oscillating-drop-oldroyd-b.toml $Q --set fluid.relaxation_time=$l \
    --out $K/oldroyd-b-lambda-$l
done
for a in 40 60 90 120 140; do
  RAYON_NUM_THREADS=1 $R run cases/sessile-drop.toml $Q --set scene.resolution=20 --set scene.contact_angle=$a \
    --out $K/sessile-r10-$a || true
  RAYON_NUM_THREADS=1 $R run cases/sessile-drop.toml $Q --set scene.contact_angle=$a --out $K/sessile-$a || true
done
M=cases/meniscus.toml
RAYON_NUM_THREADS=1 $R run $M --no-snapshots --out $K/meniscus
RAYON_NUM_THREADS=1 $R run $M $Q --set scene.contact_angle=30 --set fluid.viscosity=0.1 --set run.end_time=30 \
  --out $K/meniscus-30
RAYON_NUM_THREADS=1 $R run $M $Q --set scene.contact_angle=30 --set fluid.viscosity=0.1 --set run.end_time=30 \
  --set experimental.contact_angle_at=surface --out $K/meniscus-30-surface
RAYON_NUM_THREADS=1 $R run $M $Q --set scene.contact_angle=120 --out $K/meniscus-120
S="--set scene.contact_angle=90 --set fluid.surface_tension=1e-9 --set run.output_interval=5"
RAYON_NUM_THREADS=1 $R run $M $Q $S --out $K/still-water
RAYON_NUM_THREADS=1 $R run $M $Q $S --set scheme.gravity=predictor --out $K/still-water-predictor
fi

if [ "$part" = all ] || [ "$part" = models ]; then
# The shipped channel cases of the non-linear models and the Couette start-up, each with its
# default scheme, and the coarser and L^2 = 10 companions of the models page.
for c in couette fene-p fene-cr lptt eptt; do
  $R run cases/$c.toml --no-snapshots --no-charts --out plots/models/$c
  $R run cases/$c.toml --no-snapshots --no-charts --set scheme.viscosity=explicit --out plots/models/$c-explicit
done
$R run cases/fene-p.toml --no-snapshots --no-charts --set scene.resolution=15 --out plots/models/fene-p-15
$R run cases/fene-p.toml --no-snapshots --no-charts --set fluid.l2=10 --out plots/models/fene-p-l2-10
$R run cases/lptt.toml --no-snapshots --no-charts --set scene.resolution=15 --out plots/models/lptt-15
$R run cases/eptt.toml --no-snapshots --no-charts --set scene.resolution=15 --out plots/models/eptt-15
# The lid-driven cavity: Newtonian to t = 2 at three resolutions, the shipped Oldroyd-B case at two.
C=plots/lid-driven-cavity
for r in 20 40 80; do
  $R run cases/lid-driven-cavity.toml --no-snapshots --no-charts --set scene.resolution=$r \
    --set fluid.model=newtonian --set fluid.beta=1 --set fluid.relaxation_time=0 \
    --set run.end_time=2 --out $C/newtonian-$r
done
for r in 40 80; do
  $R run cases/lid-driven-cavity.toml --no-snapshots --no-charts --set scene.resolution=$r \
    --out $C/oldroyd-b-$r
done
# The static drop's Laplace pressure at R/dr = 10, 20, 40.
for r in 20 40 80; do
  $R run cases/static-drop.toml --no-snapshots --no-charts --set scene.resolution=$r \
    --out plots/static-drop/ring-$r
done
# The generalised Newtonian channels at three resolutions.
G=plots/generalised-newtonian
for r in 15 30 60; do
  $R run cases/power-law-channel.toml --no-snapshots --no-charts --set scene.resolution=$r \
    --out $G/power-law-0.5-$r
  $R run cases/power-law-channel.toml --no-snapshots --no-charts --set scene.resolution=$r \
    --set fluid.power_index=1.5 --set run.end_time=10 --out $G/power-law-1.5-$r
  $R run cases/bingham-channel.toml --no-snapshots --no-charts --set scene.resolution=$r \
    --out $G/bingham-$r
done
for a in 0.1 0.3; do
  $R run cases/giesekus.toml --no-snapshots --no-charts --set scene.resolution=30 --set fluid.alpha=$a \
    --out plots/models/giesekus-alpha$a-30
done
fi

if [ "$part" = all ] || [ "$part" = discs ]; then
# The free disc in plane Couette flow: the shipped case (R/dr = 8), R/dr = 12, and a cell
# twice as wide and high with the walls at -2 and 2 (the same shear rate).
D=cases/disc-in-shear.toml
$R run $D --no-snapshots --no-charts --out plots/discs/in-shear
$R run $D --no-snapshots --no-charts --set scene.resolution=96 --out plots/discs/in-shear-r12
$R run $D --no-snapshots --no-charts --set scene.length=16 --set scene.height=16 \
  --set scene.resolution=128 --set 'scene.wall_velocity=[-2.0,2.0]' \
  --set 'scene.discs=[{radius = 1.0, centre = [8.0, 8.0], motion = "free-rotation"}]' \
  --out plots/discs/in-shear-wide
# The same disc in an Oldroyd-B matrix, De = 0.25 ... 2 at beta = 0.5 and 0.2 (about 20 min).
scripts/disc_rotation.sh plots/discs/rotation > plots/discs/rotation.csv
# Migration of a free disc at y = H/2 - R to a strain of 50, Oldroyd-B and Newtonian, one output
# every strain of 10 (one thread: about 5 min each).
M=cases/disc-migration.toml
RAYON_NUM_THREADS=1 $R run $M --no-snapshots --no-charts --set run.output_interval=40 --out plots/discs/migration
RAYON_NUM_THREADS=1 $R run $M --no-snapshots --no-charts --set run.output_interval=40 \
  --set fluid.model=newtonian --set fluid.relaxation_time=0 --set fluid.beta=1 --out plots/discs/migration-newtonian
# A heavy disc settling onto the floor of an 8R x 8R Newtonian box, with and without the
# lubrication correction (about 20 s each).
S=cases/disc-sedimentation.toml
for lub in true false; do
  out=plots/discs/settling-on-floor; [ $lub = true ] || out=$out-unlubricated
  RAYON_NUM_THREADS=1 $R run $S --no-snapshots --no-charts --set scene.length=8 --set 'scene.gravity=[0.0,-10.0]' \
    --set 'scene.discs=[{radius = 1.0, centre = [4.0, 2.5], motion = "free", density_ratio = 2.0}]' \
    --set "scene.contact={strength = 0.01, repulsion = \"exponential\", lubrication = $lub}" \
    --set fluid.model=newtonian --set fluid.relaxation_time=0 --set fluid.beta=1 \
    --set run.output_interval=0.25 --set scheme.viscosity=implicit --out $out || true
done
# Sedimentation between walls, Oldroyd-B (the shipped case) and Newtonian (about 1 min each).
RAYON_NUM_THREADS=1 $R run $S --no-snapshots --no-charts --out plots/discs/sedimentation
RAYON_NUM_THREADS=1 $R run $S --no-snapshots --no-charts --set fluid.model=newtonian \
  --set fluid.relaxation_time=0 --set fluid.beta=1 --out plots/discs/sedimentation-newtonian
# Twelve discs settling in a closed box, to t = 100 (one thread: about 4 min).
RAYON_NUM_THREADS=1 $R run cases/disc-settling-array.toml --no-snapshots --no-charts \
  --set run.end_time=100 --set run.output_interval=100 --out plots/discs/settling-array
rm -f plots/discs/*/checkpoint.bin plots/discs/*/final_state.bin plots/discs/*/profile.csv
fi

if [ "$part" = all ] || [ "$part" = three-d ]; then
# Start-up Poiseuille, Re = Wi = 1, beta = 0.1, in 3D (periodic in x and z, 12 dr deep) and in
# 2D with the same scheme and box (1.2 long: H/dr = 10 must hold three supports along x).
for d in 3 2; do
  $R study convergence $C --resolutions 10,15,20 $I --set scene.dimension=$d \
    --set scene.length=1.2 --out plots/three-d/channel-${d}d
done
# Start-up Poiseuille in a circular pipe (Re = Wi = 1 on the radius, beta = 0.1) against its
# Bessel series, with the wall shear stress.
$R study convergence cases/pipe.toml --resolutions 12,16,20 $I --out plots/three-d/pipe
rm -f plots/three-d/*/runs/*/final_state.bin plots/three-d/*/runs/*/checkpoint.bin
# Stokes flow through a simple cubic array of spheres against Zick & Homsy: c = 0.125 at
# L/dr = 26 and 32, c = 0.216 at L/dr = 32 (about 50 min on 2 cores).
A=plots/three-d/sphere-array
$R run cases/sphere-array.toml --no-snapshots --no-charts --out $A/c0.125-r26
$R run cases/sphere-array.toml --no-snapshots --no-charts --set scene.resolution=32 \
  --out $A/c0.125-r32
$R run cases/sphere-array.toml --no-snapshots --no-charts --set scene.resolution=32 \
  --set scene.sphere.radius=0.3722103 --out $A/c0.216-r32
rm -f $A/*/final_state.bin $A/*/checkpoint.bin $A/*/profile.csv
# The sphere falling in a tube (a/R = 1/2): Newtonian K against 5.947 with the period, the
# resolution and the time step; Oldroyd-B (beta = 1/2) K against Wi (about 100 min on 2 cores,
# two runs at a time).
T=plots/three-d/sphere-in-tube
RHEOSPH=$R RAYON_NUM_THREADS=1 PARTS=newtonian scripts/sphere_in_tube.sh $T &
RHEOSPH=$R RAYON_NUM_THREADS=1 PARTS=oldroyd-b scripts/sphere_in_tube.sh $T &
wait
# A sphere turning freely in plane Couette flow (Newtonian, gamma = 1, a/dr = 8): the box
# test, cubes of side 3a to 6a, and a/dr = 10 in the 4a box (about 45 min on 2 cores).
S=plots/three-d/sphere-in-shear
for side in 3 4 5 6; do
  v=$(awk "BEGIN { print $side / 2 }")
  $R run cases/sphere-in-shear.toml --no-snapshots --no-charts --set scene.length=$side \
    --set scene.height=$side --set scene.depth=$side --set scene.resolution=$((8 * side)) \
    --set "scene.wall_velocity=[-$v, $v]" --out $S/box$side-r8
done
$R run cases/sphere-in-shear.toml --no-snapshots --no-charts --set scene.resolution=40 \
  --out $S/box4-r10
rm -f $S/*/final_state.bin $S/*/checkpoint.bin $S/*/profile.csv
# The same sphere in an Oldroyd-B fluid in the 3a box: De = 0.5, 1, 2 at the polymer
# fractions 0.385 and 0.9, each for 6 lambda (about 35 min on 2 cores, two runs at a time).
O=plots/three-d/sphere-rotation
for b in 0.615 0.1; do
  RHEOSPH=$R RAYON_NUM_THREADS=1 BETAS=$b scripts/sphere_rotation.sh $O &
done
wait
python3 scripts/sphere_rotation_table.py $O $S/box3-r8
rm -f $O/*/final_state.bin $O/*/checkpoint.bin $O/*/profile.csv
fi

if [ "$part" = all ] || [ "$part" = speed ]; then
# Every stage with one thread and with two (docs: Speed, serial fraction).
S=plots/bench/serial-fraction
RHEOSPH=$R scripts/serial_fraction.sh $S/channel $C --set run.end_time=3
RHEOSPH=$R scripts/serial_fraction.sh $S/cylinder-array cases/cylinder-array.toml --set run.end_time=0.05
RHEOSPH=$R scripts/serial_fraction.sh $S/sphere-in-shear cases/sphere-in-shear.toml \
  --set fluid.model=oldroyd-b --set fluid.beta=0.615 --set fluid.relaxation_time=1 --set run.end_time=0.1
fi

# The validation pages' tables from what ran (the changed numbers are listed).
$R gallery
