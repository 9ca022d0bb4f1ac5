//! Scenes: the geometry, drive and initial state of a case. One file per scene kind holds its
//! `[scene]` table as written ([`SceneSpec`] variant), its validation, and the validated type
//! implementing [`Scene`], which builds the engine's [`Setup`] and names the scene's analytic
//! reference and the velocity its series tracks.
//!
//! To add a scene: a file here with the spec, the type and its `impl Scene`, and one variant
//! with its two match arms in [`SceneSpec`] below.

pub mod cavity;
pub mod channel;
pub mod discs;
pub mod drop;
pub mod graded;
pub mod jet;
pub mod pipe;
pub mod pool;
pub mod sphere;
pub mod taylor_green;

use crate::analysis::plane::PlaneMap;
use crate::analysis::reference::Reference;
use crate::analysis::tube_load::PipeWall;
use crate::engine::boundary::{Circle, Plane, Shape, Sphere, Wall};
use crate::engine::kernel::{H_OVER_DR, SUPPORT_OVER_H};
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::reduce::blocked_sum;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{FlowSetup, Scales, Setup};
use crate::setup::error::{field_err, in_range, positive, read_table, FieldError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;

/// The `[scene]` table as written, one type per `kind`.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum SceneSpec {
    /// Periodic channel between two no-slip walls at y = 0 and y = height, optionally with
    /// a cylinder (a periodic array of cylinders).
    Channel(channel::ChannelSpec),
    /// Taylor–Green vortex in a doubly periodic square box, no walls.
    TaylorGreen(taylor_green::TaylorGreenSpec),
    /// A free-surface drop falling onto a no-slip plate at y = 0 (King & Lind §IV C).
    Drop(drop::DropSpec),
    /// A jet fed through an orifice onto a no-slip plate at y = 0 (King & Lind §IV D).
    Jet(jet::JetSpec),
    /// The lid-driven square cavity (Fattal & Kupferman 2005).
    Cavity(cavity::CavitySpec),
    /// A pool in a tank, meeting its walls at a contact angle, with plates dipped into it
    /// (capillary rise).
    Pool(pool::PoolSpec),
    /// The inside of a circular pipe along x, periodic along x (3D only).
    Pipe(pipe::PipeSpec),
}

/// The kinds in case files, for the error that names them.
const KINDS: &str = "`channel`, `pipe`, `taylor-green`, `drop`, `jet`, `cavity` or `pool`";

impl SceneSpec {
    /// Reads the `[scene]` table: its `kind` first, then the table as that kind's spec, so
    /// that an unknown or misplaced key is named as `scene.<key>`.
    pub fn from_table(mut table: toml::Table) -> Result<Self, FieldError> {
        let dimension = table.get("dimension").cloned();
        let kind = match table.remove("kind") {
            Some(toml::Value::String(k)) => k,
            Some(_) => return Err(field_err("scene.kind", format!("must be one of {KINDS}"))),
            None => return Err(field_err("scene.kind", format!("missing: one of {KINDS}"))),
        };
        if kind != "channel" && kind != "pipe" {
            match dimension {
                None => {}
                Some(toml::Value::Integer(2)) => {
                    table.remove("dimension");
                }
                Some(_) => {
                    return Err(field_err(
                        "scene.dimension",
                        format!("scene.kind = \"{kind}\" is 2D only (`channel` and `pipe` are written in 3D)"),
                    ))
                }
            }
        }
        let value = toml::Value::Table(table);
        Ok(match kind.as_str() {
            "channel" => SceneSpec::Channel(read(value)?),
            "taylor-green" => SceneSpec::TaylorGreen(read(value)?),
            "drop" => SceneSpec::Drop(read(value)?),
            "jet" => SceneSpec::Jet(read(value)?),
            "cavity" => SceneSpec::Cavity(read(value)?),
            "pool" => SceneSpec::Pool(read(value)?),
            "pipe" => SceneSpec::Pipe(read(value)?),
            other => {
                return Err(field_err(
                    "scene.kind",
                    format!("unknown scene kind `{other}`, expected {KINDS}"),
                ))
            }
        })
    }

    /// Validates the spec into its scene.
    pub fn validate(&self) -> Result<Arc<dyn Scene>, FieldError> {
        Ok(match self {
            SceneSpec::Channel(s) => Arc::new(s.validate()?),
            SceneSpec::TaylorGreen(s) => Arc::new(s.validate()?),
            SceneSpec::Drop(s) => Arc::new(s.validate()?),
            SceneSpec::Jet(s) => Arc::new(s.validate()?),
            SceneSpec::Cavity(s) => Arc::new(s.validate()?),
            SceneSpec::Pool(s) => Arc::new(s.validate()?),
            SceneSpec::Pipe(s) => Arc::new(s.validate()?),
        })
    }
}

