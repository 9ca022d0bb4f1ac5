//! A validated case, and the validation of the fluid, scheme and run tables into the
//! engine's types (the scene validates itself, see [`crate::setup::scenes`]).

use crate::engine::boundary::{TensorMirror, VelocityExtension, WallVelocityChoice};
use crate::engine::frame::Frame;
use crate::engine::free_surface::{ContactRows, SurfaceShear, SurfaceTensionForm};
use crate::engine::projection::Projection;
use crate::engine::rheology::models::Parameter;
use crate::engine::rheology::{Fluid, LawEntry, Model, Solvent, ViscosityLaw, LAWS, MODELS};
use crate::engine::scheme::{Method, Scheme};
use crate::engine::step::{FlowSetup, Scales, Setup};
use crate::setup::error::{field_err, in_range, positive, stage_err, FieldError};
use crate::setup::experimental::ExperimentalSpec;
use crate::setup::scenes::Scene;
use std::sync::Arc;

/// The criterion of `run.steady`: ⟨u⟩ varying by less than `tolerance` (relative) over
/// `window` time units, then averages over `average` time units (King & Lind: 2 % over 1,
/// then 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyCriterion {
    /// Largest (max − min)/|mean| of ⟨u⟩ over the window (default 0.02).
    pub tolerance: f64,
    /// The window over which the variation is measured (default 1).
    pub window: f64,
    /// The averaging time after steady state is reached (default 3).
    pub average: f64,
    /// What must be steady: the bulk velocity ⟨u⟩ under a constant force, the force when it
    /// holds ⟨u⟩ (`scene.mean_flow`).
    pub watch: SteadySignal,
}

/// The quantity of [`SteadyCriterion`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SteadySignal {
    BulkVelocity,
    BodyForce,
}

/// A validated case.
#[derive(Clone, Debug)]
pub struct Case {
    pub name: String,
    pub scene: Arc<dyn Scene>,
    pub fluid: Fluid,
    pub scheme: Scheme,
    pub end_time: f64,
    pub output_interval: f64,
    pub snapshot_interval: f64,
    pub checkpoint_interval: f64,
    /// Node spacing of grid snapshots; None: the particle spacing.
    pub grid_spacing: Option<f64>,
    pub steady: Option<SteadyCriterion>,
    /// The file as given (after overrides), echoed into the run summary.
    pub source: CaseFile,
}

impl Case {
    /// The one line that names the `[experimental]` variants the case sets (None: none).
    pub fn experimental_line(&self) -> Option<String> {
        let set = self.source.experimental.flagged();
        (!set.is_empty()).then(|| {
            format!(
                "experimental: {} (not a default-tier choice: see the decision log)",
                set.join(", ")
            )
        })
    }
}

impl Case {
    /// The engine's initial state for this case in the plane (refused for a scene written in
    /// space only, e.g. a pipe).
    pub fn setup(&self) -> Result<Setup, String> {
        self.scene.build(&self.fluid, &self.scheme, self.scales())
    }

    /// The case's scene in space ([`Scene::build_in_space`]).
    ///
    /// [`Scene::build_in_space`]: crate::setup::scenes::Scene::build_in_space
    pub fn setup_in_space(&self) -> Result<FlowSetup<3>, String> {
        self.scene
            .build_in_space(&self.fluid, &self.scheme, self.scales())
    }

    fn scales(&self) -> Scales {
        Scales {
            length: self.scene.length_scale(),
            velocity: self
                .scene
                .velocity_scale(&self.fluid)
                .max(f64::MIN_POSITIVE),
        }
    }
}
use crate::engine::boundary::WallModel;
use crate::engine::gravity::Gravity;
use crate::engine::kernel::H_OVER_DR;
use crate::engine::kinematics::{ConstitutiveGradient, GradientChoice};
use crate::engine::operators::{GradientOrder, LaplacianOrder, OperatorSettings};
use crate::engine::rheology::{ConformationIntegrator, ConformationScheme, IntegratorChoice};
use crate::engine::viscosity::{advective_limit, viscous_limit, Viscosity};
use crate::engine::weakly_compressible::sound_speed_for;
use crate::setup::schema::{
    CaseFile, FluidSpec, GravityChoice, MethodChoice, ProjectionChoice, RunSpec, SchemeSpec,
    ViscosityChoice,
};

