//! Numbers derived from a case, computed in one place, printed at start-up and stored in
//! every summary.

use crate::engine::free_surface::tension::capillary_limit;
use crate::engine::kernel::H_OVER_DR;
use crate::engine::scheme::Method;
use crate::engine::viscosity::{
    advective_limit, elastic_limit, viscous_limit, DtInputs, Viscosity,
};
use crate::engine::weakly_compressible::ACOUSTIC_COURANT;
use crate::setup::scenes::bytes_per_particle;
use crate::setup::validate::Case;
use serde::Serialize;

/// Numbers derived from a case.
#[derive(Clone, Debug, Serialize)]
pub struct Derived {
    pub particle_spacing: f64,
    pub smoothing_length: f64,
    pub particles: usize,
    /// Velocity scale U: channel, the Oldroyd-B steady centre-line velocity ρgH²/(8η0);
    /// channel with a cylinder, the nominal mean velocity `scene.velocity`; Taylor–Green,
    /// the initial amplitude. Re = ρUL/η0, Wi = λU/L with L the height (R with a cylinder).
    pub velocity_scale: f64,
    pub reynolds: f64,
    pub weissenberg: f64,
    pub elasticity: f64,
    pub beta: f64,
    /// δt limits with the factor 0.2: viscous 0.2ρh²/η0 (explicit viscosity only, (28)),
    /// advective 0.2h/U, elastic C·h/c of the fluid at rest (c = √(η_p/(ρλ)) the shear-wave
    /// speed; it falls as the polymer stretches, see `engine::viscosity::elastic_limit`).
    pub dt_viscous: f64,
    pub dt_advective_at_u: f64,
    pub dt_elastic: f64,
    /// The capillary limit 0.25√(ρh³/(2πσ)) (infinite without surface tension).
    pub dt_capillary: f64,
    /// Weakly compressible scheme: the speed of sound c and the acoustic limit
    /// C_a h/(c + U) (0 and infinite for the projection).
    pub sound_speed: f64,
    pub dt_acoustic: f64,
    /// end_time over the δt limit of the scheme at U.
    pub estimated_steps: f64,
    /// Particles × the measured heap per particle (`rheosph bench`).
    pub estimated_memory_bytes: f64,
    /// `scheme.viscosity` as it runs, `auto` resolved.
    pub viscosity: Viscosity,
}

impl Case {
    /// Derived numbers (see [`Derived`]).
    pub fn derived(&self) -> Derived {
        let c = &self.scene;
        let dr = c.spacing();
        let h = H_OVER_DR * dr;
        let f = &self.fluid;
        let u = c.velocity_scale(f);
        let length = c.length_scale();
        let re = f.density * u * length / f.viscosity;
        let wi = f.relaxation_time * u / length;
        let factor = self.scheme.dt_factor;
        let nu = self.scheme.viscosity_nu(f);
        let inputs = DtInputs {
            h,
            max_speed: u,
            velocity_scale: u,
            max_polymer_stress: 0.0,
        };
        let (sound_speed, dt_acoustic) = match self.scheme.method {
            Method::WeaklyCompressible(w) => {
                (w.sound_speed, ACOUSTIC_COURANT * h / (w.sound_speed + u))
            }
            Method::Projection => (0.0, f64::INFINITY),
        };
        let limit = match self.scheme.time_step {
            Some(dt) => dt / factor,
            None => self
                .scheme
                .viscosity
                .dt_limit(f, nu, &inputs)
                .min(dt_acoustic / factor),
        };
        Derived {
            particle_spacing: dr,
            smoothing_length: h,
            particles: c.particles(),
            velocity_scale: u,
            reynolds: re,
            weissenberg: wi,
            elasticity: if re > 0.0 { wi / re } else { 0.0 },
            beta: f.beta,
            dt_viscous: factor * viscous_limit(f, h),
            dt_advective_at_u: factor * advective_limit(h, u),
            dt_elastic: factor * elastic_limit(f, h, 0.0, nu),
            dt_capillary: factor * capillary_limit(f.density, f.surface_tension, h),
            sound_speed,
            dt_acoustic,
            estimated_steps: self.end_time / (factor * limit),
            estimated_memory_bytes: c.particles() as f64 * bytes_per_particle(c.dimension()),
            viscosity: self.scheme.viscosity,
        }
    }
}
