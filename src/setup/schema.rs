//! The case file as written: `[scene]`, `[fluid]`, `[scheme]` and `[run]`. Read in two
//! passes (the scene's `kind` and the fluid's `model` first, then the table as that kind or
//! model has it), so that every error names its dotted field. Serialized back into the run
//! directory (`case.toml`) and the summary.

use crate::engine::boundary::{TensorMirror, WallModel, WallPressure};
use crate::engine::frame::Frame;
use crate::engine::free_surface::{
    CapillaryTimeLevel, ContactAngleAt, ContactCurvature, ContactRows, DetachedMomentum,
    SurfaceGradient, SurfaceIndicator, SurfacePressure, SurfaceShear, SurfaceTensionForm,
};
use crate::engine::operators::{GradientOrder, LaplacianOrder};
use crate::engine::rheology::{ConformationScheme, Remap};
use crate::engine::scheme::PpeSolver;
use crate::engine::viscosity::Viscosity;
use crate::setup::error::{field_err, read_table, FieldError};
use crate::setup::scenes::SceneSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize)]
pub struct CaseFile {
    pub scene: SceneSpec,
    pub fluid: FluidSpec,
    pub scheme: SchemeSpec,
    pub run: RunSpec,
}

/// The tables besides `[scene]` and `[fluid]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Rest {
    #[serde(default)]
    scheme: SchemeSpec,
    run: RunSpec,
}

impl CaseFile {
    /// Reads a parsed (and overridden) case table.
    pub fn from_table(mut table: toml::Table) -> Result<Self, FieldError> {
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
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FluidCommon {
    model: String,
    density: f64,
    viscosity: f64,
    beta: Option<f64>,
    relaxation_time: Option<f64>,
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
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ProjectionChoice {
    /// `incremental` with implicit viscosity past a body (a cylinder), `standard` otherwise.
    Auto,
    Standard,
    Incremental,
}

/// How no-slip walls extend the velocity to their ghosts.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum WallVelocityChoice {
    /// `quadratic` where the fluid fills the walls' neighbourhoods and its viscosity is
    /// constant; `mirror` in a scene with a free surface, whose contact line truncates the
    /// support the one-sided fit assumes full (the Oldroyd-B drop at W/δr = 20 broke down
    /// at impact with it, t = 0.027, and runs through with the mirror), and for a shear-rate
    /// dependent viscosity, where it measured worse and the cause is not found (H/δr = 15,
    /// final L2: Bingham 1.66 % against 0.79 %, power law n = 0.5 3.27 % against 2.20 %);
    /// and with moving discs, whose coupling's stiffening (`engine::bodies`) is derived for
    /// mirrors that carry 2u_w (a settling disc's Galilean check, `tests/discs.rs`: 3.5 %
    /// against 1.2 % with the mirror).
    Auto,
    Mirror,
    Quadratic,
}

/// Where a uniform body force enters (see [`crate::engine::gravity`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum GravityChoice {
    /// `reduced-pressure` in a pool (a liquid resting on walls), `predictor` elsewhere.
    Auto,
    Predictor,
    ReducedPressure,
}

/// BiCGStab's preconditioner.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum PreconditionerChoice {
    /// Jacobi, turning to AMG within a solve that Jacobi does not finish in 40 iterations
    /// (see the README's speed section).
    Auto,
    Jacobi,
    Amg,
}

/// The velocity gradient of the constitutive update (see
/// [`crate::engine::kinematics::ConstitutiveGradient`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum GradientChoice {
    /// `solenoidal` in closed domains, `wall-normal-even` with free surfaces.
    Auto,
    Raw,
    WallNormalEven,
    Solenoidal,
}

/// The conformation update's order in time (`scheme.conformation_integrator`).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorChoice {
    /// `strang` with Crank–Nicolson viscosity (a second-order step needs both), else
    /// `unsplit` in the Eulerian frame (whose flows are the steady ones, and a split update's
    /// steady state moves with δt/λ), `euler` otherwise (the paper's update, whose results
    /// are then unchanged).
    Auto,
    Euler,
    Strang,
    /// The whole rate in one linearly implicit step (log-conformation only).
    Unsplit,
}

/// The ALE remap of the conformation (`scheme.conformation_remap`; see
/// `engine::rheology::remap`).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum RemapChoice {
    /// `second-order` in the Eulerian frame (the remap is the whole transport, and the
    /// first-order increment's forward-Euler growth sets its step), `limited` otherwise.
    Auto,
    Limited,
    Central,
    Upwind,
    SecondOrder,
}

