//! Solid walls and their mirror particles (King & Lind §III C). A [`Wall`] is a [`Shape`]
//! (plane or circle, [`shape`]) with a [`WallCondition`] ([`condition`]: the values its mirrors
//! carry, no slip at rest by default).
//!
//! For every fluid particle i within one kernel support of a wall, a mirror j is placed so
//! that r_ij is perpendicular to, and bisected by, the wall; across a circle it carries the
//! volume ratio of the mirrored ring element. [`Ghosts`] builds the mirrors of one step and
//! extends fluid fields to them by each wall's condition.

pub mod condition;
pub mod continuation;
pub mod fixed;
pub mod inflow;
pub mod shape;

pub use condition::{
    NoSlip, RegularisedLid, RigidNoSlip, SlidingNoSlip, TensorMirror, TurningNoSlip, WallCondition,
};
pub use continuation::VelocityExtension;
pub use fixed::WallModel;
pub use shape::{Circle, Corner, Plane, Plate, Shape, Sphere, Tube};

use crate::engine::dimension::{Dim, Dimension, SymTensor};
use crate::engine::neighbours::Domain;
use nalgebra::SVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// `[scheme.walls]`: the particles behind walls and the fields they carry.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields, default)]
pub struct WallSettings {
    /// `mirror` or `fixed-ghost`: how the particles behind plane walls are placed.
    pub model: WallModel,
    /// `auto`, `mirror` (u_j = 2u_w − u_i, the paper's) or `quadratic` (the fluid's
    /// quadratic continuation through the wall velocity): the no-slip walls' ghost
    /// velocities ([`VelocityExtension`], [`WallVelocityChoice`]).
    pub velocity: WallVelocityChoice,
    /// How the conformation is carried onto wall mirrors; unset = `linear`, or `even` in a
    /// scene with a free surface, where the continuation is not validated (the weakly
    /// compressible drop of `cases/drop-fang.toml` without artificial stress then broke down
    /// by a particle leaving through the plate at the axis, not by the tension fracture that
    /// the even copy shows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conformation: Option<TensorMirror>,
}

/// How no-slip walls extend the velocity to their ghosts.
#[derive(
    Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum WallVelocityChoice {
    /// `quadratic` where the fluid fills the walls' neighbourhoods and its viscosity is
    /// constant; `mirror` in a scene with a free surface, whose contact line truncates the
    /// support the one-sided fit assumes full (the Oldroyd-B drop at W/δr = 20 broke down
    /// at impact with it, t = 0.027, and runs through with the mirror), and for a shear-rate
    /// dependent viscosity, where it measured worse and the cause is not found (H/δr = 15,
    /// final L2: Bingham 1.66 % against 0.79 %, power law n = 0.5 3.27 % against 2.20 %);
    /// and with moving discs, whose coupling's stiffening (`engine::bodies`) is derived for
    /// mirrors that carry 2u_w (a settling disc's Galilean check, `tests/discs.rs`: 3.5 %
    /// against 1.2 % with the mirror).
    #[default]
    Auto,
    Mirror,
    Quadratic,
}

/// [`Ghosts::mark_shared_parents`]: a particle without ghosts, and one with ghosts across two
/// walls.
const NO_WALL: u16 = u16::MAX;
const SHARED: u16 = u16::MAX - 1;

/// A point in D dimensions.
type Point<const D: usize> = SVector<f64, D>;
/// The symmetric tensor of D dimensions.
type Sym<const D: usize> = <Dim<D> as Dimension<D>>::Sym;

/// A solid wall: a shape with a condition, in D dimensions (the default 2).
#[derive(Clone, Debug)]
pub struct Wall<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub shape: Shape<D>,
    pub condition: Arc<dyn WallCondition<D>>,
    /// The angle (radians, through the liquid) a free surface with surface tension meets
    /// this wall at where it is not the scene's (`Setup::contact_angle`).
    pub contact_angle: Option<f64>,
}

