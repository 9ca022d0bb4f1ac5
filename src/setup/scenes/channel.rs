//! The periodic channel (King & Lind §IV A–B): no-slip walls at y = 0 and y = H, periodic in
//! x, driven by a body force along x and/or by the walls sliding along x (plane Couette
//! flow); with a cylinder, the periodic cylinder array.

use super::discs::{check_apart, ContactSpec, DiscPlan, DiscSpec};
use super::graded::GradedPlan;
use super::sphere::{self, SphereSpec, SphereTurning};
use super::{
    check_box, check_memory_in, check_periodic_extent, check_periodic_length, circle_in_box,
    finite_force, support_in_dr, Scene, SceneBox,
};
use crate::analysis::analytic::SteadyChannel;
use crate::analysis::diagnostics::centre_line_velocity;
use crate::analysis::reference::Reference;
use crate::engine::bodies::contact::Contact;
use crate::engine::bodies::sphere::TurningSphere;
use crate::engine::boundary::{Circle, Plane, Shape, Sphere, Wall};
use crate::engine::dimension::Vector;
use crate::engine::drive::Drive;
use crate::engine::lattice::lattice;
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::resolution::Resolution;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{FlowSetup, Scales, Setup};
use crate::setup::error::{field_err, positive, FieldError};
use serde::{Deserialize, Serialize};

/// `[scene]` of `kind = "channel"`: plates at y = 0 and H, periodic along x; with sliding
/// walls start-up Couette flow (`cases/couette.toml`), with a cylinder the confined cylinder or
/// an array, with discs suspended rigid bodies.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ChannelSpec {
    /// Periodic length along x.
    pub length: f64,
    /// Distance between the walls, H.
    pub height: f64,
    /// Particles across the height, H/δr (at least 8).
    pub resolution: usize,
    /// Body force per unit mass g (along x): required unless the walls slide or
    /// `mean_flow` sets it.
    pub body_force: Option<[f64; 2]>,
    /// With a cylinder, or a sphere in a periodic box: the nominal mean velocity ⟨u⟩ defining
    /// Re and Wi.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<f64>,
    /// A solid cylinder in the channel (periodic array of cylinders).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cylinder: Option<CylinderSpec>,
    /// In 3D, a fixed solid sphere; with `walls = false` the cell of a simple cubic array of
    /// spheres (Zick & Homsy 1982).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sphere: Option<Box<SphereSpec>>,
    /// Hold the bulk velocity ⟨u⟩ = Q/H at this value by adjusting the body force every step
    /// (`body_force` is then the initial guess; see `engine::drive`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_flow: Option<f64>,
    /// The walls' velocities along x, [bottom (y = 0), top (y = H)]: plane Couette flow.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_velocity: Option<[f64; 2]>,
    /// Rigid discs in the flow (`[[scene.discs]]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub discs: Vec<DiscSpec>,
    /// The discs' short-range repulsion (`[scene.contact]`; none by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSpec>,
    /// Gravity g_s for sedimentation: it pulls the discs' buoyant mass (ρ_s − ρ_f)πR², the
    /// fluid's weight being balanced by a hydrostatic pressure left out of the solve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 2]>,
    /// The plates at y = 0 and H (true, the default); false: periodic in y as well, with a
    /// cylinder a square array of cylinders, whose drag has a series solution
    /// (`engine::bodies` has no wall to share the load with), with a sphere (3D) a simple
    /// cubic array of spheres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walls: Option<bool>,
    /// Space dimensions: 2 (the default) or 3, the channel periodic along z as well.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dimension: Option<usize>,
    /// In 3D, the periodic extent along z (default: three kernel supports, 12δr, the least
    /// a periodic axis takes; the flow does not vary along z).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<f64>,
    /// Graded resolution (fixed particles): the spacing at the plates and the cylinder is
    /// δr/`refine_walls`, growing by a quarter a layer to δr (1, the default: uniform; see
    /// `engine::resolution`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refine_walls: Option<f64>,
}

