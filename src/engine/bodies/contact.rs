//! What acts between close surfaces besides the resolved flow: a short-range repulsion that
//! keeps discs apart and off the walls, and, optionally, the lubrication force of the gap's
//! squeeze flow where the particles no longer resolve it (Vázquez-Quesada & Ellero 2017,
//! their eqs. (8)–(9): a normal lubrication force below a cut-off gap, and a repulsion for the
//! surfaces' roughness).
//!
//! Two repulsions, both along the line of centres (the wall normal):
//! * [`Repulsion::Quadratic`], F = F₀ (1 − s/ℓ)² for gaps s below the range ℓ. Without
//!   lubrication ℓ must exceed a kernel support: the run stops below one (mirrors of a
//!   gap narrower than the support miss the fluid beyond it), so this force, not the flow,
//!   sets the closest approach (validation pages, *Rigid discs*).
//! * [`Repulsion::Exponential`], the seed's eq. (9), F = F₀ τ e^{−τs}/(1 − e^{−τs}) with a
//!   decay length 1/τ fixed in units of the radius (their nearly hard spheres: 1/τ = 0.001a …
//!   0.05a), so that the contact does not change with δr.
//!
//! [`Lubrication`]: two cylinders of reduced radius R* = R_a R_b/(R_a + R_b) (R* = R at a
//! plane wall) approaching at the relative normal speed w across a gap s ≪ R* resist, per
//! unit length, with F = 3√2 π η (R*/s)^{3/2} w (Reynolds' equation in the gap
//! h = s + x²/2R*: the pressure gradient 12ηwx/h³ integrated twice over the gap). The
//! particles resolve the squeeze flow down to a gap of a few spacings; below the cut-off s_c the force
//! in excess of its value there, f(s) = 3√2 π η R*^{3/2} (s^{−3/2} − s_c^{−3/2}), is added
//! (zero at s_c, so the total is continuous). η is the zero-shear viscosity η_s + η_p, as the
//! seed takes it (a Newtonian gap inside a viscoelastic far field; they discuss why). Only the
//! normal part: the tangential resistance of a 2D gap grows as (R*/s)^{1/2} (the same
//! Reynolds equation with the surfaces sliding), far more slowly, and is left to the resolved
//! flow. The normal part's stiffness, f → ∞ as s → 0, is taken implicitly pairwise
//! ([`Contact::lubricate`]).

use super::Disc;
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;

/// The short-range repulsion's law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Repulsion {
    /// F₀ (1 − s/ℓ)² for s < ℓ.
    Quadratic { strength: f64, range: f64 },
    /// F₀ τ e^{−τs}/(1 − e^{−τs}), `decay` = 1/τ.
    Exponential { strength: f64, decay: f64 },
}

impl Repulsion {
    /// The repulsion at a surface-to-surface `gap`.
    pub fn magnitude(&self, gap: f64) -> f64 {
        match *self {
            Self::Quadratic { strength, range } => {
                if gap >= range {
                    0.0
                } else {
                    strength * (1.0 - gap.max(0.0) / range).powi(2)
                }
            }
            Self::Exponential { strength, decay } => {
                // Finite at an overlap (where the run stops): the force at s = 1/(100τ).
                let x = gap.max(0.01 * decay) / decay;
                strength / decay * (-x).exp() / -(-x).exp_m1()
            }
        }
    }
}

/// The normal lubrication correction below the cut-off gap s_c (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lubrication {
    pub cutoff: f64,
}

impl Lubrication {
    /// f(s) of two surfaces of reduced radius R* in a fluid of viscosity η: the force per unit
    /// length and unit approach speed beyond what the particles resolve (zero from s_c on).
    /// Below 10⁻⁴R* it is held at its value there (a gap the run never reaches intact).
    pub fn resistance(&self, viscosity: f64, reduced_radius: f64, gap: f64) -> f64 {
        if gap >= self.cutoff {
            return 0.0;
        }
        let s = gap.max(1e-4 * reduced_radius);
        reynolds(viscosity, reduced_radius, s) - reynolds(viscosity, reduced_radius, self.cutoff)
    }

