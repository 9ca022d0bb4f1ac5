//! Free surfaces: drops that must not move, and a coarse drop impact that must conserve its
//! area. (Detection on a square and a disc, disc normals and the Dirichlet pressure (35a) are
//! unit tests in `src/surface.rs`.)

use rheosph::engine::math::{Sym2, Vec2};
use rheosph::engine::step::{Setup, Simulation};
use rheosph::setup::case;
use std::path::Path;
use std::process::Command;

/// The set-up of the drop-impact case at W/δr = 20 with `overrides`, its initial velocity
/// replaced and no gravity.
fn free_drop_setup(velocity: Vec2, overrides: &[String]) -> Setup {
    let mut all = vec!["scene.resolution=20".to_string()];
    all.extend_from_slice(overrides);
    let case = case::load(Path::new("cases/drop-impact.toml"), &all).unwrap();
    let mut setup = case.setup().unwrap();
    setup.velocity.iter_mut().for_each(|u| *u = velocity);
    setup.body_force = Vec2::zeros();
    setup
}

/// The drop-impact case at W/δr = 20 with its initial velocity replaced and no gravity.
fn free_drop(velocity: Vec2) -> Simulation {
    Simulation::new(free_drop_setup(velocity, &[]))
}

/// Runs to t* = tU/W = 1 (W = 0.02, U = 1) and returns the largest velocity deviation from
/// `velocity` seen after any step.
fn run_one_time_unit(sim: &mut Simulation, velocity: Vec2) -> f64 {
    let mut worst: f64 = 0.0;
    while sim.state.time < 0.02 {
        sim.step(1.0).unwrap();
        let dev = sim
            .state
            .velocity
            .iter()
            .map(|u| (u - velocity).norm())
            .fold(0.0, f64::max);
        worst = worst.max(dev);
    }
    worst
}

/// An Oldroyd-B drop at rest with no gravity stays at rest: with u = 0 and A = I there is no
/// stress, no shifting (D of (41) is proportional to the speed) and a zero PPE right-hand
/// side, so any velocity at all would be a spurious force of the scheme. Bound: round-off.
#[test]
fn drop_at_rest_stays_still() {
    let mut sim = free_drop(Vec2::zeros());
    let start = sim.state.position.clone();
    // A drop at rest has no time scale of its own: steps are capped at the impact case's.
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        sim.step(1e-4).unwrap();
        let dev = sim
            .state
            .velocity
            .iter()
            .map(|u| u.norm())
            .fold(0.0, f64::max);
        worst = worst.max(dev);
    }
    assert!(worst < 1e-12, "spurious speed {worst:e} m/s");
    // Particles are reordered (Morton) from time to time: compare the sets, sorted.
    let sorted = |v: &[Vec2]| {
        let mut k: Vec<(f64, f64)> = v.iter().map(|p| (p.x, p.y)).collect();
        k.sort_by(|a, b| a.partial_cmp(b).unwrap());
        k
    };
    let moved = sorted(&start)
        .iter()
        .zip(sorted(&sim.state.position).iter())
        .map(|(a, b)| (a.0 - b.0).hypot(a.1 - b.1))
        .fold(0.0, f64::max);
    assert!(moved < 1e-12, "particles moved {moved:e} m");
}

/// `experimental.volume_relaxation` (the PPE's density-invariant source, Asai et al. 2012) restores
/// particle volumes that have drifted, where the paper's projection keeps them. A drop at
/// rest (W/δr = 20, no gravity) has its inner disc, r < R/2, squeezed by 4 % towards its
/// centre (C ≈ 1/0.96² − 1 = +8.5 %, and a sparse ring at R/2). Ideally the source removes
/// the fraction α of C/C₀ − 1 per step: with α = 0.05, 60 steps leave 0.95⁶⁰ ≈ 4.6 %
/// (measured: 8.84 % → 0.53 %, 6 %). The bound asks for a tenth, allowing for the discrete
/// operators and for the patch's neighbours, which take its excess; without the source the
/// excess stays (measured: unchanged to 14 digits; nothing moves in a drop at rest, D of
/// (41) being proportional to the speed).
#[test]
fn volume_relaxation_spreads_a_compressed_patch() {
    use rheosph::engine::kernel::QuinticSpline;
    let dr = 0.02 / 20.0;
    let excess = |alpha: f64| -> (f64, f64) {
        let mut setup = free_drop_setup(
            Vec2::zeros(),
            &[format!("experimental.volume_relaxation={alpha}")],
        );
        let n = setup.positions.len() as f64;
        let centre = setup.positions.iter().sum::<Vec2>() / n;
        for p in setup.positions.iter_mut() {
            if (*p - centre).norm() < 0.005 {
                *p = centre + 0.96 * (*p - centre);
            }
        }
        let kernel = QuinticSpline::for_spacing(dr);
        // The largest C/C₀ − 1 over the particles within 0.3R of the centre (full support).
        let worst = |points: &[Vec2]| -> f64 {
            let c = |p: Vec2| -> f64 {
                points
                    .iter()
                    .map(|q| kernel.value((p - q).norm()))
                    .sum::<f64>()
                    * dr
                    * dr
            };
            points
                .iter()
                .filter(|p| (**p - centre).norm() < 0.003)
                .map(|&p| c(p) - 1.0)
                .fold(f64::MIN, f64::max)
        };
        let before = worst(&setup.positions);
        let mut sim = Simulation::new(setup);
        for _ in 0..60 {
            sim.step(1e-4).unwrap();
        }
        (before, worst(&sim.state.position))
    };
    let (before, kept) = excess(0.0);
    assert!(before > 0.07, "the squeeze gives C/C0 - 1 = {before}");
    assert!(
        (kept - before).abs() < 0.01 * before,
        "{before} -> {kept} without the source"
    );
    let (_, relaxed) = excess(0.05);
    assert!(
        relaxed < before / 10.0,
        "{before} -> {relaxed} with alpha = 0.05"
    );
}

