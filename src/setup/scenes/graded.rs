//! The channel's graded layout (`scene.refine_walls`): rows parallel to the plates and rings
//! around the cylinder, the spacing δr/refinement at each wall growing by
//! [`GROWTH`](crate::engine::resolution::GROWTH) a layer to δr, and rows of δr between (see
//! [`crate::engine::resolution`] for why and how the operators read it).
//!
//! Each layer's particles share the layer's area equally: a row of thickness s holds
//! round(L/s) particles, a ring of thickness s at radius r holds round(2πr/s), so the layers'
//! volumes sum to their areas. The bulk rows keep δr along x and share the height left between
//! the plates' layers equally. A bulk row's particle within the cylinder's layers is dropped,
//! as the uniform lattice's is beyond its `rings`.

use crate::engine::boundary::{Circle, Plane, Shape};
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::resolution::{graded_spacings, Graded, Layer, Local, WallLayers};
use std::f64::consts::PI;

/// What the layout is built from.
pub struct GradedPlan {
    pub domain: Domain,
    /// δr.
    pub spacing: f64,
    /// The wall spacing is δr/refinement.
    pub refinement: f64,
    /// Plates at y = 0 and H.
    pub plates: bool,
    pub cylinder: Option<Circle>,
    /// Rings of δr around the cylinder beyond its graded ones.
    pub rings: usize,
}

/// Points of one layer and their spacing and volume.
struct LayerPoints {
    points: Vec<Vec2>,
    layer: Layer,
}

impl GradedPlan {
    /// The thickness of the plates' graded layers.
    pub fn plate_thickness(&self) -> f64 {
        if self.plates {
            graded_spacings(self.spacing, self.refinement).iter().sum()
        } else {
            0.0
        }
    }

    /// The thickness of the cylinder's layers, graded and uniform.
    pub fn cylinder_thickness(&self) -> f64 {
        graded_spacings(self.spacing, self.refinement)
            .iter()
            .sum::<f64>()
            + self.rings as f64 * self.spacing
    }

    /// The particles' positions and the layout they follow.
    pub fn build(&self) -> (Vec<Vec2>, Graded) {
        let length = self.domain.max.x - self.domain.min.x;
        let height = self.domain.max.y - self.domain.min.y;
        let plate = self.plate_thickness();
        let columns = (length / self.spacing).round().max(1.0) as usize;
        let middle_rows = ((height - 2.0 * plate) / self.spacing).round().max(1.0) as usize;
        let row_height = (height - 2.0 * plate) / middle_rows as f64;
        let bulk = Local {
            spacing: self.spacing,
            volume: row_height * length / columns as f64,
        };
        let mut points = Vec::new();
        let mut walls = Vec::new();
        let rings = self.cylinder.map(|c| self.rings(&c));
        let thickness = self.cylinder_thickness();
        let clear = |p: &Vec2| {
            self.cylinder.is_none_or(|c| {
                let q = Shape::Circle(c).nearest_image(p, Some(&self.domain));
                c.distance(&q) >= thickness
            })
        };
        if let (Some(c), Some(layers)) = (self.cylinder, rings) {
            walls.push(self.wall_of(Shape::Circle(c), &layers));
            points.extend(layers.into_iter().flat_map(|l| l.points));
        }
        if self.plates {
            for top in [false, true] {
                let layers = self.plate_rows(length, height, top);
                let plane = if top {
                    Plane {
                        axis: 1,
                        position: height,
                        fluid_side: -1.0,
                    }
                } else {
                    Plane::floor()
                };
                walls.push(self.wall_of(Shape::Plane(plane), &layers));
                points.extend(layers.into_iter().flat_map(|l| l.points));
            }
        }
        for j in 0..middle_rows {
            let y = self.domain.min.y + plate + (j as f64 + 0.5) * row_height;
            points.extend(row(self.domain.min.x, y, length, columns).filter(|p| clear(p)));
        }
        (points, Graded { walls, bulk })
    }

