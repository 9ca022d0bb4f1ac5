//! The PNG charts of a run: centre-line velocity and L2 error against time, and the final
//! profiles across the channel, each against the analytic reference where there is one.

use super::errors::ExactStresses;
use super::probes::centreline::{CentrelineColumn, CentrelineRow};
use crate::analysis::plane::{InPlane, PlaneMap};
use crate::analysis::reference::Reference;
use crate::app::io::SeriesRow;
use crate::app::plot::FigureFormat;
use crate::app::plot::{self, Chart, Curve, CurveStyle, PALETTE};
use crate::engine::dimension::Dim;
use crate::engine::step::{Simulation, StepDimension};
use crate::setup::scenes::Scene;
use anyhow::Result;
use std::path::Path;

fn analytic(points: Vec<(f64, f64)>) -> Curve {
    Curve {
        label: "analytic".into(),
        points,
        style: CurveStyle::Line,
        color: PALETTE[1],
    }
}

/// Draws every chart of the run directory.
pub fn draw<const D: usize>(
    dir: &Path,
    format: FigureFormat,
    scene: &dyn Scene,
    sim: &Simulation<D>,
    reference: Option<&Reference>,
    rows: &[SeriesRow],
    stresses: Option<&ExactStresses>,
) -> Result<()>
where
    Dim<D>: StepDimension<D> + InPlane<D>,
{
    let (title, axis) = scene.characteristic_name();
    let mut curves = vec![Curve {
        label: "rheosph".into(),
        points: rows.iter().map(|r| (r.t, r.u_centre)).collect(),
        style: CurveStyle::Dashed,
        color: PALETTE[0],
    }];
    if let Some(r) = reference {
        let label = match r.name() {
            _ if r.is_steady() => "steady state",
            "startup-pipe" => "Bessel series",
            _ => "Waters & King",
        };
        curves.insert(
            0,
            Curve {
                label: label.into(),
                points: rows.iter().map(|r| (r.t, r.u_centre_exact)).collect(),
                style: CurveStyle::Line,
                color: PALETTE[1],
            },
        );
    }
    plot::draw(
        &dir.join("centre_velocity.png"),
        format,
        &Chart {
            title: format!("{title} ({})", sim.fluid.model_name()),
            x_label: "t".into(),
            y_label: axis.into(),
            ..Default::default()
        },
        &curves,
    )?;
    if reference.is_some() {
        plot::draw(
            &dir.join("l2_error.png"),
            format,
            &Chart {
                title: "Velocity L2 error".into(),
                x_label: "t".into(),
                y_label: "L2 error / U".into(),
                log_y: true,
                ..Default::default()
            },
            &[Curve {
                label: String::new(),
                points: rows.iter().skip(1).map(|r| (r.t, r.l2_error)).collect(),
                style: CurveStyle::Line,
                color: PALETTE[0],
            }],
        )?;
    }
    if scene.varies_across_height() {
        profiles(dir, format, sim, scene.plane(), reference, stresses)
    } else {
        Ok(())
    }
}

/// Final profiles across the channel (or along a pipe's radius): every particle against the
/// analytic line.
fn profiles<const D: usize>(
    dir: &Path,
    format: FigureFormat,
    sim: &Simulation<D>,
    map: PlaneMap,
    reference: Option<&Reference>,
    stresses: Option<&ExactStresses>,
) -> Result<()>
where
    Dim<D>: StepDimension<D> + InPlane<D>,
{
    let s = &sim.state;
    let box_height = sim.domain.max[1] - sim.domain.min[1];
    let (across, height) = match map {
        PlaneMap::Cartesian => ("the channel", box_height),
        PlaneMap::Meridional { .. } => ("the pipe's radius", 0.5 * box_height),
    };
    let x_label = if across == "the channel" { "y" } else { "r" };
    let plane = Dim::<D>::positions(map, &s.position);
    let profile =
        |name: &str, label: &str, numeric: Vec<(f64, f64)>, exact: Option<Vec<(f64, f64)>>| {
            let mut curves = Vec::new();
            if let Some(points) = exact {
                curves.push(analytic(points));
            }
            curves.push(Curve {
                label: "particles".into(),
                points: numeric,
                style: CurveStyle::Markers,
                color: PALETTE[0],
            });
            plot::draw(
                &dir.join(name),
                format,
                &Chart {
                    title: format!("{label} across {across} at t = {:.3}", s.time),
                    x_label: x_label.into(),
                    y_label: label.into(),
                    ..Default::default()
                },
                &curves,
            )
        };
    let ys: Vec<f64> = (0..=200).map(|k| height * k as f64 / 200.0).collect();
    let exact_u = reference.map(|r| {
        ys.iter()
            .copied()
            .zip(r.velocity_profile(&ys, s.time))
            .collect()
    });
    profile(
        "profile_velocity.png",
        "u",
        plane
            .iter()
            .zip(&s.velocity)
            .map(|(p, u)| (p.y, u[0]))
            .collect(),
        exact_u,
    )?;
    if !sim.fluid.model.is_viscoelastic() {
        return Ok(());
    }
    let tau = sim.polymer_stress();
    let exact = |values: fn(&ExactStresses) -> &Vec<f64>| {
        stresses.map(|e| {
            e.grid
                .iter()
                .copied()
                .zip(values(e).iter().copied())
                .collect()
        })
    };
    // (τ_xx, τ_xy, τ_yy) in the plane: (τ_xx, τ_xr, τ_rr) for a pipe.
    let numeric = |component: usize| -> Vec<(f64, f64)> {
        s.position
            .iter()
            .zip(plane.iter())
            .zip(&tau)
            .map(|((p, q), t)| (q.y, Dim::<D>::stress(map, p, t)[component]))
            .collect()
    };
    let shear = if x_label == "y" {
        "tau_p,xy"
    } else {
        "tau_p,xr"
    };
    profile(
        "profile_tau_xy.png",
        shear,
        numeric(1),
        exact(|e| &e.profiles.xy),
    )?;
    profile(
        "profile_tau_xx.png",
        "tau_p,xx",
        numeric(0),
        exact(|e| &e.profiles.xx),
    )?;
    if matches!(sim.fluid.model, crate::engine::rheology::Model::Giesekus(_)) {
        profile(
            "profile_tau_yy.png",
            "tau_p,yy",
            numeric(2),
            exact(|e| &e.profiles.yy),
        )?;
    }
    Ok(())
}

