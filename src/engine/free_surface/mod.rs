//! Free surfaces (King & Lind §III C–D): the optional stage of a scene with free surfaces.
//! Step 2 detects the surface and its normals ([`detection`], (36)–(39)); step 5 gives the PPE
//! rows of surface particles their Dirichlet pressure ([`pressure`], (34)–(35)), with the
//! capillary jump σκ of a surface tension ([`tension`]), or the surface tension acts as a
//! pairwise cohesion force in the momentum equation instead ([`cohesion`]). The same
//! scenes use the free-surface shifting (40)–(44) and the positive stress divergence (20).

pub mod cohesion;
pub mod detached;
pub mod detection;
pub mod pressure;
pub mod shear_free;
pub mod tension;
pub mod wetting;

/// A particle set's neighbour list, kernel sums and free surface, for the unit tests.
#[cfg(test)]
pub(crate) fn surface_of(
    domain: &crate::engine::neighbours::Domain,
    points: &[Vec2],
    dr: f64,
) -> (
    NeighbourList,
    crate::engine::operators::KernelSums,
    FreeSurface,
) {
    let kernel = QuinticSpline::for_spacing(dr);
    let mut list = NeighbourList::default();
    crate::engine::neighbours::NeighbourSearch::new().build(
        domain,
        points,
        points.len(),
        kernel.support(),
        &mut list,
    );
    let mut sums = crate::engine::operators::KernelSums::default();
    sums.update(&list, &kernel, dr * dr);
    let mut fs = FreeSurface::default();
    fs.detect(&list, &sums, &kernel);
    (list, sums, fs)
}

pub use cohesion::Cohesion;
pub use detached::{BodyInputs, DetachedBodies, DetachedMomentum};
pub use detection::{FreeSurface, NEAR_SURFACE_STRENGTH};
pub use pressure::{SurfaceGradient, SurfaceInputs, SurfacePressure, SurfacePressureRule};
pub use shear_free::{ShearFreeSurface, SurfaceShear};
pub use tension::{CapillaryTimeLevel, SurfaceTension, SurfaceTensionSettings};
pub use wetting::{ContactAngleAt, ContactCurvature, Wetting, WettingSettings};

use crate::engine::boundary::Ghosts;
use crate::engine::dimension::{Dim, Dimension, Sym, Vector};
use crate::engine::kernel::QuinticSpline;
use crate::engine::math::Vec2;
use crate::engine::neighbourhood::Hood;
use crate::engine::neighbours::NeighbourList;
use crate::engine::pressure::SurfaceRows;
use crate::engine::rheology::Fluid;
use serde::{Deserialize, Serialize};

/// How a surface tension acts (`scheme.surface_tension.form`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceTensionForm {
    /// The capillary jump σκ in the free-surface pressure's normal-stress balance
    /// ([`tension`]), the contact angle imposed on the surface's shape ([`wetting`]).
    #[default]
    NormalStress,
    /// The pairwise cohesion force of Wróblewski et al. (2008) ([`cohesion`]), the contact
    /// angle through the walls' attraction.
    Cohesion,
}

/// Which PPE row a surface particle in a wall's first half-spacing takes
/// (`experimental.contact_rows`).
///
/// An interior particle that approaches a wall is held off by the PPE: its approach
/// compresses its kernel sum with its mirrors, and its pressure rises. A surface particle's
/// pressure is the Dirichlet value of (35a), so its wall-normal motion meets only the
/// viscous drag of its own mirror (u_j = −u_i), a drag and not a constraint. Measured on the
/// jet (Oldroyd-B, Wi = 5/3, D/δr = 20): after impact the two contact-line particles crept
/// from 0.5δr to the plate in 0.04 s, one crossing it at t = 0.2335 s (validation pages, jets).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum ContactRows {
    /// Every surface particle takes its Dirichlet row (the paper's).
    #[default]
    Surface,
    /// A surface particle nearer a wall than δr/2 (half the distance to its own mirror)
    /// takes an interior row, with the wall's Neumann condition, so that the PPE holds it
    /// off the wall as it holds interior particles; one with no interior neighbour (a
    /// splash on the wall) keeps its Dirichlet row and its velocity into the wall is
    /// removed instead. Not with a contact angle, which acts through exactly those
    /// particles' Dirichlet values ([`wetting`]).
    Wall,
    /// Every surface particle keeps its Dirichlet row, as under `Surface`, and one within
    /// δr/4 of a wall loses its velocity into the wall after the projection:
    /// the no-penetration condition that the PPE imposes on interior particles there and
    /// that a Dirichlet row cannot. With a contact angle, whose Dirichlet values at the
    /// contact line it keeps: the wetting foot of a sessile drop at R/δr = 10 (θ = 40°)
    /// otherwise sank through the plate at t = 2.4. The weakly compressible scheme, which
    /// has no PPE rows, takes the hold alone (after its predictor): there a foot wetting by
    /// the walls' attraction sank through the plate at t = 0.57 (θ = 60°, R/δr = 20).
    Held,
}