    /// The layers' outer distances and locals for [`Graded::at`].
    fn wall_of(&self, shape: Shape, layers: &[LayerPoints]) -> WallLayers {
        WallLayers {
            shape,
            layers: layers.iter().map(|l| l.layer).collect(),
        }
    }

    /// The cylinder's rings: graded, then `rings` of δr; alternate rings staggered.
    fn rings(&self, c: &Circle) -> Vec<LayerPoints> {
        let mut spacings = graded_spacings(self.spacing, self.refinement);
        spacings.extend(std::iter::repeat_n(self.spacing, self.rings));
        let mut inner = 0.0;
        spacings
            .iter()
            .enumerate()
            .map(|(k, &s)| {
                let r = c.radius + inner + 0.5 * s;
                inner += s;
                let n = ((2.0 * PI * r / s).round() as usize).max(3);
                let stagger = 0.5 * (k % 2) as f64;
                let points = (0..n)
                    .map(|j| {
                        let angle = 2.0 * PI * (j as f64 + stagger) / n as f64;
                        self.domain
                            .wrap(c.centre + Vec2::new(angle.cos(), angle.sin()) * r)
                    })
                    .collect();
                let layer = Layer {
                    outer: inner,
                    local: Local {
                        spacing: s,
                        volume: s * 2.0 * PI * r / n as f64,
                    },
                };
                LayerPoints { points, layer }
            })
            .collect()
    }

    /// A plate's graded rows (the floor's, or the top's with `top`).
    fn plate_rows(&self, length: f64, height: f64, top: bool) -> Vec<LayerPoints> {
        let mut inner = 0.0;
        graded_spacings(self.spacing, self.refinement)
            .iter()
            .map(|&s| {
                let d = inner + 0.5 * s;
                inner += s;
                let y = if top { height - d } else { d };
                let n = (length / s).round().max(1.0) as usize;
                let points = row(self.domain.min.x, self.domain.min.y + y, length, n).collect();
                let layer = Layer {
                    outer: inner,
                    local: Local {
                        spacing: s,
                        volume: s * length / n as f64,
                    },
                };
                LayerPoints { points, layer }
            })
            .collect()
    }
}

/// `n` points equally spaced along a periodic row of `length` at height `y`, from `x0`.
fn row(x0: f64, y: f64, length: f64, n: usize) -> impl Iterator<Item = Vec2> {
    let dx = length / n as f64;
    (0..n).map(move |i| Vec2::new(x0 + (i as f64 + 0.5) * dx, y))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(refinement: f64) -> GradedPlan {
        GradedPlan {
            domain: Domain {
                min: Vec2::zeros(),
                max: Vec2::new(6.0, 4.0),
                periodic: [true, false],
            },
            spacing: 0.1,
            refinement,
            plates: true,
            cylinder: Some(Circle {
                centre: Vec2::new(3.0, 2.0),
                radius: 1.0,
            }),
            rings: 1,
        }
    }

    /// The particles' volumes sum to the fluid's area (the box less the cylinder) within
    /// the interface between the cylinder's rings and the bulk rows (about half a row of
    /// δr² around it: 0.3 % of the area here), and every particle finds its own layer.
    #[test]
    fn the_layers_fill_the_fluid_and_each_point_finds_its_layer() {
        let p = plan(4.0);
        let (points, graded) = p.build();
        let total: f64 = points.iter().map(|x| graded.at(x, &p.domain).volume).sum();
        let area = 6.0 * 4.0 - PI;
        assert!((total / area - 1.0).abs() < 3e-3, "{total} against {area}");
        assert!((graded.finest() - 0.025).abs() < 1e-12);
        // The nearest neighbour of each point is within its own spacing's reach.
        let spacing: Vec<f64> = points
            .iter()
            .map(|x| graded.at(x, &p.domain).spacing)
            .collect();
        for (i, x) in points.iter().enumerate().step_by(7) {
            let nearest = points
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, y)| p.domain.min_image(x - y).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest > 0.4 * spacing[i] && nearest < 1.5 * spacing[i],
                "point {x}: nearest {nearest}, spacing {}",
                spacing[i]
            );
        }
    }
}
