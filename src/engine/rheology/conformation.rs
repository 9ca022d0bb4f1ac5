//! Step 3 of the time step (King & Lind §III A–B): the conformation from n−½ to n+½, by the
//! log-conformation ([`super::log_conformation`]) or directly ([`super::direct`]); then the
//! EVSS tensor Φ = τ_p − α_V η0 2D of eq. (6) and its divergence for the predictor, in the
//! form of (20) the scene needs (negative in closed domains, positive with free surfaces).

use super::remap::{keep_trace_floor, limit_increments, Remap};
use super::{
    direct_step, direct_step_strang, log_conformation_step, log_conformation_step_strang,
    log_local_rate, log_unsplit_step, Fluid, Model,
};
use crate::engine::dimension::{Dim, Dimension, Matrix, Sym, SymTensor, Vector};
use crate::engine::neighbourhood::Hood;
use crate::engine::operators::DivergenceForm;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the conformation tensor is integrated in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ConformationScheme {
    /// Log-conformation with source splitting, §III B.
    Log,
    /// First-order Euler on A itself, eq. (10): not positive-definite by construction.
    Direct,
}

/// The order in time of the conformation update.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ConformationIntegrator {
    /// King & Lind's (29)–(33): the convective step by explicit Euler, then the source step
    /// (Lie splitting), first order in δt.
    Euler,
    /// Half a source step, the convective step by the explicit midpoint rule, half a source
    /// step (Strang splitting): second order in δt.
    ///
    /// The Euler update's O(δt) error is what limited the large implicit step: start-up
    /// Poiseuille (Re = Wi = 1, β = 0.1, H/δr = 60, Eulerian, δt = 0.2h/|u|max) had an L2
    /// error of 1.7e-2 at t = 1 with either viscous integrator, 2.4e-3 with the same update
    /// split into eight sub-steps, 1.2e-3 with a 4× smaller δt.
    Strang,
    /// The whole rate in one linearly implicit Euler step (log-conformation only; see
    /// [`super::log_unsplit_step`]): first order in δt, and a steady state that does not
    /// depend on δt, which both splittings' do (by O(δt/λ) and O((δt/λ)²)).
    Unsplit,
}

/// One log-conformation update: model, A, Ψ = ln A, u_ps·∇Ψ, ∇u, δt, λ.
type LogStep<S> = fn(&Model, &S, &S, &S, &<S as SymTensor>::Matrix, f64, f64) -> S;
/// One direct update: model, A, u_ps·∇A, ∇u, δt, λ.
type DirectStep<S> = fn(&Model, &S, &S, &<S as SymTensor>::Matrix, f64, f64) -> S;

/// How the conformation is integrated: its variable, order in time and ALE remap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConformationChoice {
    pub scheme: ConformationScheme,
    pub integrator: ConformationIntegrator,
    pub remap: Remap,
}

/// The velocity fields the constitutive update reads.
#[derive(Clone, Copy)]
pub struct Flow<'a, const D: usize = 2> {
    /// ∇u^n as the constitutive update sees it.
    pub grad_u: &'a [Matrix<D>],
    /// The shift velocity u_ps, whose ALE transport remaps A, eq. (31).
    pub u_ps: &'a [Vector<D>],
}

/// The constitutive stage of a viscoelastic fluid and its buffers, in D dimensions (the
/// default 2).
#[derive(Clone, Debug)]
pub struct ConformationStage<const D: usize = 2>
where
    Dim<D>: Dimension<D>,
{
    pub scheme: ConformationScheme,
    integrator: ConformationIntegrator,
    remap: Remap,
    /// L² of a FENE model: tr A < L² is checked after every step.
    extensibility: Option<f64>,
    /// α_V η0 of eq. (6).
    evss: f64,
    /// The form of (20) in which ∇·Φ is formed (None: not formed, the integrator sums the
    /// polymer stress itself).
    form: Option<DivergenceForm>,
    log_conformation: Vec<Sym<D>>,
    advection: Vec<Sym<D>>,
    tensor_ext: Vec<Sym<D>>,
    /// [`ConformationIntegrator::Unsplit`]: the local part of the rate.
    local: Vec<Sym<D>>,
    /// [`Remap::SecondOrder`]: the rate L is applied to with the ghosts', and L of it.
    rate_ext: Vec<Sym<D>>,
    second: Vec<Sym<D>>,
    phi: Vec<Sym<D>>,
    div_phi: Vec<Vector<D>>,
}