/// Whether a particle is on the free surface or not, or partly (`experimental.surface_indicator`).
///
/// (36) is a threshold: a particle whose ⟨∇·r⟩ crosses it changes its PPE row from the
/// Poisson equation to the Dirichlet value of (35a) with σκ in one step, and enters its
/// neighbours' curvature fits at full weight. Measured on `cases/capillary-rise.toml` (θ =
/// 30°, validation pages): a particle under a steep meniscus that crossed it without moving went from
/// p = −0.36 to −3.48 and its outer neighbour's fitted value from −0.36 to +4.05 in that
/// step; the largest speed went from 0.03 to 0.51 five steps later.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceIndicator {
    /// FS or not, by (36) (the paper's).
    #[default]
    Sharp,
    /// A particle of FS counts with a weight s rising smoothly from 0 where (36) first takes
    /// it in to 1 at [`BLEND_WIDTH`] further in ([`FreeSurface::weight`]): in its neighbours'
    /// curvature fits with s times its kernel weight, and in its own PPE row as
    /// `(1 − s)·(Poisson row) + s·D_i·(p_i − p_D,i)`, D_i the Poisson row's diagonal
    /// ([`crate::engine::pressure::SurfaceRows`]). Particles well inside FS (s = 1) are as
    /// under `Sharp`.
    ///
    /// Blending the Dirichlet value in time instead, `s·p_D + (1 − s)·pⁿ` with a Dirichlet
    /// row, was measured first and dropped: a particle hovering on the threshold (s ≤ 0.015)
    /// relaxed towards its own, wrong, p_D over hundreds of steps (validation pages).
    Blended,
}

/// The ramp of [`SurfaceIndicator::Blended`] in ⟨∇·r⟩ (full support: 2; a flat surface's
/// first row ≈ 1.22, its second ≈ 1.74, against (36)'s threshold of 1.3–1.4). It need only
/// span how far a particle's ⟨∇·r⟩ wanders while it sits on the threshold: 0.007 for the
/// particle that hovered there at θ = 60° (`cases/capillary-rise.toml`). At 0.1, 17–23 of
/// the ~205 FS particles of the rising column lay on it, half of them below s = ½: surface
/// particles whose half-Poisson rows let the pool be kicked (speeds 0.8–0.96 by t = 4, the
/// wall's meniscus down to 0.01 by t = 10); at 0.03, 0–7, and the rise is calm (validation pages).
pub const BLEND_WIDTH: f64 = 0.03;

impl SurfaceIndicator {
    /// The ramp's width in ⟨∇·r⟩ (0: sharp).
    pub fn width(self) -> f64 {
        match self {
            SurfaceIndicator::Sharp => 0.0,
            SurfaceIndicator::Blended => BLEND_WIDTH,
        }
    }
}

