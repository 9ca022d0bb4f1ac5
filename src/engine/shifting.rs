//! Fickian particle shifting (King & Lind §III E, eqs. (40)–(42); after Lind et al. 2012).
//!
//! Internal flows use `u_ps = −D ∇C` with D = h²/(4δt) (first form of (41)) and
//!
//! ```text
//!     ∇C_i = Σ_j (1 + ¼ (W_ij / W(δr))⁴) ∇_i W_ij δV,        eq. (42) without the α_Ak term,
//! ```
//!
//! Sign: with ∇_i W_ij = W'(r) r_ij/r (pointing from i towards j, since W' < 0), ∇C points up
//! the particle concentration, and particles must move *down* it, so u_ps = −D∇C. (The paper
//! writes D∇C with its own sign convention for ∇W_ij; the unit test
//! `displaced_particle_returns_to_its_lattice_site` fixes ours.) The normalising kernel value
//! in the anti-clumping factor is W at the initial spacing δr, as in Lind et al. (2012); the
//! paper's "W_ii" read as W(0) would make the factor at most 1.25 and the term inert.
//!
//! Free-surface flows use the second form of (41),
//! `D_i = 4h (|u_i| + 0.2 max|u| exp(−5|u_i|/max|u|))`, which keeps particles moving apart
//! at stagnation points, shift FS particles only along the surface (`(m·∇C) m` with m ⊥ n,
//! (40)), and may add to ∇C of internal particles the repulsive term of (42)–(44),
//! `α_Ak Σ_j Q(q) r̂_ij` with α_Ak = 64/(πh) and q = |r_ij|/h. In our sign
//! convention (u_ps = −D∇C) a push of i away from j enters ∇C as −Q r̂_ij.

use crate::engine::boundary::Wall;
use crate::engine::dimension::{Dim, Dimension, Vector};
use crate::engine::frame::Frame;
use crate::engine::free_surface::FreeSurface;
use crate::engine::kernel::QuinticSpline;
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use rayon::prelude::*;

/// Which shift velocity u_ps step 2 computes: chosen once, at set-up, from the frame, the
/// scheme's shifting switch and whether the scene has free surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShiftRule {
    /// Fixed particles: u_ps = −u, so that particles move with u + u_ps = 0.
    Eulerian,
    /// Lagrangian without shifting: u_ps = 0.
    Off,
    /// Internal flows: u_ps = −(h²/4δt)∇C, (40)–(42).
    Internal,
    /// Free-surface flows: the second form of (41), tangential shifting in the surface
    /// region (40), optionally the repulsive term (42)–(44), and no shift into a wall.
    FreeSurface { repulsion: bool },
}

impl ShiftRule {
    pub fn new(frame: Frame, shifting: bool, free_surface: bool, repulsion: bool) -> Self {
        match (frame, shifting, free_surface) {
            (Frame::Eulerian, _, _) => ShiftRule::Eulerian,
            (Frame::Lagrangian, false, _) => ShiftRule::Off,
            (Frame::Lagrangian, true, false) => ShiftRule::Internal,
            (Frame::Lagrangian, true, true) => ShiftRule::FreeSurface { repulsion },
        }
    }
}

/// What the shift velocity depends on besides the velocity.
pub struct ShiftInputs<'a, const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub list: &'a NeighbourList<D>,
    pub sums: &'a KernelSums<D>,
    pub kernel: &'a QuinticSpline,
    pub spacing: f64,
    pub dt: f64,
    /// Fluid positions r* (for the distance to walls).
    pub points: &'a [Vector<D>],
    pub walls: &'a [Wall<D>],
    /// The free surface of this step (free-surface scenes).
    pub surface: Option<&'a FreeSurface<D>>,
}

/// Step 2's shift velocity: the rule and its buffers.
#[derive(Clone, Debug)]
pub struct Shifting<const D: usize = 2> {
    pub rule: ShiftRule,
    /// Internal flows: no shift into a wall within this reach (set where gaps narrower than
    /// the kernel support are allowed: discs under lubrication, [`Self::keep_off_walls`]).
    keep_off: Option<f64>,
    grad_c: Vec<Vector<D>>,
    region: Vec<bool>,
}

