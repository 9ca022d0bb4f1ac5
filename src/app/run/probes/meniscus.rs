//! The meniscus of a pool (`kind = "pool"`): how far the surface rises at the walls and
//! between the plates, against the exact static shapes of [`crate::setup::scenes::pool`].
//! `meniscus.csv` holds, at every output time, the far level and every rise above it:
//!
//! * `level`: the height of the surface in strips 2ℓ_c wide far from every wall (midway
//!   across the tank, or midway between each plate and the tank's wall): the median, over
//!   columns of width δr, of the highest particle's centre plus δr/2 (a column whose top
//!   particle has just moved out reads low, hence the median);
//! * `wall_left`, `wall_right` (the tank's walls) and `plate_left`, `plate_right` (the plates'
//!   outer faces): the height of the surface at the wall above the level, from the highest
//!   particle of each of the two columns of width δr beside the wall, extrapolated linearly to
//!   the wall, then half a spacing out along the surface's normal (δr√(1 + s²)/2 above the
//!   centres for a slope s: at 30°, δr; before this version δr/2, which read the 30° rise 4 %
//!   low at ℓ_c/δr = 12.5);
//! * `level_count`: the far level counted as N δr² over the strips' width (their edges on
//!   lattice lines): the particles keep their volume, so a count resolves the level far below
//!   one spacing, and unlike the highest particle of a column it is not raised by the
//!   surface's disorder (by 0.01–0.04 in the capillary-rise tank, growing as the particles
//!   shuffle);
//! * `gap_mean`: the lifted column's mean height, y_c + A/d − level_count, with A = N δr² the
//!   area of the liquid between the plates' flat faces above the centres y_c of their rounded
//!   ends, counted the same way: Jurin's height exactly;
//! * `gap_centre`: the surface's height midway between the plates (the meniscus's lowest point
//!   when it rises);
//! * `gap_surface`: the column's mean height read from its surface, not counted: the mean over
//!   the gap's columns of width δr of the surface above the highest particle's centre (half a
//!   spacing out along the normal, as at a wall, the slope from the neighbouring columns),
//!   less `level`.
//!   The count assumes that the particles keep their volume, and between the plates they do
//!   not always: at θ = 120° (`cases/capillary-rise.toml`, t = 40) the column above the
//!   plates' rounded ends held 11.7 % more particles than its surface encloses (the far
//!   field 0.2 %), its top row bunched to about 0.55δr, so `gap_mean` read −0.514 where the
//!   surface stood at −0.555 (Jurin −0.625); with that row exposed since
//!   ([`crate::engine::free_surface::detection`]), −0.531 against −0.593.

use super::Probe;
use crate::app::io::{self, SeriesRow};
use crate::app::plot::{self, Chart, Curve, CurveStyle, FigureFormat, PALETTE};
use crate::app::table::{self, fmt};
use crate::engine::math::Vec2;
use crate::engine::rheology::Fluid;
use crate::engine::step::Simulation;
use crate::setup::scenes::pool::Pool;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One row of `meniscus.csv` (NaN where the pool has no plates), every value to 9 digits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeniscusRow {
    #[serde(serialize_with = "fmt::sci9")]
    pub t: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub level: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub wall_left: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub wall_right: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub plate_left: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub plate_right: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub gap_mean: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub gap_centre: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub level_count: f64,
    /// NaN in a file written before the column existed.
    #[serde(default = "table::nan", serialize_with = "fmt::sci9")]
    pub gap_surface: f64,
}

impl MeniscusRow {
    /// The mean rise at the tank's two walls.
    fn wall_mean(&self) -> f64 {
        0.5 * (self.wall_left + self.wall_right)
    }
}

