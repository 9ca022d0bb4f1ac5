//! The plane the analytic references read: (x, y) of a flow that does not vary along z (a
//! channel, in the plane or in space), or the meridional plane (x, r) of an axisymmetric flow
//! along x (a pipe), for points, velocities and polymer stresses in D dimensions.

use crate::engine::dimension::{Dim, Dimension, SymTensor, Vector};
use crate::engine::math::Vec2;
use std::borrow::Cow;

/// How a scene's points map onto its reference's plane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PlaneMap {
    /// (x, y): the flow does not vary along z.
    #[default]
    Cartesian,
    /// (x, r), r the distance from the axis along x through (y, z) = `centre`; velocities map
    /// to (u_x, u_r), stresses to (τ_xx, τ_xr, τ_rr).
    Meridional { centre: [f64; 2] },
}

/// The unit radial vector (e_y, e_z) of `p` about `centre` and the distance r (e = 0 on the
/// axis).
fn radial(p: &Vector<3>, centre: [f64; 2]) -> ([f64; 2], f64) {
    let (dy, dz) = (p.y - centre[0], p.z - centre[1]);
    let r = dy.hypot(dz);
    if r > 0.0 {
        ([dy / r, dz / r], r)
    } else {
        ([0.0, 0.0], 0.0)
    }
}

/// D-vectors and D-tensors seen in the reference's plane: borrowed in the plane, projected
/// in space.
pub trait InPlane<const D: usize>: Dimension<D> {
    fn positions(map: PlaneMap, p: &[Vector<D>]) -> Cow<'_, [Vec2]>;
    /// The velocities `v` of the particles at `p`.
    fn velocities<'a>(map: PlaneMap, p: &[Vector<D>], v: &'a [Vector<D>]) -> Cow<'a, [Vec2]>;
    /// (τ_xx, τ_xy, τ_yy) in the plane of the particle at `p`.
    fn stress(map: PlaneMap, p: &Vector<D>, tau: &Self::Sym) -> [f64; 3];
}

impl InPlane<2> for Dim<2> {
    fn positions(_: PlaneMap, p: &[Vec2]) -> Cow<'_, [Vec2]> {
        Cow::Borrowed(p)
    }

    fn velocities<'a>(_: PlaneMap, _: &[Vec2], v: &'a [Vec2]) -> Cow<'a, [Vec2]> {
        Cow::Borrowed(v)
    }

    fn stress(_: PlaneMap, _: &Vec2, tau: &Self::Sym) -> [f64; 3] {
        [tau.entry(0, 0), tau.entry(0, 1), tau.entry(1, 1)]
    }
}

impl InPlane<3> for Dim<3> {
    fn positions(map: PlaneMap, p: &[Vector<3>]) -> Cow<'_, [Vec2]> {
        Cow::Owned(match map {
            PlaneMap::Cartesian => p.iter().map(|p| Vec2::new(p.x, p.y)).collect(),
            PlaneMap::Meridional { centre } => p
                .iter()
                .map(|p| Vec2::new(p.x, radial(p, centre).1))
                .collect(),
        })
    }

    fn velocities<'a>(map: PlaneMap, p: &[Vector<3>], v: &'a [Vector<3>]) -> Cow<'a, [Vec2]> {
        Cow::Owned(match map {
            PlaneMap::Cartesian => v.iter().map(|v| Vec2::new(v.x, v.y)).collect(),
            PlaneMap::Meridional { centre } => p
                .iter()
                .zip(v)
                .map(|(p, v)| {
                    let (e, _) = radial(p, centre);
                    Vec2::new(v.x, v.y * e[0] + v.z * e[1])
                })
                .collect(),
        })
    }

    fn stress(map: PlaneMap, p: &Vector<3>, tau: &Self::Sym) -> [f64; 3] {
        let t = |a, b| tau.entry(a, b);
        match map {
            PlaneMap::Cartesian => [t(0, 0), t(0, 1), t(1, 1)],
            PlaneMap::Meridional { centre } => {
                let ([ey, ez], _) = radial(p, centre);
                let rr = ey * ey * t(1, 1) + 2.0 * ey * ez * t(1, 2) + ez * ez * t(2, 2);
                [t(0, 0), ey * t(0, 1) + ez * t(0, 2), rr]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Sym3;

    /// A pipe's axisymmetric fields read the same at every angle: u_r and τ_xr of a field
    /// radial about the axis come back whole in the meridional plane.
    #[test]
    fn the_meridional_plane_reads_radial_components_at_every_angle() {
        let map = PlaneMap::Meridional { centre: [1.0, 1.0] };
        for k in 0..8 {
            let angle = std::f64::consts::TAU * k as f64 / 8.0;
            let (c, s) = (angle.cos(), angle.sin());
            let p = Vector::<3>::new(0.3, 1.0 + 0.5 * c, 1.0 + 0.5 * s);
            let v = Vector::<3>::new(2.0, 0.7 * c, 0.7 * s);
            let q = Dim::<3>::positions(map, std::slice::from_ref(&p))[0];
            let w = Dim::<3>::velocities(map, &[p], std::slice::from_ref(&v))[0];
            assert!((q - Vec2::new(0.3, 0.5)).norm() < 1e-12, "{q:?}");
            assert!((w - Vec2::new(2.0, 0.7)).norm() < 1e-12, "{w:?}");
            // τ = τ_xr (x̂ e_r + e_r x̂) + τ_rr e_r e_r with τ_xr = −3, τ_rr = 0.25.
            let tau = Sym3::new(
                1.0,
                -3.0 * c,
                -3.0 * s,
                0.25 * c * c,
                0.25 * c * s,
                0.25 * s * s,
            );
            let [xx, xr, rr] = Dim::<3>::stress(map, &p, &tau);
            assert!(
                (xx - 1.0).abs() < 1e-12 && (xr + 3.0).abs() < 1e-12 && (rr - 0.25).abs() < 1e-12
            );
        }
    }
}
