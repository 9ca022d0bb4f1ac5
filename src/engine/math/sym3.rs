//! Symmetric 3 × 3 tensors and their eigen-decomposition, the 3D counterparts of [`super::Sym2`]
//! for the log-conformation method (paper eqs. (12)–(13) with three eigenvalues).

use std::ops::{Add, AddAssign, Mul, Sub};

pub type Vec3 = nalgebra::Vector3<f64>;
/// General 3×3 matrix. For a velocity gradient `g[(a, b)] = ∂u_a/∂x_b`.
pub type Mat3 = nalgebra::Matrix3<f64>;

/// Symmetric 3×3 tensor (conformation A, its logarithm Ψ, stresses τ_p and Φ).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sym3 {
    pub xx: f64,
    pub xy: f64,
    pub xz: f64,
    pub yy: f64,
    pub yz: f64,
    pub zz: f64,
}

/// Eigen-decomposition `R diag(λ1, λ2, λ3) Rᵀ` of a symmetric tensor, eq. (12): the columns of
/// `rotation` are the eigenvectors, λ1 ≥ λ2 ≥ λ3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eigen3 {
    pub values: [f64; 3],
    pub rotation: Mat3,
}

/// The pairs (p, q), p < q, one Jacobi sweep annihilates in turn.
const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
/// Sweeps before giving up; cyclic Jacobi converges quadratically and a 3×3 tensor needs
/// four to six in double precision.
const MAX_SWEEPS: usize = 50;

impl Sym3 {
    pub const ZERO: Sym3 = Sym3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    pub const IDENTITY: Sym3 = Sym3::new(1.0, 0.0, 0.0, 1.0, 0.0, 1.0);

    pub const fn new(xx: f64, xy: f64, xz: f64, yy: f64, yz: f64, zz: f64) -> Self {
        Self {
            xx,
            xy,
            xz,
            yy,
            yz,
            zz,
        }
    }

    /// The component (i, j), i and j in 0..3, either order.
    pub fn entry(&self, i: usize, j: usize) -> f64 {
        match (i.min(j), i.max(j)) {
            (0, 0) => self.xx,
            (0, 1) => self.xy,
            (0, 2) => self.xz,
            (1, 1) => self.yy,
            (1, 2) => self.yz,
            (2, 2) => self.zz,
            _ => panic!("Sym3 has no component ({i}, {j})"),
        }
    }

    /// The tensor whose component (i, j), i ≤ j, is `f(i, j)`.
    pub fn from_entries(f: impl Fn(usize, usize) -> f64) -> Self {
        Self::new(f(0, 0), f(0, 1), f(0, 2), f(1, 1), f(1, 2), f(2, 2))
    }

    pub fn trace(&self) -> f64 {
        self.xx + self.yy + self.zz
    }

    pub fn det(&self) -> f64 {
        self.xx * (self.yy * self.zz - self.yz * self.yz)
            - self.xy * (self.xy * self.zz - self.yz * self.xz)
            + self.xz * (self.xy * self.yz - self.yy * self.xz)
    }

    pub fn is_finite(&self) -> bool {
        [self.xx, self.xy, self.xz, self.yy, self.yz, self.zz]
            .iter()
            .all(|v| v.is_finite())
    }

    /// The symmetric part `(m + mᵀ)/2` of a general matrix.
    pub fn sym_part(m: &Mat3) -> Self {
        Self::from_entries(|i, j| {
            if i == j {
                m[(i, i)]
            } else {
                0.5 * (m[(i, j)] + m[(j, i)])
            }
        })
    }

    pub fn to_mat(&self) -> Mat3 {
        Mat3::new(
            self.xx, self.xy, self.xz, self.xy, self.yy, self.yz, self.xz, self.yz, self.zz,
        )
    }

    /// `m·self·mᵀ` for a general `m` (used for rotations).
    pub fn congruence(&self, m: &Mat3) -> Self {
        Self::sym_part(&(m * self.to_mat() * m.transpose()))
    }