/// What graded resolution (`scene.refine_walls`) needs of the scheme: particles that stay
/// where they are put, mirrors, and operators that take each row's own kernel (the
/// projection's; the weakly compressible scheme's density sums and the concentration source
/// do not).
fn graded_scheme(scheme: &Scheme) -> Result<(), FieldError> {
    let refuse = |what: &str| {
        Err(field_err(
            "scene.refine_walls",
            format!("graded resolution needs {what}"),
        ))
    };
    if scheme.frame != Frame::Eulerian {
        return refuse("fixed particles: scheme.frame = \"eulerian\"");
    }
    if scheme.method != Method::Projection {
        return refuse("the projection: scheme.method = \"isph\"");
    }
    if scheme.wall_model == WallModel::FixedGhost {
        return refuse("mirrors: scheme.walls.model = \"mirror\"");
    }
    if scheme.ppe.volume_relaxation > 0.0 || scheme.hourglass_control > 0.0 {
        return refuse(
            "experimental.volume_relaxation and scheme.conformation.hourglass_control at 0",
        );
    }
    // The first-order operators are exact for linear fields only: on the graded channel
    // (H/δr = 15, refine_walls = 4, Oldroyd-B) the steady parabola kept an L2 error of
    // 2.6e-4 with them, 1.4e-4 with the Laplacian alone of second order, 1.7e-6 with both
    // (9e-7 on the uniform lattice, whose symmetry makes the first order exact for it).
    if scheme.operators.gradient_order != GradientOrder::Second
        || scheme.operators.laplacian_order != LaplacianOrder::Second
    {
        return refuse(
            "operators exact for quadratic fields across the layers: scheme.operators.gradient = \"second\" and scheme.operators.laplacian = \"second\"",
        );
    }
    Ok(())
}

pub fn validate(raw: CaseFile, name: &str) -> Result<Case, FieldError> {
    let scene = raw.scene.validate()?;
    let fluid = fluid(&raw.fluid)?;
    if fluid.surface_tension > 0.0 && !scene.has_free_surface() {
        return Err(field_err(
            "fluid.surface_tension",
            "acts only on a free surface, and this scene has none (set 0 or omit it)",
        ));
    }
    raw.experimental.validate()?;
    let written = with_experimental(&raw.scheme, &raw.experimental);
    let scheme = scheme(&written, scene.as_ref(), &fluid)?;
    if scene.graded() {
        graded_scheme(&scheme)?;
    }
    if scene.has_corners() && written.walls.model == WallModel::FixedGhost {
        return Err(field_err(
            "scheme.walls.model",
            "this scene's corners and plates need mirrors: `fixed-ghost` has no lattice behind a corner yet",
        ));
    }
    if scene.pipe_wall().is_some() && written.walls.model == WallModel::FixedGhost {
        return Err(field_err(
            "scheme.walls.model",
            "a pipe's wall needs mirrors: `fixed-ghost` has no lattice behind a tube yet",
        ));
    }
    if scene.contact_angle().is_some() && fluid.surface_tension <= 0.0 {
        return Err(field_err(
            "scene.contact_angle",
            "a contact angle needs a surface tension (set fluid.surface_tension > 0)",
        ));
    }
    if scene.contact_angle().is_some() && scheme.free_surface.contact_rows == ContactRows::Wall {
        return Err(field_err(
            "experimental.contact_rows",
            "`wall` takes the contact-line particles off the surface's Dirichlet rows, through which a contact angle acts: use `surface` or `held` with scene.contact_angle",
        ));
    }
    if scheme.surface_tension.form == SurfaceTensionForm::Cohesion
        && scheme.method == Method::Projection
    {
        // validation pages, *Cohesion*: the projection's Dirichlet rows carry none of the cohesive
        // pressure, and a static drop's surface ring drifted out until it broke down.
        return Err(field_err(
            "scheme.surface_tension.form",
            "the cohesion force needs the weakly compressible scheme (scheme.method = \"wcsph\"): with the projection the drop's surface rows do not hold its cohesive pressure",
        ));
    }
    let own_wall_angle = scene
        .pool()
        .is_some_and(|p| p.wall_contact_angle != p.contact_angle);
    if own_wall_angle && scheme.surface_tension.form == SurfaceTensionForm::Cohesion {
        return Err(field_err(
            "scene.wall_contact_angle",
            "the cohesion force's wall attraction takes one contact angle at every wall: leave scene.wall_contact_angle out",
        ));
    }
    if scheme.free_surface.shear == SurfaceShear::ShearFree
        && !(scene.has_free_surface() && scheme.method == Method::Projection)
    {
        return Err(field_err(
            "experimental.surface_shear",
            "`shear-free` completes the viscous term of the projection's free-surface rows: it needs a free surface and scheme.method = \"isph\"",
        ));
    }
    let run = run(&raw.run, scene.as_ref(), fluid.relaxation_time)?;
    if scene.dimension() == 3 {
        in_space(&scheme, run.grid_spacing)?;
    }
    Ok(Case {
        name: name.to_string(),
        scene,
        fluid,
        scheme,
        end_time: run.end_time,
        output_interval: run.output_interval,
        snapshot_interval: run.snapshot_interval,
        checkpoint_interval: run.checkpoint_interval,
        grid_spacing: run.grid_spacing,
        steady: run.steady,
        source: raw,
    })
}

