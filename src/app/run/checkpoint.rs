//! Checkpoints: the run loop's state and the state of its [`Simulation`] in one file
//! (`checkpoint.bin` in the run directory), from which a run continues bit-identically to one
//! never interrupted. This file owns the format.
//!
//! The file is the loop state as JSON, prefixed by its length (u64, little-endian), followed
//! by the simulation's checkpoint ([`encode`]).
//!
//! A step depends on nothing but [`State`] and caches that are rebuilt deterministically from
//! it: the Morton reordering is due by step count, the PPE and implicit viscous solves are
//! warm-started from `pressure` and `velocity`, BiCGStab re-initialises every work vector,
//! and the neighbour lists, kernel sums, matrices and LU factors are recomputed from the
//! positions (an Eulerian run rebuilds its fixed lists and refactorises once after a restore).
//!
//! The simulation's part, version 3, all numbers little-endian, f64 as raw IEEE bits:
//!
//! ```text
//!     magic      9 bytes  "RHEOSPHCK"
//!     version    u32      3
//!     flags      u32      bit 0: conformation stored; bit 1: Eulerian frame; bit 2: discs;
//!                         bit 3: space (D = 3; else the plane, D = 2)
//!     particles  u64      n
//!     spacing    f64      δr
//!     time       f64
//!     steps      u64
//!     body force D × f64    (the drive's force of the next step)
//!     previous δt f64       (the last step, which places A^{n−½} in time)
//!     position        n × (x, y[, z])
//!     velocity        n × (x, y[, z])
//!     pressure        n × p
//!     conformation    n × (xx, xy, yy) or (xx, xy, xz, yy, yz, zz), present with bit 0
//!     shift_velocity  n × (x, y[, z])
//!     discs           7 values a disc, present with bit 2
//!     checksum   u64      FNV-1a of every preceding byte
//! ```

use crate::engine::bodies::BodyRecord;
use crate::engine::dimension::{Dim, Sym, SymTensor, Vector};
use crate::engine::frame::Frame;
use crate::engine::step::{Simulation, State, StepDimension};
use std::path::Path;

/// The first bytes of every checkpoint.
pub const MAGIC: &[u8; 9] = b"RHEOSPHCK";
/// The format version written by [`encode`].
pub const VERSION: u32 = 3;

const FLAG_CONFORMATION: u32 = 1;
const FLAG_EULERIAN: u32 = 2;
/// The rigid bodies' records follow the particles ([`BodyRecord`]: a disc's centre, velocity,
/// spin and acceleration; a turning sphere's spin and torque; the case says how many).
const FLAG_DISCS: u32 = 4;
/// A simulation in space: three components a vector, six a conformation.
const FLAG_SPACE: u32 = 8;
const KNOWN_FLAGS: u32 = FLAG_CONFORMATION | FLAG_EULERIAN | FLAG_DISCS | FLAG_SPACE;
const VALUES_PER_DISC: usize = std::mem::size_of::<BodyRecord>() / 8;

/// Space dimensions of a checkpoint with these flags.
fn dimension(flags: u32) -> usize {
    if flags & FLAG_SPACE != 0 {
        3
    } else {
        2
    }
}

/// Bytes before the particle arrays.
fn header(flags: u32) -> usize {
    MAGIC.len() + 4 + 4 + 8 + 8 + 8 + 8 + 8 * dimension(flags) + 8
}

/// Bytes before the header's body force: enough to read the flags.
const PREAMBLE: usize = MAGIC.len() + 4 + 4;
const CHECKSUM: usize = 8;

/// Why a checkpoint could not be restored.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("not a rheosph checkpoint (wrong magic bytes)")]
    Magic,
    #[error("unsupported checkpoint version {found} (this build reads version {VERSION})")]
    Version { found: u32 },
    #[error("checkpoint truncated: {found} bytes, expected {expected}")]
    Truncated { found: usize, expected: usize },
    #[error("checkpoint has {0} unexpected trailing bytes")]
    Trailing(usize),
    #[error("checkpoint checksum mismatch: the file is corrupt")]
    Checksum,
    #[error("checkpoint does not match the simulation: {0}")]
    Mismatch(String),
    #[error("reading checkpoint: {0}")]
    Io(#[from] std::io::Error),
}

