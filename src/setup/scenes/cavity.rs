//! The lid-driven cavity: a square box of side L with no-slip walls on three sides and a lid
//! at y = L sliding along x, the viscoelastic benchmark of Fattal & Kupferman (2005) with
//! their regularised lid u_w = 16U(x/L)²(1 − x/L)² (or a uniform lid). The four corners
//! carry point-reflected ghosts ([`crate::engine::boundary::Corner`]).

use super::{check_box, check_memory, Scene, SceneBox};
use crate::analysis::reference::Reference;
use crate::engine::boundary::{Plane, RegularisedLid, Shape, Wall};
use crate::engine::drive::Drive;
use crate::engine::lattice::lattice;
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::resolution::Resolution;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{Scales, Setup};
use crate::setup::error::{field_err, positive, FieldError};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// `[scene]` of `kind = "cavity"`: the lid-driven square cavity, its lid moving along x at
/// y = L (`cases/lid-driven-cavity.toml`).
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CavitySpec {
    /// The side L.
    pub size: f64,
    /// Particles across the side, L/δr.
    pub resolution: usize,
    /// U: the lid's speed (at x = L/2 for the regularised lid).
    pub lid_velocity: f64,
    /// `regularised` (default) or `uniform`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lid: Option<String>,
}

/// The lid's profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lid {
    Regularised,
    Uniform,
}

/// A validated cavity.
#[derive(Clone, Debug, PartialEq)]
pub struct Cavity {
    pub bounds: SceneBox,
    pub lid_velocity: f64,
    pub lid: Lid,
}

impl CavitySpec {
    pub fn validate(&self) -> Result<Cavity, FieldError> {
        check_box(self.size, self.size, self.resolution)?;
        check_memory((self.resolution as f64).powi(2))?;
        let lid = match self.lid.as_deref().unwrap_or("regularised") {
            "regularised" => Lid::Regularised,
            "uniform" => Lid::Uniform,
            other => {
                return Err(field_err(
                    "scene.lid",
                    format!("expected `regularised` or `uniform`, got `{other}`"),
                ))
            }
        };
        Ok(Cavity {
            bounds: SceneBox {
                length: self.size,
                height: self.size,
                resolution: self.resolution,
            },
            lid_velocity: positive("scene.lid_velocity", self.lid_velocity)?,
            lid,
        })
    }
}

impl Cavity {
    /// The four walls (bottom, left, right, lid) and the four corners between them.
    fn walls(&self, scheme: &Scheme) -> Vec<Wall> {
        let l = self.bounds.length;
        let tensor = scheme.wall_conformation;
        let plane = |axis, position, fluid_side| {
            Shape::Plane(Plane {
                axis,
                position,
                fluid_side,
            })
        };
        let lid = match self.lid {
            Lid::Uniform => {
                Wall::sliding(plane(1, l, -1.0), tensor, Vec2::new(self.lid_velocity, 0.0))
            }
            Lid::Regularised => Wall {
                shape: plane(1, l, -1.0),
                condition: Arc::new(RegularisedLid {
                    tensor,
                    speed: self.lid_velocity,
                    length: l,
                }),
                contact_angle: None,
            },
        };
        let bottom = Wall::no_slip(plane(1, 0.0, 1.0), tensor);
        let left = Wall::no_slip(plane(0, 0.0, 1.0), tensor);
        let right = Wall::no_slip(plane(0, l, -1.0), tensor);
        let corners = [
            (&bottom, &left),
            (&bottom, &right),
            (&lid, &left),
            (&lid, &right),
        ]
        .map(|(a, b)| Wall::corner(a, b).expect("perpendicular planes meet in a corner"));
        let mut walls = vec![bottom, left, right, lid];
        walls.extend(corners);
        walls
    }
}

impl Scene for Cavity {
    fn kind(&self) -> &'static str {
        "cavity"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    fn velocity_scale(&self, _fluid: &Fluid) -> f64 {
        self.lid_velocity
    }

    fn body_force(&self) -> Vec2 {
        Vec2::zeros()
    }

    fn particles(&self) -> usize {
        self.bounds.resolution.pow(2)
    }

    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String> {
        let n = self.bounds.resolution;
        let positions = lattice(n, n, self.spacing());
        let l = self.bounds.length;
        Ok(Setup {
            domain: Domain {
                min: Vec2::zeros(),
                max: Vec2::new(l, l),
                periodic: [false, false],
            },
            walls: self.walls(scheme),
            velocity: vec![Vec2::zeros(); positions.len()],
            positions,
            spacing: self.spacing(),
            fluid: *fluid,
            scheme: *scheme,
            body_force: Vec2::zeros(),
            drive: Drive::Constant,
            scales,
            free_surface: false,
            inflow: None,
            discs: Vec::new(),
            contact: None,
            gravity: Vec2::zeros(),
            contact_angle: None,
            resolution: Resolution::Uniform,
        })
    }

    fn reference(&self, _fluid: &Fluid) -> Result<Reference, String> {
        Err("no analytic solution for the lid-driven cavity (the cavity probe compares the Stokes flow with its finite-difference solution)".into())
    }

    /// u at the cavity's centre: the mean over the particles within δr of it.
    fn characteristic_velocity(&self, positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        let c = Vec2::new(0.5 * self.bounds.length, 0.5 * self.bounds.height);
        let dr = self.spacing();
        let (sum, count) = positions
            .iter()
            .zip(velocity)
            .filter(|(p, _)| (*p - c).norm() < dr)
            .fold((0.0, 0usize), |(s, k), (_, u)| (s + u.x, k + 1));
        sum / count.max(1) as f64
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Velocity at the cavity's centre", "u(L/2, L/2)")
    }

    fn cavity(&self) -> Option<(f64, bool)> {
        Some((self.lid_velocity, self.lid == Lid::Regularised))
    }

    fn has_corners(&self) -> bool {
        true
    }
}