/// What a case in space (`scene.dimension = 3`) may not ask for: the scheme's 2D-only
/// settings ([`crate::engine::step::plane_only`]) and grid snapshots.
fn in_space(scheme: &Scheme, grid_spacing: Option<f64>) -> Result<(), FieldError> {
    let why = "is written for 2D scenes only (scene.dimension = 3)";
    if let Some(key) = crate::engine::step::plane_only(scheme) {
        let field = key.split(' ').next().unwrap_or(key);
        return Err(field_err(field, format!("`{key}` {why}")));
    }
    if grid_spacing.is_some() {
        return Err(field_err(
            "run.grid_spacing",
            format!("grid snapshots (.vti) {why}; the particles' .vtu are written"),
        ));
    }
    Ok(())
}

/// `scheme` with the `[experimental]` variants it sets put into their stages' tables.
fn with_experimental(written: &SchemeSpec, e: &ExperimentalSpec) -> SchemeSpec {
    let mut scheme = written.clone();
    fn set<T>(target: &mut T, value: Option<T>) {
        if let Some(v) = value {
            *target = v;
        }
    }
    set(&mut scheme.ppe.laplacian, e.ppe_laplacian);
    set(&mut scheme.ppe.volume_relaxation, e.volume_relaxation);
    set(
        &mut scheme.conformation.velocity_gradient,
        e.velocity_gradient,
    );
    set(&mut scheme.free_surface.gradient, e.surface_gradient);
    set(&mut scheme.free_surface.contact_rows, e.contact_rows);
    set(&mut scheme.free_surface.indicator, e.surface_indicator);
    set(&mut scheme.free_surface.shear, e.surface_shear);
    set(&mut scheme.wetting.curvature, e.contact_curvature);
    set(&mut scheme.wetting.angle_at, e.contact_angle_at);
    scheme
}

