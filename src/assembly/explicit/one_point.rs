//! The explicit fast path: the one-point Quad4 of `element::quad4_one_point` over element
//! data as structure of arrays, internal forces in parallel (docs/theory.md, "Reduced
//! explicit Quad4"). The element's kinematics, hourglass control and forces are the
//! kernel's; here the material updates the rotated stress between them.
//!
//! Legend (one element; see `element::quad4_one_point` for the kinematics)
//! ```text
//! sigma      sigma_{n+1} = material(R sigma_n R^T, d)   (back stress rotated alike)
//! W_int      t A_mid 1/2 (R sigma_n R^T + sigma_{n+1}) . d;  W_hg = 1/2 (R Q_n + Q_{n+1}) . q
//! q          the bulk viscosity's pressure from tr d / dt (by option; element::bulk_viscosity),
//!            rho, c_d, L_e on the mid configuration; the forces see sigma - q I
//! W_visc     -t A_mid 1/2 (q_n + q_{n+1}) tr d
//! s          the element's mass factor of the mass scaling (by option; 1 without it): its
//!            lumped masses are s m_a in the frequency bound and the viscous density, and
//!            an element whose bound is below the target gets a larger s (mass_scaling.rs)
//! ```
//! Parallel and deterministic: elements are processed in fixed chunks (rayon), each writes
//! its own 8 force entries; nodes then gather their elements' entries in element order, and
//! the chunk sums of the work are added in chunk order. The bits do not depend on the thread
//! count.

use super::tight::{
    ElementStiffness, Tightness, end_nodes, shortest_edge, stiffness_by_differences,
};
use super::{
    BodyParameters, CHUNK, ChunkResult, ExplicitKernel, Layout, NodeGather, PartialKernel,
    StepWork, cut, element_motion, element_scaling, fold_chunks, kept_bound, kernel_stable_step,
    point_statistic, point_step,
};
use crate::assembly::mass_scaling::ElementScaling;
use crate::assembly::{ElementFailure, ElementMasses, StableStep, State};
use crate::element::bulk_viscosity::{
    BulkViscosity, ElementScale, damped_frequency_squared, damping_factor, loaded_stress,
    volumetric_increment,
};
use crate::element::mass_scaling::MassScaling;
use crate::element::quad4_one_point::{self as one_point, BoundShape, Nodes, Section, rotate};
use crate::element::{KernelError, Voigt};
use crate::material::{PointState, dissipation};
use crate::scene::Model;
use crate::scene::model::Probe;
use rayon::prelude::*;

/// The committed state of one element as the kernel reads it.
#[derive(Debug, Clone, Copy)]
pub struct ElementState {
    /// Cauchy stress [xx yy zz xy].
    pub stress: [f64; 4],
    pub back_stress: [f64; 4],
    pub eq_plastic_strain: f64,
    /// Temperature (0 for materials that carry none).
    pub temperature: f64,
    /// Current thickness (plane stress), else 1.
    pub thickness: f64,
    /// Hourglass forces Q [x y].
    pub hourglass: [f64; 2],
    /// The bulk viscosity's pressure of the step that ended here (0 without it).
    pub viscous_pressure: f64,
}

/// The new state of one element after a step, with its forces and work.
#[derive(Debug, Clone, Copy)]
pub struct ElementStep {
    pub state: ElementState,
    /// Internal force [f1x f1y ... f4x f4y] on the end configuration.
    pub force: [f64; 8],
    /// Work of the stresses (hourglass excluded).
    pub work: f64,
    pub plastic_work: f64,
    pub hourglass_work: f64,
    /// Work of the bulk viscosity's pressure.
    pub viscous_work: f64,
    /// The bound of the element's highest frequency squared on the end configuration (with
    /// the bulk viscosity: the damped bound, `damped_frequency_squared`).
    pub omega_squared: f64,
    /// The undamped bound over the damped one (`damping_factor`; 1 without the bulk
    /// viscosity).
    pub damping: f64,
}

/// What the one-point kernel knows of an element's mass: the smallest of its lumped nodal
/// masses (the stable-step bound) and their sum (its density, for the bulk viscosity).
#[derive(Debug, Clone, Copy)]
struct ElementMass {
    smallest: f64,
    total: f64,
}