/// `[scheme.free_surface]`: the free-surface condition and how its rows are built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct FreeSurfaceSettings {
    /// `normal-stress` (35a, the paper's), `normal-stress-neighbours` or `zero` Dirichlet
    /// pressure.
    pub pressure: SurfacePressure,
    /// `full` (the normal-stress pressure's ∇u* over the whole support, the paper's) or
    /// `own-side` (over the neighbours on the particle's own side of the surface).
    /// Read from `[experimental]` (`setup::experimental`), not from this table.
    #[serde(skip)]
    pub gradient: SurfaceGradient,
    /// `surface` (every surface particle a Dirichlet row, the paper's), `wall` (one within
    /// δr/2 of a wall an interior row; not with a contact angle) or `held` (Dirichlet rows,
    /// those within δr/4 of a wall held off it); see [`ContactRows`].
    /// Read from `[experimental]` (`setup::experimental`), not from this table.
    #[serde(skip)]
    pub contact_rows: ContactRows,
    /// `sharp` ((36) decides, the paper's) or `blended` (a particle (36) has just taken into
    /// FS counts partly).
    /// Read from `[experimental]` (`setup::experimental`), not from this table.
    #[serde(skip)]
    pub indicator: SurfaceIndicator,
    /// `truncated` (the Laplacian (21) on the truncated support, the paper's) or
    /// `shear-free` (plus the tangential flux of the shear-free condition).
    /// Read from `[experimental]` (`setup::experimental`), not from this table.
    #[serde(skip)]
    pub shear: SurfaceShear,
    /// `conserved` (a body of liquid detached from the rest keeps its momentum and angular
    /// momentum) or `unconstrained` (the paper's).
    pub detached_momentum: DetachedMomentum,
    /// The repulsive term of (42)–(44) in the shifting of internal particles (King & Lind:
    /// helpful for Re < 5).
    pub repulsion: bool,
}

impl Default for FreeSurfaceSettings {
    fn default() -> Self {
        Self {
            pressure: SurfacePressure::default(),
            gradient: SurfaceGradient::default(),
            contact_rows: ContactRows::default(),
            indicator: SurfaceIndicator::default(),
            shear: SurfaceShear::default(),
            detached_momentum: DetachedMomentum::default(),
            repulsion: true,
        }
    }
}

/// The scheme's free-surface choices, taken once at setup.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceOptions {
    /// The Dirichlet pressure's rule.
    pub pressure: SurfacePressure,
    /// The PPE row of a surface particle at a wall.
    pub contact_rows: ContactRows,
    /// Where in the step the capillary curvature is taken.
    pub time_level: CapillaryTimeLevel,
    /// The viscous term's tangential flux through the surface.
    pub shear: SurfaceShear,
    /// The neighbours of (35a)'s velocity gradient.
    pub gradient: SurfaceGradient,
    /// Whether surface membership is sharp or blended.
    pub indicator: SurfaceIndicator,
}

/// What the Dirichlet pressure of Step 5 reads ([`FreeSurfaceStage::dirichlet_pressure`]).
pub struct DirichletInputs<'a, const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub hood: Hood<'a, D>,
    /// The positions of the rows (fluid first).
    pub points: &'a [Vector<D>],
    pub fluid: &'a Fluid,
    /// φ = η(γ̇)/η0 of a generalised Newtonian fluid (empty: uniform).
    pub viscosity_factor: &'a [f64],
    /// u* of the fluid, then of the ghosts.
    pub velocity_star: &'a [Vector<D>],
    /// u^n, and how far in time the positions lie ahead of r^n, for the curvature's time
    /// level ([`CapillaryTimeLevel`]).
    pub velocity: &'a [Vector<D>],
    pub ahead: f64,
    /// A^{n+½}.
    pub conformation: &'a [Sym<D>],
    /// Rows whose value is prescribed (an inflow buffer).
    pub prescribed: &'a [bool],
}

/// The free-surface stage: the surface of the current step and its pressure rule.
pub struct FreeSurfaceStage {
    /// FS and NS sets and normals of the last step.
    pub surface: FreeSurface,
    rule: Box<dyn SurfacePressureRule>,
    /// The capillary jump σκ (a fluid with surface tension).
    tension: Option<SurfaceTension>,
    dirichlet: Vec<f64>,
    contact_rows: ContactRows,
    /// The PPE's Dirichlet rows: the surface, less a wall's first half-spacing under
    /// [`ContactRows::Wall`] and the rows on a blended indicator's ramp.
    rows: Vec<bool>,
    /// The rows on the ramp of [`SurfaceIndicator::Blended`], with their weights s in (0, 1).
    blended: Vec<(usize, f64)>,
    /// The surface particles in a wall's first half-spacing that keep their Dirichlet rows
    /// (under [`ContactRows::Wall`] those that join no interior row, a splash on the wall;
    /// under [`ContactRows::Held`] all within δr/4), with the wall's normal into the fluid.
    held: Vec<(usize, Vec2)>,
    /// How many times a held particle's velocity into its wall was removed.
    pub wall_holds: u64,
    spacing: f64,
    /// The shear-free flux of the viscous term ([`SurfaceShear::ShearFree`]).
    shear_free: Option<ShearFreeSurface>,
}

