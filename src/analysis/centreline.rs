//! Profiles along the centre-line between the cylinders of a periodic array (King & Lind
//! §IV B, Figs. 9–11): from one cylinder's downstream edge (s = 0) to the next one's upstream
//! edge (s = L − 2R, which is 4 for the 6R array), at the height of the cylinder centre.
//!
//! Values at a probe point are Shepard-normalised kernel interpolants of the fluid particles,
//! f(x) = Σ_j f_j W(x − x_j) / Σ_j W(x − x_j) (equal particle volumes), which are exact for
//! constants and second-order accurate in the interior of the fluid.

use crate::engine::math::{Sym2, Vec2};
use crate::engine::step::Simulation;

/// Probe points along the centre-line.
#[derive(Clone, Debug)]
pub struct Centreline {
    /// Distance from the downstream edge of the cylinder.
    pub s: Vec<f64>,
    points: Vec<Vec2>,
    centre_y: f64,
}

/// Raw (dimensional) values at the probes.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Profile {
    /// u_x.
    pub u: Vec<f64>,
    /// τ_p,xx.
    pub tau_xx: Vec<f64>,
    /// det A (interpolated from the particles' det A; 1 where there is no conformation).
    pub det_a: Vec<f64>,
}

impl Centreline {
    /// `samples` probes from x = c_x + R to x = c_x + L − R at y = c_y (x wrapped into the
    /// periodic box by the caller's domain).
    pub fn new(centre: [f64; 2], radius: f64, length: f64, samples: usize) -> Self {
        let gap = length - 2.0 * radius;
        let samples = samples.max(2);
        let s: Vec<f64> = (0..samples)
            .map(|k| gap * k as f64 / (samples - 1) as f64)
            .collect();
        let points = s
            .iter()
            .map(|&d| Vec2::new(centre[0] + radius + d, centre[1]))
            .collect();
        Self {
            s,
            points,
            centre_y: centre[1],
        }
    }

    /// The profile of the current state; `tau` is the polymer stress per particle.
    pub fn sample(&self, sim: &Simulation, tau: &[Sym2]) -> Profile {
        let state = &sim.state;
        let support = sim.kernel.support();
        // Only particles within one support of the line can contribute.
        let near: Vec<usize> = (0..state.position.len())
            .filter(|&i| (state.position[i].y - self.centre_y).abs() < support)
            .collect();
        let mut profile = Profile {
            u: Vec::with_capacity(self.points.len()),
            tau_xx: Vec::with_capacity(self.points.len()),
            det_a: Vec::with_capacity(self.points.len()),
        };
        for p in &self.points {
            let (mut w_sum, mut u, mut t, mut d) = (0.0, 0.0, 0.0, 0.0);
            for &i in &near {
                let r = sim.domain.min_image(state.position[i] - p).norm();
                if r >= support {
                    continue;
                }
                let w = sim.kernel.value(r);
                w_sum += w;
                u += w * state.velocity[i].x;
                t += w * tau.get(i).map_or(0.0, |s| s.xx);
                d += w * state.conformation.get(i).map_or(1.0, |a| a.det());
            }
            let norm = if w_sum > 0.0 { 1.0 / w_sum } else { f64::NAN };
            profile.u.push(u * norm);
            profile.tau_xx.push(t * norm);
            profile.det_a.push(d * norm);
        }
        profile
    }
}

impl Profile {
    /// Adds `other` element-wise (for time averages).
    pub fn accumulate(&mut self, other: &Profile) {
        if self.u.is_empty() {
            *self = other.clone();
            return;
        }
        for (a, b) in [
            (&mut self.u, &other.u),
            (&mut self.tau_xx, &other.tau_xx),
            (&mut self.det_a, &other.det_a),
        ] {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
    }

    /// Divides every value by `n`.
    pub fn scaled(&self, factor: f64) -> Profile {
        let f = |v: &Vec<f64>| v.iter().map(|x| x * factor).collect();
        Profile {
            u: f(&self.u),
            tau_xx: f(&self.tau_xx),
            det_a: f(&self.det_a),
        }
    }
}