/// `[scene.cylinder]`.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpec {
    /// R: mirrors are reflected across the circle, with volume ratios.
    pub radius: f64,
    /// Centre (default: the centre of the box).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre: Option<[f64; 2]>,
    /// Layers of particles laid on circles around the cylinder, the lattice kept beyond them
    /// (0, the default: the lattice alone, cut by the cylinder). See [`Channel::positions`].
    #[serde(default)]
    pub rings: usize,
}

/// A validated channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub bounds: SceneBox,
    columns: usize,
    /// g = (g_x, 0).
    pub body_force: Vec2,
    /// The nominal mean velocity (with a cylinder; 0 without, where U follows from g).
    pub velocity: f64,
    pub cylinder: Option<Circle>,
    /// A sphere (3D).
    pub sphere: Option<Sphere>,
    /// How it turns (None: fixed).
    pub turning: Option<SphereTurning>,
    /// Layers of particles on spherical shells around the sphere.
    shells: usize,
    /// Layers of particles on circles around the cylinder.
    pub rings: usize,
    /// The bulk velocity the body force holds (None: a constant force).
    pub mean_flow: Option<f64>,
    /// Wall velocities along x at y = 0 and y = H.
    pub wall_velocity: [f64; 2],
    pub discs: Vec<DiscPlan>,
    pub contact: Option<Contact>,
    /// g_s on the discs' buoyant mass.
    pub gravity: Vec2,
    /// Plates at y = 0 and H; false: periodic in y.
    pub walls: bool,
    /// The walls' spacing is δr/`refine` (1: uniform).
    pub refine: f64,
    /// 2 or 3.
    pub dimension: usize,
    /// In 3D, the periodic extent along z and the particle layers across it (0 in 2D).
    pub depth: f64,
    layers: usize,
}

impl ChannelSpec {
    pub fn validate(&self) -> Result<Channel, FieldError> {
        check_box(self.length, self.height, self.resolution)?;
        let columns = check_periodic_length(self.length, self.height, self.resolution)?;
        let (dimension, depth, layers) = self.validate_depth()?;
        check_memory_in(
            dimension,
            (columns * self.resolution * layers.max(1)) as f64,
        )?;
        let wall_velocity = self.wall_velocity.unwrap_or([0.0, 0.0]);
        if !wall_velocity.iter().all(|v| v.is_finite()) {
            return Err(field_err("scene.wall_velocity", "must be finite"));
        }
        // What else can drive the flow: sliding walls, or discs settling under gravity.
        let driven = wall_velocity != [0.0, 0.0] || self.gravity.is_some();
        let g = match (self.body_force, driven) {
            (Some(g), _) => g,
            (None, true) => [0.0, 0.0],
            (None, false) => {
                return Err(field_err(
                    "scene.body_force",
                    "required for a channel (or scene.wall_velocity for Couette flow, scene.gravity for sedimentation)",
                ))
            }
        };
        let body_force = finite_force(g)?;
        if g[1] != 0.0 {
            return Err(field_err(
                "scene.body_force",
                "a channel is driven along x: the y component must be 0",
            ));
        }
        let walls = self.validate_walls(wall_velocity)?;
        let velocity = self.validate_velocity(walls)?;
        let cylinder = match &self.cylinder {
            None => None,
            Some(cy) => Some(cy.validate(self.length, self.height, self.resolution)?),
        };
        let rings = match (&self.cylinder, cylinder) {
            (Some(spec), Some(c)) if walls => {
                spec.validate_rings(&c, self.height, self.resolution)?
            }
            (Some(spec), Some(_)) => spec.rings,
            _ => 0,
        };
        let mean_flow = match self.mean_flow {
            None => None,
            Some(_) if g[0] <= 0.0 => {
                return Err(field_err(
                    "scene.body_force",
                    "with scene.mean_flow the force is the controller's initial guess: positive along x",
                ))
            }
            Some(u) => Some(positive("scene.mean_flow", u)?),
        };
        let bounds = SceneBox {
            length: self.length,
            height: self.height,
            resolution: self.resolution,
        };
        let discs = self
            .discs
            .iter()
            .enumerate()
            .map(|(k, d)| d.validate(k, bounds))
            .collect::<Result<Vec<_>, _>>()?;
        let support = support_in_dr() * self.height / self.resolution as f64;
        check_apart(&discs, cylinder, support)?;
        let contact = self
            .contact
            .as_ref()
            .map(|c| c.validate(support, &discs))
            .transpose()?;
        let gravity = self.validate_gravity()?;
        let refine = self.validate_refinement(walls, cylinder, rings)?;
        let sphere = match dimension {
            3 => self.validate_in_space(walls, depth)?,
            _ => None,
        };
        let shells = self.sphere.as_ref().map_or(0, |s| s.shells());
        let turning = match &self.sphere {
            Some(spec) => spec.turning()?,
            None => None,
        };
        Ok(Channel {
            bounds,
            columns,
            body_force,
            velocity,
            cylinder,
            sphere,
            shells,
            turning,
            rings,
            mean_flow,
            wall_velocity,
            discs,
            contact,
            gravity,
            walls,
            refine,
            dimension,
            depth,
            layers,
        })
    }

