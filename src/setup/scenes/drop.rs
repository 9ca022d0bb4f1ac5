//! A drop falling onto a no-slip plate (King & Lind §IV C): a disc of concentric rings of
//! particles at (0, −U) above the plate y = 0, in an open box x ∈ [−length/2, length/2],
//! y ∈ [0, height] that particles must stay in (leaving it is a breakdown).
//!
//! Without the plate (`scene.plate = false`) and gravity, the same scene is a free drop: with
//! a surface tension it holds the Laplace pressure σ/R (`cases/static-drop.toml`), and
//! stretched into an ellipse of the same area (`scene.drop.aspect_ratio` a/b) it oscillates
//! in its mode 2 (`cases/oscillating-drop.toml`).

use super::{
    centre_of_mass_velocity, open_domain, open_scene, plate, support_in_dr, DropShape, Scene,
    SceneBox,
};
use crate::analysis::reference::Reference;
use crate::engine::drive::Drive;
use crate::engine::lattice::disc;
use crate::engine::math::Vec2;
use crate::engine::resolution::Resolution;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{Scales, Setup};
use crate::setup::error::{field_err, in_range, positive, FieldError};
use serde::{Deserialize, Serialize};

/// `[scene]` of `kind = "drop"`: a drop with a free surface, falling onto a no-slip plate at
/// y = 0, resting on it (a sessile drop) or free (`plate = false`); `resolution` is W/δr,
/// `velocity` the impact speed U, `body_force` gravity.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DropSpec {
    /// The box x ∈ [−length/2, length/2] particles must stay in.
    pub length: f64,
    /// The box's height y ∈ [0, height].
    pub height: f64,
    /// Particles across the drop's diameter, W/δr.
    pub resolution: usize,
    /// Gravity, per unit mass (unset: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_force: Option<[f64; 2]>,
    /// The impact speed U.
    pub velocity: Option<f64>,
    /// The no-slip plate y = 0 (default true).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plate: Option<bool>,
    /// θ in degrees, through the liquid, where the drop meets the plate (a sessile drop).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_angle: Option<f64>,
    pub drop: Option<DropTable>,
}

/// `[scene.drop]`.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DropTable {
    /// W.
    pub diameter: f64,
    /// Height of the drop's centre above the plate (default W). Below W/2 the drop is the
    /// part of the disc above the plate, resting on it (a sessile drop), built on the
    /// square lattice: rings cut by the plate would leave particles at any distance from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_height: Option<f64>,
    /// a/b of an ellipse of the disc's area, semi-axes a = R√k along x and b = R/√k
    /// (default 1: the disc).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect_ratio: Option<f64>,
    /// How the disc is filled: `rings` (default; concentric rings, whose outer ring is
    /// already the circle) or `square` (the lattice cut to the disc: a staircase surface,
    /// which surface tension must first round, the harder Laplace test).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lattice: Option<DropLattice>,
}

/// The particle arrangement of a free drop (`scene.drop.lattice`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum DropLattice {
    #[default]
    Rings,
    Square,
}

/// A validated drop scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Drop {
    pub bounds: SceneBox,
    pub body_force: Vec2,
    pub shape: DropShape,
    pub plate: bool,
    /// a/b of the initial ellipse (1: a disc).
    pub aspect_ratio: f64,
    /// θ (radians) at the plate.
    pub contact_angle: Option<f64>,
    pub lattice: DropLattice,
}

impl DropSpec {
    pub fn validate(&self) -> Result<Drop, FieldError> {
        let (length, height, resolution) = (self.length, self.height, self.resolution);
        let bounds = SceneBox {
            length,
            height,
            resolution,
        };
        let (body_force, speed) = open_scene(bounds, self.body_force, self.velocity)?;
        let d = self.drop.as_ref().ok_or_else(|| {
            field_err(
                "scene.drop",
                "required for a drop scene: [scene.drop] diameter = W",
            )
        })?;
        let w = positive("scene.drop.diameter", d.diameter)?;
        let centre_height = in_range(
            "scene.drop.centre_height",
            d.centre_height.unwrap_or(w),
            -0.5 * w,
            f64::MAX,
        )?;
        let aspect_ratio = positive("scene.drop.aspect_ratio", d.aspect_ratio.unwrap_or(1.0))?;
        let support = support_in_dr() * w / resolution as f64;
        // The ellipse's half extents a = R√k, b = R/√k.
        let (half_x, half_y) = (0.5 * w * aspect_ratio.sqrt(), 0.5 * w / aspect_ratio.sqrt());
        let plate = self.plate.unwrap_or(true);
        let dr = w / resolution as f64;
        let resting = centre_height - half_y < 0.5 * dr;
        if resting && !(plate && aspect_ratio == 1.0 && centre_height + half_y >= 4.0 * dr) {
            return Err(field_err(
                "scene.drop.centre_height",
                format!("a drop cut by the floor y = 0 (half height {half_y}, centre height {centre_height}) must be a disc resting on the plate, at least 4 spacings high"),
            ));
        }
        let contact_angle = self
            .contact_angle
            .map(|t| in_range("scene.contact_angle", t, 15.0, 165.0).map(f64::to_radians))
            .transpose()?;
        if contact_angle.is_some() && !plate {
            return Err(field_err(
                "scene.contact_angle",
                "a contact angle needs the plate (scene.plate = true)",
            ));
        }
        if 2.0 * (half_x + support) > length || centre_height + half_y + support > height {
            return Err(field_err(
                "scene.length",
                format!(
                    "the box {length} × {height} must hold the drop and a kernel support around it"
                ),
            ));
        }
        Ok(Drop {
            bounds: SceneBox {
                length,
                height,
                resolution,
            },
            body_force,
            shape: DropShape {
                centre: Vec2::new(0.0, centre_height),
                diameter: w,
                speed,
                plate,
            },
            plate,
            aspect_ratio,
            contact_angle,
            lattice: d.lattice.unwrap_or_default(),
        })
    }
}

