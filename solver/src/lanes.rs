//! Several right-hand sides of one matrix (the components of an implicit viscous step),
//! solved by Jacobi-preconditioned BiCGStab in lock-step.
//!
//! Each right-hand side keeps its own BiCGStab recurrence, with exactly the operations, in
//! the same order, of a solve on its own ([`crate::bicgstab`]): its result is the same bit
//! for bit. What the lanes share is the matrix–vector product. A product streams the whole
//! matrix from memory for one multiply–add per entry (16 bytes of value and column index),
//! so it is bound by memory bandwidth, and one pass that multiplies the vectors of all
//! lanes costs much less than one pass each ([`crate::vector::spmv_many`]).

use crate::bicgstab::{
    apply_jacobi, jacobi, off_diagonal_ratio, Vectors, JACOBI_BUDGET, MAX_RESTARTS, WEAK_COUPLING,
};
use crate::vector::{dot, for_each_mut, norm, spmv_many, Interleaved};
use crate::{Preconditioner, SolverOptions};
use sprs::CsMat;

/// The product a lane waits for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Wait {
    /// A x into r: the true residual at a (re)start.
    TrueResidual,
    /// A y into v, then A z into t: the two products of an iteration.
    V,
    T,
    /// A x into r once more: the final residual of a lane that did not converge.
    Projected,
    Done,
    /// The lane would turn to AMG (a strongly coupled matrix): the lock-step is given up.
    Abandoned,
}

/// Where one right-hand side stands.
struct Lane<'a> {
    b: &'a [f64],
    x: &'a mut [f64],
    work: &'a mut Vectors,
    wait: Wait,
    b_norm: f64,
    target: f64,
    restart: usize,
    iterations: usize,
    switched: bool,
    /// The current cycle: its iteration, budget and scalars.
    k: usize,
    budget: usize,
    rho: f64,
    alpha: f64,
    omega: f64,
    converged_residual: Option<f64>,
    relative_residual: f64,
}

/// A lane's outcome, as [`crate::bicgstab::Outcome`].
pub(crate) struct LaneOutcome {
    pub converged: bool,
    pub iterations: usize,
    pub relative_residual: f64,
}

/// The shared state of the lanes: the matrix, the options, Jacobi's inverse diagonal.
struct Shared<'a> {
    a: &'a CsMat<f64>,
    /// Whether the matrix is weakly coupled (Jacobi kept), once a lane has asked.
    weak: Option<bool>,
    options: &'a SolverOptions,
    inv_diag: &'a [f64],
    partials: &'a mut Vec<f64>,
}

/// The breakdown threshold of [`crate::bicgstab`].
fn tiny() -> f64 {
    f64::MIN_POSITIVE.sqrt()
}

