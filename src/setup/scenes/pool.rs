//! A pool in a tank under gravity, its free surface meeting the walls at a contact angle
//! (`scene.contact_angle`), optionally with two vertical plates dipped into it: the
//! meniscus at a wall and the capillary rise between plates (Wróblewski, Boryczko & Kopeć
//! 2008, §6.2). The tank's side walls stand at x = ±length/2 on the floor y = 0, open above;
//! the plates, `plates.thickness` thick and `plates.gap` apart about x = 0, reach from
//! `plates.bottom` (the lowest point of their rounded ends) past the top of the box
//! ([`crate::engine::boundary::Plate`]).
//!
//! The static shapes are exact in 2D (the run's `meniscus` probe compares with them):
//! * at a single vertical wall the surface rises h = ℓ_c √(2(1 − sin θ)) above the level far
//!   from it, ℓ_c = √(σ/ρg) the capillary length (Landau & Lifshitz, *Fluid Mechanics*, §61);
//! * between plates d apart the column lifted above the far level has the area 2σ cos θ/(ρg)
//!   per unit depth, whatever the meniscus's shape (the vertical pull σ cos θ of both contact
//!   lines holds its weight), so its mean height is Jurin's h = 2σ cos θ/(ρgd).

use super::{check_box, check_memory, finite_force, support_in_dr, Scene, SceneBox};
use crate::analysis::reference::Reference;
use crate::engine::boundary::{Plane, Plate, Shape, Wall};
use crate::engine::drive::Drive;
use crate::engine::math::Vec2;
use crate::engine::resolution::Resolution;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{Scales, Setup};
use crate::setup::error::{field_err, in_range, positive, FieldError};
use serde::{Deserialize, Serialize};

/// `[scene]` of `kind = "pool"`: a tank filled `depth` deep under gravity, its surface
/// meeting the walls at the contact angle (`cases/meniscus.toml`), optionally with two plates
/// dipped into it (capillary rise, `cases/capillary-rise.toml`); `resolution` is height/δr.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PoolSpec {
    /// The tank's width (walls at x = ±length/2).
    pub length: f64,
    /// The height of the box particles must stay in.
    pub height: f64,
    /// The liquid's depth at rest.
    pub depth: f64,
    /// Particles across the box's height, height/δr.
    pub resolution: usize,
    /// Gravity, per unit mass.
    pub body_force: [f64; 2],
    /// θ in degrees, through the liquid, at every wall.
    pub contact_angle: f64,
    /// θ in degrees at the tank's two side walls, if not `contact_angle` (90: the level
    /// surface meets them square, without a meniscus).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_contact_angle: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plates: Option<PlatesTable>,
}

/// `[scene.plates]`.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlatesTable {
    /// d, between the plates' inner faces.
    pub gap: f64,
    /// Each plate's thickness (at least two kernel supports).
    pub thickness: f64,
    /// Height of the plates' lower ends (the lowest point of their rounded ends) above the
    /// floor.
    pub bottom: f64,
    /// The liquid's height between the plates at the start, above the pool's `depth`
    /// (negative: below it), rounded to whole rows: a column started near its static height
    /// settles in a fraction of the time a rise from the level takes, and two starts, one
    /// above and one below, bracket the static column of the discrete model. 0 by default.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fill: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A validated pool.
#[derive(Clone, Debug, PartialEq)]
pub struct Pool {
    pub bounds: SceneBox,
    pub depth: f64,
    pub gravity: Vec2,
    /// θ in radians (the plates' and the floor's).
    pub contact_angle: f64,
    /// θ in radians at the tank's side walls.
    pub wall_contact_angle: f64,
    /// The two plates (left, right), if any.
    pub plates: Option<[Plate; 2]>,
    /// The liquid's height between the plates at the start (`scene.plates.fill`).
    pub gap_level: f64,
}