/// The model with its parameters, each checked against its range and refused where the model
/// has no such parameter; then the viscosity split and relaxation time the model needs.
fn fluid(f: &FluidSpec) -> Result<Fluid, FieldError> {
    let density = positive("fluid.density", f.density)?;
    let viscosity = positive("fluid.viscosity", f.viscosity)?;
    if let Some(law) = LawEntry::named(&f.model) {
        return generalised_newtonian(f, law, density, viscosity);
    }
    let entry = Model::named(&f.model).ok_or_else(|| {
        let names: Vec<String> = MODELS
            .iter()
            .map(|m| m.name)
            .chain(LAWS.iter().map(|l| l.name))
            .map(|name| format!("`{name}`"))
            .collect();
        field_err(
            "fluid.model",
            format!(
                "unknown model `{}`, expected one of {}",
                f.model,
                names.join(", ")
            ),
        )
    })?;
    let values = parameters(f, entry.name, entry.parameters)?;
    let model = (entry.build)(&values);
    let (beta, relaxation_time) = match entry.solvent {
        Solvent::All => {
            if f.relaxation_time.is_some_and(|l| l != 0.0) {
                return Err(field_err(
                    "fluid.relaxation_time",
                    "a Newtonian fluid has no relaxation time (omit it or set 0)",
                ));
            }
            if f.beta.is_some_and(|b| b != 1.0) {
                return Err(field_err(
                    "fluid.beta",
                    "a Newtonian fluid is all solvent: β must be 1 (or omitted)",
                ));
            }
            (1.0, 0.0)
        }
        Solvent::None | Solvent::Ratio => {
            let lambda = f.relaxation_time.ok_or_else(|| {
                field_err("fluid.relaxation_time", "required for a viscoelastic model")
            })?;
            let lambda = positive("fluid.relaxation_time", lambda)?;
            let beta = match (entry.solvent, f.beta) {
                (Solvent::None, Some(b)) if b != 0.0 => {
                    return Err(field_err(
                        "fluid.beta",
                        format!(
                            "{} has no solvent viscosity: β must be 0, got {b}",
                            entry.name.to_uppercase()
                        ),
                    ));
                }
                (Solvent::None, _) => 0.0,
                (_, None) => {
                    return Err(field_err(
                        "fluid.beta",
                        format!("required for {}", entry.name),
                    ))
                }
                (_, Some(b)) => in_range("fluid.beta", b, 0.0, 1.0)?,
            };
            (beta, lambda)
        }
    };
    Ok(Fluid {
        model,
        density,
        viscosity,
        beta,
        relaxation_time,
        surface_tension: surface_tension(f)?,
        law: ViscosityLaw::Constant,
    })
}

/// σ, 0 when omitted.
fn surface_tension(f: &FluidSpec) -> Result<f64, FieldError> {
    let sigma = f.surface_tension.unwrap_or(0.0);
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(field_err(
            "fluid.surface_tension",
            format!("must be a non-negative number, got {sigma}"),
        ));
    }
    Ok(sigma)
}

/// The values of a model's or a law's parameters, in their order, each checked; a key that is
/// not one of them is refused.
fn parameters(f: &FluidSpec, name: &str, expected: &[Parameter]) -> Result<Vec<f64>, FieldError> {
    if let Some(key) = f
        .parameters
        .keys()
        .find(|k| !expected.iter().any(|p| p.key == k.as_str()))
    {
        return Err(field_err(
            &format!("fluid.{key}"),
            format!("not a parameter of model `{name}`"),
        ));
    }
    let mut values = Vec::with_capacity(expected.len());
    for p in expected {
        let field = format!("fluid.{}", p.key);
        let v = f
            .parameters
            .get(p.key)
            .ok_or_else(|| field_err(&field, "required for this model"))?;
        values.push((p.check)(*v).map_err(|m| field_err(&field, m))?);
    }
    Ok(values)
}

/// A generalised Newtonian fluid: all solvent (β = 1, no relaxation time), η(γ̇) cut at
/// η0 = `fluid.viscosity`.
fn generalised_newtonian(
    f: &FluidSpec,
    law: &LawEntry,
    density: f64,
    viscosity: f64,
) -> Result<Fluid, FieldError> {
    if f.relaxation_time.is_some_and(|l| l != 0.0) {
        return Err(field_err(
            "fluid.relaxation_time",
            format!("a {} fluid has no relaxation time (omit it)", law.name),
        ));
    }
    if f.beta.is_some_and(|b| b != 1.0) {
        return Err(field_err(
            "fluid.beta",
            format!(
                "a {} fluid is all solvent: β must be 1 (or omitted)",
                law.name
            ),
        ));
    }
    let values = parameters(f, law.name, law.parameters)?;
    Ok(Fluid {
        model: Model::Newtonian,
        density,
        viscosity,
        beta: 1.0,
        relaxation_time: 0.0,
        surface_tension: surface_tension(f)?,
        law: (law.build)(&values),
    })
}

