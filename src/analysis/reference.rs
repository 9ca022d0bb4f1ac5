//! The analytic reference of a run, in the case's dimensional units: the Waters & King
//! start-up series for Newtonian, Oldroyd-B and UCM channel flow, the steady channel
//! solution for the non-linear models (whose start-up has no closed form), and the decaying
//! Taylor–Green vortex.
//!
//! Error norms: for a channel, the streamwise velocity only (King & Lind's L2 error,
//! `sqrt(mean (u_i − u_exact(y_i))²)/U`); for Taylor–Green, the whole velocity vector.

use crate::analysis::analytic::waters_king::{self, Modes, StartupPoiseuille};
use crate::analysis::analytic::SteadyChannel;
use crate::analysis::diagnostics;
use crate::engine::math::Vec2;
use crate::engine::rheology::Model;
use crate::setup::case::{Case, SceneKind};
use crate::setup::scene::taylor_green_velocity;
use std::f64::consts::PI;

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
    /// Amplitude U e^{−2νk²t}, k = 2π/L.
    TaylorGreen {
        length: f64,
        amplitude: f64,
        decay_rate: f64,
    },
}

/// The reference solution of a case.
pub struct Reference {
    solution: Solution,
    height: f64,
    /// The case's velocity scale U.
    pub velocity_scale: f64,
    exact: Vec<Vec2>,
    scratch: Vec<f64>,
}

impl Reference {
    /// The reference for a case; an error if there is none at these parameters (e.g. a
    /// Giesekus channel without solvent beyond its largest shear stress, or a viscoelastic
    /// Taylor–Green vortex).
    pub fn for_case(case: &Case) -> Result<Self, String> {
        let d = case.derived();
        let c = &case.scene;
        let f = &case.fluid;
        if c.cylinder.is_some() {
            return Err("no analytic solution for flow past a cylinder".into());
        }
        let solution = match (c.kind, f.model) {
            (SceneKind::Channel, Model::Newtonian | Model::OldroydB | Model::Ucm) => {
                Solution::StartUp {
                    series: StartupPoiseuille::new(d.reynolds, d.weissenberg, f.beta),
                    modes: Modes::default(),
                    heights: Vec::new(),
                    time_scale: c.height / d.velocity_scale,
                    stress_scale: f.viscosity * d.velocity_scale / c.height,
                }
            }
            (SceneKind::Channel, _) => {
                Solution::Steady(SteadyChannel::new(f, c.body_force[0], c.height)?)
            }
            (SceneKind::TaylorGreen, Model::Newtonian) => {
                let k = 2.0 * PI / c.length;
                Solution::TaylorGreen {
                    length: c.length,
                    amplitude: c.velocity,
                    decay_rate: 2.0 * f.viscosity / f.density * k * k,
                }
            }
            (SceneKind::TaylorGreen, _) => {
                return Err("the Taylor–Green decay is analytic for a Newtonian fluid only".into());
            }
            (SceneKind::Drop, _) => {
                return Err("no analytic solution for a drop impact (see drop.csv)".into());
            }
            (SceneKind::Jet, _) => {
                return Err("no analytic solution for a buckling jet (see jet.csv)".into());
            }
        };
        Ok(Self {
            solution,
            height: c.height,
            velocity_scale: d.velocity_scale,
            exact: Vec::new(),
            scratch: Vec::new(),
        })
    }

