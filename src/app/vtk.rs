//! ParaView snapshots: one VTK XML unstructured grid (`.vtu`) per snapshot time, every
//! particle a vertex cell, and a `.pvd` collection listing the files with their times.
//! Written through vtkio (XML, base64 binary arrays) into memory, then atomically to disk.

use crate::app::io::write_atomic;
use crate::engine::step::Simulation;
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, IOBuffer, UnstructuredGridPiece,
    Version, VertexNumbers, Vtk,
};

/// Particle kinds in the `kind` array (ghosts are not written).
pub const KIND_FLUID: u8 = 0;

/// The `.vtu` document of the current state.
pub fn snapshot(sim: &Simulation) -> Result<Vec<u8>> {
    let s = &sim.state;
    let n = s.position.len();
    let points: Vec<f64> = s.position.iter().flat_map(|p| [p.x, p.y, 0.0]).collect();
    let velocity: Vec<f64> = s.velocity.iter().flat_map(|u| [u.x, u.y, 0.0]).collect();
    let tau = sim.polymer_stress();
    let (trace, det): (Vec<f64>, Vec<f64>) = if s.conformation.is_empty() {
        (vec![2.0; n], vec![1.0; n])
    } else {
        s.conformation.iter().map(|a| (a.trace(), a.det())).unzip()
    };
    let scalar =
        |name: &str, data: Vec<f64>| Attribute::scalars(name, 1).with_data(IOBuffer::F64(data));
    let vtk = Vtk {
        version: Version { major: 1, minor: 0 },
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity: (0..n as u64).collect(),
                    offsets: (1..=n as u64).collect(),
                },
                types: vec![CellType::Vertex; n],
            },
            data: Attributes {
                point: vec![
                    Attribute::vectors("velocity").with_data(IOBuffer::F64(velocity)),
                    scalar("pressure", s.pressure.clone()),
                    scalar("vorticity", sim.vorticity()),
                    scalar("tau_xx", tau.iter().map(|t| t.xx).collect()),
                    scalar("tau_xy", tau.iter().map(|t| t.xy).collect()),
                    scalar("tau_yy", tau.iter().map(|t| t.yy).collect()),
                    scalar("trace_A", trace),
                    scalar("det_A", det),
                    Attribute::scalars("kind", 1).with_data(IOBuffer::U8(vec![KIND_FLUID; n])),
                    // FS membership (36) of the last step; closed domains have none.
                    Attribute::scalars("free_surface", 1).with_data(IOBuffer::U8(
                        sim.surface().map_or(vec![0; n], |fs| {
                            fs.on_surface.iter().map(|&f| f as u8).collect()
                        }),
                    )),
                ],
                cell: Vec::new(),
            },
        }),
    };
    let mut bytes = Vec::new();
    vtk.write_xml(&mut bytes).context("encoding .vtu")?;
    Ok(bytes)
}

/// A run's snapshot series: `snapshots/step_NNNNNNNN.vtu` plus `snapshots.pvd`.
pub struct Series {
    dir: PathBuf,
    entries: Vec<(f64, String)>,
}

impl Series {
    pub fn new(run_dir: &Path) -> Result<Self> {
        let dir = run_dir.join("snapshots");
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self {
            dir,
            entries: Vec::new(),
        })
    }

    /// Writes the current state and rewrites the collection.
    pub fn write(&mut self, sim: &Simulation) -> Result<()> {
        let name = format!("step_{:08}.vtu", sim.state.steps);
        write_atomic(&self.dir.join(&name), &snapshot(sim)?)?;
        self.entries
            .push((sim.state.time, format!("snapshots/{name}")));
        let mut pvd = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (t, file) in &self.entries {
            let _ = writeln!(
                pvd,
                "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
            );
        }
        pvd.push_str("  </Collection>\n</VTKFile>\n");
        let parent = self.dir.parent().unwrap_or(&self.dir);
        write_atomic(&parent.join("snapshots.pvd"), pvd.as_bytes())
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