impl<const D: usize> Wall<D>
where
    Dim<D>: Dimension<D>,
{
    /// A no-slip wall at rest carrying the conformation by `tensor`.
    pub fn no_slip(shape: Shape<D>, tensor: TensorMirror) -> Self {
        Self {
            shape,
            condition: Arc::new(NoSlip { tensor }),
            contact_angle: None,
        }
    }

    /// A no-slip wall sliding at `velocity` (zero: [`Self::no_slip`]).
    pub fn sliding(shape: Shape<D>, tensor: TensorMirror, velocity: Point<D>) -> Self {
        if velocity == Point::<D>::zeros() {
            return Self::no_slip(shape, tensor);
        }
        Self {
            shape,
            condition: Arc::new(SlidingNoSlip { tensor, velocity }),
            contact_angle: None,
        }
    }

    /// The corner where plane walls `a` and `b` meet at right angles, with the conditions of
    /// both (None unless both are planes on different axes).
    /// A moving wall is taken first, so that its velocity is read on its own side of the
    /// other wall ([`condition::Corner`]): across a wall at rest the lid's profile extends
    /// odd, as no slip there requires.
    pub fn corner(a: &Wall<D>, b: &Wall<D>) -> Option<Wall<D>> {
        let (a, b) = if b.condition.moves() && !a.condition.moves() {
            (b, a)
        } else {
            (a, b)
        };
        let (Shape::Plane(pa), Shape::Plane(pb)) = (a.shape, b.shape) else {
            return None;
        };
        if pa.axis == pb.axis {
            return None;
        }
        let (mut point, mut sides) = (Point::<D>::zeros(), [0.0; D]);
        for p in [pa, pb] {
            point[p.axis] = p.position;
            sides[p.axis] = p.fluid_side;
        }
        Some(Wall {
            shape: Shape::Corner(Corner { point, sides }),
            condition: Arc::new(condition::Corner {
                first: (pa, a.condition.clone()),
                second: (pb, b.condition.clone()),
            }),
            contact_angle: None,
        })
    }

    /// Signed distance of `p` from the wall, positive in the fluid.
    pub fn distance(&self, p: &Point<D>) -> f64 {
        self.shape.distance(p)
    }

    /// Signed distance of `p`'s periodic image nearest the wall.
    pub fn distance_in(&self, p: &Point<D>, domain: &Domain<D>) -> f64 {
        self.shape
            .distance(&self.shape.nearest_image(p, Some(domain)))
    }
}

/// The field a mirror value belongs to (for the linear factor of its condition).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    Pressure,
    Velocity,
}

/// The mirror particles of one step: ghost g has parent fluid particle `parent[g]` and was
/// mirrored across wall `wall[g]`.
#[derive(Clone, Debug)]
pub struct Ghosts<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub parent: Vec<u32>,
    /// The wall each ghost mirrors across (index into `walls`).
    pub wall: Vec<u16>,
    /// Each ghost's volume relative to its parent's.
    pub volume: Vec<f64>,
    /// The surface normal between each ghost and its parent.
    pub normal: Vec<Point<D>>,
    /// r_g − r_k from each ghost's parent k to the ghost (the nearest periodic image).
    pub arm: Vec<Point<D>>,
    /// b_j of `u_j = s u_i + b_j` (empty when every wall is at rest).
    offset: Vec<Point<D>>,
    pub walls: Vec<Wall<D>>,
    /// Each wall's s and s_p (see [`condition`]).
    velocity_sign: Vec<f64>,
    pressure_sign: Vec<f64>,
    /// The box whose periodic axes circles are seen across (None: no periodic images).
    pub domain: Option<Domain<D>>,
    /// δr of the fixed ghost lattice behind every wall (None: mirrors).
    lattice: Option<f64>,
    /// Scratch of the fixed lattice's nearest-particle search and its ghosts.
    near: Vec<fixed::NearParticle>,
    lattice_ghosts: Vec<fixed::FixedGhost<D>>,
    /// The walls' shapes at the last build (for [`Self::drift`]).
    built_shapes: Vec<Shape<D>>,
    /// How [`Self::continue_velocity`] extends a no-slip wall's velocity.
    velocity_extension: VelocityExtension,
    /// The continuations' stencils of the current configuration.
    continuation: continuation::Continuation,
    /// Each fluid particle's wall, or [`SHARED`] for ghosts across two
    /// ([`Self::prepare_continuation`]).
    shared_parent: Vec<u16>,
}

