//! Pressure-driven flow in a circular pipe (3D only): the no-slip inside of a pipe of radius
//! R along x, periodic in x, driven by a body force along the axis. Its start-up has a series
//! solution in Bessel functions (`analysis::analytic::pipe`), read in the meridional plane
//! (x, r).
//!
//! With a fixed sphere on the axis and the wall sliding along it at U, the pipe is the
//! sphere falling at U through a tube of fluid at rest, seen from the sphere
//! (`cases/sphere-in-tube.toml`): the flux through every cross-section is then UπR², held by
//! the body force standing for the mean pressure gradient (`scene.mean_flow = U`).

use super::sphere::{self, SphereSpec};
use super::{check_memory_in, check_periodic_extent, support_in_dr, Scene, SceneBox};
use crate::analysis::diagnostics::centre_line_velocity;
use crate::analysis::plane::PlaneMap;
use crate::analysis::reference::Reference;
use crate::analysis::tube_load::PipeWall;
use crate::engine::boundary::{Shape, Sphere, Tube, Wall};
use crate::engine::dimension::Vector;
use crate::engine::drive::Drive;
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{FlowSetup, Scales, Setup};
use crate::setup::error::{field_err, positive, FieldError};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// `[scene]` of `kind = "pipe"`: the inside of a circular pipe along x, periodic in x
/// (`cases/pipe.toml`; with a sphere and the wall sliding, `cases/sphere-in-tube.toml`).
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PipeSpec {
    /// Periodic length along the axis (x).
    pub length: f64,
    /// The pipe's diameter 2R.
    pub diameter: f64,
    /// Particles across the diameter, 2R/δr (at least 8).
    pub resolution: usize,
    /// Body force per unit mass g along the axis (with `mean_flow`, the initial guess).
    pub body_force: f64,
    /// Space dimensions: a pipe is 3 (the default; in the plane it is the channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dimension: Option<usize>,
    /// The wall's velocity along the axis (default 0). With a sphere, the tube moving past
    /// the sphere: the fluid starts moving with it, the sphere set going at once.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_velocity: Option<f64>,
    /// Hold the bulk velocity ⟨u⟩ = Q/(πR²) at this value by adjusting the body force
    /// every step (`engine::drive`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_flow: Option<f64>,
    /// A fixed solid sphere in the pipe, clear of the wall by a kernel support (its drag
    /// coefficient K = F_x/(6πη0 a U) in `summary.json`'s `sphere_in_tube`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sphere: Option<Box<SphereSpec>>,
}

/// A validated pipe.
#[derive(Clone, Debug, PartialEq)]
pub struct Pipe {
    pub bounds: SceneBox,
    columns: usize,
    /// g along x.
    pub body_force: f64,
    /// The wall's velocity along x.
    pub wall_velocity: f64,
    /// The bulk velocity the body force holds (None: a constant force).
    pub mean_flow: Option<f64>,
    /// A fixed sphere, and the layers of particles on shells around it.
    pub sphere: Option<Sphere>,
    shells: usize,
}

impl PipeSpec {
    pub fn validate(&self) -> Result<Pipe, FieldError> {
        if self.dimension.is_some_and(|d| d != 3) {
            return Err(field_err(
                "scene.dimension",
                "a pipe is written in 3D only (in the plane it is the channel: scene.kind = \"channel\")",
            ));
        }
        positive("scene.length", self.length)?;
        positive("scene.diameter", self.diameter)?;
        // Two kernel supports across the diameter: the mirrors of opposite sides of the wall
        // must not reach past the axis.
        let least = (2.0 * support_in_dr()).ceil() as usize;
        if self.resolution < least {
            return Err(field_err(
                "scene.resolution",
                format!("must be at least {least} particles across the diameter (two kernel supports), got {}", self.resolution),
            ));
        }
        let columns =
            check_periodic_extent("scene.length", self.length, self.diameter, self.resolution)?;
        if !self.body_force.is_finite() {
            return Err(field_err("scene.body_force", "must be finite"));
        }
        let dr = self.diameter / self.resolution as f64;
        let section = cross_section(0.5 * self.diameter, dr).len();
        check_memory_in(3, (columns * section) as f64)?;
        let wall_velocity = self.wall_velocity.unwrap_or(0.0);
        if !wall_velocity.is_finite() {
            return Err(field_err("scene.wall_velocity", "must be finite"));
        }
        let mean_flow = self
            .mean_flow
            .map(|u| positive("scene.mean_flow", u))
            .transpose()?;
        if mean_flow.is_some() && self.body_force <= 0.0 {
            return Err(field_err(
                "scene.body_force",
                "with scene.mean_flow the force is the controller's initial guess: positive along x",
            ));
        }
        let mut pipe = Pipe {
            bounds: SceneBox {
                length: self.length,
                height: self.diameter,
                resolution: self.resolution,
            },
            columns,
            body_force: self.body_force,
            wall_velocity,
            mean_flow,
            sphere: None,
            shells: 0,
        };
        if let Some(spec) = &self.sphere {
            pipe.sphere = Some(pipe.validate_sphere(spec)?);
            pipe.shells = spec.shells();
        }
        Ok(pipe)
    }
}

