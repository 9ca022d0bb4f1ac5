//! The shapes of solid surfaces: planes, circles, the corners of planes and dipped plates, with the geometry the mirror
//! construction needs (signed distance, reflection, the mirrored volume ratio, the normal).
//!
//! Written once for D = 2 or 3 (the default 2): a plane is normal to an axis, a [`Circle`] is a
//! circle in the plane and a sphere in space ([`Sphere`]), a corner is where two planes meet
//! (in space, an edge). A plate is a plane shape: in space it is extruded along z.

use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use nalgebra::SVector;

/// A point in D dimensions.
type Point<const D: usize> = SVector<f64, D>;

/// The x–y components of `p` (`p` itself in the plane).
fn in_plane<const D: usize>(p: &Point<D>) -> Vec2 {
    Vec2::new(p[0], p[1])
}

/// `p` with its x–y components replaced by `q`'s.
fn with_plane<const D: usize>(mut p: Point<D>, q: Vec2) -> Point<D> {
    p[0] = q.x;
    p[1] = q.y;
    p
}

/// A straight wall normal to `axis` at `position`, the fluid on the side `fluid_side` (+1: the
/// fluid occupies coordinates above `position`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub axis: usize,
    pub position: f64,
    pub fluid_side: f64,
}

impl Plane {
    /// The wall y = 0 with the fluid above: a channel's bottom wall, a drop's or a jet's
    /// plate.
    pub fn floor() -> Self {
        Plane {
            axis: 1,
            position: 0.0,
            fluid_side: 1.0,
        }
    }

    /// Signed distance of `p` from the wall, positive in the fluid.
    pub fn distance<const D: usize>(&self, p: &Point<D>) -> f64 {
        (p[self.axis] - self.position) * self.fluid_side
    }

    /// Mirror image of `p` across the wall.
    pub fn reflect<const D: usize>(&self, p: &Point<D>) -> Point<D> {
        let mut q = *p;
        q[self.axis] = 2.0 * self.position - p[self.axis];
        q
    }

    /// The unit normal pointing into the fluid.
    pub fn inward_normal<const D: usize>(&self) -> Point<D> {
        let mut n = Point::<D>::zeros();
        n[self.axis] = self.fluid_side;
        n
    }
}

/// A solid circular cylinder (in the plane) or sphere (in space) of `radius` about `centre`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle<const D: usize = 2> {
    pub centre: Point<D>,
    pub radius: f64,
}

/// A solid sphere.
pub type Sphere = Circle<3>;

/// The inside of a circular pipe of `radius` whose axis runs along `axis` through `centre`
/// (in space; the pipe-flow benchmarks and the sphere in a tube), or of a circle (in the
/// plane, `axis` = None: a fluid in a round container). The fluid is inside; the wall's
/// mirrors lie outside, reflected along the radius in the cross-section, their axial
/// coordinate kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tube<const D: usize = 2> {
    pub centre: Point<D>,
    pub radius: f64,
    /// The axis the pipe runs along (None: the inside of a circle or a sphere).
    pub axis: Option<usize>,
}

impl<const D: usize> Tube<D> {
    /// `p − centre` in the cross-section (its axial component zero).
    fn radial(&self, p: &Point<D>) -> Point<D> {
        let mut r = p - self.centre;
        if let Some(a) = self.axis {
            r[a] = 0.0;
        }
        r
    }

    /// Distance of `p` from the wall, positive in the fluid (inside).
    pub fn distance(&self, p: &Point<D>) -> f64 {
        self.radius - self.radial(p).norm()
    }

    /// Mirror image of `p` across the wall along the radius: a particle at distance d inside
    /// lands at distance d outside, r_ij normal to the wall and bisected by it.
    pub fn reflect(&self, p: &Point<D>) -> Point<D> {
        let r = self.radial(p);
        let rho = r.norm();
        p + r * ((2.0 * self.radius - rho) / rho - 1.0)
    }

    /// Volume of the mirrored element over the original's, ((R + d)/(R − d))^k with k the
    /// curved directions of the cross-section (1 for a pipe in space or a circle in the
    /// plane, 2 for a spherical cavity): mirrors outside a concave wall are spread wider, so
    /// each carries more volume.
    pub fn volume_ratio(&self, p: &Point<D>) -> f64 {
        let d = self.distance(p);
        let ratio = (self.radius + d) / (self.radius - d);
        let curved = D - 1 - usize::from(self.axis.is_some());
        (0..curved).fold(1.0, |v, _| v * ratio)
    }

