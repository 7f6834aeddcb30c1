//! Global assembly: DOF numbering with constrained DOFs eliminated, the sparsity pattern and
//! every element's scatter positions computed once per topology, and the element loop
//! (rayon over elements, deterministic: element results are collected in order, then
//! scattered serially).
//!
//! Legend
//! ```text
//! d          global displacement increment since the reference (last converged) configuration
//! f_int      internal force sum_e f_e(d)          (Erklig eq 25)
//! K_T        sum_e K_e(d), lower triangle over the free DOFs (Erklig eq 32)
//! W_int      work of the internal forces, sum_q w_q 1/2 (sigma_n + S) . dE (trapezoid)
//! ```

pub mod explicit;
mod kernel;

use kernel::ElementOut;
pub use kernel::Kernel;

use crate::element::{KernelError, Strain};
use crate::kinematics;
use crate::material::PointState;
use crate::mesh::Cells;
use crate::scene::spec::{MassKind, Tangent};
use crate::scene::{Body, Model};
use crate::solver::Pattern;
use rayon::prelude::*;
use std::sync::Arc;

/// Per body, per material point (element-major: element e's points are e*ppe .. (e+1)*ppe).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BodyState {
    pub points: Vec<PointState>,
    /// Current thickness per point (plane stress); 1 otherwise.
    pub thickness: Vec<f64>,
}

/// The committed state of the whole model.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct State {
    pub time: f64,
    /// Node coordinates of the last converged configuration: the reference configuration of
    /// the next increment in finite strain, the initial one in small strain. Global nodes.
    pub coordinates: Vec<[f64; 2]>,
    /// Total displacement since the initial configuration, 2 per node.
    pub displacement: Vec<f64>,
    pub bodies: Vec<BodyState>,
    /// Accumulated work of the internal forces.
    pub internal_work: f64,
    /// Accumulated plastic work (part of `internal_work`).
    pub plastic_work: f64,
}

impl State {
    /// Current node positions: the reference configuration in finite strain; the initial
    /// one plus the displacement in small strain (whose reference never moves).
    pub fn positions(&self, geometry: Strain) -> std::borrow::Cow<'_, [[f64; 2]]> {
        match geometry {
            Strain::Finite => std::borrow::Cow::Borrowed(&self.coordinates),
            Strain::Small => self
                .coordinates
                .iter()
                .enumerate()
                .map(|(n, x)| {
                    [
                        x[0] + self.displacement[2 * n],
                        x[1] + self.displacement[2 * n + 1],
                    ]
                })
                .collect(),
        }
    }

    pub fn initial(model: &Model) -> State {
        let bodies = model
            .bodies
            .iter()
            .map(|b| {
                let n = b.elements() * b.points_per_element();
                let kernel = Kernel::of(b);
                let (thickness, stress) = (kernel.thickness(), kernel.stress(b.initial_stress));
                BodyState {
                    points: vec![
                        PointState {
                            stress,
                            temperature: b.material.initial_temperature(),
                            ..Default::default()
                        };
                        n
                    ],
                    thickness: vec![thickness; n],
                }
            })
            .collect();
        State {
            time: 0.0,
            coordinates: model.coordinates(),
            displacement: vec![0.0; model.dofs()],
            bodies,
            internal_work: 0.0,
            plastic_work: 0.0,
        }
    }
}

/// An element kernel failed: which body and element, and why.
#[derive(Debug, Clone, thiserror::Error)]
#[error("body `{body}`, element {element}: {error}")]
pub struct ElementFailure {
    pub body: String,
    pub element: usize,
    pub error: KernelError,
}

