//! A static contact angle θ where a free surface meets a wall (`scene.contact_angle`).
//!
//! At equilibrium the surface meets a flat wall at θ, measured through the liquid (Young
//! 1805); with the wall's unit normal n_w pointing into the fluid and its tangent t_w pointing
//! from the liquid to the gas along the wall, the surface's outward normal at the contact line
//! is `m = n_w cos θ + t_w sin θ` (Brackbill, Kothe & Zemach 1992). That is a boundary
//! condition on the surface's shape, and in this scheme the shape enters only through the
//! curvature κ of the capillary pressure σκ ([`super::tension`]). So the condition is imposed
//! where κ is fitted: the FS particle nearest the wall (the contact particle c, in the first
//! layer) continues its surface beyond the wall by the reflection of that surface across the
//! line through c along m. A curve and its reflection across the normal line at a point share
//! the tangent and the curvature there, so when the surface meets the wall at θ the
//! continuation is smooth and adds nothing; when it meets it at another angle the
//! continuation makes a corner at c whose curvature pulls the surface towards θ (a surface
//! steeper than θ = 30° allows is seen as concave, its pressure falls below the liquid's and
//! the liquid climbs the wall).
//!
//! The reflection line passes through the wall point w where the surface through the
//! particles' centres, leaving c along the prescribed tangent, meets the wall. Taken through
//! c itself (half a spacing from the wall), the meniscus at a wall came out shifted by that
//! half spacing: the rise at the wall 5.9 % above the exact value at ℓ_c/δr = 12.5
//! (`cases/meniscus.toml`), the profile correct beyond a few spacings. Which way the gas lies
//! along the wall is read from the contact particle's own normal (39); a surface lying along
//! the wall (|n·t_w| < [`MIN_TANGENTIAL`]) has no contact line there.
//!
//! **The contact particle's own curvature** ([`ContactCurvature`]). The continuation acts
//! on c only through images within its support, and the image of c itself lies 2d/sin θ
//! from it (d its distance from the wall): 3.8δr at θ = 30° and d = 0.95δr, at the edge of
//! the support, where W is nearly zero. There a surface meeting the wall flat (90°, an
//! error of 60°) gets no pull at all, and the 30° capillary rise drained under a meniscus
//! whose low contact line had gone flat (validation pages, *What drains the 30° column*). With
//! [`ContactCurvature::Turn`] c takes instead the curvature of the circle that leaves the
//! wall at θ and passes through its surface neighbours ([`ContactLine::turned_curvature`]),
//! which grows with the angle's error at any error.
//!
//! **Which curve meets the wall at θ** ([`ContactAngleAt`]). The capillary pressure takes
//! the curvature of the surface half a spacing beyond the centres ([`super::tension`]); held
//! at θ, the centres' curve puts that surface at another angle, cos θ_s = cos θ/(1 + κ_c δr/2)
//! on a circle: 20.6° for 30° between plates 10δr apart, where the column stood 12 % above
//! Jurin's height and the FS pressure under its meniscus 11–23 % above σ times the curvature
//! of the centres' circle (validation pages, *The angle at the surface*). With
//! [`ContactAngleAt::Surface`] each contact line is turned to θ_c of its particle's curvature
//! before the fits use it ([`ContactLine::for_curvature`]).

use serde::{Deserialize, Serialize};

use crate::engine::boundary::Shape;
use crate::engine::free_surface::FreeSurface;
use crate::engine::math::Vec2;
use crate::engine::neighbours::NeighbourList;
use rayon::prelude::*;

/// The tangential part of an FS particle's normal below which the surface is taken to lie
/// along the wall rather than meet it (θ within ~12° of 0 or 180°).
pub const MIN_TANGENTIAL: f64 = 0.2;

/// How far a contact corner's normal may turn into its wall beyond the prescribed normal's
/// own turn (n·n_w > min(cos θ, 0) − this, n_w the wall's normal into the fluid): the 120°
/// rise's corners measured n·n_w = −0.13, the bottom particles of a spreading 40° foot −0.3
/// to −0.8 ([`Wetting::find_corners`]). At θ > 90° the prescribed normal itself turns into
/// the wall (n·n_w = cos θ, −0.5 at 120°), so a fixed bound of −0.25 refused the corner
/// that closes a 120° contact line.
const INTO_WALL: f64 = 0.25;

/// How far from a non-wetting flat face (θ > 90°, in spacings) NS particles take the
/// exposure test ([`Wetting::is_exposed`]).
const EXPOSED_REACH: f64 = 2.5;

/// How the contact particle's own curvature is found (`experimental.contact_curvature`; module
/// docs).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum ContactCurvature {
    /// Its parabola, fitted to the real surface and its continuation beyond the wall, as for
    /// every other particle near the contact line.
    #[default]
    Fit,
    /// The circle that leaves the wall at θ and passes through its surface neighbours
    /// ([`ContactLine::turned_curvature`]).
    Turn,
}

/// `[scheme.wetting]`: how a contact angle acts on the surface's shape (module docs).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields, default)]
pub struct WettingSettings {
    /// `fit` (the contact particle's parabola over the real surface and its continuation
    /// beyond the wall) or `turn` (the circle leaving the wall at θ through its surface
    /// neighbours, which acts at any error of the angle).
    pub curvature: ContactCurvature,
    /// `centres` (the curve through the surface particles' centres meets the wall at θ) or
    /// `surface` (the surface half a spacing beyond them does, whose curvature the capillary
    /// pressure takes).
    pub angle_at: ContactAngleAt,
}

