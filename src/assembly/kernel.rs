//! The element dispatch: the one place where a body's kind picks the kernel that integrates
//! its elements (Quad4 with 2x2 Gauss, Rod2), and where an element's nodes, thickness and
//! increment are gathered for that kernel. The explicit Quad4 kernels (one-point and 2x2 in
//! rate form) are not variants here: they keep their element state as structure of arrays
//! and step it in place, so they share the trait `explicit::ExplicitKernel` instead of this
//! per-element interface, and their element math lives beside this one in `element`. Each kernel gives, for one element: the
//! internal force with the material's response (and the tangent when asked), the
//! push-forward of its stresses at commit, its consistent and lumped mass, and its element
//! frequency bound for the central-difference stable step.

use super::{BodyState, StepIncrement};
use crate::element::{
    Formulation, GeometricStiffness, KernelError, Mat4, Strain, Vec4, Vec8, Voigt, quad4, rod2,
};
use crate::kinematics;
use crate::material::{
    PointState, Response, StressCondition, UpdateContext, trapezoid_dissipation,
};
use crate::scene::spec::Tangent;
use crate::scene::{Body, BodyKind};
use nalgebra::Matrix2;
use std::time::Instant;

/// Element `element` of `body` at its committed state (`committed`, the configuration
/// `coordinates`): what every kernel call reads.
#[derive(Clone, Copy)]
pub struct ElementAt<'a> {
    pub body: &'a Body,
    pub committed: &'a BodyState,
    pub coordinates: &'a [[f64; 2]],
    pub element: usize,
}

/// Where a kernel writes one element's results: slices of the caller's arrays, so a result
/// is written once, in place, and never moved (a whole-result struct sized for a Quad4 was
/// ~1 kB a rod, copied three times an evaluation).
pub struct ElementOut<'a> {
    /// Internal force, 2 nn entries.
    pub force: &'a mut [f64],
    /// The tangent, row-major (2 nn)^2, when asked.
    pub matrix: Option<&'a mut [f64]>,
    /// Trial point states, one a point.
    pub trial: &'a mut [PointState],
    /// Out-of-plane Green-Lagrange strain a point, when asked (plane stress).
    pub strain_zz: Option<&'a mut [f64]>,
}

/// Increments of the internal and plastic work of one element.
#[derive(Debug, Clone, Copy, Default)]
pub struct ElementWork {
    pub work: f64,
    pub plastic_work: f64,
}

/// How the elements of a body are integrated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kernel {
    /// Four-node quadrilateral, 2x2 Gauss points.
    Quad4 {
        formulation: Formulation,
        bbar: bool,
        /// The initial thickness (plane stress; 1 otherwise), for the mass.
        thickness: f64,
    },
    /// Two-node rod of the given cross-section area.
    Rod2 { area: f64 },
}

/// The node coordinates of element `e` of `body` from the global `coordinates`.
fn quad_nodes(body: &Body, e: usize, coordinates: &[[f64; 2]]) -> quad4::Coords {
    let nodes = body.mesh.cells.nodes_of(e);
    std::array::from_fn(|i| coordinates[body.global(nodes[i])])
}

fn rod_nodes(body: &Body, e: usize, coordinates: &[[f64; 2]]) -> [[f64; 2]; 2] {
    let nodes = body.mesh.cells.nodes_of(e);
    [
        coordinates[body.global(nodes[0])],
        coordinates[body.global(nodes[1])],
    ]
}

/// The increment of element `e` of `body` from the global increment `d` (2 DOFs a node).
fn increment<const N: usize>(body: &Body, e: usize, d: &[f64]) -> nalgebra::SVector<f64, N> {
    let nodes = body.mesh.cells.nodes_of(e);
    nalgebra::SVector::from_fn(|k, _| d[2 * body.global(nodes[k / 2]) + k % 2])
}

/// The committed thickness at the four points of element `e`.
fn point_thickness(committed: &BodyState, e: usize) -> [f64; 4] {
    std::array::from_fn(|q| committed.thickness[4 * e + q])
}

impl Kernel {
    /// The kernel of a body.
    pub fn of(body: &Body) -> Kernel {
        match body.kind {
            BodyKind::Continuum {
                formulation,
                bbar,
                thickness,
            } => Kernel::Quad4 {
                formulation,
                bbar,
                thickness,
            },
            BodyKind::Rod { area } => Kernel::Rod2 { area },
        }
    }