    /// Eigen-decomposition by cyclic Jacobi rotations.
    ///
    /// Jacobi rather than the closed form (the roots of the characteristic cubic) or a QR
    /// iteration: those guarantee each eigenvalue only to a precision relative to the largest
    /// (the closed form's cancellation reaches that bound), so for a conformation stretched
    /// along the axes (Λ1 ~ 10⁵, Λ3 ~ 10⁻²) ln Λ3 could lose six digits. Jacobi finds each eigenvalue to a precision relative to itself wherever the
    /// tensor is well conditioned after a diagonal scaling (Demmel & Veselić 1992), provided a
    /// rotation is skipped only where the off-diagonal element is below round-off of the
    /// geometric mean of its two diagonal ones. (For a stretch along a rotated axis no method
    /// does better than the round-off the entries themselves carry.)
    pub fn eigen(&self) -> Eigen3 {
        let mut a = [
            [self.xx, self.xy, self.xz],
            [self.xy, self.yy, self.yz],
            [self.xz, self.yz, self.zz],
        ];
        let mut v = Mat3::identity();
        for _ in 0..MAX_SWEEPS {
            let mut rotated = false;
            for (p, q) in PAIRS {
                let apq = a[p][q];
                let negligible = apq.abs() <= 0.5 * f64::EPSILON * (a[p][p] * a[q][q]).abs().sqrt();
                if apq == 0.0 || negligible {
                    a[p][q] = 0.0;
                    a[q][p] = 0.0;
                    continue;
                }
                rotated = true;
                rotate(&mut a, &mut v, p, q);
            }
            if !rotated {
                break;
            }
        }
        sorted(a, v)
    }

    /// The largest eigenvalue.
    pub fn max_eigenvalue(&self) -> f64 {
        self.eigen().values[0]
    }

    /// Applies a scalar function to the eigenvalues: `R f(Λ) Rᵀ`.
    pub fn map_eigenvalues(&self, f: impl Fn(f64) -> f64) -> Self {
        let e = self.eigen();
        Self::from_eigen(&e, e.values.map(f))
    }

