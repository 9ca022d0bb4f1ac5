//! `rheosph bench`: the cost of each stage of the step, side by side in one run, for several
//! sizes of the Poiseuille scene (explicit Oldroyd-B, Re = Wi = 1, β = 0.1).
//!
//! Each size starts from a developed Lagrangian state: the steady velocity and conformation,
//! particles displaced from the lattice by up to ±0.05δr (a deterministic pseudo-random
//! pattern), so that the PPE has a non-trivial right-hand side. Components are timed on that
//! state; the whole step is then timed over `steps` steps of the full scheme.

use crate::analysis::analytic::steady_channel::steady_shear_conformation;
use crate::engine::boundary::Ghosts;
use crate::engine::math::{Mat2, Sym2, Vec2};
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::{NeighbourList, NeighbourSearch};
use crate::engine::operators::{DivergenceForm, KernelSums};
use crate::engine::pressure::PressureSystem;
use crate::engine::step::Simulation;
use crate::setup::case::{self, Case};

use crate::app::table::{self, fmt};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// One row of the benchmark table and of `bench.csv` (times in milliseconds per call).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct BenchRow {
    pub particles: usize,
    pub resolution: usize,
    #[serde(serialize_with = "fmt::fixed4")]
    pub neighbours_ms: f64,
    /// The search for Verlet candidates within support + skin (`scheme.neighbours.skin`).
    #[serde(serialize_with = "fmt::fixed4")]
    pub skin_search_ms: f64,
    /// A step that reuses the candidates: mirrors moved, candidates filtered.
    #[serde(serialize_with = "fmt::fixed4")]
    pub skin_reuse_ms: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub kernel_sums_ms: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub operators_ms: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub ppe_assembly_ms: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub ppe_bicgstab_cold_ms: f64,
    #[serde(serialize_with = "fmt::fixed2")]
    pub ppe_bicgstab_cold_iterations: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub ppe_bicgstab_warm_ms: f64,
    #[serde(serialize_with = "fmt::fixed2")]
    pub ppe_bicgstab_warm_iterations: f64,
    /// Factorisation + solve every step (NaN when skipped above `lu_max`).
    #[serde(serialize_with = "fmt::fixed4")]
    pub ppe_lu_ms: f64,
    /// Solve with the factorisation cached, as an Eulerian run does (fixed particles).
    #[serde(serialize_with = "fmt::fixed4")]
    pub ppe_lu_cached_ms: f64,
    #[serde(serialize_with = "fmt::fixed4")]
    pub step_ms: f64,
    #[serde(serialize_with = "fmt::fixed1")]
    pub particle_steps_per_second: f64,
    #[serde(serialize_with = "fmt::fixed2")]
    pub ppe_iterations_per_step: f64,
    /// Heap bytes of the simulation (state and every per-step buffer) per particle.
    #[serde(serialize_with = "fmt::fixed0")]
    pub bytes_per_particle: f64,
}

pub(crate) fn time_ms<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let start = Instant::now();
    let mut out = f();
    for _ in 1..repeats {
        out = f();
    }
    (start.elapsed().as_secs_f64() * 1e3 / repeats as f64, out)
}

/// The Poiseuille case at `resolution` particles across.
pub(crate) fn case_at(resolution: usize) -> Result<Case> {
    let text = include_str!("../../cases/poiseuille.toml");
    case::parse(
        text,
        "cases/poiseuille.toml",
        "bench",
        &[format!("scene.resolution={resolution}")],
    )
    .map_err(|e| anyhow::anyhow!("{e}"))
}

/// Peak-to-peak displacement of the bench particles from the lattice, in δr: chosen so that
/// BiCGStab needs about the iterations of the real default run at H/δr = 30 (17.8 per step).
const JITTER: f64 = 0.02;

/// A developed, disordered state (see module docs).
pub(crate) fn developed(sim: &mut Simulation, case: &Case) -> Result<()> {
    let dr = sim.spacing;
    let f = case.fluid;
    let g = case.scene.body_force()[0];
    let height = case.scene.height();
    for (k, p) in sim.state.position.iter_mut().enumerate() {
        let jitter = |s: f64| ((k as f64 * s).fract() - 0.5) * JITTER * dr;
        p.x += jitter(0.754_877_666);
        p.y = (p.y + jitter(0.569_840_290)).clamp(0.2 * dr, height - 0.2 * dr);
        *p = sim.domain.wrap(*p);
    }
    let nu = f.viscosity / f.density;
    for (k, p) in sim.state.position.iter().enumerate() {
        let shear = g / nu * (0.5 * height - p.y);
        sim.state.velocity[k] = Vec2::new(0.5 * g / nu * p.y * (height - p.y), 0.0);
        let a = steady_shear_conformation(&f.model, f.relaxation_time * shear.abs())
            .map_err(anyhow::Error::msg)?;
        sim.state.conformation[k] = Sym2::new(a.xx, a.xy.copysign(shear), a.yy);
    }
    Ok(())
}