impl ElementMass {
    /// The element's masses times the factor `factor`.
    #[inline(always)]
    fn scaled(self, factor: f64) -> ElementMass {
        ElementMass {
            smallest: self.smallest * factor,
            total: self.total * factor,
        }
    }
}

/// One element over one step of length dt: positions x at the start, increment u (`(x, u)`),
/// with the bulk viscosity `viscosity` when on (see the legend).
#[inline(always)]
fn element_step(
    p: &BodyParameters,
    (x, u): (&Nodes, &Nodes),
    committed: &ElementState,
    mass: ElementMass,
    (dt, viscosity): (f64, Option<&BulkViscosity>),
) -> Result<ElementStep, KernelError> {
    let t = committed.thickness;
    let section = if p.axisymmetric() {
        Section::Axisymmetric
    } else {
        Section::Plane { thickness: t }
    };
    let step = one_point::increment(x, u, section)?;
    let (c, s) = (step.cos, step.sin);
    let start = PointState {
        stress: Voigt::from(rotate(&committed.stress, c, s)),
        eq_plastic_strain: committed.eq_plastic_strain,
        back_stress: Voigt::from(rotate(&committed.back_stress, c, s)),
        temperature: committed.temperature,
    };
    let mut strain = step.strain;
    // the volumetric increment the viscous pressure follows (before plane stress writes the
    // thickness strain into it)
    let volumetric = volumetric_increment(&strain, p.formulation);
    let point = point_step(p, &start, &mut strain, dt);
    let thickness = if p.plane_stress() {
        t * point.strain_zz.exp()
    } else {
        t
    };
    let after = &point.state;
    let volume = step.gradient.area * section.weight(&step.mid);
    let work = volume
        * 0.5
        * (0..4)
            .map(|k| (start.stress[k] + after.stress[k]) * strain[k])
            .sum::<f64>();
    let hourglass = one_point::hourglass(
        &step,
        u,
        &committed.hourglass,
        p.hourglass_modulus,
        section.weight(&step.mid),
    );
    let viscous = viscosity.map(|viscosity| {
        let scale = ElementScale::new(&step.mid, mass.total, volume, p.wave_modulus);
        viscosity.step(&scale, volumetric, dt, volume, committed.viscous_pressure)
    });
    let state = ElementState {
        stress: after.stress.into(),
        back_stress: after.back_stress.into(),
        eq_plastic_strain: after.eq_plastic_strain,
        temperature: after.temperature,
        thickness,
        hourglass: hourglass.forces,
        viscous_pressure: viscous.map_or(committed.viscous_pressure, |v| v.pressure),
    };
    let section = match section {
        Section::Plane { .. } => Section::Plane {
            thickness: state.thickness,
        },
        axisymmetric => axisymmetric,
    };
    let end = match viscous {
        Some(v) => {
            let loaded = loaded_stress(&state.stress, v.pressure, p.formulation);
            one_point::force(&step.end, &loaded, section, &state.hourglass)?
        }
        None => one_point::force(&step.end, &state.stress, section, &state.hourglass)?,
    };
    let shape = BoundShape {
        gradient: &end.gradient,
        gamma: &end.gamma,
        volume: end.gradient.area * section.weight(&step.end),
        hoop_radius: p
            .axisymmetric()
            .then(|| one_point::centroid_radius(&step.end)),
    };
    let omega_squared =
        one_point::frequency_bound(shape, p.wave_modulus, p.hourglass_modulus, mass.smallest);
    let (omega_squared, viscous_work, damping) = match viscous {
        Some(v) => (
            damped_frequency_squared(omega_squared, v.damping_fraction),
            v.work,
            damping_factor(v.damping_fraction),
        ),
        None => (omega_squared, 0.0, 1.0),
    };
    // 1/2 (S_n + S_{n+1}) : d eps_p, the rule of the work above (trapezoid_dissipation)
    let plastic_work = volume
        * dissipation(
            &start.stress,
            &after.stress,
            &after.back_stress,
            point.plastic_work,
        )
        .map_err(|work| KernelError::NegativePlasticWork { point: 0, work })?;
    Ok(ElementStep {
        state,
        force: end.force,
        work,
        plastic_work,
        hourglass_work: hourglass.work,
        viscous_work,
        omega_squared,
        damping,
    })
}