impl PoolSpec {
    pub fn validate(&self) -> Result<Pool, FieldError> {
        let (length, height, resolution) = (self.length, self.height, self.resolution);
        check_box(length, height, resolution)?;
        let dr = height / resolution as f64;
        on_lattice("scene.length", length, dr)?;
        let depth = in_range(
            "scene.depth",
            self.depth,
            2.0 * support_in_dr() * dr,
            height,
        )?;
        on_lattice("scene.depth", depth, dr)?;
        check_memory(length * depth / (dr * dr))?;
        let gravity = finite_force(self.body_force)?;
        let theta = in_range("scene.contact_angle", self.contact_angle, 15.0, 165.0)?;
        let wall_theta = match self.wall_contact_angle {
            Some(a) => in_range("scene.wall_contact_angle", a, 15.0, 165.0)?,
            None => theta,
        };
        let plates = self
            .plates
            .as_ref()
            .map(|p| p.validate(length, depth, dr))
            .transpose()?;
        let gap_level = match &self.plates {
            Some(p) => {
                let lowest = plates.map_or(depth, |[l, _]| l.end().centre.y);
                in_range("scene.plates.fill", p.fill, lowest - depth, height - depth)? + depth
            }
            None => depth,
        };
        Ok(Pool {
            bounds: SceneBox {
                length,
                height,
                resolution,
            },
            depth,
            gravity,
            contact_angle: theta.to_radians(),
            wall_contact_angle: wall_theta.to_radians(),
            plates,
            gap_level,
        })
    }
}

impl PlatesTable {
    fn validate(&self, length: f64, depth: f64, dr: f64) -> Result<[Plate; 2], FieldError> {
        let support = support_in_dr() * dr;
        let gap = positive("scene.plates.gap", self.gap)?;
        if gap < 2.0 * support {
            return Err(field_err(
                "scene.plates.gap",
                format!(
                    "must hold two kernel supports ({:.4}), got {gap}",
                    2.0 * support
                ),
            ));
        }
        let thickness = positive("scene.plates.thickness", self.thickness)?;
        if thickness < 2.0 * support {
            return Err(field_err(
                "scene.plates.thickness",
                format!("must be at least two kernel supports ({:.4}), so that the mirrors of one side never reach the other, got {thickness}", 2.0 * support),
            ));
        }
        let bottom = in_range("scene.plates.bottom", self.bottom, 2.0 * support, depth)?;
        on_lattice("scene.plates.bottom", bottom, dr)?;
        // Both faces of each plate on lattice lines −length/2 + kδr.
        on_lattice("scene.plates.gap", 0.5 * (length - gap), dr)?;
        on_lattice("scene.plates.thickness", thickness, dr)?;
        let outer = 0.5 * gap + thickness;
        if 0.5 * length - outer < 2.0 * support {
            return Err(field_err(
                "scene.length",
                format!("the tank must leave two kernel supports beside the plates (outer faces at ±{outer})"),
            ));
        }
        let plate = |left, right| Plate {
            left,
            right,
            bottom,
        };
        Ok([plate(-outer, -0.5 * gap), plate(0.5 * gap, outer)])
    }
}

/// `value` must be a whole number of spacings (so walls and plates lie on lattice lines).
fn on_lattice(field: &str, value: f64, dr: f64) -> Result<(), FieldError> {
    let k = value / dr;
    if (k - k.round()).abs() > 1e-6 * k.max(1.0) {
        return Err(field_err(
            field,
            format!(
                "must be a whole number of particle spacings height/resolution = {dr} (got {k:.4})"
            ),
        ));
    }
    Ok(())
}

