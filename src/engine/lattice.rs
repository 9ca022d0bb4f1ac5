//! Initial particle arrangements: the square (or cubic) lattice of closed boxes and the
//! concentric-ring disc of drops.

use crate::engine::math::Vec2;
use nalgebra::SVector;
use std::f64::consts::PI;

/// Particles on a regular lattice at cell centres ((i + ½)δr, (j + ½)δr).
pub fn lattice(columns: usize, rows: usize, dr: f64) -> Vec<Vec2> {
    lattice_in([columns, rows], dr)
}

/// Particles at the centres of `counts[0] × … × counts[D − 1]` cells of side δr, the
/// first axis slowest: ((i + ½)δr, (j + ½)δr[, (k + ½)δr]).
pub fn lattice_in<const D: usize>(counts: [usize; D], dr: f64) -> Vec<SVector<f64, D>> {
    let total: usize = counts.iter().product();
    (0..total)
        .map(|mut m| {
            let mut index = [0usize; D];
            for a in (0..D).rev() {
                index[a] = m % counts[a];
                m /= counts[a];
            }
            SVector::<f64, D>::from_fn(|a, _| (index[a] as f64 + 0.5) * dr)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::frame::{Frame, StepVelocities};
    use crate::engine::math::Vec3;
    use crate::engine::neighbours::Domain;

    /// The 2D lattice is the general one's, point for point (the order the set-up and the
    /// fingerprints rely on: the first axis slowest).
    #[test]
    fn the_plane_lattice_is_the_general_one() {
        let general = lattice_in([3, 4], 0.25);
        let plane: Vec<Vec2> = (0..3)
            .flat_map(|i| {
                (0..4).map(move |j| Vec2::new((i as f64 + 0.5) * 0.25, (j as f64 + 0.5) * 0.25))
            })
            .collect();
        assert_eq!(general, plane);
        assert_eq!(lattice(3, 4, 0.25), plane);
    }

    /// A 3D lattice filling a box periodic in x and z, carried by a uniform velocity through
    /// Step 7 (27) for a whole period along each axis, comes back to itself (to round-off),
    /// every point having stayed in the box.
    #[test]
    fn a_3d_lattice_carried_through_its_periodic_box_returns() {
        let (n, dr) = ([6, 4, 5], 0.2);
        let start = lattice_in(n, dr);
        assert_eq!(start.len(), 120);
        let domain = Domain::<3> {
            min: Vec3::zeros(),
            max: Vec3::new(6.0 * dr, 4.0 * dr, 5.0 * dr),
            periodic: [true, false, true],
        };
        let u = vec![Vec3::new(1.2, 0.0, -1.0); start.len()];
        let zero = vec![Vec3::zeros(); start.len()];
        let mut points = start.clone();
        let steps = 60;
        let dt = 1.0 / steps as f64; // 1.2 = the x period, −1.0 = the z period
        for _ in 0..steps {
            let velocities = StepVelocities {
                old: &u,
                new: &u,
                shift: &zero,
            };
            Frame::Lagrangian.advance_positions(&domain, &mut points, velocities, dt);
            assert!(points
                .iter()
                .all(|p| (0..3).all(|a| p[a] >= domain.min[a] && p[a] < domain.max[a] + 1e-12)));
        }
        for (p, q) in points.iter().zip(&start) {
            let d = domain.min_image(p - q);
            assert!(d.norm() < 1e-12, "{p:?} from {q:?}");
        }
    }
}
