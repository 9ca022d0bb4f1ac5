//! The case file as written: `[scene]`, `[fluid]`, `[scheme]` and `[run]`. Read in two
//! passes (the scene's `kind` and the fluid's `model` first, then the table as that kind or
//! model has it), so that every error names its dotted field. Serialized back into the run
//! directory (`case.toml`) and the summary.

use crate::engine::boundary::WallSettings;
use crate::engine::frame::Frame;
use crate::engine::free_surface::{FreeSurfaceSettings, SurfaceTensionSettings, WettingSettings};
use crate::engine::neighbourhood::NeighbourSettings;
use crate::engine::operators::OperatorSettings;
use crate::engine::pressure::PpeSettings;
use crate::engine::rheology::ConformationSettings;
use crate::engine::viscosity::TimeStepSettings;
use crate::engine::weakly_compressible::WcsphSettings;
use crate::setup::error::{field_err, read_table, FieldError};
use crate::setup::experimental::ExperimentalSpec;
use crate::setup::scenes::SceneSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize)]
pub struct CaseFile {
    pub scene: SceneSpec,
    pub fluid: FluidSpec,
    pub scheme: SchemeSpec,
    pub run: RunSpec,
    /// `[experimental]`: variants outside the scheme's tables (flagged when set).
    #[serde(skip_serializing_if = "ExperimentalSpec::is_empty")]
    pub experimental: ExperimentalSpec,
}

/// The tables besides `[scene]` and `[fluid]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Rest {
    #[serde(default)]
    scheme: SchemeSpec,
    run: RunSpec,
    #[serde(default)]
    experimental: ExperimentalSpec,
}

impl CaseFile {
    /// Reads a parsed (and overridden) case table.
    pub fn from_table(mut table: toml::Table) -> Result<Self, FieldError> {
        crate::setup::renamed::refuse_old_keys(&table)?;
        let mut take = |key: &str| match table.remove(key) {
            Some(toml::Value::Table(t)) => Ok(t),
            Some(_) => Err(field_err(key, "must be a table")),
            None => Err(field_err(key, format!("missing table [{key}]"))),
        };
        let (scene, fluid) = (take("scene"), take("fluid"));
        let fluid = FluidSpec::from_table(fluid?)?;
        let rest: Rest = read_table(toml::Value::Table(table), "")?;
        Ok(Self {
            scene: SceneSpec::from_table(scene?)?,
            fluid,
            scheme: rest.scheme,
            run: rest.run,
            experimental: rest.experimental,
        })
    }
}

/// `[fluid]`: the model by name, the viscosity split and relaxation time, and the model's own
/// parameters (L², ε, α …, see [`crate::engine::rheology::MODELS`]).
#[derive(Clone, Debug, Serialize)]
pub struct FluidSpec {
    pub model: String,
    /// ρ.
    pub density: f64,
    /// Total viscosity η0.
    pub viscosity: f64,
    /// η_s/η0 (viscoelastic models; UCM: 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    /// λ (viscoelastic models).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relaxation_time: Option<f64>,
    /// σ, surface tension (any model; default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_tension: Option<f64>,
    /// Every other key: a parameter of the model (checked against it in validation).
    #[serde(flatten)]
    pub parameters: BTreeMap<String, f64>,
}

/// The keys of `[fluid]` every model reads.
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub(crate) struct FluidCommon {
    /// The constitutive model or generalised Newtonian law by name (the tables below); its
    /// parameters are keys of `[fluid]` too.
    model: String,
    /// ρ.
    density: f64,
    /// The total zero-shear viscosity η0 = η_s + η_p; a generalised Newtonian law's cut, the
    /// largest viscosity it takes, which the explicit step limit (28) uses.
    viscosity: f64,
    /// η_s/η0 in [0, 1]: required by the viscoelastic models with a solvent (UCM: 0,
    /// Newtonian: 1).
    beta: Option<f64>,
    /// λ: required by the viscoelastic models.
    relaxation_time: Option<f64>,
    /// σ: the capillary jump σκ in the free-surface pressure, or a cohesion force
    /// (`scheme.surface_tension.form`); free-surface scenes only. Adds the capillary step
    /// limit 0.25√(ρh³/2πσ). Unset: 0.
    surface_tension: Option<f64>,
}