/// Which curve meets the wall at θ (`experimental.contact_angle_at`; module docs).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum ContactAngleAt {
    /// The curve through the FS particles' centres.
    #[default]
    Centres,
    /// The surface half a spacing beyond the centres, whose curvature the capillary pressure
    /// takes ([`super::tension`]): the centres' curve meets the wall at θ_c with
    /// cos θ_c = cos θ (1 + κ_c δr/2) ([`ContactLine::for_curvature`]).
    Surface,
}

/// The largest |cos θ_c| a contact line is turned to (θ_c within 11.5° of the wall).
const MAX_COS: f64 = 0.98;

/// A contact particle's line: its distance from the wall, the surface normal m the angle
/// prescribes, the tangent perpendicular to m that leads away from the wall along the real
/// surface, the wall point w (relative to the particle) the reflection line passes
/// through, and the wall's unit normal into the fluid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLine {
    pub distance: f64,
    pub normal: Vec2,
    pub along: Vec2,
    pub wall_point: Vec2,
    pub wall_normal: Vec2,
    /// cos θ, the wall's prescribed angle.
    pub cos_theta: f64,
    /// How far beyond the centres the curve lies that meets the wall at θ: 0 or δr/2
    /// ([`ContactAngleAt`]).
    pub offset: f64,
}

impl ContactLine {
    /// The continuation of the surface point `q` (relative to the contact particle) beyond
    /// the wall: its reflection across the line through w along m, for points on the real
    /// side (None for the others).
    pub fn continuation(&self, q: Vec2) -> Option<Vec2> {
        let r = q - self.wall_point;
        (r.dot(&self.along) > 0.0)
            .then(|| self.wall_point + 2.0 * r.dot(&self.normal) * self.normal - r)
    }

    /// Whether the surface point `q` (relative to the contact particle) lies on the real
    /// side of the reflection line (or on it).
    pub fn on_real_side(&self, q: Vec2) -> bool {
        (q - self.wall_point).dot(&self.along) >= 0.0
    }

    /// The curvature (of the curve through the centres) of the circle that leaves the wall
    /// at θ and passes through the contact particle's surface neighbours `ahead`: points
    /// relative to it with their weights, those ahead of it along the surface (q·t > 0, t
    /// the prescribed tangent [`Self::along`]). None with fewer than two, or where the
    /// surface turns back on itself (more than 90° from t).
    ///
    /// On a circle of curvature κ the direction from c to the weighted centroid of points
    /// at arc lengths s_k from c turns from the tangent at c by κΣw s²/(2Σw s) (to leading
    /// order), and the tangent at c from the wall's by κ s₁, s₁ the arc from the wall to c.
    /// So the turn φ from t to that direction gives κ = −φ/(s₁ + Σw s²/(2Σw s)) (positive
    /// where the surface bends away from m, as on a drop). A surface leaving the wall at θ
    /// with curvature κ reaches the distance d at s₁ = (θ − arccos(cos θ + κd))/κ; s₁ starts
    /// at |w| = d/sin θ and two fixed-point steps follow (unit test: κ within 0.5 % on
    /// circles of radius 5.8δr to 20δr at θ = 30°, 60°, 120°, d = 0.3δr to 0.8δr). The turn
    /// is linear in the angle's error: a flat surface meeting a wall at 90° where θ = 30°
    /// turns by 60°.
    pub fn turned_curvature(&self, ahead: impl Iterator<Item = (Vec2, f64)>) -> Option<f64> {
        let (mut sum, mut ws, mut ws2, mut count) = (Vec2::zeros(), 0.0, 0.0, 0);
        for (q, w) in ahead.filter(|&(q, w)| w > 0.0 && q.dot(&self.along) > 0.0) {
            let s = q.norm();
            sum += w * q;
            ws += w * s;
            ws2 += w * s * s;
            count += 1;
        }
        if count < 2 || sum.norm() == 0.0 {
            return None;
        }
        let (u, half) = (sum.normalize(), 0.5 * ws2 / ws);
        let kappa = self.turn_curvature(u, half)?;
        if self.offset == 0.0 {
            return Some(kappa);
        }
        // The surface's angle: κ solves κ = G(κ), G the curvature of the line turned to
        // θ_c(κ); G' ≈ (δr/2) cot θ/(s₁ + Σw s²/(2Σw s)), about 0.4 at 30°, so secant steps.
        let g = |k: f64| self.for_curvature(k).turn_curvature(u, half).map(|g| g - k);
        let (mut k0, mut f0) = (kappa, g(kappa)?);
        let mut k1 = k0 + f0;
        for _ in 0..8 {
            let f1 = g(k1)?;
            if f1.abs() <= 1e-10 * (1.0 + k1.abs()) || f1 == f0 {
                break;
            }
            (k0, f0, k1) = (k1, f1, k1 - f1 * (k1 - k0) / (f1 - f0));
        }
        Some(k1)
    }

    /// The curvature of the circle that leaves the wall along this line and whose chord from
    /// c to the weighted centroid of its neighbours ahead has direction `u`, `half` being
    /// Σw s²/(2Σw s) ([`Self::turned_curvature`]). None where the surface turns back.
    fn turn_curvature(&self, u: Vec2, half: f64) -> Option<f64> {
        let turn = u.dot(&self.normal).atan2(u.dot(&self.along));
        if turn.abs() > std::f64::consts::FRAC_PI_2 {
            return None;
        }
        let cos = self.normal.dot(&self.wall_normal);
        let theta = self.along.dot(&self.wall_normal).atan2(cos);
        let d = self.distance;
        let mut kappa = -turn / (self.wall_point.norm() + half);
        for _ in 0..2 {
            if (kappa * d).abs() < 1e-9 {
                break;
            }
            let arc = (theta - (cos + kappa * d).clamp(-1.0, 1.0).acos()) / kappa;
            kappa = -turn / (arc + half);
        }
        Some(kappa)
    }

