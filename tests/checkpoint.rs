//! Checkpoint and restore: a run continued from a checkpoint is bit-identical to one never
//! interrupted (Lagrangian with a Morton reordering after the checkpoint, Eulerian with its
//! cached LU, implicit viscosity, a channel with a cylinder), and damaged or foreign
//! checkpoints are rejected with an error.

mod common;
use common::poiseuille;
use rheosph::app::run::checkpoint::{self, CheckpointError};
use rheosph::engine::step::{Simulation, State, REORDER_INTERVAL};
use rheosph::setup::case::{self, Case};
use std::path::Path;

/// Checkpoint before a Morton reordering (step 50), stop after it.
const CHECKPOINT_STEP: u64 = 30;
const END_STEP: u64 = 80;

fn simulation(case: &Case) -> Simulation {
    Simulation::new(case.setup().unwrap())
}

fn advance(sim: &mut Simulation, to_step: u64) {
    while sim.state.steps < to_step {
        sim.step(f64::INFINITY).expect("step succeeds");
    }
}

/// Every field of two states, compared bit for bit.
fn assert_identical(a: &State, b: &State, label: &str) {
    assert_eq!(a.steps, b.steps, "{label}: steps");
    assert_eq!(a.time.to_bits(), b.time.to_bits(), "{label}: time");
    let bits = |s: &State| {
        let vec2 = |v: &[rheosph::engine::math::Vec2]| -> Vec<u64> {
            v.iter()
                .flat_map(|u| [u.x.to_bits(), u.y.to_bits()])
                .collect()
        };
        [
            vec2(&s.position),
            vec2(&s.velocity),
            s.pressure.iter().map(|p| p.to_bits()).collect(),
            s.conformation
                .iter()
                .flat_map(|c| [c.xx.to_bits(), c.xy.to_bits(), c.yy.to_bits()])
                .collect(),
            vec2(&s.shift_velocity),
        ]
    };
    let names = [
        "position",
        "velocity",
        "pressure",
        "conformation",
        "shift_velocity",
    ];
    for ((name, x), y) in names.iter().zip(bits(a)).zip(bits(b)) {
        assert_eq!(x.len(), y.len(), "{label}: {name} length");
        if let Some(k) = x.iter().zip(&y).position(|(p, q)| p != q) {
            panic!("{label}: {name} differs first at value {k}");
        }
    }
}

/// Runs to the checkpoint, then on to the end; restores the checkpoint into a fresh
/// simulation and into the finished one (whose caches are warm), and continues both.
fn check_continuation(case: &Case, label: &str) {
    const { assert!(CHECKPOINT_STEP < REORDER_INTERVAL && REORDER_INTERVAL < END_STEP) };
    let mut reference = simulation(case);
    advance(&mut reference, CHECKPOINT_STEP);
    let bytes = checkpoint::encode(&reference);
    // As the run loop does after writing a checkpoint: solver history that the file does not
    // carry (an AMG hierarchy, the implicit viscous guess) is dropped on both sides.
    reference.reset_preconditioners();
    advance(&mut reference, END_STEP);

    let mut fresh = simulation(case);
    checkpoint::restore(&mut fresh, &bytes).expect("restore into a fresh simulation");
    assert_eq!(checkpoint::encode(&fresh), bytes, "{label}: round trip");
    advance(&mut fresh, END_STEP);
    assert_identical(&reference.state, &fresh.state, &format!("{label}, fresh"));

    let mut reused = fresh;
    checkpoint::restore(&mut reused, &bytes).expect("restore into a used simulation");
    advance(&mut reused, END_STEP);
    assert_identical(&reference.state, &reused.state, &format!("{label}, reused"));
}

#[test]
fn lagrangian_oldroyd_b_continues_bit_identically() {
    check_continuation(&poiseuille(&["scene.resolution=12"]), "lagrangian");
}

#[test]
fn eulerian_with_cached_lu_continues_bit_identically() {
    check_continuation(
        &poiseuille(&["scene.resolution=12", "scheme.frame=eulerian"]),
        "eulerian",
    );
}

#[test]
fn implicit_viscosity_continues_bit_identically() {
    check_continuation(
        &poiseuille(&["scene.resolution=12", "scheme.viscosity=implicit"]),
        "implicit",
    );
}

/// Crank–Nicolson with the Strang update spans (δt^{n−1} + δt^n)/2: the last step is state,
/// and the checkpoint must carry it (the advective step varies here as the flow speeds up).
#[test]
fn crank_nicolson_continues_bit_identically() {
    check_continuation(
        &poiseuille(&["scene.resolution=12", "scheme.viscosity=crank-nicolson"]),
        "crank-nicolson",
    );
}

#[test]
fn cylinder_array_continues_bit_identically() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/cylinder-array.toml");
    let case = case::load(&path, &["scene.resolution=36".to_string()]).expect("valid case");
    check_continuation(&case, "cylinder");
}

#[test]
fn amg_preconditioned_implicit_run_continues_bit_identically() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/cylinder-array.toml");
    let sets = ["scene.resolution=36", "scheme.ppe.preconditioner=amg"].map(String::from);
    let case = case::load(&path, &sets).expect("valid case");
    check_continuation(&case, "cylinder, AMG");
}

