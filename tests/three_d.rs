//! The step's stages in 3D, on a channel between plates at y = 0 and 1 (periodic along x and
//! z, δr = 1/8), against exact solutions and against the same stages in 2D: the PPE matrix and
//! its solvers, the implicit viscous solve, and the conformation update with EVSS.

mod common;

use nalgebra::SVector;
use rheosph::engine::boundary::{Ghosts, Plane, Shape, TensorMirror, Wall};
use rheosph::engine::dimension::{Dim, Dimension, Sym, SymTensor};
use rheosph::engine::kernel::{QuinticSpline, H_OVER_DR};
use rheosph::engine::kinematics::{ConstitutiveGradient, Kinematics};
use rheosph::engine::neighbourhood::{Geometry, Neighbourhood};
use rheosph::engine::neighbours::Domain;
use rheosph::engine::operators::DivergenceForm;
use rheosph::engine::pressure::PressureSystem;
use rheosph::engine::rheology::{
    ConformationChoice, ConformationIntegrator, ConformationScheme, ConformationStage, Flow, Fluid,
    Model, Remap, ViscosityLaw,
};
use rheosph::engine::viscosity::{Diffusion, Prescribed, Viscosity};
use rheosph_solver::{NullSpace, Preconditioner, SolverOptions, Strategy};

/// Lattice points per unit length.
const M: usize = 8;

/// The neighbourhood of an M^D lattice between no-slip plates at y = 0 and 1, periodic along
/// the other axes, its walls continuing tensors linearly ([`TensorMirror::Linear`]).
fn plates<const D: usize>() -> (Neighbourhood<D>, usize)
where
    Dim<D>: Dimension<D>,
{
    let dr = 1.0 / M as f64;
    let n = M.pow(D as u32);
    let points: Vec<SVector<f64, D>> = (0..n)
        .map(|k| SVector::from_fn(|a, _| ((k / M.pow((D - 1 - a) as u32)) % M) as f64 + 0.5) * dr)
        .collect();
    let plane = |position, fluid_side| Plane {
        axis: 1,
        position,
        fluid_side,
    };
    let walls = [plane(0.0, 1.0), plane(1.0, -1.0)]
        .map(|p| Wall::<D>::no_slip(Shape::Plane(p), TensorMirror::Linear));
    let mut hood = Neighbourhood::<D>::new(Ghosts::new(walls.to_vec()));
    hood.points = points;
    let mut periodic = [true; D];
    periodic[1] = false;
    let domain = Domain::<D> {
        min: SVector::from_fn(|a, _| if a == 1 { -1.0 } else { 0.0 }),
        max: SVector::from_fn(|a, _| if a == 1 { 2.0 } else { 1.0 }),
        periodic,
    };
    let kernel = QuinticSpline::in_dimension::<D>(H_OVER_DR * dr);
    let geometry = Geometry {
        domain: &domain,
        kernel: &kernel,
        spacing: dr,
    };
    hood.update(true, geometry, n);
    (hood, n)
}