    /// `scene.velocity`: the nominal mean velocity with a cylinder or a sphere in a periodic
    /// box, refused otherwise (a channel's scale follows from its force or its plates).
    fn validate_velocity(&self, walls: bool) -> Result<f64, FieldError> {
        // A sphere between plates is sheared by them: its scale is theirs, as a disc's is.
        let body = self.cylinder.is_some() || (self.sphere.is_some() && !walls);
        match (body, self.velocity) {
            (false, Some(_)) => {
                Err(field_err(
                    "scene.velocity",
                    "a plain channel's velocity scale follows from scene.body_force (or the plates' speed); scene.velocity is for taylor-green or a periodic box with a cylinder or a sphere",
                ))
            }
            (true, None) => {
                Err(field_err(
                    "scene.velocity",
                    "required with a cylinder or a sphere in a periodic box: the nominal mean velocity that defines Re and Wi",
                ))
            }
            (true, Some(u)) => positive("scene.velocity", u),
            (false, None) => Ok(0.0),
        }
    }

    /// `scene.dimension` (2 or 3) and, in 3D, `scene.depth` and its particle layers.
    fn validate_depth(&self) -> Result<(usize, f64, usize), FieldError> {
        let dimension = self.dimension.unwrap_or(2);
        match (dimension, self.depth) {
            (2, _) if self.sphere.is_some() => Err(field_err(
                "scene.sphere",
                "is written for 3D scenes only: set scene.dimension = 3 (in the plane, [scene.cylinder])",
            )),
            (2, None) => Ok((2, 0.0, 0)),
            (2, Some(_)) => Err(field_err(
                "scene.depth",
                "the extent along z applies in 3D: set scene.dimension = 3 or leave it out",
            )),
            (3, depth) => {
                let dr = self.height / self.resolution as f64;
                let least = (3.0 * support_in_dr()).ceil() * dr;
                let depth = depth.unwrap_or(least);
                let layers =
                    check_periodic_extent("scene.depth", depth, self.height, self.resolution)?;
                Ok((3, depth, layers))
            }
            (other, _) => Err(field_err(
                "scene.dimension",
                format!("must be 2 or 3, got {other}"),
            )),
        }
    }

    /// What a channel in space does not have yet (cylinders, discs, sedimentation and graded
    /// resolution are 2D); and the sphere, if any.
    fn validate_in_space(&self, walls: bool, depth: f64) -> Result<Option<Sphere>, FieldError> {
        let refused = [
            (self.cylinder.is_some(), "scene.cylinder"),
            (!self.discs.is_empty(), "scene.discs"),
            (self.gravity.is_some(), "scene.gravity"),
            (
                self.refine_walls.is_some_and(|r| r > 1.0),
                "scene.refine_walls",
            ),
        ];
        if let Some((_, key)) = refused.iter().find(|(r, _)| *r) {
            return Err(field_err(
                key,
                "is written for 2D scenes only (scene.dimension = 3)",
            ));
        }
        let Some(spec) = &self.sphere else {
            return Ok(None);
        };
        let domain = Domain {
            min: Vector::<3>::zeros(),
            max: Vector::<3>::new(self.length, self.height, depth),
            periodic: [true, !walls, true],
        };
        spec.validate(&domain, self.height / self.resolution as f64)
            .map(Some)
    }

