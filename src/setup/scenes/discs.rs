//! `[[scene.discs]]`: rigid discs in a channel (see [`crate::engine::bodies`]), each with its
//! motion: `fixed`, `prescribed` (constant `velocity` and `spin`: towed or turned),
//! `free-rotation` (centre held, spin free) or `free` (translating and spinning under the
//! fluid's load; `density_ratio` ρ_s/ρ_f).

use super::circle_in_box;
use crate::engine::bodies::contact::{Contact, Lubrication, Repulsion};
use crate::engine::bodies::{Disc, Motion};
use crate::engine::boundary::Circle;
use crate::engine::math::Vec2;
use crate::setup::error::{field_err, positive, FieldError};
use crate::setup::scenes::SceneBox;
use serde::{Deserialize, Serialize};

/// One `[[scene.discs]]` table.
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiscSpec {
    /// R. Each disc keeps one kernel support from the walls and the other discs (the run
    /// stops with a reason if one comes closer) unless `[scene.contact]` has lubrication or
    /// the exponential repulsion, when only an overlap stops it. Lagrangian frame only.
    pub radius: f64,
    /// [x, y] at the start.
    pub centre: [f64; 2],
    /// `fixed`, `prescribed`, `free-rotation` or `free` (default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
    /// V: constant when prescribed, initial when free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[f64; 2]>,
    /// Ω (counter-clockwise): constant when prescribed, initial when free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spin: Option<f64>,
    /// ρ_s/ρ_f (default 1, neutrally buoyant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_ratio: Option<f64>,
    /// The added mass the staggered coupling assumes, in units of ρ_f πR² (default 1, the
    /// unbounded disc's; more where discs crowd each other in a closed box).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling_added_mass: Option<f64>,
}

/// A validated disc; its density is `density_ratio` times the fluid's, set at build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscPlan {
    pub circle: Circle,
    pub velocity: Vec2,
    pub spin: f64,
    pub density_ratio: f64,
    pub motion: Motion,
    pub coupling_added_mass: f64,
}

impl DiscPlan {
    pub fn disc(&self, fluid_density: f64) -> Disc {
        Disc {
            circle: self.circle,
            velocity: self.velocity,
            spin: self.spin,
            density: self.density_ratio * fluid_density,
            motion: self.motion,
            acceleration: Vec2::zeros(),
            coupling_added_mass: self.coupling_added_mass,
        }
    }

    /// Whether its mirrors must follow it (it moves or may move).
    pub fn moves(&self) -> bool {
        self.motion != Motion::Prescribed || self.velocity != Vec2::zeros()
    }
}

impl DiscSpec {
    pub fn validate(&self, k: usize, bounds: SceneBox) -> Result<DiscPlan, FieldError> {
        let field = format!("scene.discs[{k}]");
        let circle = circle_in_box(&field, self.radius, self.centre, bounds)?;
        let motion = match self.motion.as_deref().unwrap_or("free") {
            "fixed" | "prescribed" => Motion::Prescribed,
            "free-rotation" => Motion::FreeRotation,
            "free" => Motion::Free,
            other => {
                return Err(field_err(
                    &format!("{field}.motion"),
                    format!(
                        "expected `fixed`, `prescribed`, `free-rotation` or `free`, got `{other}`"
                    ),
                ))
            }
        };
        let fixed = self.motion.as_deref() == Some("fixed");
        if fixed && (self.velocity.is_some() || self.spin.is_some()) {
            return Err(field_err(
                &format!("{field}.motion"),
                "a fixed disc has no velocity or spin (use `prescribed`)",
            ));
        }
        let velocity = self.velocity.unwrap_or([0.0, 0.0]);
        let spin = self.spin.unwrap_or(0.0);
        if !velocity.iter().all(|v| v.is_finite()) {
            return Err(field_err(&format!("{field}.velocity"), "must be finite"));
        }
        if !spin.is_finite() {
            return Err(field_err(&format!("{field}.spin"), "must be finite"));
        }
        let density_ratio = match self.density_ratio {
            None => 1.0,
            Some(r) => positive(&format!("{field}.density_ratio"), r)?,
        };
        if motion == Motion::Free && density_ratio < 1.0 {
            return Err(field_err(
                &format!("{field}.density_ratio"),
                format!("a free disc lighter than the fluid ({density_ratio}) meets the added-mass instability of the explicit coupling; at least 1"),
            ));
        }
        let coupling_added_mass = match self.coupling_added_mass {
            None => 1.0,
            Some(c) if c.is_finite() && c >= 1.0 => c,
            Some(c) => {
                return Err(field_err(
                    &format!("{field}.coupling_added_mass"),
                    format!("the coupling's added mass in units of rho_f pi R^2 must be at least 1 (the unbounded disc's), got {c}"),
                ))
            }
        };
        Ok(DiscPlan {
            circle,
            velocity: Vec2::new(velocity[0], velocity[1]),
            spin,
            density_ratio,
            motion,
            coupling_added_mass,
        })
    }
}