impl FreeSurfaceStage {
    /// The stage for the scheme's `options` and, if σ > 0, a surface tension σ on particles
    /// of spacing δr, meeting the walls at the contact angle of `wetting` if there is one.
    pub fn new(
        options: SurfaceOptions,
        surface_tension: f64,
        spacing: f64,
        wetting: Option<Wetting>,
    ) -> Self {
        let (rule, contact_rows) = (options.pressure, options.contact_rows);
        let tension = (surface_tension > 0.0).then(|| {
            let mut t = SurfaceTension::new(surface_tension, spacing, options.time_level);
            t.wetting = wetting;
            t
        });
        Self {
            surface: FreeSurface::with_blend_width(options.indicator.width()),
            rule: rule.rule(options.gradient),
            tension,
            dirichlet: Vec::new(),
            contact_rows,
            rows: Vec::new(),
            blended: Vec::new(),
            held: Vec::new(),
            wall_holds: 0,
            spacing,
            shear_free: (options.shear == SurfaceShear::ShearFree).then(ShearFreeSurface::default),
        }
    }

    /// The curvature κ of the FS particles at the last step (None without surface tension).
    pub fn curvature(&self) -> Option<&[f64]> {
        self.tension.as_ref().map(|t| t.curvature.as_slice())
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        self.surface.heap_bytes()
            + crate::engine::vec_bytes(&self.dirichlet)
            + crate::engine::vec_bytes(&self.rows)
            + crate::engine::vec_bytes(&self.blended)
            + crate::engine::vec_bytes(&self.held)
            + self.rule.heap_bytes()
            + self.tension.as_ref().map_or(0, SurfaceTension::heap_bytes)
            + self
                .shear_free
                .as_ref()
                .map_or(0, ShearFreeSurface::heap_bytes)
    }

    /// Step 4: the shear-free flux's accelerations ([`shear_free`]) from ∇u, ν and the
    /// viscosity factor (empty: uniform); None unless the scheme asks for it.
    pub fn shear_free_accelerations(
        &mut self,
        hood: Hood,
        grad_u: &[crate::engine::math::Mat2],
        nu: f64,
        factor: &[f64],
    ) -> Option<&[Vec2]> {
        let surface = &self.surface;
        self.shear_free
            .as_mut()
            .map(|s| s.accelerations(hood, surface, grad_u, nu, factor))
    }

    /// Step 2: detection (36)–(37) and normals (38)–(39), at the positions `points` (fluid
    /// first); with a contact angle, the walls' contact corners join FS
    /// ([`Wetting::find_corners`]) and the hollows under their contact lines leave it
    /// ([`Wetting::find_hollows`]). Rows in `prescribed` (an inflow buffer) take Dirichlet
    /// rows and are not near the surface themselves.
    pub fn detect(
        &mut self,
        hood: Hood,
        points: &[Vec2],
        kernel: &QuinticSpline,
        prescribed: &[bool],
    ) {
        let Hood { list, sums, .. } = hood;
        self.surface.detect(list, sums, kernel);
        if let Some(w) = self.tension.as_mut().and_then(|t| t.wetting.as_mut()) {
            if w.find_corners(points, list, &self.surface) {
                self.surface.add(w.corner_buffer(), list, sums, kernel);
            }
            if w.find_hollows(points, list, &self.surface) {
                self.surface.remove(w.hollow_buffer(), list, sums, kernel);
            }
        }
        for (i, _) in prescribed.iter().enumerate().filter(|(_, &b)| b) {
            self.surface.on_surface[i] = true;
            self.surface.near_surface[i] = false;
            self.surface.margin[i] = f64::INFINITY;
        }
    }