    /// `scene.refine_walls`: at least 1, no discs (they move), and the plates' and the
    /// cylinder's layers clear of each other by a row of δr.
    fn validate_refinement(
        &self,
        walls: bool,
        cylinder: Option<Circle>,
        rings: usize,
    ) -> Result<f64, FieldError> {
        let Some(refine) = self.refine_walls else {
            return Ok(1.0);
        };
        if !refine.is_finite() || !(1.0..=64.0).contains(&refine) {
            return Err(field_err(
                "scene.refine_walls",
                format!("must be between 1 and 64 (got {refine})"),
            ));
        }
        if !self.discs.is_empty() {
            return Err(field_err(
                "scene.refine_walls",
                "graded resolution needs fixed particles and walls: not with [[scene.discs]]",
            ));
        }
        let spacing = self.height / self.resolution as f64;
        let plan = GradedPlan {
            domain: Domain {
                min: Vec2::zeros(),
                max: Vec2::new(self.length, self.height),
                periodic: [true, !walls],
            },
            spacing,
            refinement: refine,
            plates: walls,
            cylinder,
            rings,
        };
        let room = match (walls, cylinder) {
            (true, Some(c)) => (c.centre.y - c.radius).min(self.height - c.centre.y - c.radius),
            (true, None) => self.height - plan.plate_thickness(),
            (false, _) => f64::INFINITY,
        };
        let needed =
            plan.plate_thickness() + cylinder.map_or(0.0, |_| plan.cylinder_thickness()) + spacing;
        if needed > room {
            return Err(field_err(
                "scene.refine_walls",
                format!(
                    "the graded layers ({needed:.4} with a row of δr between) do not fit in the gap {room:.4}: fewer scene.cylinder.rings or a finer scene.resolution"
                ),
            ));
        }
        Ok(refine)
    }

    /// `scene.walls`: without plates the box is a periodic cell of a square array, which
    /// needs a cylinder to hold it and has no wall to slide.
    fn validate_walls(&self, wall_velocity: [f64; 2]) -> Result<bool, FieldError> {
        let walls = self.walls.unwrap_or(true);
        if !walls && self.cylinder.is_none() && self.sphere.is_none() {
            return Err(field_err(
                "scene.walls",
                "false (periodic in y) needs a [scene.cylinder] (or in 3D a [scene.sphere]); a box periodic both ways without one is kind = \"taylor-green\"",
            ));
        }
        if !walls && wall_velocity != [0.0, 0.0] {
            return Err(field_err(
                "scene.walls",
                "false (periodic in y) leaves no wall for scene.wall_velocity to move",
            ));
        }
        Ok(walls)
    }

    fn validate_gravity(&self) -> Result<Vec2, FieldError> {
        let Some(g) = self.gravity else {
            return Ok(Vec2::zeros());
        };
        if !g.iter().all(|v| v.is_finite()) {
            return Err(field_err("scene.gravity", "must be finite"));
        }
        if self.mean_flow.is_some() {
            return Err(field_err(
                "scene.gravity",
                "the settling discs' return flow sets the mean flow: omit scene.mean_flow",
            ));
        }
        if self.discs.is_empty() {
            return Err(field_err(
                "scene.gravity",
                "acts on [[scene.discs]] only (the fluid's weight is hydrostatic); for a driven channel use scene.body_force",
            ));
        }
        Ok(Vec2::new(g[0], g[1]))
    }
}

impl CylinderSpec {
    fn validate(&self, length: f64, height: f64, resolution: usize) -> Result<Circle, FieldError> {
        let centre = self.centre.unwrap_or([0.5 * length, 0.5 * height]);
        let bounds = SceneBox {
            length,
            height,
            resolution,
        };
        circle_in_box("scene.cylinder", self.radius, centre, bounds)
    }

    /// The rings must stay a spacing clear of the plates (a lattice row between).
    fn validate_rings(
        &self,
        c: &Circle,
        height: f64,
        resolution: usize,
    ) -> Result<usize, FieldError> {
        let dr = height / resolution as f64;
        let gap = (c.centre.y - c.radius).min(height - c.centre.y - c.radius);
        if (self.rings + 1) as f64 * dr > gap {
            return Err(field_err(
                "scene.cylinder.rings",
                format!(
                    "{} rings of δr = {dr} and one lattice row do not fit in the gap {gap} between the cylinder and the plates",
                    self.rings
                ),
            ));
        }
        Ok(self.rings)
    }
}