/// The Eulerian frame keeps its particles, which neither a free surface nor a moving disc allows.
fn frame_fits(s: &SchemeSpec, scene: &dyn Scene) -> Result<(), FieldError> {
    if scene.has_free_surface() && s.frame == Frame::Eulerian {
        return Err(field_err(
            "scheme.frame",
            "a free-surface flow needs moving particles: lagrangian",
        ));
    }
    if scene.moving_bodies() && s.frame == Frame::Eulerian {
        return Err(field_err(
            "scheme.frame",
            "a moving disc needs moving particles (the Eulerian frame keeps its neighbourhoods fixed): lagrangian",
        ));
    }
    Ok(())
}

/// `scheme.walls.velocity`'s `auto` ([`WallVelocityChoice::Auto`] says why); `open`: the
/// scene has a free surface.
fn wall_velocity(
    choice: WallVelocityChoice,
    scene: &dyn Scene,
    fluid: &Fluid,
    open: bool,
) -> VelocityExtension {
    match choice {
        WallVelocityChoice::Auto
            if open || scene.discs() > 0 || fluid.law != ViscosityLaw::Constant =>
        {
            VelocityExtension::Mirror
        }
        WallVelocityChoice::Auto | WallVelocityChoice::Quadratic => VelocityExtension::Quadratic,
        WallVelocityChoice::Mirror => VelocityExtension::Mirror,
    }
}

/// Past this ratio of the explicit step's advective to viscous limit, η0/(ρUh), Crank–Nicolson's
/// undamped stiff modes spoil the start-up: the Oldroyd-B channel (H/δr = 30, Wi = 1) had an L2
/// mean of 8.7 % at a ratio of 231 (backward Euler 0.37 %) and broke down at 2310; at 23–77
/// Crank–Nicolson was as accurate as the explicit scheme (validation pages).
const CRANK_NICOLSON_STIFFNESS: f64 = 100.0;

/// `scheme.viscosity`, its `auto` resolved ([`ViscosityChoice::Auto`] says why): the
/// explicit step's advective limit h/U at the scene's velocity scale against its viscous
/// limit ρh²/η0, both of (28).
fn viscosity(
    choice: ViscosityChoice,
    method: Method,
    scene: &dyn Scene,
    fluid: &Fluid,
) -> Viscosity {
    match choice {
        ViscosityChoice::Auto => {
            let h = H_OVER_DR * scene.spacing();
            let u = scene.velocity_scale(fluid);
            let stiffness = advective_limit(h, u) / viscous_limit(fluid, h);
            // Crank–Nicolson was measured on channels only; free surfaces and bodies keep
            // backward Euler, which every such shipped case was validated with.
            let channel = !scene.has_free_surface()
                && scene.cylinder().is_none()
                && scene.discs() == 0
                && scene.cavity().is_none();
            match method {
                Method::WeaklyCompressible(_) => Viscosity::Explicit,
                Method::Projection if stiffness <= 1.0 => Viscosity::Explicit,
                Method::Projection if channel && stiffness <= CRANK_NICOLSON_STIFFNESS => {
                    Viscosity::CrankNicolson
                }
                Method::Projection => Viscosity::Implicit,
            }
        }
        ViscosityChoice::Explicit => Viscosity::Explicit,
        ViscosityChoice::Implicit => Viscosity::Implicit,
        ViscosityChoice::CrankNicolson => Viscosity::CrankNicolson,
    }
}

/// `scheme.conformation.integrator`, its `auto` resolved ([`IntegratorChoice::Auto`] says
/// why).
fn conformation_integrator(
    s: &SchemeSpec,
    viscosity: Viscosity,
) -> Result<ConformationIntegrator, FieldError> {
    let log = s.conformation.form == ConformationScheme::Log;
    Ok(match s.conformation.integrator {
        IntegratorChoice::Auto if viscosity == Viscosity::CrankNicolson => {
            ConformationIntegrator::Strang
        }
        IntegratorChoice::Auto if s.frame == Frame::Eulerian && log => {
            ConformationIntegrator::Unsplit
        }
        IntegratorChoice::Auto | IntegratorChoice::Euler => ConformationIntegrator::Euler,
        IntegratorChoice::Strang => ConformationIntegrator::Strang,
        IntegratorChoice::Unsplit if log => ConformationIntegrator::Unsplit,
        IntegratorChoice::Unsplit => {
            return Err(field_err(
                "scheme.conformation.integrator",
                "`unsplit` is formed in Ψ = ln A: it needs scheme.conformation.form = \"log\"",
            ))
        }
    })
}

