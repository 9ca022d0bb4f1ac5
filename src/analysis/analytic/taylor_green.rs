//! The Taylor–Green vortex: u = U(−cos kx sin ky, sin kx cos ky) e^{−2νk²t}, k = 2π/L, an
//! exact solution of the Navier–Stokes equations in a doubly periodic box.

use crate::engine::math::Vec2;
use crate::engine::reduce::blocked_sum;
use std::f64::consts::PI;

/// The Taylor–Green velocity u = U(−cos kx sin ky, sin kx cos ky), k = 2π/L, at amplitude `u0`.
pub fn velocity(p: &Vec2, length: f64, u0: f64) -> Vec2 {
    let k = 2.0 * PI / length;
    Vec2::new(
        -(k * p.x).cos() * (k * p.y).sin(),
        (k * p.x).sin() * (k * p.y).cos(),
    ) * u0
}

/// The amplitude of the vortex in a velocity field: the projection 2 mean(u·û) on the
/// unit-amplitude mode û.
pub fn amplitude(positions: &[Vec2], velocity: &[Vec2], length: f64) -> f64 {
    let sum = blocked_sum(positions.len(), |i| {
        velocity[i].dot(&velocity_mode(&positions[i], length))
    });
    2.0 * sum / positions.len() as f64
}

fn velocity_mode(p: &Vec2, length: f64) -> Vec2 {
    velocity(p, length, 1.0)
}
