//! A sphere between plates or turning (3D): `rotation.csv` (per output time: its spin Ω and
//! the fluid's torque T about its centre, [`crate::engine::bodies::sphere`]) and the `rotation`
//! entry of `summary.json`. With sliding plates, γ̇ = (u_top − u_bottom)/H and the fluid's
//! angular velocity in simple shear is −γ̇/2 about z:
//!
//! * `rotation_ratio`, Ω_z/(−γ̇/2) averaged over the second half of the run: 1 for a
//!   torque-free sphere in unbounded Newtonian shear (Stokes), below 1 with elasticity
//!   (Vázquez-Quesada & Ellero 2017, Fig. 2) and with confinement;
//! * `torque_ratio`, T_z/(8πη0a³(−γ̇/2 − Ω_z)) for a sphere held or turned at a given Ω: 1 in
//!   unbounded Newtonian Stokes flow, where T = 8πη0a³(ω − Ω).

use super::Probe;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::{self, Chart, Curve, CurveStyle, FigureFormat, PALETTE};
use crate::app::table::{self, fmt};
use crate::engine::bodies::sphere::{self, Turning};
use crate::engine::boundary::Sphere;
use crate::engine::dimension::Vector;
use crate::engine::step::Simulation;
use anyhow::{anyhow, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::Path;

/// One output time: a row of `rotation.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RotationRow {
    #[serde(serialize_with = "fmt::sci9")]
    pub t: f64,
    /// Ω.
    #[serde(serialize_with = "fmt::sci9")]
    pub spin_x: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub spin_y: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub spin_z: f64,
    /// The fluid's torque T about the centre.
    #[serde(serialize_with = "fmt::sci9")]
    pub torque_x: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub torque_y: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub torque_z: f64,
}

/// `summary.json`'s `rotation` entry.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RotationSummary {
    /// γ̇ of the plates (None: they do not shear).
    pub shear_rate: Option<f64>,
    /// Mean Ω_z/(−γ̇/2) over the second half of the run.
    pub rotation_ratio: Option<f64>,
    /// Mean T_z/(8πη0a³(−γ̇/2 − Ω_z)) over the second half of the run (None for a free
    /// sphere, whose torque vanishes).
    pub torque_ratio: Option<f64>,
    pub final_spin: [f64; 3],
    pub final_torque: [f64; 3],
}

/// The rotation probe.
pub struct RotationProbe {
    sphere: Sphere,
    shear_rate: Option<f64>,
    rows: Vec<RotationRow>,
}

impl RotationProbe {
    pub fn new(sphere: Sphere, shear_rate: Option<f64>) -> Self {
        Self {
            sphere,
            shear_rate,
            rows: Vec::new(),
        }
    }

    fn summary(&self, viscosity: f64, free: bool) -> RotationSummary {
        let t_end = self.rows.last().map_or(0.0, |r| r.t);
        let late: Vec<&RotationRow> = self.rows.iter().filter(|r| r.t >= 0.5 * t_end).collect();
        let mean = |f: &dyn Fn(&RotationRow) -> f64| {
            (!late.is_empty()).then(|| late.iter().map(|r| f(r)).sum::<f64>() / late.len() as f64)
        };
        let stokes = 8.0 * PI * viscosity * self.sphere.radius.powi(3);
        let last = self.rows.last().copied().unwrap_or_default();
        RotationSummary {
            shear_rate: self.shear_rate,
            rotation_ratio: self
                .shear_rate
                .and_then(|g| mean(&|r| r.spin_z / (-0.5 * g))),
            torque_ratio: self
                .shear_rate
                .filter(|_| !free)
                .and_then(|g| mean(&|r| r.torque_z / (stokes * (-0.5 * g - r.spin_z)))),
            final_spin: [last.spin_x, last.spin_y, last.spin_z],
            final_torque: [last.torque_x, last.torque_y, last.torque_z],
        }
    }

    /// `rotation.png`: Ω_z (over −γ̇/2 with sliding plates) against time.
    fn chart(&self, dir: &Path, format: FigureFormat) -> Result<()> {
        let scale = self.shear_rate.map_or(1.0, |g| -0.5 * g);
        let curve = Curve {
            label: "sphere".into(),
            points: self.rows.iter().map(|r| (r.t, r.spin_z / scale)).collect(),
            style: CurveStyle::Line,
            color: PALETTE[0],
        };
        let y_label = match self.shear_rate {
            Some(_) => "spin / (-shear rate / 2)",
            None => "spin (z)",
        };
        plot::draw(
            &dir.join("rotation.png"),
            format,
            &Chart {
                title: "Sphere rotation".into(),
                x_label: "t".into(),
                y_label: y_label.into(),
                ..Default::default()
            },
            &[curve],
        )
    }
}

impl Probe<3> for RotationProbe {
    fn name(&self) -> &'static str {
        "rotation"
    }

    /// Ω and the torque the step took (a turning sphere's), or the torque on the held
    /// sphere now; NaN where its fits fail.
    fn record(&mut self, sim: &mut Simulation<3>, _rows: &[SeriesRow]) {
        let (spin, torque) = match sim.turning_sphere() {
            Some(s) => (s.spin, s.torque),
            None => {
                let zero = Vector::<3>::zeros();
                let t = sphere::torque(sim.sphere_view(), &self.sphere, zero);
                (zero, t.unwrap_or(Vector::<3>::repeat(f64::NAN)))
            }
        };
        self.rows.push(RotationRow {
            t: sim.state.time,
            spin_x: spin.x,
            spin_y: spin.y,
            spin_z: spin.z,
            torque_x: torque.x,
            torque_y: torque.y,
            torque_z: torque.z,
        });
    }

    fn write(&self, dir: &Path) -> Result<()> {
        io::write_atomic(
            &dir.join("rotation.csv"),
            table::write_rows(&self.rows).as_bytes(),
        )
    }

    /// The rows up to `t` from `rotation.csv`.
    fn restore(&mut self, dir: &Path, t: f64, _state: Option<&serde_json::Value>) -> Result<()> {
        self.rows = super::rows_until(&dir.join("rotation.csv"), t, |r: &RotationRow| r.t)
            .map_err(|e| anyhow!("restoring the sphere's rotation: {e}"))?;
        Ok(())
    }

    fn finish(
        &mut self,
        sim: &mut Simulation<3>,
        _rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        if let Some(format) = charts {
            self.chart(dir, format)?;
        }
        let free = sim
            .turning_sphere()
            .is_some_and(|s| s.turning == Turning::Free);
        let summary = self.summary(sim.fluid.viscosity, free);
        Ok(Some(serde_json::to_value(summary)?))
    }
}