/// Element data of all Quad4 bodies as flat arrays (element-major, kernel element index
/// over the bodies in order).
pub struct Reduced {
    layout: Layout,
    /// The smallest and the total lumped nodal mass of each element.
    mass: Vec<ElementMass>,
    /// Cauchy stress, 4 per element [xx yy zz xy].
    pub stress: Vec<f64>,
    /// Back stress, 4 per element.
    pub back_stress: Vec<f64>,
    pub eq_plastic_strain: Vec<f64>,
    /// Temperature per element (0 for materials that carry none).
    pub temperature: Vec<f64>,
    /// Current thickness per element (plane stress), else 1.
    pub thickness: Vec<f64>,
    /// Hourglass forces Q, 2 per element.
    pub hourglass: Vec<f64>,
    /// The bulk viscosity (None: off) and its pressure per element.
    viscosity: Option<BulkViscosity>,
    viscous_pressure: Vec<f64>,
    /// Element forces of the last evaluation, 8 per element.
    element_forces: Vec<f64>,
    gather: NodeGather,
    /// Accumulated hourglass work.
    pub hourglass_energy: f64,
    /// The mass scaling (None: off).
    scaling: Option<ElementScaling>,
    /// The lumped mass at the four nodes of each element (unscaled), for the exact frequency.
    nodal: Vec<[f64; 4]>,
    /// Each element's frequency bound of the last step, and the ratios that make them tight
    /// (`tight`; None: the bounds stand, the default).
    bounds: Vec<f64>,
    /// Each element's `ElementStep::damping` of the last step (the bulk viscosity's at rest
    /// before the first): the tight ratios are taken against the undamped bounds.
    damping: Vec<f64>,
    tightness: Option<Tightness>,
}

impl Reduced {
    /// The kernel for the Quad4 bodies of `model` (the scene refuses rods with it),
    /// starting from the committed `state`; `kappa` is the hourglass coefficient.
    pub fn new(model: &Model, state: &State, kappa: f64, masses: &ElementMasses) -> Reduced {
        let layout = Layout::new(model, kappa);
        let count = layout.body.len();
        let (mut stress, mut back_stress) =
            (Vec::with_capacity(4 * count), Vec::with_capacity(4 * count));
        let (mut eq_plastic_strain, mut temperature, mut thickness, mut mass) = (
            Vec::with_capacity(count),
            Vec::with_capacity(count),
            Vec::with_capacity(count),
            Vec::with_capacity(count),
        );
        let mut nodal_masses = Vec::with_capacity(count);
        for &(b, e) in &layout.origin {
            let committed = &state.bodies[b];
            let p = &committed.points[4 * e];
            stress.extend(p.stress.iter());
            back_stress.extend(p.back_stress.iter());
            eq_plastic_strain.push(p.eq_plastic_strain);
            temperature.push(p.temperature);
            thickness.push(committed.thickness[4 * e]);
            let nodal = masses.of(model, b, e);
            mass.push(ElementMass {
                smallest: nodal.iter().copied().fold(f64::INFINITY, f64::min),
                total: nodal.iter().sum(),
            });
            nodal_masses.push([nodal[0], nodal[1], nodal[2], nodal[3]]);
        }
        let gather = NodeGather::new(&layout.nodes, state.coordinates.len());
        Reduced {
            layout,
            mass,
            stress,
            back_stress,
            eq_plastic_strain,
            temperature,
            thickness,
            hourglass: vec![0.0; 2 * count],
            viscosity: None,
            viscous_pressure: vec![0.0; count],
            element_forces: vec![0.0; 8 * count],
            gather,
            hourglass_energy: 0.0,
            scaling: None,
            nodal: nodal_masses,
            bounds: vec![0.0; count],
            damping: vec![1.0; count],
            tightness: None,
        }
    }

