//! Small fixed-size linear algebra: 2-vectors, 2×2 matrices, and symmetric 2×2 tensors with
//! the eigen-decomposition the log-conformation method needs (paper eqs. (12)–(13)); their
//! 3D counterparts in [`sym3`].

pub mod sym3;

pub use sym3::{Eigen3, Mat3, Sym3, Vec3};

use std::ops::{Add, AddAssign, Mul, Sub};

pub type Vec2 = nalgebra::Vector2<f64>;
/// General 2×2 matrix. For a velocity gradient `g[(a, b)] = ∂u_a/∂x_b`.
pub type Mat2 = nalgebra::Matrix2<f64>;

/// Symmetric 2×2 tensor (conformation A, its logarithm Ψ, stresses τ_p and Φ).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sym2 {
    pub xx: f64,
    pub xy: f64,
    pub yy: f64,
}

/// Eigen-decomposition `R diag(λ1, λ2) Rᵀ` of a symmetric tensor, eq. (12). The columns of R
/// are `(c, s)` for λ1 and `(−s, c)` for λ2; λ1 ≥ λ2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eigen2 {
    pub values: [f64; 2],
    pub cos: f64,
    pub sin: f64,
}

impl Sym2 {
    pub const ZERO: Sym2 = Sym2 {
        xx: 0.0,
        xy: 0.0,
        yy: 0.0,
    };
    pub const IDENTITY: Sym2 = Sym2 {
        xx: 1.0,
        xy: 0.0,
        yy: 1.0,
    };

    pub const fn new(xx: f64, xy: f64, yy: f64) -> Self {
        Self { xx, xy, yy }
    }

    pub fn trace(&self) -> f64 {
        self.xx + self.yy
    }

    pub fn det(&self) -> f64 {
        self.xx * self.yy - self.xy * self.xy
    }

    pub fn is_finite(&self) -> bool {
        self.xx.is_finite() && self.xy.is_finite() && self.yy.is_finite()
    }

    /// The symmetric part `(m + mᵀ)/2` of a general matrix.
    pub fn sym_part(m: &Mat2) -> Self {
        Self::new(m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)])
    }

    pub fn to_mat(&self) -> Mat2 {
        Mat2::new(self.xx, self.xy, self.xy, self.yy)
    }

    /// `m·self·mᵀ` for a general `m` (used for rotations).
    pub fn congruence(&self, m: &Mat2) -> Self {
        Self::sym_part(&(m * self.to_mat() * m.transpose()))
    }

    /// Closed-form eigen-decomposition; robust for repeated eigenvalues (R = I then).
    ///
    /// The eigenvalue of larger magnitude is `mean ± radius` (no cancellation); the other is
    /// det/that, which keeps full relative precision for a strongly stretched conformation
    /// (Λ1 ~ 10⁵, Λ2 ~ 10⁻²) where `mean − radius` would lose six digits.
    ///
    /// The rotation by the angle θ with tan 2θ = 2xy/(xx − yy), θ ∈ (−π/2, π/2], is taken
    /// from cos 2θ and sin 2θ by the half-angle formulas without trigonometric calls (a sixth
    /// of the constitutive stage's time went to `atan2`, `sin_cos` and `hypot`): the larger of
    /// |cos θ|, |sin θ| from its square root, the other from sin 2θ = 2 sin θ cos θ, so
    /// neither loses precision to cancellation.
    pub fn eigen(&self) -> Eigen2 {
        let mean = 0.5 * (self.xx + self.yy);
        let half_diff = 0.5 * (self.xx - self.yy);
        let radius = half_diff.mul_add(half_diff, self.xy * self.xy).sqrt();
        let (cos, sin) = half_angle(half_diff, self.xy, radius);
        let det = self.xx.mul_add(self.yy, -self.xy * self.xy);
        let values = if mean >= 0.0 {
            let large = mean + radius;
            [large, if large != 0.0 { det / large } else { 0.0 }]
        } else {
            let large = mean - radius;
            [det / large, large]
        };
        Eigen2 { values, cos, sin }
    }

    /// The largest eigenvalue, `mean + radius` (no trigonometry).
    pub fn max_eigenvalue(&self) -> f64 {
        0.5 * (self.xx + self.yy) + (0.5 * (self.xx - self.yy)).hypot(self.xy)
    }

    /// Applies a scalar function to the eigenvalues: `R f(Λ) Rᵀ`.
    pub fn map_eigenvalues(&self, f: impl Fn(f64) -> f64) -> Self {
        let e = self.eigen();
        Self::from_eigen(&e, [f(e.values[0]), f(e.values[1])])
    }

    /// `R diag(values) Rᵀ` with the rotation of `e`.
    pub fn from_eigen(e: &Eigen2, values: [f64; 2]) -> Self {
        let (c, s) = (e.cos, e.sin);
        let [l1, l2] = values;
        Self::new(
            c * c * l1 + s * s * l2,
            c * s * (l1 - l2),
            s * s * l1 + c * c * l2,
        )
    }

    /// Matrix logarithm Ψ = R ln Λ Rᵀ, eq. (13). NaN if not positive definite.
    pub fn log(&self) -> Self {
        self.map_eigenvalues(f64::ln)
    }

    /// Matrix exponential `R exp(Λ) Rᵀ`.
    pub fn exp(&self) -> Self {
        self.map_eigenvalues(f64::exp)
    }

    /// `(self·v)`.
    pub fn dot(&self, v: &Vec2) -> Vec2 {
        Vec2::new(self.xx * v.x + self.xy * v.y, self.xy * v.x + self.yy * v.y)
    }

    /// Frobenius product `self : other`.
    pub fn contract(&self, other: &Sym2) -> f64 {
        self.xx * other.xx + 2.0 * self.xy * other.xy + self.yy * other.yy
    }
}