impl Scene for Drop {
    fn kind(&self) -> &'static str {
        "drop"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    /// δr = W/resolution.
    fn spacing(&self) -> f64 {
        self.shape.diameter / self.bounds.resolution as f64
    }

    /// The diameter W (Re = ρUW/η0, De = λU/W).
    fn length_scale(&self) -> f64 {
        self.shape.diameter
    }

    /// The impact speed U; for a drop at rest, the larger of the capillary velocity
    /// √(σ/ρR) (the scale of its oscillation, ωR) and the free-fall speed √(|g|W).
    fn velocity_scale(&self, fluid: &Fluid) -> f64 {
        let radius = 0.5 * self.shape.diameter;
        let capillary = (fluid.surface_tension / (fluid.density * radius)).sqrt();
        let fall = (self.body_force.norm() * self.shape.diameter).sqrt();
        if self.shape.speed > 0.0 {
            self.shape.speed
        } else {
            capillary.max(fall)
        }
    }

    fn body_force(&self) -> Vec2 {
        self.body_force
    }

    fn particles(&self) -> usize {
        self.positions().len()
    }

    fn has_free_surface(&self) -> bool {
        true
    }

    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String> {
        let positions = self.positions();
        Ok(Setup {
            domain: open_domain(self.bounds.length, self.bounds.height),
            walls: if self.plate {
                vec![plate(scheme)]
            } else {
                Vec::new()
            },
            velocity: vec![Vec2::new(0.0, -self.shape.speed); positions.len()],
            positions,
            spacing: self.spacing(),
            fluid: *fluid,
            scheme: *scheme,
            body_force: self.body_force,
            drive: Drive::Constant,
            scales,
            free_surface: true,
            inflow: None,
            discs: Vec::new(),
            contact: None,
            gravity: Vec2::zeros(),
            contact_angle: self.contact_angle,
            resolution: Resolution::Uniform,
        })
    }

    fn reference(&self, _fluid: &Fluid) -> Result<Reference, String> {
        Err("no analytic solution for a drop impact (see drop.csv)".into())
    }

    /// The centre-of-mass vertical velocity.
    fn characteristic_velocity(&self, _positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        centre_of_mass_velocity(velocity)
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Centre-of-mass velocity", "v")
    }

    fn drop_shape(&self) -> Option<DropShape> {
        Some(self.shape)
    }

    fn contact_angle(&self) -> Option<f64> {
        self.contact_angle
    }
}

impl Drop {
    /// The disc's rings, stretched into the ellipse by the area-preserving map
    /// (x, y) → (x√k, y/√k) about the centre: every particle keeps its volume δr².
    fn positions(&self) -> Vec<Vec2> {
        let c = self.shape.centre;
        let (radius, dr) = (0.5 * self.shape.diameter, self.spacing());
        if c.y < radius + 0.5 * dr {
            return resting_cap(c, radius, dr);
        }
        let stretch = self.aspect_ratio.sqrt();
        let mut points = match self.lattice {
            DropLattice::Rings => disc(c, radius, dr),
            DropLattice::Square => square_disc(c, radius, dr),
        };
        if self.aspect_ratio != 1.0 {
            for p in points.iter_mut() {
                let r = *p - c;
                *p = c + Vec2::new(r.x * stretch, r.y / stretch);
            }
        }
        points
    }
}

/// The lattice points c + ((i + ½)δr, (j + ½)δr) within `radius` of c: the disc on the
/// square lattice, symmetric about both axes through c.
fn square_disc(centre: Vec2, radius: f64, dr: f64) -> Vec<Vec2> {
    let n = (radius / dr).ceil() as i64 + 1;
    (-n..n)
        .flat_map(|i| (-n..n).map(move |j| (i, j)))
        .map(|(i, j)| centre + Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
        .filter(|p| (p - centre).norm() <= radius)
        .collect()
}

/// The part of the disc of `radius` about `centre` above the plate y = 0, on the square
/// lattice ((i + ½)δr, (j + ½)δr) about x = centre.x.
fn resting_cap(centre: Vec2, radius: f64, dr: f64) -> Vec<Vec2> {
    let columns = (radius / dr).ceil() as i64 + 1;
    let rows = ((centre.y + radius) / dr).ceil() as i64;
    (-columns..columns)
        .flat_map(|i| (0..rows).map(move |j| (i, j)))
        .map(|(i, j)| Vec2::new(centre.x + (i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
        .filter(|p| (p - centre).norm() <= radius)
        .collect()
}
