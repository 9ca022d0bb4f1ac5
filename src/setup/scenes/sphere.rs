//! A solid sphere in the 3D channel's box (`[scene.sphere]`), fixed or turning about its
//! held centre ([`crate::engine::bodies::sphere`]). With `scene.walls = false` the box is
//! the cell of a simple cubic array of spheres, whose Stokes drag Zick & Homsy (1982)
//! computed for the whole range of solid fractions (their Table 2); between sliding plates,
//! a freely rotating sphere in shear (Vázquez-Quesada & Ellero 2017, §III A).

use super::support_in_dr;
use crate::engine::bodies::sphere::{fibonacci, golden_angle, Turning};
use crate::engine::boundary::{Shape, Sphere};
use crate::engine::dimension::Vector;
use crate::engine::neighbours::Domain;
use crate::setup::error::{field_err, positive, FieldError};
use serde::{Deserialize, Serialize};

/// `[scene.sphere]` (3D only).
#[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// a: mirrors are reflected across the sphere along its radius, with volume ratios.
    pub radius: f64,
    /// Centre (default: the centre of the box).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre: Option<[f64; 3]>,
    /// Layers of particles laid on spherical shells around the sphere, the lattice kept
    /// beyond them (default 3; 0: the lattice alone, cut by the sphere, whose drag then reads
    /// several per cent low: the decision log).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shells: Option<usize>,
    /// `fixed` (the default), `prescribed` (turning at a constant `spin`) or
    /// `free-rotation` (centre held, turning under the fluid's torque). A sphere that
    /// translates is not written yet.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
    /// Ω [x, y, z]: constant when prescribed, initial when free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spin: Option<[f64; 3]>,
    /// ρ_s/ρ_f of a freely rotating sphere (default 1, neutrally buoyant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_ratio: Option<f64>,
}

/// How a validated sphere turns (None of it: fixed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereTurning {
    pub turning: Turning,
    /// Ω at the start.
    pub spin: Vector<3>,
    /// ρ_s/ρ_f.
    pub density_ratio: f64,
}

impl SphereSpec {
    /// `shells`, by default 3 (as the cylinder's rings are in the cases).
    pub fn shells(&self) -> usize {
        self.shells.unwrap_or(3)
    }

    /// `motion`, `spin` and `density_ratio`: None for a fixed sphere.
    pub fn turning(&self) -> Result<Option<SphereTurning>, FieldError> {
        let spin = self.spin.map(Vector::<3>::from);
        if spin.is_some_and(|w| !w.iter().all(|c| c.is_finite())) {
            return Err(field_err("scene.sphere.spin", "must be finite"));
        }
        let turning = match self.motion.as_deref().unwrap_or("fixed") {
            "fixed" => None,
            "prescribed" => Some(Turning::Prescribed),
            "free-rotation" => Some(Turning::Free),
            other => {
                return Err(field_err(
                    "scene.sphere.motion",
                    format!("must be fixed, prescribed or free-rotation (a sphere that translates is not written yet), got {other:?}"),
                ))
            }
        };
        let density_ratio = match (turning, self.density_ratio) {
            (Some(Turning::Free), Some(r)) => positive("scene.sphere.density_ratio", r)?,
            (_, Some(_)) => {
                return Err(field_err(
                    "scene.sphere.density_ratio",
                    "is for motion = \"free-rotation\" only",
                ))
            }
            (_, None) => 1.0,
        };
        match (turning, spin) {
            (None, Some(_)) => Err(field_err(
                "scene.sphere.spin",
                "a fixed sphere does not turn: motion = \"prescribed\" or \"free-rotation\"",
            )),
            (Some(Turning::Prescribed), None) => Err(field_err(
                "scene.sphere.spin",
                "required with motion = \"prescribed\"",
            )),
            (None, None) => Ok(None),
            (Some(turning), spin) => Ok(Some(SphereTurning {
                turning,
                spin: spin.unwrap_or_else(Vector::<3>::zeros),
                density_ratio,
            })),
        }
    }

