//! Rigid discs: `disc.csv` (per disc and output time: centre, velocity, spin, the fluid's
//! force and torque, the contact force)
//! and the `discs` entry of `summary.json`: per disc its `rotation_ratio`, the mean over the
//! second half of the run of Ω/(−γ̇/2), with γ̇ = (u_top − u_bottom)/H the walls' shear rate
//! (a torque-free disc in unbounded simple shear turns with the fluid's angular velocity
//! −γ̇/2: ratio 1), and its final position and velocity.

use super::Probe;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::{self, Chart, Curve, CurveStyle, FigureFormat, PALETTE};
use crate::app::table::{self, fmt};
use crate::engine::step::Simulation;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One disc at one output time: a row of `disc.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DiscRow {
    #[serde(serialize_with = "fmt::sci9")]
    pub t: f64,
    pub disc: usize,
    /// The centre.
    #[serde(serialize_with = "fmt::sci9")]
    pub x: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub y: f64,
    /// The disc's velocity V and spin Ω.
    #[serde(serialize_with = "fmt::sci9")]
    pub vx: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub vy: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub spin: f64,
    /// The fluid's force F and torque T on the disc.
    #[serde(serialize_with = "fmt::sci9")]
    pub fx: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub fy: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub torque: f64,
    /// The contact force C (other discs and walls).
    #[serde(serialize_with = "fmt::sci9")]
    pub contact_x: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub contact_y: f64,
}

/// The summary of one disc.
#[derive(Clone, Debug, Serialize)]
pub struct DiscSummary {
    /// Mean Ω/(−γ̇/2) over the second half of the run (None without a wall shear).
    pub rotation_ratio: Option<f64>,
    pub final_centre: [f64; 2],
    pub final_velocity: [f64; 2],
    pub final_spin: f64,
}

/// The disc probe of a run.
pub struct DiscProbe {
    shear_rate: Option<f64>,
    pub rows: Vec<DiscRow>,
}

impl DiscProbe {
    pub fn new(shear_rate: Option<f64>) -> Self {
        Self {
            shear_rate,
            rows: Vec::new(),
        }
    }

    pub fn csv(&self) -> String {
        table::write_rows(&self.rows)
    }

    fn discs(&self) -> usize {
        self.rows.iter().map(|r| r.disc + 1).max().unwrap_or(0)
    }

    pub fn summary(&self) -> Vec<DiscSummary> {
        let t_end = self.rows.last().map_or(0.0, |r| r.t);
        (0..self.discs())
            .map(|k| {
                let rows: Vec<&DiscRow> = self.rows.iter().filter(|r| r.disc == k).collect();
                let last = |f: fn(&DiscRow) -> f64| rows.last().map_or(f64::NAN, |r| f(r));
                let late: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.t >= 0.5 * t_end)
                    .map(|r| r.spin)
                    .collect();
                DiscSummary {
                    rotation_ratio: self
                        .shear_rate
                        .filter(|_| !late.is_empty())
                        .map(|g| late.iter().sum::<f64>() / late.len() as f64 / (-0.5 * g)),
                    final_centre: [last(|r| r.x), last(|r| r.y)],
                    final_velocity: [last(|r| r.vx), last(|r| r.vy)],
                    final_spin: last(|r| r.spin),
                }
            })
            .collect()
    }

    /// `disc.png`: each disc's spin (over −γ̇/2 with a wall shear) against time.
    fn charts(&self, dir: &Path, format: FigureFormat) -> Result<()> {
        let scale = self.shear_rate.map_or(1.0, |g| -0.5 * g);
        let curves: Vec<Curve> = (0..self.discs())
            .map(|k| Curve {
                label: format!("disc {k}"),
                points: self
                    .rows
                    .iter()
                    .filter(|r| r.disc == k)
                    .map(|r| (r.t, r.spin / scale))
                    .collect(),
                style: CurveStyle::Line,
                color: PALETTE[k % PALETTE.len()],
            })
            .collect();
        let y_label = if self.shear_rate.is_some() {
            "spin / (-shear rate / 2)"
        } else {
            "spin"
        };
        plot::draw(
            &dir.join("disc.png"),
            format,
            &Chart {
                title: "Disc rotation".into(),
                x_label: "t".into(),
                y_label: y_label.into(),
                ..Default::default()
            },
            &curves,
        )
    }
}

impl Probe for DiscProbe {
    fn name(&self) -> &'static str {
        "discs"
    }

    fn record(&mut self, sim: &mut Simulation, _rows: &[SeriesRow]) {
        let t = sim.state.time;
        let bodies = sim.bodies();
        let loads = bodies.loads.iter().zip(&bodies.contact_forces);
        for (k, (d, (load, contact))) in bodies.discs.iter().zip(loads).enumerate() {
            let f = load.force.total();
            let c = d.circle.centre;
            self.rows.push(DiscRow {
                t,
                disc: k,
                x: c.x,
                y: c.y,
                vx: d.velocity.x,
                vy: d.velocity.y,
                spin: d.spin,
                fx: f.x,
                fy: f.y,
                torque: load.torque(),
                contact_x: contact.x,
                contact_y: contact.y,
            });
        }
    }

    fn write(&self, dir: &Path) -> Result<()> {
        io::write_atomic(&dir.join("disc.csv"), self.csv().as_bytes())
    }

    /// The rows up to `t` from `disc.csv`.
    fn restore(&mut self, dir: &Path, t: f64, _state: Option<&serde_json::Value>) -> Result<()> {
        self.rows = super::rows_until(&dir.join("disc.csv"), t, |r: &DiscRow| r.t)?;
        Ok(())
    }

    fn finish(
        &mut self,
        _sim: &mut Simulation,
        _rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        if let Some(format) = charts {
            self.charts(dir, format)?;
        }
        Ok(Some(serde_json::to_value(self.summary())?))
    }
}
