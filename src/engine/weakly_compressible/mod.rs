//! The weakly compressible SPH scheme (WCSPH), the method most SPH users would pick instead of
//! the projection: in the viscoelastic form of Fang, Owens, Tacher & Parriaux (2006), with the
//! δ-SPH density diffusion of Antuono, Colagrossi, Marrone & Molteni (2010) as the modern
//! variant. It replaces Steps 5–6 of the projection (the PPE and the projection) and shares
//! everything else: kernel, neighbour lists, mirrors, ∇u^n, the constitutive update (direct,
//! as Fang et al., or log-conformation), the viscous term (explicit or implicit) and outputs.
//!
//! * Equation of state, Fang et al. eq. (10): `p = c²(ρ − ρ0)`. Being linear, the pressure
//!   itself is evolved and ρ = ρ0 + p/c² follows from it.
//! * Continuity, Fang et al. eq. (26): `dρ_i/dt = Σ_j m_j u_ij·∇W_ij` (m_j = ρ0 δV), with
//!   u^{n+1} (after the momentum update: symplectic for the acoustic pair p, u), plus the δ-SPH
//!   term `δ h c Σ_j ψ_ij·∇W_ij V_j`, `ψ_ij = 2(ρ_j − ρ_i) r_ji/|r_ij|² − (⟨∇ρ⟩_i^L +
//!   ⟨∇ρ⟩_j^L)` with the Bonet–Lok corrected gradients.
//! * Momentum, Fang et al. eqs. (27), (38): the symmetric (momentum-conserving) form
//!   `Σ_j m_j (σ_i/ρ_i² + σ_j/ρ_j² − Π_ij I + f_ijⁿ (R_i + R_j))·∇W_ij` with
//!   σ = −pI + τ_p; the solvent's viscous term is the shared Morris Laplacian of the
//!   predictor (Fang et al. use a nested summation). This is the term whose tensile part
//!   makes particles clump (the tensile instability), which the artificial stress R answers.
//! * Time step: the acoustic limit `C_a h/(c + |u|_max)` beside the projection's viscous,
//!   advective and elastic limits.

pub mod artificial;

use crate::engine::dimension::{Dim, Dimension, Matrix, Sym, Vector};
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::{Sym2, Vec2};
use crate::engine::neighbourhood::Hood;
use crate::engine::rheology::Fluid;
use crate::engine::settings::{in_range, positive, Invalid};
pub use artificial::{ArtificialStress, ArtificialViscosity};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The acoustic Courant number C_a of δt ≤ C_a h/(c + |u|): Morris, Fox & Zhu (1997) take
/// 0.25 with the quintic kernel (h = 1.3δr here as there).
pub const ACOUSTIC_COURANT: f64 = 0.25;

/// The density variation the default speed of sound is chosen for (Mach 0.1): ~1 %.
pub const DEFAULT_MACH: f64 = 0.1;

/// Beyond this relative density deviation a run has left the weakly compressible regime
/// (designed for ~1 %): it stops with the reason.
pub const DENSITY_DEVIATION_LIMIT: f64 = 0.25;

/// `[scheme.wcsph]`: the weakly compressible scheme's settings as a case file writes them (read
/// with `scheme.method = "wcsph"`); [`WeaklyCompressible`] is what the step uses.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct WcsphSettings {
    /// The speed of sound c (unset: from `mach`, see [`sound_speed_for`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sound_speed: Option<f64>,
    /// The Mach number the default c is chosen for (0.1: δρ/ρ ~ 1 %).
    pub mach: f64,
    /// Monaghan's artificial viscosity α_Π (Fang et al.: 1).
    pub artificial_viscosity: f64,
    /// Monaghan's β_Π (Fang et al.: 2).
    pub artificial_viscosity_beta: f64,
    /// v0 of the shear-rate dependent artificial viscosity of Wróblewski et al. (2008, eq.
    /// (10)) (unset: Monaghan's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub artificial_viscosity_velocity: Option<f64>,
    /// The artificial stress ε (0 = off; Fang et al.: 0.5 Oldroyd-B, 0.2 Newtonian).
    pub artificial_stress: f64,
    /// The artificial stress's exponent n (Fang et al.: 4).
    pub artificial_stress_exponent: i32,
    /// δ of the δ-SPH density diffusion (0 = off; Antuono et al. 2010: 0.1).
    pub density_diffusion: f64,
    /// K of ρ0c² ≥ K τ_max, the speed of sound following the stretched polymer (0 = c fixed
    /// at `sound_speed`).
    pub sound_speed_stress_factor: f64,
}

