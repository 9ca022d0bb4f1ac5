//! Steady-state detection and the averaging window after it (King & Lind §IV B): the flow is
//! steady once the mass-flow rate (the bulk velocity ⟨u⟩) has varied by less than a relative
//! `tolerance` over the last `window` time units; quantities are then averaged over `average`
//! time units and the run ends.

use crate::analysis::centreline::Profile;
use crate::app::io::SeriesRow;
use serde::{Deserialize, Serialize};

pub use crate::setup::case::{SteadyCriterion, SteadySignal};

impl SteadyCriterion {
    /// The time at which the series first satisfies the criterion, looking at the rows up to
    /// and including the last one. Rows must cover the whole window.
    pub fn reached(&self, rows: &[SeriesRow]) -> Option<f64> {
        let last = rows.last()?;
        let from = last.t - self.window;
        if from < 0.0 || rows[0].t > from + 1e-12 {
            return None;
        }
        let start = rows.partition_point(|r| r.t < from - 1e-12);
        let values = rows[start..].iter().map(|r| match self.watch {
            SteadySignal::BulkVelocity => r.u_mean,
            SteadySignal::BodyForce => r.body_force,
        });
        let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0.0);
        for v in values {
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
            n += 1.0;
        }
        let mean = sum / n;
        (n >= 2.0 && mean.abs() > 0.0 && (hi - lo) / mean.abs() < self.tolerance).then_some(last.t)
    }
}

/// When a run became steady and the averages it keeps: once the criterion is met, each output
/// row is added to `averages` for `average` time units and the run ends; while it is not
/// steady, its last `average` time units go to `tail`, in case it never is. A checkpoint
/// keeps it whole.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SteadyWindows<A> {
    pub steady_at: Option<f64>,
    pub averages: Option<A>,
    #[serde(default)]
    pub tail: Option<A>,
}

impl<A: Serialize + serde::de::DeserializeOwned + Default> SteadyWindows<A> {
    /// What a checkpoint keeps of it.
    pub fn to_json(&self) -> Option<serde_json::Value> {
        serde_json::to_value(self).ok()
    }

    /// Continues from a checkpoint's copy (None: an older checkpoint without it).
    pub fn restore(&mut self, state: Option<&serde_json::Value>) -> serde_json::Result<()> {
        if let Some(v) = state {
            *self = serde_json::from_value(v.clone())?;
        }
        Ok(())
    }
}

/// A body's drag coefficient and the bulk velocity summed over output rows (a sphere's
/// probes).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct DragWindow {
    pub from: f64,
    pub to: f64,
    pub samples: usize,
    pub drag_k: f64,
    pub u_mean: f64,
}

impl DragWindow {
    pub fn new(from: f64) -> Self {
        Self {
            from,
            to: from,
            ..Default::default()
        }
    }

    pub fn add(&mut self, row: &SeriesRow) {
        self.to = row.t;
        self.samples += 1;
        self.drag_k += row.drag_k;
        self.u_mean += row.u_mean;
    }

    /// The window's mean K.
    pub fn drag_k(&self) -> f64 {
        self.drag_k / self.samples.max(1) as f64
    }

    /// The window's mean ⟨u⟩.
    pub fn u_mean(&self) -> f64 {
        self.u_mean / self.samples.max(1) as f64
    }
}

impl SteadyWindows<DragWindow> {
    /// After an output row: [`SteadyWindows::observe`] adding the last row.
    pub fn observe_rows(
        &mut self,
        criterion: &SteadyCriterion,
        run_end: f64,
        rows: &[SeriesRow],
    ) -> Option<f64> {
        let last = &rows[rows.len() - 1];
        self.observe(criterion, run_end, rows, DragWindow::new, |w| w.add(last))
    }

    /// The window a summary reports: the steady one, else the run's last `average` time
    /// units (not steady values), else the final row alone at `t`.
    pub fn reported(&self, t: f64, rows: &[SeriesRow]) -> DragWindow {
        let filled = |w: &Option<DragWindow>| w.filter(|w| w.samples > 0);
        filled(&self.averages)
            .or(filled(&self.tail))
            .unwrap_or_else(|| {
                let mut w = DragWindow::new(t);
                rows.last().into_iter().for_each(|r| w.add(r));
                w
            })
    }
}

impl<A> SteadyWindows<A> {
    /// After an output row (the last of `rows`): `add` puts it into the window it falls in,
    /// `start(t)` opening one; an earlier end time when the criterion is first met.
    pub fn observe(
        &mut self,
        criterion: &SteadyCriterion,
        run_end: f64,
        rows: &[SeriesRow],
        start: impl Fn(f64) -> A,
        add: impl FnOnce(&mut A),
    ) -> Option<f64> {
        let last = &rows[rows.len() - 1];
        if let Some(averages) = self.averages.as_mut() {
            add(averages);
            return None;
        }
        if let Some(t) = criterion.reached(rows) {
            self.steady_at = Some(t);
            self.averages = Some(start(t));
            return Some(t + criterion.average);
        }
        if last.t >= run_end - criterion.average - 1e-12 {
            add(self.tail.get_or_insert_with(|| start(last.t)));
        }
        None
    }
}

/// Time averages of the series and the centre-line profile.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Averages {
    pub from: f64,
    pub to: f64,
    pub samples: usize,
    u_mean: f64,
    k: [f64; 4],
    /// Σ of the momentum balance's drag ([`crate::analysis::forces::balance_drag`]).
    #[serde(default)]
    drag: f64,
    min_det_a: f64,
    max_trace_a: f64,
    profile: Profile,
}