impl Pool {
    /// The floor, the side walls, the tank's two corners and the plates.
    fn walls(&self, scheme: &Scheme) -> Vec<Wall> {
        let half = 0.5 * self.bounds.length;
        let tensor = scheme.wall_conformation;
        let plane = |axis, position, fluid_side| {
            Wall::no_slip(
                Shape::Plane(Plane {
                    axis,
                    position,
                    fluid_side,
                }),
                tensor,
            )
        };
        let floor = plane(1, 0.0, 1.0);
        let side = |position, fluid_side| Wall {
            contact_angle: Some(self.wall_contact_angle),
            ..plane(0, position, fluid_side)
        };
        let (left, right) = (side(-half, 1.0), side(half, -1.0));
        let corners = [(&floor, &left), (&floor, &right)]
            .map(|(a, b)| Wall::corner(a, b).expect("perpendicular planes meet in a corner"));
        let mut walls = vec![floor, left, right];
        walls.extend(corners);
        for p in self.plates.iter().flatten() {
            walls.push(Wall::no_slip(Shape::Plate(*p), tensor));
        }
        walls
    }

    /// The capillary length ℓ_c = √(σ/ρg).
    pub fn capillary_length(&self, fluid: &Fluid) -> f64 {
        (fluid.surface_tension / (fluid.density * self.gravity.norm())).sqrt()
    }

    /// The particles of the liquid at rest: a square lattice over the tank to `depth`, and to
    /// `gap_level` between the plates, none inside a plate.
    fn positions(&self) -> Vec<Vec2> {
        let dr = self.spacing();
        let half = 0.5 * self.bounds.length;
        let columns = (self.bounds.length / dr).round() as usize;
        let rows_to = |y: f64| (y / dr).round() as usize;
        let between = |x: f64| match self.plates {
            Some([l, r]) => x > l.right && x < r.left,
            None => false,
        };
        // Off the plates, and a tenth of a spacing off their rounded ends.
        let inside = |p: &Vec2| {
            self.plates
                .iter()
                .flatten()
                .any(|c| Shape::Plate(*c).distance(p) < 0.1 * dr)
        };
        (0..columns)
            .flat_map(|i| {
                let x = -half + (i as f64 + 0.5) * dr;
                let top = if between(x) {
                    self.gap_level
                } else {
                    self.depth
                };
                (0..rows_to(top)).map(move |j| Vec2::new(x, (j as f64 + 0.5) * dr))
            })
            .filter(|p| !inside(p))
            .collect()
    }
}

impl Scene for Pool {
    fn kind(&self) -> &'static str {
        "pool"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    /// The depth (Re and Wi use it with the gravity-wave speed).
    fn length_scale(&self) -> f64 {
        self.depth
    }

    /// √(g depth), the speed of long gravity waves.
    fn velocity_scale(&self, _fluid: &Fluid) -> f64 {
        (self.gravity.norm() * self.depth).sqrt()
    }

    fn body_force(&self) -> Vec2 {
        self.gravity
    }

    fn particles(&self) -> usize {
        self.positions().len()
    }

    fn has_free_surface(&self) -> bool {
        true
    }

    fn has_corners(&self) -> bool {
        true
    }

    fn contact_angle(&self) -> Option<f64> {
        Some(self.contact_angle)
    }

    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String> {
        let positions = self.positions();
        Ok(Setup {
            domain: super::open_domain(self.bounds.length, self.bounds.height),
            walls: self.walls(scheme),
            velocity: vec![Vec2::zeros(); positions.len()],
            positions,
            spacing: self.spacing(),
            fluid: *fluid,
            scheme: *scheme,
            body_force: self.gravity,
            drive: Drive::Constant,
            scales,
            free_surface: true,
            inflow: None,
            discs: Vec::new(),
            contact: None,
            gravity: Vec2::zeros(),
            contact_angle: Some(self.contact_angle),
            resolution: Resolution::Uniform,
        })
    }

    fn reference(&self, _fluid: &Fluid) -> Result<Reference, String> {
        Err("the pool's static meniscus and capillary rise are compared by the meniscus probe (meniscus.csv)".into())
    }

    /// The largest particle speed (zero at rest).
    fn characteristic_velocity(&self, _positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        velocity.iter().map(|u| u.norm()).fold(0.0, f64::max)
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Largest speed", "|u|max")
    }

    fn pool(&self) -> Option<&Pool> {
        Some(self)
    }
}
