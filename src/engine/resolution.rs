//! Graded particle resolution: layers of finer particles along walls, for fixed particles.
//!
//! The polymer stress of a viscoelastic flow past a body forms layers along the no-slip walls
//! much thinner than the body: on the confined cylinder (Oldroyd-B, β = 0.59, Wi = 0.5) τ_xx
//! on the cylinder's top falls by e over 0.07R, one spacing at R/δr = 15, and the drag error
//! falls with δr at an order below one. A uniform lattice fine enough for those layers would
//! hold most of its particles where nothing happens.
//!
//! Each particle i carries its own spacing s_i, smoothing length h_i = 1.3 s_i and volume V_i.
//! Row i of every operator takes the kernel of h_i over the neighbours within 3h_i, each
//! weighted by its V_j (the gather form). The corrections of eq. (22) and of the second-order
//! operators make them exact for linear (quadratic) fields whatever the volumes, so a smooth
//! grading keeps their consistency. Particles must stay where they are put (Eulerian frame):
//! a moving particle would carry its spacing out of its layer.
//!
//! The layout is a function of position, so that a reordering or a restored checkpoint finds
//! each particle's spacing and volume again: around each graded wall, layers of thickness
//! s_k (the wall's first s_w = δr/refinement, each next ×[`GROWTH`] up to δr); a particle whose
//! distance to the wall falls in layer k has spacing s_k and the volume V_k of that layer's
//! particles (its area over its particle count, so that the layers' volumes sum to their
//! area); the first wall that claims a point decides, and the bulk takes the rest.

use crate::engine::boundary::Shape;
use crate::engine::neighbours::Domain;
use nalgebra::SVector;

/// The ratio of neighbouring layers' spacings: 1.25 changes the spacing by a quarter from one
/// layer to the next, within a smoothing length of each other's supports.
pub const GROWTH: f64 = 1.25;

/// A particle's spacing s and volume V.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    pub spacing: f64,
    pub volume: f64,
}

/// One layer along a wall: the particles at wall distances below `outer` (and above the
/// previous layer's) have spacing and volume `local`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    pub outer: f64,
    pub local: Local,
}

/// A wall and its layers, innermost first.
#[derive(Clone, Debug, PartialEq)]
pub struct WallLayers<const D: usize = 2> {
    pub shape: Shape<D>,
    pub layers: Vec<Layer>,
}

/// The spacings of one wall's graded layers: δr/`refinement` at the wall, ×[`GROWTH`] a layer
/// up to (not including) `spacing`.
pub fn graded_spacings(spacing: f64, refinement: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut s = spacing / refinement;
    while s < spacing * (1.0 - 1e-9) {
        out.push(s);
        s *= GROWTH;
    }
    out
}

/// The layout of a run's particles.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Resolution<const D: usize = 2> {
    /// One spacing δr and volume δr^D for every particle.
    #[default]
    Uniform,
    Graded(Graded<D>),
}

/// Graded layers along walls, a uniform bulk elsewhere.
#[derive(Clone, Debug, PartialEq)]
pub struct Graded<const D: usize = 2> {
    pub walls: Vec<WallLayers<D>>,
    pub bulk: Local,
}

impl<const D: usize> Resolution<D> {
    pub fn graded(&self) -> Option<&Graded<D>> {
        match self {
            Resolution::Uniform => None,
            Resolution::Graded(g) => Some(g),
        }
    }
}

impl<const D: usize> Graded<D> {
    /// The spacing and volume of a particle at `p`.
    pub fn at(&self, p: &SVector<f64, D>, domain: &Domain<D>) -> Local {
        for wall in &self.walls {
            let q = wall.shape.nearest_image(p, Some(domain));
            let d = wall.shape.distance(&q);
            if let Some(layer) = wall.layers.iter().find(|l| d < l.outer) {
                return layer.local;
            }
        }
        self.bulk
    }

    /// The smallest spacing of any layer.
    pub fn finest(&self) -> f64 {
        self.walls
            .iter()
            .flat_map(|w| w.layers.iter().map(|l| l.local.spacing))
            .fold(self.bulk.spacing, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::Plane;
    use crate::engine::math::Vec2;

    /// δr/4 grows by 1.25 a layer: 0.25, 0.3125, 0.39, 0.49, 0.61, 0.76, 0.95 (< 1).
    #[test]
    fn spacings_grow_from_the_wall_to_the_bulk() {
        let s = graded_spacings(1.0, 4.0);
        assert_eq!(s.len(), 7);
        assert!((s[0] - 0.25).abs() < 1e-12);
        assert!(s.windows(2).all(|w| (w[1] / w[0] - GROWTH).abs() < 1e-12));
        assert!(*s.last().unwrap() < 1.0 && s.last().unwrap() * GROWTH >= 1.0);
        assert!(graded_spacings(1.0, 1.0).is_empty());
    }

    /// A point takes the layer its wall distance falls in, the bulk beyond the last.
    #[test]
    fn a_point_takes_its_layer() {
        let local = |s: f64| Local {
            spacing: s,
            volume: s * s,
        };
        let graded = Graded {
            walls: vec![WallLayers {
                shape: Shape::Plane(Plane::floor()),
                layers: vec![
                    Layer {
                        outer: 0.25,
                        local: local(0.25),
                    },
                    Layer {
                        outer: 0.75,
                        local: local(0.5),
                    },
                ],
            }],
            bulk: local(1.0),
        };
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(4.0, 4.0),
            periodic: [true, false],
        };
        let at = |y| graded.at(&Vec2::new(1.0, y), &domain).spacing;
        assert_eq!((at(0.1), at(0.5), at(2.0)), (0.25, 0.5, 1.0));
        assert_eq!(graded.finest(), 0.25);
    }
}