/// The meniscus summary: the rises averaged over the second half of the rows (a wide tank
/// sloshes for long after the menisci form: its gravest mode, of period 2L/√(gD), is barely
/// damped), beside the exact static values.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MeniscusSummary {
    pub contact_angle_degrees: f64,
    pub capillary_length: f64,
    /// ℓ_c √(2(1 − sin θ)), negative for θ > 90°, with θ the tank walls' angle.
    pub wall_rise_exact: f64,
    /// The mean over the tank's two walls.
    pub wall_rise: f64,
    /// None at a neutral wall (θ = 90°: no rise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wall_rise_relative_error: Option<f64>,
    /// The same at the plates' outer faces, with their angle (with plates).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plate_rise_exact: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plate_rise: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plate_rise_relative_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jurin_height: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap_mean_rise: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap_mean_rise_relative_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap_centre_rise: Option<f64>,
    /// The mean of `gap_surface`: the column's height read from its surface.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap_surface_rise: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap_surface_rise_relative_error: Option<f64>,
    /// The range of the gap's (or the walls') rise over the second half of the run, relative
    /// to the exact value: how far from static the averaged rows are.
    pub late_drift: f64,
}

/// The surface above a particle centre at height `z` where the surface slopes by `slope`:
/// half a spacing beyond the centre along the normal, δr √(1 + slope²)/2 above it (at a 30°
/// wall, where the surface stands at 60° to the level, δr rather than δr/2).
fn beyond(z: f64, slope: f64, dr: f64) -> f64 {
    z + 0.5 * dr * (1.0 + slope * slope).sqrt()
}

/// The geometry the probe reads and the rows so far.
pub struct MeniscusProbe {
    pool: Pool,
    dr: f64,
    capillary_length: f64,
    pub rows: Vec<MeniscusRow>,
}

impl MeniscusProbe {
    pub fn new(pool: &Pool, fluid: &Fluid) -> Self {
        use crate::setup::scenes::Scene;
        Self {
            pool: pool.clone(),
            dr: pool.spacing(),
            capillary_length: pool.capillary_length(fluid),
            rows: Vec::new(),
        }
    }

    fn half(&self) -> f64 {
        0.5 * self.pool.bounds.length
    }

    /// The strips of the far level: (centre, half width), both whole spacings from the
    /// tank's wall, so that the strips' edges lie on lattice lines.
    fn strips(&self) -> Vec<(f64, f64)> {
        let dr = self.dr;
        let w = (self.capillary_length / dr).round().max(2.0) * dr;
        let half = self.half();
        let on_lattice = |x: f64| -half + ((x + half) / dr).round() * dr;
        match self.pool.plates {
            None => vec![(on_lattice(0.0), w)],
            Some([_, right]) => {
                let c = on_lattice(0.5 * (right.right + half));
                vec![(-c, w), (c, w)]
            }
        }
    }