/// (cos θ, sin θ) of θ = ½ atan2(y, x) ∈ (−π/2, π/2], with `radius` = √(x² + y²)
/// ([`Sym2::eigen`]); θ = 0 where the radius is zero (repeated eigenvalues).
fn half_angle(x: f64, y: f64, radius: f64) -> (f64, f64) {
    if radius == 0.0 {
        return (1.0, 0.0);
    }
    let (cos2, sin2) = (x / radius, y / radius);
    if cos2 >= 0.0 {
        let cos = (0.5 * (1.0 + cos2)).sqrt();
        (cos, 0.5 * sin2 / cos)
    } else {
        // θ ∈ (π/4, π/2] or [−π/2, −π/4): sin θ takes the sign of y (of −0 too, as atan2).
        let sin = (0.5 * (1.0 - cos2)).sqrt().copysign(y);
        (0.5 * sin2 / sin, sin)
    }
}

impl Eigen2 {
    /// Rotation matrix R whose columns are the eigenvectors.
    pub fn rotation(&self) -> Mat2 {
        Mat2::new(self.cos, -self.sin, self.sin, self.cos)
    }
}

impl Add for Sym2 {
    type Output = Sym2;
    fn add(self, o: Sym2) -> Sym2 {
        Sym2::new(self.xx + o.xx, self.xy + o.xy, self.yy + o.yy)
    }
}

impl AddAssign for Sym2 {
    fn add_assign(&mut self, o: Sym2) {
        *self = *self + o;
    }
}

impl Sub for Sym2 {
    type Output = Sym2;
    fn sub(self, o: Sym2) -> Sym2 {
        Sym2::new(self.xx - o.xx, self.xy - o.xy, self.yy - o.yy)
    }
}

impl Mul<f64> for Sym2 {
    type Output = Sym2;
    fn mul(self, k: f64) -> Sym2 {
        Sym2::new(self.xx * k, self.xy * k, self.yy * k)
    }
}

impl Mul<Sym2> for f64 {
    type Output = Sym2;
    fn mul(self, s: Sym2) -> Sym2 {
        s * self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The half-angle rotation is the trigonometric one, ½ atan2(y, x), to round-off, in
    /// every quadrant and on the axes (signed zeros included), and a unit vector.
    #[test]
    fn half_angle_matches_the_trigonometric_rotation() {
        let mut cases: Vec<(f64, f64)> = (0..720)
            .map(|k| (k as f64 * 0.5 + 0.1).to_radians())
            .map(|a| (3.0 * a.cos(), 3.0 * a.sin()))
            .collect();
        cases.extend([
            (1.0, 0.0),
            (-1.0, 0.0),
            (-1.0, -0.0),
            (0.0, 1.0),
            (0.0, -1.0),
        ]);
        cases.extend([(1e-300, 1e-300), (-1e8, 1e-8), (-1e8, -1e-8)]);
        for (x, y) in cases {
            let (c, s) = half_angle(x, y, x.hypot(y));
            let angle = 0.5 * y.atan2(x);
            assert!(
                (c - angle.cos()).abs() < 1e-15 && (s - angle.sin()).abs() < 1e-15,
                "({x}, {y}): ({c}, {s}) against angle {angle}"
            );
            assert!((c * c + s * s - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn eigen_reconstructs_the_tensor() {
        for a in [
            Sym2::new(3.0, 1.2, -0.5),
            Sym2::new(1.0, 0.0, 1.0),
            Sym2::new(2.0, 0.0, 5.0),
            Sym2::new(1e5, 300.0, 1.0),
            Sym2::new(1.0, 1e-9, 1.0 + 1e-12),
            Sym2::new(1.0, -2.0, 1.0),
            Sym2::new(1.0, 1e-3, 4.0),
            Sym2::new(1.0, -1e-3, 4.0),
            Sym2::new(1.0, 0.0, 4.0),
            Sym2::new(1.0, -0.0, 4.0),
        ] {
            let e = a.eigen();
            let b = Sym2::from_eigen(&e, e.values);
            let scale = a.xx.abs().max(a.yy.abs()).max(1.0);
            assert!(
                (a - b).contract(&(a - b)).sqrt() < 1e-12 * scale,
                "{a:?} vs {b:?}"
            );
            assert!(e.values[0] >= e.values[1]);
        }
    }

    #[test]
    fn log_and_exp_are_inverse_and_keep_spd() {
        let a = Sym2::new(4.0, 1.5, 2.0);
        let psi = a.log();
        let back = psi.exp();
        assert!((back - a).contract(&(back - a)).sqrt() < 1e-12);
        assert!(back.det() > 0.0 && back.trace() > 0.0);
        assert!(Sym2::IDENTITY.log().contract(&Sym2::IDENTITY.log()) < 1e-30);
        // ln det A = tr ln A.
        assert!((a.det().ln() - psi.trace()).abs() < 1e-13);
    }
}