impl Default for WcsphSettings {
    fn default() -> Self {
        Self {
            sound_speed: None,
            mach: DEFAULT_MACH,
            artificial_viscosity: 0.0,
            artificial_viscosity_beta: 0.0,
            artificial_viscosity_velocity: None,
            artificial_stress: 0.0,
            artificial_stress_exponent: 4,
            density_diffusion: 0.0,
            sound_speed_stress_factor: 0.0,
        }
    }
}

impl WcsphSettings {
    /// The table's own checks and the scheme they describe, with `default_sound_speed` (the
    /// scene's, [`sound_speed_for`]) where `sound_speed` is unset.
    pub fn resolve(
        &self,
        default_sound_speed: impl FnOnce(f64) -> f64,
    ) -> Result<WeaklyCompressible, Invalid> {
        let mach = positive("mach", self.mach)?;
        let sound_speed = match self.sound_speed {
            Some(c) => positive("sound_speed", c)?,
            None => default_sound_speed(mach),
        };
        let exponent = self.artificial_stress_exponent;
        if !(1..=16).contains(&exponent) {
            return Err(Invalid::new(
                "artificial_stress_exponent",
                format!("must be an integer in 1..=16 (Fang et al.: 4), got {exponent}"),
            ));
        }
        Ok(WeaklyCompressible {
            sound_speed,
            viscosity: ArtificialViscosity {
                alpha: in_range("artificial_viscosity", self.artificial_viscosity, 0.0, 10.0)?,
                beta: in_range(
                    "artificial_viscosity_beta",
                    self.artificial_viscosity_beta,
                    0.0,
                    10.0,
                )?,
                velocity_scale: self
                    .artificial_viscosity_velocity
                    .map(|v| positive("artificial_viscosity_velocity", v))
                    .transpose()?,
            },
            stress: ArtificialStress {
                epsilon: in_range("artificial_stress", self.artificial_stress, 0.0, 1.0)?,
                exponent,
            },
            density_diffusion: in_range("density_diffusion", self.density_diffusion, 0.0, 1.0)?,
            stress_factor: in_range(
                "sound_speed_stress_factor",
                self.sound_speed_stress_factor,
                0.0,
                1e3,
            )?,
        })
    }
}

/// The settings of the weakly compressible scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeaklyCompressible {
    /// c, m/s (units of the case).
    pub sound_speed: f64,
    pub viscosity: ArtificialViscosity,
    pub stress: ArtificialStress,
    /// δ of δ-SPH (0 = off; Antuono et al. take 0.1).
    pub density_diffusion: f64,
    /// K of ρ0c² ≥ K τ_max: the speed of sound rises with the largest principal polymer
    /// stress (0 = c fixed). See [`WeakStage::follow_polymer`].
    pub stress_factor: f64,
}

/// The speed of sound for a Mach number: the largest of the scales Morris, Fox & Zhu (1997)
/// list (advective U, viscous √(νU/L), body force √(|g|L)) and the polymer's shear-wave speed
/// √(G/ρ), over the Mach number, so that δρ/ρ ~ Ma².
pub fn sound_speed_for(
    mach: f64,
    velocity: f64,
    nu: f64,
    gravity: f64,
    length: f64,
    modulus_over_rho: f64,
) -> f64 {
    let scale = velocity
        .max((nu * velocity / length).sqrt())
        .max((gravity * length).sqrt())
        .max(modulus_over_rho.sqrt());
    scale / mach
}

