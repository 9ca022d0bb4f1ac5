//! The analytic reference of a channel run, in the case's dimensional units: the Waters & King
//! start-up series for Newtonian, Oldroyd-B and UCM fluids, the steady channel solution for
//! the non-linear models (whose start-up has no closed form).

use crate::analytic::waters_king::{self, Modes, StartupPoiseuille};
use crate::analytic::SteadyChannel;
use crate::case::Case;
use crate::math::Vec2;

/// Exact polymer stress profiles (τ_xy, τ_xx, τ_yy) at a set of heights.
#[derive(Clone, Debug, Default)]
pub struct StressProfiles {
    pub xy: Vec<f64>,
    pub xx: Vec<f64>,
    pub yy: Vec<f64>,
}

enum Solution {
    StartUp {
        series: StartupPoiseuille,
        modes: Modes,
        heights: Vec<f64>,
        time_scale: f64,
        stress_scale: f64,
    },
    Steady(SteadyChannel),
}

/// The reference solution of a channel case.
pub struct Reference {
    solution: Solution,
    height: f64,
    /// U = ρgH²/(8η0), the Oldroyd-B steady centre-line velocity.
    pub velocity_scale: f64,
}

impl Reference {
    /// The reference for a channel case; an error if the model has no steady state at these
    /// parameters (e.g. Giesekus without solvent beyond its largest shear stress).
    pub fn for_case(case: &Case) -> Result<Self, String> {
        let d = case.derived();
        let c = &case.channel;
        let f = &case.fluid;
        let solution = match f.model {
            crate::rheology::Model::Newtonian
            | crate::rheology::Model::OldroydB
            | crate::rheology::Model::Ucm => Solution::StartUp {
                series: StartupPoiseuille::new(d.reynolds, d.weissenberg, f.beta),
                modes: Modes::default(),
                heights: Vec::new(),
                time_scale: c.height / d.velocity_scale,
                stress_scale: f.viscosity * d.velocity_scale / c.height,
            },
            _ => Solution::Steady(SteadyChannel::new(f, c.body_force[0], c.height)?),
        };
        Ok(Self {
            solution,
            height: c.height,
            velocity_scale: d.velocity_scale,
        })
    }

    /// `waters-king` or `steady-channel`.
    pub fn name(&self) -> &'static str {
        match self.solution {
            Solution::StartUp { .. } => "waters-king",
            Solution::Steady(_) => "steady-channel",
        }
    }

    /// Whether the reference is the steady state (compared at the end of a run).
    pub fn is_steady(&self) -> bool {
        matches!(self.solution, Solution::Steady(_))
    }

    /// Exact streamwise velocity at each particle's height, into `out`.
    pub fn velocity_at(&mut self, positions: &[Vec2], t: f64, out: &mut Vec<f64>) {
        out.resize(positions.len(), 0.0);
        let (height, scale) = (self.height, self.velocity_scale);
        match &mut self.solution {
            Solution::StartUp {
                series,
                modes,
                heights,
                time_scale,
                ..
            } => {
                heights.clear();
                heights.extend(positions.iter().map(|p| p.y / height));
                series.velocity_profile(heights, t / *time_scale, modes, out);
                out.iter_mut().for_each(|v| *v *= scale);
            }
            Solution::Steady(ch) => {
                for (o, p) in out.iter_mut().zip(positions) {
                    *o = ch.velocity(p.y);
                }
            }
        }
    }

    /// Exact centre-line velocity.
    pub fn centre_velocity(&self, t: f64) -> f64 {
        match &self.solution {
            Solution::StartUp {
                series, time_scale, ..
            } => series.velocity(0.5, t / time_scale) * self.velocity_scale,
            Solution::Steady(ch) => ch.centre_velocity(),
        }
    }

    /// Exact velocity at heights `ys`.
    pub fn velocity_profile(&self, ys: &[f64], t: f64) -> Vec<f64> {
        match &self.solution {
            Solution::StartUp {
                series, time_scale, ..
            } => {
                let m = series.modes(t / time_scale);
                ys.iter()
                    .map(|y| {
                        waters_king::velocity_from_modes(&m, y / self.height) * self.velocity_scale
                    })
                    .collect()
            }
            Solution::Steady(ch) => ys.iter().map(|&y| ch.velocity(y)).collect(),
        }
    }

    /// Exact polymer stresses at heights `ys` and time t.
    pub fn stress_profiles(&self, ys: &[f64], t: f64) -> Result<StressProfiles, String> {
        match &self.solution {
            Solution::StartUp {
                series,
                time_scale,
                stress_scale,
                ..
            } => {
                let eta: Vec<f64> = ys.iter().map(|y| y / self.height).collect();
                let tau = t / time_scale;
                let scale = |v: Vec<f64>| v.into_iter().map(|x| x * stress_scale).collect();
                Ok(StressProfiles {
                    xy: scale(series.shear_stress_profile(&eta, tau)),
                    xx: scale(series.normal_stress_profile(&eta, tau, 2000)),
                    yy: vec![0.0; ys.len()],
                })
            }
            Solution::Steady(ch) => {
                let mut p = StressProfiles::default();
                for &y in ys {
                    let s = ch.polymer_stress(y)?;
                    p.xy.push(s.xy);
                    p.xx.push(s.xx);
                    p.yy.push(s.yy);
                }
                Ok(p)
            }
        }
    }
}
