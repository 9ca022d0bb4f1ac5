//! Errors of a finished run against its analytic reference.

use crate::analysis::pipe_wall;
use crate::analysis::plane::{InPlane, PlaneMap};
use crate::analysis::reference::{Reference, StressProfiles};
use crate::app::io::SeriesRow;
use crate::app::table::{self, fmt};
use crate::engine::dimension::{Dim, SymTensor};
use crate::engine::step::{Simulation, StepDimension};
use serde::{Deserialize, Serialize};

/// The analytic comparison at the first overshoot of the centre-line velocity.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Peak {
    pub t: f64,
    pub u_centre_exact: f64,
    pub u_centre: f64,
    pub relative_error: f64,
}

/// The errors block of `summary.json`. Every value is `null` when the case has no analytic
/// reference (see `reference_unavailable`).
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct Errors {
    /// `waters-king` (transient) or `steady-channel` (compared at the end); not read back
    /// by [`super::Summary::read`].
    #[serde(skip_deserializing)]
    pub reference: Option<&'static str>,
    /// Why there is no reference, if there is none.
    pub reference_unavailable: Option<String>,
    /// Mean over the rows of series.csv (uniform in time) of the velocity L2 error / U.
    pub l2_time_mean: Option<f64>,
    pub l2_final: Option<f64>,
    pub l2_max: Option<f64>,
    /// ‖u − u_exact‖/‖u_exact‖ over the particles at the end (streamwise for a channel).
    pub u_relative_l2: Option<f64>,
    pub u_centre_final: f64,
    pub u_centre_exact_final: Option<f64>,
    pub u_centre_final_relative_error: Option<f64>,
    /// First local maximum of the analytic centre-line velocity (none for a monotone
    /// start-up or a steady reference).
    pub first_overshoot: Option<Peak>,
    /// ‖τ − τ_exact‖/‖τ_exact‖ of the polymer stresses at the end, against the analytic
    /// profiles at the stress time t − δt/2; `null` where the exact component vanishes.
    pub tau_xy_relative_l2: Option<f64>,
    pub tau_xx_relative_l2: Option<f64>,
    pub tau_yy_relative_l2: Option<f64>,
    /// A pipe's total wall shear stress σ_xr(R) at the end (η_s ∂u/∂r + τ_p,xr, negative for
    /// flow along +x), fitted from the particles (`analysis::pipe_wall`), and the series'.
    pub wall_shear_stress: Option<f64>,
    pub wall_shear_stress_exact: Option<f64>,
}

fn relative(a: f64, b: f64) -> f64 {
    if b != 0.0 {
        (a - b).abs() / b.abs()
    } else {
        (a - b).abs()
    }
}

/// Exact polymer stress profiles at the stress time t − δt/2 (§III B), on a grid of heights
/// and interpolated to the particles: τ_xx of the start-up needs a time integration per
/// height, so it is not evaluated particle by particle.
pub struct ExactStresses {
    pub grid: Vec<f64>,
    pub profiles: StressProfiles,
}

impl ExactStresses {
    pub fn at_stress_time<const D: usize>(
        sim: &Simulation<D>,
        reference: &Reference,
        dt: f64,
    ) -> Option<Self>
    where
        Dim<D>: StepDimension<D>,
    {
        if !sim.fluid.model.is_viscoelastic() || !reference.is_channel() {
            return None;
        }
        let t = (sim.state.time - 0.5 * dt).max(0.0);
        let height = reference.extent();
        let grid: Vec<f64> = (0..=100).map(|k| height * k as f64 / 100.0).collect();
        let profiles = reference.stress_profiles(&grid, t).ok()?;
        Some(Self { grid, profiles })
    }

    pub fn interpolate(&self, values: &[f64], y: f64) -> f64 {
        let g = &self.grid;
        let step = g[1] - g[0];
        let k = (((y - g[0]) / step).floor().max(0.0) as usize).min(g.len() - 2);
        let w = (y - g[k]) / step;
        values[k] * (1.0 - w) + values[k + 1] * w
    }