impl RemapChoice {
    /// The remap for `frame`.
    pub fn resolve(self, frame: Frame) -> Remap {
        match self {
            RemapChoice::Auto if frame == Frame::Eulerian => Remap::SecondOrder,
            RemapChoice::Auto | RemapChoice::Limited => Remap::Limited,
            RemapChoice::Central => Remap::Central,
            RemapChoice::Upwind => Remap::Upwind,
            RemapChoice::SecondOrder => Remap::SecondOrder,
        }
    }
}

/// The time integrator (`scheme.method`).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum MethodChoice {
    /// King & Lind's projection (incompressible SPH).
    Isph,
    /// Weakly compressible SPH (Fang et al. 2006; δ-SPH with `density_diffusion`).
    Wcsph,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SchemeSpec {
    /// `isph` (the projection, default) or `wcsph`.
    pub method: MethodChoice,
    /// WCSPH: the speed of sound c (default: from `mach`, see
    /// `engine::weakly_compressible::sound_speed_for`).
    pub sound_speed: Option<f64>,
    /// WCSPH: the Mach number the default c is chosen for (0.1: δρ/ρ ~ 1 %).
    pub mach: f64,
    /// WCSPH: Monaghan's artificial viscosity α_Π (Fang et al.: 1) and β_Π (Fang et al.: 2).
    pub artificial_viscosity: f64,
    pub artificial_viscosity_beta: f64,
    /// WCSPH: v0 of the shear-rate dependent artificial viscosity of Wróblewski et al.
    /// (2008, eq. (10)) (unset: Monaghan's).
    pub artificial_viscosity_velocity: Option<f64>,
    /// WCSPH: the artificial stress ε (0 = off; Fang et al.: 0.5 Oldroyd-B, 0.2 Newtonian)
    /// and its exponent n.
    pub artificial_stress: f64,
    pub artificial_stress_exponent: i32,
    /// WCSPH: δ of the δ-SPH density diffusion (0 = off; Antuono et al. 2010: 0.1).
    pub density_diffusion: f64,
    /// WCSPH: K of ρ0c² ≥ K τ_max, the speed of sound following the stretched polymer
    /// (0 = c fixed at `sound_speed`).
    pub sound_speed_stress_factor: f64,
    /// A fixed time step instead of the stability rules (either method).
    pub time_step: Option<f64>,
    pub frame: Frame,
    pub conformation: ConformationScheme,
    /// `auto`, `euler` (King & Lind, first order), `strang` (second order) or `unsplit`
    /// (first order, steady states independent of δt) conformation update.
    pub conformation_integrator: IntegratorChoice,
    /// The velocity gradient of the constitutive update: `auto`, `solenoidal`,
    /// `wall-normal-even` or `raw` (see `engine::kinematics`).
    pub constitutive_gradient: GradientChoice,
    /// The ALE remap u_ps·∇Ψ of the conformation: `auto` (default: `second-order` in the
    /// Eulerian frame, `limited` otherwise), `limited` (the central increment with the trace
    /// floor: det A ≥ 1), `central` (the paper's), `upwind`, or `second-order` (the limited
    /// increment with its Taylor series' second-order term; see `engine::rheology::remap`).
    pub conformation_remap: RemapChoice,
    /// Fickian shifting (with `wcsph` the density is then carried by the ALE term u_ps·∇ρ).
    /// On by default for both methods: without it the weakly compressible channel breaks
    /// down by t ≈ 1 (README); Fang et al.'s drop, which had none, sets it off.
    pub shifting: bool,
    /// α_V of the EVSS splitting, eqs. (6)–(8).
    pub evss_alpha: f64,
    /// ξ of the polymer stress's hourglass control (0 = off; see
    /// `engine::rheology::hourglass`).
    pub hourglass_control: f64,
    /// The factor 0.2 of the time-step rule (28).
    pub dt_factor: f64,
    /// `explicit` (the paper) or `implicit` solvent and EVSS viscosity.
    pub viscosity: Viscosity,
    /// Relative residual ‖b − Ap‖/‖b‖ at which BiCGStab stops.
    pub ppe_tolerance: f64,
    /// Or the r.m.s. divergence (in units of U/H) the residual corresponds to, whichever is
    /// reached first: ‖b − Ap‖ ≤ this · √n · (U/H)/δt. Default 1e-6 (see the README).
    pub ppe_divergence_tolerance: f64,
    /// BiCGStab iteration budget before the sparse-LU fallback.
    pub ppe_max_iterations: usize,
    /// α of the PPE's density-invariant source (0: off, the paper's projection): the
    /// fraction of a particle's concentration error the projection removes per step
    /// (`engine::volume`).
    pub volume_relaxation: f64,
    /// Start BiCGStab from the previous step's pressure (true) or from zero.
    pub ppe_warm_start: bool,
    /// `auto`, `bicgstab` or `lu`.
    pub ppe_solver: PpeSolver,
    /// BiCGStab's preconditioner (PPE and implicit viscosity): `auto`, `jacobi` or `amg`.
    pub preconditioner: PreconditionerChoice,
    /// Periodically sort particles along a Morton curve for memory locality.
    pub reorder: bool,
    /// Relative residual ‖b − Au‖/‖b‖ at which the implicit viscous solves stop.
    pub viscous_tolerance: f64,
    /// The Verlet skin of the neighbour search in units of δr (0: a cell search every
    /// step; unset: 0.5 when the particles move less than 1/16 of δr per step, else 0).
    /// Results do not depend on it, only the time per step.
    pub neighbour_skin: Option<f64>,
    /// How the conformation is carried onto wall mirrors; unset = `linear`, or `even` in a
    /// scene with a free surface, where the continuation is not validated (the weakly
    /// compressible drop of `cases/drop-fang.toml` without artificial stress then broke down
    /// by a particle leaving through the plate at the axis, not by the tension fracture that
    /// the even copy shows).
    pub wall_conformation: Option<TensorMirror>,
    /// `mirror` or `fixed-ghost`: how the particles behind plane walls are placed.
    pub wall_model: WallModel,
    /// `auto`, `mirror` (u_j = 2u_w − u_i, the paper's) or `quadratic` (the fluid's
    /// quadratic continuation through the wall velocity): the no-slip walls' ghost
    /// velocities; see `engine::boundary::VelocityExtension` and [`WallVelocityChoice`].
    pub wall_velocity: WallVelocityChoice,
    /// `neumann` (∂p/∂n = 0, the paper's) or `momentum` (∂p/∂n = n·(∇·Φ + ρg), see
    /// `engine::boundary::wall_pressure`): the pressure the wall ghosts carry.
    pub wall_pressure: WallPressure,
    /// `predictor` (g in the predictor (24), the paper's) or `reduced-pressure` (a uniform g
    /// absorbed into P = p − ρ g·r, exact for a liquid at rest; see `engine::gravity`);
    /// `auto` = `reduced-pressure` in a pool, `predictor` elsewhere.
    pub gravity: GravityChoice,
    /// `first` (Bonet–Lok, eq. (22)) or `second` (exact for quadratic fields, after Nasar et
    /// al. 2021): the corrected gradient of every first-derivative operator (the Laplacian
    /// keeps the first-order one).
    pub gradient_order: GradientOrder,
    /// `first` (Morris, eq. (21)) or `second` (exact for quadratic fields, after Nasar et al.
    /// 2021): the Laplacian of the PPE and the viscous term.
    pub laplacian_order: LaplacianOrder,
    /// `standard` (the Laplacian of `laplacian_order`) or `linear-exact` (that Laplacian made
    /// exact for linear fields where the support is truncated): the PPE's Laplacian.
    pub ppe_laplacian: crate::engine::operators::PpeLaplacian,
    /// `auto`, `standard` or `incremental` pressure projection.
    pub projection: ProjectionChoice,
    /// Free surfaces: `normal-stress` (35a) or `zero` Dirichlet pressure.
    pub free_surface_pressure: SurfacePressure,
    /// Free surfaces: `full` (the normal-stress pressure's ∇u* over the whole support, the
    /// paper's) or `own-side` (over the neighbours on the particle's own side of the surface;
    /// see `engine::free_surface::SurfaceGradient`).
    pub surface_gradient: SurfaceGradient,
    /// Free surfaces: `surface` (every surface particle a Dirichlet row, the paper's) or
    /// `wall` (a surface particle within δr/2 of a wall an interior row, held off the wall
    /// by the PPE; not with `scene.contact_angle`) or `held` (every surface particle a
    /// Dirichlet row, those within δr/4 of a wall held off it); see
    /// `engine::free_surface::ContactRows`.
    pub contact_line_rows: ContactRows,
    /// Free surfaces: the repulsive term of (42)–(44) in the shifting of internal particles
    /// (King & Lind: helpful for Re < 5).
    pub surface_repulsion: bool,
    /// `normal-stress` (the capillary jump σκ in the free-surface pressure) or `cohesion`
    /// (the pairwise force of Wróblewski et al. 2008).
    pub surface_tension: SurfaceTensionForm,
    /// `predicted` (r* of (23), damping a mode of frequency ω at ω²δt/4) or `midpoint`
    /// (rⁿ + (δt/2)uⁿ, no damping of a capillary mode from the step): where the capillary
    /// pressure's curvature is taken; see `engine::free_surface::tension`.
    pub capillary_time_level: CapillaryTimeLevel,
    /// `fit` (the contact particle's parabola over the real surface and its continuation
    /// beyond the wall) or `turn` (the circle leaving the wall at θ through its surface
    /// neighbours, which acts at any error of the angle); see
    /// `engine::free_surface::wetting`.
    pub contact_curvature: ContactCurvature,
    /// `centres` (the curve through the surface particles' centres meets the wall at θ) or
    /// `surface` (the surface half a spacing beyond them does, whose curvature the capillary
    /// pressure takes); see `engine::free_surface::wetting`.
    pub contact_angle_at: ContactAngleAt,
    /// Free surfaces: `sharp` ((36) decides, the paper's) or `blended` (a particle (36) has
    /// just taken into FS counts partly, rising to full weight a tenth of ⟨∇·r⟩ further in);
    /// see `engine::free_surface::SurfaceIndicator`.
    pub surface_indicator: SurfaceIndicator,
    /// `truncated` (the Laplacian of (21) as it is on a surface particle's truncated support,
    /// the paper's) or `shear-free` (plus the tangential flux of the shear-free condition,
    /// ∂u_t/∂n = −∂u_n/∂t); see `engine::free_surface::shear_free`.
    pub surface_shear: SurfaceShear,
    /// `conserved` (a body of liquid detached from the rest, from walls and from the inflow
    /// keeps its momentum and angular momentum: the step's net impulse and torque of the
    /// projection's pressure gradient removed) or `unconstrained` (the paper's); see
    /// `engine::free_surface::detached`.
    pub detached_momentum: DetachedMomentum,
}

