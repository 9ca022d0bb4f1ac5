//! Initial particle arrangements: the square lattice of closed boxes and the concentric-ring
//! disc of drops.

use crate::engine::math::Vec2;
use std::f64::consts::PI;

/// Particles on a regular lattice at cell centres ((i + ½)δr, (j + ½)δr).
pub fn lattice(columns: usize, rows: usize, dr: f64) -> Vec<Vec2> {
    (0..columns)
        .flat_map(|i| {
            (0..rows).map(move |j| Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
        })
        .collect()
}

/// A disc of particles on concentric rings: ring k at radius (k + ½)δr holds
/// round(2π(k + ½)) particles, so each ring owns its annulus [kδr, (k + 1)δr] at almost
/// exactly δr² per particle, and the outer ring lies δr/2 inside the disc's edge (as a
/// lattice's outer row does). Rings give a drop a smooth, isotropic free surface, which a
/// square lattice cut to a circle (a staircase) does not.
pub fn disc(centre: Vec2, radius: f64, dr: f64) -> Vec<Vec2> {
    let rings = (radius / dr).round() as usize;
    let mut points = Vec::new();
    for k in 0..rings {
        let r = (k as f64 + 0.5) * dr;
        let count = (2.0 * PI * (k as f64 + 0.5)).round() as usize;
        // Alternate rings are turned by half a spacing, so that no spokes form.
        let offset = if k % 2 == 0 { 0.0 } else { 0.5 };
        points.extend((0..count).map(|m| {
            let angle = 2.0 * PI * (m as f64 + offset) / count as f64;
            centre + r * Vec2::new(angle.cos(), angle.sin())
        }));
    }
    points
}