/// Deserializes one kind's table, errors naming `scene.<field>`.
fn read<T: for<'de> Deserialize<'de>>(value: toml::Value) -> Result<T, FieldError> {
    read_table(value, "scene")
}

/// The drop of a drop scene: its centre and diameter W, and the impact speed U.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DropShape {
    pub centre: Vec2,
    pub diameter: f64,
    pub speed: f64,
    /// Whether it falls onto a plate (false: a free drop).
    pub plate: bool,
}

/// The orifice of a jet scene: width D and height above the plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JetShape {
    pub width: f64,
    pub orifice_height: f64,
}

/// The box of a scene as written: x ∈ [0, length] (or [−length/2, length/2] for an open
/// scene), y ∈ [0, height], and the particles across the scene's resolved length (see
/// [`Scene::spacing`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBox {
    pub length: f64,
    pub height: f64,
    pub resolution: usize,
}

/// A validated scene.
pub trait Scene: fmt::Debug + Send + Sync {
    /// The `kind` naming it in case files.
    fn kind(&self) -> &'static str;
    fn bounds(&self) -> SceneBox;
    fn length(&self) -> f64 {
        self.bounds().length
    }
    fn height(&self) -> f64 {
        self.bounds().height
    }
    fn resolution(&self) -> usize {
        self.bounds().resolution
    }
    /// δr.
    fn spacing(&self) -> f64 {
        self.height() / self.resolution() as f64
    }
    /// The length L of Re = ρUL/η0 and Wi = λU/L.
    fn length_scale(&self) -> f64 {
        self.height()
    }
    /// The velocity scale U of Re and Wi.
    fn velocity_scale(&self, fluid: &Fluid) -> f64;
    /// Body force per unit mass.
    fn body_force(&self) -> Vec2;
    /// Initial particle count (a jet's grows).
    fn particles(&self) -> usize;
    /// Free surfaces: detection, Dirichlet pressure, free-surface shifting and stress
    /// divergence (the scene needs a moving frame).
    fn has_free_surface(&self) -> bool {
        false
    }
    /// The engine's initial state in the plane; refused, naming why, where the scene is
    /// written in space only.
    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String>;
    /// Space dimensions, `scene.dimension`: 2, or 3 where the scene is written in 3D.
    fn dimension(&self) -> usize {
        2
    }
    /// The scene in space (`scene.dimension = 3`), for [`Simulation::in_space`];
    /// refused, naming what is 2D only, where the scene is not written in 3D.
    ///
    /// [`Simulation::in_space`]: crate::engine::step::Simulation::in_space
    fn build_in_space(
        &self,
        _fluid: &Fluid,
        _scheme: &Scheme,
        _scales: Scales,
    ) -> Result<FlowSetup<3>, String> {
        Err(format!("scene.kind = \"{}\" is 2D only", self.kind()))
    }
    /// The plane its analytic reference and profiles read: (x, y), or a pipe's meridional
    /// plane (x, r).
    fn plane(&self) -> PlaneMap {
        PlaneMap::Cartesian
    }
    /// The analytic reference of the flow, or why there is none.
    fn reference(&self, fluid: &Fluid) -> Result<Reference, String>;
    /// The velocity `series.csv` tracks (`u_centre`) and its name for charts (title, axis).
    fn characteristic_velocity(&self, positions: &[Vec2], velocity: &[Vec2]) -> f64;
    fn characteristic_name(&self) -> (&'static str, &'static str);
    /// Whether the flow is along x and varies across y only (profiles are drawn against y).
    fn varies_across_height(&self) -> bool {
        false
    }
    /// Which axes (x, y) are periodic.
    fn periodic(&self) -> [bool; 2] {
        [false, false]
    }
    /// Whether the body force is adjusted to hold the bulk velocity.
    fn holds_mean_flow(&self) -> bool {
        false
    }
    /// A solid cylinder in the flow, whose drag and wake the run reports.
    fn cylinder(&self) -> Option<Circle> {
        None
    }
    /// A solid sphere in the flow (3D), whose drag (in a periodic box) or rotation and
    /// torque (between plates, or turning) the run reports.
    fn sphere(&self) -> Option<Sphere> {
        None
    }
    /// Whether the sphere turns (prescribed or free).
    fn sphere_turns(&self) -> bool {
        false
    }
    /// Whether its particles' resolution is graded along walls (`engine::resolution`).
    fn graded(&self) -> bool {
        false
    }
    /// How many rigid discs the scene holds (`[[scene.discs]]`).
    fn discs(&self) -> usize {
        0
    }
    /// Whether a disc moves or may move (its mirrors must follow the particles' frame).
    fn moving_bodies(&self) -> bool {
        false
    }
    /// The shear rate the walls impose, (u_top − u_bottom)/H, when they slide apart.
    fn wall_shear_rate(&self) -> Option<f64> {
        None
    }
    fn drop_shape(&self) -> Option<DropShape> {
        None
    }
    fn jet_shape(&self) -> Option<JetShape> {
        None
    }
    /// A lid-driven cavity: its lid speed U (the cavity probe's scale) and whether the lid
    /// is the regularised one (whose Stokes flow the probe compares with).
    fn cavity(&self) -> Option<(f64, bool)> {
        None
    }
    /// A pool with its walls and plates (the meniscus probe's geometry).
    fn pool(&self) -> Option<&pool::Pool> {
        None
    }
    /// Whether its walls meet in corners or include plates, which only mirrors handle (the
    /// fixed ghost lattice has none behind a corner yet).
    fn has_corners(&self) -> bool {
        false
    }
    /// The inside of a pipe, if a wall is one (only mirrors handle it: no fixed ghost
    /// lattice behind a tube yet).
    fn pipe_wall(&self) -> Option<PipeWall> {
        None
    }
    /// The static contact angle (radians) where the free surface meets a wall.
    fn contact_angle(&self) -> Option<f64> {
        None
    }
}

