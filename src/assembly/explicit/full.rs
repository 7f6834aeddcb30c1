//! The explicit 2x2 Quad4 in rate form: at each Gauss point of the mid-step configuration the
//! strain increment and spin of the step (Hughes-Winget), the stress rotated by it, the
//! material's update; the nodal forces on the end configuration; mean-dilatation (B-bar)
//! volumetric strain by option. The same element as the implicit 2x2 kernel at small steps
//! (where the Green-Lagrange increment and the push-forward reduce to the rate form), without
//! its tangent: the fast path of `quadrature = "full"` on finite-strain Quad4 models.
//!
//! Legend (element; q = 1..4 the Gauss points, a = 1..4 the nodes)
//! ```text
//! N_a,q, N_a,x, N_a,y   shape values and gradients at q on the mid configuration x + u/2
//! G_q                   sum_a u_a (x) grad N_a: the increment gradient at q
//! d_q, w_q              sym G_q ([xx yy zz xy], zz the hoop u_r / r in axisymmetry), and
//!                       w = (G_xy - G_yx) / 2
//! B-bar                 d_q,ii += (tr_mean - tr d_q) / 3, tr_mean the volume mean of tr d_q
//! sigma_q               material(R_q sigma_q,n R_q^T, d_q)
//! f_a                   sum_q W_q (B_q^T sigma_q) on the end configuration (B-bar likewise)
//! W_int                 sum_q W_q,mid 1/2 (R sigma_n R^T + sigma_{n+1}) . d_q
//! q_q                   the bulk viscosity's pressure at q from tr d_q / dt (by option;
//!                       element::bulk_viscosity), the element's rho, c_d, L_e on the mid
//!                       configuration; f_a then sums B_q^T (sigma_q - q_q I)
//! W_visc                -sum_q W_q,mid 1/2 (q_q,n + q_q,n+1) tr d_q
//! s                     the element's mass factor of the mass scaling (by option; 1
//!                       without it): its lumped masses are s m_a in the frequency bound and
//!                       the viscous density, and an element whose bound is below the target
//!                       gets a larger s (mass_scaling.rs)
//! ```

use super::tight::{
    ElementStiffness, Tightness, end_nodes, shortest_edge, stiffness_by_differences,
};
use super::{
    CHUNK, ChunkResult, ExplicitKernel, Layout, NodeGather, PartialKernel, StepWork, cut,
    element_motion, element_scaling, fold_chunks, kept_bound, kernel_stable_step, point_statistic,
    point_step,
};
use crate::assembly::mass_scaling::ElementScaling;
use crate::assembly::{ElementFailure, ElementMasses, StableStep, State};
use crate::element::bulk_viscosity::{
    BulkViscosity, ElementScale, damped_frequency_squared, damping_factor, loaded_stress,
    volumetric_increment,
};
use crate::element::mass_scaling::MassScaling;
use crate::element::quad4::{self, QuadValues};
use crate::element::quad4_one_point::{Nodes, rotate};
use crate::element::{Formulation, KernelError, Voigt};
use crate::material::{PointState, dissipation};
use crate::scene::Model;
use crate::scene::model::Probe;
use rayon::prelude::*;

/// The committed state of the four points of one element.
#[derive(Debug, Clone, Copy)]
struct PointsState {
    stress: [[f64; 4]; 4],
    back_stress: [[f64; 4]; 4],
    eq_plastic_strain: [f64; 4],
    /// Temperature (0 for materials that carry none).
    temperature: [f64; 4],
    thickness: [f64; 4],
    /// The bulk viscosity's pressure of the step that ended here (0 without it).
    viscous_pressure: [f64; 4],
}

/// One element after a step.
struct ElementStep {
    state: PointsState,
    force: [f64; 8],
    work: f64,
    plastic_work: f64,
    viscous_work: f64,
    omega_squared: f64,
    /// The undamped bound over the damped one (1 without the bulk viscosity).
    damping: f64,
}

