//! Surface tension in the free-surface pressure (`fluid.surface_tension`): the Laplace
//! pressure of a drop at rest and the mode-2 period of an oscillating drop, at resolutions CI
//! can afford (R/δr = 10); the convergence with resolution is in the validation pages.

mod common;
use common::{run_quiet, shipped, summary_section};
use rheosph::app::run::Outcome;
use rheosph::setup::case;
use std::path::Path;

/// Static drop, R = 1, σ = 1, R/δr = 10, to t = 2 (two capillary times, Oh = 0.1): the
/// interior pressure is Laplace's σ/R. Measured +1.17 %, the curvature fit's own error at this
/// resolution (unit test of `free_surface::tension`). Bound 3 %: without the half-spacing
/// offset of the surface the pressure reads 1/(R − δr/2), +5 %; without surface tension, 0.
/// The spurious currents stay below 1e-4 of the capillary velocity σ/η = 10 (measured 1.3e-7 on
/// the ring-built drop).
#[test]
fn static_drop_holds_the_laplace_pressure() {
    let (p, speed) = static_drop(&["scene.resolution=20", "run.end_time=2"]);
    assert!((p - 1.0).abs() < 0.03, "interior pressure {p}, Laplace 1");
    assert!(speed < 1e-3, "spurious speed {speed} against σ/η = 10");
}

/// The static drop's interior pressure and late largest speed (`summary.json`, `drop`) with
/// the overrides `sets`; the run must finish.
fn static_drop(sets: &[&str]) -> (f64, f64) {
    let case = shipped("static-drop.toml", sets);
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let d = summary_section(dir.path(), "drop");
    (
        d["interior_pressure"].as_f64().unwrap(),
        d["late_max_speed"].as_f64().unwrap(),
    )
}

/// The same drop cut from the square lattice (`scene.drop.lattice = "square"`, 316
/// particles): its staircase surface must round itself and come to rest. Measured to t = 5:
/// the corners' first jolt 0.34 (3.4 % of σ/η) at t = 0.05, the largest speed 5e-3 at t = 1,
/// 3e-4 at 2, 2e-5 at 3.5–4 (a decaying oscillation); interior pressure 1.0056 (+0.56 %; the
/// area-equivalent radius is 1.0029, its Laplace pressure 0.9971). Bounds: 3 % on the
/// pressure as above, and the late speed (t = 3.2–4) below 1e-4 σ/η, which a surface
/// still being driven by its staircase (speeds ~1e-2 at t < 1) would not meet.
#[test]
fn a_drop_cut_from_the_square_lattice_rounds_itself_and_rests_at_laplace() {
    let (p, speed) = static_drop(&[
        "scene.resolution=20",
        "run.end_time=4",
        "scene.drop.lattice=\"square\"",
    ]);
    assert!((p - 1.0).abs() < 0.03, "interior pressure {p}, Laplace 1");
    assert!(speed < 1e-3, "late speed {speed} against σ/η = 10");
}

/// The ellipse of aspect ratio 1.1 (mode-2 amplitude 0.049) at R/δr = 10, Oh = 0.005: the
/// period against the 2D inviscid 2π/√(6σ/ρR³) = 2.565. Measured 2.480 (−3.3 %; −1.0 % at
/// R/δr = 20, −0.6 % at 40) with the case's second-order gradient. Bound 4 %. Without surface
/// tension the drop does not oscillate at all; with curvature from the smoothed normals'
/// field it broke down (validation pages).
#[test]
fn oscillating_drop_has_the_capillary_period() {
    let case = shipped(
        "oscillating-drop.toml",
        &["scene.resolution=20", "run.end_time=6"],
    );
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let d = summary_section(dir.path(), "drop");
    let period = d["oscillation_period"].as_f64().expect("an oscillation");
    let exact = 2.0 * std::f64::consts::PI / 6f64.sqrt();
    assert!(
        (period / exact - 1.0).abs() < 0.04,
        "period {period}, theory {exact}"
    );
}

/// The damping of a viscous drop (η = 0.05, Oh = 0.05, R/δr = 20) against the exact linear
/// theory of the 2D liquid cylinder (`analysis::analytic::drop_oscillation`; the summary's
/// `theory_decay_rate` = 0.1773, period 2.590). Measured with the case's second-order
/// gradient and midpoint curvature: decay 0.1573 (−11 %), period 2.548 (−1.6 %). The deficit
/// is the free-surface viscous term's (−0.7, −11, −15 % at R/δr = 10, 20, 40, validation pages); with
/// the paper's operators the drop decayed at 0.1902 (+7.3 %) because two numerical dampings
/// (the first-order gradient at the surface rows, the curvature at r*) hid it. Bounds: 15 %
/// on the decay, so a drop without its viscous damping (the capillary mode alone, 0) or with
/// the old excess doubled fails; 2 % on the period.
#[test]
fn viscous_drop_decays_at_the_linear_theory_rate() {
    let case = shipped(
        "oscillating-drop.toml",
        &["scene.resolution=40", "fluid.viscosity=0.05"],
    );
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let d = summary_section(dir.path(), "drop");
    let (gamma, theory) = (d["decay_rate"].as_f64(), d["theory_decay_rate"].as_f64());
    let (gamma, theory) = (gamma.expect("a decay"), theory.expect("a theory"));
    assert!((theory - 0.1773).abs() < 1e-3, "theory {theory}");
    assert!(
        (gamma / theory - 1.0).abs() < 0.15,
        "decay {gamma}, theory {theory}"
    );
    let period = d["oscillation_period"].as_f64().unwrap();
    let exact = d["theory_period"].as_f64().unwrap();
    assert!(
        (period / exact - 1.0).abs() < 0.02,
        "period {period}, theory {exact}"
    );
}