/// The trial result of an evaluation at a given increment d.
#[derive(Debug, Clone, Default)]
pub struct Evaluation {
    /// Internal force over all DOFs.
    pub force: Vec<f64>,
    /// Trial point states (stress still the second Piola-Kirchhoff stress of the increment).
    pub trial: Vec<Vec<PointState>>,
    /// Out-of-plane Green-Lagrange strain per point of a plane-stress body (its thickness
    /// follows it); empty for the other bodies, where it is not read (16 MB an evaluation
    /// at 1e6 DOFs).
    pub strain_zz: Vec<Vec<f64>>,
    /// Increment of the internal work.
    pub work: f64,
    /// Increment of the plastic work.
    pub plastic_work: f64,
}

/// DOF numbering, sparsity and scatter positions of one topology.
pub struct System {
    /// Global DOF -> free equation number (None: constrained).
    pub equation: Vec<Option<usize>>,
    pub free: usize,
    /// Shared with the solver that factors the matrix (one copy of the largest index array).
    pub pattern: Arc<Pattern>,
    /// Per body: where each element's matrix goes in `values`.
    scatter: Vec<Scatter>,
    /// Lower-triangle values of the last assembled matrix.
    pub values: Vec<f64>,
    /// The largest diagonal entry of the last factored matrix (a stiffness scale).
    pub diagonal_max: f64,
}

/// Scatter positions of one body's element matrices, element-major: one u32 for each entry
/// of an element's lower triangle, pairs of local DOFs (a, b), b <= a, in the order (0, 0),
/// (1, 0), (1, 1), (2, 0), ... The element matrices are symmetric, so the upper triangle is
/// not looked at: 36 positions a Quad4 where the full n x n took 64, 0.07 kB a DOF less at
/// 1e6 DOFs. A position with `TRANSPOSED` set takes entry (b, a) of the element matrix, the
/// one the global lower triangle holds when b's equation number is the larger, so the sum
/// is bit for bit the one a full n x n scatter gives.
struct Scatter {
    /// Element DOFs.
    n: usize,
    /// Entries of one element's lower triangle, n (n + 1) / 2.
    per_element: usize,
    positions: Vec<u32>,
}

/// A scatter position that is not assembled (a constrained DOF).
const NONE: u32 = u32::MAX;
/// The flag of a position that takes the element matrix's transposed entry.
const TRANSPOSED: u32 = 1 << 31;

impl Scatter {
    fn new(pattern: &Pattern, elements: &[Vec<Option<usize>>]) -> Scatter {
        let n = elements.first().map_or(0, Vec::len);
        let per_element = n * (n + 1) / 2;
        let mut positions = Vec::with_capacity(elements.len() * per_element);
        for eqs in elements {
            for a in 0..n {
                for b in 0..=a {
                    positions.push(match (eqs[a], eqs[b]) {
                        (Some(i), Some(j)) => {
                            let (row, col, flag) = if i >= j {
                                (i, j, 0)
                            } else {
                                (j, i, TRANSPOSED)
                            };
                            let p = pattern
                                .position(row, col)
                                .expect("pattern holds the element");
                            p as u32 | flag
                        }
                        _ => NONE,
                    });
                }
            }
        }
        Scatter {
            n,
            per_element,
            positions,
        }
    }

    /// Adds element e's n x n row-major matrix `m` into `values`.
    fn add(&self, e: usize, m: &[f64], values: &mut [f64]) {
        self.for_each(e, |p, a, b| values[p] += m[a * self.n + b]);
    }

    /// Calls `f(position, a, b)` for each assembled lower-triangle entry of element e, with
    /// (a, b) the element matrix entry that goes there.
    fn for_each(&self, e: usize, mut f: impl FnMut(usize, usize, usize)) {
        let n = self.n;
        let positions = &self.positions[e * self.per_element..(e + 1) * self.per_element];
        let mut k = 0;
        for a in 0..n {
            for b in 0..=a {
                let p = positions[k];
                k += 1;
                if p == NONE {
                    continue;
                }
                if p & TRANSPOSED == 0 {
                    f(p as usize, a, b);
                } else {
                    f((p & !TRANSPOSED) as usize, b, a);
                }
            }
        }
    }
}