/// The linear equation of state p = c²(ρ − ρ0), Fang et al. eq. (10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eos {
    pub rho0: f64,
    pub sound_speed: f64,
}

impl Eos {
    /// ρ = ρ0 + p/c².
    #[inline]
    pub fn density(&self, p: f64) -> f64 {
        self.rho0 + p / (self.sound_speed * self.sound_speed)
    }
}

/// The stage: the pressure extended to the ghosts, the stresses, the accelerations and the
/// pressure rate, reused every step.
#[derive(Clone, Debug)]
pub struct WeakStage {
    pub settings: WeaklyCompressible,
    eos: Eos,
    /// W(δr), the reference of f_ij.
    w_spacing: f64,
    pressure_ext: Vec<f64>,
    /// σ_i/ρ_i² without the pressure: τ_p/ρ² (extended).
    stress_ext: Vec<Sym2>,
    /// R_i (extended; empty without artificial stress).
    artificial_ext: Vec<Sym2>,
    fluid_tensor: Vec<Sym2>,
    velocity_ext: Vec<Vec2>,
    /// ⟨∇p⟩^L (extended; δ-SPH only).
    gradient_ext: Vec<Vec2>,
    /// The momentum terms of this scheme, per fluid particle.
    acceleration: Vec<Vec2>,
    rate: Vec<f64>,
    /// The largest |ρ/ρ0 − 1| of the last update.
    deviation: f64,
}

/// What the momentum sum reads.
pub struct MomentumInputs<'a, const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub hood: Hood<'a, D>,
    pub kernel: &'a QuinticSpline,
    pub pressure: &'a [f64],
    /// u^n extended to the ghosts.
    pub velocity_ext: &'a [Vector<D>],
    /// A^{n+½} per fluid particle (empty for a Newtonian fluid) and the fluid, for τ_p.
    pub conformation: &'a [Sym<D>],
    pub fluid: &'a Fluid,
    /// ∇u^n, for the solvent stress 2η_s D in the artificial stress's total stress.
    pub grad_u: &'a [Matrix<D>],
}

impl WeakStage {
    pub fn new(
        settings: WeaklyCompressible,
        rho0: f64,
        kernel: &QuinticSpline,
        spacing: f64,
    ) -> Self {
        Self {
            settings,
            eos: Eos {
                rho0,
                sound_speed: settings.sound_speed,
            },
            w_spacing: kernel.value(spacing),
            pressure_ext: Vec::new(),
            stress_ext: Vec::new(),
            artificial_ext: Vec::new(),
            fluid_tensor: Vec::new(),
            velocity_ext: Vec::new(),
            gradient_ext: Vec::new(),
            acceleration: Vec::new(),
            rate: Vec::new(),
            deviation: 0.0,
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.pressure_ext)
            + b(&self.stress_ext)
            + b(&self.artificial_ext)
            + b(&self.fluid_tensor)
            + b(&self.velocity_ext)
            + b(&self.gradient_ext)
            + b(&self.acceleration)
            + b(&self.rate)
    }

    /// The largest |ρ/ρ0 − 1| after the last continuity update (0 before the first).
    pub fn density_deviation(&self) -> f64 {
        self.deviation
    }

    /// The fluid volume Σ m_i/ρ_i of a pressure field, in units of δV.
    pub fn volume(&self, pressure: &[f64]) -> f64 {
        let eos = self.eos;
        pressure.iter().map(|&p| eos.rho0 / eos.density(p)).sum()
    }

    /// The acoustic step limit C_a h/(c + |u|_max).
    pub fn dt_limit(&self, h: f64, max_speed: f64) -> f64 {
        ACOUSTIC_COURANT * h / (self.eos.sound_speed + max_speed)
    }

    /// The speed of sound of this step.
    pub fn sound_speed(&self) -> f64 {
        self.eos.sound_speed
    }