    /// Step 5: the Dirichlet pressure of every row (zero off the surface), from the
    /// predictor's velocity u*, a generalised Newtonian fluid's viscosity factor and
    /// A^{n+½} ([`DirichletInputs`]), plus the capillary jump σκ where the rule's value is
    /// trusted (not an inflow row, not a sparse splash: [`pressure::MIN_SURFACE_NEIGHBOURS`]).
    pub fn dirichlet_pressure(&mut self, d: &DirichletInputs) {
        let Hood { list, sums, .. } = d.hood;
        let prescribed = d.prescribed;
        let inputs = SurfaceInputs {
            list,
            sums,
            surface: &self.surface,
            viscosity_factor: d.viscosity_factor,
            velocity_star: d.velocity_star,
            fluid: d.fluid,
            conformation: d.conformation,
            prescribed,
        };
        self.dirichlet.clear();
        self.dirichlet.resize(list.rows(), 0.0);
        self.rule.pressure(&inputs, &mut self.dirichlet);
        if let Some(tension) = self.tension.as_mut() {
            let trusted = |i: usize| {
                !prescribed.get(i).copied().unwrap_or(false)
                    && list.range(i).len() >= pressure::MIN_SURFACE_NEIGHBOURS
            };
            let motion = tension::Motion {
                points: d.points,
                velocity: d.velocity,
                ahead: d.ahead,
            };
            tension.add_jump(list, motion, &self.surface, trusted, &mut self.dirichlet);
        }
    }