/// The 2x2 explicit kernel over a model's Quad4 bodies.
pub struct Full {
    layout: Layout,
    /// The lumped mass at the four nodes of each element (for its stable-step bound).
    lumped: Vec<[f64; 4]>,
    /// Per element, per point: Cauchy stress and back stress [xx yy zz xy] (16 each),
    /// equivalent plastic strain, temperature and thickness (4 each).
    stress: Vec<f64>,
    back_stress: Vec<f64>,
    eq_plastic_strain: Vec<f64>,
    temperature: Vec<f64>,
    thickness: Vec<f64>,
    /// The bulk viscosity (None: off) and its pressure per element, per point (4 each).
    viscosity: Option<BulkViscosity>,
    viscous_pressure: Vec<f64>,
    element_forces: Vec<f64>,
    gather: NodeGather,
    /// The mass scaling (None: off).
    scaling: Option<ElementScaling>,
    /// Each element's frequency bound of the last step, and the ratios that make them tight
    /// (`tight`; None: the bounds stand, the default).
    bounds: Vec<f64>,
    /// Each element's `ElementStep::damping` of the last step (the bulk viscosity's at rest
    /// before the first): the tight ratios are taken against the undamped bounds.
    damping: Vec<f64>,
    tightness: Option<Tightness>,
}

/// The increment gradient, strain and spin at one point.
fn point_increment(p: &quad4::PointValues, u: &Nodes, axisymmetric: bool) -> ([f64; 4], f64) {
    let (mut gxx, mut gxy, mut gyx, mut gyy) = (0.0, 0.0, 0.0, 0.0);
    for a in 0..4 {
        let [nx, ny] = p.dndx[a];
        gxx += u[a][0] * nx;
        gxy += u[a][0] * ny;
        gyx += u[a][1] * nx;
        gyy += u[a][1] * ny;
    }
    let hoop = if axisymmetric {
        (0..4).map(|a| p.shape[a] * u[a][0]).sum::<f64>() / p.radius
    } else {
        0.0
    };
    ([gxx, gyy, hoop, gxy + gyx], 0.5 * (gxy - gyx))
}

/// The nodal forces sum_q W_q B_q^T sigma_q on the configuration of `values` (B-bar: the
/// volumetric rows averaged over the element).
fn forces(values: &QuadValues, stress: &[[f64; 4]; 4], bbar: bool) -> [f64; 8] {
    let axisymmetric = values.formulation == Formulation::Axisymmetric;
    let mut f = [0.0; 8];
    let mut mean_b = [[0.0; 2]; 4];
    let mut volume = 0.0;
    let mut pressure_weight = 0.0;
    for (p, s) in values.points.iter().zip(stress) {
        let w = p.weight;
        let mean = (s[0] + s[1] + s[2]) / 3.0;
        for a in 0..4 {
            let [nx, ny] = p.dndx[a];
            let hoop = if axisymmetric {
                p.shape[a] / p.radius
            } else {
                0.0
            };
            f[2 * a] += w * (s[0] * nx + s[3] * ny + s[2] * hoop);
            f[2 * a + 1] += w * (s[3] * nx + s[1] * ny);
            if bbar {
                // minus the point's own volumetric row times its mean stress
                f[2 * a] -= w * mean * (nx + hoop);
                f[2 * a + 1] -= w * mean * ny;
                mean_b[a][0] += w * (nx + hoop);
                mean_b[a][1] += w * ny;
            }
        }
        volume += w;
        pressure_weight += w * mean;
    }
    if bbar {
        for a in 0..4 {
            f[2 * a] += mean_b[a][0] / volume * pressure_weight;
            f[2 * a + 1] += mean_b[a][1] / volume * pressure_weight;
        }
    }
    f
}