    /// The row of the particles at `points`.
    pub fn measure(&self, t: f64, points: &[Vec2]) -> MeniscusRow {
        let dr = self.dr;
        let count = |f: &dyn Fn(&Vec2) -> bool| points.iter().filter(|p| f(p)).count() as f64;
        let top = |a: f64, b: f64| {
            points
                .iter()
                .filter(|p| p.x >= a.min(b) && p.x < a.max(b))
                .map(|p| p.y + 0.5 * dr)
                .fold(f64::NAN, f64::max)
        };
        let strips = self.strips();
        let level_count = strips
            .iter()
            .map(|&(c, w)| count(&|p| (p.x - c).abs() < w) * dr * dr / (2.0 * w))
            .sum::<f64>()
            / strips.len() as f64;
        let mut tops: Vec<f64> = Vec::new();
        for &(c, w) in &strips {
            let columns = (2.0 * w / dr).round() as usize;
            let start = c - 0.5 * columns as f64 * dr;
            tops.extend((0..columns).map(|k| {
                let a = start + k as f64 * dr;
                top(a, a + dr)
            }));
        }
        tops.retain(|z| z.is_finite());
        tops.sort_unstable_by(f64::total_cmp);
        let level = tops.get(tops.len() / 2).copied().unwrap_or(f64::NAN);
        // The surface at a wall x_w whose fluid lies towards `side` (±1): the top centres of
        // the two columns beside it extrapolated to the wall, then half a spacing out along
        // the normal.
        let at_wall = |x: f64, side: f64| {
            let z0 = top(x, x + side * dr) - 0.5 * dr;
            let z1 = top(x + side * dr, x + 2.0 * side * dr) - 0.5 * dr;
            beyond(z0 + 0.5 * (z0 - z1), (z0 - z1) / dr, dr) - level
        };
        let half = self.half();
        let wall = [at_wall(-half, 1.0), at_wall(half, -1.0)];
        let (plate, gap_mean, gap_centre, gap_surface) = match self.pool.plates {
            None => ([f64::NAN; 2], f64::NAN, f64::NAN, f64::NAN),
            Some([l, r]) => {
                let gap = r.left - l.right;
                let base = l.end().centre.y;
                let inside = count(&|p| p.x > l.right && p.x < r.left && p.y > base);
                let columns = (gap / dr).round().max(1.0) as usize;
                let width = gap / columns as f64;
                let centres: Vec<f64> = (0..columns)
                    .map(|k| {
                        let a = l.right + k as f64 * width;
                        top(a, a + width) - 0.5 * dr
                    })
                    .collect();
                let surface = (0..columns)
                    .map(|k| {
                        let (a, b) = (k.saturating_sub(1), (k + 1).min(columns - 1));
                        let slope = (centres[b] - centres[a]) / ((b - a).max(1) as f64 * width);
                        beyond(centres[k], slope, dr)
                    })
                    .sum::<f64>()
                    / columns as f64;
                (
                    [at_wall(l.left, -1.0), at_wall(r.right, 1.0)],
                    base + inside * dr * dr / gap - level_count,
                    top(-dr, dr) - level,
                    surface - level,
                )
            }
        };
        MeniscusRow {
            t,
            level,
            wall_left: wall[0],
            wall_right: wall[1],
            plate_left: plate[0],
            plate_right: plate[1],
            gap_mean,
            gap_centre,
            level_count,
            gap_surface,
        }
    }

    /// ℓ_c √(2(1 − sin θ)) at the tank's walls, with the sign of cos θ.
    pub fn wall_rise_exact(&self) -> f64 {
        self.rise_exact(self.pool.wall_contact_angle)
    }

    /// ℓ_c √(2(1 − sin θ)) at a single wall of angle θ, with the sign of cos θ.
    fn rise_exact(&self, theta: f64) -> f64 {
        let rise = self.capillary_length * (2.0 * (1.0 - theta.sin())).sqrt();
        if theta.cos().abs() < 1e-12 {
            0.0
        } else {
            rise * theta.cos().signum()
        }
    }

    /// Jurin's 2σ cos θ/(ρgd), with plates.
    pub fn jurin_height(&self) -> Option<f64> {
        let [l, r] = self.pool.plates?;
        let gap = r.left - l.right;
        // 2σ cos θ/(ρgd), with σ/(ρg) = ℓ_c².
        let lc2 = self.capillary_length.powi(2);
        Some(2.0 * lc2 * self.pool.contact_angle.cos() / gap)
    }

