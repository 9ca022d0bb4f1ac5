//! Particle fields on a regular grid: corrected SPH interpolation (a quadratic
//! moving-least-squares fit with the kernel as weight, Liu & Liu 2010 §2.5), only where there
//! is fluid. Particles do not slice in ParaView; a grid does.
//!
//! At a node x the fit f(x + d) ≈ a₀ + a·d + ½ dᵀBd over the fluid particles j within the
//! kernel support minimises Σ_j V_j W(x − x_j) (f_j − fit(x_j − x))²; the interpolant is a₀.
//! It reproduces quadratic fields exactly, also on supports truncated by a wall or a free
//! surface, where the plain SPH sum loses a whole order (its Shepard sum Σ V_j W_j falls to ½)
//! and a linear fit leaves the kernel's smoothing error ½|f''|σ² (σ² ≈ 0.4h², measured: 1 %
//! of a parabola's peak at R/δr = 9). Where the quadratic fit is ill-posed (few neighbours at
//! a corner) the linear one is used, and the Shepard average where that is too.

use crate::engine::kernel::QuinticSpline;
use crate::engine::math::Vec2;
use crate::engine::neighbours::Domain;
use crate::engine::step::Simulation;
use rayon::prelude::*;

/// A node is fluid when no solid wall contains it and the Shepard sum Σ V_j W_j of the fluid
/// particles reaches this value: 0.5 at a plane wall or on a particle row at a free surface,
/// about 0.4 half a spacing beyond it, where the surface of the particle cloud lies.
const FLUID_SHEPARD_SUM: f64 = 0.4;

/// Below this ratio of a fit matrix's smallest to largest eigenvalue (too few or collinear
/// neighbours) a node falls back to the next lower order.
const FIT_CONDITION: f64 = 1e-6;

/// Cell-centred nodes covering the domain: node (i, j) at min + ((i + ½)Δx, (j + ½)Δy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    pub origin: Vec2,
    pub spacing: Vec2,
    pub dims: [usize; 2],
}

impl GridSpec {
    /// Nodes about `target` apart over `domain` (the spacing adjusted to divide it exactly).
    pub fn covering(domain: &Domain, target: f64) -> Self {
        let size = domain.size();
        let nx = ((size.x / target).round() as usize).max(1);
        let ny = ((size.y / target).round() as usize).max(1);
        let spacing = Vec2::new(size.x / nx as f64, size.y / ny as f64);
        Self {
            origin: domain.min + spacing * 0.5,
            spacing,
            dims: [nx, ny],
        }
    }

    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Node k (x fastest, as VTK image data orders points).
    pub fn node(&self, k: usize) -> Vec2 {
        let (i, j) = (k % self.dims[0], k / self.dims[0]);
        self.origin + Vec2::new(i as f64 * self.spacing.x, j as f64 * self.spacing.y)
    }
}

/// Fields on the nodes of a [`GridSpec`]; NaN at nodes outside the fluid.
#[derive(Clone, Debug)]
pub struct GridFields {
    pub spec: GridSpec,
    /// 1 at fluid nodes, 0 elsewhere.
    pub fluid: Vec<u8>,
    /// (name, one value per node).
    pub fields: Vec<(&'static str, Vec<f64>)>,
}

/// The fields a grid snapshot carries, per particle, in the order of [`GridFields::fields`].
pub fn particle_fields(sim: &Simulation) -> Vec<(&'static str, Vec<f64>)> {
    let s = &sim.state;
    let tau = sim.polymer_stress();
    let n = s.position.len();
    let (trace, det): (Vec<f64>, Vec<f64>) = if s.conformation.is_empty() {
        (vec![2.0; n], vec![1.0; n])
    } else {
        s.conformation.iter().map(|a| (a.trace(), a.det())).unzip()
    };
    vec![
        ("u", s.velocity.iter().map(|u| u.x).collect()),
        ("v", s.velocity.iter().map(|u| u.y).collect()),
        ("pressure", s.pressure.clone()),
        ("vorticity", sim.vorticity()),
        ("tau_xx", tau.iter().map(|t| t.xx).collect()),
        ("tau_xy", tau.iter().map(|t| t.xy).collect()),
        ("tau_yy", tau.iter().map(|t| t.yy).collect()),
        ("trace_A", trace),
        ("det_A", det),
    ]
}

/// The state of `sim` on nodes about `target_spacing` apart.
pub fn interpolate(sim: &Simulation, target_spacing: f64) -> GridFields {
    interpolate_on(sim, GridSpec::covering(&sim.domain, target_spacing))
}

/// The state of `sim` on the nodes of `spec` (a line of nodes is a 1 × n grid).
pub fn interpolate_on(sim: &Simulation, spec: GridSpec) -> GridFields {
    let fields = particle_fields(sim);
    let values: Vec<&[f64]> = fields.iter().map(|(_, v)| v.as_slice()).collect();
    let sampler = Sampler::new(sim);
    let per_node: Vec<Option<Vec<f64>>> = (0..spec.len())
        .into_par_iter()
        .map(|k| {
            let x = spec.node(k);
            if sampler.in_solid(&x) {
                return None;
            }
            sampler.fit(x, &values)
        })
        .collect();
    let fluid = per_node.iter().map(|v| v.is_some() as u8).collect();
    let fields = fields
        .iter()
        .enumerate()
        .map(|(f, (name, _))| {
            let column = per_node
                .iter()
                .map(|v| v.as_ref().map_or(f64::NAN, |v| v[f]))
                .collect();
            (*name, column)
        })
        .collect();
    GridFields {
        spec,
        fluid,
        fields,
    }
}

/// Interpolation of a simulation's particle values at arbitrary points.
pub struct Sampler<'a> {
    sim: &'a Simulation,
    cells: Cells,
    weights: Weights<'a>,
}

