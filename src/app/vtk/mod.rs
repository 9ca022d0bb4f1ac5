//! ParaView snapshots: one VTK XML unstructured grid (`.vtu`) per snapshot time, every
//! particle a vertex cell, the same state interpolated on a regular grid (`.vti`, see
//! [`crate::analysis::grid`]), and a `.pvd` collection of each listing the files with their
//! times. Encoded in memory by [`xml`], then written atomically.

pub mod xml;

use crate::analysis::grid::{self, GridFields};
use crate::app::io::write_atomic;
use crate::engine::dimension::{Dim, SymTensor};
use crate::engine::free_surface::FreeSurface;
use crate::engine::step::{Simulation, StepDimension};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use xml::DataArray;

/// Particle kinds in the `kind` array (ghosts are not written).
pub const KIND_FLUID: u8 = 0;

/// The `.vtu` document of the current state.
pub fn snapshot(sim: &Simulation) -> Vec<u8> {
    let s = &sim.state;
    let n = s.position.len();
    let points: Vec<f64> = s.position.iter().flat_map(|p| [p.x, p.y, 0.0]).collect();
    let velocity: Vec<f64> = s.velocity.iter().flat_map(|u| [u.x, u.y, 0.0]).collect();
    let fields = grid::particle_fields(sim);
    let kind = vec![KIND_FLUID; n];
    // FS membership of the last step (by (36), the exposure test or a contact corner), NS,
    // and (36)'s ⟨∇·r⟩ (a member above its threshold came in by exposure or as a corner);
    // closed domains have none.
    let flags = |f: fn(&FreeSurface) -> &[bool]| -> Vec<u8> {
        sim.surface()
            .map_or(vec![0; n], |fs| f(fs).iter().map(|&b| b as u8).collect())
    };
    let free_surface = flags(|fs| &fs.on_surface);
    let near_surface = flags(|fs| &fs.near_surface);
    let divergence: Vec<f64> = sim
        .surface()
        .map_or(vec![0.0; n], |fs| fs.position_divergence.clone());
    let mut arrays = vec![DataArray::F64 {
        name: "velocity",
        components: 3,
        values: &velocity,
    }];
    // u and v are in `velocity`.
    arrays.extend(
        fields[2..]
            .iter()
            .map(|(name, v)| DataArray::scalars(name, v)),
    );
    arrays.push(DataArray::U8 {
        name: "kind",
        values: &kind,
    });
    arrays.push(DataArray::U8 {
        name: "free_surface",
        values: &free_surface,
    });
    arrays.push(DataArray::U8 {
        name: "near_surface",
        values: &near_surface,
    });
    arrays.push(DataArray::scalars("position_divergence", &divergence));
    xml::unstructured_vertices(&points, &arrays)
}

/// The `.vtu` document of the particles of a simulation in D dimensions: velocity,
/// pressure and, for a viscoelastic fluid, the polymer stress's components (`tau_xx`,
/// `tau_xy`, …), tr A and det A. The plane's snapshot ([`snapshot`]) adds the vorticity and
/// the free surface's flags.
pub fn particles<const D: usize>(sim: &Simulation<D>) -> Vec<u8>
where
    Dim<D>: StepDimension<D>,
{
    let s = &sim.state;
    let n = s.position.len();
    let xyz = |v: &nalgebra::SVector<f64, D>| [0, 1, 2].map(|a| if a < D { v[a] } else { 0.0 });
    let points: Vec<f64> = s.position.iter().flat_map(xyz).collect();
    let velocity: Vec<f64> = s.velocity.iter().flat_map(xyz).collect();
    let mut scalars: Vec<(String, Vec<f64>)> = vec![("pressure".into(), s.pressure.clone())];
    if !s.conformation.is_empty() {
        let tau = sim.polymer_stress();
        let axes = ["x", "y", "z"];
        for i in 0..D {
            for j in i..D {
                let values = tau.iter().map(|t| t.entry(i, j)).collect();
                scalars.push((format!("tau_{}{}", axes[i], axes[j]), values));
            }
        }
        let (trace, det) = s.conformation.iter().map(|a| (a.trace(), a.det())).unzip();
        scalars.push(("trace_A".into(), trace));
        scalars.push(("det_A".into(), det));
    }
    let kind = vec![KIND_FLUID; n];
    let mut arrays = vec![DataArray::F64 {
        name: "velocity",
        components: 3,
        values: &velocity,
    }];
    arrays.extend(scalars.iter().map(|(name, v)| DataArray::scalars(name, v)));
    arrays.push(DataArray::U8 {
        name: "kind",
        values: &kind,
    });
    xml::unstructured_vertices(&points, &arrays)
}

