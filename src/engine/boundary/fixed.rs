//! Fixed ghost particles behind walls (Marrone et al. 2011; the image particles of Fang et
//! al. 2006): a lattice of spacing δr fixed to the wall — rows behind a plane, rings inside a
//! circle — each point taking the values of the fluid particle nearest its mirror point
//! inside the fluid (zeroth-order interpolation), by the wall's condition as a mirror would.
//! Unlike a mirror inside a convex surface, a ring point carries the fluid's own volume δV:
//! the rings are spaced δr apart, so no volume ratio is needed.
//!
//! Why: a moving mirror stands at 2d from its parent, so as a particle reaches the wall
//! (d → 0) the pair's kernel gradient, and with it the wall's pressure repulsion and the
//! compression of the continuity equation, vanish; a particle pushed by the fluid above
//! creeps through the wall. A fixed lattice keeps a row of points δr/2 behind the wall
//! whatever the fluid does.
//!
//! The lattices are written for the plane (a row of columns, rings); their types take the
//! dimension so that the walls do, but a 3D set-up refuses `scheme.walls.model = "fixed-ghost"`.

use super::{Circle, Plane, Shape};
use crate::engine::neighbours::Domain;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// A point in D dimensions.
type Point<const D: usize> = SVector<f64, D>;

/// How the particles behind a wall are placed.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum WallModel {
    /// Every fluid particle within a kernel support of a wall is mirrored across it
    /// (King & Lind §III C).
    #[default]
    Mirror,
    /// Ghosts on a lattice fixed to the wall (module docs).
    FixedGhost,
}

/// A near-wall fluid particle: tangential coordinate, distance from the wall, index.
pub type NearParticle = (f64, f64, u32);

/// One fixed ghost of a plane wall: its position and its parent.
#[derive(Clone, Copy, Debug)]
pub struct FixedGhost<const D: usize = 2> {
    pub position: Point<D>,
    pub parent: u32,
    /// The wall's unit normal at the point.
    pub normal: Point<D>,
}

/// The lattice of a plane: columns at (k + ½)δr along the wall from the box's corner, rows at
/// (m + ½)δr behind it, m while (m + ½)δr < `reach`.
pub struct Lattice<'a, const D: usize = 2> {
    pub plane: &'a Plane,
    pub spacing: f64,
    pub reach: f64,
    pub domain: Option<&'a Domain<D>>,
}

impl<const D: usize> Lattice<'_, D> {
    /// Appends to `out` every lattice point with a fluid particle within δr of its mirror
    /// point. `near` is scratch (reused between steps).
    pub fn ghosts(
        &self,
        points: &[Point<D>],
        near: &mut Vec<NearParticle>,
        out: &mut Vec<FixedGhost<D>>,
    ) {
        let (plane, dr) = (self.plane, self.spacing);
        let t = 1 - plane.axis;
        near.clear();
        for (i, p) in points.iter().enumerate() {
            let d = plane.distance(p);
            if d < self.reach + dr {
                near.push((p[t], d, i as u32));
            }
        }
        if near.is_empty() {
            return;
        }
        near.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        let origin = self.domain.map_or(0.0, |d| d.min[t]);
        let period = self.domain.and_then(|d| d.periodic[t].then(|| d.size()[t]));
        let (first, last) = match period {
            Some(l) => (0, (l / dr).round() as i64 - 1),
            None => (
                ((near[0].0 - self.reach - origin) / dr).floor() as i64,
                ((near[near.len() - 1].0 + self.reach - origin) / dr).ceil() as i64,
            ),
        };
        let rows = (self.reach / dr - 0.5).ceil().max(1.0) as usize;
        for k in first..=last {
            let s = origin + (k as f64 + 0.5) * dr;
            for m in 0..rows {
                let d = (m as f64 + 0.5) * dr;
                if let Some(parent) = nearest(near, s, d, dr, period) {
                    let mut position = Point::<D>::zeros();
                    position[t] = s;
                    position[plane.axis] = plane.position - plane.fluid_side * d;
                    out.push(FixedGhost {
                        position,
                        parent,
                        normal: Shape::<D>::Plane(*plane).normal(&position),
                    });
                }
            }
        }
    }
}

