//! Drop-impact diagnostics (King & Lind §IV C): the drop's width W* and height H* over its
//! diameter against t* = tU/W, its area (volume conservation), and snapshots coloured by tr A.
//!
//! W* = (x_max − x_min + δr)/W and H* = (y_max − y_min + δr)/W: the particles' extent plus
//! one spacing (each particle stands for a δr × δr patch), so both start at 1.
//! The area is N δV/⟨C⟩_I, N particles of volume δV over the mean kernel concentration
//! C_i = Σ_j V_j W_ij (37) of the interior particles (neither FS nor NS): a particle count is
//! conserved by construction, so what can drift is how tightly the particles pack. Its drift
//! is relative to the first step's value.

use super::Probe;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::engine::step::Simulation;
use anyhow::Result;
use std::path::Path;

/// The drop-impact summary (see `drop.csv` for the histories).
#[derive(Clone, Debug, serde::Serialize)]
pub struct DropSummary {
    pub t_star_reached: f64,
    pub max_width_star: f64,
    pub t_star_at_max_width: f64,
    pub final_width_star: f64,
    pub final_height_star: f64,
    /// Largest |area/area(first step) − 1|.
    pub max_area_drift: f64,
}

/// One row of `drop.csv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DropRow {
    pub t: f64,
    pub t_star: f64,
    pub width: f64,
    pub height: f64,
    pub area: f64,
    pub area_drift: f64,
    pub surface_particles: usize,
    pub max_trace_a: f64,
}

const HEADER: &str =
    "t,t_star,width_star,height_star,area,area_drift,surface_particles,max_trace_a";

/// The drop probe of a run: its diameter and impact speed, and the rows so far.
pub struct DropProbe {
    pub diameter: f64,
    pub speed: f64,
    pub rows: Vec<DropRow>,
    reference_area: Option<f64>,
}

impl DropProbe {
    pub fn new(diameter: f64, speed: f64) -> Self {
        Self {
            diameter,
            speed,
            rows: Vec::new(),
            reference_area: None,
        }
    }

    /// Rows of a resumed run up to time `t` (from its `drop.csv`).
    fn restore_rows(&mut self, dir: &Path, t: f64) -> Result<()> {
        let text = std::fs::read_to_string(dir.join("drop.csv"))?;
        for line in text.lines().skip(1) {
            let v: Vec<f64> = line.split(',').filter_map(|s| s.parse().ok()).collect();
            // Times are written to 9 digits: a row at t itself may read back a hair later.
            if v.len() == 8 && v[0] <= t * (1.0 + 1e-8) {
                self.rows.push(DropRow {
                    t: v[0],
                    t_star: v[1],
                    width: v[2],
                    height: v[3],
                    area: v[4],
                    area_drift: v[5],
                    surface_particles: v[6] as usize,
                    max_trace_a: v[7],
                });
            }
        }
        self.reference_area = self.rows.iter().map(|r| r.area).find(|a| a.is_finite());
        Ok(())
    }

    /// Appends the current shape.
    fn record_shape(&mut self, sim: &Simulation) {
        let s = &sim.state;
        let (mut lo, mut hi) = (s.position[0], s.position[0]);
        for p in &s.position {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let dr = sim.spacing;
        let (area, surface_particles) = match sim.surface() {
            Some(fs) => {
                let (sum, count) = (0..sim.particles())
                    .filter(|&i| !fs.on_surface[i] && !fs.near_surface[i])
                    .fold((0.0, 0usize), |(a, n), i| (a + fs.concentration[i], n + 1));
                let area = if count > 0 {
                    sim.particles() as f64 * sim.particle_volume() * count as f64 / sum
                } else {
                    f64::NAN
                };
                (area, fs.count())
            }
            None => (f64::NAN, 0),
        };
        if self.reference_area.is_none() && area.is_finite() {
            self.reference_area = Some(area);
        }
        let max_trace_a = s.conformation.iter().map(|a| a.trace()).fold(2.0, f64::max);
        self.rows.push(DropRow {
            t: s.time,
            t_star: s.time * self.speed / self.diameter,
            width: (hi.x - lo.x + dr) / self.diameter,
            height: (hi.y - lo.y + dr) / self.diameter,
            area,
            area_drift: self.reference_area.map_or(f64::NAN, |a0| area / a0 - 1.0),
            surface_particles,
            max_trace_a,
        });
    }

    /// `drop.csv`.
    pub fn csv(&self) -> String {
        let mut out = String::from(HEADER);
        out.push('\n');
        for r in &self.rows {
            out.push_str(&format!(
                "{:.8e},{:.6e},{:.6e},{:.6e},{:.6e},{:.4e},{},{:.6e}\n",
                r.t,
                r.t_star,
                r.width,
                r.height,
                r.area,
                r.area_drift,
                r.surface_particles,
                r.max_trace_a
            ));
        }
        out
    }

    /// The largest |area drift| so far.
    pub fn max_area_drift(&self) -> f64 {
        self.rows
            .iter()
            .map(|r| r.area_drift.abs())
            .filter(|d| d.is_finite())
            .fold(0.0, f64::max)
    }

    /// The summary of the rows so far (None before the first row).
    pub fn summary(&self) -> Option<DropSummary> {
        let last = self.rows.last()?;
        let widest = self
            .rows
            .iter()
            .max_by(|a, b| a.width.total_cmp(&b.width))
            .unwrap_or(last);
        Some(DropSummary {
            t_star_reached: last.t_star,
            max_width_star: widest.width,
            t_star_at_max_width: widest.t_star,
            final_width_star: last.width,
            final_height_star: last.height,
            max_area_drift: self.max_area_drift(),
        })
    }

    /// `drop.png` (W* and H* against t*) and `drop_area.png` (area drift).
    pub fn charts(&self, dir: &Path, format: FigureFormat) -> Result<()> {
        let curve = |label: &str, f: fn(&DropRow) -> f64, colour| Curve {
            label: label.into(),
            points: self.rows.iter().map(|r| (r.t_star, f(r))).collect(),
            style: CurveStyle::Line,
            color: colour,
        };
        plot::draw(
            &dir.join("drop.png"),
            format,
            &Chart {
                title: "Drop width and height".into(),
                x_label: "t* = tU/W".into(),
                y_label: "W*, H*".into(),
                ..Default::default()
            },
            &[
                curve("W*", |r| r.width, PALETTE[0]),
                curve("H*", |r| r.height, PALETTE[1]),
            ],
        )?;
        plot::draw(
            &dir.join("drop_area.png"),
            format,
            &Chart {
                title: "Drop area drift (N dV / mean interior C)".into(),
                x_label: "t* = tU/W".into(),
                y_label: "area / area(first step) - 1".into(),
                ..Default::default()
            },
            &[curve("", |r| r.area_drift, PALETTE[0])],
        )
    }
}

impl Probe for DropProbe {
    fn name(&self) -> &'static str {
        "drop"
    }

    fn record(&mut self, sim: &mut Simulation, _rows: &[SeriesRow]) {
        self.record_shape(sim);
    }

    fn restore(&mut self, dir: &Path, t: f64, _state: Option<&serde_json::Value>) -> Result<()> {
        self.restore_rows(dir, t)
    }

    fn write(&self, dir: &Path) -> Result<()> {
        io::write_atomic(&dir.join("drop.csv"), self.csv().as_bytes())
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
        Ok(self.summary().map(serde_json::to_value).transpose()?)
    }
}