impl Default for SchemeSpec {
    fn default() -> Self {
        Self {
            method: MethodChoice::Isph,
            sound_speed: None,
            mach: crate::engine::weakly_compressible::DEFAULT_MACH,
            artificial_viscosity: 0.0,
            artificial_viscosity_beta: 0.0,
            artificial_viscosity_velocity: None,
            artificial_stress: 0.0,
            artificial_stress_exponent: 4,
            density_diffusion: 0.0,
            sound_speed_stress_factor: 0.0,
            time_step: None,
            frame: Frame::Lagrangian,
            conformation: ConformationScheme::Log,
            conformation_integrator: IntegratorChoice::Auto,
            constitutive_gradient: GradientChoice::Auto,
            conformation_remap: RemapChoice::Auto,
            shifting: true,
            evss_alpha: 0.0,
            hourglass_control: 0.0,
            dt_factor: 0.2,
            viscosity: Viscosity::Explicit,
            ppe_tolerance: 1e-8,
            // Chosen by its effect on the L2 error: from 1e-10 to 1e-6 the time-mean velocity
            // error changes by < 1 % (relative) on Poiseuille (H/δr = 30, 11.6 → 0.27
            // BiCGStab iterations per step) and Taylor–Green (N = 50, 40 → 16); at 1e-3 the
            // Poiseuille error starts to grow (+0.5 %). Two decades of margin.
            ppe_divergence_tolerance: 1e-6,
            volume_relaxation: 0.0,
            ppe_max_iterations: 1000,
            ppe_warm_start: true,
            ppe_solver: PpeSolver::Auto,
            preconditioner: PreconditionerChoice::Auto,
            reorder: true,
            neighbour_skin: None,
            // Well below the O(δt) splitting error (README, *Speed*).
            viscous_tolerance: 1e-10,
            wall_conformation: None,
            wall_model: WallModel::Mirror,
            wall_velocity: WallVelocityChoice::Auto,
            wall_pressure: WallPressure::Neumann,
            gravity: GravityChoice::Auto,
            gradient_order: GradientOrder::First,
            laplacian_order: LaplacianOrder::First,
            ppe_laplacian: crate::engine::operators::PpeLaplacian::Standard,
            projection: ProjectionChoice::Auto,
            free_surface_pressure: SurfacePressure::NormalStress,
            surface_gradient: SurfaceGradient::Full,
            contact_line_rows: ContactRows::Surface,
            surface_repulsion: true,
            surface_tension: SurfaceTensionForm::NormalStress,
            capillary_time_level: CapillaryTimeLevel::Predicted,
            contact_curvature: ContactCurvature::Fit,
            contact_angle_at: ContactAngleAt::Centres,
            surface_indicator: SurfaceIndicator::Sharp,
            surface_shear: SurfaceShear::Truncated,
            detached_momentum: DetachedMomentum::Conserved,
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    pub end_time: f64,
    /// Time between rows of `series.csv` (default end_time/300).
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
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadySpec {
    #[serde(default = "default_steady_tolerance")]
    pub tolerance: f64,
    #[serde(default = "default_steady_window")]
    pub window: f64,
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
