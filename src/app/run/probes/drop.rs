//! Drop-impact diagnostics (King & Lind §IV C): the drop's width W* and height H* over its
//! diameter against t* = tU/W, its area (volume conservation), and snapshots coloured by tr A.
//!
//! W* = (x_max − x_min + δr)/W and H* = (y_max − y_min + δr)/W: the particles' extent plus
//! one spacing (each particle stands for a δr × δr patch), so both start at 1.
//! The area is N δV/⟨C⟩_I, N particles of volume δV over the mean kernel concentration
//! C_i = Σ_j V_j W_ij (37) of the interior particles (neither FS nor NS): a particle count is
//! conserved by construction, so what can drift is how tightly the particles pack. Its drift
//! is relative to the first step's value.
//!
//! Free drops (surface tension, no plate) are read by three more columns:
//! * `mode2 = 4(⟨x'²⟩ − ⟨y'²⟩)/W²`, x' = x − x̄ over the particles: an ellipse of semi-axes
//!   R(1 ± ε) has mode2 = ε (to first order), and a mode-2 oscillation, whose velocity is
//!   linear in position, keeps the drop an ellipse, so mode2 is its amplitude. The summary's
//!   `oscillation_period` is the mean spacing of its zero crossings, doubled, and
//!   `decay_rate` the slope of ln|mode2| at its extrema (a least-squares line);
//! * `interior_pressure`: the mean pressure of the particles within R/2 of the centroid
//!   (Laplace: σ/R); the summary averages it over the last 20 % of the run;
//! * `max_speed`: the largest particle speed (a static drop's spurious currents).
//!
//! A sessile drop (a contact angle at the plate) adds `contact_angle`: the angle, in
//! degrees, of the circular cap fitted to its FS particles more than 2δr above the plate (an
//! algebraic least-squares circle, Kåsa 1976), the surface lying δr/2 beyond their centres:
//! cos θ = −y_c/(ρ + δr/2) for a circle of radius ρ about (x_c, y_c). A drop at rest without
//! gravity is such a cap, whatever its angle.

use super::Probe;
use crate::analysis::analytic::DropMode;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::app::table::{self, fmt};
use crate::engine::math::Vec2;
use crate::engine::rheology::{Fluid, Model};
use crate::engine::step::Simulation;
use anyhow::Result;
use serde::{Deserialize, Serialize};
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
    /// Mean of `interior_pressure` over the rows of the last 20 % of the run.
    pub interior_pressure: f64,
    /// Largest particle speed over the rows of the last 20 % of the run.
    pub late_max_speed: f64,
    /// Largest |V/V0 − 1| of the volume Σ m_i/ρ_i (0 for the projection).
    pub max_volume_error: f64,
    /// A free drop's mode-2 period, when mode2 crosses zero at least three times.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oscillation_period: Option<f64>,
    /// The decay rate γ of mode2 ∝ e^{−γt} from its extrema (at least two).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub decay_rate: Option<f64>,
    /// The mode-2 period of linear theory, for a free drop of a liquid it covers
    /// ([`linear_mode`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theory_period: Option<f64>,
    /// The mode-2 decay rate of linear theory.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theory_decay_rate: Option<f64>,
    /// A sessile drop's contact angle (degrees), averaged over the last 20 % of the run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_angle: Option<f64>,
}

/// One row of `drop.csv`. The free-drop columns (`mode2` on) came later: a file written
/// before them reads them as NaN, as `compare-drops` and a resumed run need.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DropRow {
    #[serde(serialize_with = "fmt::sci8")]
    pub t: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub t_star: f64,
    #[serde(rename = "width_star", serialize_with = "fmt::sci6")]
    pub width: f64,
    #[serde(rename = "height_star", serialize_with = "fmt::sci6")]
    pub height: f64,
    #[serde(serialize_with = "fmt::sci6")]
    pub area: f64,
    #[serde(serialize_with = "fmt::sci4")]
    pub area_drift: f64,
    pub surface_particles: usize,
    #[serde(serialize_with = "fmt::sci6")]
    pub max_trace_a: f64,
    #[serde(default = "table::nan", serialize_with = "fmt::sci8")]
    pub mode2: f64,
    #[serde(default = "table::nan", serialize_with = "fmt::sci8")]
    pub interior_pressure: f64,
    #[serde(default = "table::nan", serialize_with = "fmt::sci6")]
    pub max_speed: f64,
    /// Σ m_i/ρ_i over N δV, the volume at ρ0 (1 for the projection, whose particles keep
    /// ρ0; the weakly compressible scheme's compression). NaN in a file written before the
    /// column existed.
    #[serde(default = "table::nan", serialize_with = "fmt::sci8")]
    pub volume: f64,
    /// A sessile drop's fitted contact angle in degrees (NaN for other drops, and in a file
    /// written before the column existed).
    #[serde(default = "table::nan", serialize_with = "fmt::sci6")]
    pub contact_angle: f64,
}

