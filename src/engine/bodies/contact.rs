//! A short-range repulsion that keeps discs apart and off the walls, as suspension codes add
//! for contact (Vázquez-Quesada & Ellero 2017 use a steep force acting over a small gap): the
//! lubrication layer between close surfaces is thinner than the particles resolve, so without
//! it two discs, or a disc and a wall, close until their mirrors overlap. The force acts along
//! the line of centres (the wall normal), F = F₀ (1 − gap/ℓ)² for gaps below the range ℓ.

use super::Disc;
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;

/// `[scene.contact]`: strength F₀ (force per unit length) and range ℓ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    pub strength: f64,
    pub range: f64,
}

impl Contact {
    /// The repulsion at a surface-to-surface `gap`.
    pub fn magnitude(&self, gap: f64) -> f64 {
        if gap >= self.range {
            0.0
        } else {
            self.strength * (1.0 - gap.max(0.0) / self.range).powi(2)
        }
    }

    /// The repulsion on each disc from the others (nearest periodic images) and from the
    /// walls bounding the non-periodic axes of `domain`.
    pub fn forces(&self, discs: &[Disc], domain: &Domain) -> Vec<Vec2> {
        let mut out = vec![Vec2::zeros(); discs.len()];
        for (k, a) in discs.iter().enumerate() {
            for (m, b) in discs.iter().enumerate().skip(k + 1) {
                let d = domain.min_image(a.circle.centre - b.circle.centre);
                let distance = d.norm();
                let gap = distance - a.circle.radius - b.circle.radius;
                let f = self.magnitude(gap) * d / distance.max(f64::MIN_POSITIVE);
                out[k] += f;
                out[m] -= f;
            }
            let (c, r) = (a.circle.centre, a.circle.radius);
            for axis in (0..2).filter(|&axis| !domain.periodic[axis]) {
                let mut push = Vec2::zeros();
                push[axis] = self.magnitude(c[axis] - r - domain.min[axis])
                    - self.magnitude(domain.max[axis] - c[axis] - r);
                out[k] += push;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::bodies::Motion;
    use crate::engine::boundary::Circle;

    fn disc(x: f64, y: f64) -> Disc {
        Disc {
            circle: Circle {
                centre: Vec2::new(x, y),
                radius: 1.0,
            },
            velocity: Vec2::zeros(),
            spin: 0.0,
            density: 1.0,
            motion: Motion::Free,
            acceleration: Vec2::zeros(),
            coupling_added_mass: 1.0,
        }
    }

    /// Equal and opposite along the line of centres (across the periodic end too), zero beyond
    /// the range, pushing away from a wall.
    #[test]
    fn repulsion_is_pairwise_and_short_ranged() {
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(10.0, 8.0),
            periodic: [true, false],
        };
        let contact = Contact {
            strength: 2.0,
            range: 0.5,
        };
        // Gap 0.25 across x = 0: half the range, a quarter of the strength.
        let f = contact.forces(&[disc(0.5, 4.0), disc(8.25, 4.0)], &domain);
        assert!((f[0].x - 0.5).abs() < 1e-12 && f[0].y == 0.0, "{f:?}");
        assert_eq!(f[0], -f[1]);
        let far = contact.forces(&[disc(3.0, 4.0), disc(6.0, 4.0)], &domain);
        assert_eq!(far, vec![Vec2::zeros(); 2]);
        // 0.1 above the floor: pushed up by 2(1 − 0.2)².
        let wall = contact.forces(&[disc(5.0, 1.1)], &domain);
        assert!((wall[0].y - 2.0 * 0.8f64.powi(2)).abs() < 1e-12);
    }
}
