//! The jet's inflow: fluid enters at exactly the prescribed flux, and a jet falling onto a
//! plate stays symmetric until it buckles.

use rheosph::engine::boundary::inflow::BUFFER_ROWS;
use rheosph::engine::step::Simulation;
use rheosph::setup::case;
use std::path::Path;

/// A coarse jet (D/δr = 10, U0 = 0.2 m/s) run for 0.05 s: one row of D/δr particles enters
/// per δr/U0 of time (rows sit half a spacing from the buffer's ends), so the particle count
/// is D/δr (BUFFER_ROWS + ⌊U0 t/δr + ½⌋) exactly; and
/// with a symmetric orifice and plate, the fluid's mean x stays on the axis (to 1e-6 D:
/// summation order changes with reordering, the scheme itself is symmetric).
#[test]
fn inflow_delivers_the_prescribed_flux_symmetrically() {
    let case = case::load(
        Path::new("cases/jet-buckling.toml"),
        &["scene.resolution=10".into()],
    )
    .unwrap();
    let mut sim = Simulation::new(case.setup().unwrap());
    let (d, u0) = (0.006, 0.2);
    let dr = d / 10.0;
    while sim.state.time < 0.05 - 1e-12 {
        let limit = 0.05 - sim.state.time;
        sim.step(limit).unwrap();
    }
    let rows = (u0 * sim.state.time / dr + 0.5).floor() as usize;
    assert_eq!(sim.particles(), 10 * (BUFFER_ROWS + rows));
    let inflow = sim.inflow().unwrap();
    assert_eq!(
        inflow.count(),
        10 * BUFFER_ROWS,
        "the buffer keeps its depth"
    );
    let mean_x = sim.state.position.iter().map(|p| p.x).sum::<f64>() / sim.particles() as f64;
    assert!(mean_x.abs() < 1e-6 * d, "mean x {mean_x:e}");
    // The released fluid has fallen below the orifice and is moving down.
    let released: Vec<usize> = (0..sim.particles()).filter(|&i| !inflow.flags[i]).collect();
    assert_eq!(released.len(), 10 * rows);
    assert!(released.iter().all(|&i| sim.state.position[i].y < 0.072));
    assert!(released.iter().all(|&i| sim.state.velocity[i].y < 0.0));
}