impl Channel {
    /// The box: periodic in x, walls at y = 0 and H (or periodic in y too).
    fn domain(&self) -> Domain {
        Domain {
            min: Vec2::zeros(),
            max: Vec2::new(self.bounds.length, self.bounds.height),
            periodic: [true, !self.walls],
        }
    }

    /// Whether a lattice point holds a fluid particle: outside the cylinder by at least
    /// 0.1δr (a closer particle's mirror would nearly coincide with it).
    fn is_fluid(&self, p: &Vec2) -> bool {
        let domain = self.domain();
        // The image of p nearest the centre, across the periodic ends.
        let clear = |c: &Circle| {
            c.distance(&Shape::Circle(*c).nearest_image(p, Some(&domain))) >= 0.1 * self.spacing()
        };
        self.cylinder.iter().all(clear) && self.discs.iter().all(|d| clear(&d.circle))
    }

    /// The lattice's fluid points, and with `rings` the body-conforming layers: ring k at
    /// r_k = R + (k + ½)δr holds round(2πr_k/δr) equally spaced particles (each an area of
    /// ≈ δr², alternate rings staggered by half a spacing), and the lattice keeps only the
    /// points at least `rings`·δr from the surface, half a spacing beyond the last ring.
    ///
    /// A lattice cut by the circle leaves particles at 0.1–1δr from the surface in a pattern
    /// set by where the centre falls on the lattice, and their mirrors with it. Measured on
    /// the Newtonian confined cylinder (R/δr = 10, K = 132.36 exact): the lattice gives
    /// K = 132.20, 135.56, 134.24 with the centre moved by 0, ¼ and ½δr along the axis;
    /// three rings give 132.34 and 132.38.
    fn positions(&self) -> Vec<Vec2> {
        match self.graded_plan() {
            Some(plan) => plan.build().0,
            None => self.uniform_positions(),
        }
    }

    /// The graded layout's plan (None: uniform).
    fn graded_plan(&self) -> Option<GradedPlan> {
        (self.refine > 1.0).then(|| GradedPlan {
            domain: self.domain(),
            spacing: self.spacing(),
            refinement: self.refine,
            plates: self.walls,
            cylinder: self.cylinder,
            rings: self.rings,
        })
    }

    /// [`Self::positions`] at one spacing.
    /// A constant body force, or one that holds `mean_flow`.
    fn drive(&self, fluid: &Fluid) -> Drive {
        match self.mean_flow {
            None => Drive::Constant,
            Some(u) => Drive::mean_flow(
                u,
                self.body_force.x,
                fluid.density,
                fluid.viscosity,
                self.bounds.height,
            ),
        }
    }

    fn uniform_positions(&self) -> Vec<Vec2> {
        let dr = self.spacing();
        let domain = self.domain();
        let clear_of_rings = |p: &Vec2| {
            self.cylinder.iter().all(|c| {
                let q = Shape::Circle(*c).nearest_image(p, Some(&domain));
                c.distance(&q) >= self.rings as f64 * dr
            })
        };
        let mut positions: Vec<Vec2> = lattice(self.columns, self.bounds.resolution, dr)
            .into_iter()
            .filter(|p| self.is_fluid(p) && clear_of_rings(p))
            .collect();
        for c in self.cylinder.iter().filter(|_| self.rings > 0) {
            for k in 0..self.rings {
                let r = c.radius + (k as f64 + 0.5) * dr;
                let n = (2.0 * std::f64::consts::PI * r / dr).round() as usize;
                let stagger = 0.5 * (k % 2) as f64;
                positions.extend((0..n).map(|j| {
                    let angle = 2.0 * std::f64::consts::PI * (j as f64 + stagger) / n as f64;
                    domain.wrap(c.centre + Vec2::new(angle.cos(), angle.sin()) * r)
                }));
            }
        }
        positions
    }
}

