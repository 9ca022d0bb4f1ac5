//! Wetting (`scene.contact_angle`): a sessile drop at rest takes the circular cap that meets
//! the plate at the prescribed angle, and a pool rises at a vertical wall by the exact 2D
//! meniscus height, at resolutions CI can afford; the resolution studies are in the validation pages.

mod common;
use common::{run_quiet, shipped, summary_section};
use rheosph::app::run::Outcome;

/// Half a disc (R/δr = 20) resting on the plate, no gravity, spreads or beads to rest at
/// θ = 40° and 120° (it starts at 90°) by the case's end time t = 10. Measured 40.4° and
/// 118.9°, late speeds 5.9e-3 and 4e-4 (the 120° drop's angle moves by 0.01° from t = 10 to
/// 20). Bound 3°, a tenth of the distance to the 90° the drop would keep without the
/// condition; the drop must also be at rest (largest speed below 1 % of the capillary
/// velocity σ/η = 10).
#[test]
fn a_sessile_drop_rests_at_its_contact_angle() {
    // Independent runs, side by side (each has serial stages).
    std::thread::scope(|s| {
        for theta in [40.0, 120.0] {
            s.spawn(move || rests_at_its_angle(theta, &[]));
        }
    });
}

/// Runs the shipped sessile drop at `theta` with `overrides` and checks that it finishes at
/// rest (largest late speed below 1 % of σ/η) within 3° of θ.
fn rests_at_its_angle(theta: f64, overrides: &[&str]) {
    let angle = format!("scene.contact_angle={theta}");
    let mut all = overrides.to_vec();
    all.push(&angle);
    let case = shipped("sessile-drop.toml", &all);
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "θ {theta}: {:?}", s.reason);
    let d = summary_section(dir.path(), "drop");
    let measured = d["contact_angle"].as_f64().unwrap();
    let speed = d["late_max_speed"].as_f64().unwrap();
    eprintln!("θ = {theta}: measured {measured:.2}°, late speed {speed:.2e}");
    assert!(
        (measured - theta).abs() < 3.0,
        "θ {theta}: measured {measured}"
    );
    assert!(speed < 0.1, "not at rest: {speed}");
}

/// The same drops at R/δr = 10, where the wetting foot is one or two particles thick, with
/// the contact-line particles held off the plate (`contact_line_rows = "held"`): with the
/// shipped `surface` the 40° foot sinks through the plate at t = 2.4 and the 60° drop sheds
/// a particle at 7.4. Measured 41.2° and 59.1°; the same bounds as at R/δr = 20 (the fitted
/// circle at this resolution rests on about 30 surface particles).
#[test]
fn a_coarse_wetting_drop_held_off_its_plate_keeps_its_foot() {
    let coarse = [
        "run.end_time=20",
        "scene.resolution=20",
        "experimental.contact_rows=\"held\"",
    ];
    std::thread::scope(|s| {
        for theta in [40.0, 60.0] {
            s.spawn(move || rests_at_its_angle(theta, &coarse));
        }
    });
}

/// The seed's wetting by attraction (weakly compressible, cohesion, the walls pulling with
/// S(1 + cos θ)/2) at θ = 60°, R/δr = 10 (c = 50, Monaghan α = 0.3, to t = 6): with
/// `contact_line_rows = "surface"` the contact-line particle, whose pressure is near zero
/// while the wall pulls it, sinks through the plate at t = 0.90 (0.57 at R/δr = 20); held off
/// the plate the drop spreads from 90° and reads 67.6° at t = 6 (62.0° at R/δr = 20, still
/// falling). Bound 10°: the spreading is slow under the artificial viscosity and this is
/// the coarsest drop; a drop that does not wet stays near 90°.
#[test]
fn a_drop_wetting_by_attraction_spreads_with_its_foot_held_off_the_plate() {
    let case = shipped(
        "sessile-drop.toml",
        &[
            "scene.resolution=20",
            "scene.contact_angle=60",
            "scheme.method=wcsph",
            "scheme.surface_tension.form=cohesion",
            "scheme.wcsph.sound_speed=50",
            "scheme.wcsph.artificial_viscosity=0.3",
            "scheme.viscosity=explicit",
            "experimental.contact_rows=held",
            "run.end_time=6",
        ],
    );
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let measured = summary_section(dir.path(), "drop")["contact_angle"]
        .as_f64()
        .unwrap();
    eprintln!("θ = 60: measured {measured:.2}°");
    assert!((measured - 60.0).abs() < 10.0, "measured {measured}");
}

/// A pool 0.6 deep in a tank 4 wide (ℓ_c = 0.5, ℓ_c/δr = 12.5), θ = 60°, to t = 12: the
/// surface at the walls stands ℓ_c √(2(1 − sin θ)) = 0.2588 above the far level (Landau &
/// Lifshitz §61). Measured here 0.2545 (−1.7 %; 0.2613 with g in the predictor); in the
/// shipped tank (6 wide, to t = 20) +0.3 % (+6.4 % with g in the predictor, −0.5 % at
/// ℓ_c/δr = 25), the excess in the first two columns (validation pages). Bound 12 %: the tank's sloshing
/// moves the rise by ±2 % over the averaged half, and without the condition the surface
/// stays flat.
#[test]
fn a_pool_rises_at_the_wall_by_the_meniscus_height() {
    let case = shipped(
        "meniscus.toml",
        &[
            "scene.length=4",
            "scene.depth=0.6",
            "scene.height=1.2",
            "scene.resolution=30",
            "run.end_time=12",
        ],
    );
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let m = summary_section(dir.path(), "meniscus");
    let (rise, exact) = (
        m["wall_rise"].as_f64().unwrap(),
        m["wall_rise_exact"].as_f64().unwrap(),
    );
    eprintln!("wall rise {rise:.4}, exact {exact:.4}");
    assert!(
        (rise / exact - 1.0).abs() < 0.12,
        "rise {rise}, exact {exact}"
    );
}