/// Global DOFs of element e of body b.
fn element_dofs(body: &Body, e: usize) -> Vec<usize> {
    body.mesh
        .cells
        .nodes_of(e)
        .iter()
        .flat_map(|n| [2 * body.global(*n), 2 * body.global(*n) + 1])
        .collect()
}

impl System {
    /// Numbers the DOFs not in `constrained` (sorted or not) and builds pattern and scatter.
    pub fn new(model: &Model, constrained: &[usize]) -> System {
        let mut equation = vec![Some(0); model.dofs()];
        for c in constrained {
            equation[*c] = None;
        }
        let mut free = 0;
        for eq in equation.iter_mut().flatten() {
            *eq = free;
            free += 1;
        }
        let element_equations: Vec<Vec<Vec<Option<usize>>>> = model
            .bodies
            .iter()
            .map(|b| {
                (0..b.elements())
                    .map(|e| element_dofs(b, e).iter().map(|g| equation[*g]).collect())
                    .collect()
            })
            .collect();
        let pattern = Pattern::from_elements(
            free,
            element_equations.iter().flatten().map(|v| v.as_slice()),
        );
        assert!(
            pattern.nonzeros() < TRANSPOSED as usize,
            "scatter positions are 31 bits: fewer than 2^31 nonzeros"
        );
        let scatter = element_equations
            .iter()
            .map(|body| Scatter::new(&pattern, body))
            .collect();
        let values = vec![0.0; pattern.nonzeros()];
        System {
            equation,
            free,
            pattern: Arc::new(pattern),
            scatter,
            values,
            diagonal_max: 0.0,
        }
    }

    /// The diagonal of the assembled matrix (the first entry of each lower-triangle column).
    pub fn diagonal(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.free).map(|j| self.values[self.pattern.col_ptr[j] as usize])
    }

    /// Restricts a global vector to the free equations.
    pub fn gather(&self, global: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.free];
        for (g, eq) in self.equation.iter().enumerate() {
            if let Some(i) = eq {
                out[*i] = global[g];
            }
        }
        out
    }

    /// Adds a free-equation vector into a global one.
    pub fn scatter_add(&self, free: &[f64], global: &mut [f64]) {
        for (g, eq) in self.equation.iter().enumerate() {
            if let Some(i) = eq {
                global[g] += free[*i];
            }
        }
    }
}

/// Material points of a chunk from which `evaluate` runs its elements in parallel. Below,
/// handing a chunk to the thread pool and back costs more than the second core gives: on this
/// project's 2-core machine (medians of interleaved whole runs, sequential against parallel)
/// two_bars with 224 rods a bar 0.92x, conical_bar 0.97x, round_bar 0.98x, sphere_wall
/// (4072 points) 0.98x, three_rings 0.98x, a 45 000-element block about even; the
/// 1e6-DOF block (chunks of 32 768 points) assembles in 0.87x the time in parallel.
const PARALLEL_FROM: usize = 8192;

/// Elements per chunk of `evaluate` (about 5 MB of results in flight).
const CHUNK: usize = 8192;