/// One element over one step of length dt: positions x at the start, increment u (`(x, u)`),
/// with the bulk viscosity `viscosity` when on (see the legend).
fn element_step(
    p: &super::BodyParameters,
    (x, u): (&Nodes, &Nodes),
    committed: &PointsState,
    lumped: &[f64; 4],
    (dt, viscosity): (f64, Option<&BulkViscosity>),
) -> Result<ElementStep, KernelError> {
    let axisymmetric = p.axisymmetric();
    let mid: Nodes = std::array::from_fn(|a| [x[a][0] + 0.5 * u[a][0], x[a][1] + 0.5 * u[a][1]]);
    let end: Nodes = std::array::from_fn(|a| [x[a][0] + u[a][0], x[a][1] + u[a][1]]);
    let at_mid = quad4::values(&mid, p.formulation, &committed.thickness)?;
    let mut strain = [[0.0; 4]; 4];
    let mut spin = [0.0; 4];
    for q in 0..4 {
        (strain[q], spin[q]) = point_increment(&at_mid.points[q], u, axisymmetric);
    }
    if p.bbar {
        let volume = at_mid.volume();
        let trace = |d: &[f64; 4]| d[0] + d[1] + d[2];
        let mean: f64 = (0..4)
            .map(|q| at_mid.points[q].weight * trace(&strain[q]))
            .sum::<f64>()
            / volume;
        for d in &mut strain {
            let shift = (mean - trace(d)) / 3.0;
            for c in 0..3 {
                d[c] += shift;
            }
        }
    }
    // the volumetric increments the viscous pressures follow (before plane stress writes the
    // thickness strain into the increments)
    let viscous = viscosity.map(|viscosity| {
        let scale = ElementScale::new(&mid, lumped.iter().sum(), at_mid.volume(), p.wave_modulus);
        let volumetric: [f64; 4] =
            std::array::from_fn(|q| volumetric_increment(&strain[q], p.formulation));
        (viscosity, scale, volumetric)
    });
    let mut state = *committed;
    let (mut work, mut plastic_work) = (0.0, 0.0);
    for q in 0..4 {
        let w = spin[q];
        let scale = 1.0 / (1.0 + 0.25 * w * w);
        let (c, s) = ((1.0 - 0.25 * w * w) * scale, w * scale);
        let start = PointState {
            stress: Voigt::from(rotate(&committed.stress[q], c, s)),
            eq_plastic_strain: committed.eq_plastic_strain[q],
            back_stress: Voigt::from(rotate(&committed.back_stress[q], c, s)),
            temperature: committed.temperature[q],
        };
        let step = point_step(p, &start, &mut strain[q], dt);
        if p.plane_stress() {
            state.thickness[q] = committed.thickness[q] * step.strain_zz.exp();
        }
        let end = &step.state;
        let weight = at_mid.points[q].weight;
        work += weight
            * 0.5
            * (0..4)
                .map(|k| (start.stress[k] + end.stress[k]) * strain[q][k])
                .sum::<f64>();
        // 1/2 (S_n + S_{n+1}) : d eps_p, the rule of the work above (trapezoid_dissipation)
        plastic_work += weight
            * dissipation(
                &start.stress,
                &end.stress,
                &end.back_stress,
                step.plastic_work,
            )
            .map_err(|work| KernelError::NegativePlasticWork { point: q, work })?;
        state.stress[q] = end.stress.into();
        state.back_stress[q] = end.back_stress.into();
        state.eq_plastic_strain[q] = end.eq_plastic_strain;
        state.temperature[q] = end.temperature;
    }
    let at_end = quad4::values(&end, p.formulation, &state.thickness)?;
    let omega_squared = quad4::frequency_bound(&at_end, p.wave_lambda, p.mu, lumped);
    let Some((viscosity, scale, volumetric)) = viscous else {
        return Ok(ElementStep {
            force: forces(&at_end, &state.stress, p.bbar),
            omega_squared,
            state,
            work,
            plastic_work,
            viscous_work: 0.0,
            damping: 1.0,
        });
    };
    let mut loaded = state.stress;
    let (mut viscous_work, mut damping_fraction) = (0.0, 0.0);
    for q in 0..4 {
        let weight = at_mid.points[q].weight;
        let v = viscosity.step(
            &scale,
            volumetric[q],
            dt,
            weight,
            committed.viscous_pressure[q],
        );
        viscous_work += v.work;
        // the most compressed point sets the element's damping
        damping_fraction = f64::max(damping_fraction, v.damping_fraction);
        state.viscous_pressure[q] = v.pressure;
        loaded[q] = loaded_stress(&state.stress[q], v.pressure, p.formulation);
    }
    Ok(ElementStep {
        force: forces(&at_end, &loaded, p.bbar),
        omega_squared: damped_frequency_squared(omega_squared, damping_fraction),
        state,
        work,
        plastic_work,
        viscous_work,
        damping: damping_factor(damping_fraction),
    })
}