/// The rings of a circle: radii R − (m + ½)δr while (m + ½)δr < `reach` (and the radius stays
/// above δr/2), each with round(2πr/δr) points at equal angles from the x axis.
pub struct Rings<'a, const D: usize = 2> {
    pub circle: &'a Circle<D>,
    pub spacing: f64,
    pub reach: f64,
    pub domain: Option<&'a Domain<D>>,
}

impl<const D: usize> Rings<'_, D> {
    /// Appends to `out` every ring point with a fluid particle within δr of its mirror point
    /// (positions wrapped into the box). `near` is scratch: (x, y) relative to the centre.
    pub fn ghosts(
        &self,
        points: &[Point<D>],
        near: &mut Vec<NearParticle>,
        out: &mut Vec<FixedGhost<D>>,
    ) {
        let (c, dr) = (self.circle, self.spacing);
        near.clear();
        for (i, p) in points.iter().enumerate() {
            let r = self
                .domain
                .map_or(p - c.centre, |d| d.min_image(p - c.centre));
            if r.norm() - c.radius < self.reach + dr {
                near.push((r[0], r[1], i as u32));
            }
        }
        if near.is_empty() {
            return;
        }
        let mut m = 0;
        while (m as f64 + 0.5) * dr < self.reach && c.radius - (m as f64 + 0.5) * dr > 0.5 * dr {
            let radius = c.radius - (m as f64 + 0.5) * dr;
            let image = c.radius + (m as f64 + 0.5) * dr;
            let count = (std::f64::consts::TAU * radius / dr).round().max(1.0) as usize;
            for k in 0..count {
                let angle = std::f64::consts::TAU * k as f64 / count as f64;
                let mut dir = Point::<D>::zeros();
                (dir[0], dir[1]) = (angle.cos(), angle.sin());
                let target = dir * image;
                let best = near
                    .iter()
                    .map(|q| ((q.0 - target[0]).powi(2) + (q.1 - target[1]).powi(2), q.2))
                    .filter(|(r2, _)| *r2 <= dr * dr)
                    .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                if let Some((_, parent)) = best {
                    let q = c.centre + dir * radius;
                    let position = self.domain.map_or(q, |d| d.wrap(q));
                    out.push(FixedGhost {
                        position,
                        parent,
                        normal: dir,
                    });
                }
            }
            m += 1;
        }
    }
}

/// The particle of `near` (sorted by s) nearest (s, d) within `radius`, seen across a
/// periodic tangential axis of length `period`.
fn nearest(near: &[NearParticle], s: f64, d: f64, radius: f64, period: Option<f64>) -> Option<u32> {
    let mut best: Option<(f64, u32)> = None;
    let (shifts, count) = match period {
        Some(l) => ([0.0, -l, l], 3),
        None => ([0.0; 3], 1),
    };
    for shift in &shifts[..count] {
        let centre = s + shift;
        let start = near.partition_point(|q| q.0 < centre - radius);
        for q in near[start..].iter().take_while(|q| q.0 <= centre + radius) {
            let r2 = (q.0 - centre).powi(2) + (q.1 - d).powi(2);
            if r2 <= radius * radius && best.is_none_or(|(b, _)| r2 < b) {
                best = Some((r2, q.2));
            }
        }
    }
    best.map(|(_, i)| i)
}