/// The particles of a cross-section of `radius` about its centre, in rings: ring k at
/// ρ_k = R − (k + ½)δr holds round(2πρ_k/δr) equally spaced particles (each an area of about
/// δr²; alternate rings staggered by half a spacing), and a ring nearer the axis than δr/4
/// is one particle on it. Rings keep the first layer δr/2 from the wall all round, so every
/// near-wall particle's mirror fills its support as a plane wall's does; a Cartesian lattice
/// cut by the circle leaves particles 0–δr from the wall (`engine::neighbourhood`'s pipe test).
pub fn cross_section(radius: f64, dr: f64) -> Vec<Vec2> {
    let mut points = Vec::new();
    for k in 0.. {
        let rho = radius - (k as f64 + 0.5) * dr;
        if rho < -0.25 * dr {
            break;
        }
        if rho < 0.25 * dr {
            points.push(Vec2::zeros());
            break;
        }
        let count = (TAU * rho / dr).round().max(1.0) as usize;
        let stagger = 0.5 * (k % 2) as f64;
        points.extend((0..count).map(|j| {
            let angle = TAU * (j as f64 + stagger) / count as f64;
            Vec2::new(rho * angle.cos(), rho * angle.sin())
        }));
    }
    points
}

impl Pipe {
    fn radius(&self) -> f64 {
        0.5 * self.bounds.height
    }

    /// The axis: x at (y, z) = (R, R).
    fn axis(&self) -> [f64; 2] {
        [self.radius(); 2]
    }

    /// The box: periodic along the axis.
    fn domain(&self) -> Domain<3> {
        let d = self.bounds.height;
        Domain {
            min: Vector::<3>::zeros(),
            max: Vector::<3>::new(self.bounds.length, d, d),
            periodic: [true, false, false],
        }
    }

    /// `[scene.sphere]`: fixed, as for the box ([`SphereSpec::validate`]), and clear of the
    /// wall by a kernel support all round (a particle's mirrors across the sphere and the
    /// wall would otherwise overlap).
    fn validate_sphere(&self, spec: &SphereSpec) -> Result<Sphere, FieldError> {
        if spec.turning()?.is_some() {
            return Err(field_err(
                "scene.sphere.motion",
                "a sphere in a pipe is fixed (turning and translating spheres are written for the channel's box)",
            ));
        }
        let s = spec.validate(&self.domain(), self.spacing())?;
        let [cy, cz] = self.axis();
        let off_axis = (s.centre.y - cy).hypot(s.centre.z - cz);
        let support = support_in_dr() * self.spacing();
        if off_axis + s.radius + support > self.radius() {
            return Err(field_err(
                "scene.sphere",
                format!(
                    "the sphere must clear the pipe's wall by a kernel support ({support:.4}): its radius plus its distance from the axis is {:.4} of R = {:.4}",
                    off_axis + s.radius,
                    self.radius()
                ),
            ));
        }
        Ok(s)
    }

    /// Cross-sections of rings ([`cross_section`]) every δr along x; with a sphere, the
    /// points within its shells taken out and the shells laid instead ([`sphere::shells`]).
    fn positions(&self) -> Vec<Vector<3>> {
        let (dr, radius, domain) = (self.spacing(), self.radius(), self.domain());
        let [cy, cz] = self.axis();
        let section = cross_section(radius, dr);
        let rings = (0..self.columns).flat_map(|i| {
            let x = (i as f64 + 0.5) * dr;
            section
                .iter()
                .map(move |q| Vector::<3>::new(x, cy + q.x, cz + q.y))
        });
        sphere::with_shells(rings, self.sphere.as_ref(), self.shells, dr, &domain)
    }