fn scheme(s: &SchemeSpec, scene: &dyn Scene, fluid: &Fluid) -> Result<Scheme, FieldError> {
    let open = scene.has_free_surface();
    let method = method(s, scene, fluid)?;
    let viscosity = viscosity(s.viscosity, method, scene, fluid);
    // 0 restores the stability rules (so `--set` can undo a case file's fixed step).
    let time_step = (s.time_step.validate()).map_err(|e| stage_err("scheme.time_step", e))?;
    frame_fits(s, scene)?;
    // Explicit: ν δt/h² = ξ × the elastic Courant number (engine::rheology::hourglass).
    (s.conformation.validate()).map_err(|e| stage_err("scheme.conformation", e))?;
    let viscous_tolerance = s.viscous_tolerance;
    if !(viscous_tolerance > 0.0 && viscous_tolerance <= 1e-2) {
        return Err(field_err(
            "scheme.viscous_tolerance",
            format!("must be in (0, 1e-2], got {viscous_tolerance}"),
        ));
    }
    (s.neighbours.validate()).map_err(|e| stage_err("scheme.neighbours", e))?;
    solver_numbers(s)?;
    Ok(Scheme {
        method,
        time_step,
        frame: s.frame,
        conformation: s.conformation.form,
        conformation_integrator: conformation_integrator(s, viscosity)?,
        constitutive_gradient: match s.conformation.velocity_gradient {
            // With free surfaces the traceless part is not taken: the coarse Oldroyd-B drop
            // (W/δr = 20, Re = 4, De = 1) lost a contact-line particle through the plate at
            // t* = 2.0 with it, and ran through without it (W/δr = 40: both run through).
            GradientChoice::Auto if open => ConstitutiveGradient::WallNormalEven,
            GradientChoice::Auto | GradientChoice::Solenoidal => ConstitutiveGradient::Solenoidal,
            GradientChoice::Raw => ConstitutiveGradient::Raw,
            GradientChoice::WallNormalEven => ConstitutiveGradient::WallNormalEven,
        },
        conformation_remap: s.conformation.remap.resolve(s.frame),
        shifting: s.shifting,
        evss_alpha: s.conformation.evss_alpha,
        hourglass_control: s.conformation.hourglass_control,
        dt_factor: s.time_step.factor,
        viscosity,
        projection: match s.projection {
            // The incremental projection only where the standard one's O(νδt/L²) splitting
            // error matters, in creeping flow past a body with implicit viscosity; elsewhere
            // the paper's. Free surfaces: with the incremental one an Oldroyd-B drop
            // (W/δr = 40) lost a contact-line particle through the plate at impact (t* = 0.54),
            // where the standard one runs on. Channels (∇p = 0 at steady state, no splitting
            // error): with the incremental one the channel broke down at Wi = 64, 85, 128
            // (Re = 1, β = 0.1, H/δr = 30) and UCM (α_V = 0.01) from Wi = 4, both at
            // δt c/h ≤ 1.9, where the standard one runs through. Discs are bodies too, and
            // the lid-driven cavity is creeping flow with ∇p ≠ 0 (Newtonian, Re = 0.01,
            // L/δr = 40: u on x = L/2 within 11.8 % of the Stokes flow with the standard
            // projection, 1.1 % with the incremental one at Re = 1). A sphere's array
            // (Re = 0.01, a/δr = 8): the standard projection's tangential slip δt∂p/∂t at the
            // sphere, which a steady state keeps, read K 35 % low (2.80 for 4.292).
            // A sphere (3D) takes the rotational form: the incremental projection's pressure
            // settled over hundreds of steps (the array at a/δr = 8: K still rising by 0.1 %
            // per 0.1 time units after 267 steps; in shear between plates 3a apart the spin
            // 2.7 % off at t = 1), the rotational one's in tens (K steady in 103 steps, the
            // spin within 0.03 % by t = 0.6). The plane's bodies keep the incremental form,
            // on which their validation was run.
            ProjectionChoice::Auto
                if viscosity.is_implicit() && !open && scene.sphere().is_some() =>
            {
                Projection::Rotational
            }
            ProjectionChoice::Auto
                if viscosity.is_implicit()
                    && !open
                    && (scene.cylinder().is_some()
                        || scene.discs() > 0
                        || scene.cavity().is_some()) =>
            {
                Projection::Incremental
            }
            ProjectionChoice::Auto | ProjectionChoice::Standard => Projection::Standard,
            ProjectionChoice::Incremental => Projection::Incremental,
            ProjectionChoice::Rotational => Projection::Rotational,
        },
        ppe: s.ppe,
        reorder: s.neighbours.reorder,
        neighbour_skin: s.neighbours.skin,
        viscous_tolerance,
        wall_conformation: s.walls.conformation.unwrap_or(if open {
            TensorMirror::Even
        } else {
            TensorMirror::Linear
        }),
        wall_model: s.walls.model,
        wall_velocity: wall_velocity(s.walls.velocity, scene, fluid, open),
        gravity: gravity(s, scene)?,
        operators: OperatorSettings {
            ppe_laplacian: s.ppe.laplacian,
            ..s.operators
        },
        free_surface: s.free_surface,
        surface_tension: s.surface_tension,
        wetting: s.wetting,
    })
}