/// The PPE matrix −∇²/ρ of (25) between 3D plates, its walls' mirrors folded into their
/// parents' columns (∂p/∂n = 0), applied to p = cos πy (which meets that condition) gives
/// π² cos πy within the truncation error of (21) at δr = 1/8: measured 2.9 % of π² (3.0 % on
/// the 2D lattice of the same spacing; bound 5 %). BiCGStab with Jacobi and with AMG inverts
/// it: from the right-hand side A p of a field varying along all three axes it recovers p
/// (up to the constant the PPE leaves free) to 1e-7 (measured 2e-14 in 10 iterations with
/// Jacobi, 1.2e-13 in 7 with AMG).
#[test]
fn the_3d_ppe_between_plates_is_the_laplacian_and_its_solvers_invert_it() {
    let (hood, n) = plates::<3>();
    let mut system = PressureSystem::new();
    system.assemble_matrix(hood.parts(), 1.0, &[]);
    let (matrix, _) = system.system();
    let apply = |p: &[f64]| -> Vec<f64> {
        let row = |r: sprs::CsVecView<f64>| r.iter().map(|(j, a)| a * p[j]).sum::<f64>();
        matrix.outer_iterator().map(row).collect()
    };
    let pi = std::f64::consts::PI;
    let p: Vec<f64> = hood.points[..n].iter().map(|r| (pi * r.y).cos()).collect();
    let worst = apply(&p)
        .iter()
        .zip(&p)
        .map(|(lp, p)| (lp - pi * pi * p).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.05 * pi * pi, "−∇²p off by {worst}");
    let rich: Vec<f64> = hood.points[..n]
        .iter()
        .map(|r| {
            let wave = (2.0 * pi * r.x).cos() * (3.0 * pi * r.y).cos() * (2.0 * pi * r.z).sin();
            (pi * r.y).cos() + 0.3 * wave + 0.1 * (2.0 * pi * r.z).cos()
        })
        .collect();
    let mean = rich.iter().sum::<f64>() / n as f64;
    let rhs = apply(&rich);
    for preconditioner in [Preconditioner::Jacobi, Preconditioner::Amg] {
        let mut system = PressureSystem::new();
        system.assemble_matrix(hood.parts(), 1.0, &[]);
        // The assembled right-hand side is −∇·u*/δt: ∇·u* = −A p for δt = 1.
        let divergence: Vec<f64> = rhs.iter().map(|b| -b).collect();
        system.assemble_rhs(&divergence, 1.0, &[], &[]);
        let options = SolverOptions {
            relative_tolerance: 1e-12,
            absolute_tolerance: 0.0,
            max_iterations: 2000,
            null_space: NullSpace::Constant,
            strategy: Strategy::IterativeWithFallback,
            matrix_unchanged: false,
            preconditioner,
        };
        let mut solved = vec![0.0; n];
        let report = system.solve(&mut solved, &options).expect("solves");
        assert!(!report.fell_back, "{preconditioner:?}: {report:?}");
        let shift = solved.iter().sum::<f64>() / n as f64;
        let error = solved
            .iter()
            .zip(&rich)
            .map(|(s, p)| (s - shift - (p - mean)).abs())
            .fold(0.0, f64::max);
        assert!(error < 1e-7, "{preconditioner:?}: p off by {error}");
    }
}

/// The implicit viscous stage in 3D (backward Euler): the steady Poiseuille profile u =
/// 4y(1 − y) x̂ under the body force g = 8ν x̂ is a fixed point of `(I − δtνL)u* = u^n + δt g`
/// (the quadratic continuation makes L exact for it), so one step from it with a cold start
/// returns it to the solve's tolerance, with the walls' stencils folded into the matrix.
#[test]
fn the_3d_implicit_viscous_step_keeps_steady_poiseuille_flow() {
    let (hood, n) = plates::<3>();
    let nu = 0.7;
    let dt = 0.05;
    let exact: Vec<_> = hood.points[..n]
        .iter()
        .map(|r| SVector::<f64, 3>::new(4.0 * r.y * (1.0 - r.y), 0.0, 0.0))
        .collect();
    let mut velocity: Vec<_> = exact
        .iter()
        .map(|u| u + dt * SVector::<f64, 3>::new(8.0 * nu, 0.0, 0.0))
        .collect();
    let mut stage = Viscosity::Implicit.stage::<3>(1e-12);
    let zeros = vec![SVector::<f64, 3>::zeros(); n];
    let reports = stage
        .solve(
            hood.parts(),
            Diffusion {
                nu_dt: nu * dt,
                factor: &[],
            },
            &zeros,
            &mut velocity,
            Prescribed {
                rows: &[],
                value: SVector::zeros(),
            },
            Preconditioner::Jacobi,
        )
        .expect("solves")
        .expect("implicit");
    assert_eq!(reports.len(), 3, "one solve per component");
    let worst = velocity
        .iter()
        .zip(&exact)
        .map(|(u, e)| (u - e).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "off the steady profile by {worst}");
}