    /// The kernel whose stable step is tight (`on`: each element's bound times its ratio to
    /// the exact frequency, `tight`; with `global` the mesh's estimate over them, `global`)
    /// or its elements' bounds (the default).
    pub fn with_tight_step(self, on: bool, global: bool) -> Reduced {
        let tightness = on.then(|| Tightness::new(self.bounds.len(), global));
        Reduced { tightness, ..self }
    }

    /// The kernel with the bulk viscosity `viscosity` (None: off). Its damping folds into the
    /// bounds; the tight ratios are taken against the undamped ones (`damping`, at rest
    /// until the first step).
    pub fn with_bulk_viscosity(self, viscosity: Option<BulkViscosity>) -> Reduced {
        let at_rest = viscosity.map_or(1.0, |v| damping_factor(v.damping_fraction_at_rest()));
        let damping = vec![at_rest; self.bounds.len()];
        Reduced {
            viscosity,
            damping,
            ..self
        }
    }

    /// The stiffness and lumped masses of element `e` at the nodes `xe` (its exact highest
    /// frequency squared their largest eigenvalue):
    /// the kernel's stiffness (hourglass and hoop included) from a stress-free state
    /// (`tight`).
    fn exact_stiffness(&self, xe: &Nodes, e: usize) -> Option<ElementStiffness> {
        let p = &self.layout.bodies[self.layout.body[e] as usize];
        let fresh = ElementState {
            stress: [0.0; 4],
            back_stress: [0.0; 4],
            eq_plastic_strain: 0.0,
            hourglass: [0.0; 2],
            viscous_pressure: 0.0,
            ..self.state_of(e)
        };
        let mass = self.mass_of(e);
        let factor = self.scaling.as_ref().map_or(1.0, |s| s.factor(e));
        let lumped = self.nodal[e].map(|m| m * factor);
        let h = 1e-7 * shortest_edge(xe);
        let k = stiffness_by_differences(h, |u| {
            element_step(p, (xe, u), &fresh, mass, (1.0, None))
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
    ) -> Reduced {
        if let Some(rule) = rule {
            let mut scaling = element_scaling(rule, model, &self.layout, masses);
            scaling.scale_at_start(|e| self.frequency(x, e).ok());
            self.scaling = Some(scaling);
        }
        self
    }

    /// The masses of element `e` (scaled by its factor with the mass scaling).
    #[inline(always)]
    fn mass_of(&self, e: usize) -> ElementMass {
        match &self.scaling {
            Some(scaling) => self.mass[e].scaled(scaling.factor(e)),
            None => self.mass[e],
        }
    }

    /// The frequency bound squared of element `e` on the positions `x` from the stored
    /// state, with its masses and (at rest: no step yet) the damping of the bulk
    /// viscosity's linear term.
    fn frequency(&self, x: &[[f64; 2]], e: usize) -> Result<f64, ElementFailure> {
        let xe: Nodes = self.layout.nodes[e].map(|n| x[n as usize]);
        let state = self.state_of(e);
        let p = &self.layout.bodies[self.layout.body[e] as usize];
        let section = self.section(e, &state);
        let end = one_point::force(&xe, &state.stress, section, &state.hourglass)
            .map_err(|err| self.layout.failure(e, err))?;
        let shape = BoundShape {
            gradient: &end.gradient,
            gamma: &end.gamma,
            volume: end.gradient.area * section.weight(&xe),
            hoop_radius: p.axisymmetric().then(|| one_point::centroid_radius(&xe)),
        };
        let smallest = self.mass_of(e).smallest;
        let omega_squared =
            one_point::frequency_bound(shape, p.wave_modulus, p.hourglass_modulus, smallest);
        Ok(match &self.viscosity {
            Some(v) => damped_frequency_squared(omega_squared, v.damping_fraction_at_rest()),
            None => omega_squared,
        })
    }

    /// The stress the forces of element `e` see in `state` (the stored viscous pressure taken
    /// off when the bulk viscosity is on).
    fn loaded(&self, e: usize, state: &ElementState) -> [f64; 4] {
        match self.viscosity {
            Some(_) => {
                let p = &self.layout.bodies[self.layout.body[e] as usize];
                loaded_stress(&state.stress, state.viscous_pressure, p.formulation)
            }
            None => state.stress,
        }
    }

    /// The section of element `e` in the state `state`.
    fn section(&self, e: usize, state: &ElementState) -> Section {
        if self.layout.bodies[self.layout.body[e] as usize].axisymmetric() {
            Section::Axisymmetric
        } else {
            Section::Plane {
                thickness: state.thickness,
            }
        }
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
            mass: &self.mass,
            scaling: self.scaling.as_ref(),
            viscosity: self.viscosity.as_ref(),
        };
        let count = self.eq_plastic_strain.len();
        let results: Vec<ChunkResult> = (
            self.stress.par_chunks_mut(4 * CHUNK),
            self.back_stress.par_chunks_mut(4 * CHUNK),
            self.eq_plastic_strain.par_chunks_mut(CHUNK),
            self.temperature.par_chunks_mut(CHUNK),
            self.thickness.par_chunks_mut(CHUNK),
            self.hourglass.par_chunks_mut(2 * CHUNK),
            self.viscous_pressure.par_chunks_mut(CHUNK),
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
    /// bounds (into `omega_squared`) where they lie: the arrays are cut at the chunks' first
    /// elements. The chunk sums are added in chunk order, so a list of all elements is
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
            mass: &self.mass,
            scaling: self.scaling.as_ref(),
            viscosity: self.viscosity.as_ref(),
        };
        let starts: Vec<usize> = elements.chunks(CHUNK).map(|c| c[0] as usize).collect();
        let mut parts = (
            cut(&mut self.stress, 4, &starts),
            cut(&mut self.back_stress, 4, &starts),
            cut(&mut self.eq_plastic_strain, 1, &starts),
            cut(&mut self.temperature, 1, &starts),
            cut(&mut self.thickness, 1, &starts),
            cut(&mut self.hourglass, 2, &starts),
            cut(&mut self.viscous_pressure, 1, &starts),
            cut(&mut self.element_forces, 8, &starts),
            cut(omega_squared, 1, &starts),
            cut(&mut self.damping, 1, &starts),
        );
        let columns: Vec<Columns> = starts
            .iter()
            .map_while(|first| {
                let (a, b, c, d, e, f, g, h, i, j) = &mut parts;
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
                    j.next()?,
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

    fn state_of(&self, e: usize) -> ElementState {
        ElementState {
            stress: std::array::from_fn(|k| self.stress[4 * e + k]),
            back_stress: std::array::from_fn(|k| self.back_stress[4 * e + k]),
            eq_plastic_strain: self.eq_plastic_strain[e],
            temperature: self.temperature[e],
            thickness: self.thickness[e],
            hourglass: [self.hourglass[2 * e], self.hourglass[2 * e + 1]],
            viscous_pressure: self.viscous_pressure[e],
        }
    }
}

/// What an element loop of the kernel reads besides the element arrays.
struct Reads<'a> {
    layout: &'a Layout,
    mass: &'a [ElementMass],
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
    hourglass: &'a mut [f64],
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
    &'a mut [f64],
);

impl<'a> Columns<'a> {
    fn of(first: usize, parts: Parts<'a>) -> Columns<'a> {
        let (
            stress,
            back,
            eps_p,
            temperature,
            thickness,
            hourglass,
            viscous,
            forces,
            bounds,
            damping,
        ) = parts;
        Columns {
            first,
            stress,
            back,
            eps_p,
            temperature,
            thickness,
            hourglass,
            viscous,
            forces,
            bounds,
            damping,
        }
    }

    /// Element e's committed state.
    #[inline(always)]
    fn state(&self, e: usize) -> ElementState {
        let i = e - self.first;
        ElementState {
            stress: std::array::from_fn(|c| self.stress[4 * i + c]),
            back_stress: std::array::from_fn(|c| self.back[4 * i + c]),
            eq_plastic_strain: self.eps_p[i],
            temperature: self.temperature[i],
            thickness: self.thickness[i],
            hourglass: [self.hourglass[2 * i], self.hourglass[2 * i + 1]],
            viscous_pressure: self.viscous[i],
        }
    }

    /// Writes element e's step `r` with its frequency bound `omega_squared`.
    #[inline(always)]
    fn store(&mut self, e: usize, r: &ElementStep, omega_squared: f64) {
        let i = e - self.first;
        self.bounds[i] = omega_squared;
        self.damping[i] = r.damping;
        self.stress[4 * i..4 * i + 4].copy_from_slice(&r.state.stress);
        self.back[4 * i..4 * i + 4].copy_from_slice(&r.state.back_stress);
        self.eps_p[i] = r.state.eq_plastic_strain;
        self.temperature[i] = r.state.temperature;
        self.thickness[i] = r.state.thickness;
        self.hourglass[2 * i..2 * i + 2].copy_from_slice(&r.state.hourglass);
        self.viscous[i] = r.state.viscous_pressure;
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
        let mass = match reads.scaling {
            Some(scaling) => reads.mass[e].scaled(scaling.factor(e)),
            None => reads.mass[e],
        };
        let committed = columns.state(e);
        let r = match element_step(p, (&xe, &ue), &committed, mass, (dt, reads.viscosity)) {
            Ok(r) => r,
            Err(err) => return (sums, Some((e, err)), grown),
        };
        let scaling = reads.scaling.filter(|_| grow);
        let omega_squared = kept_bound(scaling, e, r.omega_squared, &mut grown);
        sums.observe(omega_squared, e);
        columns.store(e, &r, omega_squared);
        sums.internal += r.work + r.hourglass_work;
        sums.plastic += r.plastic_work;
        sums.book(p.model_body, r.work + r.hourglass_work, r.plastic_work);
        sums.hourglass += r.hourglass_work;
        sums.viscous += r.viscous_work;
    }
    (sums, None, grown)
}

impl ExplicitKernel for Reduced {
    fn elements(&self) -> usize {
        self.layout.body.len()
    }

    fn locate(&self, element: usize) -> (usize, usize) {
        self.layout.origin[element]
    }

    fn internal_force(&mut self, x: &[[f64; 2]], force: &mut [f64]) -> Result<(), ElementFailure> {
        let mut forces = std::mem::take(&mut self.element_forces);
        let this = &*self;
        let error = forces
            .par_chunks_mut(8 * CHUNK)
            .enumerate()
            .map(|(k, chunk)| {
                for (i, f) in chunk.chunks_exact_mut(8).enumerate() {
                    let e = k * CHUNK + i;
                    let xe: Nodes = this.layout.nodes[e].map(|n| x[n as usize]);
                    let state = this.state_of(e);
                    let section = this.section(e, &state);
                    let stress = this.loaded(e, &state);
                    match one_point::force(&xe, &stress, section, &state.hourglass) {
                        Ok(v) => f.copy_from_slice(&v.force),
                        Err(err) => return Some((e, err)),
                    }
                }
                None
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .next();
        self.element_forces = forces;
        if let Some((e, err)) = error {
            return Err(self.layout.failure(e, err));
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
        self.hourglass_energy += total.hourglass;
        Ok(total)
    }

    fn write_points(&self, _model: &Model, state: &mut State) {
        let this = self;
        let mut start = 0;
        while start < self.layout.origin.len() {
            let b = self.layout.origin[start].0;
            let count = self.layout.origin[start..]
                .iter()
                .take_while(|(body, _)| *body == b)
                .count();
            let bs = &mut state.bodies[b];
            bs.points
                .par_chunks_mut(4)
                .zip(bs.thickness.par_chunks_mut(4))
                .enumerate()
                .for_each(|(e, (points, thickness))| {
                    let s = this.state_of(start + e);
                    let point = PointState {
                        stress: Voigt::from(s.stress),
                        eq_plastic_strain: s.eq_plastic_strain,
                        back_stress: Voigt::from(s.back_stress),
                        temperature: s.temperature,
                    };
                    points.fill(point);
                    thickness.fill(s.thickness);
                });
            start += count;
        }
    }

    fn hourglass_state(&self) -> Option<(Vec<f64>, f64)> {
        Some((self.hourglass.clone(), self.hourglass_energy))
    }

    fn restore_hourglass_state(&mut self, forces: Vec<f64>, work: f64) {
        self.hourglass = forces;
        self.hourglass_energy = work;
    }

    fn hourglass_energy(&self) -> Option<f64> {
        Some(self.hourglass_energy)
    }

    fn viscous_pressure(&self) -> &[f64] {
        &self.viscous_pressure
    }

    fn restore_viscous_pressure(&mut self, values: &[f64]) {
        self.viscous_pressure.copy_from_slice(values);
    }

    fn point_probe(&self, model: &Model, probe: &Probe) -> Option<f64> {
        let scalars = [&self.eq_plastic_strain[..], &self.temperature[..]];
        point_statistic(&self.layout, model, probe, (1, scalars), |e, _| {
            PointState {
                stress: Voigt::from(std::array::from_fn(|k| self.stress[4 * e + k])),
                eq_plastic_strain: self.eq_plastic_strain[e],
                back_stress: Voigt::from(std::array::from_fn(|k| self.back_stress[4 * e + k])),
                temperature: self.temperature[e],
            }
        })
    }

    fn eq_plastic_strain(&self) -> Vec<f64> {
        self.eq_plastic_strain.clone()
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

impl PartialKernel for Reduced {
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
        self.hourglass_energy += total.hourglass;
        Ok(total)
    }

    fn gather_nodes(&self, nodes: &[u32], force: &mut [f64]) {
        self.gather.gather_nodes(nodes, &self.element_forces, force);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Formulation;
    use crate::material::{Elastic, Material};

    fn parameters() -> BodyParameters {
        let material = Material {
            name: "m".into(),
            density: 1.0,
            elastic: Elastic::new(200.0, 0.3),
            plasticity: None,
        };
        let (lambda, mu) = material.elastic.lame();
        BodyParameters {
            name: "b".into(),
            material,
            formulation: Formulation::PlaneStrain,
            bbar: false,
            mu,
            hourglass_modulus: 0.1 * (lambda + 3.0 * mu) / 24.0,
            wave_modulus: lambda + 2.0 * mu,
            wave_lambda: lambda,
            first_element: 0,
            model_body: 0,
        }
    }

    const SQUARE: Nodes = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.5], [0.0, 1.5]];

    /// A rigid rotation by 0.3 rad in 100 increments leaves a stressed element's stress
    /// invariants unchanged (Hughes-Winget is exactly orthogonal) and its forces in
    /// equilibrium with the rotated stress.
    #[test]
    fn rigid_rotation_keeps_the_invariants() {
        let p = parameters();
        let mut x = SQUARE;
        let mut state = ElementState {
            stress: [1.0, -0.5, 0.2, 0.3],
            back_stress: [0.0; 4],
            eq_plastic_strain: 0.0,
            temperature: 0.0,
            thickness: 1.0,
            hourglass: [0.0; 2],
            viscous_pressure: 0.0,
        };
        let step: f64 = 0.003;
        let (c, s) = (step.cos(), step.sin());
        for _ in 0..100 {
            let u: Nodes = std::array::from_fn(|a| {
                let [px, py] = x[a];
                [c * px - s * py - px, s * px + c * py - py]
            });
            let mass = ElementMass {
                smallest: 1.0,
                total: 4.0,
            };
            state = element_step(&p, (&x, &u), &state, mass, (1.0, None))
                .unwrap()
                .state;
            x = std::array::from_fn(|a| [x[a][0] + u[a][0], x[a][1] + u[a][1]]);
        }
        // round-off: E ~ 200 times strains of ~1e-16 per step
        let [a, b, zz, t] = state.stress;
        assert!((a + b - 0.5).abs() < 1e-11, "trace {}", a + b);
        assert!((a * b - t * t - (-0.5 - 0.09)).abs() < 1e-11);
        assert!((zz - 0.2).abs() < 1e-11, "zz {zz}");
        // and it turned with the body (counter-clockwise by phi = 0.3):
        // sigma_xy = (a0 - b0)/2 sin 2 phi + t0 cos 2 phi
        let expected = 0.5 * (1.0 + 0.5) * 0.6f64.sin() + 0.3 * 0.6f64.cos();
        assert!((t - expected).abs() < 1e-11, "xy {t} vs {expected}");
    }
}