impl<const D: usize> Default for Ghosts<D>
where
    Dim<D>: Dimension<D>,
{
    fn default() -> Self {
        Self {
            parent: Vec::new(),
            wall: Vec::new(),
            volume: Vec::new(),
            normal: Vec::new(),
            arm: Vec::new(),
            offset: Vec::new(),
            walls: Vec::new(),
            velocity_sign: Vec::new(),
            pressure_sign: Vec::new(),
            domain: None,
            lattice: None,
            near: Vec::new(),
            lattice_ghosts: Vec::new(),
            built_shapes: Vec::new(),
            velocity_extension: VelocityExtension::default(),
            continuation: continuation::Continuation::default(),
            shared_parent: Vec::new(),
        }
    }
}

/// One mirror's position and the values its wall gives it.
struct Mirror<const D: usize> {
    position: Point<D>,
    volume: f64,
    normal: Point<D>,
    offset: Point<D>,
}

impl<const D: usize> Ghosts<D>
where
    Dim<D>: Dimension<D>,
{
    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.parent)
            + b(&self.wall)
            + b(&self.volume)
            + b(&self.normal)
            + b(&self.offset)
            + b(&self.near)
            + b(&self.lattice_ghosts)
            + b(&self.built_shapes)
            + b(&self.arm)
            + self.continuation.heap_bytes()
            + b(&self.shared_parent)
    }

    pub fn new(walls: Vec<Wall<D>>) -> Self {
        Self {
            velocity_sign: walls.iter().map(|w| w.condition.velocity_sign()).collect(),
            pressure_sign: walls.iter().map(|w| w.condition.pressure_sign()).collect(),
            walls,
            ..Default::default()
        }
    }

    /// Places the ghosts of every wall on a fixed lattice of spacing `spacing`
    /// ([`WallModel::FixedGhost`]); mirrors otherwise.
    pub fn set_model(&mut self, model: WallModel, spacing: f64) {
        self.lattice = (model == WallModel::FixedGhost).then_some(spacing);
    }

    /// How the no-slip walls' ghost velocities continue the fluid's
    /// ([`Self::continue_velocity`]).
    pub fn set_velocity_extension(&mut self, extension: VelocityExtension) {
        self.velocity_extension = extension;
    }

    /// Replaces wall `k` (a body that moved); its mirrors follow at the next [`Self::build`].
    pub fn set_wall(&mut self, k: usize, wall: Wall<D>) {
        self.velocity_sign[k] = wall.condition.velocity_sign();
        self.pressure_sign[k] = wall.condition.pressure_sign();
        self.walls[k] = wall;
    }

    /// Sets wall `k`'s condition in place (its shape unchanged: a body turning about a held
    /// centre) and recomputes its mirrors' offsets from their parents among `fluid`, so
    /// that a new wall velocity reaches the ghosts also where the configuration is not
    /// rebuilt (the Eulerian frame's fixed particles). The wall must have moved at the
    /// last build (its offsets exist) or not have been built yet.
    pub fn set_condition(&mut self, k: usize, wall: Wall<D>, fluid: &[Point<D>]) {
        debug_assert!(wall.shape == self.walls[k].shape);
        self.set_wall(k, wall);
        if !self.has_offsets() {
            return;
        }
        let wall = &self.walls[k];
        for g in (0..self.parent.len()).filter(|&g| self.wall[g] as usize == k) {
            let p = wall
                .shape
                .nearest_image(&fluid[self.parent[g] as usize], self.domain.as_ref());
            self.offset[g] = wall.condition.velocity_offset(wall.shape.reflect(&p));
        }
    }

    /// Whether any ghost carries a volume other than its parent's.
    pub fn has_volume_ratios(&self) -> bool {
        self.lattice.is_none()
            && self
                .walls
                .iter()
                .any(|w| matches!(w.shape, Shape::Circle(_) | Shape::Plate(_) | Shape::Tube(_)))
    }

    pub fn len(&self) -> usize {
        self.parent.len()
    }

    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }

    /// Creates mirrors of the fluid particles within `reach` of a wall, appending their
    /// positions to `points` (which holds the fluid positions on entry).
    pub fn build(&mut self, reach: f64, points: &mut Vec<Point<D>>) {
        self.parent.clear();
        self.wall.clear();
        self.volume.clear();
        self.normal.clear();
        self.arm.clear();
        self.offset.clear();
        self.built_shapes.clear();
        self.built_shapes.extend(self.walls.iter().map(|w| w.shape));
        let moving = self.walls.iter().any(|w| w.condition.moves());
        if let Some(spacing) = self.lattice {
            self.build_fixed(reach, spacing, moving, points);
            return;
        }
        let n_fluid = points.len();
        for i in 0..n_fluid {
            for (w, wall) in self.walls.iter().enumerate() {
                // A circle sees the particle's periodic image nearest its centre.
                let p = wall.shape.nearest_image(&points[i], self.domain.as_ref());
                if wall.shape.distance(&p) < reach {
                    let m = self.mirror(wall, &p, moving);
                    self.volume.push(m.volume);
                    self.normal.push(m.normal);
                    if moving {
                        self.offset.push(m.offset);
                    }
                    self.arm.push(self.arm_to(m.position, points[i]));
                    points.push(m.position);
                    self.parent.push(i as u32);
                    self.wall.push(w as u16);
                }
            }
        }
    }

    /// The mirror of the fluid point `p` (its image nearest the wall) across `wall`, back
    /// in the box.
    fn mirror(&self, wall: &Wall<D>, p: &Point<D>, moving: bool) -> Mirror<D> {
        let q = wall.shape.reflect(p);
        Mirror {
            position: self.domain.map_or(q, |d| d.wrap(q)),
            volume: wall.shape.volume_ratio(p),
            normal: wall.shape.normal(p),
            offset: if moving {
                wall.condition.velocity_offset(q)
            } else {
                Point::<D>::zeros()
            },
        }
    }

    /// r_g − r_k from a parent at `parent` to its ghost at `ghost` (nearest image).
    fn arm_to(&self, ghost: Point<D>, parent: Point<D>) -> Point<D> {
        let arm = ghost - parent;
        self.domain.map_or(arm, |d| d.min_image(arm))
    }

    /// Whether [`Self::refresh`] can move the ghosts of the last build (mirrors can; the
    /// fixed lattice re-chooses its parents, which only a build does).
    pub fn can_refresh(&self) -> bool {
        self.lattice.is_none()
    }

    /// Moves the mirrors of the last [`Self::build`] to the parents' positions in `points`
    /// (the fluid positions on entry), appending them as `build` would, with their volumes,
    /// normals and offsets: the same mirrors, in the same order, for a Verlet skin.
    pub fn refresh(&mut self, points: &mut Vec<Point<D>>) {
        let moving = self.walls.iter().any(|w| w.condition.moves());
        for g in 0..self.parent.len() {
            let wall = &self.walls[self.wall[g] as usize];
            let parent = points[self.parent[g] as usize];
            let p = wall.shape.nearest_image(&parent, self.domain.as_ref());
            let m = self.mirror(wall, &p, moving);
            self.volume[g] = m.volume;
            self.normal[g] = m.normal;
            self.arm[g] = self.arm_to(m.position, parent);
            if moving {
                self.offset[g] = m.offset;
            }
            points.push(m.position);
        }
    }

    /// How far any wall has moved since the last build (∞ for a wall that changed shape).
    pub fn drift(&self) -> f64 {
        self.walls
            .iter()
            .zip(&self.built_shapes)
            .map(|(w, built)| w.shape.displacement_from(built))
            .fold(0.0, f64::max)
    }

    /// The fixed ghosts of every wall ([`fixed`]).
    fn build_fixed(&mut self, reach: f64, spacing: f64, moving: bool, points: &mut Vec<Point<D>>) {
        let n_fluid = points.len() - self.parent.len();
        let mut near = std::mem::take(&mut self.near);
        let mut found = std::mem::take(&mut self.lattice_ghosts);
        for (w, wall) in self.walls.iter().enumerate() {
            found.clear();
            fixed::ghosts_of(
                &wall.shape,
                spacing,
                reach,
                self.domain.as_ref(),
                &points[..n_fluid],
                &mut near,
                &mut found,
            );
            for g in &found {
                self.volume.push(1.0);
                self.normal.push(g.normal);
                if moving {
                    self.offset.push(wall.condition.velocity_offset(g.position));
                }
                let arm = g.position - points[g.parent as usize];
                self.arm.push(self.domain.map_or(arm, |d| d.min_image(arm)));
                points.push(g.position);
                self.parent.push(g.parent);
                self.wall.push(w as u16);
            }
        }
        self.near = near;
        self.lattice_ghosts = found;
    }

    /// Volumes of all points relative to a fluid particle's (1 for fluid particles).
    pub fn point_volumes(&self, n_fluid: usize, out: &mut Vec<f64>) {
        out.clear();
        out.resize(n_fluid, 1.0);
        out.extend_from_slice(&self.volume);
    }

    /// The parent fluid index of extended index `j` (identity for fluid particles).
    #[inline]
    pub fn owner(&self, j: usize, n_fluid: usize) -> usize {
        if j < n_fluid {
            j
        } else {
            self.parent[j - n_fluid] as usize
        }
    }

    /// The linear factor of ghost `g`'s `field` over its parent's.
    #[inline]
    pub fn sign(&self, field: Field, g: usize) -> f64 {
        let w = self.wall[g] as usize;
        match field {
            Field::Pressure => self.pressure_sign[w],
            Field::Velocity => self.velocity_sign[w],
        }
    }

    /// Fluid velocities followed by the ghosts' `u_j = s u_i + b_j`.
    pub fn extend_velocity(&self, fluid: &[Point<D>], out: &mut Vec<Point<D>>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(
            self.parent
                .iter()
                .zip(&self.wall)
                .map(|(&p, &w)| self.velocity_sign[w as usize] * fluid[p as usize]),
        );
        if !self.offset.is_empty() {
            let n = fluid.len();
            out[n..]
                .iter_mut()
                .zip(&self.offset)
                .for_each(|(u, b)| *u += b);
        }
    }

    /// Fluid velocities followed by the ghosts' as the operators read them: the mirrors'
    /// `u_j = s u_i + b_j` ([`Self::extend_velocity`]), or under
    /// [`VelocityExtension::Quadratic`] the no-slip walls' quadratic continuation of the
    /// fluid's velocity ([`continuation`]; its stencils from the last
    /// [`Self::prepare_continuation`]).
    pub fn continue_velocity(&self, fluid: &[Point<D>], out: &mut Vec<Point<D>>) {
        self.extend_velocity(fluid, out);
        if self.velocity_extension == VelocityExtension::Quadratic {
            let n = fluid.len();
            self.continuation
                .velocity(fluid, &self.offset, &mut out[n..]);
        }
    }

    /// Ghost g's velocity as a combination of fluid velocities, `u_g = Σ_m c_m u_m + u_w(1 −
    /// Σ_m c_m)`, where it is continued: the points m and the weights c_m. The implicit
    /// matrices fold it into those columns ([`Self::extend_offsets`] keeps the rest).
    pub fn velocity_stencil(&self, g: usize) -> Option<(&[u32], &[f64])> {
        if self.velocity_extension == VelocityExtension::Quadratic {
            self.continuation.velocity_stencil(g)
        } else {
            None
        }
    }

    /// Builds the continuations' stencils for the configuration of `list` and `sums` (the
    /// first `n_fluid` points are the fluid's; `support` the kernel's): where no wall
    /// continues a tensor and the velocity is mirrored, nothing.
    pub fn prepare_continuation(
        &mut self,
        pairs: continuation::PairKernel<D>,
        n_fluid: usize,
        support: f64,
    ) {
        let tensor = self.walls.iter().any(|w| w.condition.continues_tensor());
        let velocity = self.velocity_extension == VelocityExtension::Quadratic;
        let mut continuation = std::mem::take(&mut self.continuation);
        let mut shared = std::mem::take(&mut self.shared_parent);
        self.mark_shared_parents(n_fluid, support, &mut shared);
        let (walls, wall, sign) = (&self.walls, &self.wall, &self.velocity_sign);
        let lone = |g: usize| shared[self.parent[g] as usize] != SHARED;
        let ghosts = continuation::GhostView {
            parent: &self.parent,
            arm: &self.arm,
            velocity: &|g| velocity && sign[wall[g] as usize] < 0.0 && lone(g),
            tensor: &|g| tensor && walls[wall[g] as usize].condition.continues_tensor(),
        };
        continuation.build(pairs, n_fluid, &ghosts);
        self.continuation = continuation;
        self.shared_parent = shared;
    }

    /// Flags the fluid particles (of `n_fluid`) that have ghosts across two or more walls:
    /// within one support of a second wall (a gap, a corner), where the one-sided quadratic
    /// fit of their ghosts' velocities is ill-posed and they keep the mirror. Between a disc
    /// and the floor of `tests/discs.rs` at a gap of 0.07R (R/δr = 8) the fits' Lebesgue
    /// constants Σ|c_j| reached 17 (at most 7.6 over a lone wall) and the disc's tangential
    /// mode grew from 1e-8 to 1e-3 within three time units.
    /// `wall_of` gets each particle's wall ([`NO_WALL`] without ghosts, [`SHARED`] across two).
    /// Only ghosts within the particle's own support count (|arm| = 2 × its distance to the
    /// wall < 2 × `support`): a search with a Verlet skin mirrors particles further out, and
    /// the choice must not depend on the skin.
    fn mark_shared_parents(&self, n_fluid: usize, support: f64, wall_of: &mut Vec<u16>) {
        wall_of.clear();
        wall_of.resize(n_fluid, NO_WALL);
        let near = self.arm.iter().map(|a| a.norm() < 2.0 * support);
        for ((&k, &w), _) in self
            .parent
            .iter()
            .zip(&self.wall)
            .zip(near)
            .filter(|(_, n)| *n)
        {
            let first = &mut wall_of[k as usize];
            if *first == NO_WALL {
                *first = w;
            } else if *first != w {
                *first = SHARED;
            }
        }
    }

    /// Whether some ghost carries a velocity offset b_j (a moving wall).
    pub fn has_offsets(&self) -> bool {
        !self.offset.is_empty()
    }

    /// Zero for the fluid particles followed by the part of each ghost's velocity that the
    /// implicit matrices cannot fold into fluid columns: a mirror's offset b_j, or a
    /// continued ghost's u_w(1 − Σ_m c_m) ([`Self::velocity_stencil`]; u_w = b_j/2).
    pub fn extend_offsets(&self, n_fluid: usize, out: &mut Vec<Point<D>>) {
        out.clear();
        out.resize(n_fluid, Point::<D>::zeros());
        out.extend_from_slice(&self.offset);
        for (g, b) in out[n_fluid..].iter_mut().enumerate() {
            if let Some((_, c)) = self.velocity_stencil(g) {
                *b *= 0.5 * (1.0 - c.iter().sum::<f64>());
            }
        }
    }

    /// Fluid pressures followed by the ghosts' `p_j = s_p p_i` (the homogeneous Neumann
    /// condition), for the pressure or an increment.
    pub fn extend_pressure(&self, fluid: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(
            self.parent
                .iter()
                .zip(&self.wall)
                .map(|(&p, &w)| self.pressure_sign[w as usize] * fluid[p as usize]),
        );
    }

    /// Fluid scalars followed by the ghosts' copies of their parents' values (an even field
    /// such as a viscosity).
    pub fn extend_scalar(&self, fluid: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(self.parent.iter().map(|&p| fluid[p as usize]));
    }

    /// Fluid tensors followed by the ghosts' values by their walls' conditions.
    pub fn extend_tensor(&self, fluid: &[Sym<D>], out: &mut Vec<Sym<D>>) {
        out.clear();
        out.extend_from_slice(fluid);
        out.extend(
            self.parent
                .iter()
                .zip(&self.wall)
                .zip(&self.normal)
                .map(|((&p, &w), n)| {
                    self.walls[w as usize]
                        .condition
                        .tensor(&fluid[p as usize], n)
                }),
        );
    }

    /// Fluid tensors followed by the ghosts' values, the parent's tensor first continued to
    /// the ghost, `T_k + (r_g − r_k)·∇T_k`, at the walls whose rule is
    /// [`TensorMirror::Linear`] ([`continuation`]; its stencils from the last
    /// [`Self::prepare_continuation`]), then mapped by each wall's rule.
    pub fn continue_tensor(&self, fluid: &[Sym<D>], out: &mut Vec<Sym<D>>) {
        let n = fluid.len();
        out.clear();
        out.extend_from_slice(fluid);
        out.resize(n + self.parent.len(), <Sym<D> as SymTensor>::ZERO);
        self.continuation.tensor(fluid, &self.parent, &mut out[n..]);
        let walls = &self.walls;
        out[n..].par_iter_mut().enumerate().for_each(|(g, t)| {
            *t = walls[self.wall[g] as usize]
                .condition
                .tensor(t, &self.normal[g]);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::{Sym2, Vec2};

    fn channel(tensor: TensorMirror) -> Ghosts {
        let plane = |position, fluid_side| {
            Wall::no_slip(
                Shape::Plane(Plane {
                    axis: 1,
                    position,
                    fluid_side,
                }),
                tensor,
            )
        };
        Ghosts::new(vec![plane(0.0, 1.0), plane(1.0, -1.0)])
    }

    #[test]
    fn mirrors_are_bisected_by_the_wall() {
        let mut g = channel(TensorMirror::Even);
        let mut pts = vec![
            Vec2::new(0.3, 0.05),
            Vec2::new(0.4, 0.5),
            Vec2::new(0.1, 0.9),
        ];
        g.build(0.2, &mut pts);
        assert_eq!(g.parent, vec![0, 2]);
        assert!((pts[3] - Vec2::new(0.3, -0.05)).norm() < 1e-15);
        assert!((pts[4] - Vec2::new(0.1, 1.1)).norm() < 1e-15);
        for (k, &p) in g.parent.iter().enumerate() {
            let mid = 0.5 * (pts[p as usize] + pts[3 + k]);
            let Shape::Plane(wall) = g.walls[g.wall[k] as usize].shape else {
                panic!()
            };
            assert!((mid.y - wall.position).abs() < 1e-15);
        }
    }

    #[test]
    fn ghost_values_follow_the_no_slip_rules() {
        let mut g = channel(TensorMirror::Even);
        let mut pts = vec![Vec2::new(0.3, 0.05)];
        g.build(0.2, &mut pts);
        let mut u = Vec::new();
        g.extend_velocity(&[Vec2::new(2.0, -1.0)], &mut u);
        assert_eq!(u[1], Vec2::new(-2.0, 1.0));
        let mut p = Vec::new();
        g.extend_pressure(&[3.5], &mut p);
        assert_eq!(p[1], 3.5);
        let mut a = Vec::new();
        g.extend_tensor(&[Sym2::new(5.0, 2.0, 1.0)], &mut a);
        assert_eq!(a[1], Sym2::new(5.0, 2.0, 1.0));
        let mut g = channel(TensorMirror::Reflected);
        g.build(0.2, &mut vec![Vec2::new(0.3, 0.05)]);
        g.extend_tensor(&[Sym2::new(5.0, 2.0, 1.0)], &mut a);
        assert_eq!(a[1], Sym2::new(5.0, -2.0, 1.0));
    }

    /// Across a circle the mirror sits on the same radius at the same distance inside, the
    /// segment's midpoint lies on the surface, its volume shrinks by (R − d)/(R + d), and the
    /// reflected tensor rule uses the local radial normal.
    #[test]
    fn circle_mirrors_are_bisected_by_the_surface() {
        let c = Circle {
            centre: Vec2::new(3.0, 2.0),
            radius: 1.0,
        };
        let mut g = Ghosts::new(vec![Wall::no_slip(Shape::Circle(c), TensorMirror::Even)]);
        let p = Vec2::new(3.0 + 1.1 * 0.6, 2.0 + 1.1 * 0.8);
        let mut pts = vec![p, Vec2::new(0.2, 0.2)];
        g.build(0.3, &mut pts);
        assert_eq!(g.parent, vec![0]);
        let m = pts[2];
        let mid = 0.5 * (p + m);
        assert!(
            ((mid - c.centre).norm() - 1.0).abs() < 1e-14,
            "midpoint on the circle"
        );
        assert!(((m - c.centre).norm() - 0.9).abs() < 1e-14);
        let radial = (p - c.centre).normalize();
        assert!(
            (m - p).normalize().dot(&radial) + 1.0 < 1e-14,
            "along the radius"
        );
        assert!((g.volume[0] - 0.9 / 1.1).abs() < 1e-14);
        // The reflected rule flips the normal–tangential shear in the local frame.
        let mut g = Ghosts::new(vec![Wall::no_slip(
            Shape::Circle(c),
            TensorMirror::Reflected,
        )]);
        g.build(0.3, &mut vec![p, Vec2::new(0.2, 0.2)]);
        let n = radial;
        let t = Vec2::new(-n.y, n.x);
        let shear = Sym2::new(2.0 * n.x * t.x, n.x * t.y + n.y * t.x, 2.0 * n.y * t.y); // n⊗t + t⊗n
        let mut out = Vec::new();
        g.extend_tensor(&[shear, Sym2::ZERO], &mut out);
        let d = out[2] + shear;
        assert!(d.contract(&d).sqrt() < 1e-14);
    }

    /// In space: a sphere's mirror sits on the same radius at the same depth inside, the
    /// segment's midpoint on the surface, its volume the shell's area ratio ((R − d)/(R + d))²;
    /// the reflected tensor rule flips the normal–tangential shear in the local frame.
    #[test]
    fn sphere_mirrors_are_bisected_by_the_surface() {
        use crate::engine::boundary::shape::Sphere;
        use crate::engine::math::{Sym3, Vec3};
        let c = Sphere {
            centre: Vec3::new(1.0, 2.0, 3.0),
            radius: 1.0,
        };
        let radial = Vec3::new(0.48, 0.6, 0.64);
        let p = c.centre + 1.1 * radial;
        let mut g = Ghosts::<3>::new(vec![Wall::no_slip(
            Shape::Circle(c),
            TensorMirror::Reflected,
        )]);
        let mut pts = vec![p, Vec3::new(5.0, 5.0, 5.0)];
        g.build(0.3, &mut pts);
        assert_eq!(g.parent, vec![0]);
        let m = pts[2];
        assert!((((p + m) * 0.5 - c.centre).norm() - 1.0).abs() < 1e-14);
        assert!(((m - c.centre).norm() - 0.9).abs() < 1e-14);
        assert!((g.volume[0] - (0.9f64 / 1.1).powi(2)).abs() < 1e-14);
        let t = Vec3::new(0.8, -0.64, 0.0).normalize();
        let t = (t - radial * t.dot(&radial)).normalize();
        let shear = Sym3::from_entries(|a, b| radial[a] * t[b] + radial[b] * t[a]);
        let normal_stress = Sym3::from_entries(|a, b| radial[a] * radial[b]);
        let mut out = Vec::new();
        g.extend_tensor(&[shear, shear], &mut out);
        let d = out[2] + shear;
        assert!(d.contract(&d).sqrt() < 1e-14, "n⊗t + t⊗n is odd");
        g.extend_tensor(&[normal_stress, normal_stress], &mut out);
        let d = out[2] - normal_stress;
        assert!(d.contract(&d).sqrt() < 1e-14, "n⊗n is even");
    }

    /// In space two planes meet along an edge: the corner ghost of a particle near both is
    /// reflected across the two planes' axes and keeps its coordinate along the edge, and the
    /// composed no-slip condition gives it u_c = u_i (two odd copies).
    #[test]
    fn a_3d_corner_reflects_across_its_edge() {
        use crate::engine::math::Vec3;
        let floor = Wall::<3>::no_slip(Shape::Plane(Plane::floor()), TensorMirror::Even);
        let side = Wall::<3>::no_slip(
            Shape::Plane(Plane {
                axis: 2,
                position: 0.0,
                fluid_side: 1.0,
            }),
            TensorMirror::Even,
        );
        let corner = Wall::corner(&floor, &side).expect("planes on different axes");
        let p = Vec3::new(0.7, 0.05, 0.1);
        assert!((corner.distance(&p) - (0.05f64.hypot(0.1))).abs() < 1e-15);
        assert_eq!(corner.shape.reflect(&p), Vec3::new(0.7, -0.05, -0.1));
        assert!((corner.distance(&Vec3::new(0.7, -0.02, 0.3)) + 0.02).abs() < 1e-15);
        let mut g = Ghosts::<3>::new(vec![floor, side, corner]);
        let mut pts = vec![p];
        g.build(0.2, &mut pts);
        assert_eq!(g.wall, vec![0, 1, 2]);
        let mut u = Vec::new();
        g.extend_velocity(&[Vec3::new(1.0, 2.0, 3.0)], &mut u);
        assert_eq!(u[3], Vec3::new(1.0, 2.0, 3.0));
    }
}