/// FNV-1a, 64 bit.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn flags_of<const D: usize>(sim: &Simulation<D>) -> u32
where
    Dim<D>: StepDimension<D>,
{
    let mut flags = 0;
    if sim.fluid.model.is_viscoelastic() {
        flags |= FLAG_CONFORMATION;
    }
    if sim.scheme.frame == Frame::Eulerian {
        flags |= FLAG_EULERIAN;
    }
    if !sim.body_motions().is_empty() {
        flags |= FLAG_DISCS;
    }
    if D == 3 {
        flags |= FLAG_SPACE;
    }
    flags
}

/// f64 values per particle of a checkpoint with these flags.
fn values_per_particle(flags: u32) -> usize {
    let d = dimension(flags);
    let conformation = if flags & FLAG_CONFORMATION != 0 {
        d * (d + 1) / 2
    } else {
        0
    };
    d + d + 1 + conformation + d
}

/// The checkpoint of `sim`.
pub fn encode<const D: usize>(sim: &Simulation<D>) -> Vec<u8>
where
    Dim<D>: StepDimension<D>,
{
    let s = &sim.state;
    let flags = flags_of(sim);
    let n = s.position.len();
    let motions = sim.body_motions();
    let discs = 8 * VALUES_PER_DISC * motions.len();
    let size = header(flags) + 8 * n * values_per_particle(flags) + discs + CHECKSUM;
    let mut out = Vec::with_capacity(size);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&flags.to_le_bytes());
    out.extend_from_slice(&(n as u64).to_le_bytes());
    out.extend_from_slice(&sim.spacing.to_le_bytes());
    out.extend_from_slice(&s.time.to_le_bytes());
    out.extend_from_slice(&s.steps.to_le_bytes());
    let mut put = |v: f64| out.extend_from_slice(&v.to_le_bytes());
    s.body_force.iter().for_each(|&v| put(v));
    put(s.previous_dt);
    for field in [&s.position, &s.velocity] {
        field.iter().flat_map(|u| u.iter()).for_each(|&v| put(v));
    }
    s.pressure.iter().for_each(|&p| put(p));
    if flags & FLAG_CONFORMATION != 0 {
        for a in &s.conformation {
            (0..D).for_each(|i| (i..D).for_each(|j| put(a.entry(i, j))));
        }
    }
    s.shift_velocity
        .iter()
        .flat_map(|u| u.iter())
        .for_each(|&v| put(v));
    motions.iter().flatten().for_each(|&v| put(v));
    let checksum = fnv1a(&out);
    out.extend_from_slice(&checksum.to_le_bytes());
    out
}

/// Little-endian reader over bytes whose length has already been checked.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut a = [0; N];
        a.copy_from_slice(&self.bytes[self.at..self.at + N]);
        self.at += N;
        a
    }

    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }

    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }

    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }

    fn vector<const D: usize>(&mut self) -> Vector<D> {
        let mut v = Vector::<D>::zeros();
        v.iter_mut().for_each(|c| *c = self.f64());
        v
    }

    fn vectors<const D: usize>(&mut self, n: usize) -> Vec<Vector<D>> {
        (0..n).map(|_| self.vector()).collect()
    }

    /// A symmetric tensor stored as its upper triangle, row by row.
    fn sym<const D: usize>(&mut self) -> Sym<D>
    where
        Dim<D>: StepDimension<D>,
    {
        let mut upper = [0.0; 6];
        for value in upper.iter_mut().take(D * (D + 1) / 2) {
            *value = self.f64();
        }
        let index = |i: usize, j: usize| {
            let (i, j) = (i.min(j), i.max(j));
            i * D - i * (i + 1) / 2 + j
        };
        Sym::<D>::from_entries(|i, j| upper[index(i, j)])
    }
}