impl Full {
    /// The kernel for the Quad4 bodies of `model` from the committed `state`.
    pub fn new(model: &Model, state: &State, masses: &ElementMasses) -> Full {
        let layout = Layout::new(model, 0.0);
        let count = layout.body.len();
        let mut kernel = Full {
            lumped: Vec::with_capacity(count),
            stress: Vec::with_capacity(16 * count),
            back_stress: Vec::with_capacity(16 * count),
            eq_plastic_strain: Vec::with_capacity(4 * count),
            temperature: Vec::with_capacity(4 * count),
            thickness: Vec::with_capacity(4 * count),
            viscosity: None,
            viscous_pressure: vec![0.0; 4 * count],
            element_forces: vec![0.0; 8 * count],
            gather: NodeGather::new(&layout.nodes, state.coordinates.len()),
            layout,
            scaling: None,
            bounds: vec![0.0; count],
            damping: vec![1.0; count],
            tightness: None,
        };
        for &(b, e) in &kernel.layout.origin {
            let committed = &state.bodies[b];
            for p in &committed.points[4 * e..4 * e + 4] {
                kernel.stress.extend(p.stress.iter());
                kernel.back_stress.extend(p.back_stress.iter());
                kernel.eq_plastic_strain.push(p.eq_plastic_strain);
                kernel.temperature.push(p.temperature);
            }
            kernel
                .thickness
                .extend_from_slice(&committed.thickness[4 * e..4 * e + 4]);
            let m = masses.of(model, b, e);
            kernel.lumped.push([m[0], m[1], m[2], m[3]]);
        }
        kernel
    }

    /// The kernel whose stable step is tight (`on`: each element's bound times its ratio to
    /// the exact frequency, `tight`; with `global` the mesh's estimate over them, `global`)
    /// or its elements' bounds (the default).
    pub fn with_tight_step(self, on: bool, global: bool) -> Full {
        let tightness = on.then(|| Tightness::new(self.bounds.len(), global));
        Full { tightness, ..self }
    }

    /// The kernel with the bulk viscosity `viscosity` (None: off). Its damping folds into the
    /// bounds; the tight ratios are taken against the undamped ones (`damping`, at rest
    /// until the first step).
    pub fn with_bulk_viscosity(self, viscosity: Option<BulkViscosity>) -> Full {
        let at_rest = viscosity.map_or(1.0, |v| damping_factor(v.damping_fraction_at_rest()));
        let damping = vec![at_rest; self.bounds.len()];
        Full {
            viscosity,
            damping,
            ..self
        }
    }

    /// The stiffness and lumped masses of element `e` at the nodes `xe` (its exact highest
    /// frequency squared their largest eigenvalue):
    /// the kernel's stiffness from a stress-free state (`tight`).
    fn exact_stiffness(&self, xe: &Nodes, e: usize) -> Option<ElementStiffness> {
        let p = self.parameters(e);
        let fresh = PointsState {
            stress: [[0.0; 4]; 4],
            back_stress: [[0.0; 4]; 4],
            eq_plastic_strain: [0.0; 4],
            viscous_pressure: [0.0; 4],
            ..self.state_of(e)
        };
        let lumped = self.lumped_of(e);
        let h = 1e-7 * shortest_edge(xe);
        let k = stiffness_by_differences(h, |u| {
            element_step(p, (xe, u), &fresh, &lumped, (1.0, None))
                .ok()
                .map(|r| r.force)
        })?;
        Some(ElementStiffness { k, lumped })
    }

    /// The kernel with the mass scaling `rule` (None: off), the elements below its target
    /// on the positions `x` scaled (`masses`: the lumped masses the kernel was made with).
    pub fn with_mass_scaling(
        mut self,
        rule: Option<MassScaling>,
        model: &Model,
        masses: &ElementMasses,
        x: &[[f64; 2]],
    ) -> Full {
        if let Some(rule) = rule {
            let mut scaling = element_scaling(rule, model, &self.layout, masses);
            scaling.scale_at_start(|e| self.frequency(x, e).ok());
            self.scaling = Some(scaling);
        }
        self
    }

