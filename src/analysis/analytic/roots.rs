//! A robust scalar root finder: Brent's method (inverse quadratic interpolation, secant and
//! bisection, with a guaranteed bracket), plus bracket expansion.

/// Finds x in [a, b] with f(x) = 0, given f(a) and f(b) of opposite signs (or one zero).
/// Converges to |b − a| ≤ 2ε|x| + tolerance.
pub fn brent(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    tolerance: f64,
) -> Result<f64, String> {
    let (mut fa, mut fb) = (f(a), f(b));
    if fa == 0.0 {
        return Ok(a);
    }
    if fb == 0.0 {
        return Ok(b);
    }
    if !(fa.is_finite() && fb.is_finite()) || fa.signum() == fb.signum() {
        return Err(format!("no sign change in [{a}, {b}]: f = {fa}, {fb}"));
    }
    let (mut c, mut fc) = (a, fa);
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..200 {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * tolerance;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return Ok(b);
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                (2.0 * m * s, 1.0 - s)
            } else {
                let q = fa / fc;
                let r = fb / fc;
                (
                    s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0)),
                    (q - 1.0) * (r - 1.0) * (s - 1.0),
                )
            };
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
        if !fb.is_finite() {
            return Err(format!("f({b}) is not finite"));
        }
    }
    Err("Brent's method did not converge in 200 iterations".into())
}

/// Doubles `hi` (from `lo`) until f changes sign, then solves by [`brent`]. For f increasing
/// from f(lo) ≤ 0.
pub fn solve_increasing(
    f: impl Fn(f64) -> f64,
    lo: f64,
    mut hi: f64,
    tolerance: f64,
) -> Result<f64, String> {
    let f_lo = f(lo);
    if f_lo == 0.0 {
        return Ok(lo);
    }
    for _ in 0..200 {
        let f_hi = f(hi);
        if f_hi.is_finite() && f_hi.signum() != f_lo.signum() {
            return brent(&f, lo, hi, tolerance);
        }
        hi = lo + 2.0 * (hi - lo);
    }
    Err(format!("no root found above {lo}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots_of_smooth_and_awkward_functions() {
        let r = brent(|x| x * x - 2.0, 0.0, 2.0, 1e-15).unwrap();
        assert!((r - 2f64.sqrt()).abs() < 1e-14);
        let r = brent(|x| x.powi(3) - x - 1.0, 1.0, 2.0, 1e-15).unwrap();
        assert!((r.powi(3) - r - 1.0).abs() < 1e-13);
        // A function flat near its root.
        let r = brent(|x: f64| (x - 0.3).powi(5), 0.0, 1.0, 1e-12).unwrap();
        assert!((r - 0.3).abs() < 1e-2);
        let r = solve_increasing(|x| x.ln() - 5.0, 1.0, 2.0, 1e-14).unwrap();
        assert!((r - 5f64.exp()).abs() < 1e-10);
        assert!(brent(|x| x * x + 1.0, -1.0, 1.0, 1e-12).is_err());
    }
}