/// The control: a continuation that loses the PPE warm start (the previous pressure) is not
/// bit-identical, so the comparison above does see history that a checkpoint must keep.
#[test]
fn losing_the_warm_start_changes_the_bits() {
    let case = poiseuille(&["scene.resolution=12"]);
    let mut reference = simulation(&case);
    advance(&mut reference, CHECKPOINT_STEP);
    let bytes = checkpoint::encode(&reference);
    advance(&mut reference, END_STEP);
    let mut cold = simulation(&case);
    checkpoint::restore(&mut cold, &bytes).unwrap();
    cold.state.pressure.iter_mut().for_each(|p| *p = 0.0);
    advance(&mut cold, END_STEP);
    let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    assert!(!same(&reference.state.pressure, &cold.state.pressure));
}

#[test]
fn checkpoint_file_round_trips() {
    let case = poiseuille(&["scene.resolution=12"]);
    let mut sim = simulation(&case);
    advance(&mut sim, 5);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("state.ck");
    checkpoint::write(&path, &sim).unwrap();
    let mut restored = simulation(&case);
    checkpoint::read(&path, &mut restored).unwrap();
    assert_identical(&sim.state, &restored.state, "file");
    let missing = checkpoint::read(&dir.path().join("none.ck"), &mut restored);
    assert!(matches!(missing, Err(CheckpointError::Io(_))));
}

/// Restores `bytes` into `sim`, expecting an error and `sim` untouched.
fn rejected(sim: &mut Simulation, bytes: &[u8]) -> CheckpointError {
    let before = checkpoint::encode(sim);
    let e = checkpoint::restore(sim, bytes).expect_err("checkpoint must be rejected");
    assert!(!e.to_string().is_empty());
    assert_eq!(
        checkpoint::encode(sim),
        before,
        "state changed by a failed restore"
    );
    e
}

#[test]
fn damaged_checkpoints_are_rejected() {
    let case = poiseuille(&["scene.resolution=12"]);
    let mut sim = simulation(&case);
    advance(&mut sim, 3);
    let bytes = checkpoint::encode(&sim);
    let mut target = simulation(&case);

    for len in [
        0,
        4,
        9,
        12,
        13,
        20,
        48,
        49,
        bytes.len() / 2,
        bytes.len() - 1,
    ] {
        let e = rejected(&mut target, &bytes[..len]);
        assert!(
            matches!(e, CheckpointError::Truncated { .. }),
            "{len} bytes: {e}"
        );
    }

    let mut wrong = bytes.clone();
    wrong[0] = b'X';
    assert!(matches!(
        rejected(&mut target, &wrong),
        CheckpointError::Magic
    ));
    assert!(matches!(
        rejected(&mut target, b"not a checkpoint at all"),
        CheckpointError::Magic
    ));

    let mut version = bytes.clone();
    version[9..13].copy_from_slice(&99u32.to_le_bytes());
    assert!(matches!(
        rejected(&mut target, &version),
        CheckpointError::Version { found: 99 }
    ));

    let mut flipped = bytes.clone();
    let middle = bytes.len() / 2;
    flipped[middle] ^= 0x10;
    assert!(matches!(
        rejected(&mut target, &flipped),
        CheckpointError::Checksum
    ));

    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(
        rejected(&mut target, &longer),
        CheckpointError::Trailing(1)
    ));

    // Every truncation and every single-bit flip is an error, never a panic.
    for len in 0..bytes.len() {
        assert!(checkpoint::restore(&mut target, &bytes[..len]).is_err());
    }
    for k in 0..bytes.len() {
        let mut flipped = bytes.clone();
        flipped[k] ^= 1 << (k % 8);
        assert!(
            checkpoint::restore(&mut target, &flipped).is_err(),
            "byte {k}"
        );
    }
    assert_identical(
        &simulation(&case).state,
        &target.state,
        "after failed restores",
    );

    checkpoint::restore(&mut target, &bytes).expect("the intact checkpoint restores");
}

#[test]
fn checkpoints_of_other_simulations_are_rejected() {
    let bytes = checkpoint::encode(&simulation(&poiseuille(&["scene.resolution=12"])));
    for (overrides, what) in [
        (&["scene.resolution=14"][..], "particles"),
        (
            &[
                "scene.resolution=12",
                "fluid.model=newtonian",
                "fluid.relaxation_time=0",
                "fluid.beta=1",
            ][..],
            "conformation",
        ),
        (
            &["scene.resolution=12", "scheme.frame=eulerian"][..],
            "frames",
        ),
        (
            &["scene.resolution=12", "scene.height=2", "scene.length=2"][..],
            "spacing",
        ),
    ] {
        let mut other = simulation(&poiseuille(overrides));
        let e = rejected(&mut other, &bytes);
        assert!(
            matches!(e, CheckpointError::Mismatch(_)) && e.to_string().contains(what),
            "{overrides:?}: {e}"
        );
    }
}