/// Internal force (and, when `system` is given, the tangent into `system.values`) at the
/// increment `d` over the time step `dt` (the strain rate of rate-dependent materials;
/// infinity: no step) from the committed `state`.
pub fn evaluate(
    model: &Model,
    state: &State,
    d: &[f64],
    dt: f64,
    geometry: Strain,
    mut system: Option<&mut System>,
    tangent: Tangent,
) -> Result<Evaluation, ElementFailure> {
    let _timer = crate::profile::Timer::new(crate::profile::Phase::Assembly);
    crate::profile::count_elements(model.elements());
    let want_tangent = system.is_some();
    if let Some(s) = system.as_deref_mut() {
        s.values.iter_mut().for_each(|v| *v = 0.0);
    }
    let mut force = vec![0.0; model.dofs()];
    let mut trial = Vec::with_capacity(model.bodies.len());
    let mut strain_zz = Vec::with_capacity(model.bodies.len());
    let mut work = 0.0;
    let mut plastic_work = 0.0;
    for (b, body) in model.bodies.iter().enumerate() {
        let kernel = Kernel::of(body);
        let ppe = body.points_per_element();
        let nodes = body.mesh.cells.nodes_of(0).len();
        let thins = kernel.thins();
        // each element's results in one stride of `out`: force, then the matrix when asked,
        // then the out-of-plane strains of a plane-stress body; trial states in place
        let n = 2 * nodes;
        let matrix = if want_tangent { n * n } else { 0 };
        let zz = if thins { ppe } else { 0 };
        let stride = n + matrix + zz;
        let mut body_trial = vec![PointState::default(); body.elements() * ppe];
        let mut body_zz = vec![0.0; body.elements() * zz];
        // elements in chunks, each evaluated (in parallel when it pays) and then scattered:
        // the results in flight stay a few MB however large the mesh
        let chunk = CHUNK.min(body.elements());
        let mut out = vec![0.0; chunk * stride];
        let mut works = Vec::with_capacity(chunk);
        for first in (0..body.elements()).step_by(CHUNK) {
            let last = (first + CHUNK).min(body.elements());
            let out = &mut out[..(last - first) * stride];
            let element = |(k, (o, t)): (usize, (&mut [f64], &mut [PointState]))| {
                let (f, rest) = o.split_at_mut(n);
                let (m, z) = rest.split_at_mut(matrix);
                kernel.evaluate(
                    body,
                    &state.bodies[b],
                    &state.coordinates,
                    d,
                    dt,
                    first + k,
                    geometry,
                    want_tangent.then_some(tangent),
                    ElementOut {
                        force: f,
                        matrix: want_tangent.then_some(m),
                        trial: t,
                        strain_zz: thins.then_some(z),
                    },
                )
            };
            let trial = &mut body_trial[first * ppe..last * ppe];
            if (last - first) * ppe >= PARALLEL_FROM {
                out.par_chunks_mut(stride)
                    .zip(trial.par_chunks_mut(ppe))
                    .enumerate()
                    .map(element)
                    .collect_into_vec(&mut works);
            } else {
                works.clear();
                works.extend(
                    out.chunks_mut(stride)
                        .zip(trial.chunks_mut(ppe))
                        .enumerate()
                        .map(element),
                );
            }
            for ((w, o), e) in works.iter().zip(out.chunks(stride)).zip(first..last) {
                let w = w.as_ref().map_err(|error| ElementFailure {
                    body: body.name.clone(),
                    element: e,
                    error: *error,
                })?;
                for (a, node) in body.mesh.cells.nodes_of(e).iter().enumerate() {
                    let g = 2 * body.global(*node);
                    force[g] += o[2 * a];
                    force[g + 1] += o[2 * a + 1];
                }
                if let Some(s) = system.as_deref_mut() {
                    s.scatter[b].add(e, &o[n..n + matrix], &mut s.values);
                }
                body_zz[e * zz..(e + 1) * zz].copy_from_slice(&o[n + matrix..]);
                work += w.work;
                plastic_work += w.plastic_work;
            }
        }
        trial.push(body_trial);
        strain_zz.push(body_zz);
    }
    Ok(Evaluation {
        force,
        trial,
        strain_zz,
        work,
        plastic_work,
    })
}

