//! Where a uniform body force g enters the projection (`scheme.gravity`).
//!
//! * [`Gravity::Predictor`], the paper's: g is a term of the predictor (24), and the PPE (25)
//!   solves for the pressure p, which takes it back in the projection (26).
//! * [`Gravity::ReducedPressure`]: a uniform g is the gradient of g·r, so it can be absorbed
//!   into a reduced pressure P = p − ρ g·r (the hydrostatic part taken out, as pressure
//!   correction schemes for free-surface flow commonly do). The predictor then carries no g,
//!   the PPE solves for P with the free-surface Dirichlet values p_s − ρ g·r_s, and the
//!   projection's −δt∇P/ρ is the old −δt∇p/ρ + δt g. In the continuous equations the two are
//!   the same; discretely they differ where the split is not neutral:
//!   - a liquid at rest has P constant, which every operator reproduces exactly, where the
//!     hydrostatic p is linear, and Morris's Laplacian (21) is not exact for a linear field
//!     on a support a free surface truncates (validation pages, *Still water*);
//!   - with implicit viscosity the no-slip mirrors act on u*, which with g in the predictor
//!     carries the free-fall increment δt g: next to a wall the solve damps it, the projection
//!     then removes all of it, and the wall's first particles gain up to δt g each step (a
//!     layer rising up the walls of a pool at rest). Without g in u* there is nothing to damp;
//!   - a wall's ∂P/∂n = 0 (the mirrors' p_j = p_i) is ∂p/∂n = ρ g·n, the normal momentum
//!     balance of a liquid at rest, where ∂p/∂n = 0 is not.
//!
//!   It needs g·r to be single-valued: no periodic axis along g, no force that changes in time
//!   (mean-flow control, a disc's held return flow), and a projection (not the weakly
//!   compressible scheme, whose pressure is the equation of state's). The state's pressure is
//!   always p: P exists only from the predictor to the end of the projection.

use crate::engine::dimension::Vector;
use rayon::prelude::*;

/// Where the body force enters (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gravity {
    /// In the predictor (24), King & Lind's.
    Predictor,
    /// In the reduced pressure P = p − ρ g·r.
    ReducedPressure,
}

impl Gravity {
    /// The body force the predictor (24) adds: g, or nothing when the pressure carries it.
    pub fn predictor_force<const D: usize>(self, g: Vector<D>) -> Vector<D> {
        match self {
            Gravity::Predictor => g,
            Gravity::ReducedPressure => Vector::zeros(),
        }
    }

    /// p → P = p − ρ g·r at the points `points` (one per value; nothing under `Predictor`).
    pub fn reduce<const D: usize>(
        self,
        pressure: &mut [f64],
        points: &[Vector<D>],
        rho_g: Vector<D>,
    ) {
        self.shift(pressure, points, rho_g, -1.0);
    }

    /// P → p = P + ρ g·r, the inverse of [`Gravity::reduce`] at the same points.
    pub fn restore<const D: usize>(
        self,
        pressure: &mut [f64],
        points: &[Vector<D>],
        rho_g: Vector<D>,
    ) {
        self.shift(pressure, points, rho_g, 1.0);
    }

    fn shift<const D: usize>(
        self,
        pressure: &mut [f64],
        points: &[Vector<D>],
        rho_g: Vector<D>,
        sign: f64,
    ) {
        if self == Gravity::Predictor || rho_g == Vector::<D>::zeros() {
            return;
        }
        pressure
            .par_iter_mut()
            .zip(points.par_iter())
            .for_each(|(p, r)| *p += sign * rho_g.dot(r));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Vec2;

    #[test]
    fn reduce_and_restore_are_inverse_and_take_out_the_hydrostatic_part() {
        // Hydrostatic p = ρg(y_s − y) under g = (0, −g), surface at y_s = 1: P is constant.
        let (rho, g) = (2.0, 9.81);
        let points = [
            Vec2::new(0.3, 0.2),
            Vec2::new(-1.0, 0.7),
            Vec2::new(4.0, 1.0),
        ];
        let p0: Vec<f64> = points.iter().map(|r| rho * g * (1.0 - r.y)).collect();
        let rho_g = rho * Vec2::new(0.0, -g);
        let mut p = p0.clone();
        Gravity::ReducedPressure.reduce(&mut p, &points, rho_g);
        for value in &p {
            assert!(
                (value - rho * g).abs() < 1e-12,
                "P = {value}, expected ρg y_s"
            );
        }
        Gravity::ReducedPressure.restore(&mut p, &points, rho_g);
        for (a, b) in p.iter().zip(&p0) {
            assert!((a - b).abs() < 1e-12);
        }
        let mut q = p0.clone();
        Gravity::Predictor.reduce(&mut q, &points, rho_g);
        assert_eq!(q, p0);
        assert_eq!(
            Gravity::ReducedPressure.predictor_force(rho_g),
            Vec2::zeros()
        );
        assert_eq!(Gravity::Predictor.predictor_force(rho_g), rho_g);
    }
}