    /// A constant body force, or one that holds `mean_flow` on the viscous time across
    /// the radius, ρR²/η0 (the diameter's, four times longer, left the sphere in a tube
    /// short of its flux after 135 steps and 3a/U).
    fn drive(&self, fluid: &Fluid) -> Drive {
        match self.mean_flow {
            None => Drive::Constant,
            Some(u) => Drive::mean_flow(
                u,
                self.body_force,
                fluid.density,
                fluid.viscosity,
                self.radius(),
            ),
        }
    }
}

impl Scene for Pipe {
    fn kind(&self) -> &'static str {
        "pipe"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    /// The radius R (Re = ρUR/η0, Wi = λU/R, as the series is written); with a sphere its
    /// radius a (Wi = λU/a, as the benchmark is written).
    fn length_scale(&self) -> f64 {
        self.sphere.map_or(self.radius(), |s| s.radius)
    }

    /// The wall's speed or the held bulk velocity, whichever is larger; without either the
    /// Newtonian (and Oldroyd-B) steady centre-line velocity ρgR²/(4η0).
    fn velocity_scale(&self, f: &Fluid) -> f64 {
        let moving = self.wall_velocity.abs().max(self.mean_flow.unwrap_or(0.0));
        match moving > 0.0 {
            true => moving,
            false => {
                f.density * self.body_force.abs() * self.radius().powi(2) / (4.0 * f.viscosity)
            }
        }
    }

    fn body_force(&self) -> Vec2 {
        Vec2::new(self.body_force, 0.0)
    }

    fn particles(&self) -> usize {
        match self.sphere {
            Some(_) => self.positions().len(),
            None => self.columns * cross_section(self.radius(), self.spacing()).len(),
        }
    }

    fn build(&self, _: &Fluid, _: &Scheme, _: Scales) -> Result<Setup, String> {
        Err("scene.kind = \"pipe\" is 3D only (in the plane it is the channel)".into())
    }

    fn dimension(&self) -> usize {
        3
    }

    /// [`Pipe::positions`], the wall's mirrors reflected along the radius
    /// (`boundary::Tube`), the sphere's across its surface; the fluid starts at the wall's
    /// velocity.
    fn build_in_space(
        &self,
        fluid: &Fluid,
        scheme: &Scheme,
        scales: Scales,
    ) -> Result<FlowSetup<3>, String> {
        let radius = self.radius();
        let [cy, cz] = self.axis();
        let positions = self.positions();
        let tube = Tube::<3> {
            centre: Vector::<3>::new(0.0, cy, cz),
            radius,
            axis: Some(0),
        };
        let tensor = scheme.wall_conformation;
        let u_wall = Vector::<3>::new(self.wall_velocity, 0.0, 0.0);
        let mut walls = vec![Wall::sliding(Shape::Tube(tube), tensor, u_wall)];
        walls.extend(self.sphere.map(|s| Wall::no_slip(Shape::Circle(s), tensor)));
        let n = positions.len();
        Ok(FlowSetup {
            domain: self.domain(),
            walls,
            velocity: vec![u_wall; n],
            positions,
            spacing: self.spacing(),
            fluid: *fluid,
            scheme: *scheme,
            body_force: Vector::<3>::new(self.body_force, 0.0, 0.0),
            drive: self.drive(fluid),
            scales,
            sphere: None,
            flow_volume: Some(std::f64::consts::PI * radius * radius * self.bounds.length),
        })
    }

    fn plane(&self) -> PlaneMap {
        PlaneMap::Meridional {
            centre: self.axis(),
        }
    }

    fn reference(&self, fluid: &Fluid) -> Result<Reference, String> {
        if self.sphere.is_some() {
            return Err("no analytic solution for flow past a sphere".into());
        }
        if self.wall_velocity != 0.0 || self.mean_flow.is_some() {
            return Err("the pipe's series is for a wall at rest and a constant force".into());
        }
        Reference::pipe(fluid, self.radius(), self.velocity_scale(fluid))
    }

    /// The centre-line velocity: a quadratic fit in r through the particles within 2.5δr of
    /// the axis (`positions` are (x, r)).
    fn characteristic_velocity(&self, positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        centre_line_velocity(positions, velocity, 0.0, self.spacing())
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Centre-line velocity", "u(r = 0)")
    }

    fn varies_across_height(&self) -> bool {
        true
    }