    /// Internal force, trial point states and work of the element `at` at the increment `d`
    /// over the time step `dt` from the committed state, into `out`; with `tangent`, its
    /// matrix.
    // inlined into the assembly's element loop, whose kernel is fixed for a body: the rod
    // loop then runs without the Quad4 arm's frame (the 224-rod bars 0.90x, the Quad4
    // scenes 0.97-1.0x)
    #[inline(always)]
    pub fn evaluate(
        &self,
        at: ElementAt<'_>,
        step: StepIncrement<'_>,
        tangent: Option<Tangent>,
        out: ElementOut<'_>,
    ) -> Result<ElementWork, KernelError> {
        let StepIncrement { d, dt, geometry } = step;
        let ElementAt {
            body,
            committed,
            coordinates,
            element: e,
        } = at;
        // the material's tangent, or D_e (Erklig's modified Newton); K_sigma unless `elastic`
        let elastic_moduli = tangent.is_some_and(|t| t != Tangent::Consistent);
        let geometric = if tangent == Some(Tangent::Elastic) {
            GeometricStiffness::Omitted
        } else {
            GeometricStiffness::Included
        };
        match *self {
            Kernel::Quad4 {
                formulation, bbar, ..
            } => {
                let x = quad_nodes(body, e, coordinates);
                let thickness = point_thickness(committed, e);
                let geom = quad4::values(&x, formulation, &thickness)?;
                let de: Vec8 = increment(body, e, d);
                let op = quad4::Operator {
                    strain: geometry,
                    bbar,
                };
                let points = Points::new(&geom, &de, op, out.matrix.is_some());
                if geometry == Strain::Finite {
                    check_orientation(&points.deformation())?;
                }
                let strains = points.strains();
                let condition = StressCondition::of(formulation);
                let context = UpdateContext { condition, dt };
                let fine = crate::profile::fine_sample(e).then(Instant::now);
                // the algorithmic moduli only where the matrix is asked for and made of them
                let with_tangent = out.matrix.is_some() && !elastic_moduli;
                let update = |q: usize| {
                    let point = &committed.points[4 * e + q];
                    body.material
                        .update_with(point, &strains[q], context, with_tangent)
                };
                // written out, not array::from_fn: whether that generic helper is inlined
                // depends on how the build splits the crate, and out of line it moved the
                // four ~0.3 kB responses through memory (three_rings 1.12x between builds)
                let responses = [update(0), update(1), update(2), update(3)];
                if let Some(start) = fine {
                    crate::profile::add_constitutive(start);
                }
                let stress = responses.map(|r| r.stress);
                let start = &committed.points[4 * e..4 * e + 4];
                let (work, plastic_work) = quad_work(&geom, start, &strains, &responses);
                let force = points.internal_force(&geom, &stress);
                out.force.copy_from_slice(force.as_slice());
                if let (Some(m), Points::Operators(operators)) = (out.matrix, &points) {
                    let moduli = if elastic_moduli {
                        [body.material.elastic.moduli(condition); 4]
                    } else {
                        responses.map(|r| r.moduli)
                    };
                    let k = quad4::tangent(&geom, operators, (&stress, &moduli), op, geometric);
                    m.copy_from_slice(k.transpose().as_slice()); // row-major
                }
                for (t, r) in out.trial.iter_mut().zip(&responses) {
                    *t = r.state;
                }
                if let Some(zz) = out.strain_zz {
                    for (z, r) in zz.iter_mut().zip(&responses) {
                        *z = r.strain_zz;
                    }
                }
                Ok(ElementWork { work, plastic_work })
            }
            Kernel::Rod2 { area } => {
                let x = rod_nodes(body, e, coordinates);
                let de: Vec4 = increment(body, e, d);
                let strain = rod2::strain(&x, &de, geometry)?;
                let response = body
                    .material
                    .update_uniaxial(&committed.points[e], strain, dt);
                let stress = response.stress;
                let length = rod2::length(&x)?;
                let work = area * length * 0.5 * (committed.points[e].stress[0] + stress) * strain;
                // 1/2 (S_n + S_{n+1}) dep, as the work (see trapezoid_dissipation)
                let plastic_work = area
                    * length
                    * trapezoid_dissipation(
                        &committed.points[e].stress,
                        &response.state.stress,
                        &response.state.back_stress,
                        response.plastic_work,
                    );
                let f4 = rod2::internal_force(&x, &de, stress, area, geometry)?;
                if let Some(m) = out.matrix {
                    let modulus = if elastic_moduli {
                        body.material.elastic.young
                    } else {
                        response.tangent
                    };
                    let axial = rod2::Axial { stress, modulus };
                    let k: Mat4 = rod2::tangent(&x, &de, axial, area, (geometry, geometric))?;
                    m.copy_from_slice(k.transpose().as_slice());
                }
                out.force.copy_from_slice(f4.as_slice());
                out.trial[0] = response.state;
                if let Some(zz) = out.strain_zz {
                    zz[0] = 0.0;
                }
                Ok(ElementWork { work, plastic_work })
            }
        }
    }