    /// The sphere in `domain` at spacing `dr`. Its radius is at least two kernel supports
    /// (a particle's mirrors must not reach round to the far side, as for a cylinder). Each
    /// face of the box is at least a support away; across a periodic axis the gap between
    /// the sphere and its image is at least two supports, because a particle's mirrors are
    /// reflected across the image nearest it only, and a particle within a support of two
    /// images would need both.
    pub fn validate(&self, domain: &Domain<3>, dr: f64) -> Result<Sphere, FieldError> {
        let shells = self.shells();
        let gap = (0..3)
            .map(|a| domain.max[a] - domain.min[a] - 2.0 * self.radius)
            .fold(f64::INFINITY, f64::min);
        if 2.0 * (shells + 1) as f64 * dr > gap {
            return Err(field_err(
                "scene.sphere.shells",
                format!(
                    "{} shells of δr = {dr:.4} on each side and a lattice row between do not fit in the gap {gap:.4} between the sphere and its images",
                    shells
                ),
            ));
        }
        let radius = positive("scene.sphere.radius", self.radius)?;
        let support = support_in_dr() * dr;
        if radius < 2.0 * support {
            return Err(field_err(
                "scene.sphere.radius",
                format!(
                    "must be at least two kernel supports ({:.4}) at this resolution, got {radius}",
                    2.0 * support
                ),
            ));
        }
        let centre = self
            .centre
            .map_or(0.5 * (domain.min + domain.max), Vector::<3>::from);
        for a in 0..3 {
            let (lo, hi) = (domain.min[a], domain.max[a]);
            let fits = if domain.periodic[a] {
                hi - lo >= 2.0 * (radius + support)
            } else {
                centre[a] - radius >= lo + support && centre[a] + radius <= hi - support
            };
            if !(centre[a].is_finite() && fits && (lo..=hi).contains(&centre[a])) {
                return Err(field_err(
                    "scene.sphere",
                    format!(
                        "the sphere must lie in the box with a kernel support ({support:.4}) to each wall and two between it and its periodic images (axis {a})"
                    ),
                ));
            }
        }
        Ok(Sphere { centre, radius })
    }
}

/// The solid fraction of a simple cubic array whose cell is `domain`: (4/3)πa³ over the
/// cell's volume.
pub fn solid_fraction(sphere: &Sphere, domain: &Domain<3>) -> f64 {
    let cell: f64 = (domain.max - domain.min).iter().product();
    4.0 / 3.0 * std::f64::consts::PI * sphere.radius.powi(3) / cell
}

/// The body-conforming layers around `sphere`: shell k at r_k = a + (k + ½)δr holds
/// n_k = round(4πr_k²/δr²) points (each an area of ≈ δr², a volume of ≈ δr³) on a Fibonacci
/// spiral, whose points are spread evenly over the sphere without the crowding of a
/// latitude–longitude grid at the poles; alternate shells turn by half the spiral's angle, so
/// that neighbouring shells' points do not line up radially. The lattice keeps only the
/// points at least `count`·δr from the surface, half a spacing beyond the last shell.
pub fn shells(sphere: &Sphere, count: usize, dr: f64, domain: &Domain<3>) -> Vec<Vector<3>> {
    let mut points = Vec::new();
    for k in 0..count {
        let r = sphere.radius + (k as f64 + 0.5) * dr;
        let n = (4.0 * std::f64::consts::PI * r * r / (dr * dr)).round() as usize;
        let turn = 0.5 * golden_angle() * (k % 2) as f64;
        points.extend(fibonacci(n, turn).map(|u| domain.wrap(sphere.centre + u * r)));
    }
    points
}