    /// Raises c to √(K τ_max/ρ0) when the polymer is stretched beyond ρ0c²/K (never below
    /// the set speed). Why: in the symmetric momentum form a polymer tension τ_xx acts like a
    /// negative pressure, and the particle arrangement is stable only while the equation of
    /// state's stiffness ρ0c² dominates it. Measured (start-up Poiseuille, Re = 1, β = 0.1,
    /// c = 28.3): Wi = 16 and 64 broke down, velocity first, once τ_xx ≈ 0.33ρ0c² near the
    /// walls, with det A ≥ 1 and the elastic Courant number 0.13; with c doubled Wi = 16 ran
    /// to t = 15. Following τ_max helps but does not cure (H/δr = 15, t = 15): K = 6 moved the
    /// breakdowns at Wi = 16 / 64 from t = 4.8 / 5.5 to 11.4 / 8.5, K = 12 ran Wi = 16 through
    /// and Wi = 64 to 11.7, where c chased a stress that was already running away; so it is
    /// off by default (the classic fixed c). The pressure is the evolved variable, so c may
    /// change between steps (an artificial compressibility).
    pub fn follow_polymer(&mut self, max_polymer_stress: f64) {
        let k = self.settings.stress_factor;
        let base = self.settings.sound_speed;
        self.eos.sound_speed = if k > 0.0 && max_polymer_stress > 0.0 {
            base.max((k * max_polymer_stress / self.eos.rho0).sqrt())
        } else {
            base
        };
    }