    /// The unit normal at the wall point nearest `p`, along the radius (outward).
    pub fn normal(&self, p: &Point<D>) -> Point<D> {
        self.radial(p).normalize()
    }
}

impl<const D: usize> Circle<D> {
    /// Distance of `p` from the surface, positive in the fluid.
    pub fn distance(&self, p: &Point<D>) -> f64 {
        (p - self.centre).norm() - self.radius
    }

    /// Mirror image of `p` across the surface along the radius: a particle at distance d
    /// outside lands at distance d inside, so r_ij is normal to, and bisected by, the surface.
    pub fn reflect(&self, p: &Point<D>) -> Point<D> {
        let r = p - self.centre;
        let rho = r.norm();
        self.centre + r * ((2.0 * self.radius - rho) / rho)
    }

    /// Volume of the mirrored shell element over the original's, ((R − d)/(R + d))^(D−1):
    /// mirrors are packed closer inside a convex surface, so each carries less volume (the
    /// ring's length ratio in the plane, the shell's area ratio in space).
    pub fn volume_ratio(&self, p: &Point<D>) -> f64 {
        let d = self.distance(p);
        let ratio = (self.radius - d) / (self.radius + d);
        (1..D).fold(1.0, |v, _| v * ratio)
    }

    /// Outward unit normal at the surface point nearest `p`.
    pub fn normal(&self, p: &Point<D>) -> Point<D> {
        (p - self.centre).normalize()
    }
}

/// The corner where two perpendicular plane walls meet, the fluid in the quadrant on their
/// fluid sides. A particle near both walls has a mirror across each; the quadrant behind
/// the corner, which neither reaches, is filled by its point reflection 2c − p (the
/// mirror of a mirror), so that a corner particle's support is as full as a wall
/// particle's. Its values compose the two walls' conditions ([`super::condition::Corner`]).
/// In space the two planes meet along an edge: the corner's axes are the two planes' normals,
/// and along the third nothing changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner<const D: usize = 2> {
    /// A point of the corner (its components along the two planes' normals count).
    pub point: Point<D>,
    /// The fluid side along each axis (±1 along the two planes' normals, 0 along the edge).
    pub sides: [f64; D],
}

impl<const D: usize> Corner<D> {
    /// `p − c` along the corner's two axes (zero along the edge).
    fn offset(&self, p: &Point<D>) -> Point<D> {
        Point::<D>::from_fn(|a, _| {
            if self.sides[a] == 0.0 {
                0.0
            } else {
                p[a] - self.point[a]
            }
        })
    }

    /// The distance from the corner inside the fluid quadrant; outside it, the (negative)
    /// distance from the nearer wall.
    pub fn distance(&self, p: &Point<D>) -> f64 {
        let d = self.offset(p);
        let sides = (0..D).filter(|&a| self.sides[a] != 0.0);
        let nearer = sides.fold(f64::INFINITY, |m, a| m.min(d[a] * self.sides[a]));
        if nearer >= 0.0 {
            d.norm()
        } else {
            nearer
        }
    }

    /// The point reflection 2c − p across the corner (across its edge in space).
    pub fn reflect(&self, p: &Point<D>) -> Point<D> {
        Point::<D>::from_fn(|a, _| {
            if self.sides[a] == 0.0 {
                p[a]
            } else {
                2.0 * self.point[a] - p[a]
            }
        })
    }
}

/// A vertical plate x ∈ [left, right] standing on a rounded lower end (a half disc of the
/// plate's half thickness, its lowest point at `bottom`) and reaching past the top of the
/// box, with fluid on both sides and below: a plate dipped into a pool (capillary rise
/// between two of them). The sides mirror as planes, the end as a circle (radially, with the
/// circle's volume ratio). A square end was tried first: its convex corners, which no mirror
/// construction fills consistently, let a particle of the flow rising into the gap through
/// the corner at t = 0.68 (`cases/capillary-rise.toml`). The plate must be thicker than two
/// kernel supports, so that the mirrors of one side never reach the fluid of the other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plate {
    pub left: f64,
    pub right: f64,
    pub bottom: f64,
}

impl Plate {
    /// The rounded end as a circle (in the x–y plane).
    pub fn end(&self) -> Circle {
        let radius = 0.5 * (self.right - self.left);
        Circle {
            centre: Vec2::new(0.5 * (self.left + self.right), self.bottom + radius),
            radius,
        }
    }