    /// The line of a curve through the centres whose parallel curve [`Self::offset`] further
    /// out meets the wall at the prescribed θ, where the centres' curve has curvature `kappa`
    /// at the contact (positive as on a drop): it meets the wall at θ_c with
    /// cos θ_c = cos θ (1 + κ offset). On a circle of radius R_s meeting the wall at θ its
    /// centre lies R_s |cos θ| from the wall, and the centres' curve is the concentric circle
    /// of radius R_s ∓ offset (convex, concave), so cos θ_c = cos θ R_s/R_c, and
    /// R_s/R_c = 1 + κ offset. At θ = 30° between plates d = 10δr apart (R_s = 5.8δr) θ_c
    /// is 37.2°: held at 30°, the centres' curve put the surface at 20.6° and the column
    /// 9 % above Jurin's height. The same line with offset 0.
    pub fn for_curvature(&self, kappa: f64) -> ContactLine {
        if self.offset == 0.0 {
            return *self;
        }
        let cos_c = (self.cos_theta * (1.0 + kappa * self.offset)).clamp(-MAX_COS, MAX_COS);
        let now = self.normal.dot(&self.wall_normal).clamp(-1.0, 1.0).acos();
        // m(θ) = n_w cos θ + t_w sin θ, t(θ) = n_w sin θ − t_w cos θ: dm/dθ = −t, dt/dθ = m.
        let (sin, cos) = (cos_c.acos() - now).sin_cos();
        let normal = self.normal * cos - self.along * sin;
        let along = self.along * cos + self.normal * sin;
        let to_wall = self.distance / along.dot(&self.wall_normal).max(MIN_TANGENTIAL);
        ContactLine {
            normal,
            along,
            wall_point: -to_wall * along,
            ..*self
        }
    }
}

/// A wall and the contact angle at its flat faces (cos θ, sin θ).
#[derive(Clone, Copy, Debug)]
struct WettedWall {
    shape: Shape,
    cos: f64,
    sin: f64,
}

/// The contact angles of a scene at its flat walls, and the contact lines of the last step.
#[derive(Clone, Debug)]
pub struct Wetting {
    /// The walls the angles hold at (only their flat faces count, [`Shape::face`]).
    walls: Vec<WettedWall>,
    /// How near a wall an FS particle must be to be a contact particle: 1.5δr (the first
    /// layer's centres are δr/2 from the wall). Within δr, a drop beading towards 120°
    /// (R/δr = 20) lost its contact lines at t ≈ 2: its lowest FS particle stood 1.1δr above
    /// the plate, the particle under it (0.67δr up) being interior, and the drop stayed at
    /// 101° with a vertical foot and no condition on it.
    reach: f64,
    /// The contact line of each FS particle in reach of a wall, None elsewhere.
    pub lines: Vec<Option<ContactLine>>,
    /// δr.
    spacing: f64,
    /// Scratch of [`Self::find_corners`].
    corners: Vec<bool>,
    /// Scratch of [`Self::find_hollows`].
    hollows: Vec<bool>,
    /// How the contact particle's own curvature is found.
    pub curvature: ContactCurvature,
    /// How far beyond the centres the curve lies that meets the wall at θ (0 or δr/2).
    offset: f64,
}

impl Wetting {
    /// The angle `theta` (radians, through the liquid) at the flat faces of `walls`, for
    /// particles of spacing `spacing`.
    #[cfg(test)]
    pub fn new(theta: f64, walls: Vec<Shape>, spacing: f64) -> Self {
        let walls = walls.into_iter().map(|w| (w, theta)).collect();
        Self::per_wall(walls, spacing, WettingSettings::default())
    }

    /// Each wall's own angle (radians, through the liquid) at its flat faces, for particles
    /// of spacing `spacing`, the contact particle's curvature and the curve the angle holds
    /// for as `settings` say.
    pub fn per_wall(walls: Vec<(Shape, f64)>, spacing: f64, settings: WettingSettings) -> Self {
        let walls = walls
            .into_iter()
            .map(|(shape, theta)| WettedWall {
                shape,
                cos: theta.cos(),
                sin: theta.sin(),
            })
            .collect();
        Self {
            walls,
            reach: 1.5 * spacing,
            lines: Vec::new(),
            spacing,
            corners: Vec::new(),
            hollows: Vec::new(),
            curvature: settings.curvature,
            offset: match settings.angle_at {
                ContactAngleAt::Centres => 0.0,
                ContactAngleAt::Surface => 0.5 * spacing,
            },
        }
    }