impl Lane<'_> {
    /// The vector this lane wants multiplied and where the product goes.
    fn request(&mut self) -> Option<(&[f64], &mut [f64])> {
        let w = &mut *self.work;
        match self.wait {
            Wait::TrueResidual | Wait::Projected => Some((&*self.x, &mut w.r)),
            Wait::V => Some((&w.y, &mut w.v)),
            Wait::T => Some((&w.z, &mut w.t)),
            Wait::Done | Wait::Abandoned => None,
        }
    }

    /// Takes the product just computed and runs until the next one is needed.
    fn advance(&mut self, sh: &mut Shared) {
        match self.wait {
            Wait::TrueResidual => self.after_true_residual(sh),
            Wait::V => self.after_v(sh),
            Wait::T => self.after_t(sh),
            Wait::Projected => {
                let (b, r) = (self.b, &mut self.work.r);
                for_each_mut(r, |i, ri| *ri = b[i] - *ri);
                self.relative_residual = norm(r, sh.partials) / self.b_norm;
                self.wait = Wait::Done;
            }
            Wait::Done | Wait::Abandoned => {}
        }
    }

    /// The restart loop's head of `BiCgStabWorkspace::solve` (no null space).
    fn after_true_residual(&mut self, sh: &mut Shared) {
        let b = self.b;
        for_each_mut(&mut self.work.r, |i, ri| *ri = b[i] - *ri);
        let mut residual = norm(&self.work.r, sh.partials);
        if self.restart == 0 && residual > self.b_norm {
            // Start cold; A·0 = 0 exactly, so r = b.
            self.x.iter_mut().for_each(|v| *v = 0.0);
            self.work.r.copy_from_slice(b);
            residual = norm(&self.work.r, sh.partials);
        }
        if residual <= self.target {
            self.converged_residual = Some(residual);
            return self.finish();
        }
        if self.iterations >= sh.options.max_iterations {
            return self.finish();
        }
        self.budget = sh.options.max_iterations - self.iterations;
        let adapting = sh.options.preconditioner == Preconditioner::Adaptive && !self.switched;
        if adapting {
            if self.iterations >= JACOBI_BUDGET {
                // The solve on its own tries AMG here: it keeps Jacobi for a weakly coupled
                // matrix, at the cost of a restart, and otherwise builds a hierarchy that
                // the later components would use from their start, which the lock-step
                // cannot follow.
                let (a, weak) = (sh.a, &mut sh.weak);
                if !*weak.get_or_insert_with(|| off_diagonal_ratio(a) < WEAK_COUPLING) {
                    self.wait = Wait::Abandoned;
                    return;
                }
                self.switched = true;
                return self.next_restart();
            }
            self.budget = self.budget.min(JACOBI_BUDGET - self.iterations);
        }
        let w = &mut *self.work;
        w.r_hat.copy_from_slice(&w.r);
        w.p.iter_mut().for_each(|e| *e = 0.0);
        w.v.iter_mut().for_each(|e| *e = 0.0);
        (self.rho, self.alpha, self.omega) = (1.0, 1.0, 1.0);
        self.k = 0;
        self.cycle_head(sh);
    }

    /// The top of a BiCGStab iteration, up to the first product.
    fn cycle_head(&mut self, sh: &mut Shared) {
        if self.k >= self.budget {
            return self.end_cycle(self.budget);
        }
        let w = &mut *self.work;
        let rho_new = dot(&w.r_hat, &w.r, sh.partials);
        if rho_new.abs() < tiny() || self.omega.abs() < tiny() {
            return self.end_cycle(self.k);
        }
        let beta = (rho_new / self.rho) * (self.alpha / self.omega);
        self.rho = rho_new;
        let omega = self.omega;
        {
            let (r, v) = (&w.r, &w.v);
            for_each_mut(&mut w.p, |i, pi| *pi = r[i] + beta * (*pi - omega * v[i]));
        }
        apply_jacobi(sh.inv_diag, &w.p, &mut w.y);
        self.wait = Wait::V;
    }

    fn after_v(&mut self, sh: &mut Shared) {
        let w = &mut *self.work;
        let denominator = dot(&w.r_hat, &w.v, sh.partials);
        if denominator.abs() < tiny() {
            return self.end_cycle(self.k);
        }
        self.alpha = self.rho / denominator;
        let alpha = self.alpha;
        {
            let (r, v) = (&w.r, &w.v);
            for_each_mut(&mut w.s, |i, si| *si = r[i] - alpha * v[i]);
        }
        if norm(&w.s, sh.partials) <= self.target {
            let y = &w.y;
            for_each_mut(self.x, |i, xi| *xi += alpha * y[i]);
            return self.end_cycle(self.k + 1);
        }
        apply_jacobi(sh.inv_diag, &w.s, &mut w.z);
        self.wait = Wait::T;
    }

    fn after_t(&mut self, sh: &mut Shared) {
        let w = &mut *self.work;
        let tt = dot(&w.t, &w.t, sh.partials);
        self.omega = if tt > 0.0 {
            dot(&w.t, &w.s, sh.partials) / tt
        } else {
            0.0
        };
        let (alpha, omega) = (self.alpha, self.omega);
        {
            let (y, z) = (&w.y, &w.z);
            for_each_mut(self.x, |i, xi| *xi += alpha * y[i] + omega * z[i]);
        }
        {
            let (s, t) = (&w.s, &w.t);
            for_each_mut(&mut w.r, |i, ri| *ri = s[i] - omega * t[i]);
        }
        if norm(&w.r, sh.partials) <= self.target {
            return self.end_cycle(self.k + 1);
        }
        self.k += 1;
        self.cycle_head(sh);
    }

    fn end_cycle(&mut self, spent: usize) {
        self.iterations += spent;
        self.next_restart();
    }

    fn next_restart(&mut self) {
        self.restart += 1;
        if self.restart > MAX_RESTARTS {
            self.finish();
        } else {
            self.wait = Wait::TrueResidual;
        }
    }

    fn finish(&mut self) {
        match self.converged_residual {
            Some(residual) => {
                self.relative_residual = residual / self.b_norm;
                self.wait = Wait::Done;
            }
            None => self.wait = Wait::Projected,
        }
    }
}

