//! A static contact angle θ where a free surface meets a wall (`scene.contact_angle`).
//!
//! At equilibrium the surface meets a flat wall at θ, measured through the liquid (Young
//! 1805); with the wall's unit normal n_w pointing into the fluid and its tangent t_w pointing
//! from the liquid to the gas along the wall, the surface's outward normal at the contact line
//! is `m = n_w cos θ + t_w sin θ` (Brackbill, Kothe & Zemach 1992). That is a boundary
//! condition on the surface's shape, and in this scheme the shape enters only through the
//! curvature κ of the capillary pressure σκ ([`super::tension`]). So the condition is imposed
//! where κ is fitted: the FS particle nearest the wall (the contact particle c, in the first
//! layer) continues its surface beyond the wall by the reflection of that surface across the
//! line through c along m. A curve and its reflection across the normal line at a point share
//! the tangent and the curvature there, so when the surface meets the wall at θ the
//! continuation is smooth and adds nothing; when it meets it at another angle the
//! continuation makes a corner at c whose curvature pulls the surface towards θ (a surface
//! steeper than θ = 30° allows is seen as concave, its pressure falls below the liquid's and
//! the liquid climbs the wall).
//!
//! The reflection line passes through the wall point w where the surface through the
//! particles' centres, leaving c along the prescribed tangent, meets the wall. Taken through
//! c itself (half a spacing from the wall), the meniscus at a wall came out shifted by that
//! half spacing: the rise at the wall 5.9 % above the exact value at ℓ_c/δr = 12.5
//! (`cases/meniscus.toml`), the profile correct beyond a few spacings. Which way the gas lies
//! along the wall is read from the contact particle's own normal (39); a surface lying along
//! the wall (|n·t_w| < [`MIN_TANGENTIAL`]) has no contact line there.

use crate::engine::boundary::Shape;
use crate::engine::free_surface::FreeSurface;
use crate::engine::math::Vec2;
use rayon::prelude::*;

/// The tangential part of an FS particle's normal below which the surface is taken to lie
/// along the wall rather than meet it (θ within ~12° of 0 or 180°).
pub const MIN_TANGENTIAL: f64 = 0.2;

/// A contact particle's line: its distance from the wall, the surface normal m the angle
/// prescribes, the tangent perpendicular to m that leads away from the wall along the real
/// surface, and the wall point w (relative to the particle) the reflection line passes
/// through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLine {
    pub distance: f64,
    pub normal: Vec2,
    pub along: Vec2,
    pub wall_point: Vec2,
}

impl ContactLine {
    /// The continuation of the surface point `q` (relative to the contact particle) beyond
    /// the wall: its reflection across the line through w along m, for points on the real
    /// side (None for the others).
    pub fn continuation(&self, q: Vec2) -> Option<Vec2> {
        let r = q - self.wall_point;
        (r.dot(&self.along) > 0.0)
            .then(|| self.wall_point + 2.0 * r.dot(&self.normal) * self.normal - r)
    }

    /// Whether the surface point `q` (relative to the contact particle) lies on the real
    /// side of the reflection line (or on it).
    pub fn on_real_side(&self, q: Vec2) -> bool {
        (q - self.wall_point).dot(&self.along) >= 0.0
    }
}

/// A wall and the contact angle at its flat faces (cos θ, sin θ).
#[derive(Clone, Copy, Debug)]
struct WettedWall {
    shape: Shape,
    cos: f64,
    sin: f64,
}

/// The contact angles of a scene at its flat walls, and the contact lines of the last step.
#[derive(Clone, Debug)]
pub struct Wetting {
    /// The walls the angles hold at (only their flat faces count, [`Shape::face`]).
    walls: Vec<WettedWall>,
    /// How near a wall an FS particle must be to be a contact particle: 1.5δr (the first
    /// layer's centres are δr/2 from the wall). Within δr, a drop beading towards 120°
    /// (R/δr = 20) lost its contact lines at t ≈ 2: its lowest FS particle stood 1.1δr above
    /// the plate, the particle under it (0.67δr up) being interior, and the drop stayed at
    /// 101° with a vertical foot and no condition on it.
    reach: f64,
    /// The contact line of each FS particle in reach of a wall, None elsewhere.
    pub lines: Vec<Option<ContactLine>>,
}

impl Wetting {
    /// The angle `theta` (radians, through the liquid) at the flat faces of `walls`, for
    /// particles of spacing `spacing`.
    #[cfg(test)]
    pub fn new(theta: f64, walls: Vec<Shape>, spacing: f64) -> Self {
        Self::per_wall(walls.into_iter().map(|w| (w, theta)).collect(), spacing)
    }

    /// Each wall's own angle (radians, through the liquid) at its flat faces, for particles
    /// of spacing `spacing`.
    pub fn per_wall(walls: Vec<(Shape, f64)>, spacing: f64) -> Self {
        let walls = walls
            .into_iter()
            .map(|(shape, theta)| WettedWall {
                shape,
                cos: theta.cos(),
                sin: theta.sin(),
            })
            .collect();
        Self {
            walls,
            reach: 1.5 * spacing,
            lines: Vec::new(),
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.lines) + crate::engine::vec_bytes(&self.walls)
    }

    /// The contact lines of the FS particles at `points` (the fluid positions).
    pub fn update(&mut self, points: &[Vec2], surface: &FreeSurface) {
        // Filled in place (the buffer is reused from step to step).
        let mut lines = std::mem::take(&mut self.lines);
        lines.resize(surface.on_surface.len(), None);
        let this = &*self;
        lines.par_iter_mut().enumerate().for_each(|(i, line)| {
            *line = surface.on_surface[i]
                .then(|| this.line(&points[i], surface.normal[i]))
                .flatten();
        });
        self.lines = lines;
    }