impl<const D: usize> Shifting<D>
where
    Dim<D>: Dimension<D>,
{
    pub fn new(rule: ShiftRule) -> Self {
        Self {
            rule,
            keep_off: None,
            grad_c: Vec::new(),
            region: Vec::new(),
        }
    }

    /// Internal shifting stops moving particles towards a wall within `reach` of it. In a gap
    /// narrower than the kernel support the mirrors of one wall miss the fluid beyond the
    /// other, ∇C points away from the nearer wall's far side, and the shift walks the
    /// particles left in the gap through it. Measured: a disc settling onto the floor under
    /// lubrication (R/δr = 8, gap 0.57δr) lost the particle under it through the floor, at
    /// ~0.004 a step with its velocity pointing up (validation pages, *Rigid discs*).
    pub fn keep_off_walls(mut self, reach: f64) -> Self {
        self.keep_off = Some(reach);
        self
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.grad_c) + crate::engine::vec_bytes(&self.region)
    }

    /// u_ps of every fluid particle from u^n (`velocity`).
    pub fn compute(
        &mut self,
        inputs: &ShiftInputs<D>,
        velocity: &[Vector<D>],
        u_ps: &mut [Vector<D>],
    ) {
        let ShiftInputs {
            list, sums, kernel, ..
        } = *inputs;
        let n = velocity.len();
        match self.rule {
            ShiftRule::Eulerian => u_ps
                .par_iter_mut()
                .zip(velocity.par_iter())
                .for_each(|(s, u)| *s = -u),
            ShiftRule::Off => u_ps.iter_mut().for_each(|s| *s = Vector::<D>::zeros()),
            ShiftRule::Internal => {
                self.grad_c.resize(n, Vector::<D>::zeros());
                concentration_gradient(list, sums, kernel, inputs.spacing, &mut self.grad_c);
                internal_shifting_velocity(&self.grad_c, kernel.h(), inputs.dt, u_ps);
                if let Some(reach) = self.keep_off {
                    self.region.resize(n, true);
                    keep_off_walls(&inputs.points[..n], inputs.walls, &self.region, reach, u_ps);
                }
            }
            ShiftRule::FreeSurface { repulsion } => {
                let surface = inputs
                    .surface
                    .expect("free-surface shifting runs with the free-surface stage");
                self.grad_c.resize(n, Vector::<D>::zeros());
                concentration_gradient(list, sums, kernel, inputs.spacing, &mut self.grad_c);
                if repulsion {
                    add_repulsion(list, kernel, &surface.on_surface, &mut self.grad_c);
                }
                surface.region(&mut self.region);
                free_surface_shifting_velocity(
                    &self.grad_c,
                    velocity,
                    &self.region,
                    &surface.normal,
                    kernel.h(),
                    inputs.dt,
                    u_ps,
                );
                keep_off_walls(
                    &inputs.points[..n],
                    inputs.walls,
                    &self.region,
                    kernel.support(),
                    u_ps,
                );
            }
        }
    }
}

/// Exponent and weight of the anti-clumping factor in eq. (42).
const CLUMP_WEIGHT: f64 = 0.25;

/// Concentration gradient ∇C_i of eq. (42) (internal flows: no repulsive α_Ak term).
pub fn concentration_gradient<const D: usize>(
    list: &NeighbourList<D>,
    sums: &KernelSums<D>,
    kernel: &QuinticSpline,
    dr: f64,
    out: &mut [Vector<D>],
) where
    Dim<D>: Dimension<D>,
{
    let w_ref = kernel.value(dr);
    let dv = sums.dv;
    out.par_iter_mut().enumerate().for_each(|(i, g)| {
        let mut acc = Vector::<D>::zeros();
        for k in list.range(i) {
            let ratio = sums.value[k] / w_ref;
            let r2 = ratio * ratio;
            acc += (1.0 + CLUMP_WEIGHT * r2 * r2) * sums.grad_w(list, k);
        }
        *g = acc * dv;
    });
}

/// Shifting velocity for internal flows, u_ps = −(h²/(4δt)) ∇C, eqs. (40)–(41).
pub fn internal_shifting_velocity<const D: usize>(
    grad_c: &[Vector<D>],
    h: f64,
    dt: f64,
    out: &mut [Vector<D>],
) {
    let diffusivity = h * h / (4.0 * dt);
    out.par_iter_mut()
        .zip(grad_c.par_iter())
        .for_each(|(u, g)| *u = -diffusivity * g);
}

