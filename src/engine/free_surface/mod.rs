//! Free surfaces (King & Lind §III C–D): the optional stage of a scene with free surfaces.
//! Step 2 detects the surface and its normals ([`detection`], (36)–(39)); step 5 gives the PPE
//! rows of surface particles their Dirichlet pressure ([`pressure`], (34)–(35)), with the
//! capillary jump σκ of a surface tension ([`tension`]), or the surface tension acts as a
//! pairwise cohesion force in the momentum equation instead ([`cohesion`]). The same
//! scenes use the free-surface shifting (40)–(44) and the positive stress divergence (20).

pub mod cohesion;
pub mod detection;
pub mod pressure;
pub mod tension;
pub mod wetting;

pub use cohesion::Cohesion;
pub use detection::{FreeSurface, NEAR_SURFACE_STRENGTH};
pub use pressure::{SurfaceInputs, SurfacePressure, SurfacePressureRule};
pub use tension::SurfaceTension;
pub use wetting::Wetting;

use crate::engine::kernel::QuinticSpline;
use crate::engine::math::{Sym2, Vec2};
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use crate::engine::rheology::Fluid;
use serde::{Deserialize, Serialize};

/// How a surface tension acts (`scheme.surface_tension`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceTensionForm {
    /// The capillary jump σκ in the free-surface pressure's normal-stress balance
    /// ([`tension`]), the contact angle imposed on the surface's shape ([`wetting`]).
    NormalStress,
    /// The pairwise cohesion force of Wróblewski et al. (2008) ([`cohesion`]), the contact
    /// angle through the walls' attraction.
    Cohesion,
}

/// The free-surface stage: the surface of the current step and its pressure rule.
pub struct FreeSurfaceStage {
    /// FS and NS sets and normals of the last step.
    pub surface: FreeSurface,
    rule: Box<dyn SurfacePressureRule>,
    /// The capillary jump σκ (a fluid with surface tension).
    tension: Option<SurfaceTension>,
    dirichlet: Vec<f64>,
}

impl FreeSurfaceStage {
    /// The stage for a rule and, if σ > 0, a surface tension σ on particles of spacing δr,
    /// meeting the walls at the contact angle of `wetting` if there is one.
    pub fn new(
        rule: SurfacePressure,
        surface_tension: f64,
        spacing: f64,
        wetting: Option<Wetting>,
    ) -> Self {
        let tension = (surface_tension > 0.0).then(|| {
            let mut t = SurfaceTension::new(surface_tension, spacing);
            t.wetting = wetting;
            t
        });
        Self {
            surface: FreeSurface::default(),
            rule: rule.rule(),
            tension,
            dirichlet: Vec::new(),
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
            + self.rule.heap_bytes()
            + self.tension.as_ref().map_or(0, SurfaceTension::heap_bytes)
    }

    /// Step 2: detection (36)–(37) and normals (38)–(39). Rows in `prescribed` (an inflow
    /// buffer) take Dirichlet rows and are not near the surface themselves.
    pub fn detect(
        &mut self,
        list: &NeighbourList,
        sums: &KernelSums,
        kernel: &QuinticSpline,
        prescribed: &[bool],
    ) {
        self.surface.detect(list, sums, kernel);
        for (i, _) in prescribed.iter().enumerate().filter(|(_, &b)| b) {
            self.surface.on_surface[i] = true;
            self.surface.near_surface[i] = false;
        }
    }

    /// Step 5: the Dirichlet pressure of every row (zero off the surface), from the
    /// predictor's velocity u* (fluid values, then the ghosts'), a generalised Newtonian
    /// fluid's viscosity factor φ = η(γ̇)/η0 (empty: uniform) and A^{n+½}, plus the
    /// capillary jump σκ where the rule's value is trusted (not an inflow row, not a sparse
    /// splash: [`pressure::MIN_SURFACE_NEIGHBOURS`]). `points` are the positions of the
    /// rows (fluid first).
    pub fn dirichlet_pressure(
        &mut self,
        (list, sums, points): (&NeighbourList, &KernelSums, &[Vec2]),
        (fluid, viscosity_factor): (&Fluid, &[f64]),
        velocity_star: &[Vec2],
        conformation: &[Sym2],
        prescribed: &[bool],
    ) -> &mut [f64] {
        let inputs = SurfaceInputs {
            list,
            sums,
            surface: &self.surface,
            viscosity_factor,
            velocity_star,
            fluid,
            conformation,
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
            tension.add_jump((list, points), &self.surface, trusted, &mut self.dirichlet);
        }
        &mut self.dirichlet
    }

    /// The Dirichlet rows of the PPE and their values, after [`Self::dirichlet_pressure`].
    pub fn dirichlet(&self) -> (&[bool], &[f64]) {
        (&self.surface.on_surface, &self.dirichlet)
    }

    /// The PPE rows that are Dirichlet rows.
    pub fn rows(&self) -> &[bool] {
        &self.surface.on_surface
    }
}