/// Runs BiCGStab on every lane (`b[c]`, `x[c]`, finite; `work` holds M workspaces) in
/// lock-step, Jacobi-preconditioned, with the control of [`crate::bicgstab`]'s solve.
/// `None` where a lane would turn to AMG (the adaptive preconditioner on a strongly coupled
/// matrix): the guesses are then spent and the solves must run one after the other.
pub(crate) fn solve<const M: usize>(
    a: &CsMat<f64>,
    b: [&[f64]; M],
    x: [&mut [f64]; M],
    work: &mut [Vectors],
    scratch: &mut Scratch,
    options: &SolverOptions,
) -> Option<[LaneOutcome; M]> {
    let n = a.rows();
    let Scratch {
        inv_diag,
        partials,
        products,
    } = scratch;
    inv_diag.resize(n, 0.0);
    jacobi(a, 0.0, inv_diag);
    let mut sh = Shared {
        a,
        weak: None,
        options,
        inv_diag,
        partials,
    };
    let mut pairs = b.into_iter().zip(x).zip(work.iter_mut());
    let mut lanes: [Lane; M] = std::array::from_fn(|_| {
        let ((b, x), work) = pairs
            .next()
            .expect("M right-hand sides, guesses and workspaces");
        work.resize(n);
        let b_norm = norm(b, sh.partials);
        let mut lane = Lane {
            b,
            x,
            work,
            wait: Wait::TrueResidual,
            b_norm,
            target: (options.relative_tolerance * b_norm).max(options.absolute_tolerance),
            restart: 0,
            iterations: 0,
            switched: false,
            k: 0,
            budget: 0,
            rho: 1.0,
            alpha: 1.0,
            omega: 1.0,
            converged_residual: None,
            relative_residual: f64::NAN,
        };
        if b_norm == 0.0 {
            // x = 0 exactly, as a solve on its own returns.
            lane.x.iter_mut().for_each(|v| *v = 0.0);
            lane.converged_residual = Some(0.0);
            lane.relative_residual = 0.0;
            lane.wait = Wait::Done;
        }
        lane
    });
    loop {
        let mut waiting = lanes.iter_mut();
        let mut requests: [Option<(&[f64], &mut [f64])>; M] =
            std::array::from_fn(|_| waiting.next().and_then(|l| l.request()));
        if requests.iter().all(Option::is_none) {
            break;
        }
        spmv_many(a, &mut requests, products);
        for lane in lanes.iter_mut().filter(|l| l.wait != Wait::Done) {
            lane.advance(&mut sh);
        }
        if lanes.iter().any(|l| l.wait == Wait::Abandoned) {
            return None;
        }
    }
    Some(std::array::from_fn(|c| {
        let l = &lanes[c];
        LaneOutcome {
            converged: l.converged_residual.is_some() && l.relative_residual.is_finite(),
            iterations: l.iterations,
            relative_residual: l.relative_residual,
        }
    }))
}

/// Scratch shared by the lanes: Jacobi's inverse diagonal, reduction partials, and the
/// interleaved products of [`spmv_many`].
#[derive(Default)]
pub(crate) struct Scratch {
    pub inv_diag: Vec<f64>,
    pub partials: Vec<f64>,
    pub products: Interleaved,
}

impl Scratch {
    pub(crate) fn heap_bytes(&self) -> usize {
        [&self.inv_diag, &self.partials]
            .iter()
            .map(|v| v.capacity() * std::mem::size_of::<f64>())
            .sum::<usize>()
            + self.products.heap_bytes()
    }
}