/// Q(q) of eq. (43).
fn repulsion_weight(q: f64) -> f64 {
    if q < 0.5 {
        1.0 / 32.0
    } else if q < 1.0 {
        let a = q * (1.0 - q);
        a * a * a
    } else {
        0.0
    }
}

/// Adds the repulsive term of (42), weighted by α_Ak of (44), to ∇C of the particles not on
/// the free surface.
pub fn add_repulsion<const D: usize>(
    list: &NeighbourList<D>,
    kernel: &QuinticSpline,
    on_surface: &[bool],
    grad_c: &mut [Vector<D>],
) {
    let alpha = 64.0 / (std::f64::consts::PI * kernel.h());
    // q = r/h: the term reaches nearest neighbours only (h = 1.3δr), where Q falls with
    // distance and so pushes hardest on the closest. Read as q = r/(kernel support), every
    // neighbour within two spacings would sit on the flat Q = 1/32 and the term would only
    // count neighbours: measured on a drop in free fall (W/δr = 40), interior shifting
    // speeds of 4–5 U that never settle, against < 0.01 U without the term.
    let support = kernel.h();
    grad_c.par_iter_mut().enumerate().for_each(|(i, g)| {
        if on_surface[i] {
            return;
        }
        let mut acc = Vector::<D>::zeros();
        for k in list.range(i) {
            let r = list.rij[k];
            let d = r.norm();
            if d > 0.0 {
                acc -= repulsion_weight(d / support) * r / d;
            }
        }
        *g += alpha * acc;
    });
}

/// Shifting velocity of free-surface flows, eqs. (40)–(41) (second form of D): −D∇C inside,
/// −D(m·∇C)m in the surface region (m the unit tangent, ⟂ to the outward normal).
///
/// The surface region is FS and the NS particles with a well-defined normal (see
/// [`crate::engine::free_surface::FreeSurface::region`]), not FS alone as (40) reads: the truncated support
/// of an NS particle gives ∇C pointing inwards, so −D∇C pushes it towards the surface, where
/// the particles pack. Measured on the Oldroyd-B drop at W/δr = 40 (t* = 3): area drift 5.6 %
/// with FS alone, 1.9 % with the region, as Lind et al. (2012) restrict the normal shift near
/// the surface.
///
/// D is capped at the internal form h²/(4δt): explicit shifting is a diffusion of particle
/// concentration, stable only for Dδt/h² of order 1/4, and the second form of (41) gives 0.8
/// at δt = 0.2h/|u|. Uncapped, the interior of a drop in free fall (W/δr = 40) had shifting
/// speeds growing 3.2 → 14 → 24 U over its first three steps.
pub fn free_surface_shifting_velocity<const D: usize>(
    grad_c: &[Vector<D>],
    velocity: &[Vector<D>],
    surface_region: &[bool],
    normal: &[Vector<D>],
    h: f64,
    dt: f64,
    out: &mut [Vector<D>],
) where
    Dim<D>: Dimension<D>,
{
    let cap = h * h / (4.0 * dt);
    let max_speed = velocity
        .par_iter()
        .map(|u| u.norm())
        .reduce(|| 0.0, f64::max);
    out.par_iter_mut().enumerate().for_each(|(i, u_s)| {
        let speed = velocity[i].norm();
        let floor = if max_speed > 0.0 {
            0.2 * max_speed * (-5.0 * speed / max_speed).exp()
        } else {
            0.0
        };
        let diffusivity = (4.0 * h * (speed + floor)).min(cap);
        *u_s = if surface_region[i] {
            Dim::<D>::tangential(-diffusivity, &grad_c[i], &normal[i])
        } else {
            -diffusivity * grad_c[i]
        };
    });
}