    /// The relative normal velocity w^{n+1} of a pair of total mobility Σ inside the cut-off
    /// from the load's w* and the last step's w^n ([`Contact::lubricate`]), with the
    /// correction f that acts.
    fn relax(
        &self,
        w: f64,
        w_old: f64,
        sq: &Squeeze,
        mobility: f64,
        reduced_radius: f64,
        gap: f64,
    ) -> (f64, f64) {
        let f = self.resistance(sq.viscosity, reduced_radius, gap);
        let f_r = reynolds(sq.viscosity, reduced_radius, self.cutoff);
        let k = sq.dt * mobility;
        (f, (w + k * f_r * w_old) / (1.0 + k * (f_r + f)))
    }
}

/// Reynolds' squeeze resistance 3√2π η (R*/s)^{3/2} of a gap s (module docs).
fn reynolds(viscosity: f64, reduced_radius: f64, gap: f64) -> f64 {
    3.0 * 2f64.sqrt() * std::f64::consts::PI * viscosity * (reduced_radius / gap).powf(1.5)
}

/// `[scene.contact]`: the repulsion and, optionally, the lubrication correction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    pub repulsion: Repulsion,
    pub lubrication: Option<Lubrication>,
}

/// What the implicit lubrication needs of each disc and of the step.
#[derive(Clone, Copy, Debug)]
pub struct Squeeze<'a> {
    /// 1/M per disc: the inverse of its translational inertia in the coupling
    /// (m + m_a + δt k_V), 0 for a disc whose translation is prescribed.
    pub mobility: &'a [f64],
    /// Each disc's velocity at the start of the step, V^n.
    pub previous: &'a [Vec2],
    /// η0.
    pub viscosity: f64,
    pub dt: f64,
}

impl Contact {
    /// The repulsion at a surface-to-surface `gap`.
    pub fn magnitude(&self, gap: f64) -> f64 {
        self.repulsion.magnitude(gap)
    }

    /// Whether the model is meant for gaps narrower than a kernel support: with lubrication,
    /// or with the exponential repulsion. The quadratic repulsion alone keeps the surfaces
    /// a support apart.
    pub fn closes_gaps(&self) -> bool {
        !matches!(
            (self.repulsion, self.lubrication),
            (Repulsion::Quadratic { .. }, None)
        )
    }

    /// The smallest gap the run accepts: one kernel `support` unless the model
    /// [`Self::closes_gaps`] (mirrors of a narrower gap miss the fluid beyond it); none then
    /// (an overlap stops it).
    pub fn smallest_gap(&self, support: f64) -> f64 {
        if self.closes_gaps() {
            0.0
        } else {
            support
        }
    }

    /// The repulsion on each disc from the others (nearest periodic images) and from the
    /// walls bounding the non-periodic axes of `domain`.
    pub fn forces(&self, discs: &[Disc], domain: &Domain) -> Vec<Vec2> {
        let mut out = vec![Vec2::zeros(); discs.len()];
        for (k, a) in discs.iter().enumerate() {
            for (m, b) in discs.iter().enumerate().skip(k + 1) {
                let d = domain.min_image(a.circle.centre - b.circle.centre);
                let (gap, _) = pair_gap(a, b, domain);
                let f = self.magnitude(gap) * d / d.norm().max(f64::MIN_POSITIVE);
                out[k] += f;
                out[m] -= f;
            }
            for (gap, normal) in wall_gaps(a, domain) {
                out[k] += self.magnitude(gap) * normal;
            }
        }
        out
    }