    /// Whether the angle holds for the surface beyond the centres ([`ContactAngleAt`]).
    pub fn at_surface(&self) -> bool {
        self.offset > 0.0
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.lines)
            + crate::engine::vec_bytes(&self.walls)
            + crate::engine::vec_bytes(&self.corners)
            + crate::engine::vec_bytes(&self.hollows)
    }

    /// Marks in [`Self::corner_buffer`] the contact corners among the particles at `points`
    /// (the fluid positions, the rows of `list`): a particle in a wall's first layer
    /// (within δr of a flat face) that (36) left out of FS although it closes the surface
    /// at the wall: no fluid of the first layer lies ahead of it along the wall towards the
    /// gas (by more than δr/4). Which way the gas lies is read from its normal (39), which
    /// must be well defined (near the surface), not along the wall's normal, and not turned
    /// into the wall by more than [`INTO_WALL`] beyond the prescribed normal. At a
    /// non-wetting wall the particles [`Self::is_exposed`] finds join too. Whether any was
    /// found.
    ///
    /// (36) misses such a particle: its mirrors fill the wall's side of its support, and a
    /// surface particle beside it fills the rest enough; the exposure test is not applied
    /// near walls ([`crate::engine::free_surface::detection`]), and here the particle beside
    /// it lies in its scan region. Measured in the 120° capillary rise
    /// (`cases/capillary-rise.toml`, t = 6): the gap's surface row ended 1.27δr from the
    /// plate, the particle beside it at 0.73δr and 0.4δr lower had ⟨∇·r⟩ = 1.44 against the
    /// threshold 1.34 and C = 0.87, took an interior row, and its PPE pressure, hydrostatic
    /// under the row, closed the surface at the wall: the angle acted on nothing and the
    /// column stood at −0.09 against Jurin's −0.625.
    ///
    /// Without the bound on the normal the bottom particles of a spreading foot, with two
    /// neighbours within 1.6δr, both above them, and normals turned into the plate, were
    /// taken (the sessile drop at θ = 40°, R/δr = 20: n·n_w = −0.3 to −0.8; a particle was
    /// thrown out of the box). The bound is empirical: the rise's corners measured −0.13.
    pub fn find_corners(
        &mut self,
        points: &[Vec2],
        list: &NeighbourList,
        surface: &FreeSurface,
    ) -> bool {
        let n = list.rows();
        let mut corners = std::mem::take(&mut self.corners);
        corners.resize(n, false);
        let this = &*self;
        corners.par_iter_mut().enumerate().for_each(|(i, corner)| {
            *corner = surface.is_near_with_normal(i)
                && (this.is_corner(i, points, list, surface)
                    || this.is_exposed(i, points, list, surface));
        });
        self.corners = corners;
        self.corners.iter().any(|&c| c)
    }

    /// The flags of the last [`Self::find_corners`].
    pub fn corner_buffer(&self) -> &[bool] {
        &self.corners
    }

    /// Whether particle i, an NS particle with a well-defined normal, is a contact corner
    /// ([`Self::find_corners`]): no fluid of its layer ahead, its normal not turned into the
    /// wall.
    fn is_corner(
        &self,
        i: usize,
        points: &[Vec2],
        list: &NeighbourList,
        surface: &FreeSurface,
    ) -> bool {
        self.in_layer(i, points, list, surface)
            .is_some_and(|(ahead, into_wall)| !ahead && !into_wall)
    }

    /// Marks in [`Self::hollow_buffer`] the FS particles of (36) (not the corners or exposed
    /// particles added after it) that lie under a hollow rather than on the surface: in a
    /// wall's first layer, with fluid of that layer ahead of them towards the gas (the
    /// contact line lies further along the wall) and a normal turned into the wall beyond
    /// the angle's own turn ([`INTO_WALL`], as for the corners). Whether any was found.
    ///
    /// Measured in `cases/capillary-rise.toml` at 30° with `contact_angle_at = "surface"`:
    /// on the plates' outer faces the surface row climbed the wall as a single crowded row
    /// (0.6δr apart) over a hollow 2.7δr deep between it and the wall (present from t ≈ 3).
    /// At t = 31.45 the particle at the hollow's floor, 0.58δr from the wall, crossed (36)'s
    /// threshold (⟨∇·r⟩ 1.304 → 1.300, the threshold's floor 1.3) with its normal (39)
    /// pointing up into the hollow and the wall (n·n_w = −0.56). Its facing FS neighbours
    /// were the row across the hollow, lying along its normal (tangential offsets 1.7–2.0δr,
    /// normal ones 0.2–2.9δr), and the parabola through them gave κ = +1.54 (a convex
    /// surface), a Dirichlet pressure of +0.39 among neighbours at −0.33 to −0.46: the
    /// meniscus was thrown off the wall and the run broke down at t = 32.3.
    pub fn find_hollows(
        &mut self,
        points: &[Vec2],
        list: &NeighbourList,
        surface: &FreeSurface,
    ) -> bool {
        let n = list.rows();
        let mut hollows = std::mem::take(&mut self.hollows);
        hollows.resize(n, false);
        let this = &*self;
        hollows.par_iter_mut().enumerate().for_each(|(i, hollow)| {
            *hollow = surface.on_surface[i]
                && surface.margin[i].is_finite()
                && this
                    .in_layer(i, points, list, surface)
                    .is_some_and(|(ahead, into_wall)| ahead && into_wall);
        });
        self.hollows = hollows;
        self.hollows.iter().any(|&h| h)
    }

    /// The flags of the last [`Self::find_hollows`].
    pub fn hollow_buffer(&self) -> &[bool] {
        &self.hollows
    }

    /// Particle i's place in the first layer of its nearest flat face (within δr of it):
    /// whether fluid of that layer lies ahead of it along the wall towards the gas (by more
    /// than δr/4; which way the gas lies is read from its normal (39)), and whether its
    /// normal turns into the wall beyond the angle's own turn (n·n_w ≤ min(cos θ, 0) −
    /// [`INTO_WALL`]). None outside the layer or where the normal lies along the wall's.
    fn in_layer(
        &self,
        i: usize,
        points: &[Vec2],
        list: &NeighbourList,
        surface: &FreeSurface,
    ) -> Option<(bool, bool)> {
        let layer = self.spacing;
        let (distance, wall_normal, wall) = self.nearest_face(&points[i], layer)?;
        let tangent = Vec2::new(-wall_normal.y, wall_normal.x);
        let toward_gas = surface.normal[i].dot(&tangent);
        if toward_gas.abs() < MIN_TANGENTIAL {
            return None;
        }
        let t_g = tangent * toward_gas.signum();
        let n = list.rows();
        let layer_ahead = list.range(i).any(|k| {
            let r = -list.rij[k];
            (list.index[k] as usize) < n
                && r.dot(&t_g) > 0.25 * layer
                && distance + r.dot(&wall_normal) < layer
        });
        let into_wall = surface.normal[i].dot(&wall_normal) <= wall.cos.min(0.0) - INTO_WALL;
        Some((layer_ahead, into_wall))
    }

    /// Whether particle i, an NS particle from δr to [`EXPOSED_REACH`] spacings from a
    /// non-wetting flat face (θ > 90°) whose normal (39) turns towards that face
    /// (n·n_w < 0), is exposed:
    /// the scan region of Marrone et al. (2010) about its normal holds no neighbour.
    /// [`crate::engine::free_surface::detection`] skips this test within about 2.5δr of any
    /// wall, and there (36) misses exactly these particles: where the surface faces the wall
    /// (a depressed meniscus, θ > 90°), the wall's mirrors lie on the gas side of it and
    /// fill the support. Measured in the 120° capillary rise (t = 40, the corner alone): the
    /// row 1.5δr and 2.1δr from the plate, ⟨∇·r⟩ 1.41 and 1.57 with nothing above, was
    /// interior and the column stalled at −0.25 (Jurin −0.625). Where the surface faces
    /// away from the wall the mirrors lie under the liquid and (36) sees the surface. At a
    /// wetting wall the test is left off: taken there it flagged particles of the 40°
    /// sessile drop's thin foot on and off and kicked the drop at rest to speeds of
    /// 0.004–0.065 (0.0001 without), and 0.18 when only the normals facing the plate took
    /// it (the foot's tip turns down).
    fn is_exposed(
        &self,
        i: usize,
        points: &[Vec2],
        list: &NeighbourList,
        surface: &FreeSurface,
    ) -> bool {
        let reach = EXPOSED_REACH * self.spacing;
        self.nearest_face(&points[i], reach)
            .is_some_and(|(d, n_w, wall)| {
                wall.cos < 0.0 && d >= self.spacing && surface.normal[i].dot(&n_w) < 0.0
            })
            && crate::engine::free_surface::detection::scan_region_empty(
                list,
                i,
                surface.normal[i],
                self.spacing,
            )
    }

    /// The contact lines of the FS particles at `points` (the fluid positions).
    pub fn update(&mut self, points: &[Vec2], surface: &FreeSurface) {
        // Filled in place (the buffer is reused from step to step).
        let mut lines = std::mem::take(&mut self.lines);
        lines.resize(surface.on_surface.len(), None);
        let this = &*self;
        lines.par_iter_mut().enumerate().for_each(|(i, line)| {
            *line = surface.on_surface[i]
                .then(|| this.line(&points[i], surface.normal[i]))
                .flatten();
        });
        self.lines = lines;
    }

    /// The flat face nearest `p` among those less than `within` from it (on the fluid's
    /// side): `p`'s distance from it, its unit normal into the fluid and its wall.
    fn nearest_face(&self, p: &Vec2, within: f64) -> Option<(f64, Vec2, &WettedWall)> {
        self.walls
            .iter()
            .filter_map(|w| w.shape.face(p).map(|(d, normal)| (d, normal, w)))
            .filter(|&(d, _, _)| (0.0..within).contains(&d))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// The contact line of an FS particle at `p` with normal (39) `n`, at the nearest flat
    /// face in reach.
    fn line(&self, p: &Vec2, n: Vec2) -> Option<ContactLine> {
        let (distance, wall_normal, wall) = self.nearest_face(p, self.reach)?;
        let tangent = Vec2::new(-wall_normal.y, wall_normal.x);
        let toward_gas = n.dot(&tangent);
        if toward_gas.abs() < MIN_TANGENTIAL {
            return None;
        }
        let t_w = tangent * toward_gas.signum();
        let m = wall_normal * wall.cos + t_w * wall.sin;
        let mut along = Vec2::new(-m.y, m.x);
        if along.dot(&wall_normal) < 0.0 {
            along = -along;
        }
        // Back along the surface to the wall (along·n_w = sin θ ≥ sin 15°).
        let to_wall = distance / along.dot(&wall_normal).max(MIN_TANGENTIAL);
        Some(ContactLine {
            distance,
            normal: m,
            along,
            wall_point: -to_wall * along,
            wall_normal,
            cos_theta: wall.cos,
            offset: self.offset,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::Plane;
    use std::f64::consts::FRAC_PI_2;

    fn vertical_wall() -> Shape {
        // x = 0, fluid at x > 0.
        Shape::Plane(Plane {
            axis: 0,
            position: 0.0,
            fluid_side: 1.0,
        })
    }

    /// The fluid particles `fluid` of spacing `dr` beside the wall x = 0 with their mirrors
    /// across it (fluid first), their neighbour list and their free surface (36)–(39).
    fn beside_wall(fluid: &[Vec2], dr: f64) -> (Vec<Vec2>, NeighbourList, FreeSurface) {
        use crate::engine::kernel::QuinticSpline;
        use crate::engine::neighbours::{Domain, NeighbourSearch};
        use crate::engine::operators::KernelSums;
        let kernel = QuinticSpline::for_spacing(dr);
        let n = fluid.len();
        let mut points = fluid.to_vec();
        points.extend(fluid.iter().map(|p| Vec2::new(-p.x, p.y)));
        let domain = Domain {
            min: Vec2::new(-2.0, 0.0),
            max: Vec2::new(2.0, 2.0),
            periodic: [false, false],
        };
        let mut list = NeighbourList::default();
        NeighbourSearch::new().build(&domain, &points, n, kernel.support(), &mut list);
        let mut sums = KernelSums::default();
        sums.update(&list, &kernel, dr * dr);
        let mut fs = FreeSurface::default();
        fs.detect(&list, &sums, &kernel);
        (points, list, fs)
    }

    /// At a vertical wall with the liquid to its right and the gas above, θ = 30° asks for the
    /// surface normal m = (cos θ, sin θ): the real surface leaves the wall downwards, 60°
    /// below the horizontal (a meniscus drawn up the wall).
    #[test]
    fn contact_normal_and_continuation_at_a_vertical_wall() {
        let theta = 30f64.to_radians();
        let w = Wetting::new(theta, vec![vertical_wall()], 0.1);
        let line = w
            .line(&Vec2::new(0.05, 1.0), Vec2::new(0.3, 1.0).normalize())
            .unwrap();
        assert!((line.normal - Vec2::new(theta.cos(), theta.sin())).norm() < 1e-12);
        assert!((line.along - Vec2::new(theta.sin(), -theta.cos())).norm() < 1e-12);
        // The wall point: back from the particle along the surface to x = 0.
        assert!(
            (line.wall_point.x + 0.05).abs() < 1e-12,
            "{:?}",
            line.wall_point
        );
        // A point on the real surface at 60° below the horizontal is continued along the
        // same straight line behind the wall: a surface at θ is smooth through w.
        let q = line.along * 0.2;
        let image = line.continuation(q).unwrap();
        let w = line.wall_point;
        assert!((image - w + (q - w)).norm() < 1e-12, "{image:?}");
        // A horizontal surface is continued upwards behind the wall: a corner whose
        // curvature is negative (the liquid is drawn up).
        let image = line.continuation(Vec2::new(0.2, 0.0)).unwrap();
        assert!(image.y > w.y + 0.1, "{image:?}");
        assert!(line.continuation(w - line.along * 0.2).is_none());
    }

    /// The circular arc of `radius` leaving the wall point (0, 0) of the wall x = 0 at `theta`,
    /// along t = (sin θ, −cos θ), bending towards m = (cos θ, sin θ) (concave, `bend` 1) or
    /// away from it (convex, −1), by its arc length.
    fn meniscus_arc(theta: f64, radius: f64, bend: f64) -> impl Fn(f64) -> Vec2 {
        let (t, m) = (
            Vec2::new(theta.sin(), -theta.cos()),
            Vec2::new(theta.cos(), theta.sin()),
        );
        move |s: f64| {
            let a = s / radius;
            t * radius * a.sin() + m * bend * radius * (1.0 - a.cos())
        }
    }

    /// The arc length at which `arc` reaches the distance `d` from the wall (bisection).
    fn arc_reaching(arc: &impl Fn(f64) -> Vec2, d: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 8.0);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if arc(mid).x < d {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// [`ContactLine::turned_curvature`] on the surface through the centres of a circular
    /// meniscus meeting the vertical wall x = 0 at θ (concave below 90°, convex above),
    /// the contact particle d from the wall and its neighbours δr apart along the arc,
    /// weighted by W: κR = 1 within 0.5 % (its leading-order error; measured 0.2 %). A
    /// flat surface meeting the wall square where θ = 30° turns by 60°: strongly concave.
    #[test]
    fn the_turned_curvature_of_a_circular_meniscus() {
        use crate::engine::kernel::QuinticSpline;
        let dr = 1.0;
        let kernel = QuinticSpline::for_spacing(dr);
        for theta in [30f64, 60.0, 120.0] {
            let theta = theta.to_radians();
            let w = Wetting::new(theta, vec![vertical_wall()], dr);
            for radius in [5.8, 10.0, 20.0] {
                for d in [0.3, 0.5, 0.8] {
                    // The arc leaves the wall point (0, 0) along t = (sin θ, −cos θ),
                    // bending towards m (concave) or away from it (convex).
                    let bend = if theta < FRAC_PI_2 { 1.0 } else { -1.0 };
                    let m = Vec2::new(theta.cos(), theta.sin());
                    let arc = meniscus_arc(theta, radius, bend);
                    let lo = arc_reaching(&arc, d);
                    let c = arc(lo);
                    let line = w.line(&c, m).unwrap();
                    let ahead = (1..4).map(|k| {
                        let q = arc(lo + k as f64 * dr) - c;
                        (q, kernel.value(q.norm()))
                    });
                    let kappa = line.turned_curvature(ahead).unwrap();
                    let error = kappa * radius + bend;
                    assert!(error.abs() < 5e-3, "θ {theta} R {radius} d {d}: {error}");
                }
            }
        }
        let w = Wetting::new(30f64.to_radians(), vec![vertical_wall()], dr);
        let line = w.line(&Vec2::new(0.95, 0.0), Vec2::new(0.0, 1.0)).unwrap();
        let flat = (1..4).map(|k| (Vec2::new(k as f64, 0.0), 1.0));
        let kappa = line.turned_curvature(flat).unwrap();
        // 60° over an arc of about 1.9δr + the neighbours' 1.2δr.
        assert!(kappa < -0.25, "{kappa}");
    }

    /// With the angle at the surface (`contact_angle_at = "surface"`) the centres lie on the
    /// circle concentric with the surface's, δr/2 further in (radius R_s ± δr/2), which meets
    /// the wall at θ_c, cos θ_c = cos θ R_s/R_c: the turned curvature of that circle is
    /// 1/R_c within 0.5 % (as the centres' rule on its own circles), and its line's normal
    /// makes θ_c with the wall (measured: within 0.24 %). The centres' rule reads the same
    /// points as a circle that left the wall at θ and turned since, 47 % more concave at
    /// θ = 30° and 23 % more curved at 60° and 120°: the pull of a contact angle 7° or 2° off.
    #[test]
    fn the_surface_angle_turns_the_centres_curve() {
        use crate::engine::kernel::QuinticSpline;
        let dr = 1.0;
        let kernel = QuinticSpline::for_spacing(dr);
        let walls = |theta: f64| vec![(vertical_wall(), theta)];
        for theta in [30f64, 60.0, 120.0] {
            let theta = theta.to_radians();
            let at_surface = Wetting::per_wall(
                walls(theta),
                dr,
                WettingSettings {
                    angle_at: ContactAngleAt::Surface,
                    ..WettingSettings::default()
                },
            );
            let at_centres = Wetting::new(theta, vec![vertical_wall()], dr);
            let bend = if theta < FRAC_PI_2 { 1.0 } else { -1.0 };
            for surface_radius in [5.8, 10.0, 20.0] {
                let radius = surface_radius + bend * 0.5 * dr;
                let theta_c = (theta.cos() * surface_radius / radius).acos();
                let m = Vec2::new(theta_c.cos(), theta_c.sin());
                let arc = meniscus_arc(theta_c, radius, bend);
                let lo = arc_reaching(&arc, 0.5 * dr);
                let (c, arc) = (arc(lo), &arc);
                let ahead = || {
                    (1..4).map(move |k| {
                        let q = arc(lo + k as f64 * dr) - c;
                        (q, kernel.value(q.norm()))
                    })
                };
                let line = at_surface.line(&c, m).unwrap();
                let kappa = line.turned_curvature(ahead()).unwrap();
                let error = kappa * radius + bend;
                assert!(error.abs() < 5e-3, "θ {theta} R {surface_radius}: {error}");
                let turned = line.for_curvature(kappa);
                assert!((turned.normal.dot(&turned.wall_normal) - theta_c.cos()).abs() < 5e-3);
                let centres = at_centres.line(&c, m).unwrap().turned_curvature(ahead());
                let biased = centres.unwrap() * radius + bend;
                if surface_radius < 6.0 && theta < FRAC_PI_2 {
                    assert!(biased.abs() > 0.03, "θ {theta}: the centres' rule {biased}");
                }
            }
        }
    }

    /// θ = 120° at the same wall: m points into the wall's side, the real surface rises away
    /// from the wall (a depressed meniscus).
    #[test]
    fn a_non_wetting_angle_depresses_the_surface() {
        let theta = 120f64.to_radians();
        let w = Wetting::new(theta, vec![vertical_wall()], 0.1);
        let line = w.line(&Vec2::new(0.05, 1.0), Vec2::new(0.0, 1.0)).unwrap();
        assert!(line.normal.x < 0.0 && line.normal.y > 0.0);
        assert!(line.along.x > 0.0 && line.along.y > 0.0);
    }

    /// No contact line beyond 1.5 spacings, nor where the surface lies along the wall.
    #[test]
    fn contact_lines_only_where_the_surface_meets_the_wall() {
        let w = Wetting::new(1.0, vec![vertical_wall()], 0.1);
        assert!(w.line(&Vec2::new(0.2, 1.0), Vec2::new(0.0, 1.0)).is_none());
        assert!(w
            .line(&Vec2::new(0.05, 1.0), Vec2::new(-1.0, 0.05))
            .is_none());
    }

    /// A block of liquid beside the wall x = 0 whose top row stops 1.27δr from it, the
    /// particle beside the wall 0.4δr lower (the 120° capillary rise's corner, module docs
    /// of [`Wetting::find_corners`]): (36) takes it for interior, the corner test gives it
    /// to FS; no other particle is a corner, and none at all in the plain block.
    #[test]
    fn the_particle_closing_the_surface_at_a_wall_is_a_corner() {
        let dr = 0.1;
        // As measured at t = 6: the row's end 1.27δr from the plate, the corner 0.73δr from
        // it and 0.4δr under the row, the two particles under the corner 0.57δr and 1.37δr
        // lower (the plate's column compressed).
        let (corner, end) = (
            Vec2::new(0.73 * dr, 9.1 * dr),
            Vec2::new(1.27 * dr, 9.5 * dr),
        );
        let block = |lowered: bool| -> Vec<Vec2> {
            let mut fluid: Vec<Vec2> = (0..16)
                .flat_map(|i| (0..10).map(move |j| (i, j)))
                .filter(|&(i, j)| !(lowered && i == 0 && j >= 8))
                .map(|(i, j)| Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
                .collect();
            if lowered {
                fluid.retain(|p| (p - Vec2::new(1.5 * dr, 9.5 * dr)).norm() > 1e-9);
                fluid.retain(|p| !(p.x < dr && p.y > 6.9 * dr));
                fluid.push(Vec2::new(0.56 * dr, 7.73 * dr));
                fluid.push(Vec2::new(0.6 * dr, 8.53 * dr));
                fluid.push(end);
                fluid.push(corner);
            }
            fluid
        };
        let corners = |fluid: &[Vec2]| {
            let n = fluid.len();
            let (points, list, fs) = beside_wall(fluid, dr);
            let mut w = Wetting::new(2.0, vec![vertical_wall()], dr);
            w.find_corners(&points[..n], &list, &fs);
            (fs, w.corner_buffer().to_vec())
        };
        let lowered = block(true);
        let (fs, found) = corners(&lowered);
        let c = lowered.len() - 1;
        // Its normal lies along the wall (n·n_w = 0.009).
        assert!(fs.normal[c].x.abs() < INTO_WALL);
        let flagged: Vec<usize> = (0..lowered.len()).filter(|&i| found[i]).collect();
        assert_eq!(flagged, vec![c]);
        let (_, found) = corners(&block(false));
        assert!(found.iter().all(|&f| !f));
    }

    /// The hollow of the 30° capillary rise's outer faces (module docs of
    /// [`Wetting::find_hollows`]; positions as measured at t = 31.45, in spacings from the
    /// wall, the contact particle at height 10): a single surface row climbing the wall at
    /// 45° over a hollow 2.7δr deep, the particle at its floor 0.58δr from the wall. That
    /// particle, which (36) puts in FS with its normal into the wall, is the one hollow; the
    /// row is not, nor is anything once the hollow is filled.
    #[test]
    fn the_particle_under_a_hollow_leaves_the_surface() {
        let dr = 0.1;
        let floor = Vec2::new(0.58, 6.65) * dr;
        let block = |filled: bool| -> Vec<Vec2> {
            let mut fluid: Vec<Vec2> = (0..16)
                .flat_map(|i| (0..if i < 1 { 6 } else { 7 }).map(move |j| (i, j)))
                .map(|(i, j)| Vec2::new(i as f64 + 0.5, j as f64 + 0.5) * dr)
                .collect();
            let row = [
                (0.32, 10.0),
                (0.84, 9.31),
                (1.27, 8.83),
                (1.67, 8.38),
                (2.17, 7.91),
                (2.68, 7.42),
                (3.27, 6.93),
            ];
            fluid.extend(row.iter().map(|&(x, y)| Vec2::new(x, y) * dr));
            fluid.push(floor);
            if filled {
                fluid.extend(
                    [(0.5, 7.6), (0.5, 8.5), (1.4, 7.6)].map(|(x, y)| Vec2::new(x, y) * dr),
                );
            }
            fluid
        };
        // (36) put the floor in FS at its threshold (⟨∇·r⟩ 1.300 against a floor of 1.3 in
        // the sparse pool); in this small block it reads 1.52 against 1.4, so the test puts
        // it there as (36) did there. Its normal (39), from its neighbours, is the measured
        // kind: up into the hollow and into the wall.
        let hollows = |fluid: &[Vec2]| -> (Vec2, Vec<usize>) {
            let n = fluid.len();
            let (points, list, mut fs) = beside_wall(fluid, dr);
            let f = fluid.iter().position(|&p| p == floor).unwrap();
            fs.on_surface[f] = true;
            let mut w = Wetting::new(30f64.to_radians(), vec![vertical_wall()], dr);
            w.find_hollows(&points[..n], &list, &fs);
            let found = (0..n).filter(|&i| w.hollow_buffer()[i]).collect();
            (fs.normal[f], found)
        };
        let open = block(false);
        let (normal, found) = hollows(&open);
        assert!(normal.x < -INTO_WALL, "{normal:?}");
        assert_eq!(found, vec![open.iter().position(|&p| p == floor).unwrap()]);
        let (normal, found) = hollows(&block(true));
        assert!(
            normal.x > -INTO_WALL && found.is_empty(),
            "{normal:?} {found:?}"
        );
    }

    /// A block beside the wall x = 0 whose surface falls towards the wall (one row per two
    /// columns, a depressed meniscus's slope): at θ = 120° the one particle (36) misses
    /// between δr and 2.5δr from the wall is exposed; at a wetting wall (60°) none is, nor
    /// any of a plain block.
    #[test]
    fn particles_hidden_by_a_non_wetting_wall_are_exposed() {
        let dr = 0.1;
        let block = |sloped: bool| -> Vec<Vec2> {
            (0..16)
                .flat_map(|i| {
                    let rows = if sloped { 6 + (i / 2).min(4) } else { 10 };
                    (0..rows).map(move |j| Vec2::new((i as f64 + 0.5) * dr, (j as f64 + 0.5) * dr))
                })
                .collect()
        };
        let flagged = |fluid: &[Vec2], theta: f64| -> Vec<usize> {
            let n = fluid.len();
            let (points, list, fs) = beside_wall(fluid, dr);
            let w = Wetting::new(theta.to_radians(), vec![vertical_wall()], dr);
            (0..n)
                .filter(|&i| fs.is_near_with_normal(i) && w.is_exposed(i, &points[..n], &list, &fs))
                .collect()
        };
        let sloped = block(true);
        // The top of the second column, (1.5δr, 5.5δr), under the step up to the third:
        // (36) takes it for interior.
        let exposed: Vec<Vec2> = flagged(&sloped, 120.0)
            .iter()
            .map(|&i| sloped[i] / dr)
            .collect();
        assert_eq!(exposed.len(), 1, "{exposed:?}");
        assert!(
            (exposed[0] - Vec2::new(1.5, 5.5)).norm() < 1e-9,
            "{exposed:?}"
        );
        assert!(flagged(&sloped, 60.0).is_empty());
        assert!(flagged(&block(false), 120.0).is_empty());
    }

    /// Each wall keeps its own angle: 30° at x = 0, 90° (neutral) at x = 1, where the
    /// surface meets the wall square, m along the wall.
    #[test]
    fn each_wall_has_its_own_angle() {
        let right = Shape::Plane(Plane {
            axis: 0,
            position: 1.0,
            fluid_side: -1.0,
        });
        let (wetting, neutral) = (30f64.to_radians(), 90f64.to_radians());
        let angles = vec![(vertical_wall(), wetting), (right, neutral)];
        let w = Wetting::per_wall(angles, 0.1, WettingSettings::default());
        let up = Vec2::new(0.0, 1.0);
        let left = w.line(&Vec2::new(0.05, 1.0), Vec2::new(0.3, 1.0).normalize());
        assert!((left.unwrap().normal - Vec2::new(wetting.cos(), wetting.sin())).norm() < 1e-12);
        let line = w.line(&Vec2::new(0.95, 1.0), Vec2::new(0.3, 1.0).normalize());
        assert!((line.unwrap().normal - up).norm() < 1e-12);
    }
}
