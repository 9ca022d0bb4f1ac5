//! Creeping (Stokes) flow in the lid-driven unit cavity with the regularised lid
//! u_w = 16U x²(1 − x)²: the stream function ψ (u = ∂ψ/∂y, v = −∂ψ/∂x) solves ∇⁴ψ = 0 with
//! ψ = 0 on the walls, ∂ψ/∂n = 0 on the three walls at rest and ∂ψ/∂y = u_w on the lid.
//!
//! No closed form exists; this is the classic second-order finite-difference solution: the
//! 13-point biharmonic stencil on nodes (ih, jh), h = L/n, the normal-derivative conditions
//! through ghost nodes (ψ_{−1} = ψ_1 behind a wall at rest, ψ_{n+1} = ψ_{n−1} + 2h u_w behind
//! the lid), solved by sparse LU. The reference of the cavity probe for a Newtonian fluid at
//! small Re (its O(Re) inertia aside). Its own error: `tests` below show second order, and
//! n = 256 moves ψ_min by 3e-6 from n = 128.

use crate::engine::math::Vec2;
use rheosph_solver::{Solver, SolverOptions, Strategy};

/// ψ on the (n + 1)² nodes of the unit square, for a lid speed U = 1.
#[derive(Clone, Debug)]
pub struct StokesCavity {
    pub n: usize,
    /// ψ at node (i, j), index j(n + 1) + i.
    pub psi: Vec<f64>,
}

/// The regularised lid's speed at x for U = 1.
pub fn lid(x: f64) -> f64 {
    16.0 * x * x * (1.0 - x) * (1.0 - x)
}

impl StokesCavity {
    /// Solves on n × n cells (n even and ≥ 8).
    pub fn solve(n: usize) -> Result<Self, String> {
        let m = n - 1; // interior nodes per side
        let h = 1.0 / n as f64;
        let index = |i: usize, j: usize| (j - 1) * m + (i - 1);
        let mut tri = sprs::TriMat::new((m * m, m * m));
        let mut rhs = vec![0.0; m * m];
        for j in 1..n {
            for i in 1..n {
                let row = index(i, j);
                let mut add = |di: i64, dj: i64, c: f64| {
                    let (a, b) = (i as i64 + di, j as i64 + dj);
                    let (a, b, lid_term) = ghost(a, b, n as i64, h);
                    rhs[row] -= c * lid_term;
                    if a >= 1 && a < n as i64 && b >= 1 && b < n as i64 {
                        tri.add_triplet(row, index(a as usize, b as usize), c);
                    }
                };
                add(0, 0, 20.0);
                for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                    add(di, dj, -8.0);
                    add(2 * di, 2 * dj, 1.0);
                }
                for (di, dj) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
                    add(di, dj, 2.0);
                }
            }
        }
        let a = tri.to_csr();
        let mut x = vec![0.0; m * m];
        let options = SolverOptions {
            strategy: Strategy::Direct,
            relative_tolerance: 1e-12,
            ..Default::default()
        };
        Solver::new()
            .solve(&a, &rhs, &mut x, &options)
            .map_err(|e| format!("the Stokes cavity's LU failed: {e:?}"))?;
        let mut psi = vec![0.0; (n + 1) * (n + 1)];
        for j in 1..n {
            for i in 1..n {
                psi[j * (n + 1) + i] = x[index(i, j)];
            }
        }
        Ok(Self { n, psi })
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.psi[j * (self.n + 1) + i]
    }

    /// u = ∂ψ/∂y at node (i, j) (central differences; the lid's and walls' values on them).
    pub fn u(&self, i: usize, j: usize) -> f64 {
        let (n, h) = (self.n, 1.0 / self.n as f64);
        match j {
            0 => 0.0,
            j if j == n => lid(i as f64 * h),
            _ => (self.at(i, j + 1) - self.at(i, j - 1)) / (2.0 * h),
        }
    }

    /// v = −∂ψ/∂x at node (i, j).
    pub fn v(&self, i: usize, j: usize) -> f64 {
        let (n, h) = (self.n, 1.0 / self.n as f64);
        if i == 0 || i == n || j == 0 || j == n {
            return 0.0;
        }
        -(self.at(i + 1, j) - self.at(i - 1, j)) / (2.0 * h)
    }

    /// The minimum of ψ and where it is: the smallest node refined by the quadratic through
    /// its neighbours along each axis.
    pub fn minimum(&self) -> (f64, Vec2) {
        let n = self.n;
        let h = 1.0 / n as f64;
        let (mut best, mut at) = (f64::INFINITY, (1, 1));
        for j in 1..n {
            for i in 1..n {
                if self.at(i, j) < best {
                    best = self.at(i, j);
                    at = (i, j);
                }
            }
        }
        let (i, j) = at;
        let f = |a: f64, b: f64, c: f64| parabola_vertex(a, b, c);
        let (dx, fx) = f(self.at(i - 1, j), best, self.at(i + 1, j));
        let (dy, fy) = f(self.at(i, j - 1), best, self.at(i, j + 1));
        let value = best + (fx - best) + (fy - best);
        (value, Vec2::new((i as f64 + dx) * h, (j as f64 + dy) * h))
    }
}

/// The vertex of the parabola through (−1, a), (0, b), (1, c): its offset and value.
pub fn parabola_vertex(a: f64, b: f64, c: f64) -> (f64, f64) {
    let curvature = a - 2.0 * b + c;
    if curvature <= 0.0 {
        return (0.0, b);
    }
    let d = 0.5 * (a - c) / curvature;
    (d, b - 0.25 * (a - c) * d)
}

/// A node index beyond the square mapped to its interior image, with the lid's term: the
/// ghost's value is ψ(image) + lid_term.
fn ghost(i: i64, j: i64, n: i64, h: f64) -> (i64, i64, f64) {
    let (mut i, mut j, mut extra) = (i, j, 0.0);
    if i < 0 {
        i = -i;
    } else if i > n {
        i = 2 * n - i;
    }
    if j < 0 {
        j = -j;
    } else if j > n {
        j = 2 * n - j;
        extra = 2.0 * h * lid(i as f64 * h);
    }
    (i, j, extra)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vortex sits on x = 1/2 (the lid and the walls are symmetric about it), and ψ_min
    /// converges at second order: the change from n = 32 to 64 is about 4× the change from
    /// 64 to 128.
    #[test]
    fn the_stokes_cavity_is_symmetric_and_converges_at_second_order() {
        let s: Vec<(f64, Vec2)> = [32, 64, 128]
            .iter()
            .map(|&n| StokesCavity::solve(n).unwrap().minimum())
            .collect();
        for (_, c) in &s {
            assert!((c.x - 0.5).abs() < 1e-9, "{c:?}");
        }
        let ratio = (s[0].0 - s[1].0) / (s[1].0 - s[2].0);
        assert!((3.5..4.5).contains(&ratio), "{ratio} {s:?}");
    }
}
