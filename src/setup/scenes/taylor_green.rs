//! The Taylor–Green vortex: a doubly periodic square box, no walls, decaying freely from
//! u = U(−cos kx sin ky, sin kx cos ky), k = 2π/L.

use super::{check_box, check_memory, check_periodic_length, Scene, SceneBox};
use crate::analysis::analytic::taylor_green;
use crate::analysis::reference::Reference;
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

/// `[scene]` of `kind = "taylor-green"`: the decaying Taylor–Green vortex in a doubly
/// periodic square box.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TaylorGreenSpec {
    /// The box side (length = height).
    pub length: f64,
    /// Equal to `length`.
    pub height: f64,
    /// Particles across the box.
    pub resolution: usize,
    /// The initial amplitude U.
    pub velocity: Option<f64>,
    /// Refused unless zero: the vortex decays freely.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_force: Option<[f64; 2]>,
}

/// A validated Taylor–Green box.
#[derive(Clone, Debug, PartialEq)]
pub struct TaylorGreen {
    pub bounds: SceneBox,
    columns: usize,
    /// The initial amplitude U.
    pub velocity: f64,
}

impl TaylorGreenSpec {
    pub fn validate(&self) -> Result<TaylorGreen, FieldError> {
        check_box(self.length, self.height, self.resolution)?;
        let columns = check_periodic_length(self.length, self.height, self.resolution)?;
        check_memory(columns as f64 * self.resolution as f64)?;
        if self.body_force.is_some_and(|g| g != [0.0, 0.0]) {
            return Err(field_err(
                "scene.body_force",
                "the Taylor–Green vortex decays freely: no body force",
            ));
        }
        if (self.length - self.height).abs() > 1e-12 * self.height {
            return Err(field_err(
                "scene.length",
                "the Taylor–Green box is square: length = height",
            ));
        }
        let u0 = self
            .velocity
            .ok_or_else(|| field_err("scene.velocity", "required for taylor-green"))?;
        Ok(TaylorGreen {
            bounds: SceneBox {
                length: self.length,
                height: self.height,
                resolution: self.resolution,
            },
            columns,
            velocity: positive("scene.velocity", u0)?,
        })
    }
}

impl Scene for TaylorGreen {
    fn kind(&self) -> &'static str {
        "taylor-green"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    fn velocity_scale(&self, _fluid: &Fluid) -> f64 {
        self.velocity
    }

    fn body_force(&self) -> Vec2 {
        Vec2::zeros()
    }

    fn periodic(&self) -> [bool; 2] {
        [true, true]
    }

    fn particles(&self) -> usize {
        self.columns * self.bounds.resolution
    }

    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String> {
        let positions = lattice(self.columns, self.bounds.resolution, self.spacing());
        let velocity = positions
            .iter()
            .map(|p| taylor_green::velocity(p, self.bounds.length, self.velocity))
            .collect();
        Ok(Setup {
            domain: Domain {
                min: Vec2::zeros(),
                max: Vec2::new(self.bounds.length, self.bounds.height),
                periodic: [true, true],
            },
            walls: Vec::new(),
            positions,
            velocity,
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

    fn reference(&self, fluid: &Fluid) -> Result<Reference, String> {
        Reference::taylor_green(fluid, self.bounds.length, self.velocity)
    }

    /// The amplitude: the projection 2 mean(u·û) on the unit-amplitude mode û.
    fn characteristic_velocity(&self, positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        taylor_green::amplitude(positions, velocity, self.bounds.length)
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Taylor-Green amplitude", "amplitude")
    }
}
