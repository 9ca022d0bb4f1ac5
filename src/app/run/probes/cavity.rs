//! The lid-driven cavity: at the end of the run, `cavity.csv` (u along the vertical
//! centre-line x = L/2 and v along y = 3L/4, the lines of Fattal & Kupferman 2005 and Sousa
//! et al. 2016) and the `cavity` entry of `summary.json`: the stream function's minimum
//! ψ_min/(UL) (ψ = ∫₀^y u dy, negative in the primary vortex) and the vortex centre, the
//! extrema of the two profiles, and for a Newtonian fluid the same numbers of the Stokes
//! flow ([`crate::analysis::analytic::stokes_cavity`], regularised lid) with the relative L2
//! differences of the profiles.
//!
//! The fields come from the corrected grid interpolation ([`crate::analysis::grid`]) on
//! nodes δr/2 apart; ψ integrates u up each column by the trapezoidal rule from the wall.

use super::Probe;
use crate::analysis::analytic::stokes_cavity::{parabola_vertex, StokesCavity};
use crate::analysis::grid::{interpolate_on, GridSpec};
use crate::app::io::{self, SeriesRow};
use crate::app::plot::{self, Chart, Curve, CurveStyle, FigureFormat, PALETTE};
use crate::app::table::{self, fmt};
use crate::engine::math::Vec2;
use crate::engine::step::Simulation;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Cells per side of the finite-difference Stokes reference (ψ_min within 1e-5 relative).
const STOKES_CELLS: usize = 128;

/// The cavity probe of a run.
pub struct CavityProbe {
    /// U, L.
    speed: f64,
    size: f64,
    /// Whether the Stokes flow is the reference (a Newtonian fluid).
    stokes: bool,
    lines: Option<Lines>,
}

/// Both profiles at the nodes s_k = (k + ½)Δ: u(L/2, s), v(s, 3L/4), and the Stokes ones.
#[derive(Clone, Debug, Default)]
struct Lines {
    s: Vec<f64>,
    u: Vec<f64>,
    v: Vec<f64>,
    u_stokes: Vec<f64>,
    v_stokes: Vec<f64>,
}

/// One row of `cavity.csv`: the profiles at s_k, u(L/2, s) and v(s, 3L/4) beside the Stokes
/// flow's (NaN where there is none), to 9 digits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CavityRow {
    #[serde(serialize_with = "fmt::sci9")]
    pub s: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub u_x_half: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub u_stokes: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub v_y_three_quarters: f64,
    #[serde(serialize_with = "fmt::sci9")]
    pub v_stokes: f64,
}

/// The numbers of one flow (scaled by U and L).
#[derive(Clone, Debug, Serialize)]
pub struct CavityNumbers {
    pub psi_min: f64,
    pub vortex_centre: [f64; 2],
    /// The smallest u on x = L/2 and its y.
    pub u_min: [f64; 2],
    /// The largest and smallest v on y = 3L/4 and their x.
    pub v_max: [f64; 2],
    pub v_min: [f64; 2],
}

#[derive(Clone, Debug, Serialize)]
struct CavitySummary {
    #[serde(flatten)]
    sph: CavityNumbers,
    stokes: Option<CavityNumbers>,
    /// ‖u − u_Stokes‖/‖u_Stokes‖ on x = L/2, and the same for v on y = 3L/4.
    u_relative_l2: Option<f64>,
    v_relative_l2: Option<f64>,
}

impl CavityProbe {
    pub fn new(speed: f64, size: f64, stokes: bool) -> Self {
        Self {
            speed,
            size,
            stokes,
            lines: None,
        }
    }

