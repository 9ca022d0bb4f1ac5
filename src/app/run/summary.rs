//! `summary.json`: how a run ended, what it cost (per stage), its errors against the analytic
//! reference, PPE statistics and what the probes report; and the lines a run prints at its
//! start and end.

use super::errors::Errors;
use crate::engine::timing::StageSeconds;
use crate::setup::case::{Case, Derived};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// How a run ended.
#[derive(Clone, Copy, Debug, Serialize, serde::Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    Finished,
    BrokeDown,
}

impl Outcome {
    /// As `summary.json` names it.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Finished => "finished",
            Outcome::BrokeDown => "broke_down",
        }
    }
}

#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct PpeSummary {
    pub mean_iterations: f64,
    pub max_iterations: usize,
    pub lu_fallbacks: u64,
    /// Solves by each method, and LU factorisations (a fixed-particle run factorises once).
    pub bicgstab_solves: u64,
    pub lu_solves: u64,
    pub lu_factorisations: usize,
    /// Largest relative residual ‖b − Ap‖/‖b‖ of any solve.
    pub max_relative_residual: f64,
    /// Solves that stopped on the divergence tolerance (`scheme.ppe.divergence_tolerance`) before
    /// reaching the relative tolerance; for these ‖b‖ is near round-off and the relative
    /// residual can be O(1) by design.
    pub absolute_floor_stops: u64,
    pub matrix_nonzeros: usize,
    /// Mean BiCGStab iterations per step of the implicit viscous solve (its components
    /// together; 0 with explicit viscosity).
    pub viscous_mean_iterations: f64,
}

/// `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub outcome: Outcome,
    pub reason: Option<String>,
    pub t_reached: f64,
    pub end_time: f64,
    pub particles: usize,
    pub steps: u64,
    pub wall_seconds: f64,
    pub particle_steps_per_second: f64,
    pub stage_seconds: StageSeconds,
    pub threads: usize,
    pub derived: Derived,
    pub errors: Errors,
    pub ppe: PpeSummary,
    /// The largest |ρ/ρ0 − 1| after any step: the weakly compressible scheme's compression
    /// (0 for the projection).
    pub max_density_deviation: f64,
    /// The largest speed of sound of a step (WCSPH, which raises it with the polymer stress
    /// by `scheme.wcsph.sound_speed_stress_factor`; 0 for the projection).
    pub max_sound_speed: f64,
    pub neighbour_pairs_per_particle: f64,
    /// Cell searches for neighbours (`scheme.neighbours.skin`: the other steps filter the
    /// last search's candidates).
    pub neighbour_searches: usize,
    /// What the probes report, by name: `steady` (channels with a cylinder: steady state,
    /// time averages, drag and centre-line values), `sphere` (a fixed sphere in 3D: steady
    /// state, drag against Zick & Homsy), `drop` (the largest width, the final shape, the
    /// area drift), `jet` (impact, buckling onset, folding frequency).
    #[serde(flatten)]
    pub probes: BTreeMap<&'static str, serde_json::Value>,
    pub version: &'static str,
    pub case: crate::setup::case::CaseFile,
}

/// What [`Summary::read`] takes from `summary.json`; the rest comes from the case.
#[derive(serde::Deserialize)]
struct Stored {
    outcome: Outcome,
    reason: Option<String>,
    t_reached: f64,
    end_time: f64,
    particles: usize,
    steps: u64,
    wall_seconds: f64,
    particle_steps_per_second: f64,
    stage_seconds: StageSeconds,
    threads: usize,
    errors: Errors,
    ppe: PpeSummary,
    max_density_deviation: f64,
    max_sound_speed: f64,
    neighbour_pairs_per_particle: f64,
    neighbour_searches: usize,
    #[serde(flatten)]
    rest: BTreeMap<String, serde_json::Value>,
}

impl Summary {
    /// The summary a finished run of `case` wrote (`summary.json`'s text), read back: the
    /// derived numbers and the case are `case`'s, the probes those `case` has.
    pub fn read(json: &str, case: &Case) -> Option<Self> {
        let s: Stored = serde_json::from_str(json).ok()?;
        let mut rest = s.rest;
        let probes = super::probes::names(case)
            .into_iter()
            .filter_map(|name| Some((name, rest.remove(name)?)))
            .collect();
        Some(Self {
            outcome: s.outcome,
            reason: s.reason,
            t_reached: s.t_reached,
            end_time: s.end_time,
            particles: s.particles,
            steps: s.steps,
            wall_seconds: s.wall_seconds,
            particle_steps_per_second: s.particle_steps_per_second,
            stage_seconds: s.stage_seconds,
            threads: s.threads,
            derived: case.derived(),
            errors: s.errors,
            ppe: s.ppe,
            max_density_deviation: s.max_density_deviation,
            max_sound_speed: s.max_sound_speed,
            neighbour_pairs_per_particle: s.neighbour_pairs_per_particle,
            neighbour_searches: s.neighbour_searches,
            probes,
            version: env!("CARGO_PKG_VERSION"),
            case: case.source.clone(),
        })
    }

    /// The steady-state entry of a run with a cylinder.
    pub fn steady(&self) -> Option<super::probes::steady::SteadySummary> {
        self.probes
            .get("steady")
            .and_then(|v| serde_json::from_value(v.clone()).ok())
    }
}