    /// The contact line of an FS particle at `p` with normal (39) `n`, at the nearest flat
    /// face in reach.
    fn line(&self, p: &Vec2, n: Vec2) -> Option<ContactLine> {
        let (distance, wall_normal, wall) = self
            .walls
            .iter()
            .filter_map(|w| w.shape.face(p).map(|(d, normal)| (d, normal, w)))
            .filter(|&(d, _, _)| d >= 0.0 && d < self.reach)
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        let tangent = Vec2::new(-wall_normal.y, wall_normal.x);
        let toward_gas = n.dot(&tangent);
        if toward_gas.abs() < MIN_TANGENTIAL {
            return None;
        }
        let t_w = tangent * toward_gas.signum();
        let m = wall_normal * wall.cos + t_w * wall.sin;
        let mut along = Vec2::new(-m.y, m.x);
        if along.dot(&wall_normal) < 0.0 {
            along = -along;
        }
        // Back along the surface to the wall (along·n_w = sin θ ≥ sin 15°).
        let to_wall = distance / along.dot(&wall_normal).max(MIN_TANGENTIAL);
        Some(ContactLine {
            distance,
            normal: m,
            along,
            wall_point: -to_wall * along,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::Plane;

    fn vertical_wall() -> Shape {
        // x = 0, fluid at x > 0.
        Shape::Plane(Plane {
            axis: 0,
            position: 0.0,
            fluid_side: 1.0,
        })
    }

    /// At a vertical wall with the liquid to its right and the gas above, θ = 30° asks for the
    /// surface normal m = (cos θ, sin θ): the real surface leaves the wall downwards, 60°
    /// below the horizontal (a meniscus drawn up the wall).
    #[test]
    fn contact_normal_and_continuation_at_a_vertical_wall() {
        let theta = 30f64.to_radians();
        let w = Wetting::new(theta, vec![vertical_wall()], 0.1);
        let line = w
            .line(&Vec2::new(0.05, 1.0), Vec2::new(0.3, 1.0).normalize())
            .unwrap();
        assert!((line.normal - Vec2::new(theta.cos(), theta.sin())).norm() < 1e-12);
        assert!((line.along - Vec2::new(theta.sin(), -theta.cos())).norm() < 1e-12);
        // The wall point: back from the particle along the surface to x = 0.
        assert!(
            (line.wall_point.x + 0.05).abs() < 1e-12,
            "{:?}",
            line.wall_point
        );
        // A point on the real surface at 60° below the horizontal is continued along the
        // same straight line behind the wall: a surface at θ is smooth through w.
        let q = line.along * 0.2;
        let image = line.continuation(q).unwrap();
        let w = line.wall_point;
        assert!((image - w + (q - w)).norm() < 1e-12, "{image:?}");
        // A horizontal surface is continued upwards behind the wall: a corner whose
        // curvature is negative (the liquid is drawn up).
        let image = line.continuation(Vec2::new(0.2, 0.0)).unwrap();
        assert!(image.y > w.y + 0.1, "{image:?}");
        assert!(line.continuation(w - line.along * 0.2).is_none());
    }

    /// θ = 120° at the same wall: m points into the wall's side, the real surface rises away
    /// from the wall (a depressed meniscus).
    #[test]
    fn a_non_wetting_angle_depresses_the_surface() {
        let theta = 120f64.to_radians();
        let w = Wetting::new(theta, vec![vertical_wall()], 0.1);
        let line = w.line(&Vec2::new(0.05, 1.0), Vec2::new(0.0, 1.0)).unwrap();
        assert!(line.normal.x < 0.0 && line.normal.y > 0.0);
        assert!(line.along.x > 0.0 && line.along.y > 0.0);
    }

    /// No contact line beyond 1.5 spacings, nor where the surface lies along the wall.
    #[test]
    fn contact_lines_only_where_the_surface_meets_the_wall() {
        let w = Wetting::new(1.0, vec![vertical_wall()], 0.1);
        assert!(w.line(&Vec2::new(0.2, 1.0), Vec2::new(0.0, 1.0)).is_none());
        assert!(w
            .line(&Vec2::new(0.05, 1.0), Vec2::new(-1.0, 0.05))
            .is_none());
    }

    /// Each wall keeps its own angle: 30° at x = 0, 90° (neutral) at x = 1, where the
    /// surface meets the wall square, m along the wall.
    #[test]
    fn each_wall_has_its_own_angle() {
        let right = Shape::Plane(Plane {
            axis: 0,
            position: 1.0,
            fluid_side: -1.0,
        });
        let (wetting, neutral) = (30f64.to_radians(), 90f64.to_radians());
        let w = Wetting::per_wall(vec![(vertical_wall(), wetting), (right, neutral)], 0.1);
        let up = Vec2::new(0.0, 1.0);
        let left = w.line(&Vec2::new(0.05, 1.0), Vec2::new(0.3, 1.0).normalize());
        assert!((left.unwrap().normal - Vec2::new(wetting.cos(), wetting.sin())).norm() < 1e-12);
        let line = w.line(&Vec2::new(0.95, 1.0), Vec2::new(0.3, 1.0).normalize());
        assert!((line.unwrap().normal - up).norm() < 1e-12);
    }
}