/// Commits an evaluation: pushes the stresses forward to the new configuration (nonlinear
/// geometry), updates the reference coordinates, thickness and the accumulated work.
pub fn commit(
    model: &Model,
    state: &mut State,
    d: &[f64],
    evaluation: Evaluation,
    geometry: Strain,
) {
    let Evaluation {
        mut trial,
        strain_zz,
        work,
        plastic_work: evaluation_plastic_work,
        ..
    } = evaluation;
    for (b, body) in model.bodies.iter().enumerate() {
        // the trial states become the committed ones (taken, not copied: a copy of every
        // point's state beside the factor set the implicit memory peak)
        let mut points = std::mem::take(&mut trial[b]);
        if geometry == Strain::Finite {
            let kernel = Kernel::of(body);
            for e in 0..body.elements() {
                kernel.push_forward(
                    body,
                    &state.bodies[b],
                    &state.coordinates,
                    d,
                    &strain_zz[b],
                    e,
                    &mut points,
                );
            }
            if kernel.thins() {
                let bs = &mut state.bodies[b];
                for (t, ezz) in bs.thickness.iter_mut().zip(&strain_zz[b]) {
                    *t *= kinematics::plane_stress_stretch(*ezz);
                }
            }
        }
        state.bodies[b].points = points;
    }
    if geometry == Strain::Finite {
        for (n, x) in state.coordinates.iter_mut().enumerate() {
            x[0] += d[2 * n];
            x[1] += d[2 * n + 1];
        }
    }
    for (u, du) in state.displacement.iter_mut().zip(d) {
        *u += du;
    }
    state.internal_work += work;
    state.plastic_work += evaluation_plastic_work;
}

/// The mass matrix. In the updated-Lagrangian description rho dV is invariant, so the mass
/// is computed once on the initial configuration and never changes.
pub struct Mass {
    pub kind: MassKind,
    /// Per body, per element: the scalar nn x nn matrix (the same for x and y), row-major.
    elements: Vec<Vec<f64>>,
    /// Row sums per DOF (the lumped mass; also used by the explicit method).
    pub lumped: Vec<f64>,
}

impl Mass {
    pub fn new(model: &Model, kind: MassKind) -> Result<Mass, ElementFailure> {
        let coords = model.coordinates();
        let mut lumped = vec![0.0; model.dofs()];
        let mut elements = Vec::with_capacity(model.bodies.len());
        for body in &model.bodies {
            let kernel = Kernel::of(body);
            let nn = body.mesh.cells.nodes_of(0).len();
            let mut body_m = Vec::with_capacity(body.elements() * nn * nn);
            for e in 0..body.elements() {
                let nodes = body.mesh.cells.nodes_of(e);
                let failure = |error| ElementFailure {
                    body: body.name.clone(),
                    element: e,
                    error,
                };
                let mut m = kernel.mass(body, &coords, e).map_err(failure)?;
                if kind == MassKind::DispersionFree {
                    dispersion_free(&mut m, nn);
                }
                for (i, n) in nodes.iter().enumerate() {
                    let row: f64 = m[i * nn..(i + 1) * nn].iter().sum();
                    lumped[2 * body.global(*n)] += row;
                    lumped[2 * body.global(*n) + 1] += row;
                }
                body_m.extend(m);
            }
            elements.push(body_m);
        }
        Ok(Mass {
            kind,
            elements,
            lumped,
        })
    }

    /// The same mass with the nodes flagged in `massless` (per node) carrying none: in each
    /// element their rows and columns are removed and the mass they held goes onto the
    /// element's other nodes in proportion to those nodes' row sums, so every element keeps
    /// its mass (Khenous, Laborde & Renard 2008). An element whose nodes are all flagged
    /// keeps its mass as it is.
    pub fn redistributed(mut self, model: &Model, massless: &[bool]) -> Mass {
        self.lumped.iter_mut().for_each(|m| *m = 0.0);
        for (b, body) in model.bodies.iter().enumerate() {
            let nn = body.mesh.cells.nodes_of(0).len();
            for e in 0..body.elements() {
                let nodes = body.mesh.cells.nodes_of(e);
                let flagged: Vec<bool> = nodes.iter().map(|n| massless[body.global(*n)]).collect();
                let m = &mut self.elements[b][e * nn * nn..(e + 1) * nn * nn];
                if flagged.iter().any(|f| *f) && !flagged.iter().all(|f| *f) {
                    redistribute(m, nn, &flagged);
                }
                for (i, n) in nodes.iter().enumerate() {
                    let row: f64 = m[i * nn..(i + 1) * nn].iter().sum();
                    self.lumped[2 * body.global(*n)] += row;
                    self.lumped[2 * body.global(*n) + 1] += row;
                }
            }
        }
        self
    }

