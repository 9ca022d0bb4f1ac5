//! A finished run's state carried onto another resolution (grid sequencing): `run --from DIR`
//! with a case whose particle spacing differs from the one DIR ran at. The new case's particles
//! start on their own lattice and take the old run's fields there:
//!
//! - velocity and pressure by the corrected interpolation of [`crate::analysis::grid`] (a
//!   quadratic moving-least-squares fit, exact for quadratics also on truncated supports);
//! - the conformation by the Shepard average, a convex combination of the old tensors, which
//!   keeps what the constitutive invariants need (A symmetric positive definite, det A ≥ 1 for
//!   Oldroyd-B by Minkowski's determinant inequality, tr A < L² for the FENE models);
//! - the body force (a mean-flow controller's reached force) as it was.
//!
//! A coarse steady state is thereby the start of a fine run, which then only has to relax the
//! difference between the resolutions rather than the whole start-up: at high Wi the start-up
//! lasts several relaxation times, and it is the costly part of a fine run.

use crate::analysis::grid::Sampler;
use crate::engine::math::{Sym2, Vec2};
use crate::engine::step::Simulation;
use anyhow::{bail, Result};
use rayon::prelude::*;

/// One target particle's sampled (u, v, p) and (A_xx, A_xy, A_yy), or its position where
/// nothing was stored.
type Sample = Result<(Vec<f64>, Vec<f64>), Vec2>;

