//! The analytic reference of a run, in the case's dimensional units: the Waters & King
//! start-up series for Newtonian, Oldroyd-B and UCM channel flow, the steady channel
//! solution for the non-linear models (whose start-up has no closed form), the start-up of
//! pipe flow (its Bessel series, read in the meridional plane (x, r)), and the decaying
//! Taylor–Green vortex.
//!
//! Error norms: for a channel or a pipe, the streamwise velocity only (King & Lind's L2 error,
//! `sqrt(mean (u_i − u_exact(y_i))²)/U`); for Taylor–Green, the whole velocity vector.

use crate::analysis::analytic::taylor_green::velocity as taylor_green_velocity;
use crate::analysis::analytic::waters_king::{self, Modes, StartupPoiseuille};
use crate::analysis::analytic::{StartupCouette, StartupPipe, SteadyChannel};
use crate::analysis::diagnostics;
use crate::engine::math::Vec2;
use crate::engine::rheology::{Fluid, Model};
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
    /// Start-up plane Couette flow (Newtonian, Oldroyd-B, UCM).
    Couette {
        series: StartupCouette,
        heights: Vec<f64>,
    },
    /// Start-up pipe flow (Newtonian, Oldroyd-B, UCM); positions are (x, r).
    Pipe {
        series: StartupPipe,
        modes: Modes,
        radii: Vec<f64>,
        time_scale: f64,
        stress_scale: f64,
    },
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
    /// The channel's height, the pipe's radius, the Taylor–Green box's side.
    height: f64,
    /// The case's velocity scale U.
    pub velocity_scale: f64,
    exact: Vec<Vec2>,
    scratch: Vec<f64>,
}

impl Reference {
    /// Start-up Poiseuille flow in a channel of `height` driven by `body_force` (along x):
    /// the Waters & King series for Newtonian, Oldroyd-B and UCM fluids, the exact steady
    /// solution for the others; an error where there is none at these parameters (e.g. a
    /// Giesekus channel without solvent beyond its largest shear stress). `velocity_scale`
    /// is the case's U.
    pub fn channel(
        f: &Fluid,
        body_force: f64,
        height: f64,
        velocity_scale: f64,
    ) -> Result<Self, String> {
        let u = velocity_scale;
        let solution = match f.model {
            Model::Newtonian | Model::OldroydB | Model::Ucm if f.law.is_constant() => {
                Solution::StartUp {
                    series: StartupPoiseuille::new(
                        f.density * u * height / f.viscosity,
                        f.relaxation_time * u / height,
                        f.beta,
                    ),
                    modes: Modes::default(),
                    heights: Vec::new(),
                    time_scale: height / u,
                    stress_scale: f.viscosity * u / height,
                }
            }
            _ => Solution::Steady(SteadyChannel::new(f, body_force, height)?),
        };
        Ok(Self::new(solution, height, u))
    }

    /// Start-up pipe flow in a pipe of `radius` driven by a body force along its axis: the
    /// Bessel series of `analytic::pipe`, scaled by the case's `velocity_scale` U (the steady
    /// centre-line velocity ρgR²/(4η0)) and R; Newtonian, Oldroyd-B and UCM only.
    pub fn pipe(f: &Fluid, radius: f64, velocity_scale: f64) -> Result<Self, String> {
        if !matches!(f.model, Model::Newtonian | Model::OldroydB | Model::Ucm)
            || !f.law.is_constant()
        {
            return Err("start-up pipe flow is analytic for Newtonian, Oldroyd-B and UCM".into());
        }
        let u = velocity_scale;
        let solution = Solution::Pipe {
            series: StartupPipe::new(
                f.density * u * radius / f.viscosity,
                f.relaxation_time * u / radius,
                f.beta,
            ),
            modes: Modes::default(),
            radii: Vec::new(),
            time_scale: radius / u,
            stress_scale: f.viscosity * u / radius,
        };
        Ok(Self::new(solution, radius, u))
    }

    /// Start-up plane Couette flow between walls at y = 0 and `height` sliding at
    /// `wall_velocity` (x-components), from rest: Newtonian, Oldroyd-B and UCM only.
    pub fn couette(f: &Fluid, height: f64, wall_velocity: [f64; 2]) -> Result<Self, String> {
        if !matches!(f.model, Model::Newtonian | Model::OldroydB | Model::Ucm)
            || !f.law.is_constant()
        {
            return Err("start-up Couette is analytic for Newtonian, Oldroyd-B and UCM".into());
        }
        let series = StartupCouette {
            density: f.density,
            solvent_viscosity: f.solvent_viscosity(),
            polymer_viscosity: f.polymer_viscosity(),
            relaxation_time: f.relaxation_time,
            height,
            wall_velocity,
        };
        let scale = wall_velocity[0].abs().max(wall_velocity[1].abs());
        let solution = Solution::Couette {
            series,
            heights: Vec::new(),
        };
        Ok(Self::new(solution, height, scale))
    }