/// A drop translating at U = 1 m/s with no gravity is a drop at rest in a moving frame: the
/// velocity stays uniform (the scheme is Galilean invariant for uniform flow; the shifting,
/// which depends on |u|, moves particles but u_ps·∇u vanishes) and the drop keeps its width
/// and height to within one particle spacing (δr/W = 0.05).
#[test]
fn translating_drop_keeps_its_shape() {
    let u = Vec2::new(1.0, 0.0);
    let mut sim = free_drop(u);
    let worst = run_one_time_unit(&mut sim, u);
    assert!(worst < 1e-9, "velocity deviation {worst:e} m/s");
    let (mut lo, mut hi) = (sim.state.position[0], sim.state.position[0]);
    for p in &sim.state.position {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let (w, h) = ((hi.x - lo.x) / 0.02, (hi.y - lo.y) / 0.02);
    // Initially (W − δr)/W = 0.95 across the outer ring's centres.
    assert!((w - 0.95).abs() < 0.05, "width {w}");
    assert!((h - 0.95).abs() < 0.05, "height {h}");
    assert!(
        (lo.x + hi.x) * 0.5 > 0.0195 && (lo.x + hi.x) * 0.5 < 0.0205,
        "the drop moved to {}",
        (lo.x + hi.x) * 0.5
    );
}

/// A free drop at rest, no gravity, given a random conformation at each particle
/// (eigenvalues in 1–3 and 1–1.5, random axes): nothing outside acts on it, so its momentum
/// must stay zero whatever its internal stresses do. The projection's corrected pressure
/// gradient on the Dirichlet values of (35a) is not a sum of antisymmetric pair terms, and
/// with `detached_momentum = "unconstrained"` this drop's momentum reaches 25 % of the sum of
/// its particles' speeds within 20 steps, and its angular momentum 1.2 % of Σ|r − c||u|
/// (measured). Conserved: 3e-17 (bound 1e-12, round-off) and 4e-5 (bound 1e-3: shifting
/// moves the particles and with them the lever arms, which the step does not correct).
#[test]
fn a_stressed_free_drop_keeps_its_momentum() {
    let drift = |detached: &str| {
        let setup = free_drop_setup(
            Vec2::zeros(),
            &[format!("scheme.free_surface.detached_momentum={detached}")],
        );
        let mut sim = Simulation::new(setup);
        let mut seed: u64 = 12345;
        let mut uniform = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for a in sim.state.conformation.iter_mut() {
            let (l1, l2) = (1.0 + 2.0 * uniform(), 1.0 + 0.5 * uniform());
            let (c, s) = (std::f64::consts::PI * uniform()).sin_cos();
            *a = Sym2::new(
                l1 * c * c + l2 * s * s,
                (l1 - l2) * c * s,
                l1 * s * s + l2 * c * c,
            );
        }
        for _ in 0..20 {
            sim.step(1e-4).unwrap();
        }
        let u = &sim.state.velocity;
        let speed: f64 = u.iter().map(|v| v.norm()).sum();
        let momentum: Vec2 = u.iter().sum();
        let n = u.len() as f64;
        let c: Vec2 = sim.state.position.iter().sum::<Vec2>() / n;
        let (mut spin, mut arm) = (0.0, 0.0);
        for (p, v) in sim.state.position.iter().zip(u) {
            let d = p - c;
            spin += d.x * v.y - d.y * v.x;
            arm += d.norm() * v.norm();
        }
        (momentum.norm() / speed, (spin / arm).abs())
    };
    let (free, _) = drift("unconstrained");
    let (kept, spin) = drift("conserved");
    assert!(
        free > 1e-3,
        "the scheme alone kept the momentum ({free:e}): test not needed"
    );
    assert!(kept < 1e-12, "momentum / speed {kept:e}");
    assert!(spin < 1e-3, "angular momentum / (arm × speed) {spin:e}");
}

/// The Oldroyd-B drop of King & Lind (Re = 4, De = 1, β = 0.1) at a coarse W/δr = 20, run
/// through impact to t* = 3 with the binary: it must finish, keep its area, and spread as
/// finer runs do.
/// * Area: the drift of N δV/⟨C⟩_I falls with resolution, 5.95 / 1.70 / 0.86 % at W/δr =
///   20 / 40 / 80 (measured); bound 8 % at 20.
/// * Largest width: 2.023 at W/δr = 20, 2.002 at 40 and 1.990 at 80 (t* ≈ 1.3); within 5 % of
///   the finest.
#[test]
fn coarse_drop_impact_conserves_area() {
    let tmp = tempfile::tempdir().unwrap();
    let status = Command::new(env!("CARGO_BIN_EXE_rheosph"))
        .args([
            "-q",
            "run",
            "cases/drop-impact.toml",
            "--no-snapshots",
            "--set",
            "scene.resolution=20",
            "--set",
            "run.end_time=0.06",
        ])
        .arg("--out")
        .arg(tmp.path())
        .status()
        .unwrap();
    assert!(status.success());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["outcome"], "finished", "{}", summary["reason"]);
    let drop = &summary["drop"];
    let drift = drop["max_area_drift"].as_f64().unwrap();
    assert!(drift < 0.08, "area drift {drift}");
    let widest = drop["max_width_star"].as_f64().unwrap();
    assert!((widest / 1.990 - 1.0).abs() < 0.05, "largest W* {widest}");
    for f in ["drop.csv", "drop.png", "drop_area.png"] {
        assert!(tmp.path().join(f).exists(), "{f} missing");
    }
}