/// The points of `lattice` beyond `count` shells of `sphere` ([`beyond_shells`]) and the
/// shells themselves ([`shells`]); without a sphere, the lattice.
pub fn with_shells(
    lattice: impl Iterator<Item = Vector<3>>,
    sphere: Option<&Sphere>,
    count: usize,
    dr: f64,
    domain: &Domain<3>,
) -> Vec<Vector<3>> {
    lattice
        .filter(|p| sphere.is_none_or(|s| beyond_shells(s, count, p, domain, dr)))
        .chain(
            sphere
                .into_iter()
                .flat_map(|s| shells(s, count, dr, domain)),
        )
        .collect()
}

/// Whether a lattice point lies beyond `count` shells of `sphere` (its nearest image).
pub fn beyond_shells(
    sphere: &Sphere,
    count: usize,
    p: &Vector<3>,
    domain: &Domain<3>,
    dr: f64,
) -> bool {
    let q = Shape::Circle(*sphere).nearest_image(p, Some(domain));
    sphere.distance(&q) >= (count as f64 * dr).max(0.1 * dr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::scenes::channel::ChannelSpec;

    fn cube() -> Domain<3> {
        Domain {
            min: Vector::<3>::zeros(),
            max: Vector::<3>::repeat(1.0),
            periodic: [true; 3],
        }
    }

    /// Each shell holds about one particle per δr² of its area, so the shells carry the volume
    /// they cover to within the rounding of n_k; no two points of a shell or of neighbouring
    /// shells come closer than 0.7δr (the lattice's spacing is δr).
    #[test]
    fn shells_cover_their_volume_without_crowding() {
        let dr = 1.0 / 26.0;
        let sphere = Sphere {
            centre: Vector::<3>::repeat(0.5),
            radius: 0.31,
        };
        let points = shells(&sphere, 3, dr, &cube());
        let (inner, outer) = (sphere.radius, sphere.radius + 3.0 * dr);
        let volume = 4.0 / 3.0 * std::f64::consts::PI * (outer.powi(3) - inner.powi(3));
        let covered = points.len() as f64 * dr.powi(3);
        assert!(
            (covered / volume - 1.0).abs() < 0.01,
            "{covered} vs {volume}"
        );
        let closest = points
            .iter()
            .enumerate()
            .flat_map(|(i, p)| points[i + 1..].iter().map(move |q| (p - q).norm()))
            .fold(f64::INFINITY, f64::min);
        assert!(closest > 0.7 * dr, "closest pair {:.3}δr", closest / dr);
    }

    fn channel(extra: &str) -> Result<crate::setup::scenes::channel::Channel, FieldError> {
        let spec: ChannelSpec = toml::from_str(&format!(
            "length = 1.0\nheight = 1.0\nresolution = 26\nbody_force = [1.0, 0.0]\n\
             velocity = 1.0\n{extra}"
        ))
        .unwrap();
        spec.validate()
    }

    /// A sphere is 3D, two supports across at least, and its shells must fit in the gap to
    /// its images; between plates, whose speed sets the scale, it takes no scene.velocity;
    /// each refusal names its key.
    #[test]
    fn a_sphere_is_refused_where_it_does_not_fit() {
        let field = |extra: &str| channel(extra).unwrap_err().0;
        let sphere = "[sphere]\nradius = 0.31\n";
        assert_eq!(field(&format!("walls = false\n{sphere}")), "scene.sphere");
        let space = "dimension = 3\ndepth = 1.0\n";
        assert_eq!(field(&format!("{space}{sphere}")), "scene.velocity");
        let periodic = format!("{space}walls = false\n");
        assert!(channel(&format!("{periodic}{sphere}")).is_ok());
        assert_eq!(
            field(&format!("{periodic}[sphere]\nradius = 0.2\n")),
            "scene.sphere.radius"
        );
        assert_eq!(
            field(&format!("{periodic}[sphere]\nradius = 0.31\nshells = 5\n")),
            "scene.sphere.shells"
        );
        assert_eq!(
            field(&format!("{periodic}[sphere]\nradius = 0.4\nshells = 0\n")),
            "scene.sphere"
        );
    }
}