/// `scheme.gravity`: `auto` is the reduced pressure in a pool, where a liquid rests on walls
/// (with g in the predictor a pool at rest swells and climbs its walls: validation pages, *Still
/// water*), and the paper's predictor elsewhere. `reduced-pressure` needs g·r single-valued
/// and fixed in time (see `engine::gravity`).
fn gravity(s: &SchemeSpec, scene: &dyn Scene) -> Result<Gravity, FieldError> {
    match s.gravity {
        GravityChoice::Predictor => return Ok(Gravity::Predictor),
        GravityChoice::Auto if scene.pool().is_none() || s.method != MethodChoice::Isph => {
            return Ok(Gravity::Predictor)
        }
        _ => {}
    }
    let why = if s.method != MethodChoice::Isph {
        Some("the weakly compressible scheme's pressure comes from its equation of state, which a reduced pressure would shift: use `predictor`")
    } else if scene.holds_mean_flow() || scene.discs() > 0 {
        Some("the body force here changes in time (mean-flow control or a disc's held return flow), and the reduced pressure needs a fixed one: use `predictor`")
    } else if (0..2).any(|a| scene.periodic()[a] && scene.body_force()[a] != 0.0) {
        Some("the body force has a component along a periodic axis, where g·r is not single-valued: use `predictor`")
    } else {
        None
    };
    match why {
        Some(why) => Err(field_err("scheme.gravity", why)),
        None => Ok(Gravity::ReducedPressure),
    }
}

/// The PPE's table: positive, in range.
fn solver_numbers(s: &SchemeSpec) -> Result<(), FieldError> {
    s.ppe.validate().map_err(|e| stage_err("scheme.ppe", e))
}