impl Channel {
    /// The box in space: periodic along x and z, and along y without plates.
    fn space_domain(&self) -> Domain<3> {
        Domain {
            min: Vector::<3>::zeros(),
            max: Vector::<3>::new(self.bounds.length, self.bounds.height, self.depth),
            periodic: [true, !self.walls, true],
        }
    }

    /// The cubic lattice's points in space, less those inside the sphere (or within 0.1δr
    /// of it, as for a cylinder: [`Self::is_fluid`]), and the sphere's shells
    /// ([`sphere::shells`]) with the lattice points within them taken out.
    fn space_positions(&self) -> Vec<Vector<3>> {
        let (dr, domain) = (self.spacing(), self.space_domain());
        let counts = [self.columns, self.bounds.resolution, self.layers];
        let n: usize = counts.iter().product();
        let lattice = (0..n).map(|k| {
            let index = [
                k % counts[0],
                (k / counts[0]) % counts[1],
                k / (counts[0] * counts[1]),
            ];
            Vector::<3>::from_fn(|a, _| (index[a] as f64 + 0.5) * dr)
        });
        sphere::with_shells(lattice, self.sphere.as_ref(), self.shells, dr, &domain)
    }
}

impl Scene for Channel {
    fn kind(&self) -> &'static str {
        "channel"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    /// The radius R of the cylinder or the sphere (Wi = ⟨u⟩λ/R), else the height.
    fn length_scale(&self) -> f64 {
        let body = self.cylinder.map(|c| c.radius);
        body.or(self.sphere.map(|s| s.radius))
            .unwrap_or(self.bounds.height)
    }

    /// The nominal mean velocity with a cylinder; else the largest of the Oldroyd-B steady
    /// centre-line velocity ρgH²/(8η0), the fastest wall's speed, the fastest disc
    /// surface's given speed |V| + |Ω|R and a sedimenting disc's scale
    /// |ρ_s − ρ_f||g_s|R²/(4η0), of the order of its terminal velocity ΔρgπR²/(η0 K) when
    /// the drag coefficient K = F/(η0 U) is ~4π (it is 15–30 in a channel of 4R–8R).
    fn velocity_scale(&self, f: &Fluid) -> f64 {
        let settling = |d: &DiscPlan| {
            let dr = (d.density_ratio - 1.0).abs() * f.density;
            dr * self.gravity.norm() * d.circle.radius.powi(2) / (4.0 * f.viscosity)
        };
        let discs = self
            .discs
            .iter()
            .map(|d| d.velocity.norm() + d.spin.abs() * d.circle.radius + settling(d));
        let walls = discs.fold(
            self.wall_velocity[0].abs().max(self.wall_velocity[1].abs()),
            f64::max,
        );
        match self.velocity > 0.0 {
            true => self.velocity,
            false => {
                let h = self.bounds.height;
                let newtonian = f.density * self.body_force.x.abs() * h * h / (8.0 * f.viscosity);
                // A generalised Newtonian fluid: its own steady centre-line velocity (the
                // Newtonian estimate with η0, the cut, can be far too small).
                let centre = if f.law.is_constant() {
                    newtonian
                } else {
                    SteadyChannel::new(f, self.body_force.x, h)
                        .map_or(newtonian, |c| c.centre_velocity().abs())
                };
                centre.max(walls)
            }
        }
    }

    fn body_force(&self) -> Vec2 {
        self.body_force
    }

    fn graded(&self) -> bool {
        self.refine > 1.0
    }