    /// The lumped masses of element `e` (scaled by its factor with the mass scaling).
    #[inline(always)]
    fn lumped_of(&self, e: usize) -> [f64; 4] {
        scaled(&self.lumped[e], self.scaling.as_ref().map(|s| s.factor(e)))
    }

    /// The frequency bound squared of element `e` on the positions `x` from the stored
    /// state, with its masses and (at rest: no step yet) the damping of the bulk
    /// viscosity's linear term.
    fn frequency(&self, x: &[[f64; 2]], e: usize) -> Result<f64, ElementFailure> {
        let xe: Nodes = self.layout.nodes[e].map(|n| x[n as usize]);
        let p = self.parameters(e);
        let values = quad4::values(&xe, p.formulation, &self.state_of(e).thickness)
            .map_err(|err| self.layout.failure(e, err))?;
        let w = quad4::frequency_bound(&values, p.wave_lambda, p.mu, &self.lumped_of(e));
        Ok(match &self.viscosity {
            Some(v) => damped_frequency_squared(w, v.damping_fraction_at_rest()),
            None => w,
        })
    }

    /// The element loop of a step: the elements' new states, forces and frequency bounds
    /// (`bounds`), the sums with the largest bound.
    fn step_bounds(
        &mut self,
        x: &[[f64; 2]],
        du: &[f64],
        dt: f64,
    ) -> Result<StepWork, ElementFailure> {
        let reads = Reads {
            layout: &self.layout,
            lumped: &self.lumped,
            scaling: self.scaling.as_ref(),
            viscosity: self.viscosity.as_ref(),
        };
        let count = self.bounds.len();
        let results: Vec<ChunkResult> = (
            self.stress.par_chunks_mut(16 * CHUNK),
            self.back_stress.par_chunks_mut(16 * CHUNK),
            self.eq_plastic_strain.par_chunks_mut(4 * CHUNK),
            self.temperature.par_chunks_mut(4 * CHUNK),
            self.thickness.par_chunks_mut(4 * CHUNK),
            self.viscous_pressure.par_chunks_mut(4 * CHUNK),
            self.element_forces.par_chunks_mut(8 * CHUNK),
            self.bounds.par_chunks_mut(CHUNK),
            self.damping.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .with_max_len(1)
            .enumerate()
            .map(|(k, parts)| {
                let first = k * CHUNK;
                let mut columns = Columns::of(first, parts);
                let elements = first..(first + CHUNK).min(count);
                step_chunk(&reads, &mut columns, elements, (x, du), dt, true)
            })
            .collect();
        fold_chunks(results, &self.layout, self.scaling.as_mut())
    }

    /// The steps of the elements `elements` (ascending, each once) in chunks of `CHUNK`
    /// entries, in parallel, each chunk writing its elements' state, forces and frequency
    /// bounds (into `omega_squared`) where they lie (the arrays `cut` at the chunks' first
    /// elements). The chunk sums are added in chunk order, so a list of all elements is
    /// summed as `step_bounds` sums them, and the bits do not depend on the thread count.
    fn step_subset(
        &mut self,
        elements: &[u32],
        motion: (&[[f64; 2]], &[f64]),
        dt: f64,
        omega_squared: &mut [f64],
    ) -> Result<StepWork, ElementFailure> {
        let reads = Reads {
            layout: &self.layout,
            lumped: &self.lumped,
            scaling: self.scaling.as_ref(),
            viscosity: self.viscosity.as_ref(),
        };
        let starts: Vec<usize> = elements.chunks(CHUNK).map(|c| c[0] as usize).collect();
        let mut parts = (
            cut(&mut self.stress, 16, &starts),
            cut(&mut self.back_stress, 16, &starts),
            cut(&mut self.eq_plastic_strain, 4, &starts),
            cut(&mut self.temperature, 4, &starts),
            cut(&mut self.thickness, 4, &starts),
            cut(&mut self.viscous_pressure, 4, &starts),
            cut(&mut self.element_forces, 8, &starts),
            cut(omega_squared, 1, &starts),
            cut(&mut self.damping, 1, &starts),
        );
        let columns: Vec<Columns> = starts
            .iter()
            .map_while(|first| {
                let (a, b, c, d, e, f, g, h, i) = &mut parts;
                let next = (
                    a.next()?,
                    b.next()?,
                    c.next()?,
                    d.next()?,
                    e.next()?,
                    f.next()?,
                    g.next()?,
                    h.next()?,
                    i.next()?,
                );
                Some(Columns::of(*first, next))
            })
            .collect();
        let results: Vec<ChunkResult> = columns
            .into_par_iter()
            .zip(elements.par_chunks(CHUNK))
            .with_max_len(1)
            .map(|(mut columns, list)| {
                let list = list.iter().map(|e| *e as usize);
                step_chunk(&reads, &mut columns, list, motion, dt, false)
            })
            .collect();
        fold_chunks(results, &self.layout, None)
    }

    fn state_of(&self, e: usize) -> PointsState {
        PointsState {
            stress: std::array::from_fn(|q| {
                std::array::from_fn(|c| self.stress[16 * e + 4 * q + c])
            }),
            back_stress: std::array::from_fn(|q| {
                std::array::from_fn(|c| self.back_stress[16 * e + 4 * q + c])
            }),
            eq_plastic_strain: std::array::from_fn(|q| self.eq_plastic_strain[4 * e + q]),
            temperature: std::array::from_fn(|q| self.temperature[4 * e + q]),
            thickness: std::array::from_fn(|q| self.thickness[4 * e + q]),
            viscous_pressure: std::array::from_fn(|q| self.viscous_pressure[4 * e + q]),
        }
    }

    /// The stress the forces of element `e` see in `state` (the stored viscous pressure taken
    /// off when the bulk viscosity is on).
    fn loaded(&self, e: usize, state: &PointsState) -> [[f64; 4]; 4] {
        match self.viscosity {
            Some(_) => std::array::from_fn(|q| {
                loaded_stress(
                    &state.stress[q],
                    state.viscous_pressure[q],
                    self.parameters(e).formulation,
                )
            }),
            None => state.stress,
        }
    }

    fn parameters(&self, e: usize) -> &super::BodyParameters {
        &self.layout.bodies[self.layout.body[e] as usize]
    }
}

impl PartialKernel for Full {
    fn element_nodes(&self) -> &[[u32; 4]] {
        &self.layout.nodes
    }