    /// M x over all DOFs.
    pub fn product(&self, model: &Model, x: &[f64]) -> Vec<f64> {
        match self.kind {
            MassKind::Lumped => self.lumped.iter().zip(x).map(|(m, v)| m * v).collect(),
            MassKind::Consistent | MassKind::DispersionFree => {
                let mut y = vec![0.0; x.len()];
                for (b, body) in model.bodies.iter().enumerate() {
                    // the node count fixed at compile time: the loops unroll (the products
                    // of the residual, the reactions and the kinetic energy run several
                    // times a step)
                    match &body.mesh.cells {
                        Cells::Quad4(cells) => {
                            block_product(body, cells, &self.elements[b], x, &mut y)
                        }
                        Cells::Rod2(cells) => {
                            block_product(body, cells, &self.elements[b], x, &mut y)
                        }
                    }
                }
                y
            }
        }
    }

    /// 1/2 v . M v
    pub fn kinetic_energy(&self, model: &Model, v: &[f64]) -> f64 {
        0.5 * self
            .product(model, v)
            .iter()
            .zip(v)
            .map(|(a, b)| a * b)
            .sum::<f64>()
    }

    /// Adds `coefficient` M into the free-DOF matrix of `system`.
    pub fn add_to(&self, model: &Model, system: &mut System, coefficient: f64) {
        for (b, body) in model.bodies.iter().enumerate() {
            let nn = body.mesh.cells.nodes_of(0).len();
            for e in 0..body.elements() {
                let m = &self.elements[b][e * nn * nn..(e + 1) * nn * nn];
                let values = &mut system.values;
                // DOF a is node a / 2's component a % 2; the mass couples equal components only
                system.scatter[b].for_each(e, |p, a, b| {
                    let (i, j) = (a / 2, b / 2);
                    if a % 2 != b % 2 {
                        return;
                    }
                    let value = match self.kind {
                        MassKind::Consistent | MassKind::DispersionFree => m[i * nn + j],
                        // the element's own row sum: summed over elements, the lumped diagonal
                        MassKind::Lumped if i == j => m[i * nn..(i + 1) * nn].iter().sum(),
                        MassKind::Lumped => 0.0,
                    };
                    values[p] += coefficient * value;
                });
            }
        }
    }
}

/// y += M x over one body's elements, each an nn x nn scalar block (row-major in `blocks`)
/// acting on both components.
fn block_product<const NN: usize>(
    body: &Body,
    cells: &[[usize; NN]],
    blocks: &[f64],
    x: &[f64],
    y: &mut [f64],
) {
    for (nodes, m) in cells.iter().zip(blocks.chunks_exact(NN * NN)) {
        let g: [usize; NN] = std::array::from_fn(|i| 2 * body.global(nodes[i]));
        for i in 0..NN {
            for j in 0..NN {
                y[g[i]] += m[i * NN + j] * x[g[j]];
                y[g[i] + 1] += m[i * NN + j] * x[g[j] + 1];
            }
        }
    }
}

/// The rod blend 3/2 consistent - 1/2 lumped in place (an nn x nn element matrix): for the
/// two-node rod rho A h / 4 [[1, 1], [1, 1]], with which the trapezoidal rule is free of
/// dispersion at Courant number 1 (docs/theory.md "Contact in implicit dynamics").
fn dispersion_free(m: &mut [f64], nn: usize) {
    let rows: Vec<f64> = (0..nn)
        .map(|i| m[i * nn..(i + 1) * nn].iter().sum())
        .collect();
    for i in 0..nn {
        for j in 0..nn {
            let lumped = if i == j { rows[i] } else { 0.0 };
            m[i * nn + j] = 1.5 * m[i * nn + j] - 0.5 * lumped;
        }
    }
}