/// The charts of a channel with a cylinder: ⟨u⟩ and K against time, the averaged centre-line
/// profiles (the rows of `centreline.csv`), and the final vorticity and
/// tr A fields.
pub fn cylinder(
    dir: &Path,
    format: FigureFormat,
    sim: &Simulation,
    rows: &[SeriesRow],
    profile: &[CentrelineRow],
    disc: ((f64, f64), f64),
) -> Result<()> {
    let line = |points: Vec<(f64, f64)>| Curve {
        label: String::new(),
        points,
        style: CurveStyle::Line,
        color: PALETTE[0],
    };
    let time_chart = |name: &str, title: &str, y: &str, f: &dyn Fn(&SeriesRow) -> f64| {
        plot::draw(
            &dir.join(name),
            format,
            &Chart {
                title: title.into(),
                x_label: "t".into(),
                y_label: y.into(),
                ..Default::default()
            },
            &[line(rows.iter().skip(1).map(|r| (r.t, f(r))).collect())],
        )
    };
    time_chart("u_mean.png", "Bulk velocity <u> = Q/H", "<u>", &|r| {
        r.u_mean
    })?;
    time_chart(
        "drag.png",
        "Drag coefficient K = F_x/(eta0 <u>)",
        "K",
        &|r| r.drag_k,
    )?;
    let columns: [(CentrelineColumn, &str, &str, &str); 3] = [
        (
            |r| r.u_over_umean,
            "centreline_u.png",
            "Centre-line velocity between cylinders",
            "u/<u>",
        ),
        (
            |r| r.tau_xx_scaled,
            "centreline_tau_xx.png",
            "Centre-line polymer stress",
            "tau_xx/(eta_s <u>/R)",
        ),
        (
            |r| r.det_a,
            "centreline_det_a.png",
            "Centre-line det A",
            "det A",
        ),
    ];
    for (value, name, title, y) in columns {
        plot::draw(
            &dir.join(name),
            format,
            &Chart {
                title: title.into(),
                x_label: "s (0: downstream edge of a cylinder)".into(),
                y_label: y.into(),
                ..Default::default()
            },
            &[line(profile.iter().map(|p| (p.s, value(p))).collect())],
        )?;
    }
    let points: Vec<(f64, f64)> = sim.state.position.iter().map(|p| (p.x, p.y)).collect();
    let extent = sim.domain.size();
    let extent = ((0.0, extent.x), (0.0, extent.y));
    let t = sim.state.time;
    plot::draw_field(
        &dir.join("field_vorticity.png"),
        format,
        &plot::Field {
            title: format!("Vorticity, t = {t:.3}"),
            points: &points,
            values: &sim.vorticity(),
            extent,
            spacing: sim.spacing,
            diverging: true,
            disc: Some(disc),
        },
    )?;
    let trace = trace_a(sim);
    plot::draw_field(
        &dir.join("field_trace_a.png"),
        format,
        &plot::Field {
            title: format!("tr A, t = {t:.3}"),
            points: &points,
            values: &trace,
            extent,
            spacing: sim.spacing,
            diverging: false,
            disc: Some(disc),
        },
    )
}

/// A PNG of a free-surface scene's particles coloured by tr A, cropped to the fluid's bounding
/// box (two spacings of margin) from the plate up: `dir/name`.
pub fn free_surface_snapshot(
    dir: &Path,
    format: FigureFormat,
    sim: &Simulation,
    title: &str,
    name: &str,
) -> Result<()> {
    let points: Vec<(f64, f64)> = sim.state.position.iter().map(|p| (p.x, p.y)).collect();
    let trace = trace_a(sim);
    let margin = 2.0 * sim.spacing;
    let (lo, hi) = points.iter().fold(
        ((f64::INFINITY, f64::NEG_INFINITY), f64::NEG_INFINITY),
        |((a, b), c), p| ((a.min(p.0), b.max(p.0)), c.max(p.1)),
    );
    std::fs::create_dir_all(dir)?;
    plot::draw_field(
        &dir.join(name),
        format,
        &plot::Field {
            title: title.into(),
            points: &points,
            values: &trace,
            extent: ((lo.0 - margin, lo.1 + margin), (0.0, hi + margin)),
            spacing: sim.spacing,
            diverging: false,
            disc: None,
        },
    )
}

/// tr A of every particle (2, the rest state, for a Newtonian fluid).
fn trace_a(sim: &Simulation) -> Vec<f64> {
    if sim.state.conformation.is_empty() {
        vec![2.0; sim.particles()]
    } else {
        sim.state.conformation.iter().map(|a| a.trace()).collect()
    }
}