    /// The lubrication correction, implicit in the relative normal velocity of each close
    /// pair (and of each disc and a wall, at rest along its normal); nothing without
    /// lubrication. With 1/M the discs' mobilities, Σ = 1/M_a + 1/M_b, w* the relative
    /// velocity the load has given and w^n the last step's,
    ///
    ///   w^{n+1} = (w* + δt Σ f_r w^n) / (1 + δt Σ (f_r + f)),
    ///
    /// the change shared in proportion to the mobilities, so momentum is conserved and no
    /// step, however stiff f, reverses the approach. f_r is the squeeze resistance the
    /// particles resolve, f_r = 3√2π η R*^{3/2} s_c^{−3/2} inside the cut-off: like the
    /// coupling's k_V ([`super`]), it stands for the load's response within the step to the
    /// discs' own motion along the gap, the pressure's, instantaneous in a gap of a few
    /// spacings; it vanishes at a steady state (w^{n+1} = w^n = w*). It was added for the
    /// normal bounce of a disc settling onto a wall without lubrication (R/δr = 8, s ≈ 0.1R);
    /// the breakdowns measured with it were tangential, and were cured by the coupling's
    /// stiffening ([`super::Coupling::stiffening`]), which scales k_V along the normal too,
    /// so whether f_r is still needed beside it was not isolated. One Gauss–Seidel sweep
    /// over the pairs, then the walls (exact for a single pair). Returns each disc's
    /// lubrication force f w^{n+1} (for the record).
    pub fn lubricate(&self, discs: &mut [Disc], sq: &Squeeze, domain: &Domain) -> Vec<Vec2> {
        let mut out = vec![Vec2::zeros(); discs.len()];
        let Some(lub) = self.lubrication else {
            return out;
        };
        let n = discs.len();
        for k in 0..n {
            for m in k + 1..n {
                let (a, b) = (&discs[k], &discs[m]);
                let (gap, e) = pair_gap(a, b, domain);
                let mobility = sq.mobility[k] + sq.mobility[m];
                if gap >= lub.cutoff || mobility == 0.0 {
                    continue;
                }
                let (ra, rb) = (a.circle.radius, b.circle.radius);
                let reduced = ra * rb / (ra + rb);
                let w = (a.velocity - b.velocity).dot(&e);
                let w_old = (sq.previous[k] - sq.previous[m]).dot(&e);
                let (f, w_new) = lub.relax(w, w_old, sq, mobility, reduced, gap);
                let dw = (w_new - w) * e;
                discs[k].velocity += dw * (sq.mobility[k] / mobility);
                discs[m].velocity -= dw * (sq.mobility[m] / mobility);
                out[k] -= f * w_new * e;
                out[m] += f * w_new * e;
            }
        }
        for (k, disc) in discs.iter_mut().enumerate() {
            for (gap, normal) in wall_gaps(disc, domain) {
                if gap >= lub.cutoff || sq.mobility[k] == 0.0 {
                    continue;
                }
                let w = disc.velocity.dot(&normal);
                let w_old = sq.previous[k].dot(&normal);
                let mobility = sq.mobility[k];
                let (f, w_new) = lub.relax(w, w_old, sq, mobility, disc.circle.radius, gap);
                disc.velocity += (w_new - w) * normal;
                out[k] -= f * w_new * normal;
            }
        }
        out
    }
}

/// Disc `k`'s narrowest gap to another disc (nearest periodic image) or a wall of `domain`.
pub fn narrowest_gap(discs: &[Disc], k: usize, domain: &Domain) -> f64 {
    let a = &discs[k];
    let to_discs = discs
        .iter()
        .enumerate()
        .filter(|&(m, _)| m != k)
        .map(|(_, b)| pair_gap(a, b, domain).0);
    let to_walls = wall_gaps(a, domain).into_iter().map(|(gap, _)| gap);
    to_discs.chain(to_walls).fold(f64::INFINITY, f64::min)
}

/// The gap between discs `a` and `b` (nearest periodic images) and the unit vector from b
/// to a.
fn pair_gap(a: &Disc, b: &Disc, domain: &Domain) -> (f64, Vec2) {
    let d = domain.min_image(a.circle.centre - b.circle.centre);
    let distance = d.norm();
    let gap = distance - a.circle.radius - b.circle.radius;
    (gap, d / distance.max(f64::MIN_POSITIVE))
}

