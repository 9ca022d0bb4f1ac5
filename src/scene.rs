//! Geometry builders: initial particle lattices, walls and periodic boxes for each scene.

use crate::boundary::Wall;
use crate::case::{Case, Channel};
use crate::math::Vec2;
use crate::neighbours::Domain;
use crate::step::{Scales, Setup};

/// Start-up channel flow: a regular lattice of particles at cell centres
/// ((i + ½)δr, (j + ½)δr) between no-slip walls at y = 0 and y = H, periodic in x.
pub fn channel(case: &Case) -> Setup {
    let c: &Channel = &case.channel;
    let dr = c.spacing();
    let positions = (0..c.columns())
        .flat_map(|i| {
            (0..c.resolution).map(move |j| Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
        })
        .collect();
    let f = &case.fluid;
    Setup {
        domain: Domain {
            min: Vec2::zeros(),
            max: Vec2::new(c.length, c.height),
            periodic: [true, false],
        },
        walls: vec![
            Wall {
                axis: 1,
                position: 0.0,
                fluid_side: 1.0,
            },
            Wall {
                axis: 1,
                position: c.height,
                fluid_side: -1.0,
            },
        ],
        positions,
        spacing: dr,
        fluid: *f,
        scheme: case.scheme,
        body_force: Vec2::new(c.body_force[0], c.body_force[1]),
        scales: Scales {
            length: c.height,
            velocity: case.derived().velocity_scale.max(f64::MIN_POSITIVE),
        },
    }
}
