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

pub mod reduced;

use crate::element::{
    Formulation, GeometricStiffness, KernelError, Mat4, Strain, Vec4, Vec8, Voigt, quad4, rod2,
};
use crate::kinematics;
use crate::material::{PointState, StressCondition};
use crate::scene::spec::{MassKind, Tangent};
use crate::scene::{Body, BodyKind, Model};
use crate::solver::Pattern;
use rayon::prelude::*;
use std::time::Instant;

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
                let thickness = match b.kind {
                    BodyKind::Continuum { thickness, .. } => thickness,
                    BodyKind::Rod { .. } => 1.0,
                };
                let stress = match b.kind {
                    BodyKind::Continuum { .. } => b.initial_stress,
                    BodyKind::Rod { .. } => Voigt::new(b.initial_stress[0], 0.0, 0.0, 0.0),
                };
                BodyState {
                    points: vec![
                        PointState {
                            stress,
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
    /// Out-of-plane Green-Lagrange strain per point (plane stress), else 0.
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
    pub pattern: Pattern,
    /// Per body: scatter positions, element-major, (2 nn)^2 per element.
    scatter: Vec<Vec<usize>>,
    /// Lower-triangle values of the last assembled matrix.
    pub values: Vec<f64>,
    /// The largest diagonal entry of the last factored matrix (a stiffness scale).
    pub diagonal_max: f64,
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
        let scatter = element_equations
            .iter()
            .map(|body| body.iter().flat_map(|eqs| pattern.scatter(eqs)).collect())
            .collect();
        let values = vec![0.0; pattern.nonzeros()];
        System {
            equation,
            free,
            pattern,
            scatter,
            values,
            diagonal_max: 0.0,
        }
    }

    /// The diagonal of the assembled matrix (the first entry of each lower-triangle column).
    pub fn diagonal(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.free).map(|j| self.values[self.pattern.col_ptr[j]])
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

/// Elements per chunk of `evaluate` (about 5 MB of results in flight).
const CHUNK: usize = 8192;

struct ElementResult {
    force: Vec8,
    matrix: Option<[f64; 64]>,
    trial: [PointState; 4],
    strain_zz: [f64; 4],
    work: f64,
    plastic_work: f64,
}

/// Internal force (and, when `system` is given, the tangent into `system.values`) at the
/// increment `d` from the committed `state`.
pub fn evaluate(
    model: &Model,
    state: &State,
    d: &[f64],
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
        let ppe = body.points_per_element();
        let mut body_trial = Vec::with_capacity(body.elements() * ppe);
        let mut body_zz = Vec::with_capacity(body.elements() * ppe);
        // elements in chunks, each evaluated in parallel and then scattered: the results in
        // flight stay a few MB however large the mesh (a whole mesh's 8 x 8 matrices at once
        // was 0.7 kB per element of transient memory)
        let mut results = Vec::with_capacity(CHUNK.min(body.elements()));
        for first in (0..body.elements()).step_by(CHUNK) {
            let last = (first + CHUNK).min(body.elements());
            (first..last)
                .into_par_iter()
                .map(|e| {
                    element(
                        body,
                        &state.bodies[b],
                        &state.coordinates,
                        d,
                        e,
                        geometry,
                        want_tangent.then_some(tangent),
                    )
                })
                .collect_into_vec(&mut results);
            for (r, e) in results.iter().zip(first..last) {
                let r = r.as_ref().map_err(|(element, error)| ElementFailure {
                    body: body.name.clone(),
                    element: *element,
                    error: *error,
                })?;
                let dofs = element_dofs(body, e);
                for (a, g) in dofs.iter().enumerate() {
                    force[*g] += r.force[a];
                }
                if let (Some(s), Some(m)) = (system.as_deref_mut(), &r.matrix) {
                    let n = dofs.len();
                    let positions = &s.scatter[b][e * n * n..(e + 1) * n * n];
                    for (k, p) in positions.iter().enumerate() {
                        if *p != usize::MAX {
                            s.values[*p] += m[k];
                        }
                    }
                }
                body_trial.extend_from_slice(&r.trial[..ppe]);
                body_zz.extend_from_slice(&r.strain_zz[..ppe]);
                work += r.work;
                plastic_work += r.plastic_work;
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

fn element(
    body: &Body,
    committed: &BodyState,
    reference: &[[f64; 2]],
    d: &[f64],
    e: usize,
    geometry: Strain,
    tangent: Option<Tangent>,
) -> Result<ElementResult, (usize, KernelError)> {
    // the material's tangent, or D_e (Erklig's modified Newton); K_sigma unless `elastic`
    let elastic_moduli = tangent.is_some_and(|t| t != Tangent::Consistent);
    let geometric = if tangent == Some(Tangent::Elastic) {
        GeometricStiffness::Omitted
    } else {
        GeometricStiffness::Included
    };
    let nodes = body.mesh.cells.nodes_of(e);
    match body.kind {
        BodyKind::Continuum {
            formulation, bbar, ..
        } => {
            let x: quad4::Coords = std::array::from_fn(|i| reference[body.global(nodes[i])]);
            let thickness: [f64; 4] = std::array::from_fn(|q| committed.thickness[4 * e + q]);
            let geom = quad4::values(&x, formulation, &thickness).map_err(|err| (e, err))?;
            let de = Vec8::from_fn(|k, _| d[2 * body.global(nodes[k / 2]) + k % 2]);
            if geometry == Strain::Finite {
                check_orientation(&geom, &de).map_err(|err| (e, err))?;
            }
            let op = quad4::Operator {
                strain: geometry,
                bbar,
            };
            let strains = quad4::strains(&geom, &de, op);
            let stress_state = if formulation == Formulation::PlaneStress {
                StressCondition::PlaneStress
            } else {
                StressCondition::General
            };
            let fine = crate::profile::fine().then(Instant::now);
            let responses: [_; 4] = std::array::from_fn(|q| {
                body.material
                    .update(&committed.points[4 * e + q], &strains[q], stress_state)
            });
            if let Some(start) = fine {
                crate::profile::add_constitutive(start);
            }
            let stress = responses.map(|r| r.stress);
            let mut work = 0.0;
            let mut plastic_work = 0.0;
            for q in 0..4 {
                plastic_work += geom.points[q].weight * responses[q].plastic_work;
                let mut strain = strains[q];
                strain[2] = responses[q].strain_zz;
                work += geom.points[q].weight
                    * 0.5
                    * (committed.points[4 * e + q].stress + stress[q]).dot(&strain);
            }
            let force = quad4::internal_force(&geom, &de, &stress, op);
            let matrix = tangent.map(|_| {
                let moduli = if elastic_moduli {
                    [body.material.elastic.moduli(stress_state); 4]
                } else {
                    responses.map(|r| r.moduli)
                };
                let k = quad4::tangent(&geom, &de, &stress, &moduli, op, geometric);
                let mut m = [0.0; 64];
                m.copy_from_slice(k.transpose().as_slice()); // row-major
                m
            });
            Ok(ElementResult {
                force,
                matrix,
                trial: responses.map(|r| r.state),
                strain_zz: responses.map(|r| r.strain_zz),
                work,
                plastic_work,
            })
        }
        BodyKind::Rod { area } => {
            let x = [
                reference[body.global(nodes[0])],
                reference[body.global(nodes[1])],
            ];
            let de = Vec4::from_fn(|k, _| d[2 * body.global(nodes[k / 2]) + k % 2]);
            let strain = rod2::strain(&x, &de, geometry).map_err(|err| (e, err))?;
            let response = body.material.update_uniaxial(&committed.points[e], strain);
            let (stress, modulus, state, plastic_density) = (
                response.stress,
                response.tangent,
                response.state,
                response.plastic_work,
            );
            let length = rod2::length(&x).map_err(|err| (e, err))?;
            let work = area * length * 0.5 * (committed.points[e].stress[0] + stress) * strain;
            let plastic_work = area * length * plastic_density;
            let f4 =
                rod2::internal_force(&x, &de, stress, area, geometry).map_err(|err| (e, err))?;
            let matrix = if tangent.is_some() {
                let modulus = if elastic_moduli {
                    body.material.elastic.young
                } else {
                    modulus
                };
                let k: Mat4 = rod2::tangent(&x, &de, stress, modulus, area, geometry, geometric)
                    .map_err(|err| (e, err))?;
                let mut m = [0.0; 64];
                m[..16].copy_from_slice(k.transpose().as_slice());
                Some(m)
            } else {
                None
            };
            let mut force = Vec8::zeros();
            force.fixed_rows_mut::<4>(0).copy_from(&f4);
            Ok(ElementResult {
                force,
                matrix,
                trial: [state; 4],
                strain_zz: [0.0; 4],
                work,
                plastic_work,
            })
        }
    }
}

/// det F > 0 at every Gauss point of the increment (the element does not turn inside out).
fn check_orientation(geom: &quad4::QuadValues, d: &Vec8) -> Result<(), KernelError> {
    for (point, (f, f_zz)) in quad4::deformation(geom, d).iter().enumerate() {
        let det = f.determinant() * f_zz;
        if !(det > 0.0) {
            return Err(KernelError::NegativeJacobian { point, det });
        }
    }
    Ok(())
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
        trial,
        strain_zz,
        work,
        plastic_work: evaluation_plastic_work,
        ..
    } = evaluation;
    for (b, body) in model.bodies.iter().enumerate() {
        let mut points = trial[b].clone();
        if geometry == Strain::Finite {
            push_forward_body(
                body,
                &state.bodies[b],
                &state.coordinates,
                d,
                &strain_zz[b],
                &mut points,
            );
            let bs = &mut state.bodies[b];
            if let BodyKind::Continuum {
                formulation: Formulation::PlaneStress,
                ..
            } = body.kind
            {
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

fn push_forward_body(
    body: &Body,
    committed: &BodyState,
    reference: &[[f64; 2]],
    d: &[f64],
    strain_zz: &[f64],
    points: &mut [PointState],
) {
    for e in 0..body.elements() {
        let nodes = body.mesh.cells.nodes_of(e);
        match body.kind {
            BodyKind::Continuum { formulation, .. } => {
                let x: quad4::Coords = std::array::from_fn(|i| reference[body.global(nodes[i])]);
                let thickness: [f64; 4] = std::array::from_fn(|q| committed.thickness[4 * e + q]);
                let geom = quad4::values(&x, formulation, &thickness)
                    .expect("checked during the evaluation");
                let de = Vec8::from_fn(|k, _| d[2 * body.global(nodes[k / 2]) + k % 2]);
                for (q, (f, hoop)) in quad4::deformation(&geom, &de).iter().enumerate() {
                    let f_zz = match formulation {
                        Formulation::PlaneStress => {
                            kinematics::plane_stress_stretch(strain_zz[4 * e + q])
                        }
                        Formulation::Axisymmetric => *hoop,
                        Formulation::PlaneStrain => 1.0,
                    };
                    let p = &mut points[4 * e + q];
                    p.stress = kinematics::push_forward(&p.stress, f, f_zz);
                    p.back_stress = kinematics::push_forward(&p.back_stress, f, f_zz);
                }
            }
            BodyKind::Rod { .. } => {
                let x = [
                    reference[body.global(nodes[0])],
                    reference[body.global(nodes[1])],
                ];
                let de = Vec4::from_fn(|k, _| d[2 * body.global(nodes[k / 2]) + k % 2]);
                let stretch = rod2::stretch(&x, &de).expect("checked during the evaluation");
                points[e].stress[0] *= stretch;
                points[e].back_stress[0] *= stretch;
            }
        }
    }
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
            let rho = body.material.density;
            let nn = body.mesh.cells.nodes_of(0).len();
            let mut body_m = Vec::with_capacity(body.elements() * nn * nn);
            for e in 0..body.elements() {
                let nodes = body.mesh.cells.nodes_of(e);
                let failure = |error| ElementFailure {
                    body: body.name.clone(),
                    element: e,
                    error,
                };
                let m: Vec<f64> = match body.kind {
                    BodyKind::Continuum {
                        formulation,
                        thickness,
                        ..
                    } => {
                        let x: quad4::Coords =
                            std::array::from_fn(|i| coords[body.global(nodes[i])]);
                        let geom =
                            quad4::values(&x, formulation, &[thickness; 4]).map_err(failure)?;
                        let m = quad4::mass(&geom) * rho;
                        m.transpose().as_slice().to_vec()
                    }
                    BodyKind::Rod { area } => {
                        let x = [coords[body.global(nodes[0])], coords[body.global(nodes[1])]];
                        let m = rod2::mass(&x).map_err(failure)?;
                        m.iter().flatten().map(|v| v * rho * area).collect()
                    }
                };
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

    /// M x over all DOFs.
    pub fn product(&self, model: &Model, x: &[f64]) -> Vec<f64> {
        match self.kind {
            MassKind::Lumped => self.lumped.iter().zip(x).map(|(m, v)| m * v).collect(),
            MassKind::Consistent => {
                let mut y = vec![0.0; x.len()];
                for (b, body) in model.bodies.iter().enumerate() {
                    let nn = body.mesh.cells.nodes_of(0).len();
                    for e in 0..body.elements() {
                        let nodes = body.mesh.cells.nodes_of(e);
                        let m = &self.elements[b][e * nn * nn..(e + 1) * nn * nn];
                        for i in 0..nn {
                            let gi = body.global(nodes[i]);
                            for j in 0..nn {
                                let gj = body.global(nodes[j]);
                                y[2 * gi] += m[i * nn + j] * x[2 * gj];
                                y[2 * gi + 1] += m[i * nn + j] * x[2 * gj + 1];
                            }
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
            let n = 2 * nn;
            for e in 0..body.elements() {
                let positions = &system.scatter[b][e * n * n..(e + 1) * n * n];
                let m = &self.elements[b][e * nn * nn..(e + 1) * nn * nn];
                for i in 0..nn {
                    for j in 0..nn {
                        let value = match self.kind {
                            MassKind::Consistent => m[i * nn + j],
                            // the element's own row sum: summed over elements, the lumped diagonal
                            MassKind::Lumped if i == j => m[i * nn..(i + 1) * nn].iter().sum(),
                            MassKind::Lumped => 0.0,
                        };
                        for c in 0..2 {
                            let p = positions[(2 * i + c) * n + 2 * j + c];
                            if p != usize::MAX {
                                system.values[p] += coefficient * value;
                            }
                        }
                    }
                }
            }
        }
    }
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
    let zero = vec![0.0; model.dofs()];
    let coords = model.coordinates();
    let mut best = FrequencyBound {
        omega_squared: 0.0,
        body: 0,
        element: 0,
    };
    for (b, body) in model.bodies.iter().enumerate() {
        let rho = body.material.density;
        for e in 0..body.elements() {
            let failure = |error| ElementFailure {
                body: body.name.clone(),
                element: e,
                error,
            };
            let r = element(
                body,
                &state.bodies[b],
                &state.coordinates,
                &zero,
                e,
                geometry,
                Some(Tangent::Consistent),
            )
            .map_err(|(_, err)| failure(err))?;
            let k = r.matrix.expect("tangent requested");
            let nodes = body.mesh.cells.nodes_of(e);
            let lumped: Vec<f64> = match body.kind {
                BodyKind::Continuum {
                    formulation,
                    thickness,
                    ..
                } => {
                    let x: quad4::Coords = std::array::from_fn(|i| coords[body.global(nodes[i])]);
                    let geom = quad4::values(&x, formulation, &[thickness; 4]).map_err(failure)?;
                    let m = quad4::mass(&geom);
                    (0..4).map(|i| rho * m.row(i).sum()).collect()
                }
                BodyKind::Rod { area } => {
                    let x = [coords[body.global(nodes[0])], coords[body.global(nodes[1])]];
                    let l = rod2::length(&x).map_err(failure)?;
                    vec![rho * area * l / 2.0; 2]
                }
            };
            let n = 2 * lumped.len();
            let scale: Vec<f64> = (0..n).map(|i| 1.0 / lumped[i / 2].sqrt()).collect();
            let a = nalgebra::DMatrix::from_fn(n, n, |i, j| k[i * n + j] * scale[i] * scale[j]);
            let a = (&a + a.transpose()) * 0.5;
            let lambda = a.symmetric_eigenvalues().max();
            if lambda > best.omega_squared {
                best = FrequencyBound {
                    omega_squared: lambda,
                    body: b,
                    element: e,
                };
            }
        }
    }
    Ok(best)
}