/// Per-step costs measured inside real steps.
struct Timed {
    heap_bytes: usize,
    step_ms: f64,
    solve_ms: f64,
    iterations: f64,
}

/// Steps run before timing: the synthetic developed state carries a pressure transient (the
/// jitter's divergence) that decays over the first tens of steps; a warm start from that
/// transient is worse than a cold one, which no real run sees.
const WARM_UP_STEPS: usize = 30;

/// Runs `steps` steps (after [`WARM_UP_STEPS`]) of the developed state with `overrides`.
fn timed_steps(resolution: usize, steps: usize, overrides: &[&str]) -> Result<Timed> {
    let mut o: Vec<String> = vec![format!("scene.resolution={resolution}")];
    o.extend(overrides.iter().map(|s| s.to_string()));
    let case = case::parse(
        include_str!("../../cases/poiseuille.toml"),
        "cases/poiseuille.toml",
        "bench",
        &o,
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut sim = Simulation::new(case.setup().map_err(anyhow::Error::msg)?);
    developed(&mut sim, &case)?;
    let step = |sim: &mut Simulation| {
        sim.step(f64::INFINITY)
            .map_err(|b| anyhow::anyhow!(b.reason))
    };
    for _ in 0..WARM_UP_STEPS {
        step(&mut sim)?;
    }
    let before = sim.timers.ppe_solve;
    let mut iterations = 0usize;
    let start = Instant::now();
    for _ in 0..steps {
        iterations += step(&mut sim)?.ppe.map_or(0, |r| r.iterations);
    }
    let seconds = start.elapsed().as_secs_f64();
    Ok(Timed {
        heap_bytes: sim.heap_bytes(),
        step_ms: seconds * 1e3 / steps as f64,
        solve_ms: (sim.timers.ppe_solve - before) * 1e3 / steps as f64,
        iterations: iterations as f64 / steps as f64,
    })
}

/// Benchmarks one size.
pub fn bench_size(target_particles: usize, steps: usize, lu_max: usize) -> Result<BenchRow> {
    let resolution = (target_particles as f64).sqrt().round().max(8.0) as usize;
    let case = case_at(resolution)?;
    let setup = case.setup().map_err(anyhow::Error::msg)?;
    let walls = setup.walls.clone();
    let mut sim = Simulation::new(setup);
    developed(&mut sim, &case)?;
    sim.reorder();
    let n = sim.particles();
    let kernel = sim.kernel;
    let repeats = (200_000 / n).clamp(2, 50);

    // Neighbour search: mirrors, cell lists, CSR lists; with a Verlet skin, the search for
    // candidates (mirrors within support + skin, rows sorted) and a step that reuses them
    // (mirrors moved, candidates filtered).
    let support = kernel.support();
    let reach = support + crate::engine::neighbourhood::SKIN * sim.spacing;
    let mut ghosts = Ghosts::new(walls);
    ghosts.domain = Some(sim.domain);
    let mut search = NeighbourSearch::new();
    let mut list = NeighbourList::default();
    let mut candidates = NeighbourList::default();
    let mut points = Vec::new();
    let (neighbours_ms, _) = time_ms(repeats, || {
        points.clear();
        points.extend_from_slice(&sim.state.position);
        ghosts.build(support, &mut points);
        search.build(&sim.domain, &points, n, support, &mut list);
    });
    let (skin_search_ms, _) = time_ms(repeats, || {
        points.truncate(n);
        ghosts.build(reach, &mut points);
        search.build_candidates(&sim.domain, &points, n, reach, &mut candidates);
    });
    let (skin_reuse_ms, _) = time_ms(repeats, || {
        points.truncate(n);
        ghosts.refresh(&mut points);
        search.filter(&candidates, &sim.domain, &points, support, &mut list);
    });
    let mut sums = KernelSums::default();
    let dv = sim.particle_volume();
    let (kernel_sums_ms, _) = time_ms(repeats, || sums.update(&list, &kernel, dv));

    // A representative set of operator sums: ∇u, ∇²u, ∇·Φ, ∇·u.
    let mut u_ext = Vec::new();
    ghosts.extend_velocity(&sim.state.velocity, &mut u_ext);
    let tau: Vec<Sym2> = sim.polymer_stress();
    let mut t_ext = Vec::new();
    ghosts.continue_tensor(&tau, &mut t_ext);
    let (mut grad, mut lap, mut div_t, mut div) = (
        vec![Mat2::zeros(); n],
        vec![Vec2::zeros(); n],
        vec![Vec2::zeros(); n],
        vec![0.0; n],
    );
    let (operators_ms, _) = time_ms(repeats, || {
        sums.gradient_vector(&list, &u_ext, &mut grad);
        sums.laplacian_vector(&list, &u_ext, &mut lap);
        sums.divergence_tensor(&list, &t_ext, DivergenceForm::Negative, &mut div_t);
        sums.divergence(&list, &u_ext, &mut div);
    });

    let mut ppe = PressureSystem::new();
    let (ppe_assembly_ms, _) = time_ms(repeats, || {
        ppe.assemble_matrix(
            Hood {
                list: &list,
                sums: &sums,
                ghosts: &ghosts,
            },
            case.fluid.density,
            &[],
        )
    });

    // The PPE solvers inside real steps of the same developed state.
    let warm = timed_steps(resolution, steps, &[])?;
    let cold = timed_steps(resolution, steps, &["scheme.ppe.warm_start=false"])?;
    let lu = if n <= lu_max {
        // A factorisation per step is expensive at large sizes: three steps suffice.
        Some(timed_steps(
            resolution,
            steps.min(3),
            &["scheme.ppe.solver=lu"],
        )?)
    } else {
        None
    };
    let eulerian = if n <= lu_max {
        Some(timed_steps(resolution, steps, &["scheme.frame=eulerian"])?)
    } else {
        None
    };
    Ok(BenchRow {
        particles: n,
        resolution,
        neighbours_ms,
        skin_search_ms,
        skin_reuse_ms,
        kernel_sums_ms,
        operators_ms,
        ppe_assembly_ms,
        ppe_bicgstab_cold_ms: cold.solve_ms,
        ppe_bicgstab_cold_iterations: cold.iterations,
        ppe_bicgstab_warm_ms: warm.solve_ms,
        ppe_bicgstab_warm_iterations: warm.iterations,
        ppe_lu_ms: lu.as_ref().map_or(f64::NAN, |t| t.solve_ms),
        ppe_lu_cached_ms: eulerian.as_ref().map_or(f64::NAN, |t| t.solve_ms),
        step_ms: warm.step_ms,
        particle_steps_per_second: 1e3 * n as f64 / warm.step_ms,
        ppe_iterations_per_step: warm.iterations,
        bytes_per_particle: warm.heap_bytes as f64 / n as f64,
    })
}

/// Runs the benchmark for every size, printing a table and writing `bench.csv` in `out`.
pub fn run(
    sizes: &[usize],
    steps: usize,
    lu_max: usize,
    out: &Path,
    quiet: bool,
) -> Result<Vec<BenchRow>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut rows = Vec::new();
    let mut table = String::new();
    let _ = writeln!(
        table,
        "{:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>14} {:>14} {:>9} {:>9} {:>9} {:>11} {:>7} {:>9}",
        "N",
        "neigh ms",
        "skin srch",
        "reuse",
        "kernel",
        "ops",
        "assembly",
        "cold ms (it)",
        "warm ms (it)",
        "LU ms",
        "LU cached",
        "step ms",
        "p-steps/s",
        "it/step",
        "B/part"
    );
    if !quiet {
        eprintln!(
            "rheosph bench: {} threads, {steps} steps per size",
            rayon::current_num_threads()
        );
        eprint!("{table}");
    }
    for &size in sizes {
        let r = bench_size(size, steps, lu_max)?;
        let line = format!(
            "{:>7} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>8.2} ({:>4.0}) {:>8.2} ({:>4.0}) {:>9.2} {:>9.3} {:>9.2} {:>11.0} {:>7.1} {:>9.0}\n",
            r.particles,
            r.neighbours_ms,
            r.skin_search_ms,
            r.skin_reuse_ms,
            r.kernel_sums_ms,
            r.operators_ms,
            r.ppe_assembly_ms,
            r.ppe_bicgstab_cold_ms,
            r.ppe_bicgstab_cold_iterations,
            r.ppe_bicgstab_warm_ms,
            r.ppe_bicgstab_warm_iterations,
            r.ppe_lu_ms,
            r.ppe_lu_cached_ms,
            r.step_ms,
            r.particle_steps_per_second,
            r.ppe_iterations_per_step,
            r.bytes_per_particle
        );
        if !quiet {
            eprint!("{line}");
        }
        table.push_str(&line);
        rows.push(r);
    }
    let csv = table::write_rows(&rows);
    crate::app::io::write_atomic(&out.join("bench.csv"), csv.as_bytes())?;
    crate::app::io::write_atomic(&out.join("bench.txt"), table.as_bytes())?;
    Ok(rows)
}