impl<const D: usize> ConformationStage<D>
where
    Dim<D>: Dimension<D>,
    Sym<D>: SymTensor<Matrix = Matrix<D>>,
{
    /// The stage for `fluid` with EVSS weight α_V; `form` of the divergence (20), None when
    /// the time integrator takes the polymer stress in its own momentum sum.
    pub fn new(
        choice: ConformationChoice,
        fluid: &Fluid,
        evss_alpha: f64,
        form: Option<DivergenceForm>,
    ) -> Self {
        let ConformationChoice {
            scheme,
            integrator,
            remap,
        } = choice;
        Self {
            scheme,
            integrator,
            remap,
            extensibility: fluid.model.extensibility(),
            evss: evss_alpha * fluid.viscosity,
            form,
            log_conformation: Vec::new(),
            advection: Vec::new(),
            tensor_ext: Vec::new(),
            local: Vec::new(),
            rate_ext: Vec::new(),
            second: Vec::new(),
            phi: Vec::new(),
            div_phi: Vec::new(),
        }
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use crate::engine::vec_bytes as b;
        b(&self.log_conformation)
            + b(&self.advection)
            + b(&self.tensor_ext)
            + b(&self.local)
            + b(&self.rate_ext)
            + b(&self.second)
            + b(&self.phi)
            + b(&self.div_phi)
    }

    /// The time the update from A^{n−½} to A^{n+½} spans, given the last step δt^{n−1} (0
    /// before the first) and this one δt^n.
    ///
    /// A^{n−½} sits at t^n − δt^{n−1}/2 (the initial conformation at t = 0), so the span is
    /// (δt^{n−1} + δt^n)/2, which is δt^n only while the step is constant. The second-order
    /// integrator needs it: a span of δt^n whatever the step leaves the stress behind its
    /// level by (δt^n − δt^0)/2, an O(δt) error wherever the step varies (the advective step
    /// of start-up Poiseuille falls 2.7× as the flow overshoots). King & Lind's Euler update
    /// keeps δt^n, so that its results are those of the paper's scheme.
    pub fn span(&self, previous_dt: f64, dt: f64) -> f64 {
        match self.integrator {
            ConformationIntegrator::Euler | ConformationIntegrator::Unsplit => dt,
            ConformationIntegrator::Strang => 0.5 * (previous_dt + dt),
        }
    }

    /// Advances `conformation` from A^{n−½} to A^{n+½} with ∇u^n and the shift velocity,
    /// then Φ and ∇·Φ where the stage forms them.
    pub fn update(
        &mut self,
        fluid: &Fluid,
        dt: f64,
        hood: Hood<D>,
        flow: Flow<D>,
        conformation: &mut [Sym<D>],
    ) {
        self.advance(fluid, dt, hood, flow, conformation);
        let grad_u = flow.grad_u;
        if let Some(form) = self.form {
            self.evss_divergence(fluid, hood, grad_u, conformation, form);
        }
    }

    /// Advances `conformation` from A^{n−½} to A^{n+½} only.
    fn advance(
        &mut self,
        fluid: &Fluid,
        dt: f64,
        hood: Hood<D>,
        flow: Flow<D>,
        conformation: &mut [Sym<D>],
    ) {
        let Flow { grad_u, u_ps } = flow;
        let ghosts = hood.ghosts;
        let n = conformation.len();
        let lambda = fluid.relaxation_time;
        let model = fluid.model;
        self.advection.resize(n, Sym::<D>::ZERO);
        match self.scheme {
            ConformationScheme::Log => {
                self.log_conformation.resize(n, Sym::<D>::ZERO);
                self.log_conformation
                    .par_iter_mut()
                    .zip(conformation.par_iter())
                    .for_each(|(psi, a)| *psi = a.log());
                // The transport reads the even copy (see [`Self::remap_rate`]).
                ghosts.extend_tensor(&self.log_conformation, &mut self.tensor_ext);
                if self.integrator == ConformationIntegrator::Unsplit {
                    self.local.resize(n, Sym::<D>::ZERO);
                    self.local
                        .par_iter_mut()
                        .zip(conformation.par_iter().zip(grad_u.par_iter()))
                        .for_each(|(l, (a, g))| *l = log_local_rate(&model, a, g, lambda));
                }
                self.remap_rate(hood, u_ps, dt);
                let (psi, adv, local) = (&self.log_conformation, &self.advection, &self.local);
                let step: LogStep<Sym<D>> = match self.integrator {
                    ConformationIntegrator::Euler => log_conformation_step,
                    ConformationIntegrator::Strang => |m, a, _psi, adv, g, dt, lambda| {
                        log_conformation_step_strang(m, a, adv, g, dt, lambda)
                    },
                    ConformationIntegrator::Unsplit => {
                        conformation.par_iter_mut().enumerate().for_each(|(i, a)| {
                            *a = log_unsplit_step(&model, a, &(adv[i] + local[i]), dt, lambda);
                        });
                        return;
                    }
                };
                conformation.par_iter_mut().enumerate().for_each(|(i, a)| {
                    *a = step(&model, a, &psi[i], &adv[i], &grad_u[i], dt, lambda);
                });
            }
            ConformationScheme::Direct => {
                ghosts.extend_tensor(conformation, &mut self.tensor_ext);
                self.remap_rate(hood, u_ps, dt);
                let adv = &self.advection;
                let step: DirectStep<Sym<D>> = match self.integrator {
                    // Refused at set-up (the unsplit step is formed in Ψ).
                    ConformationIntegrator::Euler | ConformationIntegrator::Unsplit => direct_step,
                    ConformationIntegrator::Strang => direct_step_strang,
                };
                conformation.par_iter_mut().enumerate().for_each(|(i, a)| {
                    *a = step(&model, a, &adv[i], &grad_u[i], dt, lambda);
                });
            }
        }
    }

    /// The remap rate u_ps·∇T of the tensor T in `tensor_ext` (Ψ or A with the ghosts'), into
    /// `advection`, limited by [`Remap`] over `dt`.
    ///
    /// The ghosts carry the even copy here, not the wall continuation that the stress
    /// divergence reads ([`crate::engine::boundary::TensorMirror::Linear`]): the copy's error
    /// is in ∂T/∂n alone, which the transport multiplies by u_ps·n, zero on a no-slip wall;
    /// and a copy is an admissible state where a linear extrapolation need not be (det A < 1
    /// wherever tr log A rises from ≈ 0 at the wall), which the upwind transport would carry
    /// into the fluid: in the lid-driven cavity at Wi = 1 the extrapolated ghosts took the
    /// fluid's det A down to 0.88 by t = 4.
    fn remap_rate(&mut self, hood: Hood<D>, u_ps: &[Vector<D>], dt: f64) {
        let Hood { list, sums, ghosts } = hood;
        let ext = &self.tensor_ext;
        let rate = &mut self.advection;
        match self.remap {
            Remap::Central => sums.advective_tensor(list, ext, u_ps, rate),
            Remap::Limited => {
                sums.advective_tensor(list, ext, u_ps, rate);
                keep_trace_floor(list, ext, dt, rate);
            }
            Remap::SecondOrder => {
                sums.advective_tensor(list, ext, u_ps, rate);
                // L of the whole rate where the update is unsplit, which vanishes with it in
                // a steady state (Lax & Wendroff's Ψ_tt); of the transport alone otherwise.
                let whole = &mut self.second;
                whole.clear();
                whole.extend_from_slice(rate);
                for (w, l) in whole.iter_mut().zip(&self.local) {
                    *w += *l;
                }
                ghosts.extend_tensor(whole, &mut self.rate_ext);
                self.second.resize(rate.len(), Sym::<D>::ZERO);
                sums.advective_tensor(list, &self.rate_ext, u_ps, &mut self.second);
                rate.par_iter_mut()
                    .zip(self.second.par_iter())
                    .for_each(|(r, l2)| *r += *l2 * (0.5 * dt));
                keep_trace_floor(list, ext, dt, rate);
            }
            Remap::Upwind => {
                sums.advective_tensor_upwind(list, ext, u_ps, rate);
                limit_increments(list, ext, dt, rate);
            }
        }
    }

    /// Φ = τ_p − α_V η0 2D, eq. (6), with D from ∇u^n, and ∇·Φ.
    fn evss_divergence(
        &mut self,
        fluid: &Fluid,
        hood: Hood<D>,
        grad_u: &[Matrix<D>],
        conformation: &[Sym<D>],
        form: DivergenceForm,
    ) {
        let Hood { list, sums, ghosts } = hood;
        let n = conformation.len();
        let evss = self.evss;
        self.phi.resize(n, Sym::<D>::ZERO);
        self.phi
            .par_iter_mut()
            .zip(conformation.par_iter())
            .enumerate()
            .for_each(|(i, (phi, a))| {
                let strain_rate = Sym::<D>::sym_part(&grad_u[i]) * 2.0;
                *phi = fluid.polymer_stress(a) - strain_rate * evss;
            });
        ghosts.continue_tensor(&self.phi, &mut self.tensor_ext);
        self.div_phi.resize(n, Vector::<D>::zeros());
        sums.divergence_tensor(list, &self.tensor_ext, form, &mut self.div_phi);
    }

    /// ∇·Φ of the last update, for terms that add to it (the hourglass control).
    pub fn stress_divergence_mut(&mut self) -> &mut [Vector<D>] {
        &mut self.div_phi
    }

    /// ∇·Φ of the last update, for the predictor (None: not formed).
    pub fn stress_divergence(&self) -> Option<&[Vector<D>]> {
        self.form.map(|_| &self.div_phi[..])
    }

    /// The invariant the integration does not keep by construction: positive definiteness
    /// under direct integration (the log-conformation keeps it exactly).
    pub fn check(&self, conformation: &[Sym<D>]) -> Result<(), String> {
        if self.scheme == ConformationScheme::Direct
            && conformation
                .par_iter()
                .any(|a| a.det() <= 0.0 || a.trace() <= 0.0)
        {
            return Err("conformation tensor lost positive definiteness".into());
        }
        if let Some(l2) = self.extensibility {
            if let Some(a) = conformation.par_iter().find_any(|a| a.trace() >= l2) {
                return Err(format!(
                    "tr A = {:.4e} reached the extensibility L² = {l2}: the chains are longer than fully extended",
                    a.trace()
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::boundary::Ghosts;
    use crate::engine::math::{Mat2, Sym2, Vec2};
    use crate::engine::neighbours::NeighbourList;
    use crate::engine::operators::KernelSums;
    use crate::engine::rheology::{FeneCr, ViscosityLaw};

    /// tr A < L² is a FENE invariant the step checks: a conformation at L² stops the run
    /// with the reason, one just below it does not, and Oldroyd-B has no such bound.
    #[test]
    fn a_fene_conformation_at_its_extensibility_is_reported() {
        let fluid = |model| Fluid {
            model,
            density: 1.0,
            viscosity: 1.0,
            beta: 0.5,
            relaxation_time: 1.0,
            surface_tension: 0.0,
            law: ViscosityLaw::Constant,
        };
        let stage = |model| {
            ConformationStage::<2>::new(
                ConformationChoice {
                    scheme: ConformationScheme::Log,
                    integrator: ConformationIntegrator::Euler,
                    remap: Remap::Limited,
                },
                &fluid(model),
                0.0,
                Some(DivergenceForm::Negative),
            )
        };
        let fene = stage(Model::FeneCr(FeneCr { l2: 10.0 }));
        let at_bound = [Sym2::IDENTITY, Sym2::new(6.0, 1.0, 4.0)];
        let reason = fene.check(&at_bound).unwrap_err();
        assert!(reason.contains("L² = 10"), "{reason}");
        assert!(fene.check(&[Sym2::new(6.0, 1.0, 3.99)]).is_ok());
        assert!(stage(Model::OldroydB).check(&at_bound).is_ok());
    }

    /// One Eulerian step of pure transport (u = (U, 0), no relaxation) of a traceless mode
    /// Ψ_xy = ε cos kx on a periodic lattice, k at 5.3δr, near the corrected gradient's
    /// largest symbol. The mode is an eigenvector of the central operator L = −u·∇ with
    /// eigenvalue i s: the first-order increment multiplies its amplitude by √(1 + z²),
    /// z = δt s (forward Euler's anti-diffusion), the second-order one by |1 + iz − z²/2| =
    /// √(1 + z⁴/4) ([`Remap::SecondOrder`]). Both within 1e-9 (round-off of the
    /// projection; z = 0.8 so that the two differ by 27 %).
    #[test]
    fn the_second_order_remap_removes_forward_euler_s_growth_of_a_transported_mode() {
        use crate::engine::kernel::QuinticSpline;
        use crate::engine::lattice::lattice;
        use crate::engine::neighbours::{Domain, NeighbourSearch};
        let (n, eps) = (32, 1e-3);
        let dr = 1.0 / n as f64;
        let domain = Domain {
            min: Vec2::zeros(),
            max: Vec2::new(1.0, 1.0),
            periodic: [true, true],
        };
        let pts: Vec<Vec2> = lattice(n, n, dr);
        let kernel = QuinticSpline::for_spacing(dr);
        let mut list = NeighbourList::default();
        NeighbourSearch::new().build(&domain, &pts, pts.len(), kernel.support(), &mut list);
        let mut sums = KernelSums::default();
        sums.update(&list, &kernel, dr * dr);
        let ghosts = Ghosts::default();
        let k = 2.0 * std::f64::consts::PI * 6.0;
        let mode = |p: &Vec2| (k * p.x).cos();
        // The mode's amplitude, projected on cos and sin kx.
        let amplitude = |a: &[Sym2]| {
            let (c, s) = a.iter().zip(&pts).fold((0.0, 0.0), |(c, s), (t, p)| {
                let psi = t.log().xy;
                (c + psi * (k * p.x).cos(), s + psi * (k * p.x).sin())
            });
            2.0 * c.hypot(s) / pts.len() as f64
        };
        let fluid = Fluid {
            model: Model::OldroydB,
            density: 1.0,
            viscosity: 1.0,
            beta: 0.5,
            relaxation_time: 1e12,
            surface_tension: 0.0,
            law: crate::engine::rheology::ViscosityLaw::Constant,
        };
        let u_ps = vec![Vec2::new(-1.0, 0.0); pts.len()];
        let grad_u = vec![Mat2::zeros(); pts.len()];
        let start: Vec<Sym2> = pts
            .iter()
            .map(|p| Sym2::new(0.0, eps * mode(p), 0.0).exp())
            .collect();
        let growth = |remap, dt| {
            let mut stage = ConformationStage::new(
                ConformationChoice {
                    scheme: ConformationScheme::Log,
                    integrator: ConformationIntegrator::Euler,
                    remap,
                },
                &fluid,
                0.0,
                Some(DivergenceForm::Negative),
            );
            let mut a = start.clone();
            stage.advance(
                &fluid,
                dt,
                crate::engine::neighbourhood::Hood {
                    list: &list,
                    sums: &sums,
                    ghosts: &ghosts,
                },
                Flow {
                    grad_u: &grad_u,
                    u_ps: &u_ps,
                },
                &mut a,
            );
            amplitude(&a) / amplitude(&start)
        };
        // s from an infinitesimal step: the amplitude grows by √(1 + z²) ≈ 1 + z²/2.
        let probe = 1e-3;
        let s = ((growth(Remap::Central, probe).powi(2) - 1.0).sqrt()) / probe;
        assert!(
            s > 0.5 * 0.865 / kernel.h() && s < 1.001 * 0.865 / kernel.h(),
            "symbol {s}"
        );
        let dt = 0.8 / s;
        let z = s * dt;
        let central = growth(Remap::Limited, dt);
        let second = growth(Remap::SecondOrder, dt);
        assert!((central - (1.0 + z * z).sqrt()).abs() < 1e-9, "{central}");
        assert!(
            (second - (1.0 + z.powi(4) / 4.0).sqrt()).abs() < 1e-9,
            "{second}"
        );
    }
}