    fn particles(&self) -> usize {
        if self.sphere.is_some() {
            self.space_positions().len()
        } else if self.cylinder.is_none() && self.discs.is_empty() && self.refine <= 1.0 {
            self.columns * self.bounds.resolution * self.layers.max(1)
        } else {
            self.positions().len()
        }
    }

    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String> {
        let (positions, resolution) = match self.graded_plan() {
            Some(plan) => {
                let (points, graded) = plan.build();
                (points, Resolution::Graded(graded))
            }
            None => (self.positions(), Resolution::Uniform),
        };
        let wall = |shape| Wall::no_slip(shape, scheme.wall_conformation);
        let sliding =
            |shape, u: f64| Wall::sliding(shape, scheme.wall_conformation, Vec2::new(u, 0.0));
        let top = Plane {
            axis: 1,
            position: self.bounds.height,
            fluid_side: -1.0,
        };
        let mut walls = Vec::new();
        if self.walls {
            walls.push(sliding(Shape::Plane(Plane::floor()), self.wall_velocity[0]));
            walls.push(sliding(Shape::Plane(top), self.wall_velocity[1]));
        }
        walls.extend(self.cylinder.map(|c| wall(Shape::Circle(c))));
        Ok(Setup {
            domain: self.domain(),
            walls,
            velocity: vec![Vec2::zeros(); positions.len()],
            positions,
            spacing: self.spacing(),
            fluid: *fluid,
            scheme: *scheme,
            body_force: self.body_force,
            drive: self.drive(fluid),
            scales,
            free_surface: false,
            inflow: None,
            discs: self.discs.iter().map(|d| d.disc(fluid.density)).collect(),
            contact: self.contact,
            gravity: self.gravity,
            contact_angle: None,
            resolution,
        })
    }

    /// Plates at y = 0 and H (or none: periodic in y), periodic along x and z, on a cubic
    /// lattice: the flow does not vary along z, so a depth of three kernel supports (the
    /// least a periodic axis takes) suffices. Cylinders, discs and graded resolution are 2D.
    fn dimension(&self) -> usize {
        self.dimension
    }

    fn build_in_space(
        &self,
        fluid: &Fluid,
        scheme: &Scheme,
        scales: Scales,
    ) -> Result<FlowSetup<3>, String> {
        if self.dimension != 3 {
            return Err("scene.dimension is 2".into());
        }
        let dr = self.spacing();
        let positions = self.space_positions();
        let n = positions.len();
        let plate = |position, fluid_side, u: f64| {
            let plane = Plane {
                axis: 1,
                position,
                fluid_side,
            };
            let velocity = Vector::<3>::new(u, 0.0, 0.0);
            Wall::sliding(Shape::Plane(plane), scheme.wall_conformation, velocity)
        };
        let mut walls = if self.walls {
            vec![
                plate(0.0, 1.0, self.wall_velocity[0]),
                plate(self.bounds.height, -1.0, self.wall_velocity[1]),
            ]
        } else {
            Vec::new()
        };
        let turning = self
            .sphere
            .zip(self.turning)
            .map(|(sphere, t)| TurningSphere {
                sphere,
                wall: walls.len(),
                spin: t.spin,
                density: t.density_ratio * fluid.density,
                turning: t.turning,
                tensor: scheme.wall_conformation,
                torque: Vector::<3>::zeros(),
            });
        match (self.sphere, turning) {
            (_, Some(t)) => walls.push(t.wall()),
            (Some(s), None) => {
                walls.push(Wall::no_slip(Shape::Circle(s), scheme.wall_conformation))
            }
            (None, None) => {}
        }
        let g = self.body_force;
        Ok(FlowSetup {
            domain: self.space_domain(),
            walls,
            velocity: vec![Vector::<3>::zeros(); n],
            positions,
            spacing: dr,
            fluid: *fluid,
            scheme: *scheme,
            body_force: Vector::<3>::new(g.x, g.y, 0.0),
            drive: self.drive(fluid),
            scales,
            sphere: turning,
            flow_volume: None,
        })
    }

    fn reference(&self, fluid: &Fluid) -> Result<Reference, String> {
        if self.cylinder.is_some() || self.sphere.is_some() {
            return Err("no analytic solution for flow past a cylinder or a sphere".into());
        }
        if !self.discs.is_empty() {
            return Err("no analytic solution for flow with discs".into());
        }
        if self.wall_velocity != [0.0, 0.0] {
            if self.body_force.x != 0.0 || self.mean_flow.is_some() {
                return Err("no analytic solution for combined Couette–Poiseuille flow".into());
            }
            return Reference::couette(fluid, self.bounds.height, self.wall_velocity);
        }
        Reference::channel(
            fluid,
            self.body_force.x,
            self.bounds.height,
            self.velocity_scale(fluid),
        )
    }