impl<'a> Sampler<'a> {
    pub fn new(sim: &'a Simulation) -> Self {
        Self {
            sim,
            cells: Cells::new(&sim.domain, &sim.state.position, sim.kernel.support()),
            weights: Weights {
                kernel: &sim.kernel,
                domain: &sim.domain,
                positions: &sim.state.position,
                volume: sim.particle_volume(),
            },
        }
    }

    /// Whether a solid wall of the simulation contains `x`.
    pub fn in_solid(&self, x: &Vec2) -> bool {
        let domain = &self.sim.domain;
        self.sim
            .walls()
            .iter()
            .any(|w| w.distance_in(x, domain) < 0.0)
    }

    /// The corrected interpolants of the per-particle `values` at `x` (module docs), or None
    /// where the Shepard sum says `x` is outside the fluid.
    pub fn fit(&self, x: Vec2, values: &[&[f64]]) -> Option<Vec<f64>> {
        self.weights.fit(&self.cells, x, values)
    }

    /// The Shepard averages Σ_j V_j W_j f_j / Σ_j V_j W_j at `x`: convex combinations, so
    /// they keep what a convex set keeps (a conformation's positive definiteness and
    /// det A ≥ 1, by Minkowski's determinant inequality; tr A < L²). None: no particle within
    /// the support.
    pub fn shepard(&self, x: Vec2, values: &[&[f64]]) -> Option<Vec<f64>> {
        let w = &self.weights;
        let mut sum = 0.0;
        let mut out = vec![0.0; values.len()];
        self.cells.for_each_near(w.domain, x, |j| {
            let r = w.domain.min_image(w.positions[j] - x).norm();
            if r >= w.kernel.support() {
                return;
            }
            let weight = w.kernel.value(r);
            sum += weight;
            for (o, v) in out.iter_mut().zip(values) {
                *o += weight * v[j];
            }
        });
        (sum > 0.0).then(|| out.iter().map(|o| o / sum).collect())
    }
}

/// The particles and the kernel an interpolation weighs them with.
struct Weights<'a> {
    kernel: &'a QuinticSpline,
    domain: &'a Domain,
    positions: &'a [Vec2],
    volume: f64,
}

impl Weights<'_> {
    /// The corrected interpolants of every field at `x`, or None outside the fluid.
    fn fit(&self, cells: &Cells, x: Vec2, values: &[&[f64]]) -> Option<Vec<f64>> {
        let support = self.kernel.support();
        let h = self.kernel.h();
        // Moments of the weights: m = Σ w p pᵀ, b_f = Σ w f p, with the quadratic basis
        // p = [1, d, d²-terms] in units of h (for conditioning).
        let mut m = Matrix6::zeros();
        let mut b = vec![Vector6::zeros(); values.len()];
        cells.for_each_near(self.domain, x, |j| {
            let d = self.domain.min_image(self.positions[j] - x);
            let r = d.norm();
            if r >= support {
                return;
            }
            let w = self.volume * self.kernel.value(r);
            let (s, t) = (d.x / h, d.y / h);
            let p = Vector6::new(1.0, s, t, s * s, s * t, t * t);
            m += p * p.transpose() * w;
            for (bf, v) in b.iter_mut().zip(values) {
                *bf += p * (w * v[j]);
            }
        });
        let shepard = m[(0, 0)];
        if shepard < FLUID_SHEPARD_SUM {
            return None;
        }
        // The quadratic fit, else the linear one (the leading 3 × 3 block), else Shepard.
        let quadratic = solver(m);
        let linear = solver(m.fixed_view::<3, 3>(0, 0).into_owned());
        Some(
            b.iter()
                .map(|bf| match (&quadratic, &linear) {
                    (Some(q), _) => (q * bf)[0],
                    (None, Some(l)) => (l * bf.fixed_rows::<3>(0))[0],
                    (None, None) => bf[0] / shepard,
                })
                .collect(),
        )
    }
}