    /// Whether `p` lies level with the flat sides (above the end's centre).
    fn beside(&self, p: &Vec2) -> bool {
        p.y >= self.end().centre.y
    }

    /// Distance from the plate, positive in the fluid.
    pub fn distance<const D: usize>(&self, p: &Point<D>) -> f64 {
        let p = in_plane(p);
        if self.beside(&p) {
            (self.left - p.x).max(p.x - self.right)
        } else {
            self.end().distance(&p)
        }
    }

    /// The image across the nearest side, or across the end along its radius.
    pub fn reflect<const D: usize>(&self, p: &Point<D>) -> Point<D> {
        let q = in_plane(p);
        if !self.beside(&q) {
            return with_plane(*p, self.end().reflect(&q));
        }
        let side = if q.x < 0.5 * (self.left + self.right) {
            self.left
        } else {
            self.right
        };
        with_plane(*p, Vec2::new(2.0 * side - q.x, q.y))
    }

    /// A mirror's volume relative to its parent's: 1 beside the sides, the circle's ratio
    /// below.
    pub fn volume_ratio<const D: usize>(&self, p: &Point<D>) -> f64 {
        let p = in_plane(p);
        if self.beside(&p) {
            1.0
        } else {
            self.end().volume_ratio(&p)
        }
    }

    /// The flat side nearest `p` and `p`'s distance from it, with the side's unit normal
    /// pointing into the fluid (None below the end's centre: no contact line there).
    pub fn face<const D: usize>(&self, p: &Point<D>) -> Option<(f64, Point<D>)> {
        let q = in_plane(p);
        if !self.beside(&q) {
            return None;
        }
        let d = self.distance(p);
        let x = if q.x < 0.5 * (self.left + self.right) {
            -1.0
        } else {
            1.0
        };
        Some((d, with_plane(Point::<D>::zeros(), Vec2::new(x, 0.0))))
    }

    /// Unit normal of the nearest side or of the end.
    pub fn normal<const D: usize>(&self, p: &Point<D>) -> Point<D> {
        let q = in_plane(p);
        let n = if self.beside(&q) {
            Vec2::new(1.0, 0.0)
        } else {
            self.end().normal(&q)
        };
        with_plane(Point::<D>::zeros(), n)
    }
}

/// The shape of a solid surface that creates mirror particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape<const D: usize = 2> {
    Plane(Plane),
    Circle(Circle<D>),
    Corner(Corner<D>),
    Plate(Plate),
    Tube(Tube<D>),
}

impl<const D: usize> Shape<D> {
    /// The periodic image of `p` nearest a circle's centre (`p` itself for a plane, or
    /// without a domain).
    pub fn nearest_image(&self, p: &Point<D>, domain: Option<&Domain<D>>) -> Point<D> {
        match (self, domain) {
            (Shape::Circle(c), Some(d)) => c.centre + d.min_image(p - c.centre),
            (Shape::Tube(c), Some(d)) => c.centre + d.min_image(p - c.centre),
            _ => *p,
        }
    }

    pub fn distance(&self, p: &Point<D>) -> f64 {
        match self {
            Shape::Plane(w) => w.distance(p),
            Shape::Circle(c) => c.distance(p),
            Shape::Corner(c) => c.distance(p),
            Shape::Plate(c) => c.distance(p),
            Shape::Tube(c) => c.distance(p),
        }
    }

    pub fn reflect(&self, p: &Point<D>) -> Point<D> {
        match self {
            Shape::Plane(w) => w.reflect(p),
            Shape::Circle(c) => c.reflect(p),
            Shape::Corner(c) => c.reflect(p),
            Shape::Plate(c) => c.reflect(p),
            Shape::Tube(c) => c.reflect(p),
        }
    }

    /// The flat face nearest `p`, where a free surface may meet the wall at a contact angle:
    /// `p`'s distance from it and its unit normal into the fluid (None for a circle or a
    /// corner, whose planes are walls of their own).
    pub fn face(&self, p: &Point<D>) -> Option<(f64, Point<D>)> {
        match self {
            Shape::Plane(w) => Some((w.distance(p), w.inward_normal())),
            Shape::Plate(c) => c.face(p),
            Shape::Circle(_) | Shape::Corner(_) | Shape::Tube(_) => None,
        }
    }