    fn frequency_of(&self, x: &[[f64; 2]], e: usize) -> Result<f64, ElementFailure> {
        let bound = self.frequency(x, e)?;
        Ok(match &self.tightness {
            Some(tight) => {
                let nodes = self.layout.nodes[e].map(|n| x[n as usize]);
                bound * tight.ratio_for(e, bound, || self.exact_stiffness(&nodes, e))
            }
            None => bound,
        })
    }

    fn step_elements(
        &mut self,
        elements: &[u32],
        (x, du): (&[[f64; 2]], &[f64]),
        dt: f64,
        omega_squared: &mut [f64],
    ) -> Result<StepWork, ElementFailure> {
        let mut total = self.step_subset(elements, (x, du), dt, omega_squared)?;
        if let Some(mut tight) = self.tightness.take() {
            let end = |e: usize| end_nodes(self.layout.nodes[e], x, du);
            (total.omega_squared, total.critical_element) =
                tight.apply_subset(elements, omega_squared, |e| {
                    self.exact_stiffness(&end(e), e)
                });
            self.tightness = Some(tight);
        }
        Ok(total)
    }

    fn gather_nodes(&self, nodes: &[u32], force: &mut [f64]) {
        self.gather.gather_nodes(nodes, &self.element_forces, force);
    }
}

/// What an element loop of the kernel reads besides the element arrays.
struct Reads<'a> {
    layout: &'a Layout,
    lumped: &'a [[f64; 4]],
    scaling: Option<&'a ElementScaling>,
    viscosity: Option<&'a BulkViscosity>,
}

/// The element arrays of one chunk of an element loop: element `first + i` at entry i.
struct Columns<'a> {
    first: usize,
    stress: &'a mut [f64],
    back: &'a mut [f64],
    eps_p: &'a mut [f64],
    temperature: &'a mut [f64],
    thickness: &'a mut [f64],
    viscous: &'a mut [f64],
    forces: &'a mut [f64],
    /// The frequency bounds the loop writes.
    bounds: &'a mut [f64],
    damping: &'a mut [f64],
}