/// The kernel support in particle spacings (3h = 3.9δr).
pub(crate) fn support_in_dr() -> f64 {
    SUPPORT_OVER_H * H_OVER_DR
}

/// Checks of the box common to every scene: positive sizes and at least two kernel supports
/// across the height (mirrors of two walls must not meet).
pub(crate) fn check_box(length: f64, height: f64, resolution: usize) -> Result<(), FieldError> {
    positive("scene.length", length)?;
    positive("scene.height", height)?;
    let min_resolution = (2.0 * support_in_dr()).ceil() as usize;
    if resolution < min_resolution {
        return Err(field_err(
            "scene.resolution",
            format!(
                "must be at least {min_resolution} particles across the height (two kernel supports of {}δr), got {resolution}",
                support_in_dr()
            ),
        ));
    }
    Ok(())
}

/// A periodic box: a whole number of spacings `height/resolution` along x, and at least three
/// kernel supports (the neighbour search needs three cells of one support each). Returns
/// the number of columns.
pub(crate) fn check_periodic_length(
    length: f64,
    height: f64,
    resolution: usize,
) -> Result<usize, FieldError> {
    check_periodic_extent("scene.length", length, height, resolution)
}

/// [`check_periodic_length`] for the periodic extent `field`.
pub(crate) fn check_periodic_extent(
    field: &str,
    length: f64,
    height: f64,
    resolution: usize,
) -> Result<usize, FieldError> {
    let dr = height / resolution as f64;
    let columns = length / dr;
    if (columns - columns.round()).abs() > 1e-6 * columns {
        return Err(field_err(
            field,
            format!("must be a whole number of particle spacings height/resolution = {dr}, got {columns:.4} spacings"),
        ));
    }
    if columns.round() < (3.0 * support_in_dr()).ceil() {
        return Err(field_err(
            field,
            format!("the periodic length must hold three kernel supports ({:.0} spacings), got {columns:.0}", (3.0 * support_in_dr()).ceil()),
        ));
    }
    Ok(columns.round() as usize)
}

/// Heap bytes per particle measured by `rheosph bench` (3 285 at 64k particles, explicit
/// viscosity), rounded up for the implicit solver's second matrix.
pub const BYTES_PER_PARTICLE: f64 = 4000.0;
/// The same in 3D, where a particle has about 250 neighbours in its support against 44:
/// peak resident memory of an explicit channel run, 46 kB a particle at 10k and 50k
/// particles, rounded up.
pub const BYTES_PER_PARTICLE_3D: f64 = 48_000.0;

/// The heap estimate per particle in `dimension`.
pub fn bytes_per_particle(dimension: usize) -> f64 {
    if dimension == 3 {
        BYTES_PER_PARTICLE_3D
    } else {
        BYTES_PER_PARTICLE
    }
}
/// Largest estimated heap a case may ask for.
pub const MAX_MEMORY_BYTES: f64 = 16.0 * 1024.0 * 1024.0 * 1024.0;