    /// Pushes the trial stresses of the element `at` (second Piola-Kirchhoff of the
    /// increment `d`) forward to Cauchy stresses on the new configuration (finite strain).
    pub fn push_forward(
        &self,
        at: ElementAt<'_>,
        d: &[f64],
        strain_zz: &[f64],
        points: &mut [PointState],
    ) {
        let ElementAt {
            body,
            committed,
            coordinates,
            element: e,
        } = at;
        match *self {
            Kernel::Quad4 { formulation, .. } => {
                let x = quad_nodes(body, e, coordinates);
                let thickness = point_thickness(committed, e);
                let geom = quad4::values(&x, formulation, &thickness)
                    .expect("checked during the evaluation");
                let de: Vec8 = increment(body, e, d);
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
            Kernel::Rod2 { .. } => {
                let x = rod_nodes(body, e, coordinates);
                let de: Vec4 = increment(body, e, d);
                let stretch = rod2::stretch(&x, &de).expect("checked during the evaluation");
                points[e].stress[0] *= stretch;
                points[e].back_stress[0] *= stretch;
            }
        }
    }

    /// The initial thickness of the points (1 for rods: their area is their own).
    pub fn thickness(&self) -> f64 {
        match *self {
            Kernel::Quad4 { thickness, .. } => thickness,
            Kernel::Rod2 { .. } => 1.0,
        }
    }

    /// The stress a point of this kernel carries of a body's `initial` stress (rods: the
    /// axial component only).
    pub fn stress(&self, initial: Voigt) -> Voigt {
        match self {
            Kernel::Quad4 { .. } => initial,
            Kernel::Rod2 { .. } => Voigt::new(initial[0], 0.0, 0.0, 0.0),
        }
    }

    /// Whether the body's thickness follows the out-of-plane stretch (plane stress).
    pub fn thins(&self) -> bool {
        matches!(
            self,
            Kernel::Quad4 {
                formulation: Formulation::PlaneStress,
                ..
            }
        )
    }

    /// The consistent mass of element `e` on the `initial` coordinates, rho N^T N, the same
    /// for x and y: nn x nn, row-major.
    pub fn mass(
        &self,
        body: &Body,
        initial: &[[f64; 2]],
        e: usize,
    ) -> Result<Vec<f64>, KernelError> {
        let rho = body.material.density;
        match *self {
            Kernel::Quad4 {
                formulation,
                thickness,
                ..
            } => {
                let x = quad_nodes(body, e, initial);
                let geom = quad4::values(&x, formulation, &[thickness; 4])?;
                let m = quad4::mass(&geom) * rho;
                Ok(m.transpose().as_slice().to_vec())
            }
            Kernel::Rod2 { area } => {
                let x = rod_nodes(body, e, initial);
                let m = rod2::mass(&x)?;
                Ok(m.iter().flatten().map(|v| v * rho * area).collect())
            }
        }
    }

    /// The lumped mass per node of element `e` on the `initial` coordinates: the row sums of
    /// its consistent mass.
    pub fn lumped_mass(
        &self,
        body: &Body,
        initial: &[[f64; 2]],
        e: usize,
    ) -> Result<Vec<f64>, KernelError> {
        let m = self.mass(body, initial, e)?;
        let nn = body.mesh.cells.nodes_of(e).len();
        Ok(m.chunks_exact(nn).map(|row| row.iter().sum()).collect())
    }

    /// An upper bound of the highest frequency squared of element `e` on the `coordinates`
    /// with its lumped nodal masses `lumped` (the elastic moduli of its material): the
    /// central-difference stable step is at least 2 / sqrt of it. Quad4: the bound of
    /// `quad4::frequency_bound`; Rod2: exact.
    pub fn frequency_bound(
        &self,
        body: &Body,
        committed: &BodyState,
        coordinates: &[[f64; 2]],
        e: usize,
        lumped: &[f64],
    ) -> Result<f64, KernelError> {
        let elastic = &body.material.elastic;
        match *self {
            Kernel::Quad4 { formulation, .. } => {
                let x = quad_nodes(body, e, coordinates);
                let geom = quad4::values(&x, formulation, &point_thickness(committed, e))?;
                let (lambda, mu) = elastic.lame_in(StressCondition::of(formulation));
                let m = [lumped[0], lumped[1], lumped[2], lumped[3]];
                Ok(quad4::frequency_bound(&geom, lambda, mu, &m))
            }
            Kernel::Rod2 { area } => {
                let x = rod_nodes(body, e, coordinates);
                rod2::frequency_squared(&x, elastic.young, area, lumped[0].min(lumped[1]))
            }
        }
    }

    /// The largest eigenvalue of M_e^-1 K_e of the element `at` (lumped M_e, from the
    /// `initial` coordinates) at the committed state, its frequency squared; `zero` is a zero
    /// increment over all DOFs.
    pub fn max_frequency_squared(
        &self,
        at: ElementAt<'_>,
        initial: &[[f64; 2]],
        zero: &[f64],
        geometry: Strain,
    ) -> Result<f64, KernelError> {
        let ElementAt {
            body, element: e, ..
        } = at;
        let lumped = self.lumped_mass(body, initial, e)?;
        let n = 2 * lumped.len();
        let (mut force, mut k) = ([0.0; 8], [0.0; 64]);
        let mut trial = [PointState::default(); 4];
        // a zero increment: no step, no rate
        let increment = StepIncrement {
            d: zero,
            dt: f64::INFINITY,
            geometry,
        };
        self.evaluate(
            at,
            increment,
            Some(Tangent::Consistent),
            ElementOut {
                force: &mut force[..n],
                matrix: Some(&mut k[..n * n]),
                trial: &mut trial[..body.points_per_element()],
                strain_zz: None,
            },
        )?;
        Ok(crate::element::highest_frequency_squared(
            |i, j| k[i * n + j],
            &lumped,
        ))
    }
}

/// det F > 0 at every Gauss point of the increment (the element does not turn inside out).
fn check_orientation(deformation: &[(Matrix2<f64>, f64); 4]) -> Result<(), KernelError> {
    for (point, (f, f_zz)) in deformation.iter().enumerate() {
        let det = f.determinant() * f_zz;
        if !(det > 0.0) {
            return Err(KernelError::NegativeJacobian { point, det });
        }
    }
    Ok(())
}

/// A Quad4 element's points: with their operators B (a tangent, B-bar), or their gradients
/// alone (a residual). It lives on the stack for one element, so the larger variant is not
/// boxed (a heap allocation an element would cost more than the unused bytes).
#[allow(clippy::large_enum_variant)]
enum Points {
    Operators(quad4::StrainOperators),
    Gradients(quad4::Gradients),
}

impl Points {
    /// The operators where a matrix is asked or B-bar changes them; a residual without B-bar
    /// forms none (see quad4::Gradients).
    #[inline(always)]
    fn new(geom: &quad4::QuadValues, de: &Vec8, op: quad4::Operator, matrix: bool) -> Points {
        if matrix || op.bbar {
            Points::Operators(quad4::StrainOperators::new(geom, de, op))
        } else {
            Points::Gradients(quad4::Gradients::new(geom, de, op.strain))
        }
    }