    /// Step 5, after [`Self::dirichlet_pressure`]: the Dirichlet values, for the projection
    /// to shift to its unknown.
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.dirichlet
    }

    /// Step 5: which rows are Dirichlet rows ([`ContactRows`]); `points` are the rows'
    /// positions (fluid, then the ghosts').
    ///
    /// A surface particle leaves its Dirichlet row only if it has an interior (non-surface)
    /// fluid neighbour, through which its row joins the bulk's, which the surface's Dirichlet
    /// rows pin. Without that test a splash lying on the wall took a row whose only links
    /// were its own mirror (which carries its pressure) and other such particles: a Neumann
    /// block with nothing to fix its level, so the PPE was singular (the Wi = 5/3 jet with
    /// the solenoidal gradient at 0.240 s: a lone particle 60δr out on the plate with one
    /// neighbour; no solver reached the tolerance, best relative residual 8·10⁵). Such a
    /// particle keeps its Dirichlet row and is held off the wall by [`Self::hold_off_walls`].
    pub fn choose_rows(&mut self, list: &NeighbourList, points: &[Vec2], ghosts: &Ghosts) {
        let on_surface = &self.surface.on_surface;
        self.rows.clear();
        self.rows.extend_from_slice(on_surface);
        self.held.clear();
        if self.contact_rows != ContactRows::Surface {
            self.leave_walls(list, points, ghosts);
        }
        self.blend_ramp_rows();
    }

    /// Under [`ContactRows::Wall`] and [`ContactRows::Held`]: which surface particles in a
    /// wall's first half-spacing lose their Dirichlet rows or are held (see
    /// [`Self::choose_rows`]).
    fn leave_walls(&mut self, list: &NeighbourList, points: &[Vec2], ghosts: &Ghosts) {
        let on_surface = &self.surface.on_surface;
        let keep_rows = self.contact_rows == ContactRows::Held;
        // A wetting foot at rest stands ~0.44δr above the plate: held from δr/2, the
        // R/δr = 20 drop at θ = 40° chattered (speeds to 0.02σ/η) and threw a particle out at
        // t ≈ 39; from δr/4 the hold meets only a foot that is sinking.
        let reach = if keep_rows { 0.5 } else { 1.0 } * self.spacing;
        let n = on_surface.len();
        let joins_bulk = |i: usize| {
            list.range(i).any(|k| {
                let j = list.index[k] as usize;
                j < n && !on_surface[j]
            })
        };
        for (k, &p) in ghosts.parent.iter().enumerate() {
            let p = p as usize;
            let to_mirror = (points[n + k] - points[p]).norm();
            if !on_surface[p] || to_mirror >= reach {
                continue;
            }
            if !keep_rows && joins_bulk(p) {
                self.rows[p] = false;
            } else {
                let inward = (points[p] - points[n + k]) / to_mirror.max(f64::MIN_POSITIVE);
                self.held.push((p, inward));
            }
        }
    }

    /// Under a blended indicator, the Dirichlet rows on the ramp (s < 1) become blended rows
    /// (s > 0) or Poisson rows (s = 0).
    fn blend_ramp_rows(&mut self) {
        self.blended.clear();
        if self.surface.blend_width <= 0.0 {
            return;
        }
        for (i, row) in self.rows.iter_mut().enumerate().filter(|(_, r)| **r) {
            let s = self.surface.weight(i);
            if s < 1.0 {
                *row = false;
                if s > 0.0 {
                    self.blended.push((i, s));
                }
            }
        }
    }

    /// After the projection: a surface particle in a wall's first half-spacing that kept
    /// its Dirichlet row (see [`Self::choose_rows`]) loses its velocity into the wall, the
    /// no-penetration condition u·n = 0 that the PPE imposes on every other particle there
    /// (walls whose normal velocity is zero: fixed or sliding). Nothing else acts on it: its
    /// pressure is the Dirichlet value and its mirror's drag is bounded, so under gravity a
    /// lone particle on the plate sank through it (the Wi = 5/3 jet at 0.288 s).
    pub fn hold_off_walls(&mut self, velocity: &mut [Vec2]) {
        for &(i, inward) in &self.held {
            let into = velocity[i].dot(&inward);
            if into < 0.0 {
                velocity[i] -= into * inward;
                self.wall_holds += 1;
            }
        }
    }

    /// The PPE's surface rows and their values, after [`Self::dirichlet_pressure`] and
    /// [`Self::choose_rows`].
    pub fn dirichlet(&self) -> SurfaceRows<'_> {
        SurfaceRows {
            dirichlet: &self.rows,
            values: &self.dirichlet,
            blended: &self.blended,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four particles over a wall at y = 0 (spacing 0.1): 0 on the surface at 0.4δr with an
    /// interior neighbour (2), 1 on the surface at 0.6δr, 2 interior, 3 on the surface at
    /// 0.2δr whose only fluid neighbour (1) is on the surface (a splash on the wall).
    fn four_over_a_wall(contact: ContactRows) -> FreeSurfaceStage {
        let options = SurfaceOptions {
            pressure: SurfacePressure::NormalStress,
            contact_rows: contact,
            time_level: CapillaryTimeLevel::Predicted,
            shear: SurfaceShear::Truncated,
            gradient: SurfaceGradient::Full,
            indicator: SurfaceIndicator::Sharp,
        };
        let mut stage = FreeSurfaceStage::new(options, 0.0, 0.1, None);
        stage.surface.on_surface = vec![true, true, false, true];
        let mut ghosts = Ghosts::default();
        ghosts.parent = vec![0, 1, 2, 3];
        let points = [
            Vec2::new(0.0, 0.04),
            Vec2::new(1.0, 0.06),
            Vec2::new(2.0, 0.03),
            Vec2::new(3.0, 0.02),
            Vec2::new(0.0, -0.04),
            Vec2::new(1.0, -0.06),
            Vec2::new(2.0, -0.03),
            Vec2::new(3.0, -0.02),
        ];
        // Fluid neighbours only (the mirrors do not decide): 0–2, 1–2, 3–1.
        let list = NeighbourList {
            offsets: vec![0, 1, 3, 5, 6],
            index: vec![2, 2, 3, 0, 1, 1],
            rij: vec![Vec2::zeros(); 6],
        };
        stage.choose_rows(&list, &points, &ghosts);
        stage
    }

    /// Under `wall` a surface particle nearer the wall than δr/2 (its mirror nearer than δr)
    /// with an interior neighbour loses its Dirichlet row; one at 0.6δr, one as near whose
    /// only fluid neighbour is on the surface (its row would join no pinned row), an interior
    /// particle and every row under `surface` keep theirs.
    #[test]
    fn contact_line_particles_take_interior_rows_only_under_wall() {
        let rows = |contact| four_over_a_wall(contact).dirichlet().dirichlet.to_vec();
        assert_eq!(rows(ContactRows::Wall), vec![false, true, false, true]);
        assert_eq!(rows(ContactRows::Surface), vec![true, true, false, true]);
        assert_eq!(rows(ContactRows::Held), vec![true, true, false, true]);
    }

    /// The splash on the wall (3) loses its velocity into the wall and keeps the rest; a
    /// velocity away from the wall and every other particle are untouched, and under
    /// `surface` nothing is held.
    #[test]
    fn a_splash_on_the_wall_is_held_off_it_only_under_wall() {
        let into = vec![Vec2::new(0.3, -0.2); 4];
        let mut stage = four_over_a_wall(ContactRows::Wall);
        let mut v = into.clone();
        stage.hold_off_walls(&mut v);
        assert_eq!(&v[..3], &into[..3]);
        assert_eq!(v[3], Vec2::new(0.3, 0.0));
        assert_eq!(stage.wall_holds, 1);
        let mut away = vec![Vec2::new(0.3, 0.2); 4];
        stage.hold_off_walls(&mut away);
        assert_eq!(away, vec![Vec2::new(0.3, 0.2); 4]);
        let mut v = into.clone();
        four_over_a_wall(ContactRows::Surface).hold_off_walls(&mut v);
        assert_eq!(v, into);
    }

    /// Under a blended indicator an FS particle on the ramp takes a Poisson row where (36)
    /// has only just taken it in (s = 0), a blended row half-way up (s = ½ at margin
    /// BLEND_WIDTH/2), and a Dirichlet row from the ramp's top on and on exposed particles
    /// (margin +∞); under a sharp indicator every FS particle takes a Dirichlet row.
    #[test]
    fn blended_rows_lie_on_the_ramp_only() {
        let choose = |indicator: SurfaceIndicator| {
            let options = SurfaceOptions {
                pressure: SurfacePressure::NormalStress,
                contact_rows: ContactRows::Surface,
                time_level: CapillaryTimeLevel::Predicted,
                shear: SurfaceShear::Truncated,
                gradient: SurfaceGradient::Full,
                indicator,
            };
            let mut stage = FreeSurfaceStage::new(options, 0.0, 0.1, None);
            stage.surface.on_surface = vec![true, true, true, true, false];
            let half = 0.5 * BLEND_WIDTH;
            stage.surface.margin = vec![0.0, half, BLEND_WIDTH, f64::INFINITY, -0.3];
            let list = NeighbourList {
                offsets: vec![0; 6],
                index: Vec::new(),
                rij: Vec::new(),
            };
            stage.choose_rows(&list, &[Vec2::zeros(); 5], &Ghosts::default());
            let rows = stage.dirichlet();
            (
                rows.dirichlet.to_vec(),
                rows.blended.to_vec(),
                rows.pin_level(),
            )
        };
        let (rows, blended, pinned) = choose(SurfaceIndicator::Blended);
        assert_eq!(rows, vec![false, false, true, true, false]);
        assert_eq!(blended, vec![(1, 0.5)]);
        assert!(pinned);
        let (rows, blended, _) = choose(SurfaceIndicator::Sharp);
        assert_eq!(rows, vec![true, true, true, true, false]);
        assert!(blended.is_empty());
    }

    /// Under `held` every surface particle within δr/4 of the wall (3, at 0.2δr) loses its
    /// velocity into the wall whatever its neighbours; the one at 0.4δr (where a foot at
    /// rest stands), the one at 0.6δr and the interior particle do not.
    #[test]
    fn held_contact_lines_keep_their_rows_and_lose_their_velocity_into_the_wall() {
        let mut stage = four_over_a_wall(ContactRows::Held);
        let mut v = vec![Vec2::new(0.3, -0.2); 4];
        stage.hold_off_walls(&mut v);
        let free = Vec2::new(0.3, -0.2);
        assert_eq!(v, vec![free, free, free, Vec2::new(0.3, 0.0)]);
        assert_eq!(stage.wall_holds, 1);
    }
}
