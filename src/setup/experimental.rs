//! `[experimental]`: variants that no study of ours has shown to win on two shipped cases.
//! Each fixes one case's failure or was tried on one scene; they stay available, outside the
//! scheme's tables, and `rheosph check` and every run name the ones a case sets in one line.
//! A variant moves to its stage's table when it wins a measured comparison on two shipped
//! cases, or goes (its finding in the decision log) when it loses one.

use crate::engine::free_surface::{
    ContactAngleAt, ContactCurvature, ContactRows, SurfaceGradient, SurfaceIndicator, SurfaceShear,
};
use crate::engine::kinematics::GradientChoice;
use crate::engine::operators::PpeLaplacian;
use serde::{Deserialize, Serialize};

/// The experimental variants a case sets (unset: the stage's default).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ExperimentalSpec {
    /// The PPE's Laplacian made exact for linear fields where a free surface truncates the
    /// support (`linear-exact`): keeps a pool's volume, breaks down at a drop's impact.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ppe_laplacian: Option<PpeLaplacian>,
    /// α of the PPE's density-invariant source (Asai et al. 2012), which restores drifted
    /// particle volumes; set by the capillary-rise case only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_relaxation: Option<f64>,
    /// The velocity gradient the conformation update sees (`solenoidal`, `wall-normal-even`,
    /// `raw`) where the scene's `auto` would choose otherwise; set by the jet only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_gradient: Option<GradientChoice>,
    /// The free-surface pressure's velocity gradient over the particle's own side of the
    /// surface (`own-side`); set by the jet only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_gradient: Option<SurfaceGradient>,
    /// The PPE row of a surface particle at a wall: `wall` or `held`; the jet sets `held`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_rows: Option<ContactRows>,
    /// A surface membership blended over a tenth of (36)'s margin (`blended`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_indicator: Option<SurfaceIndicator>,
    /// The shear-free condition's flux on free-surface rows (`shear-free`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_shear: Option<SurfaceShear>,
    /// A contact particle's own curvature from the circle leaving the wall at θ (`turn`);
    /// set by the capillary-rise case only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_curvature: Option<ContactCurvature>,
    /// The contact angle held by the surface half a spacing beyond the centres (`surface`);
    /// set by the capillary-rise case only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_angle_at: Option<ContactAngleAt>,
}

impl ExperimentalSpec {
    /// The ranges of the numeric variants.
    pub fn validate(&self) -> Result<(), crate::setup::error::FieldError> {
        if let Some(alpha) = self.volume_relaxation {
            crate::setup::error::in_range("experimental.volume_relaxation", alpha, 0.0, 1.0)?;
        }
        Ok(())
    }

    /// Whether no variant is set.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// The variants set, `key = value`, for the one line a check or a run prints.
    pub fn flagged(&self) -> Vec<String> {
        let table = toml::Table::try_from(self).unwrap_or_default();
        table.iter().map(|(k, v)| format!("{k} = {v}")).collect()
    }
}