impl FluidSpec {
    fn from_table(mut table: toml::Table) -> Result<Self, FieldError> {
        const COMMON: [&str; 6] = [
            "model",
            "density",
            "viscosity",
            "beta",
            "relaxation_time",
            "surface_tension",
        ];
        let keys: Vec<String> = table
            .keys()
            .filter(|k| !COMMON.contains(&k.as_str()))
            .cloned()
            .collect();
        let mut parameters = BTreeMap::new();
        for key in keys {
            let value = match table.remove(&key) {
                Some(toml::Value::Float(v)) => v,
                Some(toml::Value::Integer(v)) => v as f64,
                _ => return Err(field_err(&format!("fluid.{key}"), "must be a number")),
            };
            parameters.insert(key, value);
        }
        let common: FluidCommon = read_table(toml::Value::Table(table), "fluid")?;
        Ok(Self {
            model: common.model,
            density: common.density,
            viscosity: common.viscosity,
            beta: common.beta,
            relaxation_time: common.relaxation_time,
            surface_tension: common.surface_tension,
            parameters,
        })
    }
}

/// How the projection treats the pressure of the previous step (see
/// [`crate::engine::projection`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ProjectionChoice {
    /// `rotational` with implicit viscosity past a sphere, `incremental` past the plane's
    /// bodies (a cylinder, discs) and in the cavity, `standard` otherwise.
    Auto,
    Standard,
    Incremental,
    /// The incremental projection in rotational form: its pressure settles in tens of steps
    /// where the incremental one's takes hundreds (creeping flow past a body).
    Rotational,
}

/// How the viscous term is integrated (see [`crate::engine::viscosity`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ViscosityChoice {
    /// By the ratio of the explicit step's advective to viscous limit, η0/(ρUh) at the
    /// scene's velocity scale U: `explicit` at or below 1 (the advective limit binds and a
    /// solve buys no larger step) and always with `wcsph` (the acoustic limit binds);
    /// `crank-nicolson` from 1 to 100 (channels at Re ~ 1: the explicit scheme's error at a
    /// fraction of its cost); `implicit` beyond 100 (creeping flow, where Crank–Nicolson's
    /// undamped stiff modes spoil the start-up).
    Auto,
    /// Explicit, as in King & Lind: δt ≤ 0.2ρh²/η0.
    Explicit,
    /// Backward Euler: δt set by the advective CFL and the elastic wave speed; damps the
    /// stiff modes (free surfaces, bodies, creeping flow).
    Implicit,
    /// Crank–Nicolson: half the term at u^n, half at u*; second order in δt with the Strang
    /// conformation update, δt as for `implicit`.
    CrankNicolson,
}

/// Where a uniform body force enters (see [`crate::engine::gravity`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum GravityChoice {
    /// `reduced-pressure` in a pool (a liquid resting on walls), `predictor` elsewhere.
    Auto,
    Predictor,
    ReducedPressure,
}

/// The time integrator (`scheme.method`).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum MethodChoice {
    /// King & Lind's projection (incompressible SPH).
    Isph,
    /// Weakly compressible SPH (Fang et al. 2006; δ-SPH with `density_diffusion`).
    Wcsph,
}