    /// `waters-king`, `steady-channel` or `taylor-green`.
    pub fn name(&self) -> &'static str {
        match self.solution {
            Solution::StartUp { .. } => "waters-king",
            Solution::Steady(_) => "steady-channel",
            Solution::TaylorGreen { .. } => "taylor-green",
        }
    }

    /// Whether the reference is a steady state (compared at the end of a run).
    pub fn is_steady(&self) -> bool {
        matches!(self.solution, Solution::Steady(_))
    }

    /// Whether the reference describes a channel (profiles across y are meaningful).
    pub fn is_channel(&self) -> bool {
        !matches!(self.solution, Solution::TaylorGreen { .. })
    }

    /// Exact velocity at each particle, into `out`.
    pub fn velocity_at(&mut self, positions: &[Vec2], t: f64, out: &mut Vec<Vec2>) {
        out.resize(positions.len(), Vec2::zeros());
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
                self.scratch.resize(positions.len(), 0.0);
                series.velocity_profile(heights, t / *time_scale, modes, &mut self.scratch);
                for (o, u) in out.iter_mut().zip(&self.scratch) {
                    *o = Vec2::new(u * scale, 0.0);
                }
            }
            Solution::Steady(ch) => {
                for (o, p) in out.iter_mut().zip(positions) {
                    *o = Vec2::new(ch.velocity(p.y), 0.0);
                }
            }
            Solution::TaylorGreen {
                length,
                amplitude,
                decay_rate,
            } => {
                let a = *amplitude * (-*decay_rate * t).exp();
                for (o, p) in out.iter_mut().zip(positions) {
                    *o = taylor_green_velocity(p, *length, a);
                }
            }
        }
    }

    /// The velocity error `sqrt(mean_i |u_i − u_exact|²)/U`: streamwise for a channel, the
    /// whole vector for Taylor–Green.
    pub fn l2_error(&mut self, positions: &[Vec2], velocity: &[Vec2], t: f64) -> f64 {
        let mut exact = std::mem::take(&mut self.exact);
        self.velocity_at(positions, t, &mut exact);
        let channel = self.is_channel();
        let sum = diagnostics::blocked_sum(velocity.len(), |i| {
            let d = velocity[i] - exact[i];
            if channel {
                d.x * d.x
            } else {
                d.norm_squared()
            }
        });
        self.exact = exact;
        (sum / velocity.len() as f64).sqrt() / self.velocity_scale
    }

    /// ‖u − u_exact‖/‖u_exact‖ over the particles (same components as [`Self::l2_error`]).
    pub fn relative_l2(&mut self, positions: &[Vec2], velocity: &[Vec2], t: f64) -> Option<f64> {
        let mut exact = std::mem::take(&mut self.exact);
        self.velocity_at(positions, t, &mut exact);
        let channel = self.is_channel();
        let (mut diff, mut base) = (0.0, 0.0);
        for (u, e) in velocity.iter().zip(&exact) {
            let d = u - e;
            diff += if channel { d.x * d.x } else { d.norm_squared() };
            base += if channel { e.x * e.x } else { e.norm_squared() };
        }
        self.exact = exact;
        (base > 0.0).then(|| (diff / base).sqrt())
    }

    /// The characteristic velocity of the series: the exact centre-line velocity of a
    /// channel, the exact amplitude of the Taylor–Green vortex.
    pub fn characteristic_velocity(&self, t: f64) -> f64 {
        match &self.solution {
            Solution::StartUp {
                series, time_scale, ..
            } => series.velocity(0.5, t / time_scale) * self.velocity_scale,
            Solution::Steady(ch) => ch.centre_velocity(),
            Solution::TaylorGreen {
                amplitude,
                decay_rate,
                ..
            } => amplitude * (-decay_rate * t).exp(),
        }
    }

    /// Exact streamwise velocity at heights `ys` (channels).
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
            Solution::TaylorGreen { .. } => vec![f64::NAN; ys.len()],
        }
    }

    /// Exact polymer stresses at heights `ys` and time t (channels).
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
            Solution::TaylorGreen { .. } => Err("no stress profiles for Taylor–Green".into()),
        }
    }
}

/// The measured characteristic velocity of a scene: the channel's centre-line velocity (a
/// quadratic fit through the particles near y = H/2), the Taylor–Green amplitude, the
/// projection `2 mean(u·û)` on the unit-amplitude mode û, or a drop's centre-of-mass
/// vertical velocity.
pub fn measured_velocity(
    kind: SceneKind,
    positions: &[Vec2],
    velocity: &[Vec2],
    length: f64,
    height: f64,
    spacing: f64,
) -> f64 {
    match kind {
        SceneKind::Channel => {
            diagnostics::centre_line_velocity(positions, velocity, 0.5 * height, spacing)
        }
        SceneKind::TaylorGreen => {
            let sum = diagnostics::blocked_sum(positions.len(), |i| {
                velocity[i].dot(&taylor_green_velocity(&positions[i], length, 1.0))
            });
            2.0 * sum / positions.len() as f64
        }
        SceneKind::Drop | SceneKind::Jet => {
            diagnostics::blocked_sum(velocity.len(), |i| velocity[i].y) / velocity.len() as f64
        }
    }
}
