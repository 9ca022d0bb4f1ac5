//! The viscosity field of a generalised Newtonian fluid
//! ([`crate::engine::rheology::generalised_newtonian`]): each step, from ∇u^n,
//! φ_i = η(γ̇_i)/η0 with γ̇ = √(2 D:D), extended to the wall mirrors (a mirror takes its
//! parent's value: the viscosity is even across a wall, as the shear rate is). The viscous
//! term of (24) becomes ν0 ∇·(φ∇u), explicit or implicit, with the pair viscosity of
//! [`crate::engine::operators::pair_viscosity`]. Lagging φ by one step (∇u^n, not ∇u*)
//! keeps the implicit solve linear; at steady state the lag vanishes.

use crate::engine::boundary::Ghosts;
use crate::engine::dimension::{Dim, Dimension, Matrix};
use crate::engine::rheology::ViscosityLaw;
use rayon::prelude::*;

/// φ = η(γ̇)/η0 over the fluid particles and their mirrors.
#[derive(Clone, Debug)]
pub struct ShearDependentViscosity {
    law: ViscosityLaw,
    eta0: f64,
    fluid: Vec<f64>,
    extended: Vec<f64>,
}

/// γ̇ = √(2 D:D) of a velocity gradient, D = (∇u + ∇uᵀ)/2.
pub fn shear_rate<const D: usize>(grad_u: &Matrix<D>) -> f64 {
    let d = (grad_u + grad_u.transpose()) * 0.5;
    (2.0 * d.component_mul(&d).sum()).sqrt()
}

impl ShearDependentViscosity {
    pub fn new(law: ViscosityLaw, eta0: f64) -> Self {
        Self {
            law,
            eta0,
            fluid: Vec::new(),
            extended: Vec::new(),
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        crate::engine::vec_bytes(&self.fluid) + crate::engine::vec_bytes(&self.extended)
    }

    /// φ from ∇u^n of the fluid particles.
    pub fn update<const D: usize>(&mut self, grad_u: &[Matrix<D>], ghosts: &Ghosts<D>)
    where
        Dim<D>: Dimension<D>,
    {
        let (law, eta0) = (self.law, self.eta0);
        self.fluid.resize(grad_u.len(), 1.0);
        self.fluid
            .par_iter_mut()
            .zip(grad_u.par_iter())
            .for_each(|(phi, g)| *phi = law.viscosity(eta0, shear_rate(g)) / eta0);
        ghosts.extend_scalar(&self.fluid, &mut self.extended);
    }

    /// φ of the fluid particles, then of the ghosts.
    pub fn factor(&self) -> &[f64] {
        &self.extended
    }

    /// φ of the fluid particles.
    pub fn fluid_factor(&self) -> &[f64] {
        &self.fluid
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::math::Mat2;

    /// Simple shear u = (γ̇ y, 0) has √(2 D:D) = γ̇; planar extension (ε, −ε) has 2ε.
    #[test]
    fn shear_rate_of_simple_flows() {
        assert!((shear_rate(&Mat2::new(0.0, 3.0, 0.0, 0.0)) - 3.0).abs() < 1e-14);
        assert!((shear_rate(&Mat2::new(0.5, 0.0, 0.0, -0.5)) - 1.0).abs() < 1e-14);
    }
}