    /// Relative L2 errors of τ_xy, τ_xx, τ_yy in the reference's plane over the particles.
    fn relative_errors<const D: usize>(
        &self,
        sim: &Simulation<D>,
        map: PlaneMap,
    ) -> [Option<f64>; 3]
    where
        Dim<D>: StepDimension<D> + InPlane<D>,
    {
        let s = &sim.state;
        let heights = Dim::<D>::positions(map, &s.position);
        let tau: Vec<[f64; 3]> = sim
            .polymer_stress()
            .iter()
            .zip(&s.position)
            .map(|(t, p)| Dim::<D>::stress(map, p, t))
            .collect();
        let norm = |component: usize, exact: &[f64]| {
            let (mut diff, mut base) = (0.0, 0.0);
            for (t, p) in tau.iter().zip(heights.iter()) {
                let e = self.interpolate(exact, p.y);
                diff += (t[component] - e).powi(2);
                base += e * e;
            }
            (base > 1e-24 * (1.0 + diff)).then(|| (diff / base).sqrt())
        };
        let p = &self.profiles;
        [norm(1, &p.xy), norm(0, &p.xx), norm(2, &p.yy)]
    }
}

/// The errors block for a run that ended in `sim`, with its series rows.
pub fn final_errors<const D: usize>(
    sim: &Simulation<D>,
    map: PlaneMap,
    reference: Result<&mut Reference, &str>,
    rows: &[SeriesRow],
    dt: f64,
) -> (Errors, Option<ExactStresses>)
where
    Dim<D>: StepDimension<D> + InPlane<D>,
{
    let last = rows.last().copied().unwrap_or_default();
    let reference = match reference {
        Ok(r) => r,
        Err(why) => {
            let errors = Errors {
                reference_unavailable: Some(why.to_string()),
                u_centre_final: last.u_centre,
                ..Default::default()
            };
            return (errors, None);
        }
    };
    let l2: Vec<f64> = rows
        .iter()
        .map(|r| r.l2_error)
        .filter(|v| v.is_finite())
        .collect();
    let first_overshoot = rows.windows(3).find(|w| {
        w[1].u_centre_exact > w[0].u_centre_exact && w[1].u_centre_exact >= w[2].u_centre_exact
    });
    let s = &sim.state;
    let u_relative_l2 = reference.relative_l2(
        &Dim::<D>::positions(map, &s.position),
        &Dim::<D>::velocities(map, &s.position, &s.velocity),
        s.time,
    );
    let stresses = ExactStresses::at_stress_time(sim, reference, dt);
    let [tau_xy, tau_xx, tau_yy] = stresses
        .as_ref()
        .map_or([None; 3], |s| s.relative_errors(sim, map));
    let wall_shear_exact = reference.wall_shear_stress(s.time);
    let errors = Errors {
        reference: Some(reference.name()),
        reference_unavailable: None,
        l2_time_mean: (!l2.is_empty()).then(|| l2.iter().sum::<f64>() / l2.len() as f64),
        l2_final: Some(last.l2_error),
        l2_max: Some(l2.iter().copied().fold(0.0, f64::max)),
        u_relative_l2,
        u_centre_final: last.u_centre,
        u_centre_exact_final: Some(last.u_centre_exact),
        u_centre_final_relative_error: Some(relative(last.u_centre, last.u_centre_exact)),
        first_overshoot: first_overshoot.map(|w| Peak {
            t: w[1].t,
            u_centre_exact: w[1].u_centre_exact,
            u_centre: w[1].u_centre,
            relative_error: relative(w[1].u_centre, w[1].u_centre_exact),
        }),
        tau_xy_relative_l2: tau_xy,
        tau_xx_relative_l2: tau_xx,
        tau_yy_relative_l2: tau_yy,
        wall_shear_stress: wall_shear_exact.and_then(|_| wall_shear(sim, map, reference.extent())),
        wall_shear_stress_exact: wall_shear_exact,
    };
    (errors, stresses)
}

/// The wall shear stress of a pipe of `radius` fitted from the particles of `sim`.
fn wall_shear<const D: usize>(sim: &Simulation<D>, map: PlaneMap, radius: f64) -> Option<f64>
where
    Dim<D>: StepDimension<D> + InPlane<D>,
{
    let s = &sim.state;
    let plane = Dim::<D>::positions(map, &s.position);
    let axial: Vec<f64> = s.velocity.iter().map(|v| v[0]).collect();
    let tau_xr: Vec<f64> = sim
        .polymer_stress()
        .iter()
        .zip(&s.position)
        .map(|(t, p)| Dim::<D>::stress(map, p, t)[1])
        .collect();
    let eta_s = sim.fluid.solvent_viscosity();
    pipe_wall::wall_shear_stress(&plane, &axial, &tau_xr, eta_s, radius)
}