/// PPE statistics over a window of steps.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct PpeWindow {
    pub steps: u64,
    pub iterations: u64,
    pub max_iterations: usize,
    pub max_residual: f64,
    pub fallbacks: u64,
    pub floor_stops: u64,
    pub lu_solves: u64,
    /// The largest elastic Courant number δt c/h of a step.
    #[serde(default)]
    pub max_elastic_courant: f64,
    /// Implicit viscous BiCGStab iterations (both components).
    #[serde(default)]
    pub viscous_iterations: u64,
    /// The largest |ρ/ρ0 − 1| after a step (weakly compressible scheme; 0 for the projection).
    #[serde(default)]
    pub max_density_deviation: f64,
    /// Steps with a PPE solve (all of them for the projection, none for WCSPH).
    #[serde(default)]
    pub solves: u64,
    /// The largest speed of sound of a step (WCSPH; 0 for the projection).
    #[serde(default)]
    pub max_sound_speed: f64,
}

impl PpeWindow {
    pub fn add(&mut self, step: &crate::engine::step::StepReport) {
        self.max_elastic_courant = self.max_elastic_courant.max(step.elastic_courant);
        self.viscous_iterations += step.viscous_iterations as u64;
        self.steps += 1;
        self.max_density_deviation = self.max_density_deviation.max(step.density_deviation);
        self.max_sound_speed = self.max_sound_speed.max(step.sound_speed);
        let Some(r) = &step.ppe else {
            return;
        };
        self.solves += 1;
        self.iterations += r.iterations as u64;
        self.max_iterations = self.max_iterations.max(r.iterations);
        self.max_residual = self.max_residual.max(r.relative_residual);
        self.floor_stops += r.on_absolute_floor as u64;
        self.lu_solves += (r.method == rheosph_solver::Method::SparseLu) as u64;
        self.fallbacks += r.fell_back as u64;
    }

    pub fn mean_iterations(&self) -> f64 {
        if self.solves == 0 {
            0.0
        } else {
            self.iterations as f64 / self.solves as f64
        }
    }
}

pub fn progress_bar(quiet: bool, end_time: f64) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40.cyan/blue} {percent:>3}% {msg} of {prefix} [{elapsed_precise}, ETA {eta}]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_prefix(format!("{end_time}"));
    bar
}

pub fn report_start(case: &Case, d: &Derived) {
    let f = &case.fluid;
    eprintln!(
        "rheosph {}: case `{}`",
        env!("CARGO_PKG_VERSION"),
        case.name
    );
    eprintln!(
        "  scene {}, model {}{}  Re = {:.4}  Wi = {:.4}  El = {:.4}  beta = {}  evss_alpha = {}",
        case.scene.kind(),
        f.model_name(),
        (case.source.fluid.parameters.iter())
            .map(|(key, value)| format!(" {key} = {value}"))
            .collect::<String>(),
        d.reynolds,
        d.weissenberg,
        d.elasticity,
        d.beta,
        case.scheme.evss_alpha
    );
    eprintln!(
        "  {} particles (~{:.0} MB), dr = {:.4e}, h = {:.4e}; U = {:.4e}; dt limits: viscous {:.3e}, advective {:.3e}, elastic {:.3e}, capillary {:.3e}; ~{:.0} steps",
        d.particles, d.estimated_memory_bytes / 1e6, d.particle_spacing, d.smoothing_length, d.velocity_scale, d.dt_viscous, d.dt_advective_at_u, d.dt_elastic, d.dt_capillary, d.estimated_steps
    );
    if d.sound_speed > 0.0 {
        eprintln!(
            "  weakly compressible: c = {:.4e}, acoustic dt limit {:.3e}",
            d.sound_speed, d.dt_acoustic
        );
    }
    eprintln!(
        "  frame {:?}, conformation {:?} ({:?}), viscosity {:?}, shifting {}, {} threads",
        case.scheme.frame,
        case.scheme.conformation,
        case.scheme.conformation_integrator,
        case.scheme.viscosity,
        case.scheme.shifting,
        rayon::current_num_threads()
    );
    if let Some(line) = case.experimental_line() {
        eprintln!("  {line}");
    }
}

pub fn report_end(s: &Summary, dir: &Path) {
    match s.outcome {
        Outcome::Finished => {
            eprintln!("finished at t = {:.4} after {} steps", s.t_reached, s.steps)
        }
        Outcome::BrokeDown => eprintln!(
            "broke down at t = {:.4} after {} steps: {}",
            s.t_reached,
            s.steps,
            s.reason.as_deref().unwrap_or("?")
        ),
    }
    if let (Some(mean), Some(last)) = (s.errors.l2_time_mean, s.errors.l2_final) {
        eprintln!(
            "  velocity L2 error against {}: time mean {mean:.3e}, final {last:.3e}",
            s.errors.reference.unwrap_or("?")
        );
    }
    eprintln!(
        "  {:.0} particle-steps/s ({:.1} s wall, PPE {:.1} iterations/step)",
        s.particle_steps_per_second, s.wall_seconds, s.ppe.mean_iterations
    );
    eprintln!("  output in {}", dir.display());
}
