//! Free surfaces (King & Lind §III C–D): the optional stage of a scene with free surfaces.
//! Step 2 detects the surface and its normals ([`detection`], (36)–(39)); step 5 gives the PPE
//! rows of surface particles their Dirichlet pressure ([`pressure`], (34)–(35)). The same
//! scenes use the free-surface shifting (40)–(44) and the positive stress divergence (20).

pub mod detection;
pub mod pressure;

pub use detection::{FreeSurface, NEAR_SURFACE_STRENGTH};
pub use pressure::{SurfaceInputs, SurfacePressure, SurfacePressureRule};

use crate::engine::kernel::QuinticSpline;
use crate::engine::math::{Sym2, Vec2};
use crate::engine::neighbours::NeighbourList;
use crate::engine::operators::KernelSums;
use crate::engine::rheology::Fluid;

/// The free-surface stage: the surface of the current step and its pressure rule.
pub struct FreeSurfaceStage {
    /// FS and NS sets and normals of the last step.
    pub surface: FreeSurface,
    rule: Box<dyn SurfacePressureRule>,
    dirichlet: Vec<f64>,
}

impl FreeSurfaceStage {
    pub fn new(rule: SurfacePressure) -> Self {
        Self {
            surface: FreeSurface::default(),
            rule: rule.rule(),
            dirichlet: Vec::new(),
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        self.surface.heap_bytes()
            + crate::engine::vec_bytes(&self.dirichlet)
            + self.rule.heap_bytes()
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
    /// predictor's velocity u* (fluid values, then the ghosts') and A^{n+½}.
    pub fn dirichlet_pressure(
        &mut self,
        (list, sums): (&NeighbourList, &KernelSums),
        fluid: &Fluid,
        velocity_star: &[Vec2],
        conformation: &[Sym2],
        prescribed: &[bool],
    ) -> &mut [f64] {
        let inputs = SurfaceInputs {
            list,
            sums,
            surface: &self.surface,
            velocity_star,
            fluid,
            conformation,
            prescribed,
        };
        self.dirichlet.clear();
        self.dirichlet.resize(list.rows(), 0.0);
        self.rule.pressure(&inputs, &mut self.dirichlet);
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
