//! Global assembly: DOF numbering with constrained DOFs eliminated, the sparsity pattern and
//! every element's scatter positions computed once per topology (`scatter`), the element loop
//! (in chunks; a chunk's elements in parallel where it pays, their results written in place
//! and scattered serially in element order, so the sums do not depend on the thread count),
//! and the mass matrix (`mass`); the explicit element loops (`explicit`) and their mass
//! scaling (`mass_scaling`).
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
mod mass;
pub mod mass_scaling;
mod scatter;

use kernel::ElementOut;
pub use kernel::{ElementAt, Kernel};
pub use mass::{Mass, body_sums, check_mass};
use scatter::{Scatter, TRANSPOSED};

use crate::element::{KernelError, Strain};
use crate::kinematics;
use crate::material::PointState;
use crate::scene::spec::Tangent;
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
    /// The body's share of `State::internal_work` and `State::plastic_work`: the work its
    /// elements' stresses (and hourglass forces) did, and the plastic part of it.
    pub work: BodyWork,
}

/// The accumulated work of one body's elements (history.csv `internal_energy[body]` is
/// `internal - plastic`, `plastic_work[body]` is `plastic`).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyWork {
    /// The work of the internal forces, plastic work and hourglass work included.
    pub internal: f64,
    pub plastic: f64,
}

impl BodyWork {
    pub fn add(&mut self, other: &BodyWork) {
        self.internal += other.internal;
        self.plastic += other.plastic;
    }
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
                    work: BodyWork::default(),
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
    /// StepIncrement of the internal work.
    pub work: f64,
    /// StepIncrement of the plastic work.
    pub plastic_work: f64,
    /// The increments of each body (model order): their sums are `work` and `plastic_work`.
    pub body_work: Vec<BodyWork>,
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
    /// The share by which a static tangent's diagonal is raised before it is factored
    /// (`regularize`): 0, unless a body is held by its contact alone (docs/theory.md 5c).
    pub held: f64,
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
            held: 0.0,
        }
    }

    /// Raises each diagonal entry of the assembled matrix by the share `held` (none when 0):
    /// a body held by its contact alone has a rigid motion that only the contact rows hold,
    /// so its tangent is singular by itself, and the Schur complement needs it factored
    /// (docs/theory.md 5c). Newton's residual stays exact, so the shift moves the converged
    /// answer by nothing but a slower contraction.
    pub fn regularize(&mut self) {
        if self.held > 0.0 {
            for j in 0..self.free {
                self.values[self.pattern.col_ptr[j] as usize] *= 1.0 + self.held;
            }
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
    increment: StepIncrement,
    system: Option<&mut System>,
    tangent: Tangent,
) -> Result<Evaluation, ElementFailure> {
    let _timer = crate::profile::Timer::new(crate::profile::Phase::Assembly);
    crate::profile::count_elements(model.elements());
    evaluate_elements(model, state, increment, system, tangent)
}

/// The increment an evaluation takes from the committed state: the displacement increment
/// `d` (all DOFs) over the step `dt` (infinity: no rate), under small or finite strain.
#[derive(Debug, Clone, Copy)]
pub struct StepIncrement<'a> {
    pub d: &'a [f64],
    pub dt: f64,
    pub geometry: Strain,
}