    /// The centre-line velocity: a quadratic fit through the particles near y = H/2.
    fn characteristic_velocity(&self, positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        centre_line_velocity(
            positions,
            velocity,
            0.5 * self.bounds.height,
            self.spacing(),
        )
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Centre-line velocity", "u(H/2)")
    }

    fn varies_across_height(&self) -> bool {
        self.cylinder.is_none() && self.sphere.is_none()
    }

    fn periodic(&self) -> [bool; 2] {
        self.domain().periodic
    }

    fn holds_mean_flow(&self) -> bool {
        self.mean_flow.is_some()
    }

    fn cylinder(&self) -> Option<Circle> {
        self.cylinder
    }

    fn sphere(&self) -> Option<Sphere> {
        self.sphere
    }

    fn sphere_turns(&self) -> bool {
        self.turning.is_some()
    }

    fn discs(&self) -> usize {
        self.discs.len()
    }

    fn moving_bodies(&self) -> bool {
        self.discs.iter().any(DiscPlan::moves)
    }

    fn wall_shear_rate(&self) -> Option<f64> {
        let [bottom, top] = self.wall_velocity;
        (top != bottom).then(|| (top - bottom) / self.bounds.height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(rings: usize) -> Result<Channel, FieldError> {
        let spec: ChannelSpec = toml::from_str(&format!(
            "length = 12.0\nheight = 4.0\nresolution = 40\nbody_force = [1.0, 0.0]\n\
             velocity = 1.0\n[cylinder]\nradius = 1.0\nrings = {rings}\n"
        ))
        .unwrap();
        spec.validate()
    }

    /// With rings every particle keeps at least 0.5δr from every other (the lattice is held
    /// half a spacing off the last ring, the rings a spacing apart), none lies inside the
    /// cylinder, and the particles fill the fluid's area at about one per δr² (the lattice
    /// cut alone: 1 to round-off of the cut).
    #[test]
    fn the_rings_lie_clear_of_each_other_and_of_the_lattice() {
        let c = channel(3).unwrap();
        let (p, dr) = (c.positions(), c.spacing());
        let domain = c.domain();
        let circle = c.cylinder.unwrap();
        for (i, a) in p.iter().enumerate() {
            assert!(circle.distance(a) > 0.4 * dr, "{a:?} inside the first ring");
            for b in &p[i + 1..] {
                let d = domain.min_image(*a - *b).norm();
                assert!(
                    d > 0.5 * dr - 1e-12,
                    "{a:?} and {b:?} {:.3}δr apart",
                    d / dr
                );
            }
        }
        let area = 12.0 * 4.0 - std::f64::consts::PI;
        let density = p.len() as f64 * dr * dr / area;
        assert!((density - 1.0).abs() < 0.01, "{density}");
    }

    /// Rings that would reach the plates are refused, naming the key.
    #[test]
    fn rings_that_reach_the_plates_are_refused() {
        assert!(channel(9).is_ok());
        let err = channel(10).unwrap_err();
        assert!(
            format!("{err:?}").contains("scene.cylinder.rings"),
            "{err:?}"
        );
    }

    /// Without plates the box is periodic both ways; it needs a cylinder and has no wall to
    /// slide, and each refusal names `scene.walls`.
    #[test]
    fn a_channel_without_walls_is_periodic_and_needs_a_cylinder() {
        let spec = |extra: &str| -> Result<Channel, FieldError> {
            toml::from_str::<ChannelSpec>(&format!(
                "length = 6.0\nheight = 6.0\nresolution = 60\nbody_force = [1.0, 0.0]\n\
                 walls = false\n{extra}"
            ))
            .unwrap()
            .validate()
        };
        let array = spec("velocity = 1.0\n[cylinder]\nradius = 1.0\n").unwrap();
        assert_eq!(array.domain().periodic, [true, true]);
        for extra in [
            "",
            "wall_velocity = [1.0, 0.0]\nvelocity = 1.0\n[cylinder]\nradius = 1.0\n",
        ] {
            let err = spec(extra).unwrap_err();
            assert!(format!("{err:?}").contains("scene.walls"), "{err:?}");
        }
    }
}