/// The parts of a chunk's columns, in the order of `Columns`' fields after `first`.
type Parts<'a> = (
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
    &'a mut [f64],
);

impl<'a> Columns<'a> {
    fn of(first: usize, parts: Parts<'a>) -> Columns<'a> {
        let (stress, back, eps_p, temperature, thickness, viscous, forces, bounds, damping) = parts;
        Columns {
            first,
            stress,
            back,
            eps_p,
            temperature,
            thickness,
            viscous,
            forces,
            bounds,
            damping,
        }
    }

    /// Element e's committed state.
    #[inline(always)]
    fn state(&self, e: usize) -> PointsState {
        let i = e - self.first;
        PointsState {
            stress: std::array::from_fn(|q| {
                std::array::from_fn(|c| self.stress[16 * i + 4 * q + c])
            }),
            back_stress: std::array::from_fn(|q| {
                std::array::from_fn(|c| self.back[16 * i + 4 * q + c])
            }),
            eq_plastic_strain: std::array::from_fn(|q| self.eps_p[4 * i + q]),
            temperature: std::array::from_fn(|q| self.temperature[4 * i + q]),
            thickness: std::array::from_fn(|q| self.thickness[4 * i + q]),
            viscous_pressure: std::array::from_fn(|q| self.viscous[4 * i + q]),
        }
    }

    /// Writes element e's step `r` with its frequency bound `omega_squared`.
    #[inline(always)]
    fn store(&mut self, e: usize, r: &ElementStep, omega_squared: f64) {
        let i = e - self.first;
        self.bounds[i] = omega_squared;
        self.damping[i] = r.damping;
        for q in 0..4 {
            self.stress[16 * i + 4 * q..16 * i + 4 * q + 4].copy_from_slice(&r.state.stress[q]);
            self.back[16 * i + 4 * q..16 * i + 4 * q + 4].copy_from_slice(&r.state.back_stress[q]);
        }
        self.eps_p[4 * i..4 * i + 4].copy_from_slice(&r.state.eq_plastic_strain);
        self.temperature[4 * i..4 * i + 4].copy_from_slice(&r.state.temperature);
        self.thickness[4 * i..4 * i + 4].copy_from_slice(&r.state.thickness);
        self.viscous[4 * i..4 * i + 4].copy_from_slice(&r.state.viscous_pressure);
        self.forces[8 * i..8 * i + 8].copy_from_slice(&r.force);
    }
}

/// Steps the elements `elements` of the chunk `columns` from the positions and increments
/// `(x, du)`: their sums in element order, the first that failed, and (with `grow`, under
/// the mass scaling) the elements whose mass factor grew.
#[inline(always)]
fn step_chunk(
    reads: &Reads,
    columns: &mut Columns,
    elements: impl Iterator<Item = usize>,
    (x, du): (&[[f64; 2]], &[f64]),
    dt: f64,
    grow: bool,
) -> ChunkResult {
    let layout = reads.layout;
    let mut sums = StepWork::default();
    let mut grown = Vec::new();
    for e in elements {
        let (xe, ue) = element_motion(layout.nodes[e], x, du);
        let p = &layout.bodies[layout.body[e] as usize];
        let lumped = scaled(&reads.lumped[e], reads.scaling.map(|s| s.factor(e)));
        let committed = columns.state(e);
        let step = (dt, reads.viscosity);
        let r = match element_step(p, (&xe, &ue), &committed, &lumped, step) {
            Ok(r) => r,
            Err(err) => return (sums, Some((e, err)), grown),
        };
        let scaling = reads.scaling.filter(|_| grow);
        let omega_squared = kept_bound(scaling, e, r.omega_squared, &mut grown);
        sums.observe(omega_squared, e);
        columns.store(e, &r, omega_squared);
        sums.internal += r.work;
        sums.plastic += r.plastic_work;
        sums.book(p.model_body, r.work, r.plastic_work);
        sums.viscous += r.viscous_work;
    }
    (sums, None, grown)
}

impl ExplicitKernel for Full {
    fn elements(&self) -> usize {
        self.layout.body.len()
    }

    fn locate(&self, element: usize) -> (usize, usize) {
        self.layout.origin[element]
    }