/// Removes the part of u_ps that points into a wall from surface-region particles within
/// `reach` of it. At a contact line the free surface meets the plate and its tangent points
/// into it, so the tangential shift of (40) walks FS particles through the plate, which no
/// pressure resists (their PPE rows are Dirichlet). Measured: the Oldroyd-B drop at De = 10
/// (W/δr = 40) lost a contact-line particle through the plate at t* = 7.9, and at β ≤ 0.05 at
/// impact.
pub fn keep_off_walls<const D: usize>(
    points: &[Vector<D>],
    walls: &[Wall<D>],
    region: &[bool],
    reach: f64,
    u_ps: &mut [Vector<D>],
) where
    Dim<D>: Dimension<D>,
{
    u_ps.par_iter_mut().enumerate().for_each(|(i, u)| {
        if !region[i] {
            return;
        }
        let p = points[i];
        for wall in walls {
            let d = wall.shape.distance(&p);
            if d > 0.0 && d < reach {
                let into_fluid = (p - wall.shape.reflect(&p)) / (2.0 * d);
                let toward = u.dot(&into_fluid);
                if toward < 0.0 {
                    *u -= toward * into_fluid;
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Vec2;
    use crate::engine::neighbours::{Domain, NeighbourSearch};

    /// A surface-region particle near a plate keeps the part of its shift along the plate and
    /// away from it, and loses the part into it; particles outside the region or beyond the
    /// reach keep theirs.
    #[test]
    fn shifting_never_walks_surface_particles_into_a_wall() {
        use crate::engine::boundary::{Plane, Shape, TensorMirror, Wall};
        let plate = Wall::no_slip(Shape::Plane(Plane::floor()), TensorMirror::Even);
        let points = [
            Vec2::new(0.0, 0.05),
            Vec2::new(1.0, 0.05),
            Vec2::new(2.0, 0.05),
            Vec2::new(3.0, 5.0),
        ];
        let region = [true, true, false, true];
        let mut u = [
            Vec2::new(0.3, -0.4),
            Vec2::new(0.3, 0.4),
            Vec2::new(0.3, -0.4),
            Vec2::new(0.3, -0.4),
        ];
        keep_off_walls(&points, &[plate], &region, 1.0, &mut u);
        assert_eq!(
            u[0],
            Vec2::new(0.3, 0.0),
            "the part into the plate is removed"
        );
        assert_eq!(u[1], Vec2::new(0.3, 0.4), "away from the plate is kept");
        assert_eq!(u[2], Vec2::new(0.3, -0.4), "not in the surface region");
        assert_eq!(u[3], Vec2::new(0.3, -0.4), "beyond the reach");
    }

    /// One particle of a regular periodic lattice is displaced by (0.2, 0.1)δr. Each shifting
    /// step (all particles move with u_ps, lists rebuilt) must bring it closer to its site,
    /// along the displacement rather than sideways, and repeated steps must return it there.
    #[test]
    fn displaced_particle_returns_to_its_lattice_site() {
        let n = 20;
        let dr = 1.0 / n as f64;
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, true],
        };
        let mut pts: Vec<Vec2> = (0..n * n)
            .map(|k| Vec2::new(((k / n) as f64 + 0.5) * dr, ((k % n) as f64 + 0.5) * dr))
            .collect();
        let target = 10 * n + 10;
        let site = pts[target];
        let offset = Vec2::new(0.2, 0.1) * dr;
        pts[target] += offset;

        let kernel = QuinticSpline::for_spacing(dr);
        let mut search = NeighbourSearch::new();
        let mut list = NeighbourList::default();
        let mut sums = KernelSums::default();
        let mut grad_c = vec![Vec2::zeros(); pts.len()];
        let mut u_ps = vec![Vec2::zeros(); pts.len()];
        let dt = 1e-3;
        let initial = offset.norm();
        let mut distance = initial;
        for step in 0..30 {
            search.build(&domain, &pts, pts.len(), kernel.support(), &mut list);
            sums.update(&list, &kernel, dr * dr);
            concentration_gradient(&list, &sums, &kernel, dr, &mut grad_c);
            internal_shifting_velocity(&grad_c, kernel.h(), dt, &mut u_ps);
            if step == 0 {
                assert!(
                    (dt * u_ps[target]).dot(&offset) < -0.9 * (dt * u_ps[target]).norm() * initial,
                    "first shift must point back along the displacement"
                );
                let far = 2 * n + 2;
                assert!(
                    u_ps[far].norm() * dt < 1e-12,
                    "undisturbed particles stay put"
                );
            }
            for (p, u) in pts.iter_mut().zip(&u_ps) {
                *p = domain.wrap(*p + dt * u);
            }
            let d = (pts[target] - site).norm();
            assert!(
                d < distance,
                "step {step}: distance to site grew {distance} -> {d}"
            );
            distance = d;
        }
        assert!(
            distance < 0.3 * initial,
            "after 30 steps {distance} of {initial}"
        );
    }
}
