//! A jet fed through an orifice onto a no-slip plate (King & Lind §IV D): an orifice of width
//! D centred on x = 0 at `orifice_height` above the plate y = 0, fed downwards at U0 through
//! an inflow buffer, in an open box x ∈ [−length/2, length/2], y ∈ [0, height].

use super::{
    centre_of_mass_velocity, open_domain, open_scene, plate, support_in_dr, JetShape, Scene,
    SceneBox,
};
use crate::analysis::reference::Reference;
use crate::engine::boundary::inflow::{Inflow, BUFFER_ROWS};
use crate::engine::drive::Drive;
use crate::engine::math::Vec2;
use crate::engine::resolution::Resolution;
use crate::engine::rheology::Fluid;
use crate::engine::scheme::Scheme;
use crate::engine::step::{Scales, Setup};
use crate::setup::error::{field_err, positive, FieldError};
use serde::{Deserialize, Serialize};

/// `[scene]` of `kind = "jet"`: a jet from an orifice onto a no-slip plate at y = 0, fed by
/// an inflow buffer (jet buckling); `resolution` is D/δr, `velocity` the inflow speed U0,
/// `body_force` gravity.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JetSpec {
    /// The box x ∈ [−length/2, length/2] particles must stay in.
    pub length: f64,
    /// The box's height y ∈ [0, height], the plate at y = 0.
    pub height: f64,
    /// Particles across the orifice, D/δr.
    pub resolution: usize,
    /// Gravity, per unit mass (unset: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_force: Option<[f64; 2]>,
    /// The inflow speed U0.
    pub velocity: Option<f64>,
    pub jet: Option<JetTable>,
}

/// `[scene.jet]`.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JetTable {
    /// D.
    pub width: f64,
    /// The orifice's height above the plate, where the inflow buffer feeds the jet.
    pub orifice_height: f64,
}

/// A validated jet scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Jet {
    pub bounds: SceneBox,
    pub body_force: Vec2,
    /// U0.
    pub speed: f64,
    pub shape: JetShape,
}

impl JetSpec {
    pub fn validate(&self) -> Result<Jet, FieldError> {
        let (length, height, resolution) = (self.length, self.height, self.resolution);
        let bounds = SceneBox {
            length,
            height,
            resolution,
        };
        let (body_force, speed) = open_scene(bounds, self.body_force, self.velocity)?;
        let j = self.jet.as_ref().ok_or_else(|| {
            field_err(
                "scene.jet",
                "required for a jet scene: [scene.jet] width = D, orifice_height = H",
            )
        })?;
        let d = positive("scene.jet.width", j.width)?;
        let orifice = positive("scene.jet.orifice_height", j.orifice_height)?;
        let dr = d / resolution as f64;
        let top = orifice + (BUFFER_ROWS as f64 + support_in_dr()) * dr;
        if top > height {
            return Err(field_err(
                "scene.height",
                format!("the box must hold the orifice, its inflow buffer and a kernel support: at least {top}"),
            ));
        }
        if d + 2.0 * support_in_dr() * dr > length {
            return Err(field_err(
                "scene.length",
                "the box must be wider than the jet and a kernel support each side",
            ));
        }
        if speed <= 0.0 {
            return Err(field_err(
                "scene.velocity",
                "a jet's inflow speed must be positive",
            ));
        }
        Ok(Jet {
            bounds: SceneBox {
                length,
                height,
                resolution,
            },
            body_force,
            speed,
            shape: JetShape {
                width: d,
                orifice_height: orifice,
            },
        })
    }
}

impl Scene for Jet {
    fn kind(&self) -> &'static str {
        "jet"
    }

    fn bounds(&self) -> SceneBox {
        self.bounds
    }

    /// δr = D/resolution.
    fn spacing(&self) -> f64 {
        self.shape.width / self.bounds.resolution as f64
    }

    /// The width D (Wi = λU0/D).
    fn length_scale(&self) -> f64 {
        self.shape.width
    }

    fn velocity_scale(&self, _fluid: &Fluid) -> f64 {
        self.speed
    }

    fn body_force(&self) -> Vec2 {
        self.body_force
    }

    /// The initial inflow buffer (it grows as the jet runs).
    fn particles(&self) -> usize {
        self.bounds.resolution * BUFFER_ROWS
    }

    fn has_free_surface(&self) -> bool {
        true
    }

    fn build(&self, fluid: &Fluid, scheme: &Scheme, scales: Scales) -> Result<Setup, String> {
        let s = &self.shape;
        let (inflow, positions) =
            Inflow::new(0.0, s.width, s.orifice_height, self.speed, self.spacing());
        Ok(Setup {
            domain: open_domain(self.bounds.length, self.bounds.height),
            walls: vec![plate(scheme)],
            velocity: vec![Vec2::new(0.0, -self.speed); positions.len()],
            positions,
            spacing: self.spacing(),
            fluid: *fluid,
            scheme: *scheme,
            body_force: self.body_force,
            drive: Drive::Constant,
            scales,
            free_surface: true,
            inflow: Some(inflow),
            discs: Vec::new(),
            contact: None,
            gravity: Vec2::zeros(),
            contact_angle: None,
            resolution: Resolution::Uniform,
        })
    }

    fn reference(&self, _fluid: &Fluid) -> Result<Reference, String> {
        Err("no analytic solution for a buckling jet (see jet.csv)".into())
    }

    /// The centre-of-mass vertical velocity.
    fn characteristic_velocity(&self, _positions: &[Vec2], velocity: &[Vec2]) -> f64 {
        centre_of_mass_velocity(velocity)
    }

    fn characteristic_name(&self) -> (&'static str, &'static str) {
        ("Centre-of-mass velocity", "v")
    }

    fn jet_shape(&self) -> Option<JetShape> {
        Some(self.shape)
    }
}