type Matrix6 = nalgebra::SMatrix<f64, 6, 6>;
type Vector6 = nalgebra::SVector<f64, 6>;

/// The inverse of a moment matrix, unless it is too ill-conditioned to trust.
fn solver<const N: usize>(m: nalgebra::SMatrix<f64, N, N>) -> Option<nalgebra::SMatrix<f64, N, N>>
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>
        + nalgebra::ToTypenum
        + nalgebra::DimSub<nalgebra::U1>,
    nalgebra::DefaultAllocator:
        nalgebra::allocator::Allocator<nalgebra::DimDiff<nalgebra::Const<N>, nalgebra::U1>>,
{
    let eig = m.symmetric_eigenvalues();
    (eig.min() > FIT_CONDITION * eig.max())
        .then(|| m.try_inverse())
        .flatten()
}

/// Particles binned in square cells of the kernel support, for queries at arbitrary points.
/// Not the step's [`crate::engine::neighbours::NeighbourSearch`]: that one skips coincident
/// points (they carry no gradient), and at a lattice start every particle sits exactly on a
/// cell-centred node, where it carries the largest weight of the fit.
struct Cells {
    size: f64,
    dims: [usize; 2],
    /// CSR: cell c holds `index[start[c]..start[c + 1]]`.
    start: Vec<usize>,
    index: Vec<usize>,
}

impl Cells {
    fn new(domain: &Domain, positions: &[Vec2], support: f64) -> Self {
        let extent = domain.size();
        let dims = [
            ((extent.x / support).floor() as usize).max(1),
            ((extent.y / support).floor() as usize).max(1),
        ];
        let size = support;
        let mut grid = Self {
            size,
            dims,
            start: vec![0; dims[0] * dims[1] + 1],
            index: Vec::with_capacity(positions.len()),
        };
        let cell_of: Vec<usize> = positions
            .iter()
            .map(|p| grid.cell(grid.coords(domain, *p)))
            .collect();
        for &c in &cell_of {
            grid.start[c + 1] += 1;
        }
        for c in 0..grid.start.len() - 1 {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        grid.index.resize(positions.len(), 0);
        for (j, &c) in cell_of.iter().enumerate() {
            grid.index[fill[c]] = j;
            fill[c] += 1;
        }
        grid
    }

    /// Cell coordinates of a point (clamped into the box; cells are at least a support wide,
    /// the last one wider when the box is not a whole number of supports).
    fn coords(&self, domain: &Domain, p: Vec2) -> [isize; 2] {
        let q = domain.wrap(p) - domain.min;
        let c = |v: f64, n: usize| ((v / self.size).floor() as isize).clamp(0, n as isize - 1);
        [c(q.x, self.dims[0]), c(q.y, self.dims[1])]
    }

    fn cell(&self, c: [isize; 2]) -> usize {
        c[1] as usize * self.dims[0] + c[0] as usize
    }

    /// Calls `visit` with every particle in the 3 × 3 cells around `x` (each once).
    fn for_each_near(&self, domain: &Domain, x: Vec2, mut visit: impl FnMut(usize)) {
        let centre = self.coords(domain, x);
        let mut seen = [usize::MAX; 9];
        for (k, (dx, dy)) in (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
            .enumerate()
        {
            let Some(c) = self.neighbour(domain, centre, dx, dy) else {
                continue;
            };
            if seen[..k].contains(&c) {
                continue; // fewer than three cells along a periodic axis
            }
            seen[k] = c;
            for &j in &self.index[self.start[c]..self.start[c + 1]] {
                visit(j);
            }
        }
    }

    fn neighbour(&self, domain: &Domain, c: [isize; 2], dx: isize, dy: isize) -> Option<usize> {
        let mut q = [c[0] + dx, c[1] + dy];
        for ((q, n), periodic) in q.iter_mut().zip(self.dims).zip(domain.periodic) {
            let n = n as isize;
            if *q < 0 || *q >= n {
                if !periodic {
                    return None;
                }
                *q = q.rem_euclid(n);
            }
        }
        Some(self.cell(q))
    }
}