#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SchemeSpec {
    /// `isph` (the projection, default) or `wcsph`.
    pub method: MethodChoice,
    pub frame: Frame,
    /// Fickian shifting (with `wcsph` the density is then carried by the ALE term u_ps·∇ρ).
    /// On by default for both methods: without it the weakly compressible channel breaks
    /// down by t ≈ 1 (validation pages); Fang et al.'s drop, which had none, sets it off.
    pub shifting: bool,
    /// How the solvent and EVSS viscosity is integrated in time; `auto` takes the measured
    /// best for the scene, printed at start-up.
    pub viscosity: ViscosityChoice,
    /// Relative residual ‖b − Au‖/‖b‖ at which the implicit viscous solves stop.
    pub viscous_tolerance: f64,
    /// `predictor` (g in the predictor (24), the paper's) or `reduced-pressure` (a uniform g
    /// absorbed into P = p − ρ g·r, exact for a liquid at rest; see `engine::gravity`);
    /// `auto` = `reduced-pressure` in a pool, `predictor` elsewhere.
    pub gravity: GravityChoice,
    /// `auto`, `standard`, `incremental` or `rotational` pressure projection.
    pub projection: ProjectionChoice,
    /// `[scheme.time_step]`: the stability rules' factor, or a fixed step.
    pub time_step: TimeStepSettings,
    /// `[scheme.operators]`: the gradient's and the Laplacian's order.
    pub operators: OperatorSettings,
    /// `[scheme.neighbours]`: the neighbour search's skin and the particles' order in memory.
    pub neighbours: NeighbourSettings,
    /// `[scheme.conformation]`: the constitutive update.
    pub conformation: ConformationSettings,
    /// `[scheme.walls]`: the particles behind walls and the fields they carry.
    pub walls: WallSettings,
    /// `[scheme.ppe]`: the PPE's solver, its stopping rule and its Laplacian.
    pub ppe: PpeSettings,
    /// `[scheme.wcsph]`: the weakly compressible scheme's speed of sound, artificial
    /// viscosity and stress, and density diffusion.
    pub wcsph: WcsphSettings,
    /// `[scheme.free_surface]`: the free-surface condition and its rows.
    pub free_surface: FreeSurfaceSettings,
    /// `[scheme.surface_tension]`: how a surface tension acts.
    pub surface_tension: SurfaceTensionSettings,
    /// How a contact angle acts: both its choices are in `[experimental]`.
    #[serde(skip)]
    pub wetting: WettingSettings,
}

impl Default for SchemeSpec {
    fn default() -> Self {
        Self {
            method: MethodChoice::Isph,
            frame: Frame::Lagrangian,
            shifting: true,
            viscosity: ViscosityChoice::Auto,
            // Well below the O(δt) splitting error (validation pages, *Speed*).
            viscous_tolerance: 1e-10,
            gravity: GravityChoice::Auto,
            projection: ProjectionChoice::Auto,
            time_step: TimeStepSettings::default(),
            operators: OperatorSettings::default(),
            neighbours: NeighbourSettings::default(),
            conformation: ConformationSettings::default(),
            walls: WallSettings::default(),
            ppe: PpeSettings::default(),
            wcsph: WcsphSettings::default(),
            free_surface: FreeSurfaceSettings::default(),
            surface_tension: SurfaceTensionSettings::default(),
            wetting: WettingSettings::default(),
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// The time the run ends at (the case's units).
    pub end_time: f64,
    /// Time between rows of `series.csv` (default end_time/300): a row at the first step at
    /// or past each multiple.
    pub output_interval: Option<f64>,
    /// Time between `.vtu` snapshots (default end_time/20).
    pub snapshot_interval: Option<f64>,
    /// Time between checkpoints (`checkpoint.bin`, for `rheosph run --resume`; default
    /// end_time/10).
    pub checkpoint_interval: Option<f64>,
    /// Node spacing of the grid snapshots (`.vti`) written with every `.vtu` one (default: the
    /// particle spacing).
    pub grid_spacing: Option<f64>,
    /// Stop once steady, after averaging (channels with a cylinder).
    pub steady: Option<SteadySpec>,
}

/// `[run.steady]`: ⟨u⟩ (or, with the mean flow held, the body force) varying by less than
/// `tolerance` (relative) over `window` time units, but never fewer than the relaxation time
/// λ, then averages over `average` time units (King & Lind: 2 % over 1, then 3).
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SteadySpec {
    /// The relative variation of ⟨u⟩ (or of the held mean flow's body force) below which the
    /// flow counts as steady.
    #[serde(default = "default_steady_tolerance")]
    pub tolerance: f64,
    /// The time window over which the variation is measured (never shorter than λ).
    #[serde(default = "default_steady_window")]
    pub window: f64,
    /// The time over which the steady quantities are then averaged before the run stops.
    #[serde(default = "default_steady_average")]
    pub average: f64,
}

fn default_steady_tolerance() -> f64 {
    0.02
}
fn default_steady_window() -> f64 {
    1.0
}
fn default_steady_average() -> f64 {
    3.0
}