/// Oldroyd-B in the 3D channel's steady Poiseuille flow advanced by the conformation stage
/// (log-conformation, Strang, with EVSS and ∇·Φ) matches the 2D stage on the same flow over
/// 20 steps at every particle: A's in-plane components within 1e-12 relative (the two
/// eigen-decompositions differ in round-off), A_zz = 1, A_xz = A_yz = 0, det A ≥ 1; ∇·Φ in
/// the plane within 1e-4 relative and zero along z. ∇·Φ is not equal to round-off: the
/// discrete A_xy is not exactly linear in y, and the two lattices' supports sample it with
/// different truncation errors (measured 3.9e-6 relative).
#[test]
fn the_3d_conformation_stage_matches_the_2d_one_on_channel_flow() {
    fn run<const D: usize>() -> (Vec<SVector<f64, D>>, Vec<Sym<D>>, Vec<SVector<f64, D>>)
    where
        Dim<D>: Dimension<D>,
    {
        let (hood, n) = plates::<D>();
        let fluid = Fluid {
            model: Model::OldroydB,
            density: 1.0,
            viscosity: 1.0,
            beta: 0.1,
            relaxation_time: 1.0,
            surface_tension: 0.0,
            law: ViscosityLaw::Constant,
        };
        let velocity: Vec<SVector<f64, D>> = hood.points[..n]
            .iter()
            .map(|r| {
                SVector::from_fn(|a, _| {
                    if a == 0 {
                        4.0 * r[1] * (1.0 - r[1])
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        let mut kinematics = Kinematics::<D>::new(ConstitutiveGradient::Solenoidal);
        kinematics.update(hood.parts(), &velocity);
        let choice = ConformationChoice {
            scheme: ConformationScheme::Log,
            integrator: ConformationIntegrator::Strang,
            remap: Remap::Limited,
        };
        let mut stage =
            ConformationStage::<D>::new(choice, &fluid, 0.1, Some(DivergenceForm::Negative));
        let mut a = vec![Sym::<D>::IDENTITY; n];
        let u_ps = vec![SVector::<f64, D>::zeros(); n];
        for _ in 0..20 {
            let flow = Flow {
                grad_u: kinematics.constitutive(),
                u_ps: &u_ps,
            };
            stage.update(&fluid, 0.01, hood.parts(), flow, &mut a);
        }
        let div = stage.stress_divergence().expect("formed").to_vec();
        (hood.points[..n].to_vec(), a, div)
    }
    let (p2, a2, d2) = run::<2>();
    let (p3, a3, d3) = run::<3>();
    let scale = a3.iter().map(|a| a.trace()).fold(0.0, f64::max);
    let mut checked = 0;
    for (i, p) in p3.iter().enumerate() {
        // The 2D particle at the same (x, y): the 3D lattice runs z fastest.
        let j = p2
            .iter()
            .position(|q| (q.x - p.x).abs() < 1e-12 && (q.y - p.y).abs() < 1e-12)
            .expect("same lattice in the plane");
        let (a, b) = (&a3[i], &a2[j]);
        for (r, c) in [(0, 0), (0, 1), (1, 1)] {
            assert!(
                (a.entry(r, c) - b.entry(r, c)).abs() < 1e-12 * scale,
                "A_{r}{c} at {i}"
            );
        }
        assert!((a.entry(2, 2) - 1.0).abs() < 1e-12 && a.entry(0, 2).abs() < 1e-12);
        assert!(a.entry(1, 2).abs() < 1e-12);
        assert!(a.det() >= 1.0 - 1e-12, "det A = {} at {i}", a.det());
        let dscale = 1.0 + d2[j].norm();
        assert!((d3[i].xy() - d2[j]).norm() < 1e-4 * dscale, "∇·Φ at {i}");
        assert!(d3[i].z.abs() < 1e-12 * dscale, "∇·Φ_z at {i}");
        checked += 1;
    }
    assert_eq!(checked, M * M * M);
}

/// The shipped start-up Poiseuille case (Oldroyd-B, Re = Wi = 1, β = 0.1, the paper's
/// explicit viscosity) in `dimension` at H/δr = `resolution`, at least 12δr long so that
/// H/δr = 10 holds the three supports a periodic axis needs (in 3D as deep, the default).
fn poiseuille(dimension: usize, resolution: usize, end_time: f64) -> rheosph::setup::case::Case {
    let text = std::fs::read_to_string("cases/poiseuille.toml").unwrap();
    let length = 12.0 / resolution as f64;
    let overrides = [
        format!("scene.dimension={dimension}"),
        format!("scene.resolution={resolution}"),
        format!("scene.length={}", length.max(1.0)),
        format!("run.end_time={end_time}"),
    ];
    rheosph::setup::case::parse(&text, "poiseuille.toml", "poiseuille", &overrides).unwrap()
}

/// The streamwise L2 error against Waters–King at the output times `every` apart to
/// `end_time` (the series' measure, `Reference::l2_error`), and min det A over the run.
fn channel_errors<const D: usize>(
    sim: &mut rheosph::engine::step::Simulation<D>,
    reference: &mut rheosph::analysis::reference::Reference,
    every: f64,
    end_time: f64,
) -> (Vec<f64>, f64)
where
    Dim<D>: rheosph::engine::step::StepDimension<D>,
{
    let (mut errors, mut min_det) = (Vec::new(), f64::INFINITY);
    let plane = |v: &[SVector<f64, D>]| -> Vec<rheosph::engine::math::Vec2> {
        v.iter()
            .map(|p| rheosph::engine::math::Vec2::new(p[0], p[1]))
            .collect()
    };
    let mut next = every;
    while sim.state.time < end_time - 1e-12 {
        let report = sim.step(next - sim.state.time).expect("a stable run");
        assert!(report.dt > 0.0);
        let det = sim
            .state
            .conformation
            .iter()
            .map(|a| a.det())
            .fold(f64::INFINITY, f64::min);
        min_det = min_det.min(det);
        if sim.state.time >= next - 1e-12 {
            let s = &sim.state;
            errors.push(reference.l2_error(&plane(&s.position), &plane(&s.velocity), s.time));
            next += every;
        }
    }
    (errors, min_det)
}

/// Start-up Oldroyd-B Poiseuille flow between plates in space (periodic in x and z, three
/// kernel supports deep) follows Waters & King (1970) as the same scene does in the plane:
/// at H/δr = 10, the streamwise L2 at t = 0.25, 0.5, …, 2 averages 2.98e-2 in 3D against
/// 3.15e-2 in 2D, and each of the eight errors is within 10 % of the 2D one (the error is
/// the resolution's, not the dimension's: both lattices' operators are O(δr²)). Bound: the
/// 3D mean within 1.25 times the 2D mean, which a wrong 3D normalisation, mirror or stress
/// divergence exceeds many times over. det A ≥ 1 − 1e-9 throughout (Oldroyd-B keeps
/// det A ≥ 1; the log form does to round-off).
#[test]
fn the_3d_channel_follows_waters_king_as_the_2d_one_does() {
    let (every, end) = (0.25, 2.0);
    let case = poiseuille(2, 10, end);
    let mut reference = case.scene.reference(&case.fluid).unwrap();
    let mut plane = rheosph::engine::step::Simulation::new(case.setup().unwrap());
    let (errors_2d, det_2d) = channel_errors(&mut plane, &mut reference, every, end);
    let setup = poiseuille(3, 10, end).setup_in_space().unwrap();
    let mut space = rheosph::engine::step::Simulation::in_space(setup).unwrap();
    let (errors_3d, det_3d) = channel_errors(&mut space, &mut reference, every, end);
    let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len() as f64;
    let (l2_2d, l2_3d) = (mean(&errors_2d), mean(&errors_3d));
    println!("H/dr = 10, t <= {end}: L2 2D {l2_2d:.3e}, 3D {l2_3d:.3e}; min det A 2D {det_2d:.12}, 3D {det_3d:.12}");
    assert_eq!(errors_3d.len(), errors_2d.len());
    assert!(l2_3d < 1.25 * l2_2d, "3D L2 {l2_3d:e}, 2D {l2_2d:e}");
    assert!(det_3d > 1.0 - 1e-9, "min det A = {det_3d}");
}

/// A case in space refuses, by key, what is written for the plane only, and a 2D entry
/// point refuses a 3D case instead of running it flat.
#[test]
fn a_3d_case_names_what_it_cannot_have() {
    let text = std::fs::read_to_string("cases/poiseuille.toml").unwrap();
    let parse = |extra: &[&str]| {
        let mut overrides = vec!["scene.dimension=3".to_string()];
        overrides.extend(extra.iter().map(|s| s.to_string()));
        rheosph::setup::case::parse(&text, "poiseuille.toml", "p", &overrides)
    };
    let refused = |extra: &[&str], field: &str| {
        let e = parse(extra).expect_err("refused");
        assert_eq!(e.field, field, "{e}");
    };
    refused(&["scheme.method=\"wcsph\""], "scheme.method");
    refused(
        &["scheme.operators.laplacian=\"second\""],
        "scheme.operators.laplacian",
    );
    refused(&["scene.refine_walls=2.0"], "scene.refine_walls");
    refused(&["scene.depth=0.2"], "scene.depth");
    refused(&["scene.dimension=4"], "scene.dimension");
    let drop = std::fs::read_to_string("cases/drop-impact.toml").unwrap();
    let e = rheosph::setup::case::parse(&drop, "d", "d", &["scene.dimension=3".into()]).err();
    assert_eq!(e.expect("refused").field, "scene.dimension");
    let flat = rheosph::setup::case::parse(&text, "p", "p", &["scene.depth=1.0".into()]).err();
    assert_eq!(flat.expect("refused").field, "scene.depth");
    let case = parse(&[]).unwrap();
    let options = rheosph::app::run::RunOptions {
        out_dir: std::env::temp_dir().join("rheosph-3d-refused"),
        quiet: true,
        charts: None,
        snapshots: false,
        progress: None,
    };
    let start = rheosph::app::run::run_loop::Start::Fresh;
    let two_d = rheosph::app::run::run_loop::Run::<2>::new(&case, &options, start);
    assert!(two_d
        .err()
        .unwrap()
        .to_string()
        .contains("scene.dimension = 3"));
}

/// A 3D run continued from its checkpoint is bit-identical to one never interrupted: the
/// explicit Oldroyd-B channel at H/δr = 10, checkpointed at step 30 and compared at step 80,
/// across a Morton reordering (step 50); a 2D checkpoint is refused by a 3D simulation.
#[test]
fn a_3d_checkpoint_continues_bit_identically() {
    use rheosph::app::run::checkpoint;
    use rheosph::engine::step::Simulation;
    let space = || Simulation::in_space(poiseuille(3, 10, 1.0).setup_in_space().unwrap()).unwrap();
    let advance = |sim: &mut Simulation<3>, to: u64| {
        while sim.state.steps < to {
            sim.step(f64::INFINITY).expect("a stable run");
        }
    };
    let mut reference = space();
    advance(&mut reference, 30);
    let bytes = checkpoint::encode(&reference);
    reference.reset_preconditioners();
    advance(&mut reference, 80);
    let mut resumed = space();
    checkpoint::restore(&mut resumed, &bytes).expect("restore");
    assert_eq!(checkpoint::encode(&resumed), bytes, "round trip");
    advance(&mut resumed, 80);
    assert_eq!(
        checkpoint::encode(&resumed),
        checkpoint::encode(&reference),
        "the continued state differs"
    );
    let plane = Simulation::new(poiseuille(2, 10, 1.0).setup().unwrap());
    let refused = checkpoint::restore(&mut resumed, &checkpoint::encode(&plane));
    assert!(refused.is_err());
}

/// Start-up Oldroyd-B flow in a circular pipe (`cases/pipe.toml`: Re = Wi = 1 on the radius,
/// β = 0.1) at 2R/δr = 12, t ≤ 2, against the Bessel series of `analysis::analytic::pipe`
/// read in the meridional plane (x, r): through the whole run loop (the 3D dispatch, the
/// meridional map, `profile.csv` with its z columns). Measured: time-mean streamwise L2 over
/// t = 0.25, 0.5, …, 2 of 5.18e-2 (the error of the start-up's elastic oscillation at this
/// resolution: the study of the validation pages takes it down at order 1.6–1.7 through
/// 2R/δr = 16 and 20), the fitted wall shear stress at t = 2 −2.127 against the series'
/// −2.077 (2.4 %), min det A 1. Bounds: L2 below 6.5e-2 (a quarter above the measured;
/// a 3D ingredient off by a factor, e.g. the kernel's normalisation, would be far above it),
/// the wall shear stress within 5 % (twice the measured), det A ≥ 1 − 1e-9 (Oldroyd-B).
#[test]
fn the_pipe_follows_its_bessel_series() {
    let text = std::fs::read_to_string("cases/pipe.toml").unwrap();
    let overrides = [
        "scene.resolution=12".to_string(),
        "run.end_time=2".to_string(),
        "run.output_interval=0.25".to_string(),
    ];
    let case = rheosph::setup::case::parse(&text, "pipe.toml", "pipe", &overrides).unwrap();
    assert_eq!(case.scene.dimension(), 3);
    let out = std::env::temp_dir().join("rheosph-pipe-test");
    let options = rheosph::app::run::RunOptions {
        out_dir: out.clone(),
        quiet: true,
        charts: None,
        snapshots: false,
        progress: None,
    };
    let summary = rheosph::app::run::run(&case, &options).unwrap();
    let e = &summary.errors;
    let (l2, tau_w, exact) = (
        e.l2_time_mean.unwrap(),
        e.wall_shear_stress.unwrap(),
        e.wall_shear_stress_exact.unwrap(),
    );
    let t = summary.t_reached;
    println!("2R/dr = 12, t <= 2: L2 mean {l2:.3e}; wall shear stress at t = {t} {tau_w:.4} vs {exact:.4}");
    assert_eq!(e.reference, Some("startup-pipe"));
    assert!(l2 < 6.5e-2, "L2 {l2:e}");
    assert!((tau_w / exact - 1.0).abs() < 0.05, "{tau_w} vs {exact}");
    let profile = std::fs::read_to_string(out.join("profile.csv")).unwrap();
    assert!(
        profile.starts_with("x,y,z,u,v,w,u_exact"),
        "{}",
        &profile[..80]
    );
}

/// Stokes flow through a simple cubic array of spheres (`cases/sphere-array.toml`: c = 0.125,
/// a/δr = 8.06, three shells, ⟨u⟩ held, Re = 0.01) through the run loop, to t = 0.1 (21
/// steps): the drag coefficient K = F/(6πη a⟨u⟩) of the last row against Zick & Homsy's
/// 4.292 (their Table 2). Measured: K = 4.2594 (−0.76 %; steady at 4.2575, −0.80 %, the
/// validation page). Bound: 2 %, which each variant the decision log records misses: the
/// incremental projection without the rotational form, whose pressure lags (K = 4.11 at
/// t = 0.15, −4.1 %), the lattice cut by the sphere instead of shells (−11.5 % at t = 0.15)
/// and the standard projection, whose tangential slip δt∂p/∂t at the sphere survives a
/// steady state (−35 %). The particles' volume must match the box less the sphere within 1 %
/// (the body force acts on it; measured +0.36 %), and ⟨u⟩ the held 1 within 1 %.
#[test]
fn a_cubic_array_of_spheres_has_zick_and_homsys_drag() {
    let case = common::shipped(
        "sphere-array.toml",
        &["run.end_time=0.1", "run.output_interval=0.05"],
    );
    let (summary, out) = common::run_quiet(&case, false);
    let rows = rheosph::app::io::read_series(&out.path().join("series.csv")).unwrap();
    let last = rows.last().unwrap();
    let sphere = &summary.probes["sphere"];
    let reference = sphere["drag_k_zick_homsy"].as_f64().unwrap();
    let deficit = sphere["volume_deficit"].as_f64().unwrap();
    let contour = sphere["drag_k_contour"][2].as_f64().unwrap();
    println!(
        "t = {}: K = {:.4} against {reference}, {contour:.4} on the control sphere a + 5δr; <u> = {:.5}; volume {deficit:+.2e}",
        last.t, last.drag_k, last.u_mean
    );
    assert_eq!(reference, 4.292);
    assert!(
        (last.drag_k / reference - 1.0).abs() < 0.02,
        "K {}",
        last.drag_k
    );
    assert!(deficit.abs() < 0.01, "volume {deficit}");
    assert!((last.u_mean - 1.0).abs() < 0.01, "<u> {}", last.u_mean);
}

/// A neutrally buoyant sphere free to turn between plates sliding at ∓V (Newtonian,
/// a/δr = 8, a box of 3a periodic along x and z, Re_p = 0.015) settles to a torque-free spin
/// about z. The same box run to t = 3 turns at 0.90339 of −γ̇/2 (the plates and the periodic
/// images 3a apart slow it; the validation pages' box test takes the box to 6a). By t = 0.45
/// (about 21 steps) the spin is within 0.2 % of it (measured 0.04 %) and the
/// torque below 0.2 % of the held sphere's 8πηa³γ̇/2 (measured 0.03 %); without the
/// rotational form of the projection, whose pressure settles over hundreds of steps, the
/// spin was 5.4 % off at t = 0.45 (0.952) and the torque 0.8 %. The spin stays in the plane
/// of shear.
#[test]
fn a_newtonian_sphere_in_shear_turns_torque_free() {
    let case = common::shipped(
        "sphere-in-shear.toml",
        &[
            "scene.length=3.0",
            "scene.height=3.0",
            "scene.depth=3.0",
            "scene.resolution=24",
            "scene.wall_velocity=[-1.5, 1.5]",
            "run.end_time=0.45",
            "run.output_interval=0.05",
        ],
    );
    let (summary, _out) = common::run_quiet(&case, false);
    let rotation = &summary.probes["rotation"];
    let spin: Vec<f64> = (0..3)
        .map(|a| rotation["final_spin"][a].as_f64().unwrap())
        .collect();
    let torque = rotation["final_torque"][2].as_f64().unwrap();
    let ratio = spin[2] / -0.5;
    let held = 8.0 * std::f64::consts::PI * 100.0 * 0.5;
    println!(
        "Ω = {spin:?}: Ω_z/(−γ̇/2) = {ratio:.5}; T_z = {torque:.4} ({:.2e} of the held sphere's)",
        torque / held
    );
    assert!((ratio / 0.90339 - 1.0).abs() < 0.002, "ratio {ratio}");
    assert!(torque.abs() < 0.002 * held, "torque {torque}");
    assert!(spin[0].abs().max(spin[1].abs()) < 1e-3 * 0.5, "{spin:?}");
}

/// The pipe wall's axial load (`analysis::tube_load`, which a sphere's drag in a tube is read
/// with) on the steady Poiseuille profile u = g(R² − r²)/(4ν) laid on the particles of
/// `cases/pipe.toml` (2R/δr = 12, a Newtonian fluid): the wall stress is ρgR/2 all round,
/// so the wall pulls the fluid back by ρgπR²L, which balances the drive. The surface fits
/// take the velocity quadratic with the wall's value imposed, exact on this profile, so
/// the bound is round-off (1e-6); a wrong normal, area or sign is off by a factor. With the
/// wall sliding at U the profile's shear, and the load, are the same.
#[test]
fn the_pipe_wall_holds_back_the_poiseuille_drive() {
    use rheosph::analysis::tube_load::{axial_load, PipeWall};
    let text = std::fs::read_to_string("cases/pipe.toml").unwrap();
    for velocity in [0.0, 1.0] {
        let overrides = [
            "scene.resolution=12".to_string(),
            "fluid.model=\"newtonian\"".to_string(),
            "fluid.relaxation_time=0".to_string(),
            "fluid.beta=1".to_string(),
            format!("scene.wall_velocity={velocity}"),
        ];
        let case = rheosph::setup::case::parse(&text, "pipe.toml", "pipe", &overrides).unwrap();
        let mut sim =
            rheosph::engine::step::Simulation::in_space(case.setup_in_space().unwrap()).unwrap();
        let (g, nu, radius, length) = (4.0, 1.0, 1.0, 2.0);
        for (u, p) in sim.state.velocity.iter_mut().zip(&sim.state.position) {
            let r2 = (p.y - radius).powi(2) + (p.z - radius).powi(2);
            u.x = velocity + g * (radius * radius - r2) / (4.0 * nu);
        }
        let wall = PipeWall {
            axis: [radius, radius],
            radius,
            velocity,
        };
        let load = axial_load(&sim, wall).expect("every fit holds");
        let exact = -g * std::f64::consts::PI * radius * radius * length;
        println!("U = {velocity}: W_x = {load:.8} against {exact:.8}");
        assert!((load / exact - 1.0).abs() < 1e-6, "{load} vs {exact}");
    }
}
