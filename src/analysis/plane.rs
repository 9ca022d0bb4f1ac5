//! The plane (x, y) of points and velocities in D dimensions: what the analytic references
//! and the channel's profiles read (a channel in space does not vary along z).

use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::math::Vec2;
use std::borrow::Cow;

/// The (x, y) components of D-vectors: borrowed in the plane, projected in space.
pub trait InPlane<const D: usize>: Dimension<D> {
    fn in_plane(v: &[Vector<D>]) -> Cow<'_, [Vec2]>;
}

impl InPlane<2> for Dim<2> {
    fn in_plane(v: &[Vec2]) -> Cow<'_, [Vec2]> {
        Cow::Borrowed(v)
    }
}

impl InPlane<3> for Dim<3> {
    fn in_plane(v: &[Vector<3>]) -> Cow<'_, [Vec2]> {
        Cow::Owned(v.iter().map(|p| Vec2::new(p.x, p.y)).collect())
    }
}