/// Removes the rows and columns of the `flagged` nodes of an element matrix and puts the
/// mass they held on the diagonal of the others, in proportion to their row sums.
fn redistribute(m: &mut [f64], nn: usize, flagged: &[bool]) {
    let total: f64 = m.iter().sum();
    let rows: Vec<f64> = (0..nn)
        .map(|i| m[i * nn..(i + 1) * nn].iter().sum())
        .collect();
    for i in 0..nn {
        for j in 0..nn {
            if flagged[i] || flagged[j] {
                m[i * nn + j] = 0.0;
            }
        }
    }
    let kept: f64 = m.iter().sum();
    let weight: f64 = (0..nn).filter(|i| !flagged[*i]).map(|i| rows[i]).sum();
    for i in (0..nn).filter(|i| !flagged[*i]) {
        m[i * nn + i] += (total - kept) * rows[i] / weight;
    }
}

/// The lumped mass of every element at its nodes (per body, element-major, nodes per
/// element each): invariant in the updated-Lagrangian description (rho dV is).
#[derive(Debug, Clone)]
pub struct ElementMasses {
    bodies: Vec<Vec<f64>>,
}

impl ElementMasses {
    pub fn new(model: &Model) -> Result<ElementMasses, ElementFailure> {
        let initial = model.coordinates();
        let bodies = model
            .bodies
            .iter()
            .map(|body| {
                let kernel = Kernel::of(body);
                let mut masses = Vec::new();
                for e in 0..body.elements() {
                    let m =
                        kernel
                            .lumped_mass(body, &initial, e)
                            .map_err(|error| ElementFailure {
                                body: body.name.clone(),
                                element: e,
                                error,
                            })?;
                    masses.extend(m);
                }
                Ok(masses)
            })
            .collect::<Result<_, _>>()?;
        Ok(ElementMasses { bodies })
    }

    /// The lumped masses of element `e` of body `b`.
    pub fn of(&self, model: &Model, b: usize, e: usize) -> &[f64] {
        let nn = model.bodies[b].mesh.cells.nodes_of(e).len();
        &self.bodies[b][e * nn..(e + 1) * nn]
    }
}

/// An upper bound of the highest frequency squared of the model at the committed state,
/// element by element (Irons' theorem: the assembled model's highest frequency is at most
/// the elements' highest), from the closed-form bounds of the kernels (`Kernel::
/// frequency_bound`); with the element that sets it (the lowest index among equals, so the
/// result does not depend on the thread count).
pub fn frequency_bound(
    model: &Model,
    state: &State,
    masses: &ElementMasses,
) -> Result<FrequencyBound, ElementFailure> {
    let mut best = FrequencyBound {
        omega_squared: 0.0,
        body: 0,
        element: 0,
    };
    for (b, body) in model.bodies.iter().enumerate() {
        let kernel = Kernel::of(body);
        let committed = &state.bodies[b];
        let worst = (0..body.elements())
            .into_par_iter()
            .map(|e| {
                kernel
                    .frequency_bound(
                        body,
                        committed,
                        &state.coordinates,
                        e,
                        masses.of(model, b, e),
                    )
                    .map(|w| (w, e))
                    .map_err(|error| (e, error))
            })
            .try_reduce(
                || (0.0, usize::MAX),
                |a, b| {
                    Ok(if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) {
                        b
                    } else {
                        a
                    })
                },
            )
            .map_err(|(element, error)| ElementFailure {
                body: body.name.clone(),
                element,
                error,
            })?;
        if worst.0 > best.omega_squared {
            best = FrequencyBound {
                omega_squared: worst.0,
                body: b,
                element: worst.1,
            };
        }
    }
    Ok(best)
}