/// The gaps between a disc and the walls bounding the non-periodic axes of `domain`, each
/// with the wall's normal into the fluid.
fn wall_gaps(disc: &Disc, domain: &Domain) -> Vec<(f64, Vec2)> {
    let (c, r) = (disc.circle.centre, disc.circle.radius);
    let mut out = Vec::new();
    for axis in (0..2).filter(|&axis| !domain.periodic[axis]) {
        let mut normal = Vec2::zeros();
        normal[axis] = 1.0;
        out.push((c[axis] - r - domain.min[axis], normal));
        out.push((domain.max[axis] - c[axis] - r, -normal));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::bodies::Motion;
    use crate::engine::boundary::Circle;

    fn disc(x: f64, y: f64) -> Disc {
        Disc {
            circle: Circle {
                centre: Vec2::new(x, y),
                radius: 1.0,
            },
            velocity: Vec2::zeros(),
            spin: 0.0,
            density: 1.0,
            motion: Motion::Free,
            acceleration: Vec2::zeros(),
            coupling_added_mass: 1.0,
        }
    }

    fn domain() -> Domain {
        Domain {
            min: Vec2::zeros(),
            max: Vec2::new(10.0, 8.0),
            periodic: [true, false],
        }
    }

    fn quadratic(strength: f64, range: f64) -> Contact {
        Contact {
            repulsion: Repulsion::Quadratic { strength, range },
            lubrication: None,
        }
    }

    /// Equal and opposite along the line of centres (across the periodic end too), zero beyond
    /// the range, pushing away from a wall.
    #[test]
    fn repulsion_is_pairwise_and_short_ranged() {
        let contact = quadratic(2.0, 0.5);
        // Gap 0.25 across x = 0: half the range, a quarter of the strength.
        let f = contact.forces(&[disc(0.5, 4.0), disc(8.25, 4.0)], &domain());
        assert!((f[0].x - 0.5).abs() < 1e-12 && f[0].y == 0.0, "{f:?}");
        assert_eq!(f[0], -f[1]);
        let far = contact.forces(&[disc(3.0, 4.0), disc(6.0, 4.0)], &domain());
        assert_eq!(far, vec![Vec2::zeros(); 2]);
        // 0.1 above the floor: pushed up by 2(1 − 0.2)².
        let wall = contact.forces(&[disc(5.0, 1.1)], &domain());
        assert!((wall[0].y - 2.0 * 0.8f64.powi(2)).abs() < 1e-12);
        assert_eq!(contact.smallest_gap(0.3), 0.3);
    }

    /// The seed's eq. (9): F₀/s at gaps well inside 1/τ, F₀τ e^{−τs} well beyond.
    #[test]
    fn the_exponential_repulsion_has_the_seeds_limits() {
        let r = Repulsion::Exponential {
            strength: 2.0,
            decay: 0.01,
        };
        let near = r.magnitude(1e-4);
        assert!((near * 1e-4 / 2.0 - 1.0).abs() < 0.01, "{near}");
        let far = r.magnitude(0.1);
        assert!((far / (200.0 * (-10f64).exp()) - 1.0).abs() < 1e-4, "{far}");
        let c = Contact {
            repulsion: r,
            lubrication: None,
        };
        assert_eq!(c.smallest_gap(0.3), 0.0);
    }

    /// f(s) is Reynolds' 3√2π η (R*/s)^{3/2} less its value at the cut-off, with R* = R/2 for
    /// two equal discs, and that law is the gap's: the lubrication pressure of h = s + x²/2R*,
    /// integrated numerically here, carries the same force.
    #[test]
    fn the_lubrication_resistance_is_reynolds_law() {
        let lub = Lubrication { cutoff: 0.5 };
        let (eta, s) = (3.0, 0.01);
        let law = |rr: f64| 3.0 * 2f64.sqrt() * std::f64::consts::PI * eta * rr.powf(1.5);
        let plane = lub.resistance(eta, 1.0, s);
        assert!((plane - law(1.0) * (s.powf(-1.5) - 0.5f64.powf(-1.5))).abs() < 1e-9 * plane);
        let pair = lub.resistance(eta, 0.5, s);
        assert!((pair - law(0.5) * (s.powf(-1.5) - 0.5f64.powf(-1.5))).abs() < 1e-9 * pair);
        assert_eq!(lub.resistance(eta, 1.0, 0.5), 0.0);
        // F = ∫ 12ηw x²/h³ dx (by parts from dp/dx = 12ηwx/h³), midpoint rule over ±400√(2R*s).
        let (rr, s) = (0.5f64, 1e-3f64);
        let half = 400.0 * (2.0 * rr * s).sqrt();
        let n = 400_000;
        let dx = 2.0 * half / n as f64;
        let force: f64 = (0..n)
            .map(|i| {
                let x = -half + (i as f64 + 0.5) * dx;
                12.0 * eta * x * x / (s + x * x / (2.0 * rr)).powi(3) * dx
            })
            .sum();
        // The tails beyond ±400√(2R*s) hold 3/(π 400³)·(…) ≈ 1e-8 of it.
        let reynolds = law(rr) * s.powf(-1.5);
        assert!((force / reynolds - 1.0).abs() < 1e-4, "{force} {reynolds}");
    }

    /// The implicit step: an approaching pair keeps its momentum, its relative normal speed
    /// relaxes as (w* + δt Σ f_r w^n)/(1 + δt Σ (f_r + f)) and never reverses, the tangential
    /// part is untouched; a disc falling on a wall is slowed alike, and a prescribed disc
    /// (mobility 0) takes none of the change. At a steady approach (w* = w^n) without the
    /// correction (f = 0, at the cut-off) nothing changes.
    #[test]
    fn the_lubrication_step_conserves_momentum_and_never_reverses() {
        let contact = Contact {
            repulsion: Repulsion::Exponential {
                strength: 1.0,
                decay: 0.01,
            },
            lubrication: Some(Lubrication { cutoff: 0.5 }),
        };
        let mut pair = [disc(3.0, 4.0), disc(5.05, 4.0)];
        pair[0].velocity = Vec2::new(1.0, 0.3);
        pair[1].velocity = Vec2::new(-0.5, 0.0);
        let mobility = [1.0, 0.5];
        let previous = [Vec2::new(0.9, 0.3), Vec2::new(-0.5, 0.0)];
        let sq = Squeeze {
            mobility: &mobility,
            previous: &previous,
            viscosity: 1.0,
            dt: 0.1,
        };
        let momentum = |d: &[Disc]| d[0].velocity / mobility[0] + d[1].velocity / mobility[1];
        let before = momentum(&pair);
        let f = contact.lubricate(&mut pair, &sq, &domain());
        assert!((momentum(&pair) - before).norm() < 1e-12);
        let fr = Lubrication { cutoff: 0.5 }.resistance(1.0, 0.5, 0.05);
        let f_r = reynolds(1.0, 0.5, 0.5);
        let k = 0.1 * 1.5;
        let expected = (1.5 + k * f_r * 1.4) / (1.0 + k * (f_r + fr));
        let w = pair[0].velocity.x - pair[1].velocity.x;
        assert!((w - expected).abs() < 1e-12 && w > 0.0, "{w} {expected}");
        assert_eq!(pair[0].velocity.y, 0.3);
        assert!((f[0].x + fr * w).abs() < 1e-9 && f[1] == -f[0]);
        let mut steady = [disc(3.0, 4.0), disc(5.0 + 1.0, 4.0)];
        steady[0].velocity = Vec2::new(0.25, 0.0);
        steady[0].circle.centre.x = 3.5 + 1e-9; // a gap just inside the cut-off
        let at_cutoff = [steady[0].velocity, steady[1].velocity];
        let sq_steady = Squeeze {
            previous: &at_cutoff,
            ..sq
        };
        contact.lubricate(&mut steady, &sq_steady, &domain());
        assert!(
            (steady[0].velocity.x - 0.25).abs() < 1e-6,
            "{:?}",
            steady[0].velocity
        );
        let mut falling = [disc(5.0, 1.02)];
        falling[0].velocity = Vec2::new(0.2, -1.0);
        let fell = [falling[0].velocity];
        let one = [1.0];
        let sq_wall = Squeeze {
            mobility: &one,
            previous: &fell,
            ..sq
        };
        contact.lubricate(&mut falling, &sq_wall, &domain());
        // (1 + δt f_r)/(1 + δt (f_r + f)) = 4.77/472.4 of the approach is left.
        let v = falling[0].velocity;
        assert!(v.y < 0.0 && v.y > -0.02 && v.x == 0.2, "{v:?}");
        let mut held = [disc(3.0, 4.0), disc(5.05, 4.0)];
        held[0].velocity = Vec2::new(1.0, 0.0);
        let fixed = [0.0, 0.0];
        let sq = Squeeze {
            mobility: &fixed,
            ..sq
        };
        contact.lubricate(&mut held, &sq, &domain());
        assert_eq!(held[0].velocity.x, 1.0);
    }
}