/// The time integrator and, for the weakly compressible one, its settings; what it cannot
/// combine with is refused here, naming the key.
fn method(s: &SchemeSpec, scene: &dyn Scene, fluid: &Fluid) -> Result<Method, FieldError> {
    if s.method == MethodChoice::Isph {
        return Ok(Method::Projection);
    }
    let refuse = |key: &str, why: &str| {
        Err(field_err(
            key,
            format!("with scheme.method = \"wcsph\": {why}"),
        ))
    };
    if s.frame == Frame::Eulerian {
        return refuse(
            "scheme.frame",
            "weakly compressible particles move with the flow: lagrangian",
        );
    }
    if s.conformation.evss_alpha != 0.0 {
        return refuse(
            "scheme.conformation.evss_alpha",
            "the polymer stress enters whole in the symmetric form, without EVSS (set 0)",
        );
    }
    if s.conformation.hourglass_control != 0.0 {
        return refuse(
            "scheme.conformation.hourglass_control",
            "it acts on the projection's nested stress divergence, which is not formed (set 0)",
        );
    }
    if fluid.surface_tension > 0.0 && s.surface_tension.form != SurfaceTensionForm::Cohesion {
        return refuse(
            "fluid.surface_tension",
            "its capillary jump enters the projection's free-surface pressure only (set scheme.surface_tension.form = \"cohesion\")",
        );
    }
    if matches!(
        s.projection,
        ProjectionChoice::Incremental | ProjectionChoice::Rotational
    ) {
        return refuse("scheme.projection", "there is no projection");
    }
    if s.ppe.volume_relaxation != 0.0 {
        return refuse("experimental.volume_relaxation", "there is no PPE (set 0)");
    }
    if s.free_surface.contact_rows == ContactRows::Wall {
        return refuse(
            "experimental.contact_rows",
            "there are no PPE rows to give the contact lines (`held` holds them off the wall)",
        );
    }
    let u = scene.velocity_scale(fluid);
    let length = scene.length_scale();
    let nu = fluid.viscosity / fluid.density;
    let modulus = if fluid.model.is_viscoelastic() && fluid.relaxation_time > 0.0 {
        fluid.polymer_viscosity() / (fluid.relaxation_time * fluid.density)
    } else {
        0.0
    };
    let g = scene.body_force().norm();
    let default_sound_speed = |mach| sound_speed_for(mach, u, nu, g, length, modulus);
    let scheme = s.wcsph.resolve(default_sound_speed);
    Ok(Method::WeaklyCompressible(
        scheme.map_err(|e| stage_err("scheme.wcsph", e))?,
    ))
}

/// The run's validated times.
struct Run {
    end_time: f64,
    output_interval: f64,
    snapshot_interval: f64,
    checkpoint_interval: f64,
    grid_spacing: Option<f64>,
    steady: Option<SteadyCriterion>,
}

/// The run settings; `relaxation_time` λ of the fluid (0: Newtonian) bounds the steady window
/// from below.
fn run(r: &RunSpec, scene: &dyn Scene, relaxation_time: f64) -> Result<Run, FieldError> {
    let end_time = positive("run.end_time", r.end_time)?;
    let interval = |field: &str, given: Option<f64>, parts: f64| match given {
        Some(dt) => positive(field, dt),
        None => Ok(end_time / parts),
    };
    let output_interval = interval("run.output_interval", r.output_interval, 300.0)?;
    let snapshot_interval = interval("run.snapshot_interval", r.snapshot_interval, 20.0)?;
    let checkpoint_interval = interval("run.checkpoint_interval", r.checkpoint_interval, 10.0)?;
    let grid_spacing = r
        .grid_spacing
        .map(|h| positive("run.grid_spacing", h))
        .transpose()?;
    let steady = match &r.steady {
        None => None,
        Some(st) => {
            if scene.cylinder().is_none() && scene.sphere().is_none() {
                return Err(field_err(
                    "run.steady",
                    "steady-state detection is for a channel with a cylinder or a sphere (the plain channel has an analytic reference)",
                ));
            }
            let tolerance = positive("run.steady.tolerance", st.tolerance)?;
            if tolerance >= 1.0 {
                return Err(field_err(
                    "run.steady.tolerance",
                    format!("a relative variation, must be below 1, got {tolerance}"),
                ));
            }
            Some(SteadyCriterion {
                tolerance,
                // A polymer drifts on its relaxation time: over a window shorter than λ a slow
                // approach passes a 2 % test long before the stress has developed (the array
                // at Wi = 8 with ⟨u⟩ held passed it at t = 1.45 with the body force still
                // rising). The window is at least λ.
                window: positive("run.steady.window", st.window)?.max(relaxation_time),
                average: positive("run.steady.average", st.average)?,
                watch: if scene.holds_mean_flow() {
                    SteadySignal::BodyForce
                } else {
                    SteadySignal::BulkVelocity
                },
            })
        }
    };
    Ok(Run {
        end_time,
        output_interval,
        snapshot_interval,
        checkpoint_interval,
        grid_spacing,
        steady,
    })
}