/// [`evaluate`] without its timing (for a caller that times the element loop itself).
pub(crate) fn evaluate_elements(
    model: &Model,
    state: &State,
    increment: StepIncrement,
    mut system: Option<&mut System>,
    tangent: Tangent,
) -> Result<Evaluation, ElementFailure> {
    let want_tangent = system.is_some();
    if let Some(s) = system.as_deref_mut() {
        s.values.iter_mut().for_each(|v| *v = 0.0);
    }
    let mut force = vec![0.0; model.dofs()];
    let mut trial = Vec::with_capacity(model.bodies.len());
    let mut strain_zz = Vec::with_capacity(model.bodies.len());
    let mut work = 0.0;
    let mut plastic_work = 0.0;
    let mut body_work = vec![BodyWork::default(); model.bodies.len()];
    for (b, body) in model.bodies.iter().enumerate() {
        let kernel = Kernel::of(body);
        let ppe = body.points_per_element();
        let nodes = body.mesh.cells.nodes_per_cell();
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
                let at = ElementAt {
                    body,
                    committed: &state.bodies[b],
                    coordinates: &state.coordinates,
                    element: first + k,
                };
                kernel.evaluate(
                    at,
                    increment,
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
                body_work[b].internal += w.work;
                body_work[b].plastic += w.plastic_work;
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
        body_work,
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
        body_work,
        ..
    } = evaluation;
    for (b, body) in model.bodies.iter().enumerate() {
        // the trial states become the committed ones (taken, not copied: a copy of every
        // point's state beside the factor set the implicit memory peak)
        let mut points = std::mem::take(&mut trial[b]);
        if geometry == Strain::Finite {
            let kernel = Kernel::of(body);
            for e in 0..body.elements() {
                let at = ElementAt {
                    body,
                    committed: &state.bodies[b],
                    coordinates: &state.coordinates,
                    element: e,
                };
                kernel.push_forward(at, d, &strain_zz[b], &mut points);
            }
            if kernel.thins() {
                let bs = &mut state.bodies[b];
                for (t, ezz) in bs.thickness.iter_mut().zip(&strain_zz[b]) {
                    *t *= kinematics::plane_stress_stretch(*ezz);
                }
            }
        }
        state.bodies[b].points = points;
        state.bodies[b].work.add(&body_work[b]);
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

/// The lumped mass of every element at its nodes (per body, element-major, nodes per
/// element each): invariant in the updated-Lagrangian description (rho dV is).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
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

    /// Body `b`'s element masses replaced by `masses` (element-major, as `of` reads them): an
    /// ALE remap moves mass between the elements (docs/theory.md 8.11).
    pub fn replace(&mut self, b: usize, masses: Vec<f64>) {
        assert_eq!(
            masses.len(),
            self.bodies[b].len(),
            "one mass per element node"
        );
        self.bodies[b] = masses;
    }

    /// The lumped nodal masses, 2 per node (both components): the sums of the elements'.
    pub fn lumped(&self, model: &Model) -> Vec<f64> {
        let mut m = vec![0.0; model.dofs()];
        for (b, body) in model.bodies.iter().enumerate() {
            for e in 0..body.elements() {
                let nodes = body.mesh.cells.nodes_of(e);
                for (n, value) in nodes.iter().zip(self.of(model, b, e)) {
                    let g = body.global(*n);
                    m[2 * g] += value;
                    m[2 * g + 1] += value;
                }
            }
        }
        m
    }

    /// The lumped masses of element `e` of body `b`.
    pub fn of(&self, model: &Model, b: usize, e: usize) -> &[f64] {
        let nn = model.bodies[b].mesh.cells.nodes_of(e).len();
        &self.bodies[b][e * nn..(e + 1) * nn]
    }
}

/// A stable step of central difference, dt = 2 / omega, and the element that sets it: the
/// one type of the stable step. The explicit kernels' bounds, the run's clock, `impact check`
/// and summary.json `dt_limit` (the body by name) all carry it (docs/theory.md 8.7).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StableStep {
    pub dt: f64,
    pub body: usize,
    pub element: usize,
}

impl StableStep {
    /// The step 2 / omega of an element whose highest frequency squared is `omega_squared`
    /// (infinite for an element that does not vibrate).
    pub fn of_frequency(omega_squared: f64, body: usize, element: usize) -> StableStep {
        StableStep {
            dt: 2.0 / omega_squared.sqrt(),
            body,
            element,
        }
    }
}

/// A stable step of the model at the committed state from the closed-form element frequency
/// bounds of the kernels (`Kernel::frequency_bound`; Irons' theorem: the assembled model's
/// highest frequency is at most the elements' highest); with the element that sets it (the
/// lowest index among equals, so the result does not depend on the thread count).
pub fn bound_stable_step(
    model: &Model,
    state: &State,
    masses: &ElementMasses,
) -> Result<StableStep, ElementFailure> {
    let (omega_squared, body, element) = largest_frequency_bound(model, state, masses)?;
    Ok(StableStep::of_frequency(omega_squared, body, element))
}

/// The largest closed-form element frequency bound squared of the model at the committed
/// state (`bound_stable_step`), with its body and element.
pub(crate) fn largest_frequency_bound(
    model: &Model,
    state: &State,
    masses: &ElementMasses,
) -> Result<(f64, usize, usize), ElementFailure> {
    let mut best = (0.0, 0, 0);
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
        if worst.0 > best.0 {
            best = (worst.0, b, worst.1);
        }
    }
    Ok(best)
}

/// The stability limit of central difference from the element eigenvalues: 2 / sqrt of the
/// largest lambda_max(M_e^-1 K_e) with the lumped element mass (an upper bound of the
/// assembled model's highest frequency squared, Irons' element eigenvalue theorem), and the
/// element that has it (the first among equals).
pub fn eigenvalue_stable_step(
    model: &Model,
    state: &State,
    geometry: Strain,
) -> Result<StableStep, ElementFailure> {
    let mut best = (0.0, 0, 0);
    for (b, e, omega_squared) in element_eigenvalues(model, state, geometry)? {
        if omega_squared > best.0 {
            best = (omega_squared, b, e);
        }
    }
    Ok(StableStep::of_frequency(best.0, best.1, best.2))
}

/// Every element's eigenvalue stable step (as `eigenvalue_stable_step` takes the shortest of
/// them), body by body in element order.
pub fn element_stable_steps(
    model: &Model,
    state: &State,
    geometry: Strain,
) -> Result<Vec<StableStep>, ElementFailure> {
    Ok(element_eigenvalues(model, state, geometry)?
        .into_iter()
        .map(|(b, e, omega_squared)| StableStep::of_frequency(omega_squared, b, e))
        .collect())
}

/// Every element's largest eigenvalue lambda_max(M_e^-1 K_e): (body, element, lambda).
fn element_eigenvalues(
    model: &Model,
    state: &State,
    geometry: Strain,
) -> Result<Vec<(usize, usize, f64)>, ElementFailure> {
    let zero = vec![0.0; model.dofs()];
    let coords = model.coordinates();
    let mut eigenvalues = Vec::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let kernel = Kernel::of(body);
        // the elements in parallel, then the first failure in element order
        let lambdas: Vec<Result<f64, KernelError>> = (0..body.elements())
            .into_par_iter()
            .map(|e| {
                kernel.max_frequency_squared(
                    ElementAt {
                        body,
                        committed: &state.bodies[b],
                        coordinates: &state.coordinates,
                        element: e,
                    },
                    &coords,
                    &zero,
                    geometry,
                )
            })
            .collect();
        for (e, lambda) in lambdas.into_iter().enumerate() {
            let lambda = lambda.map_err(|error| ElementFailure {
                body: body.name.clone(),
                element: e,
                error,
            })?;
            eigenvalues.push((b, e, lambda));
        }
    }
    Ok(eigenvalues)
}