    /// The accelerations of the pressure, polymer stress, artificial viscosity and stress in
    /// the symmetric form (module docs), for the predictor.
    pub fn momentum(&mut self, m: &MomentumInputs) -> &[Vec2] {
        let Hood { list, sums, ghosts } = m.hood;
        let n = m.pressure.len();
        ghosts.extend_pressure(m.pressure, &mut self.pressure_ext);
        self.fill_stresses(m);
        self.acceleration.resize(n, Vec2::zeros());
        let (p_ext, tau_ext, r_ext) = (&self.pressure_ext, &self.stress_ext, &self.artificial_ext);
        let eos = self.eos;
        let mass = eos.rho0 * sums.dv;
        let (c, h, w_dr) = (eos.sound_speed, m.kernel.h(), self.w_spacing);
        let (av, stress) = (self.settings.viscosity, self.settings.stress);
        self.acceleration
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, acc)| {
                let rho_i = eos.density(p_ext[i]);
                let p_i = p_ext[i] / (rho_i * rho_i);
                let mut a = Vec2::zeros();
                for k in list.range(i) {
                    let j = list.index[k] as usize;
                    let rij = list.rij[k];
                    let grad = sums.factor[k] * rij;
                    let rho_j = eos.density(p_ext[j]);
                    let mut scalar = p_i + p_ext[j] / (rho_j * rho_j);
                    if !av.is_off() {
                        let u_ij = m.velocity_ext[i] - m.velocity_ext[j];
                        scalar += av.pair(u_ij, rij, 0.5 * (rho_i + rho_j), c, h);
                    }
                    let mut tensor = Sym2::ZERO;
                    if !tau_ext.is_empty() {
                        tensor = tau_ext[i] + tau_ext[j];
                    }
                    if !r_ext.is_empty() {
                        let f = stress.pair_weight(m.kernel, rij.norm(), w_dr);
                        tensor += (r_ext[i] + r_ext[j]) * f;
                    }
                    a += mass * (tensor.dot(&grad) - scalar * grad);
                }
                *acc = a;
            });
        &self.acceleration
    }

    /// τ_p/ρ² and the artificial stress R of every particle, extended to the ghosts.
    fn fill_stresses(&mut self, m: &MomentumInputs) {
        let ghosts = m.hood.ghosts;
        let n = m.pressure.len();
        let eos = self.eos;
        let rho = |i: usize| eos.density(m.pressure[i]);
        self.stress_ext.clear();
        let tau = |i: usize| match m.conformation.get(i) {
            Some(a) => m.fluid.polymer_stress(a),
            None => Sym2::ZERO,
        };
        if !m.conformation.is_empty() {
            self.fluid_tensor.clear();
            self.fluid_tensor
                .extend((0..n).map(|i| tau(i) * (1.0 / rho(i).powi(2))));
            ghosts.continue_tensor(&self.fluid_tensor, &mut self.stress_ext);
        }
        self.artificial_ext.clear();
        if self.settings.stress.is_off() {
            return;
        }
        let stress = self.settings.stress;
        self.fluid_tensor.clear();
        self.fluid_tensor.extend((0..n).map(|i| {
            let solvent = Sym2::sym_part(&m.grad_u[i]) * (2.0 * m.fluid.solvent_viscosity());
            let total = tau(i) + solvent - Sym2::IDENTITY * m.pressure[i];
            stress.tensor(&total, rho(i))
        }));
        ghosts.continue_tensor(&self.fluid_tensor, &mut self.artificial_ext);
    }

    /// Continuity (module docs) with u^{n+1}: p^{n+1} = p^n + δt c² dρ/dt. With shifting
    /// (`shift` = u_ps), the ALE transport u_ps·∇p of the moved particles (King & Lind's
    /// form (1) for ρ) is added.
    pub fn continuity(
        &mut self,
        hood: Hood,
        kernel: &QuinticSpline,
        velocity: &[Vec2],
        shift: Option<&[Vec2]>,
        pressure: &mut [f64],
        dt: f64,
    ) {
        let Hood { list, sums, ghosts } = hood;
        let n = pressure.len();
        ghosts.extend_velocity(velocity, &mut self.velocity_ext);
        ghosts.extend_pressure(pressure, &mut self.pressure_ext);
        let delta = self.settings.density_diffusion;
        let c = self.eos.sound_speed;
        self.gradient_ext.clear();
        if delta > 0.0 || shift.is_some() {
            self.gradient_ext.resize(n, Vec2::zeros());
            sums.gradient_scalar(list, &self.pressure_ext, &mut self.gradient_ext);
            // A mirror's gradient of an even field is its parent's reflected.
            for (g, nrm) in ghosts.parent.iter().zip(&ghosts.normal) {
                let parent = self.gradient_ext[*g as usize];
                self.gradient_ext.push(parent - 2.0 * parent.dot(nrm) * nrm);
            }
        }
        self.rate.resize(n, 0.0);
        let (u, p, grad) = (&self.velocity_ext, &self.pressure_ext, &self.gradient_ext);
        let (dv, rho0) = (sums.dv, self.eos.rho0);
        let diffusion = delta * kernel.h() * c;
        self.rate.par_iter_mut().enumerate().for_each(|(i, rate)| {
            let mut div = 0.0;
            let mut diff = 0.0;
            for k in list.range(i) {
                let j = list.index[k] as usize;
                let rij = list.rij[k];
                let w = sums.factor[k] * dv;
                div += w * (u[i] - u[j]).dot(&rij);
                if diffusion > 0.0 {
                    let psi = 2.0 * (p[i] - p[j]) * rij / rij.norm_squared() - (grad[i] + grad[j]);
                    diff += w * psi.dot(&rij);
                }
            }
            // m_j/ρ0 = δV: dρ/dt = ρ0 Σ δV u_ij·∇W_ij, so dp/dt = c² ρ0 (…).
            *rate = c * c * rho0 * div + diffusion * diff;
            if let Some(u_ps) = shift {
                *rate += u_ps[i].dot(&grad[i]);
            }
        });
        let max_p = pressure
            .par_iter_mut()
            .zip(self.rate.par_iter())
            .map(|(p, r)| {
                *p += dt * r;
                p.abs()
            })
            .reduce(|| 0.0, f64::max);
        self.deviation = max_p / (rho0 * c * c);
    }
}
