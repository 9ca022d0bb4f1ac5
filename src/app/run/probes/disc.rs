//! Rigid discs: `disc.csv` (per disc and output time: centre, velocity, spin, the fluid's
//! force and torque, the contact force)
//! and the `discs` entry of `summary.json`: per disc its `rotation_ratio`, the mean over the
//! second half of the run of Ω/(−γ̇/2), with γ̇ = (u_top − u_bottom)/H the walls' shear rate
//! (a torque-free disc in unbounded simple shear turns with the fluid's angular velocity
//! −γ̇/2: ratio 1), and its final position and velocity.

use super::Probe;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::{self, Chart, Curve, CurveStyle, FigureFormat, PALETTE};
use crate::engine::step::Simulation;
use anyhow::{Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// One disc at one output time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscRow {
    pub t: f64,
    pub disc: usize,
    /// x, y, V_x, V_y, Ω, F_x, F_y, T, and the contact force C_x, C_y.
    pub values: [f64; 10],
}

const HEADER: &str = "t,disc,x,y,vx,vy,spin,fx,fy,torque,contact_x,contact_y";

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
        let mut s = format!("{HEADER}\n");
        for r in &self.rows {
            let _ = write!(s, "{:.9e},{}", r.t, r.disc);
            for v in r.values {
                let _ = write!(s, ",{v:.9e}");
            }
            s.push('\n');
        }
        s
    }

    fn discs(&self) -> usize {
        self.rows.iter().map(|r| r.disc + 1).max().unwrap_or(0)
    }

    pub fn summary(&self) -> Vec<DiscSummary> {
        let t_end = self.rows.last().map_or(0.0, |r| r.t);
        (0..self.discs())
            .map(|k| {
                let rows: Vec<&DiscRow> = self.rows.iter().filter(|r| r.disc == k).collect();
                let last = rows.last().map_or([f64::NAN; 10], |r| r.values);
                let late: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.t >= 0.5 * t_end)
                    .map(|r| r.values[4])
                    .collect();
                DiscSummary {
                    rotation_ratio: self
                        .shear_rate
                        .filter(|_| !late.is_empty())
                        .map(|g| late.iter().sum::<f64>() / late.len() as f64 / (-0.5 * g)),
                    final_centre: [last[0], last[1]],
                    final_velocity: [last[2], last[3]],
                    final_spin: last[4],
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
                    .map(|r| (r.t, r.values[4] / scale))
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
                values: [
                    c.x,
                    c.y,
                    d.velocity.x,
                    d.velocity.y,
                    d.spin,
                    f.x,
                    f.y,
                    load.torque(),
                    contact.x,
                    contact.y,
                ],
            });
        }
    }

    fn write(&self, dir: &Path) -> Result<()> {
        io::write_atomic(&dir.join("disc.csv"), self.csv().as_bytes())
    }

    /// The rows up to `t` from `disc.csv`.
    fn restore(&mut self, dir: &Path, t: f64, _state: Option<&serde_json::Value>) -> Result<()> {
        let path = dir.join("disc.csv");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        self.rows = text
            .lines()
            .skip(1)
            .filter_map(|line| {
                let v: Vec<f64> = line.split(',').filter_map(|x| x.parse().ok()).collect();
                (v.len() == 12).then(|| DiscRow {
                    t: v[0],
                    disc: v[1] as usize,
                    values: std::array::from_fn(|k| v[k + 2]),
                })
            })
            .filter(|r| r.t <= t * (1.0 + 1e-9))
            .collect();
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