/// The drop probe of a run: its diameter and impact speed, and the rows so far.
pub struct DropProbe {
    pub diameter: f64,
    pub speed: f64,
    /// A free drop (no plate): its mode-2 period and decay are summarised.
    pub free: bool,
    /// A sessile drop (a contact angle at the plate): its angle is measured.
    pub sessile: bool,
    pub rows: Vec<DropRow>,
    /// A free drop's mode 2 in linear theory, when the liquid has one ([`linear_mode`]).
    pub theory: Option<DropMode>,
    reference_area: Option<f64>,
}

impl DropProbe {
    pub fn new(diameter: f64, speed: f64) -> Self {
        Self {
            diameter,
            speed,
            free: false,
            sessile: false,
            rows: Vec::new(),
            theory: None,
            reference_area: None,
        }
    }

    /// Rows of a resumed run up to time `t` (from its `drop.csv`).
    fn restore_rows(&mut self, dir: &Path, t: f64) -> Result<()> {
        let rows: Vec<DropRow> = table::read_rows(&dir.join("drop.csv"))?;
        // Times are written to 9 digits: a row at t itself may read back a hair later.
        self.rows
            .extend(rows.into_iter().filter(|r| r.t <= t * (1.0 + 1e-8)));
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
        let (mode2, interior_pressure) = self.moments(sim);
        let max_speed = s.velocity.iter().map(|u| u.norm()).fold(0.0, f64::max);
        let volume = sim.fluid_volume() / (sim.particles() as f64 * sim.particle_volume());
        let contact_angle = if self.sessile {
            cap_angle(sim).unwrap_or(f64::NAN)
        } else {
            f64::NAN
        };
        self.rows.push(DropRow {
            t: s.time,
            t_star: s.time * self.speed / self.diameter,
            width: (hi.x - lo.x + dr) / self.diameter,
            height: (hi.y - lo.y + dr) / self.diameter,
            area,
            area_drift: self.reference_area.map_or(f64::NAN, |a0| area / a0 - 1.0),
            surface_particles,
            max_trace_a,
            mode2,
            interior_pressure,
            max_speed,
            volume,
            contact_angle,
        });
    }

    /// mode2 and the interior pressure (module docs).
    fn moments(&self, sim: &Simulation) -> (f64, f64) {
        let s = &sim.state;
        let n = s.position.len();
        let sum = |f: &(dyn Fn(usize) -> f64 + Sync)| crate::engine::reduce::blocked_sum(n, f);
        let centre = Vec2::new(
            sum(&|i| s.position[i].x) / n as f64,
            sum(&|i| s.position[i].y) / n as f64,
        );
        let spread = sum(&|i| {
            let r = s.position[i] - centre;
            r.x * r.x - r.y * r.y
        }) / n as f64;
        let mode2 = 4.0 * spread / (self.diameter * self.diameter);
        let inner = 0.25 * self.diameter;
        let (p, count) = (0..n)
            .filter(|&i| (s.position[i] - centre).norm() < inner)
            .fold((0.0, 0usize), |(p, c), i| (p + s.pressure[i], c + 1));
        let interior = if count > 0 {
            p / count as f64
        } else {
            f64::NAN
        };
        (mode2, interior)
    }