/// The discs must not overlap each other or the cylinder (one kernel support apart).
pub fn check_apart(
    discs: &[DiscPlan],
    cylinder: Option<Circle>,
    support: f64,
) -> Result<(), FieldError> {
    let circles: Vec<Circle> = discs.iter().map(|d| d.circle).chain(cylinder).collect();
    for (a, ca) in circles.iter().enumerate() {
        for cb in &circles[a + 1..] {
            if (ca.centre - cb.centre).norm() < ca.radius + cb.radius + support {
                return Err(field_err(
                    &format!("scene.discs[{a}].centre"),
                    format!("closer than one kernel support ({support:.4}) to another disc or the cylinder"),
                ));
            }
        }
    }
    Ok(())
}

/// `[scene.contact]`: the discs' short-range repulsion and lubrication (see
/// [`crate::engine::bodies::contact`]).
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// F₀: force per unit length at contact (`quadratic`), or the seed's F_rep (`exponential`,
    /// force F₀/s at gaps s ≪ 1/τ).
    pub strength: f64,
    /// `quadratic` (default) or `exponential` (Vázquez-Quesada & Ellero 2017, eq. (9)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repulsion: Option<RepulsionKind>,
    /// `quadratic`: ℓ, the gap below which it acts (default two kernel supports);
    /// `exponential`: the decay length 1/τ (default 0.01 of the smallest disc radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<f64>,
    /// The normal lubrication force below `lubrication_cutoff` (default off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lubrication: Option<bool>,
    /// s_c, the gap below which the particles no longer resolve the squeeze flow (default
    /// one kernel support).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lubrication_cutoff: Option<f64>,
}

/// The repulsion's law (see [`Repulsion`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum RepulsionKind {
    Quadratic,
    Exponential,
}

impl ContactSpec {
    /// Without a model for closer gaps the run stops when a gap falls below one kernel
    /// `support` (mirrors of a narrower gap miss the fluid beyond it), so the quadratic
    /// repulsion alone must reach further.
    pub fn validate(&self, support: f64, discs: &[DiscPlan]) -> Result<Contact, FieldError> {
        if discs.is_empty() {
            return Err(field_err(
                "scene.contact",
                "there are no [[scene.discs]] to keep apart",
            ));
        }
        let strength = positive("scene.contact.strength", self.strength)?;
        let lubrication = match self.lubrication {
            Some(true) => Some(Lubrication {
                cutoff: positive(
                    "scene.contact.lubrication_cutoff",
                    self.lubrication_cutoff.unwrap_or(support),
                )?,
            }),
            _ if self.lubrication_cutoff.is_some() => {
                return Err(field_err(
                    "scene.contact.lubrication_cutoff",
                    "needs scene.contact.lubrication = true",
                ))
            }
            _ => None,
        };
        let repulsion = match self.repulsion.unwrap_or(RepulsionKind::Quadratic) {
            RepulsionKind::Quadratic => {
                let range = self.range.unwrap_or(2.0 * support);
                let floor = if lubrication.is_some() { 0.0 } else { support };
                if range.is_nan() || range <= floor || !range.is_finite() {
                    return Err(field_err(
                        "scene.contact.range",
                        format!("must exceed {floor:.4} (one kernel support without lubrication, where the run stops), got {range}"),
                    ));
                }
                Repulsion::Quadratic { strength, range }
            }
            RepulsionKind::Exponential => {
                let smallest = discs
                    .iter()
                    .map(|d| d.circle.radius)
                    .fold(f64::MAX, f64::min);
                let decay = positive("scene.contact.range", self.range.unwrap_or(0.01 * smallest))?;
                Repulsion::Exponential { strength, decay }
            }
        };
        Ok(Contact {
            repulsion,
            lubrication,
        })
    }
}