impl Averages {
    pub fn new(from: f64) -> Self {
        Self {
            from,
            to: from,
            // Finite sentinels: the averages are saved in checkpoints as JSON.
            min_det_a: f64::MAX,
            max_trace_a: f64::MIN,
            ..Default::default()
        }
    }

    /// Adds one output row, its centre-line profile and the momentum balance's drag.
    pub fn add(&mut self, row: &SeriesRow, profile: &Profile, drag: f64) {
        self.samples += 1;
        self.drag += drag;
        self.to = row.t;
        self.u_mean += row.u_mean;
        for (a, v) in
            self.k
                .iter_mut()
                .zip([row.drag_k, row.k_pressure, row.k_solvent, row.k_polymer])
        {
            *a += v;
        }
        self.min_det_a = self.min_det_a.min(row.min_det_a);
        self.max_trace_a = self.max_trace_a.max(row.max_trace_a);
        self.profile.accumulate(profile);
    }

    /// The mean centre-line profile.
    pub fn profile(&self) -> Profile {
        self.profile.scaled(1.0 / self.samples.max(1) as f64)
    }

    /// The mean bulk velocity.
    pub fn u_mean(&self) -> f64 {
        self.u_mean / self.samples.max(1) as f64
    }

    /// The summary entry; `eta_s` and `radius` scale τ_xx by η_s⟨u⟩/R.
    pub fn summary(
        &self,
        reached_at: Option<f64>,
        eta_s: f64,
        radius: f64,
        s: &[f64],
    ) -> SteadySummary {
        let n = self.samples.max(1) as f64;
        let u = self.u_mean();
        let profile = self.profile();
        let scale = eta_s * u / radius;
        let (peak_at, peak) = s.iter().zip(&profile.tau_xx).fold(
            (f64::NAN, f64::NEG_INFINITY),
            |(a, m), (&si, &t)| {
                if t > m {
                    (si, t)
                } else {
                    (a, m)
                }
            },
        );
        SteadySummary {
            reached_at,
            averaged_from: self.from,
            averaged_to: self.to,
            samples: self.samples,
            u_mean: u,
            drag_k: self.drag / n,
            drag_k_surface: self.k[0] / n,
            k_pressure: self.k[1] / n,
            k_solvent: self.k[2] / n,
            k_polymer: self.k[3] / n,
            peak_tau_xx_centreline: peak / scale,
            peak_tau_xx_at: peak_at,
            min_det_a_centreline: profile.det_a.iter().copied().fold(f64::INFINITY, f64::min),
            min_det_a: self.min_det_a,
            max_trace_a: self.max_trace_a,
            momentum_balance: None,
        }
    }
}

/// `summary.json`'s `steady` entry (runs with a cylinder).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SteadySummary {
    /// When the criterion was met (None: not met before the end time; the averages are then
    /// over the last `average` time units and are not steady values).
    pub reached_at: Option<f64>,
    pub averaged_from: f64,
    pub averaged_to: f64,
    pub samples: usize,
    /// ⟨u⟩ = Q/H.
    pub u_mean: f64,
    /// K = F_x/(η0⟨u⟩) from the momentum balance (`analysis::forces::balance_drag`), the
    /// window's mean; the surface integral reads it 2–6 % high.
    pub drag_k: f64,
    /// The window's mean of the surface integral's K, and its pressure, solvent and polymer
    /// parts; both K's and the pressure part include the driving gradient's force
    /// (`analysis::forces::displaced`).
    #[serde(default)]
    pub drag_k_surface: f64,
    pub k_pressure: f64,
    pub k_solvent: f64,
    pub k_polymer: f64,
    /// Largest τ_xx/(η_s⟨u⟩/R) on the centre-line between cylinders, and where (s).
    pub peak_tau_xx_centreline: f64,
    pub peak_tau_xx_at: f64,
    /// Smallest det A on the centre-line profile and over all particles in the window.
    pub min_det_a_centreline: f64,
    pub min_det_a: f64,
    pub max_trace_a: f64,
    /// The final state's x-momentum balance (the body force against the cylinder's and the
    /// plane walls' loads).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub momentum_balance: Option<crate::analysis::forces::MomentumBalance>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(values: &[(f64, f64)]) -> Vec<SeriesRow> {
        values
            .iter()
            .map(|&(t, u)| SeriesRow {
                t,
                u_mean: u,
                ..Default::default()
            })
            .collect()
    }

    #[test]
    fn steady_needs_a_full_window_below_the_tolerance() {
        let c = SteadyCriterion {
            tolerance: 0.02,
            window: 1.0,
            average: 3.0,
            watch: SteadySignal::BulkVelocity,
        };
        // Not a full window yet.
        assert_eq!(c.reached(&rows(&[(0.0, 1.0), (0.5, 1.0)])), None);
        // A 3 % swing inside the window.
        assert_eq!(
            c.reached(&rows(&[(0.0, 1.0), (0.5, 1.03), (1.0, 1.0)])),
            None
        );
        // 1 % over the last unit; the earlier transient is outside the window.
        let r = rows(&[(0.0, 0.2), (0.5, 1.0), (1.0, 1.01), (1.5, 1.005)]);
        assert_eq!(c.reached(&r), Some(1.5));
        // Holding ⟨u⟩, the force must settle instead: ⟨u⟩ steady, the force still moving.
        let held = SteadyCriterion {
            watch: SteadySignal::BodyForce,
            ..c
        };
        let moving: Vec<SeriesRow> = r
            .iter()
            .enumerate()
            .map(|(k, row)| SeriesRow {
                body_force: 300.0 + 10.0 * k as f64,
                ..*row
            })
            .collect();
        assert_eq!(held.reached(&moving), None);
    }
}