    /// Samples the final state: the profiles and ψ's minimum.
    fn sample(&mut self, sim: &Simulation) -> CavityNumbers {
        let (l, n) = (self.size, (2.0 * self.size / sim.spacing).round() as usize);
        let d = l / n as f64;
        let grid = |origin: Vec2, dims: [usize; 2], field: usize| {
            let spec = GridSpec {
                origin,
                spacing: Vec2::new(d, d),
                dims,
            };
            let mut values = interpolate_on(sim, spec).fields.swap_remove(field).1;
            // Nodes the fit leaves out (a corner) are at the walls' rest.
            values
                .iter_mut()
                .filter(|v| v.is_nan())
                .for_each(|v| *v = 0.0);
            values
        };
        let (u_field, v_field) = (0, 1);
        let u_all = grid(Vec2::new(0.5 * d, 0.5 * d), [n, n], u_field);
        let mut lines = Lines {
            s: (0..n).map(|k| (k as f64 + 0.5) * d / l).collect(),
            u: grid(Vec2::new(0.5 * l, 0.5 * d), [1, n], u_field),
            v: grid(Vec2::new(0.5 * d, 0.75 * l), [n, 1], v_field),
            ..Default::default()
        };
        lines.u.iter_mut().for_each(|u| *u /= self.speed);
        lines.v.iter_mut().for_each(|v| *v /= self.speed);
        let (psi_min, centre) = stream_minimum(&u_all, n, d);
        let numbers = CavityNumbers {
            psi_min: psi_min / (self.speed * l),
            vortex_centre: [centre.x / l, centre.y / l],
            ..extrema(&lines.s, &lines.u, &lines.v)
        };
        self.lines = Some(lines);
        numbers
    }

    /// The Stokes flow's numbers and its profiles at the probe's nodes.
    fn stokes(&mut self) -> Result<CavityNumbers> {
        let st = StokesCavity::solve(STOKES_CELLS).map_err(anyhow::Error::msg)?;
        let lines = self.lines.as_mut().expect("sampled first");
        let m = STOKES_CELLS;
        // Linear interpolation between the reference's nodes along a line.
        let along = |s: f64, f: &dyn Fn(usize) -> f64| {
            let x = s * m as f64;
            let k = (x.floor() as usize).min(m - 1);
            let w = x - k as f64;
            (1.0 - w) * f(k) + w * f(k + 1)
        };
        lines.u_stokes = lines
            .s
            .iter()
            .map(|&y| along(y, &|j| st.u(m / 2, j)))
            .collect();
        lines.v_stokes = lines
            .s
            .iter()
            .map(|&x| along(x, &|i| st.v(i, 3 * m / 4)))
            .collect();
        let (psi_min, c) = st.minimum();
        Ok(CavityNumbers {
            psi_min,
            vortex_centre: [c.x, c.y],
            ..extrema(&lines.s, &lines.u_stokes, &lines.v_stokes)
        })
    }

    fn csv(&self) -> String {
        let rows: Vec<CavityRow> = self.lines.as_ref().map_or_else(Vec::new, |l| {
            let st = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(f64::NAN);
            (0..l.s.len())
                .map(|k| CavityRow {
                    s: l.s[k],
                    u_x_half: l.u[k],
                    u_stokes: st(&l.u_stokes, k),
                    v_y_three_quarters: l.v[k],
                    v_stokes: st(&l.v_stokes, k),
                })
                .collect()
        });
        table::write_rows(&rows)
    }

    /// `cavity.png`: u(L/2, y)/U against y/L, beside the Stokes flow's.
    fn chart(&self, dir: &Path, format: FigureFormat) -> Result<()> {
        let Some(l) = &self.lines else { return Ok(()) };
        let curve = |label: &str, v: &[f64], style, color| Curve {
            label: label.into(),
            points: v.iter().zip(&l.s).map(|(&u, &y)| (u, y)).collect(),
            style,
            color,
        };
        let mut curves = vec![curve("SPH", &l.u, CurveStyle::Line, PALETTE[0])];
        if !l.u_stokes.is_empty() {
            curves.push(curve(
                "Stokes (FD)",
                &l.u_stokes,
                CurveStyle::Dashed,
                PALETTE[1],
            ));
        }
        plot::draw(
            &dir.join("cavity.png"),
            format,
            &Chart {
                title: "Lid-driven cavity: u on x = L/2".into(),
                x_label: "u / U".into(),
                y_label: "y / L".into(),
                ..Default::default()
            },
            &curves,
        )
    }
}