/// Restores the checkpoint `bytes` into `sim`, a simulation built from the same case. On
/// error `sim` is left unchanged.
pub fn restore<const D: usize>(sim: &mut Simulation<D>, bytes: &[u8]) -> Result<(), CheckpointError>
where
    Dim<D>: StepDimension<D>,
{
    let magic_len = MAGIC.len().min(bytes.len());
    if bytes[..magic_len] != MAGIC[..magic_len] {
        return Err(CheckpointError::Magic);
    }
    let truncated = |expected: usize| CheckpointError::Truncated {
        found: bytes.len(),
        expected,
    };
    if bytes.len() < MAGIC.len() + 4 {
        return Err(truncated(header(0) + CHECKSUM));
    }
    let mut r = Reader {
        bytes,
        at: MAGIC.len(),
    };
    let version = r.u32();
    if version != VERSION {
        return Err(CheckpointError::Version { found: version });
    }
    if bytes.len() < PREAMBLE {
        return Err(truncated(header(0) + CHECKSUM));
    }
    let flags = r.u32();
    if bytes.len() < header(flags) + CHECKSUM {
        return Err(truncated(header(flags) + CHECKSUM));
    }
    if flags & !KNOWN_FLAGS != 0 {
        return Err(CheckpointError::Mismatch(format!(
            "unknown flags {flags:#x}"
        )));
    }
    let n = r.u64();
    let discs = if flags & FLAG_DISCS != 0 {
        8 * VALUES_PER_DISC * sim.body_motions().len()
    } else {
        0
    };
    let expected = usize::try_from(n)
        .ok()
        .and_then(|n| n.checked_mul(8 * values_per_particle(flags)))
        .and_then(|body| body.checked_add(header(flags) + discs + CHECKSUM))
        .unwrap_or(usize::MAX);
    if bytes.len() < expected {
        return Err(truncated(expected));
    }
    if bytes.len() > expected {
        return Err(CheckpointError::Trailing(bytes.len() - expected));
    }
    let (body, stored) = bytes.split_at(expected - CHECKSUM);
    if fnv1a(body).to_le_bytes() != stored {
        return Err(CheckpointError::Checksum);
    }

    let n = n as usize;
    let mismatch = |m: String| Err(CheckpointError::Mismatch(m));
    if n != sim.particles() {
        return mismatch(format!(
            "{n} particles stored, the simulation has {}",
            sim.particles()
        ));
    }
    let wanted = flags_of(sim);
    if flags & FLAG_CONFORMATION != wanted & FLAG_CONFORMATION {
        return mismatch(
            "conformation stored for a Newtonian fluid, or missing for a viscoelastic one".into(),
        );
    }
    if flags & FLAG_EULERIAN != wanted & FLAG_EULERIAN {
        return mismatch("the frames (Lagrangian/Eulerian) differ".into());
    }
    if flags & FLAG_DISCS != wanted & FLAG_DISCS {
        return mismatch("discs stored for a scene without, or missing for one with".into());
    }
    if flags & FLAG_SPACE != wanted & FLAG_SPACE {
        return mismatch("the dimensions (2D/3D) differ".into());
    }
    let spacing = r.f64();
    if spacing.to_bits() != sim.spacing.to_bits() {
        return mismatch(format!(
            "particle spacing {spacing:e} stored, the simulation has {:e}",
            sim.spacing
        ));
    }
    let time = r.f64();
    let steps = r.u64();
    let body_force = r.vector();
    let previous_dt = r.f64();
    let position = r.vectors(n);
    let velocity = r.vectors(n);
    let pressure = (0..n).map(|_| r.f64()).collect();
    let conformation = if flags & FLAG_CONFORMATION != 0 {
        (0..n).map(|_| r.sym()).collect()
    } else {
        Vec::new()
    };
    let shift_velocity = r.vectors(n);
    let discs = read_discs(&mut r, discs / (8 * VALUES_PER_DISC));
    debug_assert_eq!(r.at, body.len());
    sim.restore_state(State {
        time,
        steps,
        position,
        velocity,
        pressure,
        conformation,
        previous_dt,
        shift_velocity,
        body_force,
    });
    sim.restore_bodies(&discs);
    Ok(())
}

