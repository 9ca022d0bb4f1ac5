//! Pressure-driven flow in a circular pipe (3D only): the no-slip inside of a pipe of radius
//! R along x, periodic in x, driven by a body force along the axis. Its start-up has a series
//! solution in Bessel functions (`analysis::analytic::pipe`), read in the meridional plane
//! (x, r).

use super::{check_memory_in, check_periodic_extent, support_in_dr, Scene, SceneBox};
use crate::analysis::diagnostics::centre_line_velocity;
use crate::analysis::plane::PlaneMap;
use crate::analysis::reference::Reference;
use crate::engine::boundary::{Shape, Tube, Wall};
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
/// (`cases/pipe.toml`).
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PipeSpec {
    /// Periodic length along the axis (x).
    pub length: f64,
    /// The pipe's diameter 2R.
    pub diameter: f64,
    /// Particles across the diameter, 2R/δr (at least 8).
    pub resolution: usize,
    /// Body force per unit mass g along the axis.
    pub body_force: f64,
    /// Space dimensions: a pipe is 3 (the default; in the plane it is the channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dimension: Option<usize>,
}

/// A validated pipe.
#[derive(Clone, Debug, PartialEq)]
pub struct Pipe {
    pub bounds: SceneBox,
    columns: usize,
    /// g along x.
    pub body_force: f64,
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
        Ok(Pipe {
            bounds: SceneBox {
                length: self.length,
                height: self.diameter,
                resolution: self.resolution,
            },
            columns,
            body_force: self.body_force,
        })
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
}

impl Scene for Pipe {
    fn kind(&self) -> &'static str {
        "pipe"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    /// The radius R (Re = ρUR/η0, Wi = λU/R, as the series is written).
    fn length_scale(&self) -> f64 {
        self.radius()
    }

    /// The Newtonian (and Oldroyd-B) steady centre-line velocity ρgR²/(4η0).
    fn velocity_scale(&self, f: &Fluid) -> f64 {
        f.density * self.body_force.abs() * self.radius().powi(2) / (4.0 * f.viscosity)
    }

    fn body_force(&self) -> Vec2 {
        Vec2::new(self.body_force, 0.0)
    }

    fn particles(&self) -> usize {
        self.columns * cross_section(self.radius(), self.spacing()).len()
    }

    fn build(&self, _: &Fluid, _: &Scheme, _: Scales) -> Result<Setup, String> {
        Err("scene.kind = \"pipe\" is 3D only (in the plane it is the channel)".into())
    }

    fn dimension(&self) -> usize {
        3
    }

    /// Cross-sections of rings ([`cross_section`]) every δr along x, the wall's mirrors
    /// reflected along the radius (`boundary::Tube`).
    fn build_in_space(
        &self,
        fluid: &Fluid,
        scheme: &Scheme,
        scales: Scales,
    ) -> Result<FlowSetup<3>, String> {
        let (dr, radius) = (self.spacing(), self.radius());
        let [cy, cz] = self.axis();
        let section = cross_section(radius, dr);
        let positions: Vec<Vector<3>> = (0..self.columns)
            .flat_map(|i| {
                let x = (i as f64 + 0.5) * dr;
                section
                    .iter()
                    .map(move |q| Vector::<3>::new(x, cy + q.x, cz + q.y))
            })
            .collect();
        let tube = Tube::<3> {
            centre: Vector::<3>::new(0.0, cy, cz),
            radius,
            axis: Some(0),
        };
        let n = positions.len();
        Ok(FlowSetup {
            domain: Domain {
                min: Vector::<3>::zeros(),
                max: Vector::<3>::new(self.bounds.length, self.bounds.height, self.bounds.height),
                periodic: [true, false, false],
            },
            walls: vec![Wall::no_slip(Shape::Tube(tube), scheme.wall_conformation)],
            velocity: vec![Vector::<3>::zeros(); n],
            positions,
            spacing: dr,
            fluid: *fluid,
            scheme: *scheme,
            body_force: Vector::<3>::new(self.body_force, 0.0, 0.0),
            drive: Drive::Constant,
            scales,
            sphere: None,
        })
    }

    fn plane(&self) -> PlaneMap {
        PlaneMap::Meridional {
            centre: self.axis(),
        }
    }

    fn reference(&self, fluid: &Fluid) -> Result<Reference, String> {
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

    fn has_tube(&self) -> bool {
        true
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

    #[test]
    fn a_pipe_in_the_plane_is_refused() {
        let spec = PipeSpec {
            length: 1.0,
            diameter: 1.0,
            resolution: 20,
            body_force: 1.0,
            dimension: Some(2),
        };
        let (field, why) = spec.validate().unwrap_err();
        assert_eq!(field, "scene.dimension", "{why}");
    }
}