    pub fn summary(&self) -> Option<MeniscusSummary> {
        let from = self.rows.len() / 2;
        let late = self.rows.get(from..).filter(|l| !l.is_empty())?;
        let mean =
            |f: &dyn Fn(&MeniscusRow) -> f64| late.iter().map(f).sum::<f64>() / late.len() as f64;
        let plates = self.pool.plates.is_some();
        let wall_rise = mean(&|r| r.wall_mean());
        let plate_rise = plates.then(|| mean(&|r| 0.5 * (r.plate_left + r.plate_right)));
        let exact = self.wall_rise_exact();
        let plate_exact = plates.then(|| self.rise_exact(self.pool.contact_angle));
        let relative = |rise: f64, exact: f64| (exact != 0.0).then(|| rise / exact - 1.0);
        let jurin = self.jurin_height();
        let gap_mean = plates.then(|| mean(&|r| r.gap_mean));
        let gap_surface = plates.then(|| mean(&|r| r.gap_surface));
        let watched = |r: &MeniscusRow| {
            if plates {
                r.gap_mean
            } else {
                r.wall_mean()
            }
        };
        let (lo, hi) = late
            .iter()
            .map(watched)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        Some(MeniscusSummary {
            contact_angle_degrees: self.pool.contact_angle.to_degrees(),
            capillary_length: self.capillary_length,
            wall_rise_exact: exact,
            wall_rise,
            wall_rise_relative_error: relative(wall_rise, exact),
            plate_rise_exact: plate_exact,
            plate_rise,
            plate_rise_relative_error: plate_rise
                .zip(plate_exact)
                .and_then(|(r, e)| relative(r, e)),
            jurin_height: jurin,
            gap_mean_rise: gap_mean,
            gap_mean_rise_relative_error: gap_mean.zip(jurin).map(|(g, j)| g / j - 1.0),
            gap_centre_rise: plates.then(|| mean(&|r| r.gap_centre)),
            gap_surface_rise: gap_surface,
            gap_surface_rise_relative_error: gap_surface.zip(jurin).map(|(g, j)| g / j - 1.0),
            late_drift: (hi - lo) / jurin.unwrap_or(exact).abs(),
        })
    }

    pub fn csv(&self) -> String {
        table::write_rows(&self.rows)
    }

    fn chart(&self, dir: &Path, format: FigureFormat) -> Result<()> {
        let curve = |label: &str, f: &dyn Fn(&MeniscusRow) -> f64, color, style| Curve {
            label: label.into(),
            points: self.rows.iter().map(|r| (r.t, f(r))).collect(),
            style,
            color,
        };
        let exact = self.wall_rise_exact();
        let mut curves = vec![
            curve(
                "at the walls",
                &|r| r.wall_mean(),
                PALETTE[0],
                CurveStyle::Line,
            ),
            curve("exact", &|_| exact, PALETTE[0], CurveStyle::Dashed),
        ];
        if let Some(j) = self.jurin_height() {
            curves.push(curve(
                "between the plates (mean)",
                &|r| r.gap_mean,
                PALETTE[1],
                CurveStyle::Line,
            ));
            curves.push(curve(
                "between the plates (surface)",
                &|r| r.gap_surface,
                PALETTE[2],
                CurveStyle::Line,
            ));
            curves.push(curve("Jurin", &|_| j, PALETTE[1], CurveStyle::Dashed));
        }
        plot::draw(
            &dir.join("meniscus.png"),
            format,
            &Chart {
                title: "Rise of the surface above the far level".into(),
                x_label: "t".into(),
                y_label: "rise".into(),
                ..Default::default()
            },
            &curves,
        )
    }
}

impl Probe for MeniscusProbe {
    fn name(&self) -> &'static str {
        "meniscus"
    }

    fn record(&mut self, sim: &mut Simulation, _rows: &[SeriesRow]) {
        let row = self.measure(sim.state.time, &sim.state.position);
        self.rows.push(row);
    }

    fn restore(&mut self, dir: &Path, t: f64, _state: Option<&serde_json::Value>) -> Result<()> {
        let rows: Vec<MeniscusRow> = table::read_rows(&dir.join("meniscus.csv"))?;
        self.rows
            .extend(rows.into_iter().filter(|r| r.t <= t * (1.0 + 1e-8)));
        Ok(())
    }

    fn write(&self, dir: &Path) -> Result<()> {
        io::write_atomic(&dir.join("meniscus.csv"), self.csv().as_bytes())
    }

    fn finish(
        &mut self,
        _sim: &mut Simulation,
        _rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        // meniscus.csv is already written with the series (`Probe::write`).
        if let Some(format) = charts {
            self.chart(dir, format)?;
        }
        Ok(self.summary().map(serde_json::to_value).transpose()?)
    }
}