/// The bodies' block: each body's record ([`BodyRecord`]).
fn read_discs(r: &mut Reader, count: usize) -> Vec<BodyRecord> {
    (0..count)
        .map(|_| std::array::from_fn(|_| r.f64()))
        .collect()
}

/// Writes the checkpoint of `sim` to `path` atomically.
pub fn write<const D: usize>(path: &Path, sim: &Simulation<D>) -> std::io::Result<()>
where
    Dim<D>: StepDimension<D>,
{
    crate::app::io::write_atomic(path, &encode(sim)).map_err(|e| {
        let kind = e
            .root_cause()
            .downcast_ref::<std::io::Error>()
            .map_or(std::io::ErrorKind::Other, |io| io.kind());
        std::io::Error::new(kind, format!("{e:#}"))
    })
}

/// Reads the checkpoint at `path` and restores it into `sim` (see [`restore`]).
pub fn read<const D: usize>(path: &Path, sim: &mut Simulation<D>) -> Result<(), CheckpointError>
where
    Dim<D>: StepDimension<D>,
{
    let bytes = std::fs::read(path)?;
    restore(sim, &bytes)
}

/// The checkpoint file of a run directory.
/// A finished run's final state, in the simulation encoding of [`encode`], for `run --from`.
pub const FINAL_STATE_FILE: &str = "final_state.bin";
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";

/// The run loop's own state, saved with each checkpoint.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct LoopState {
    pub case_name: String,
    pub cadence: super::cadence::Cadence,
    pub window: super::summary::PpeWindow,
    pub totals: super::summary::PpeWindow,
    pub last_dt: f64,
    /// The `.vtu` snapshots written so far (time, file).
    pub snapshots: Vec<(f64, String)>,
    /// The probes' own state, by name.
    #[serde(default)]
    pub probes: std::collections::BTreeMap<String, serde_json::Value>,
    /// Wall seconds the run had spent up to this checkpoint, over all its segments (0 in
    /// checkpoints written before it was recorded).
    #[serde(default)]
    pub wall_seconds: f64,
    /// The per-stage timing up to this checkpoint, so a resumed run's breakdown covers the
    /// whole run.
    #[serde(default)]
    pub stage_seconds: crate::engine::timing::StageSeconds,
}

/// Writes the checkpoint file: the loop state and the simulation, atomically.
pub fn save<const D: usize>(
    dir: &Path,
    state: &LoopState,
    sim: &Simulation<D>,
) -> anyhow::Result<()>
where
    Dim<D>: StepDimension<D>,
{
    let json = serde_json::to_vec(state)?;
    let mut bytes = (json.len() as u64).to_le_bytes().to_vec();
    bytes.extend_from_slice(&json);
    bytes.extend_from_slice(&encode(sim));
    crate::app::io::write_atomic(&dir.join(CHECKPOINT_FILE), &bytes)
}

/// Reads a run directory's checkpoint file: the loop state and the simulation's bytes (for
/// [`restore`]).
pub fn load(dir: &Path) -> anyhow::Result<(LoopState, Vec<u8>)> {
    use anyhow::Context;
    let path = dir.join(CHECKPOINT_FILE);
    let mut bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    anyhow::ensure!(bytes.len() >= 8, "{CHECKPOINT_FILE}: truncated");
    let json_len = u64::from_le_bytes(bytes[..8].try_into()?) as usize;
    anyhow::ensure!(bytes.len() >= 8 + json_len, "{CHECKPOINT_FILE}: truncated");
    let state: LoopState = serde_json::from_slice(&bytes[8..8 + json_len])
        .with_context(|| format!("{CHECKPOINT_FILE}: bad run state"))?;
    Ok((state, bytes.split_off(8 + json_len)))
}
