//! Jet-buckling diagnostics (King & Lind §IV D): when the jet reaches the plate, when it
//! starts to buckle and how often it folds.
//!
//! The buckling signal is the lateral centroid x_b of the fluid in a band y ∈ [1.5D, 2.5D]
//! above the plate (below the orifice, above the early heap): a straight jet has x_b = 0 by
//! symmetry, a buckling one swings from side to side. Onset is the first time after impact
//! that |x_b| exceeds D/4; the frequency counts sign changes of x_b after onset (two per
//! period).

use super::Probe;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::app::table::{self, fmt};
use crate::engine::step::Simulation;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One row of `jet.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JetRow {
    #[serde(serialize_with = "fmt::sci6")]
    pub t: f64,
    pub particles: usize,
    /// Lowest fluid particle, over D.
    #[serde(rename = "tip_over_d", serialize_with = "fmt::sci6")]
    pub tip: f64,
    /// x_b/D, NaN while the band is empty.
    #[serde(rename = "band_x_over_d", serialize_with = "fmt::sci6")]
    pub band_x: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub max_trace_a: f64,
}

/// The jet summary (see `jet.csv` for the histories).
#[derive(Clone, Debug, Serialize)]
pub struct JetSummary {
    pub particles: usize,
    /// When the jet first reached the plate (tip below one spacing).
    pub t_impact: Option<f64>,
    /// First time after impact with |x_b| > D/4.
    pub t_buckling: Option<f64>,
    /// Folding frequency after onset (Hz), from sign changes of x_b.
    pub frequency: Option<f64>,
    pub max_band_x: f64,
    /// How many times a surface particle on the plate with no interior neighbour had its
    /// velocity into the plate removed (`experimental.contact_rows = "wall"`).
    pub wall_holds: u64,
    /// Detached bodies of liquid whose momentum a step corrected, summed over the steps, and
    /// the largest velocity one correction removed from a particle (m/s)
    /// (`scheme.free_surface.detached_momentum = "conserved"`; 0 otherwise).
    pub detached_body_steps: u64,
    pub largest_detached_correction: f64,
}

/// The jet probe of a run.
pub struct JetProbe {
    pub width: f64,
    pub rows: Vec<JetRow>,
}

const ONSET: f64 = 0.25;

impl JetProbe {
    pub fn new(width: f64) -> Self {
        Self {
            width,
            rows: Vec::new(),
        }
    }

    fn record_state(&mut self, sim: &Simulation) {
        let d = self.width;
        let s = &sim.state;
        let buffer = sim.inflow().map(|b| b.flags.as_slice());
        let fluid = |i: &usize| buffer.is_none_or(|b| !b[*i]);
        let tip = (0..s.position.len())
            .filter(fluid)
            .map(|i| s.position[i].y)
            .fold(f64::INFINITY, f64::min);
        let (sum, count) = (0..s.position.len())
            .filter(fluid)
            .filter(|&i| (1.5 * d..2.5 * d).contains(&s.position[i].y))
            .fold((0.0, 0usize), |(a, n), i| (a + s.position[i].x, n + 1));
        self.rows.push(JetRow {
            t: s.time,
            particles: s.position.len(),
            tip: tip / d,
            band_x: if count > 0 {
                sum / count as f64 / d
            } else {
                f64::NAN
            },
            max_trace_a: s.conformation.iter().map(|a| a.trace()).fold(2.0, f64::max),
        });
    }

    pub fn csv(&self) -> String {
        table::write_rows(&self.rows)
    }

    /// The jet's impact, buckling onset and folding frequency; the free surface's wall holds
    /// and the detached bodies' corrections ([`JetSummary`]) as the run counted them.
    pub fn summary(
        &self,
        spacing: f64,
        wall_holds: u64,
        detached_body_steps: u64,
        largest_detached_correction: f64,
    ) -> JetSummary {
        let t_impact = self
            .rows
            .iter()
            .find(|r| r.tip * self.width < spacing)
            .map(|r| r.t);
        let after = |t0: f64| self.rows.iter().filter(move |r| r.t >= t0);
        let t_buckling =
            t_impact.and_then(|t0| after(t0).find(|r| r.band_x.abs() > ONSET).map(|r| r.t));
        let frequency = t_buckling.and_then(|t0| {
            let signs: Vec<(f64, f64)> = after(t0)
                .filter(|r| r.band_x.is_finite())
                .map(|r| (r.t, r.band_x))
                .collect();
            let crossings: Vec<f64> = signs
                .windows(2)
                .filter(|w| w[0].1 * w[1].1 < 0.0)
                .map(|w| w[1].0)
                .collect();
            (crossings.len() >= 2).then(|| {
                let span = crossings[crossings.len() - 1] - crossings[0];
                0.5 * (crossings.len() - 1) as f64 / span
            })
        });
        JetSummary {
            particles: self.rows.last().map_or(0, |r| r.particles),
            t_impact,
            t_buckling,
            frequency,
            max_band_x: self
                .rows
                .iter()
                .map(|r| r.band_x.abs())
                .filter(|v| v.is_finite())
                .fold(0.0, f64::max),
            wall_holds,
            detached_body_steps,
            largest_detached_correction,
        }
    }

    /// `jet.png`: x_b/D and the tip height against t.
    pub fn charts(&self, dir: &Path, format: FigureFormat) -> Result<()> {
        plot::draw(
            &dir.join("jet.png"),
            format,
            &Chart {
                title: "Jet: lateral centroid at 1.5-2.5 D, tip height".into(),
                x_label: "t (s)".into(),
                y_label: "x_b / D, tip / D".into(),
                ..Default::default()
            },
            &[
                Curve {
                    label: "x_b / D".into(),
                    points: self
                        .rows
                        .iter()
                        .filter(|r| r.band_x.is_finite())
                        .map(|r| (r.t, r.band_x))
                        .collect(),
                    style: CurveStyle::Line,
                    color: PALETTE[0],
                },
                Curve {
                    label: "tip / D".into(),
                    points: self.rows.iter().map(|r| (r.t, r.tip)).collect(),
                    style: CurveStyle::Line,
                    color: PALETTE[1],
                },
            ],
        )
    }
}

impl Probe for JetProbe {
    fn name(&self) -> &'static str {
        "jet"
    }

    fn record(&mut self, sim: &mut Simulation, _rows: &[SeriesRow]) {
        self.record_state(sim);
    }

    fn write(&self, dir: &Path) -> Result<()> {
        io::write_atomic(&dir.join("jet.csv"), self.csv().as_bytes())
    }

    fn finish(
        &mut self,
        sim: &mut Simulation,
        _rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        if let Some(format) = charts {
            self.charts(dir, format)?;
        }
        let (body_steps, largest) = sim.detached_corrections();
        let summary = self.summary(sim.spacing, sim.surface_wall_holds(), body_steps, largest);
        Ok(Some(serde_json::to_value(summary)?))
    }
}