/// The `.vti` document of grid fields: a `velocity` vector, the scalars, and `fluid` (1 at
/// nodes inside the fluid; the fields are NaN elsewhere).
pub fn grid_snapshot(g: &GridFields) -> Vec<u8> {
    let column = |name: &str| {
        g.fields
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(&[][..], |(_, v)| v.as_slice())
    };
    let velocity: Vec<f64> = column("u")
        .iter()
        .zip(column("v"))
        .flat_map(|(u, v)| [*u, *v, 0.0])
        .collect();
    let mut arrays = vec![DataArray::F64 {
        name: "velocity",
        components: 3,
        values: &velocity,
    }];
    arrays.extend(
        g.fields
            .iter()
            .filter(|(name, _)| !matches!(*name, "u" | "v"))
            .map(|(name, v)| DataArray::scalars(name, v)),
    );
    arrays.push(DataArray::U8 {
        name: "fluid",
        values: &g.fluid,
    });
    let spec = &g.spec;
    xml::image_data(
        [spec.origin.x, spec.origin.y],
        [spec.spacing.x, spec.spacing.y],
        spec.dims,
        &arrays,
    )
}

/// A run's snapshot series: `snapshots/step_NNNNNNNN.vtu` plus `snapshots.pvd`, and with a
/// grid `snapshots/step_NNNNNNNN.vti` plus `grid.pvd`.
pub struct Series {
    dir: PathBuf,
    /// Node spacing of the grid snapshots (None: particles only).
    grid_spacing: Option<f64>,
    entries: Vec<(f64, String)>,
}

impl Series {
    pub fn new(run_dir: &Path, grid_spacing: Option<f64>) -> Result<Self> {
        let dir = run_dir.join("snapshots");
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self {
            dir,
            grid_spacing,
            entries: Vec::new(),
        })
    }

    /// Writes the current state and rewrites the collections.
    pub fn write(&mut self, sim: &Simulation) -> Result<()> {
        let name = self.write_particles(sim.state.time, sim.state.steps, &snapshot(sim))?;
        if let Some(spacing) = self.grid_spacing {
            let parent = self.dir.parent().unwrap_or(&self.dir).to_path_buf();
            let grid = grid::interpolate(sim, spacing);
            let name = name.replace(".vtu", ".vti");
            write_atomic(&self.dir.join(name), &grid_snapshot(&grid))?;
            write_atomic(&parent.join("grid.pvd"), &collection(&self.entries, "vti"))?;
        }
        Ok(())
    }

    /// Writes the particles' `document` (a `.vtu`) of step `steps` at time `t` and rewrites
    /// `snapshots.pvd`; returns the file's name.
    pub fn write_particles(&mut self, t: f64, steps: u64, document: &[u8]) -> Result<String> {
        let name = format!("step_{steps:08}.vtu");
        write_atomic(&self.dir.join(&name), document)?;
        self.entries.push((t, format!("snapshots/{name}")));
        let parent = self.dir.parent().unwrap_or(&self.dir).to_path_buf();
        write_atomic(
            &parent.join("snapshots.pvd"),
            &collection(&self.entries, "vtu"),
        )?;
        Ok(name)
    }

    /// The (time, file) entries of the collection.
    pub fn entries(&self) -> &[(f64, String)] {
        &self.entries
    }

    /// Continues a collection after a restart from a checkpoint: later files are dropped
    /// from it (they will be rewritten).
    pub fn restore_entries(&mut self, entries: Vec<(f64, String)>) {
        self.entries = entries;
    }

    /// Time of the last snapshot written.
    pub fn last_time(&self) -> Option<f64> {
        self.entries.last().map(|e| e.0)
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// A `.pvd` collection of the entries' files with the extension `ext`.
fn collection(entries: &[(f64, String)], ext: &str) -> Vec<u8> {
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, file) in entries {
        let file = file.replace(".vtu", &format!(".{ext}"));
        let _ = writeln!(
            pvd,
            "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        );
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    pvd.into_bytes()
}