    fn strains(&self) -> [Voigt; 4] {
        match self {
            Points::Operators(k) => k.strains(),
            Points::Gradients(g) => g.strains(),
        }
    }

    fn deformation(&self) -> [(Matrix2<f64>, f64); 4] {
        match self {
            Points::Operators(k) => k.deformation(),
            Points::Gradients(g) => g.deformation(),
        }
    }

    fn internal_force(&self, geom: &quad4::QuadValues, stress: &[Voigt; 4]) -> Vec8 {
        match self {
            Points::Operators(k) => quad4::internal_force(geom, k, stress),
            Points::Gradients(g) => g.internal_force(geom, stress),
        }
    }
}

/// The increments of the internal work and of the plastic dissipation of a Quad4 element,
/// both by the trapezoidal rule over its four points: 1/2 (S_n + S_{n+1}) : dE (with plane
/// stress's dE_zz from the material) and 1/2 (S_n + S_{n+1}) : d eps_p.
fn quad_work(
    geom: &quad4::QuadValues,
    start: &[PointState],
    strains: &[Voigt; 4],
    responses: &[Response; 4],
) -> (f64, f64) {
    let (mut work, mut plastic_work) = (0.0, 0.0);
    for q in 0..4 {
        let (weight, end) = (geom.points[q].weight, &responses[q]);
        plastic_work += weight
            * trapezoid_dissipation(
                &start[q].stress,
                &end.state.stress,
                &end.state.back_stress,
                end.plastic_work,
            );
        let mut strain = strains[q];
        strain[2] = end.strain_zz;
        work += weight * 0.5 * (start[q].stress + end.stress).dot(&strain);
    }
    (work, plastic_work)
}