    /// Volume of a mirror relative to its parent's (1 for a plane).
    pub fn volume_ratio(&self, p: &Point<D>) -> f64 {
        match self {
            Shape::Plane(_) | Shape::Corner(_) => 1.0,
            Shape::Circle(c) => c.volume_ratio(p),
            Shape::Plate(c) => c.volume_ratio(p),
            Shape::Tube(c) => c.volume_ratio(p),
        }
    }

    /// How far this shape lies from `other`: the largest distance a surface point moved
    /// (∞ when they are not the same kind of surface or face different ways).
    pub fn displacement_from(&self, other: &Shape<D>) -> f64 {
        match (self, other) {
            (Shape::Plane(a), Shape::Plane(b))
                if a.axis == b.axis && a.fluid_side == b.fluid_side =>
            {
                (a.position - b.position).abs()
            }
            (Shape::Circle(a), Shape::Circle(b)) => {
                (a.centre - b.centre).norm() + (a.radius - b.radius).abs()
            }
            (Shape::Tube(a), Shape::Tube(b)) if a.axis == b.axis => {
                (a.centre - b.centre).norm() + (a.radius - b.radius).abs()
            }
            (Shape::Corner(a), Shape::Corner(b)) if a.sides == b.sides => {
                (a.point - b.point).norm()
            }
            (Shape::Plate(a), Shape::Plate(b)) => (a.left - b.left)
                .abs()
                .max((a.right - b.right).abs())
                .max((a.bottom - b.bottom).abs()),
            _ => f64::INFINITY,
        }
    }

    /// The deepest a mirror can lie behind the surface and still be inside the solid: 2R
    /// for a circle (a particle farther than 2R from its surface would be mirrored through
    /// the centre into the fluid beyond), a plate's thickness, unbounded for a plane, a
    /// corner or a tube (the solid is all outside).
    pub fn mirror_depth(&self) -> f64 {
        match self {
            Shape::Plane(_) | Shape::Corner(_) | Shape::Tube(_) => f64::INFINITY,
            Shape::Circle(c) => 2.0 * c.radius,
            // The thickness, which is also the end's diameter.
            Shape::Plate(c) => c.right - c.left,
        }
    }

    /// Unit normal of the surface near `p` (sign irrelevant for reflections).
    pub fn normal(&self, p: &Point<D>) -> Point<D> {
        match self {
            Shape::Plane(w) => {
                let mut n = Point::<D>::zeros();
                n[w.axis] = 1.0;
                n
            }
            Shape::Circle(c) => c.normal(p),
            // The diagonal from the corner (the composed condition does not use it).
            Shape::Corner(c) => c.offset(p).normalize(),
            Shape::Plate(c) => c.normal(p),
            Shape::Tube(c) => c.normal(p),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Vec3;

    /// A point d inside a tube of radius R mirrors to d outside on its radius, its axial
    /// coordinate kept; the mirror's volume ratio is ((R + d)/(R − d))^k, k the curved
    /// directions: 1 for a pipe in space and a circle in the plane, 2 for a spherical cavity.
    #[test]
    fn a_tube_mirrors_outward_along_the_radius() {
        let (radius, d) = (2.0, 0.25);
        let pipe = Tube::<3> {
            centre: Vec3::new(0.0, 1.0, 1.0),
            radius,
            axis: Some(0),
        };
        let p = Vec3::new(7.0, 1.0, 1.0 + radius - d);
        assert!((pipe.distance(&p) - d).abs() < 1e-15);
        let q = pipe.reflect(&p);
        assert!((q - Vec3::new(7.0, 1.0, 1.0 + radius + d)).norm() < 1e-14);
        let ratio = (radius + d) / (radius - d);
        assert!((pipe.volume_ratio(&p) - ratio).abs() < 1e-14);
        let cavity = Tube::<3> { axis: None, ..pipe };
        let on_radius = Vec3::new(0.0, 1.0, 1.0 + radius - d);
        assert!((cavity.volume_ratio(&on_radius) - ratio * ratio).abs() < 1e-14);
        let circle = Tube::<2> {
            centre: Vec2::new(0.0, 0.0),
            radius,
            axis: None,
        };
        assert!((circle.volume_ratio(&Vec2::new(radius - d, 0.0)) - ratio).abs() < 1e-14);
        assert!(Shape::Tube(pipe).mirror_depth().is_infinite());
    }
}