    fn internal_force(&mut self, x: &[[f64; 2]], force: &mut [f64]) -> Result<(), ElementFailure> {
        for e in 0..self.elements() {
            let xe: Nodes = self.layout.nodes[e].map(|n| x[n as usize]);
            let state = self.state_of(e);
            let p = self.parameters(e);
            let values = quad4::values(&xe, p.formulation, &state.thickness)
                .map_err(|err| self.layout.failure(e, err))?;
            let f = forces(&values, &self.loaded(e, &state), p.bbar);
            self.element_forces[8 * e..8 * e + 8].copy_from_slice(&f);
        }
        self.gather.gather(&self.element_forces, force);
        Ok(())
    }

    fn stable_step(&self, x: &[[f64; 2]]) -> Result<StableStep, ElementFailure> {
        kernel_stable_step(
            &self.layout,
            x,
            (self.tightness.as_ref(), &self.damping),
            |e| self.frequency(x, e),
            |xe, e| self.exact_stiffness(xe, e),
        )
    }

    fn step(
        &mut self,
        x: &[[f64; 2]],
        du: &[f64],
        dt: f64,
        force: &mut [f64],
    ) -> Result<StepWork, ElementFailure> {
        let mut total = self.step_bounds(x, du, dt)?;
        if let Some(mut tight) = self.tightness.take() {
            let end = |e: usize| end_nodes(self.layout.nodes[e], x, du);
            (total.omega_squared, total.critical_element) =
                tight.apply(&self.bounds, &self.damping, &self.layout.nodes, |e| {
                    self.exact_stiffness(&end(e), e)
                });
            self.tightness = Some(tight);
        }
        self.gather.gather(&self.element_forces, force);
        Ok(total)
    }

    fn write_points(&self, _model: &Model, state: &mut State) {
        for (k, &(b, e)) in self.layout.origin.iter().enumerate() {
            let s = self.state_of(k);
            let bs = &mut state.bodies[b];
            for q in 0..4 {
                bs.points[4 * e + q] = PointState {
                    stress: Voigt::from(s.stress[q]),
                    eq_plastic_strain: s.eq_plastic_strain[q],
                    back_stress: Voigt::from(s.back_stress[q]),
                    temperature: s.temperature[q],
                };
                bs.thickness[4 * e + q] = s.thickness[q];
            }
        }
    }

    fn point_probe(&self, model: &Model, probe: &Probe) -> Option<f64> {
        let scalars = [&self.eq_plastic_strain[..], &self.temperature[..]];
        point_statistic(&self.layout, model, probe, (4, scalars), |e, q| {
            PointState {
                stress: Voigt::from(std::array::from_fn(|k| self.stress[16 * e + 4 * q + k])),
                eq_plastic_strain: self.eq_plastic_strain[4 * e + q],
                back_stress: Voigt::from(std::array::from_fn(|k| {
                    self.back_stress[16 * e + 4 * q + k]
                })),
                temperature: self.temperature[4 * e + q],
            }
        })
    }

    fn eq_plastic_strain(&self) -> Vec<f64> {
        self.eq_plastic_strain.clone()
    }

    fn viscous_pressure(&self) -> &[f64] {
        &self.viscous_pressure
    }

    fn restore_viscous_pressure(&mut self, values: &[f64]) {
        self.viscous_pressure.copy_from_slice(values);
    }

    fn mass_scaling(&self) -> Option<&ElementScaling> {
        self.scaling.as_ref()
    }

    fn tightness(&self) -> Option<&Tightness> {
        self.tightness.as_ref()
    }

    fn restore_tightness(&mut self, tightness: Tightness) {
        if self.tightness.is_some() {
            self.tightness = Some(tightness);
        }
    }

    fn mass_scaling_mut(&mut self) -> Option<&mut ElementScaling> {
        self.scaling.as_mut()
    }

    fn partial(&mut self) -> Option<&mut dyn PartialKernel> {
        Some(self)
    }
}

/// An element's lumped masses `lumped` times its mass factor (as they are without one).
#[inline(always)]
fn scaled(lumped: &[f64; 4], factor: Option<f64>) -> [f64; 4] {
    match factor {
        Some(s) => lumped.map(|m| m * s),
        None => *lumped,
    }
}