/// Sets `target`'s velocity, pressure, conformation and body force from `source`'s particles
/// (module docs). The scenes must cover the same domain with the same solids: a target
/// particle inside a source solid, or with no source particle within the kernel support, is
/// an error naming where.
pub fn transfer(source: &Simulation, target: &mut Simulation) -> Result<()> {
    if source.domain != target.domain {
        let extent = |d: &crate::engine::neighbours::Domain| {
            format!("[{}, {}] × [{}, {}]", d.min.x, d.max.x, d.min.y, d.max.y)
        };
        bail!(
            "the domains differ: {} stored, {} in this case",
            extent(&source.domain),
            extent(&target.domain)
        );
    }
    if !source.state.conformation.is_empty() && target.state.conformation.is_empty() {
        bail!("the stored run is viscoelastic and this case is Newtonian");
    }
    let sampler = Sampler::new(source);
    let s = &source.state;
    let ux: Vec<f64> = s.velocity.iter().map(|u| u.x).collect();
    let uy: Vec<f64> = s.velocity.iter().map(|u| u.y).collect();
    let kinematic = [ux.as_slice(), uy.as_slice(), s.pressure.as_slice()];
    let parts = |f: fn(&Sym2) -> f64| s.conformation.iter().map(f).collect::<Vec<f64>>();
    let (xx, xy, yy) = (parts(|a| a.xx), parts(|a| a.xy), parts(|a| a.yy));
    let conformation = [xx.as_slice(), xy.as_slice(), yy.as_slice()];
    let sampled: Vec<Sample> = target
        .state
        .position
        .par_iter()
        .map(|&x| {
            if sampler.in_solid(&x) {
                return Err(x);
            }
            // Shepard where the fit is ill-posed (a particle half a fine spacing from a
            // wall, outside the coarse particle cloud).
            let u = sampler
                .fit(x, &kinematic)
                .or_else(|| sampler.shepard(x, &kinematic))
                .ok_or(x)?;
            let a = if s.conformation.is_empty() {
                Vec::new()
            } else {
                sampler.shepard(x, &conformation).ok_or(x)?
            };
            Ok((u, a))
        })
        .collect();
    let t = &mut target.state;
    for (i, v) in sampled.into_iter().enumerate() {
        let (u, a) = v.map_err(|x| {
            anyhow::anyhow!(
                "no stored fluid at this case's particle ({:.4}, {:.4}): do the scenes match?",
                x.x,
                x.y
            )
        })?;
        t.velocity[i] = Vec2::new(u[0], u[1]);
        t.pressure[i] = u[2];
        // A Newtonian source leaves the target's conformation at rest (A = I).
        if let [xx, xy, yy] = a[..] {
            t.conformation[i] = Sym2 { xx, xy, yy };
        }
    }
    t.body_force = s.body_force;
    let state = std::mem::take(&mut target.state);
    target.restore_state(state);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::case;

    /// The cylinder array (a periodic box, plane walls and a curved solid) at `resolution`.
    fn array(resolution: usize) -> Simulation {
        let text = include_str!("../../../cases/cylinder-array.toml");
        let overrides = [
            format!("scene.resolution={resolution}"),
            "scene.mean_flow=1.0".to_string(),
        ];
        let case = case::parse(text, "cylinder-array.toml", "t", &overrides).unwrap();
        Simulation::new(case.setup().unwrap())
    }

    /// Fields quadratic in y (so periodic in x) and a conformation with det A ≥ 1.
    fn velocity(p: Vec2) -> Vec2 {
        Vec2::new(p.y * (4.0 - p.y), 0.1 * p.y * p.y)
    }
    fn pressure(p: Vec2) -> f64 {
        3.0 - p.y * p.y
    }
    fn conformation(p: Vec2) -> Sym2 {
        Sym2 {
            xx: 1.0 + p.y * p.y,
            xy: 0.5 * p.y,
            yy: 1.0,
        }
    }

    #[test]
    fn a_coarse_state_lands_on_a_finer_lattice_with_its_invariants() {
        let mut coarse = array(36);
        let s = &mut coarse.state;
        s.velocity = s.position.iter().map(|&p| velocity(p)).collect();
        s.pressure = s.position.iter().map(|&p| pressure(p)).collect();
        s.conformation = s.position.iter().map(|&p| conformation(p)).collect();
        s.body_force = Vec2::new(321.0, 0.0);
        let mut fine = array(54);
        transfer(&coarse, &mut fine).unwrap();
        let t = &fine.state;
        assert_eq!(t.body_force, Vec2::new(321.0, 0.0));
        // The quadratic fit reproduces quadratics to round-off (measured 6e-14): from a
        // lattice start every fine particle, also half a fine spacing from a wall or the
        // cylinder, has a well-posed fit, so no fallback lowers the order here. The Shepard
        // conformation carries the kernel's smoothing error ½|f''|σ², σ² the kernel's second
        // moment per axis (h the coarse smoothing length): measured 0.0102 = 0.49h² for
        // A_xx = 1 + y² away from the solids, σ² ≈ 0.5h²; the bound allows 20 % over that.
        let h = coarse.kernel.h();
        let (mut kinematic, mut smoothing) = (0.0_f64, 0.0_f64);
        for (i, &p) in t.position.iter().enumerate() {
            let e = (t.velocity[i] - velocity(p)).norm() + (t.pressure[i] - pressure(p)).abs();
            kinematic = kinematic.max(e);
            let gap = fine
                .walls()
                .iter()
                .map(|w| w.distance_in(&p, &fine.domain))
                .fold(f64::INFINITY, f64::min);
            if gap > coarse.kernel.support() {
                smoothing = smoothing.max((t.conformation[i].xx - conformation(p).xx).abs());
            }
        }
        assert!(
            kinematic < 1e-9,
            "velocity and pressure error {kinematic:e}"
        );
        assert!(
            smoothing < 0.6 * h * h,
            "A_xx smoothing error {smoothing:e}"
        );
        // The Shepard average of the conformation is a convex combination: det A ≥ 1 at
        // every particle, however large its smoothing error.
        let min_det = t
            .conformation
            .iter()
            .map(|a| a.det())
            .fold(f64::MAX, f64::min);
        assert!(min_det >= 1.0 - 1e-12, "min det A {min_det}");
    }

    #[test]
    fn a_scene_of_another_size_is_refused() {
        let coarse = array(36);
        let text = include_str!("../../../cases/cylinder-array.toml");
        let overrides = ["scene.length=7.0".to_string()];
        let other = case::parse(text, "cylinder-array.toml", "t", &overrides).unwrap();
        let mut other = Simulation::new(other.setup().unwrap());
        let e = transfer(&coarse, &mut other).unwrap_err().to_string();
        assert!(e.contains("domains differ"), "{e}");
    }
}