/// The highest element frequency squared and the element that has it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrequencyBound {
    /// max_e lambda_max(M_e^-1 K_e).
    pub omega_squared: f64,
    pub body: usize,
    pub element: usize,
}

/// The largest element eigenvalue max_e lambda_max(M_e^-1 K_e) with the lumped element mass:
/// an upper bound of the highest natural frequency squared of the assembled model (Irons'
/// element eigenvalue theorem), so 2 / sqrt(it) is a safe central-difference step.
pub fn max_frequency_squared(
    model: &Model,
    state: &State,
    geometry: Strain,
) -> Result<FrequencyBound, ElementFailure> {
    let mut best = FrequencyBound {
        omega_squared: 0.0,
        body: 0,
        element: 0,
    };
    for bound in frequency_bounds(model, state, geometry)? {
        if bound.omega_squared > best.omega_squared {
            best = bound;
        }
    }
    Ok(best)
}

/// Every element's frequency bound (as `max_frequency_squared` takes the largest of them),
/// body by body in element order.
pub fn frequency_bounds(
    model: &Model,
    state: &State,
    geometry: Strain,
) -> Result<Vec<FrequencyBound>, ElementFailure> {
    let zero = vec![0.0; model.dofs()];
    let coords = model.coordinates();
    let mut bounds = Vec::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let kernel = Kernel::of(body);
        for e in 0..body.elements() {
            let failure = |error| ElementFailure {
                body: body.name.clone(),
                element: e,
                error,
            };
            let lambda = kernel
                .max_frequency_squared(
                    body,
                    &state.bodies[b],
                    &state.coordinates,
                    &coords,
                    &zero,
                    e,
                    geometry,
                )
                .map_err(failure)?;
            bounds.push(FrequencyBound {
                omega_squared: lambda,
                body: b,
                element: e,
            });
        }
    }
    Ok(bounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower-triangle scatter adds, at every global entry (i, j), i >= j, the element
    /// entries (a, b) with equations (i, j): what a dense assembly of the full element
    /// matrices gives there. The element matrices are deliberately not symmetric, so a
    /// transposed entry taken where the plain one belongs (or the reverse) shows.
    #[test]
    fn lower_triangle_scatter_matches_a_dense_assembly() {
        // three 4-DOF elements, equations in both orders, one constrained DOF (None)
        let elements: Vec<Vec<Option<usize>>> = vec![
            vec![Some(4), Some(1), Some(0), Some(3)],
            vec![Some(2), Some(4), None, Some(5)],
            vec![Some(5), Some(0), Some(1), Some(2)],
        ];
        let size = 6;
        let pattern = Pattern::from_elements(size, elements.iter().map(|v| v.as_slice()));
        let scatter = Scatter::new(&pattern, &elements);
        let n = 4;
        let matrix = |e: usize| -> Vec<f64> {
            (0..n * n)
                .map(|k| 1.0 + (e * 16 + k) as f64 * 0.37 + (k % 3) as f64 * 1e-3)
                .collect()
        };
        let mut values = vec![0.0; pattern.nonzeros()];
        let mut dense = vec![vec![0.0; size]; size];
        for (e, eqs) in elements.iter().enumerate() {
            let m = matrix(e);
            scatter.add(e, &m, &mut values);
            for a in 0..n {
                for b in 0..n {
                    if let (Some(i), Some(j)) = (eqs[a], eqs[b]) {
                        dense[i][j] += m[a * n + b];
                    }
                }
            }
        }
        for j in 0..size {
            for i in j..size {
                let got = pattern.position(i, j).map_or(0.0, |p| values[p]);
                // exact: each entry receives one element entry per element, in element order
                // in both sums
                assert_eq!(got, dense[i][j], "entry ({i}, {j})");
            }
        }
    }
}