/// `scene.wall_contact_angle` is range-checked like `scene.contact_angle`, and refused by the
/// cohesion variant, whose wall attraction takes one angle at every wall.
#[test]
fn the_tank_walls_angle_is_validated() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/capillary-rise.toml");
    let bad = |o: &[&str]| {
        let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
        rheosph::setup::case::load(&path, &o)
            .unwrap_err()
            .to_string()
    };
    assert!(bad(&["scene.wall_contact_angle=170"]).contains("scene.wall_contact_angle"));
    // The case's volume source belongs to the PPE, which the weakly compressible method has not.
    let cohesion = [
        "scene.wall_contact_angle=90",
        "scheme.method=wcsph",
        "experimental.volume_relaxation=0",
        "scheme.surface_tension.form=cohesion",
    ];
    assert!(bad(&cohesion).contains("scene.wall_contact_angle"));
    let o = vec!["scene.wall_contact_angle=90".to_string()];
    assert!(rheosph::setup::case::load(&path, &o).is_ok());
}

/// A pool at rest (2 wide, 0.4 deep, δr = 0.04, θ = 90°, σ ≈ 0, implicit viscosity) with the
/// body force in the reduced pressure (`scheme.gravity = "auto"`, which a pool resolves to
/// `reduced-pressure`) stays at rest to t = 5: P = p − ρ g·r is constant, which every
/// operator reproduces, so nothing is left to move it but the solves' residuals (measured:
/// level moved 4.7e-7, speeds ≤ 8.5e-7). Bounds: the level within δr/40 = 1e-3, every speed
/// below 1e-4 (a ten-thousandth of √(gD)). With g in the predictor (the paper's) the same
/// tank swells by 0.046 (validation pages, *Still water*); the test checks it moves more than 10× the
/// bound, so that the comparison is the reduced pressure's doing. The validation refuses the
/// reduced pressure where g·r is not single-valued.
#[test]
fn a_pool_at_rest_stays_at_rest_with_gravity_in_the_reduced_pressure() {
    let still = [
        "scene.length=2",
        "scene.depth=0.4",
        "scene.height=0.8",
        "scene.resolution=20",
        "scene.contact_angle=90",
        "fluid.surface_tension=1e-9",
        "scheme.viscosity=implicit",
        "run.end_time=5",
    ];
    let (moved, fastest) = pool_drift(&still);
    eprintln!("reduced pressure: level moved {moved:.2e}, largest speed {fastest:.2e}");
    assert!(moved < 1e-3, "level moved {moved}");
    assert!(fastest < 1e-4, "largest speed {fastest}");
    let predictor = [&still[..], &["scheme.gravity=predictor"]].concat();
    let (moved, fastest) = pool_drift(&predictor);
    eprintln!("g in the predictor: level moved {moved:.2e}, largest speed {fastest:.2e}");
    assert!(moved > 1e-2, "the predictor's pool moved only {moved}");

    // The channel's body force drives it along its periodic axis.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/poiseuille.toml");
    let o = vec!["scheme.gravity=reduced-pressure".to_string()];
    let refused = rheosph::setup::case::load(&path, &o)
        .unwrap_err()
        .to_string();
    assert!(refused.contains("scheme.gravity"), "{refused}");
}

/// `scene.plates.fill` starts the column between the plates above (or below) the pool's
/// depth: the shipped case (d = 0.4 = 10δr) gains 10 particles per row, 35 rows for a fill
/// of 1.4, loses 10 per row down to the rounded ends' centres, and refuses a column below
/// them or above the box, naming the field.
#[test]
fn the_column_between_the_plates_starts_where_asked() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/capillary-rise.toml");
    let load = |o: &[&str]| {
        let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
        rheosph::setup::case::load(&path, &o)
    };
    let particles = |fill: &str| {
        let case = load(&[&format!("scene.plates.fill={fill}")]).unwrap();
        case.scene.particles() as i64
    };
    let base = load(&[]).unwrap().scene.particles() as i64;
    assert_eq!(particles("0"), base);
    assert_eq!(particles("1.4") - base, 350);
    assert_eq!(particles("-0.4") - base, -100);
    for bad in ["-0.9", "1.7", "nan"] {
        let e = load(&[&format!("scene.plates.fill={bad}")]).unwrap_err();
        assert!(e.to_string().contains("scene.plates.fill"), "{e}");
    }
}

/// How far the far level of `meniscus.toml` with `overrides` moved over the run, and the
/// largest particle speed.
fn pool_drift(overrides: &[&str]) -> (f64, f64) {
    let (s, dir) = run_quiet(&shipped("meniscus.toml", overrides), false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let level = column(&dir.path().join("meniscus.csv"), "level");
    let speed = column(&dir.path().join("series.csv"), "max_speed");
    let moved = (level[level.len() - 1] - level[0]).abs();
    (moved, speed.iter().cloned().fold(0.0, f64::max))
}

/// A column of a CSV file by its header name.
fn column(path: &std::path::Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}