    /// `drop.csv`.
    pub fn csv(&self) -> String {
        table::write_rows(&self.rows)
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
        let late: Vec<&DropRow> = self.rows.iter().filter(|r| r.t >= 0.8 * last.t).collect();
        Some(DropSummary {
            t_star_reached: last.t_star,
            max_width_star: widest.width,
            t_star_at_max_width: widest.t_star,
            final_width_star: last.width,
            final_height_star: last.height,
            max_area_drift: self.max_area_drift(),
            interior_pressure: late.iter().map(|r| r.interior_pressure).sum::<f64>()
                / late.len() as f64,
            late_max_speed: late.iter().map(|r| r.max_speed).fold(0.0, f64::max),
            max_volume_error: self
                .rows
                .iter()
                .map(|r| (r.volume - 1.0).abs())
                .fold(0.0, f64::max),
            oscillation_period: oscillation_period(&self.rows).filter(|_| self.free),
            decay_rate: decay_rate(&self.rows).filter(|_| self.free),
            theory_period: self.theory.and_then(|m| m.period()),
            theory_decay_rate: self.theory.and_then(|m| m.decay_rate()),
            contact_angle: self
                .sessile
                .then(|| late.iter().map(|r| r.contact_angle).sum::<f64>() / late.len() as f64),
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

/// The contact angle of a sessile drop (module docs), in degrees; None without a surface or
/// with fewer than three surface particles above 2δr.
fn cap_angle(sim: &Simulation) -> Option<f64> {
    let fs = sim.surface()?;
    let dr = sim.spacing;
    let points: Vec<Vec2> = (0..sim.particles())
        .filter(|&i| fs.on_surface[i] && sim.state.position[i].y > 2.0 * dr)
        .map(|i| sim.state.position[i])
        .collect();
    let (centre, radius) = fit_circle(&points)?;
    let cos = (-centre.y / (radius + 0.5 * dr)).clamp(-1.0, 1.0);
    Some(cos.acos().to_degrees())
}

/// The circle x² + y² + Dx + Ey + F = 0 nearest `points` in the algebraic least-squares
/// sense (Kåsa 1976), as its centre and radius (None with fewer than three points or
/// collinear ones).
pub fn fit_circle(points: &[Vec2]) -> Option<(Vec2, f64)> {
    use nalgebra::{Matrix3, Vector3};
    if points.len() < 3 {
        return None;
    }
    // Centred on the points' mean for conditioning.
    let mean = points.iter().sum::<Vec2>() / points.len() as f64;
    let (mut m, mut b) = (Matrix3::zeros(), Vector3::zeros());
    for p in points {
        let q = p - mean;
        let row = Vector3::new(q.x, q.y, 1.0);
        m += row * row.transpose();
        b -= row * q.norm_squared();
    }
    let c = m.lu().solve(&b)?;
    let centre = Vector3::new(-0.5 * c[0], -0.5 * c[1], 0.0);
    let r2 = centre.x * centre.x + centre.y * centre.y - c[2];
    (r2 > 0.0).then(|| (mean + Vec2::new(centre.x, centre.y), r2.sqrt()))
}

/// Mode 2 of a free drop of radius `radius` in linear theory
/// ([`crate::analysis::analytic::drop_oscillation`]): for a Newtonian liquid of constant
/// viscosity with surface tension, and for the models whose response about rest is
/// Oldroyd-B's (a single Maxwell mode η_p, λ beside the solvent); None for the others (FENE
/// models relax from a rest state of their own, and a shear-dependent viscosity has no
/// single η).
pub fn linear_mode(fluid: &Fluid, radius: f64) -> Option<DropMode> {
    let maxwell = matches!(
        fluid.model,
        Model::OldroydB
            | Model::Ucm
            | Model::LinearPtt(_)
            | Model::ExponentialPtt(_)
            | Model::Giesekus(_)
    );
    let newtonian = fluid.model == Model::Newtonian && fluid.law.is_constant();
    (fluid.surface_tension > 0.0 && (maxwell || newtonian)).then(|| DropMode {
        n: 2,
        surface_tension: fluid.surface_tension,
        density: fluid.density,
        radius,
        solvent_viscosity: fluid.solvent_viscosity(),
        polymer_viscosity: if maxwell {
            fluid.polymer_viscosity()
        } else {
            0.0
        },
        relaxation_time: if maxwell { fluid.relaxation_time } else { 0.0 },
    })
}

/// Smallest |mode2| peak that counts as an oscillation (0.1 % of W): below it the signal is
/// a drop's round-off and lattice noise (a static drop: ~1e-9).
const MIN_MODE2: f64 = 1e-3;

/// Whether mode2 ever exceeds [`MIN_MODE2`].
fn oscillates(rows: &[DropRow]) -> bool {
    rows.iter().any(|r| r.mode2.abs() > MIN_MODE2)
}

/// The times at which mode2 changes sign (linear interpolation between rows).
fn zero_crossings(rows: &[DropRow]) -> Vec<f64> {
    rows.windows(2)
        .filter(|w| w[0].mode2 * w[1].mode2 < 0.0)
        .map(|w| {
            let (a, b) = (w[0].mode2, w[1].mode2);
            w[0].t + (w[1].t - w[0].t) * a / (a - b)
        })
        .collect()
}

/// Twice the mean spacing of mode2's zero crossings (None with fewer than three).
pub fn oscillation_period(rows: &[DropRow]) -> Option<f64> {
    let zeros = zero_crossings(rows);
    (oscillates(rows) && zeros.len() >= 3)
        .then(|| 2.0 * (zeros[zeros.len() - 1] - zeros[0]) / (zeros.len() - 1) as f64)
}

/// γ of mode2 ∝ e^{−γt}: the least-squares slope of ln|mode2| at its extremum between each
/// pair of successive zero crossings (and before the first), None with fewer than two.
pub fn decay_rate(rows: &[DropRow]) -> Option<f64> {
    let zeros = zero_crossings(rows);
    let mut bounds = vec![rows.first()?.t];
    bounds.extend(&zeros);
    let peaks: Vec<(f64, f64)> = bounds
        .windows(2)
        .filter_map(|w| {
            rows.iter()
                .filter(|r| r.t >= w[0] && r.t <= w[1])
                .max_by(|a, b| a.mode2.abs().total_cmp(&b.mode2.abs()))
                .map(|r| (r.t, r.mode2.abs().ln()))
        })
        .collect();
    if peaks.len() < 2 || !oscillates(rows) {
        return None;
    }
    let m = peaks.len() as f64;
    let (st, sl) = peaks
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mt, ml) = (st / m, sl / m);
    let (num, den) = peaks.iter().fold((0.0, 0.0), |(n, d), p| {
        (n + (p.0 - mt) * (p.1 - ml), d + (p.0 - mt).powi(2))
    });
    (den > 0.0).then(|| -num / den)
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