    /// The decaying Taylor–Green vortex of initial amplitude `amplitude` in a box of side
    /// `length` (Newtonian fluids only).
    pub fn taylor_green(f: &Fluid, length: f64, amplitude: f64) -> Result<Self, String> {
        if f.model != Model::Newtonian || !f.law.is_constant() {
            return Err("the Taylor–Green decay is analytic for a Newtonian fluid only".into());
        }
        let k = 2.0 * PI / length;
        let solution = Solution::TaylorGreen {
            length,
            amplitude,
            decay_rate: 2.0 * f.viscosity / f.density * k * k,
        };
        Ok(Self::new(solution, length, amplitude))
    }

    fn new(solution: Solution, height: f64, velocity_scale: f64) -> Self {
        Self {
            solution,
            height,
            velocity_scale,
            exact: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// `waters-king`, `steady-channel` or `taylor-green`.
    pub fn name(&self) -> &'static str {
        match self.solution {
            Solution::StartUp { .. } => "waters-king",
            Solution::Steady(_) => "steady-channel",
            Solution::Couette { .. } => "startup-couette",
            Solution::Pipe { .. } => "startup-pipe",
            Solution::TaylorGreen { .. } => "taylor-green",
        }
    }

    /// Whether the reference is a steady state (compared at the end of a run).
    pub fn is_steady(&self) -> bool {
        matches!(self.solution, Solution::Steady(_))
    }

    /// A pipe's total wall shear stress σ_xr(R, t) = η_s ∂u/∂r + τ_p,xr at r = R (negative
    /// for flow along +x; steady −ρgR/2); None for other references.
    pub fn wall_shear_stress(&self, t: f64) -> Option<f64> {
        match &self.solution {
            Solution::Pipe {
                series,
                time_scale,
                stress_scale,
                ..
            } => Some(series.wall_shear_stress(t / time_scale) * stress_scale),
            _ => None,
        }
    }

    /// The extent of its profiles: the channel's height, the pipe's radius.
    pub fn extent(&self) -> f64 {
        self.height
    }

    /// Whether the reference describes a channel or a pipe (profiles across y, or r, are
    /// meaningful).
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
            Solution::Pipe {
                series,
                modes,
                radii,
                time_scale,
                ..
            } => {
                radii.clear();
                radii.extend(positions.iter().map(|p| p.y / height));
                self.scratch.resize(positions.len(), 0.0);
                series.velocity_profile(radii, t / *time_scale, modes, &mut self.scratch);
                for (o, u) in out.iter_mut().zip(&self.scratch) {
                    *o = Vec2::new(u * scale, 0.0);
                }
            }
            Solution::Couette { series, heights } => {
                heights.clear();
                heights.extend(positions.iter().map(|p| p.y));
                series.velocity_profile(heights, t, &mut self.scratch);
                for (o, u) in out.iter_mut().zip(&self.scratch) {
                    *o = Vec2::new(*u, 0.0);
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
            Solution::Couette { series, .. } => series.velocity(0.5 * self.height, t),
            Solution::Pipe {
                series, time_scale, ..
            } => series.velocity(0.0, t / time_scale) * self.velocity_scale,
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
            Solution::Couette { series, .. } => {
                let mut out = Vec::new();
                series.velocity_profile(ys, t, &mut out);
                out
            }
            Solution::Pipe {
                series, time_scale, ..
            } => {
                let m = series.modes(t / time_scale);
                ys.iter()
                    .map(|r| series.velocity_from_modes(&m, r / self.height) * self.velocity_scale)
                    .collect()
            }
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
                    xx: scale(series.normal_stress_profile(
                        &eta,
                        tau,
                        series.normal_stress_substeps(tau),
                    )),
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
            Solution::Couette { series, .. } => Ok(StressProfiles {
                xy: ys.iter().map(|&y| series.shear_stress(y, t)).collect(),
                // τ_xx = 2λ∫ τ_xy γ̇ e^{..}: not integrated (module docs); τ_yy = 0 exactly.
                xx: vec![f64::NAN; ys.len()],
                yy: vec![0.0; ys.len()],
            }),
            Solution::Pipe {
                series,
                time_scale,
                stress_scale,
                ..
            } => {
                let radii: Vec<f64> = ys.iter().map(|r| r / self.height).collect();
                let tau = t / time_scale;
                let scale = |v: Vec<f64>| v.into_iter().map(|x| x * stress_scale).collect();
                // The series' τ_zz is the axial normal stress: τ_xx of a pipe along x.
                Ok(StressProfiles {
                    xy: scale(series.shear_stress_profile(&radii, tau)),
                    xx: scale(series.normal_stress_profile(
                        &radii,
                        tau,
                        series.normal_stress_substeps(tau),
                    )),
                    yy: vec![0.0; ys.len()],
                })
            }
            Solution::TaylorGreen { .. } => Err("no stress profiles for Taylor–Green".into()),
        }
    }
}
