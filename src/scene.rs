//! Geometry builders: initial particle lattices, walls, periodic boxes and initial fields.

use crate::boundary::{Circle, Surface, Wall};
use crate::case::{Case, SceneKind};
use crate::math::Vec2;
use crate::neighbours::Domain;
use crate::step::{Scales, Setup};
use std::f64::consts::PI;

/// Particles on a regular lattice at cell centres ((i + ½)δr, (j + ½)δr).
fn lattice(columns: usize, rows: usize, dr: f64) -> Vec<Vec2> {
    (0..columns)
        .flat_map(|i| {
            (0..rows).map(move |j| Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
        })
        .collect()
}

/// The Taylor–Green velocity u = U(−cos kx sin ky, sin kx cos ky), k = 2π/L, at amplitude `u0`.
pub fn taylor_green_velocity(p: &Vec2, length: f64, u0: f64) -> Vec2 {
    let k = 2.0 * PI / length;
    Vec2::new(
        -(k * p.x).cos() * (k * p.y).sin(),
        (k * p.x).sin() * (k * p.y).cos(),
    ) * u0
}

/// The initial state of a case.
pub fn build(case: &Case) -> Setup {
    let c = &case.scene;
    let dr = c.spacing();
    let positions: Vec<Vec2> = lattice(c.columns(), c.resolution, dr)
        .into_iter()
        .filter(|p| c.is_fluid(p.x, p.y))
        .collect();
    let d = case.derived();
    let (periodic_y, mut walls, velocity) = match c.kind {
        SceneKind::Channel => (
            false,
            vec![
                Surface::Plane(Wall {
                    axis: 1,
                    position: 0.0,
                    fluid_side: 1.0,
                }),
                Surface::Plane(Wall {
                    axis: 1,
                    position: c.height,
                    fluid_side: -1.0,
                }),
            ],
            vec![Vec2::zeros(); positions.len()],
        ),
        SceneKind::TaylorGreen => (
            true,
            Vec::new(),
            positions
                .iter()
                .map(|p| taylor_green_velocity(p, c.length, c.velocity))
                .collect(),
        ),
    };
    if let Some((centre, radius)) = c.cylinder {
        walls.push(Surface::Circle(Circle {
            centre: Vec2::new(centre[0], centre[1]),
            radius,
        }));
    }
    Setup {
        domain: Domain {
            min: Vec2::zeros(),
            max: Vec2::new(c.length, c.height),
            periodic: [true, periodic_y],
        },
        walls,
        positions,
        velocity,
        spacing: dr,
        fluid: case.fluid,
        scheme: case.scheme,
        body_force: Vec2::new(c.body_force[0], c.body_force[1]),
        scales: Scales {
            length: c.length_scale(),
            velocity: d.velocity_scale.max(f64::MIN_POSITIVE),
        },
    }
}