/// ψ = ∫₀^y u dy up each column of the n × n cell-centred grid (u = 0 on the wall), and its
/// minimum refined by the parabola through the neighbouring nodes along each axis.
fn stream_minimum(u: &[f64], n: usize, d: f64) -> (f64, Vec2) {
    let mut psi = vec![0.0; n * n];
    for i in 0..n {
        let mut acc = 0.5 * d * 0.5 * u[i]; // from the wall to the first node
        psi[i] = acc;
        for j in 1..n {
            acc += 0.5 * d * (u[(j - 1) * n + i] + u[j * n + i]);
            psi[j * n + i] = acc;
        }
    }
    let k = (0..n * n)
        .min_by(|&a, &b| psi[a].total_cmp(&psi[b]))
        .unwrap_or(0);
    let (i, j) = (k % n, k / n);
    let at = |i: usize, j: usize| psi[j * n + i];
    let (i, j) = (i.clamp(1, n - 2), j.clamp(1, n - 2));
    let best = at(i, j);
    let (dx, fx) = parabola_vertex(at(i - 1, j), best, at(i + 1, j));
    let (dy, fy) = parabola_vertex(at(i, j - 1), best, at(i, j + 1));
    let centre = Vec2::new((i as f64 + 0.5 + dx) * d, (j as f64 + 0.5 + dy) * d);
    (best + (fx - best) + (fy - best), centre)
}

/// The extrema of the two profiles (positions and values), ψ left to the caller.
fn extrema(s: &[f64], u: &[f64], v: &[f64]) -> CavityNumbers {
    let pick = |values: &[f64], sign: f64| {
        let k = (0..values.len())
            .min_by(|&a, &b| (sign * values[a]).total_cmp(&(sign * values[b])))
            .unwrap_or(0);
        [
            values.get(k).copied().unwrap_or(f64::NAN),
            s.get(k).copied().unwrap_or(f64::NAN),
        ]
    };
    CavityNumbers {
        psi_min: f64::NAN,
        vortex_centre: [f64::NAN; 2],
        u_min: pick(u, 1.0),
        v_max: pick(v, -1.0),
        v_min: pick(v, 1.0),
    }
}

/// ‖a − b‖/‖b‖.
fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let den: f64 = b.iter().map(|y| y * y).sum();
    (num / den).sqrt()
}

impl Probe for CavityProbe {
    fn name(&self) -> &'static str {
        "cavity"
    }

    fn record(&mut self, _sim: &mut Simulation, _rows: &[SeriesRow]) {}

    fn finish(
        &mut self,
        sim: &mut Simulation,
        _rows: &[SeriesRow],
        dir: &Path,
        charts: Option<FigureFormat>,
    ) -> Result<Option<serde_json::Value>> {
        let sph = self.sample(sim);
        let stokes = if self.stokes {
            Some(self.stokes()?)
        } else {
            None
        };
        let l = self.lines.as_ref().expect("sampled");
        let (u_l2, v_l2) = match stokes {
            Some(_) => (
                Some(relative_l2(&l.u, &l.u_stokes)),
                Some(relative_l2(&l.v, &l.v_stokes)),
            ),
            None => (None, None),
        };
        io::write_atomic(&dir.join("cavity.csv"), self.csv().as_bytes())?;
        if let Some(format) = charts {
            self.chart(dir, format)?;
        }
        let summary = CavitySummary {
            sph,
            stokes,
            u_relative_l2: u_l2,
            v_relative_l2: v_l2,
        };
        Ok(Some(serde_json::to_value(summary)?))
    }
}