/// `cases/oscillating-drop-oldroyd-b.toml` (η0 = 0.05, β = 0.2, λ = 1: De = ω0λ = 2.45,
/// R/δr = 20) against the linear theory with the complex viscosity η_s + η_p/(1 + λs):
/// period 2.515, decay 0.0644, a third of the Newtonian drop's of the same η0 (0.177) because
/// the polymer's damping falls as 1/(1 + De²). Measured: period 2.473 (−1.7 %), decay 0.0658
/// (+2.2 %). With the paper's first-order gradient and the curvature at r* the drop decayed
/// at 0.0878 (+36 %): the first-order gradient's damping at the surface rows (0.0851 with the
/// midpoint curvature alone, 0.0683 with the second-order gradient alone; validation pages). Bounds:
/// 3 % on the period; 10 % on the decay, which the old operators fail and a drop that lost
/// the polymer's memory (decaying as the Newtonian one, 0.19) or its damping (η_s alone:
/// 0.038) fails by far.
#[test]
fn oldroyd_b_drop_follows_the_complex_viscosity() {
    let case = shipped("oscillating-drop-oldroyd-b.toml", &[]);
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let d = summary_section(dir.path(), "drop");
    let period = d["oscillation_period"].as_f64().unwrap();
    let exact = d["theory_period"].as_f64().unwrap();
    assert!(
        (period / exact - 1.0).abs() < 0.03,
        "period {period}, theory {exact}"
    );
    let gamma = d["decay_rate"].as_f64().unwrap();
    let theory = d["theory_decay_rate"].as_f64().unwrap();
    assert!((theory - 0.0644).abs() < 1e-3, "theory {theory}");
    assert!(
        (gamma / theory - 1.0).abs() < 0.10,
        "decay {gamma}, theory {theory}"
    );
}

/// The seed's cohesion force (scheme.surface_tension.form = "cohesion") in the weakly compressible
/// scheme: a drop of R = 0.75 at δr = 0.05 (R/δr = 15, σ = 1, c = 50, Monaghan α = 1 to damp
/// its breathing, to t = 3) holds together, and its interior pressure is the flat surface's
/// cohesive pressure K (15.92, the mean field's, `Cohesion::flat_pressure`) plus σ_eff/R.
/// Measured 17.66 at t = 4 against K + σ/R = 17.25 (+2.4 %). The Laplace test over R = 0.75,
/// 1, 1.5 (validation pages) gives p0 = 16.01 (K + 0.6 %) and σ_eff = 1.20σ; the breathing left
/// ±0.1 in the late mean. Bound 5 %: the Laplace part σ/R is 7.7 % of the pressure, so a
/// drop without surface tension beyond K would pass, but one without the cohesion force (p
/// ≈ 0) or with K of a wrong normalisation (a factor 2π or ρ) would not.
#[test]
fn cohesion_drop_holds_the_cohesive_and_laplace_pressure() {
    let case = shipped(
        "static-drop.toml",
        &[
            "scene.resolution=30",
            "scene.drop.diameter=1.5",
            "scene.length=3.75",
            "scene.height=3.75",
            "scene.drop.centre_height=1.875",
            "scheme.surface_tension.form=cohesion",
            "scheme.method=wcsph",
            "scheme.wcsph.sound_speed=50",
            "scheme.wcsph.artificial_viscosity=1",
            "scheme.wcsph.density_diffusion=0.1",
            "run.end_time=3",
        ],
    );
    let (s, dir) = run_quiet(&case, false);
    assert_eq!(s.outcome, Outcome::Finished, "{:?}", s.reason);
    let support = rheosph::engine::kernel::QuinticSpline::for_spacing(0.05).support();
    let none: &[rheosph::engine::boundary::Shape] = &[];
    let k = rheosph::engine::free_surface::Cohesion::new(1.0, 1.0, 0.05, support, none, None)
        .flat_pressure;
    assert!((k - 15.92).abs() < 0.01, "K {k}");
    let d = summary_section(dir.path(), "drop");
    let p = d["interior_pressure"].as_f64().unwrap();
    let laplace = k + 1.0 / 0.75;
    assert!(
        (p / laplace - 1.0).abs() < 0.05,
        "interior pressure {p}, K + σ/R {laplace}"
    );
    let width = d["final_width_star"].as_f64().unwrap();
    assert!((width - 1.0).abs() < 0.02, "the drop's width {width}");
}

/// Surface tension needs a free surface: a channel refuses it, naming the key.
#[test]
fn surface_tension_needs_a_free_surface() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/poiseuille.toml");
    let e = case::load(&path, &["fluid.surface_tension=0.1".to_string()]).unwrap_err();
    assert!(e.to_string().contains("fluid.surface_tension"), "{e}");
}