    fn periodic(&self) -> [bool; 2] {
        [true, false]
    }

    fn pipe_wall(&self) -> Option<PipeWall> {
        Some(PipeWall {
            axis: self.axis(),
            radius: self.radius(),
            velocity: self.wall_velocity,
        })
    }

    fn holds_mean_flow(&self) -> bool {
        self.mean_flow.is_some()
    }

    fn sphere(&self) -> Option<Sphere> {
        self.sphere
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rings tile the disc: as many particles as the area holds (πR²/δr², within the
    /// rounding of each ring's count), none closer to the wall than δr/2.
    #[test]
    fn the_rings_fill_the_cross_section() {
        for m in [8usize, 10, 15, 16, 20, 31] {
            let (radius, dr) = (0.5, 1.0 / m as f64);
            let section = cross_section(radius, dr);
            let area = std::f64::consts::PI * radius * radius / (dr * dr);
            let ratio = section.len() as f64 / area;
            assert!(
                (ratio - 1.0).abs() < 0.06,
                "m = {m}: {} for {area:.1}",
                section.len()
            );
            let outer = section.iter().map(|p| p.norm()).fold(0.0, f64::max);
            assert!(
                (radius - outer - 0.5 * dr).abs() < 1e-12,
                "m = {m}: outer ring {outer}"
            );
        }
    }

    fn tube(extra: &str) -> Result<Pipe, FieldError> {
        let spec: PipeSpec = toml::from_str(&format!(
            "length = 6.0\ndiameter = 4.0\nresolution = 32\nbody_force = 250.0\n\
             wall_velocity = 1.0\nmean_flow = 1.0\n{extra}"
        ))
        .unwrap();
        spec.validate()
    }

    /// The sphere's shells and the rings beyond them fill the tube less the sphere: the
    /// particles' volume Nδr³ within 1 % of πR²L − (4/3)πa³ (the rings' rounding is 6 % at
    /// most per section, `the_rings_fill_the_cross_section`, and averages out along the
    /// tube; the shells carry their volume within 1 %), none inside the sphere or the wall.
    #[test]
    fn a_sphere_in_a_pipe_leaves_the_rest_of_the_tube_filled() {
        let pipe = tube("[sphere]\nradius = 1.0\n").unwrap();
        let points = pipe.positions();
        let dr = pipe.spacing();
        let (a, r, l) = (1.0, 2.0, 6.0);
        let volume = std::f64::consts::PI * (r * r * l - 4.0 / 3.0 * a * a * a);
        let filled = points.len() as f64 * dr.powi(3);
        assert!((filled / volume - 1.0).abs() < 0.01, "{filled} vs {volume}");
        let centre = Vector::<3>::new(3.0, 2.0, 2.0);
        for p in &points {
            let from_sphere = (p - centre).norm() - a;
            let from_wall = r - (p.y - 2.0).hypot(p.z - 2.0);
            assert!(from_sphere > 0.4 * dr && from_wall > 0.4 * dr, "{p:?}");
        }
    }

    /// A sphere must clear the wall by a support and stays fixed; with `mean_flow` the
    /// force is the controller's guess along +x; each refusal names its key.
    #[test]
    fn a_sphere_in_a_pipe_is_refused_where_it_cannot_be_held() {
        let field = |extra: &str| tube(extra).unwrap_err().0;
        assert_eq!(
            field("[sphere]\nradius = 1.0\ncentre = [3.0, 2.45, 2.45]\n"),
            "scene.sphere"
        );
        assert_eq!(
            field("[sphere]\nradius = 1.0\nmotion = \"free-rotation\"\n"),
            "scene.sphere.motion"
        );
        let spec: PipeSpec = toml::from_str(
            "length = 6.0\ndiameter = 4.0\nresolution = 32\nbody_force = -1.0\nmean_flow = 1.0\n",
        )
        .unwrap();
        assert_eq!(spec.validate().unwrap_err().0, "scene.body_force");
    }

    #[test]
    fn a_pipe_in_the_plane_is_refused() {
        let spec = PipeSpec {
            length: 1.0,
            diameter: 1.0,
            resolution: 20,
            body_force: 1.0,
            dimension: Some(2),
            wall_velocity: None,
            mean_flow: None,
            sphere: None,
        };
        let (field, why) = spec.validate().unwrap_err();
        assert_eq!(field, "scene.dimension", "{why}");
    }
}