    /// `R diag(values) Rᵀ` with the rotation of `e`.
    pub fn from_eigen(e: &Eigen3, values: [f64; 3]) -> Self {
        let r = &e.rotation;
        Self::from_entries(|i, j| (0..3).map(|k| r[(i, k)] * values[k] * r[(j, k)]).sum())
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
    pub fn dot(&self, v: &Vec3) -> Vec3 {
        self.to_mat() * v
    }

    /// Frobenius product `self : other`.
    pub fn contract(&self, other: &Sym3) -> f64 {
        self.xx * other.xx
            + self.yy * other.yy
            + self.zz * other.zz
            + 2.0 * (self.xy * other.xy + self.xz * other.xz + self.yz * other.yz)
    }
}

/// One Jacobi rotation in the (p, q) plane that zeroes `a[p][q]` (the stable form with
/// t = tan φ the smaller root of t² + 2θt − 1 = 0), accumulated into the eigenvectors `v`.
fn rotate(a: &mut [[f64; 3]; 3], v: &mut Mat3, p: usize, q: usize) {
    let apq = a[p][q];
    let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    let t = if theta.abs() > 1e150 {
        0.5 / theta
    } else {
        theta.signum() / (theta.abs() + theta.mul_add(theta, 1.0).sqrt())
    };
    let c = 1.0 / t.mul_add(t, 1.0).sqrt();
    let s = t * c;
    a[p][p] -= t * apq;
    a[q][q] += t * apq;
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    let r = 3 - p - q;
    let (arp, arq) = (a[r][p], a[r][q]);
    a[r][p] = c * arp - s * arq;
    a[p][r] = a[r][p];
    a[r][q] = s * arp + c * arq;
    a[q][r] = a[r][q];
    for k in 0..3 {
        let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
        v[(k, p)] = c * vkp - s * vkq;
        v[(k, q)] = s * vkp + c * vkq;
    }
}

/// The diagonal of the rotated tensor and the eigenvectors, in decreasing order.
fn sorted(a: [[f64; 3]; 3], v: Mat3) -> Eigen3 {
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    Eigen3 {
        values: order.map(|k| a[k][k]),
        rotation: Mat3::from_fn(|i, j| v[(i, order[j])]),
    }
}

impl Add for Sym3 {
    type Output = Sym3;
    fn add(self, o: Sym3) -> Sym3 {
        Sym3::from_entries(|i, j| self.entry(i, j) + o.entry(i, j))
    }
}

impl AddAssign for Sym3 {
    fn add_assign(&mut self, o: Sym3) {
        *self = *self + o;
    }
}

impl Sub for Sym3 {
    type Output = Sym3;
    fn sub(self, o: Sym3) -> Sym3 {
        Sym3::from_entries(|i, j| self.entry(i, j) - o.entry(i, j))
    }
}

impl Mul<f64> for Sym3 {
    type Output = Sym3;
    fn mul(self, k: f64) -> Sym3 {
        Sym3::from_entries(|i, j| self.entry(i, j) * k)
    }
}

impl Mul<Sym3> for f64 {
    type Output = Sym3;
    fn mul(self, s: Sym3) -> Sym3 {
        s * self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn norm(s: Sym3) -> f64 {
        s.contract(&s).sqrt()
    }

    /// A rotation of diag(values) by the angles (α, β, γ) about z, y, z.
    fn rotated(values: [f64; 3], angles: [f64; 3]) -> Sym3 {
        let r = nalgebra::Rotation3::from_euler_angles(angles[0], angles[1], angles[2]);
        let d = Mat3::from_diagonal(&Vec3::from(values));
        Sym3::sym_part(&(r.matrix() * d * r.matrix().transpose()))
    }

    /// The decomposition reconstructs the tensor to round-off, its eigenvectors are
    /// orthonormal and its eigenvalues sorted, for distinct, repeated and triple eigenvalues,
    /// diagonal tensors and indefinite ones.
    #[test]
    fn eigen_reconstructs_the_tensor() {
        let cases = [
            rotated([3.0, 2.0, 1.0], [0.3, 1.1, -0.7]),
            rotated([5.0, 5.0, 1.0], [0.9, 0.2, 0.4]),
            rotated([2.0, 2.0, 2.0], [0.1, 0.2, 0.3]),
            rotated([-4.0, 0.5, 7.0], [2.0, -1.0, 0.5]),
            Sym3::new(1.0, 0.0, 0.0, 4.0, 0.0, 2.0),
            Sym3::IDENTITY,
            Sym3::new(1.0, 1e-9, 0.0, 1.0 + 1e-12, 0.0, 1.0),
        ];
        for a in cases {
            let e = a.eigen();
            let back = Sym3::from_eigen(&e, e.values);
            let scale = e.values.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            assert!(norm(a - back) < 1e-13 * scale, "{a:?} vs {back:?}");
            let orthogonality = e.rotation.transpose() * e.rotation - Mat3::identity();
            assert!(orthogonality.norm() < 1e-14, "{a:?}");
            assert!(e.values[0] >= e.values[1] && e.values[1] >= e.values[2]);
        }
    }

    /// A conformation stretched along the axes, A = DHD with D = diag(316, 1.7, 0.1) and H
    /// well conditioned (Λ from 1.1e5 to 7e-3), keeps each eigenvalue to a precision relative
    /// to itself. The reference for the smallest is 1/Λ_max(A⁻¹), A⁻¹ = D⁻¹H⁻¹D⁻¹ formed
    /// without cancellation and its largest eigenvalue accurate relative to itself by any
    /// backward-stable method.
    #[test]
    fn small_eigenvalues_keep_their_relative_precision() {
        let d = Mat3::from_diagonal(&Vec3::new(316.0, 1.7, 0.1));
        let h = Mat3::new(1.0, 0.3, 0.1, 0.3, 1.0, 0.2, 0.1, 0.2, 1.0);
        let a = Sym3::sym_part(&(d * h * d));
        let d_inv = d.try_inverse().unwrap();
        let h_inv = h.try_inverse().unwrap();
        let inverse = d_inv * h_inv * d_inv;
        let reference_small = 1.0 / inverse.symmetric_eigen().eigenvalues.max();
        let reference_large = a.to_mat().symmetric_eigen().eigenvalues.max();
        let e = a.eigen();
        let small = (e.values[2] - reference_small).abs() / reference_small;
        let large = (e.values[0] - reference_large).abs() / reference_large;
        assert!(small < 1e-12 && large < 1e-13, "Λ3 {small:e}, Λ1 {large:e}");
    }

    #[test]
    fn log_and_exp_are_inverse_and_keep_spd() {
        let a = rotated([4.0, 1.5, 0.3], [0.2, -0.5, 1.3]);
        let back = a.log().exp();
        assert!(norm(back - a) < 1e-12);
        assert!(back.det() > 0.0 && back.trace() > 0.0);
        assert!(norm(Sym3::IDENTITY.log()) < 1e-15);
        // ln det A = tr ln A.
        assert!((a.det().ln() - a.log().trace()).abs() < 1e-13);
    }
}