/// Appends the fixed ghosts of one wall of `shape` (module docs) to `out`.
pub fn ghosts_of<const D: usize>(
    shape: &Shape<D>,
    spacing: f64,
    reach: f64,
    domain: Option<&Domain<D>>,
    points: &[Point<D>],
    near: &mut Vec<NearParticle>,
    out: &mut Vec<FixedGhost<D>>,
) {
    match shape {
        Shape::Plane(plane) => Lattice {
            plane,
            spacing,
            reach,
            domain,
        }
        .ghosts(points, near, out),
        Shape::Circle(circle) => Rings {
            circle,
            spacing,
            reach,
            domain,
        }
        .ghosts(points, near, out),
        // No lattice behind a corner or a tube yet: scenes with them take mirrors
        // (`setup::scenes::cavity`).
        Shape::Corner(_) | Shape::Plate(_) | Shape::Tube(_) => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Vec2;

    #[test]
    fn lattice_points_take_the_particle_nearest_their_mirror_point() {
        let plane = Plane::floor();
        let dr = 0.1;
        // Two columns of fluid at x = 0.05, 0.15, rows y = 0.05, 0.15, plus one particle
        // drifted to the wall at x = 0.25.
        let mut pts = Vec::new();
        for x in [0.05, 0.15] {
            for y in [0.05, 0.15] {
                pts.push(Vec2::new(x, y));
            }
        }
        pts.push(Vec2::new(0.25, 0.001));
        let domain = Domain {
            min: Vec2::new(0.0, -1.0),
            max: Vec2::new(0.3, 1.0),
            periodic: [false, false],
        };
        let lattice = Lattice {
            plane: &plane,
            spacing: dr,
            reach: 0.2,
            domain: Some(&domain),
        };
        let mut got = Vec::new();
        lattice.ghosts(&pts, &mut Vec::new(), &mut got);
        // Column x = 0.05, row y = −0.05 takes particle 0 (at its mirror point (0.05, 0.05)).
        let g = got
            .iter()
            .find(|g| (g.position - Vec2::new(0.05, -0.05)).norm() < 1e-12)
            .unwrap();
        assert_eq!(g.parent, 0);
        // The particle at the wall still has a fixed ghost δr/2 below the wall beneath it:
        // its own, whose mirror point (0.25, 0.05) is within δr of it.
        let g = got
            .iter()
            .find(|g| (g.position - Vec2::new(0.25, -0.05)).norm() < 1e-12)
            .unwrap();
        assert_eq!(g.parent, 4);
        // Every ghost stands behind the wall, on the lattice.
        assert!(got.iter().all(|g| g.position.y < 0.0));
        // Nothing beneath empty space (x = 0.35 has no fluid within δr of its mirror point).
        assert!(got.iter().all(|g| g.position.x < 0.3));
    }

    #[test]
    fn ring_points_sit_inside_the_circle_and_take_the_particle_at_their_mirror_point() {
        let circle = Circle {
            centre: Vec2::new(0.0, 0.0),
            radius: 1.0,
        };
        let dr = 0.1;
        // One particle just outside the surface on the x axis, at the mirror point of the
        // first ring's point at angle 0 (radius 0.95 ↔ 1.05).
        let pts = vec![Vec2::new(1.05, 0.0)];
        let rings = Rings {
            circle: &circle,
            spacing: dr,
            reach: 0.35,
            domain: None,
        };
        let mut got = Vec::new();
        rings.ghosts(&pts, &mut Vec::new(), &mut got);
        let g = got
            .iter()
            .find(|g| (g.position - Vec2::new(0.95, 0.0)).norm() < 1e-12)
            .expect("the first ring's point at angle 0");
        assert_eq!(g.parent, 0);
        // Every point is inside, on a ring δr/2, 3δr/2, ... below the surface, and near the
        // particle's mirror point.
        for g in &got {
            let depth = circle.radius - g.position.norm();
            assert!(
                depth > 0.0 && ((depth / dr) - 0.5).fract().abs() < 1e-9,
                "{depth}"
            );
        }
    }

    #[test]
    fn nearest_looks_across_a_periodic_seam() {
        let near = vec![(0.01, 0.05, 7u32), (0.5, 0.05, 8)];
        assert_eq!(nearest(&near, 0.99, 0.05, 0.1, Some(1.0)), Some(7));
        assert_eq!(nearest(&near, 0.99, 0.05, 0.1, None), None);
    }
}