/// The estimated heap of `particles` must fit in what this build allows.
pub(crate) fn check_memory(particles: f64) -> Result<(), FieldError> {
    check_memory_in(2, particles)
}

/// [`check_memory`] for particles in `dimension`.
pub(crate) fn check_memory_in(dimension: usize, particles: f64) -> Result<(), FieldError> {
    let each = bytes_per_particle(dimension);
    let memory = particles * each;
    if memory > MAX_MEMORY_BYTES {
        return Err(field_err(
            "scene.resolution",
            format!(
                "{particles:.3e} particles would need about {:.1} GiB (≈{each} bytes each), above the {} GiB this build allows",
                memory / 1024f64.powi(3),
                MAX_MEMORY_BYTES / 1024f64.powi(3)
            ),
        ));
    }
    Ok(())
}

/// The common checks and drive of an open scene (a drop or a jet): the box, gravity
/// (`scene.body_force`, default none) and the speed `scene.velocity` (≥ 0).
pub(crate) fn open_scene(
    bounds: SceneBox,
    body_force: Option<[f64; 2]>,
    velocity: Option<f64>,
) -> Result<(Vec2, f64), FieldError> {
    let SceneBox {
        length,
        height,
        resolution,
    } = bounds;
    check_box(length, height, resolution)?;
    check_memory(0.25 * std::f64::consts::PI * (resolution as f64).powi(2))?;
    let g = finite_force(body_force.unwrap_or([0.0, 0.0]))?;
    let u = velocity.ok_or_else(|| {
        field_err(
            "scene.velocity",
            "required for a drop (the impact speed U) or a jet (the inflow speed U0)",
        )
    })?;
    Ok((g, in_range("scene.velocity", u, 0.0, f64::MAX)?))
}

/// The open box of a drop or a jet, x ∈ [−length/2, length/2], y ∈ [0, height].
pub(crate) fn open_domain(length: f64, height: f64) -> Domain {
    Domain {
        min: Vec2::new(-0.5 * length, 0.0),
        max: Vec2::new(0.5 * length, height),
        periodic: [false, false],
    }
}

/// The no-slip plate y = 0 under a drop or a jet.
pub(crate) fn plate(scheme: &Scheme) -> Wall {
    Wall::no_slip(Shape::Plane(Plane::floor()), scheme.wall_conformation)
}

/// The centre-of-mass vertical velocity (the characteristic velocity of open scenes).
pub(crate) fn centre_of_mass_velocity(velocity: &[Vec2]) -> f64 {
    blocked_sum(velocity.len(), |i| velocity[i].y) / velocity.len() as f64
}

/// The body force of a scene that must be finite.
pub(crate) fn finite_force(g: [f64; 2]) -> Result<Vec2, FieldError> {
    if !(g[0].is_finite() && g[1].is_finite()) {
        return Err(field_err("scene.body_force", "must be finite"));
    }
    Ok(Vec2::new(g[0], g[1]))
}

/// A circle of `radius` about `centre` (fields `<field>.radius`, `<field>.centre`) checked to
/// lie in the channel `(length, height, resolution)`: at least two kernel supports in radius
/// (mirrors reach one support into it and must stay on their side of its centre), one
/// support from each wall, and fitting the periodic length.
pub(crate) fn circle_in_box(
    field: &str,
    radius: f64,
    centre: [f64; 2],
    bounds: SceneBox,
) -> Result<Circle, FieldError> {
    let SceneBox {
        length,
        height,
        resolution,
    } = bounds;
    let radius_field = format!("{field}.radius");
    let radius = positive(&radius_field, radius)?;
    let support = support_in_dr() * height / resolution as f64;
    if radius < 2.0 * support {
        return Err(field_err(
            &radius_field,
            format!(
                "must be at least two kernel supports ({:.4}) at this resolution, got {radius}",
                2.0 * support
            ),
        ));
    }
    let gap = (centre[1] - radius).min(height - centre[1] - radius);
    if !(centre[0].is_finite() && centre[1].is_finite())
        || gap < support
        || centre[0] < 0.0
        || centre[0] > length
    {
        return Err(field_err(
            &format!("{field}.centre"),
            format!("the circle must lie inside the box with at least one kernel support ({support:.4}) to each wall"),
        ));
    }
    if 2.0 * radius + 2.0 * support > length {
        return Err(field_err(
            &radius_field,
            "the circle does not fit in the periodic length",
        ));
    }
    Ok(Circle {
        centre: Vec2::new(centre[0], centre[1]),
        radius,
    })
}
