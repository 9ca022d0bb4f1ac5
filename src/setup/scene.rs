//! Geometry builders: initial particle lattices, walls, periodic boxes and initial fields.

use crate::engine::boundary::inflow::Inflow;
use crate::engine::boundary::{Circle, Surface, Wall};
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::step::{Scales, Setup};
use crate::setup::case::{Case, SceneKind};
use std::f64::consts::PI;

/// Particles on a regular lattice at cell centres ((i + ½)δr, (j + ½)δr).
fn lattice(columns: usize, rows: usize, dr: f64) -> Vec<Vec2> {
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

/// The Taylor–Green velocity u = U(−cos kx sin ky, sin kx cos ky), k = 2π/L, at amplitude `u0`.
pub fn taylor_green_velocity(p: &Vec2, length: f64, u0: f64) -> Vec2 {
    let k = 2.0 * PI / length;
    Vec2::new(
        -(k * p.x).cos() * (k * p.y).sin(),
        (k * p.x).sin() * (k * p.y).cos(),
    ) * u0
}

/// The no-slip wall y = 0 with the fluid above: a channel's bottom wall, a drop's or a jet's
/// plate.
fn floor() -> Surface {
    Surface::Plane(Wall {
        axis: 1,
        position: 0.0,
        fluid_side: 1.0,
    })
}

/// The initial state of a case.
pub fn build(case: &Case) -> Setup {
    let c = &case.scene;
    let dr = c.spacing();
    let d = case.derived();
    let scales = Scales {
        length: c.length_scale(),
        velocity: d.velocity_scale.max(f64::MIN_POSITIVE),
    };
    let body_force = Vec2::new(c.body_force[0], c.body_force[1]);
    if c.has_free_surface() {
        // A drop (a disc of rings falling at (0, −U)) or a jet's inflow buffer, above a
        // no-slip plate at y = 0, in an open box.
        let (positions, inflow) = match (c.drop, c.jet) {
            (Some((centre, w)), _) => (disc(Vec2::new(centre[0], centre[1]), 0.5 * w, dr), None),
            (None, Some((width, orifice))) => {
                let (inflow, positions) = Inflow::new(0.0, width, orifice, c.velocity, dr);
                (positions, Some(inflow))
            }
            (None, None) => unreachable!("validated: a free-surface scene has a drop or a jet"),
        };
        let velocity = vec![Vec2::new(0.0, -c.velocity); positions.len()];
        return Setup {
            domain: Domain {
                min: Vec2::new(-0.5 * c.length, 0.0),
                max: Vec2::new(0.5 * c.length, c.height),
                periodic: [false, false],
            },
            walls: vec![floor()],
            positions,
            velocity,
            spacing: dr,
            fluid: case.fluid,
            scheme: case.scheme,
            body_force,
            scales,
            free_surface: true,
            inflow,
        };
    }
    let positions: Vec<Vec2> = lattice(c.columns(), c.resolution, dr)
        .into_iter()
        .filter(|p| c.is_fluid(p.x, p.y))
        .collect();
    let (periodic_y, mut walls, velocity) = match c.kind {
        SceneKind::Channel => (
            false,
            vec![
                floor(),
                Surface::Plane(Wall {
                    axis: 1,
                    position: c.height,
                    fluid_side: -1.0,
                }),
            ],
            vec![Vec2::zeros(); positions.len()],
        ),
        SceneKind::TaylorGreen | SceneKind::Drop | SceneKind::Jet => (
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
        body_force,
        scales,
        free_surface: false,
        inflow: None,
    }
}