/// One row of `profile.csv`: a particle at the end of the run. The analytic columns are
/// empty where there is no reference (or no exact stress), so they are options; they are
/// the reference's plane's components: for a pipe (x, r), `u_exact` axial, `tau_xy_exact`
/// τ_xr and `tau_yy_exact` τ_rr, beside the particle's Cartesian ones.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ProfileRow {
    #[serde(serialize_with = "fmt::sci8")]
    pub x: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub y: f64,
    /// In space only.
    #[serde(
        serialize_with = "fmt::opt_sci8",
        skip_serializing_if = "Option::is_none"
    )]
    pub z: Option<f64>,
    #[serde(serialize_with = "fmt::sci8")]
    pub u: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub v: f64,
    /// In space only.
    #[serde(
        serialize_with = "fmt::opt_sci8",
        skip_serializing_if = "Option::is_none"
    )]
    pub w: Option<f64>,
    #[serde(serialize_with = "fmt::opt_sci8")]
    pub u_exact: Option<f64>,
    #[serde(serialize_with = "fmt::sci8")]
    pub tau_xx: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub tau_xy: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub tau_yy: f64,
    /// In space only.
    #[serde(
        serialize_with = "fmt::opt_sci8",
        skip_serializing_if = "Option::is_none"
    )]
    pub tau_xz: Option<f64>,
    /// In space only.
    #[serde(
        serialize_with = "fmt::opt_sci8",
        skip_serializing_if = "Option::is_none"
    )]
    pub tau_yz: Option<f64>,
    /// In space only.
    #[serde(
        serialize_with = "fmt::opt_sci8",
        skip_serializing_if = "Option::is_none"
    )]
    pub tau_zz: Option<f64>,
    #[serde(serialize_with = "fmt::opt_sci8")]
    pub tau_xx_exact: Option<f64>,
    #[serde(serialize_with = "fmt::opt_sci8")]
    pub tau_xy_exact: Option<f64>,
    #[serde(serialize_with = "fmt::opt_sci8")]
    pub tau_yy_exact: Option<f64>,
    #[serde(serialize_with = "fmt::sci8")]
    pub p: f64,
    #[serde(serialize_with = "fmt::sci8")]
    pub eta: f64,
}

/// `profile.csv`: every particle at the end of the run with the analytic values at its height
/// (empty where there is no reference), its pressure p and the viscosity η of its viscous term
/// (η(γ̇) of a generalised Newtonian fluid, η_s otherwise), for post-processing and profile
/// comparisons.
pub fn profile_csv<const D: usize>(
    sim: &Simulation<D>,
    map: PlaneMap,
    reference: Option<&mut Reference>,
    stresses: Option<&ExactStresses>,
) -> String
where
    Dim<D>: StepDimension<D> + InPlane<D>,
{
    let s = &sim.state;
    let mut exact_u = Vec::new();
    let has_reference = reference.is_some();
    let heights = Dim::<D>::positions(map, &s.position);
    if let Some(r) = reference {
        r.velocity_at(&heights, s.time, &mut exact_u);
    }
    let third = |v: &nalgebra::SVector<f64, D>| (D == 3).then(|| v[D - 1]);
    let tau = sim.polymer_stress();
    let eta = sim.viscosity();
    let rows: Vec<ProfileRow> = s
        .position
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let height = heights[i].y;
            let ex =
                |f: fn(&ExactStresses) -> &Vec<f64>| stresses.map(|e| e.interpolate(f(e), height));
            let (u, t) = (&s.velocity[i], &tau[i]);
            ProfileRow {
                x: p[0],
                y: p[1],
                z: third(p),
                u: u[0],
                v: u[1],
                w: third(u),
                u_exact: has_reference.then(|| exact_u[i].x),
                tau_xx: t.entry(0, 0),
                tau_xy: t.entry(0, 1),
                tau_yy: t.entry(1, 1),
                tau_xz: (D == 3).then(|| t.entry(0, D - 1)),
                tau_yz: (D == 3).then(|| t.entry(1, D - 1)),
                tau_zz: (D == 3).then(|| t.entry(D - 1, D - 1)),
                tau_xx_exact: ex(|e| &e.profiles.xx),
                tau_xy_exact: ex(|e| &e.profiles.xy),
                tau_yy_exact: ex(|e| &e.profiles.yy),
                p: s.pressure[i],
                eta: eta[i],
            }
        })
        .collect();
    table::write_rows(&rows)
}
