//! The explicit element loops: element data as structure of arrays, the element kernels run
//! in parallel over fixed chunks, nodal forces gathered in element order (the bits do not
//! depend on the thread count). Three kernels: the one-point Quad4 with hourglass control
//! (`one_point`, `quadrature = "reduced"`), the 2x2 Quad4 in the same rate form (`full`,
//! `quadrature = "full"` on finite-strain Quad4 models), both rules of the one Quad4 loop
//! (`skeleton`), and the general element loop behind the same interface for the rest
//! (`general`: rods, small strain). The two Quad4 kernels give the element frequency
//! bound of the end configuration for the stable step, and both carry the optional bulk
//! viscosity (`element::bulk_viscosity`), whose damping they fold into that bound, and the
//! optional mass scaling (`element::mass_scaling`, `assembly::mass_scaling`), which raises
//! the masses of the elements whose bound is below its target as they deform. With
//! `analysis.stable_step = "tight"` each element's bound is made tight by its ratio to the
//! element's exact frequency (`tight`); `analysis.stable_step = "global"` estimates the
//! mesh's highest frequency by Lanczos on the element stiffnesses (`global`).
//!
//! **Wider registers.** The loops that carry a step's arithmetic (the element steps of a
//! chunk, the tight step's element stiffnesses, the global estimate's product, dot products
//! and updates) are compiled twice by `multiversion`: for the baseline x86-64 of the release
//! build and for the level with AVX2 and FMA, chosen at run time where the processor has it.
//! Rust never fuses a multiply and an add on its own, so the two builds do the same
//! operations in the same order and give the same bits (docs/performance.md, "Wider
//! registers where the processor has them").

pub mod full;
pub mod general;
pub mod global;
pub mod one_point;
pub mod skeleton;
pub mod tight;

pub use full::Full;
pub use general::General;
pub use one_point::Reduced;

use super::mass_scaling::ElementScaling;
use super::{BodyWork, ElementFailure, ElementMasses, StableStep, State};
use crate::element::Formulation;
use crate::element::Strain;
use crate::element::mass_scaling::MassScaling;
use crate::element::quad4_one_point::Nodes;
use crate::element::{KernelError, Voigt};
use crate::material::{Material, PointState, PointStep, StressCondition, UpdateContext};
use crate::scene::DynamicAnalysis;
use crate::scene::model::{PointFold, PointScalar, Probe, extreme_of_run};
use crate::scene::spec::Quadrature;
use crate::scene::spec::Statistic;
use crate::scene::{Continuum, Model};
use rayon::prelude::*;

/// Elements per parallel task (fixed, so the work sums do not depend on the thread count).
/// The element loops give each chunk its own task (`with_max_len(1)`): rayon's adaptive
/// splitter cuts a loop into about as many pieces as threads and splits further only where a
/// piece is stolen, which left the stepping thread two pieces of 9-10 chunks holding a Taylor
/// rod's plastic elements (16 % more element work than the other thread; docs/performance.md).
pub(super) const CHUNK: usize = 64;

/// The fewest chunks of `CHUNK` nodes a task of the gather takes: a node's sum reads four
/// entries, so a task of 512 nodes takes about what handing it to a thread still awake from
/// the element loop costs.
const GATHER_CHUNKS_PER_TASK: usize = 8;

/// The sums of one step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepWork {
    /// Work of the stresses and the hourglass forces (includes plastic and hourglass below,
    /// not the bulk viscosity).
    pub internal: f64,
    pub plastic: f64,
    pub hourglass: f64,
    /// Work of the bulk viscosity's pressure (0 without it).
    pub viscous: f64,
    /// The largest element frequency bound squared on the end configuration, and its
    /// element (index over the kernel's elements; the lowest among equals).
    pub omega_squared: f64,
    pub critical_element: usize,
    /// `internal` and `plastic` by model body, in runs of consecutive elements of one body
    /// (a body's elements are consecutive in a kernel, so a chunk holds one run, or two
    /// where it crosses a body's end; a body may appear in several runs).
    pub bodies: Vec<(usize, BodyWork)>,
}

impl Default for StepWork {
    fn default() -> StepWork {
        StepWork {
            internal: 0.0,
            plastic: 0.0,
            hourglass: 0.0,
            viscous: 0.0,
            omega_squared: 0.0,
            critical_element: usize::MAX,
            bodies: Vec::new(),
        }
    }
}

impl StepWork {
    /// Takes an element's frequency bound into the maximum.
    pub fn observe(&mut self, omega_squared: f64, element: usize) {
        if omega_squared > self.omega_squared
            || (omega_squared == self.omega_squared && element < self.critical_element)
        {
            self.omega_squared = omega_squared;
            self.critical_element = element;
        }
    }

    /// Takes an element's internal and plastic work into its model body's run.
    #[inline(always)]
    pub(super) fn book(&mut self, body: usize, internal: f64, plastic: f64) {
        match self.bodies.last_mut() {
            Some((b, work)) if *b == body => {
                work.internal += internal;
                work.plastic += plastic;
            }
            _ => self.bodies.push((body, BodyWork { internal, plastic })),
        }
    }

    /// Adds a chunk's sums (in chunk order).
    pub(super) fn add(&mut self, other: &StepWork) {
        self.internal += other.internal;
        self.plastic += other.plastic;
        self.hourglass += other.hourglass;
        self.viscous += other.viscous;
        self.observe(other.omega_squared, other.critical_element);
        for (body, work) in &other.bodies {
            self.book(*body, work.internal, work.plastic);
        }
    }

    /// Adds the step's work by body into the state's bodies.
    pub fn commit_bodies(&self, state: &mut State) {
        for (body, work) in &self.bodies {
            state.bodies[*body].work.add(work);
        }
    }
}

/// What the kernels need of a Quad4 body.
#[derive(Debug, Clone)]
pub struct BodyParameters {
    pub name: String,
    pub material: Material,
    pub formulation: Formulation,
    pub bbar: bool,
    /// The shear modulus.
    pub mu: f64,
    /// The plane-wave modulus of the stable-step bound: lambda + 2 mu (plane stress:
    /// E / (1 - nu^2)), and the lambda that goes with it.
    pub wave_modulus: f64,
    pub wave_lambda: f64,
    /// kappa (lambda + 3 mu) / 24 with the plane-stress lambda (the one-point kernel).
    pub hourglass_modulus: f64,
    /// The body's first element in the kernel's numbering.
    pub first_element: usize,
    /// The body's index in the model.
    pub model_body: usize,
}

impl BodyParameters {
    pub fn plane_stress(&self) -> bool {
        self.formulation == Formulation::PlaneStress
    }
    pub fn axisymmetric(&self) -> bool {
        self.formulation == Formulation::Axisymmetric
    }
}

/// The material's one update (`Material::step`) of a point of body `p` from its committed
/// state rotated by the step's spin: the new state, heating inside; in plane stress the
/// material's out-of-plane strain is written into `strain[2]`. Each arm calls the update
/// with its stress condition fixed, so the inlined update keeps one path.
#[inline(always)]
pub(super) fn point_step(
    p: &BodyParameters,
    start: &PointState,
    strain: &mut [f64; 4],
    dt: f64,
) -> PointStep {
    let increment = Voigt::from(*strain);
    if p.plane_stress() {
        let condition = StressCondition::PlaneStress;
        let step = p
            .material
            .step(start, &increment, UpdateContext { condition, dt });
        strain[2] = step.strain_zz;
        step
    } else {
        let condition = StressCondition::General;
        p.material
            .step(start, &increment, UpdateContext { condition, dt })
    }
}

/// The Quad4 bodies of a model as the kernels see them: per body its parameters, per element
/// its body and global nodes.
pub(super) struct Layout {
    pub bodies: Vec<BodyParameters>,
    pub body: Vec<u32>,
    pub nodes: Vec<[u32; 4]>,
    /// (model body, element in it) of each kernel element.
    pub origin: Vec<(usize, usize)>,
    /// The kernel element of each model body's first element (None: not a Quad4 body).
    pub first_of_body: Vec<Option<usize>>,
}

impl Layout {
    pub(super) fn new(model: &Model, kappa: f64) -> Layout {
        let mut layout = Layout {
            bodies: Vec::new(),
            body: Vec::new(),
            nodes: Vec::new(),
            origin: Vec::new(),
            first_of_body: Vec::new(),
        };
        for (b, spec) in model.bodies.iter().enumerate() {
            let Some(Continuum {
                formulation, bbar, ..
            }) = spec.kind.continuum()
            else {
                layout.first_of_body.push(None);
                continue;
            };
            layout.first_of_body.push(Some(layout.body.len()));
            let condition = StressCondition::of(formulation);
            let elastic = &spec.material.elastic;
            let (_, mu) = elastic.lame();
            let (wave_lambda, _) = elastic.lame_in(condition);
            layout.bodies.push(BodyParameters {
                name: spec.name.clone(),
                material: spec.material.clone(),
                formulation,
                bbar,
                mu,
                wave_modulus: elastic.p_wave_modulus(condition),
                wave_lambda,
                hourglass_modulus: kappa * (wave_lambda + 3.0 * mu) / 24.0,
                first_element: layout.body.len(),
                model_body: b,
            });
            let index = (layout.bodies.len() - 1) as u32;
            for e in 0..spec.elements() {
                let n = spec.mesh.cells.nodes_of(e);
                layout.body.push(index);
                layout
                    .nodes
                    .push(std::array::from_fn(|a| spec.global(n[a]) as u32));
                layout.origin.push((b, e));
            }
        }
        layout
    }

    pub(super) fn failure(
        &self,
        element: usize,
        error: crate::element::KernelError,
    ) -> ElementFailure {
        let p = &self.bodies[self.body[element] as usize];
        ElementFailure {
            body: p.name.clone(),
            element: element - p.first_element,
            error,
        }
    }
}

/// Node -> its entries in the element forces (8 per element), in element order: the gather
/// that sums the element forces into the nodes.
#[derive(Debug, Clone)]
pub(super) struct NodeGather {
    start: Vec<usize>,
    entries: Vec<u32>,
}

impl NodeGather {
    pub(super) fn new(nodes: &[[u32; 4]], node_count: usize) -> NodeGather {
        let mut start = vec![0usize; node_count + 1];
        for element in nodes {
            for n in element {
                start[*n as usize + 1] += 1;
            }
        }
        for n in 0..node_count {
            start[n + 1] += start[n];
        }
        let mut fill = start.clone();
        let mut entries = vec![0u32; start[node_count]];
        for (e, element) in nodes.iter().enumerate() {
            for (a, n) in element.iter().enumerate() {
                entries[fill[*n as usize]] = (8 * e + 2 * a) as u32;
                fill[*n as usize] += 1;
            }
        }
        NodeGather { start, entries }
    }

    /// Sums the element forces `element_forces` into the nodes: `force` over all DOFs
    /// (overwritten; nodes of no element get zero).
    pub(super) fn gather(&self, element_forces: &[f64], force: &mut [f64]) {
        let ef = element_forces;
        force
            .par_chunks_mut(2 * CHUNK)
            .enumerate()
            .with_min_len(GATHER_CHUNKS_PER_TASK)
            .for_each(|(k, chunk)| {
                for (i, f) in chunk.chunks_exact_mut(2).enumerate() {
                    f.copy_from_slice(&self.node_force(k * CHUNK + i, ef));
                }
            });
    }

    /// Sums the element forces into the nodes `nodes` only (`force` elsewhere untouched).
    pub(super) fn gather_nodes(&self, nodes: &[u32], element_forces: &[f64], force: &mut [f64]) {
        for &n in nodes {
            let n = n as usize;
            force[2 * n..2 * n + 2].copy_from_slice(&self.node_force(n, element_forces));
        }
    }

    /// Node n's force: its elements' entries of `element_forces`, in element order.
    #[inline(always)]
    fn node_force(&self, n: usize, element_forces: &[f64]) -> [f64; 2] {
        let (mut fx, mut fy) = (0.0, 0.0);
        for entry in &self.entries[self.start[n]..self.start[n + 1]] {
            fx += element_forces[*entry as usize];
            fy += element_forces[*entry as usize + 1];
        }
        [fx, fy]
    }
}

/// A chunk's sums, its failed element, and the elements whose mass factor grew (with the
/// new factor), in element order.
pub(super) type ChunkResult = (StepWork, Option<(usize, KernelError)>, Vec<(usize, f64)>);

/// The chunks' results of an element loop, in chunk order: the first element that failed,
/// else the sums, with the grown mass factors taken into `scaling`.
pub(super) fn fold_chunks(
    results: Vec<ChunkResult>,
    layout: &Layout,
    mut scaling: Option<&mut ElementScaling>,
) -> Result<StepWork, ElementFailure> {
    let mut total = StepWork::default();
    for (sums, error, grown) in results {
        if let Some((e, err)) = error {
            return Err(layout.failure(e, err));
        }
        total.add(&sums);
        if let Some(scaling) = scaling.as_deref_mut() {
            for (e, factor) in grown {
                scaling.grow(e, factor);
            }
        }
    }
    Ok(total)
}

/// The start positions and the increments of the nodes `nodes` of an element.
#[inline(always)]
pub(super) fn element_motion(nodes: [u32; 4], x: &[[f64; 2]], du: &[f64]) -> (Nodes, Nodes) {
    (
        nodes.map(|n| x[n as usize]),
        nodes.map(|n| [du[2 * n as usize], du[2 * n as usize + 1]]),
    )
}

/// Element e's frequency bound `omega_squared` as an element loop keeps it: under the mass
/// scaling `scaling` (None: off, or not grown in this loop) the bound of its grown mass
/// factor where the target asks (the element and its factor noted in `grown`).
#[inline(always)]
pub(super) fn kept_bound(
    scaling: Option<&ElementScaling>,
    e: usize,
    omega_squared: f64,
    grown: &mut Vec<(usize, f64)>,
) -> f64 {
    match scaling.and_then(|s| s.rule().rescale(s.factor(e), omega_squared)) {
        Some(rescaled) => {
            grown.push((e, rescaled.factor));
            rescaled.omega_squared
        }
        None => omega_squared,
    }
}

/// `data` (`width` values per element) cut at the elements `starts` (ascending): part c
/// holds elements starts[c] .. starts[c + 1], the last part those from the last start on
/// (the elements before the first start are in no part). What lets a loop over a list of
/// elements write each chunk's elements in parallel.
pub(super) fn cut<'a>(
    data: &'a mut [f64],
    width: usize,
    starts: &[usize],
) -> std::vec::IntoIter<&'a mut [f64]> {
    let mut parts = Vec::with_capacity(starts.len());
    let Some(&first) = starts.first() else {
        return parts.into_iter();
    };
    let (_, mut rest) = data.split_at_mut(width * first);
    for pair in starts.windows(2) {
        let (part, tail) = std::mem::take(&mut rest).split_at_mut(width * (pair[1] - pair[0]));
        parts.push(part);
        rest = tail;
    }
    parts.push(rest);
    parts.into_iter()
}

/// An explicit element loop over a model's Quad4 bodies.
pub trait ExplicitKernel: Send {
    fn elements(&self) -> usize;
    /// The model's body and the element's number in it of kernel element `element`.
    fn locate(&self, element: usize) -> (usize, usize);
    /// The internal force on the positions `x` from the stored state (no update), written
    /// into `force` over all DOFs.
    fn internal_force(&mut self, x: &[[f64; 2]], force: &mut [f64]) -> Result<(), ElementFailure>;
    /// One step from positions `x` by the increment `du` (2 per node): updates the element
    /// state and writes the internal force on x + du into `force`. After an error the
    /// element state is partly updated and the run must stop. `dt` is the step's length
    /// (the strain rate of rate-dependent materials).
    fn step(
        &mut self,
        x: &[[f64; 2]],
        du: &[f64],
        dt: f64,
        force: &mut [f64],
    ) -> Result<StepWork, ElementFailure>;
    /// The stable step of the positions `x` from the stored state: 2 / sqrt of the largest
    /// element frequency bound.
    fn stable_step(&self, x: &[[f64; 2]]) -> Result<StableStep, ElementFailure>;
    /// Copies the element state into the points of `state` (what output reads).
    fn write_points(&self, model: &Model, state: &mut State);
    /// The accumulated hourglass work (the one-point kernel).
    fn hourglass_energy(&self) -> Option<f64> {
        None
    }
    /// The bulk viscosity's pressure q of the last step at every point the kernel keeps
    /// (zeros without it): what a checkpoint carries, since the next step's work needs it.
    fn viscous_pressure(&self) -> &[f64];
    /// Takes the viscous pressures of a checkpoint (as `viscous_pressure` gave them).
    fn restore_viscous_pressure(&mut self, values: &[f64]);
    /// The kernel's element state that `State` does not hold (the one-point kernel's hourglass
    /// forces, 2 per element, and their work so far), to carry into a kernel rebuilt after an
    /// ALE remap (None: there is none).
    fn hourglass_state(&self) -> Option<(Vec<f64>, f64)> {
        None
    }
    fn restore_hourglass_state(&mut self, _forces: Vec<f64>, _work: f64) {}
    /// The statistic of point probe `probe` over the kernel's own point values, as
    /// `write_points` and the probe over the state's points would give it (None: a body the
    /// kernel does not hold, or a nodal quantity).
    fn point_probe(&self, _model: &Model, _probe: &Probe) -> Option<f64> {
        None
    }
    /// The equivalent plastic strain of every point the kernel keeps (for studies).
    fn eq_plastic_strain(&self) -> Vec<f64>;
    /// The mass scaling of the kernel's elements (None: off): their factors, the mass they
    /// added, and the nodal masses the run has still to take.
    fn mass_scaling(&self) -> Option<&ElementScaling>;
    fn mass_scaling_mut(&mut self) -> Option<&mut ElementScaling>;
    /// The tight stable step's ratios (None: the element bounds stand): what a checkpoint
    /// carries, since the ratios were taken on earlier configurations.
    fn tightness(&self) -> Option<&tight::Tightness> {
        None
    }
    /// Takes the ratios of a checkpoint (as `tightness` gave them).
    fn restore_tightness(&mut self, _tightness: tight::Tightness) {}
    /// The element loop a subcycled run steps a few elements at a time with (None: the
    /// kernel steps all its elements together only).
    fn partial(&mut self) -> Option<&mut dyn PartialKernel> {
        None
    }
}

/// An element loop that steps a subset of its elements (subcycling, docs/theory.md 8.7c):
/// each element from its own start positions by its own increment, the nodes that need it
/// gathering the element forces of their elements' last steps.
pub trait PartialKernel {
    /// The global nodes of every kernel element.
    fn element_nodes(&self) -> &[[u32; 4]];
    /// Element `e`'s frequency bound squared on the positions `x` from the stored state (the
    /// bound `stable_step` takes the largest of).
    fn frequency_of(&self, x: &[[f64; 2]], e: usize) -> Result<f64, ElementFailure>;
    /// Every element's, into `omega_squared`.
    fn frequencies(&self, x: &[[f64; 2]], omega_squared: &mut [f64]) -> Result<(), ElementFailure> {
        for (e, omega_squared) in omega_squared.iter_mut().enumerate() {
            *omega_squared = self.frequency_of(x, e)?;
        }
        Ok(())
    }
    /// One step of length `dt` of the elements `elements` (ascending) from the positions `x`
    /// by the increments `du` (both read at those elements' nodes only): their state and
    /// their element forces updated, their frequency bounds squared on the end
    /// configuration written into `omega_squared` (over all elements); the step's sums.
    fn step_elements(
        &mut self,
        elements: &[u32],
        motion: (&[[f64; 2]], &[f64]),
        dt: f64,
        omega_squared: &mut [f64],
    ) -> Result<StepWork, ElementFailure>;
    /// The internal force of the nodes `nodes` from their elements' last element forces,
    /// written into `force` at those nodes only.
    fn gather_nodes(&self, nodes: &[u32], force: &mut [f64]);
}

/// A point probe's statistic over the points of a kernel's elements: `point(e, q)` the state of
/// point q of kernel element e, `distinct` points per element (a one-point element's one
/// state stands for all its points, as `write_points` copies it); the fold over the probe's
/// elements' points in the state's order, `points_per_element` each.
pub(super) struct KernelPoints<'a, P> {
    pub probe: &'a Probe,
    /// The kernel element of the body's first element.
    pub first: usize,
    pub points_per_element: usize,
    pub distinct: usize,
    pub point: P,
    /// The kernel's arrays of the points' equivalent plastic strain and temperature
    /// (`distinct` entries per element), which a probe of either reads directly.
    pub scalars: [&'a [f64]; 2],
}

impl<P: Fn(usize, usize) -> PointState + Sync> PointFold for KernelPoints<'_, P> {
    #[inline]
    fn fold(self, value: impl Fn(&PointState) -> f64 + Sync) -> f64 {
        let KernelPoints {
            probe,
            first,
            points_per_element,
            distinct,
            point,
            ..
        } = self;
        let (point, value) = (&point, &value);
        probe.combine(|members| {
            members.iter().flat_map(move |&e| {
                let one = (distinct == 1).then(|| value(&point(first + e, 0)));
                (0..points_per_element)
                    .map(move |q| one.unwrap_or_else(|| value(&point(first + e, q))))
            })
        })
    }

    /// The same values as `fold` of `scalar`, read from the kernel's array: a point's whole
    /// state is not built for one number of it (a probe of the largest plastic strain was 3 %
    /// of a Taylor rod's run on one thread). The largest or smallest of a one-point element's
    /// points is its one value; a mean weighs each element by its points, as `fold` does.
    fn fold_scalar(self, scalar: PointScalar) -> f64 {
        let (probe, first, distinct) = (self.probe, self.first, self.distinct);
        let values = self.scalars[scalar as usize];
        if distinct == 1 && matches!(probe.statistic, Statistic::Max | Statistic::Min) {
            // (min and max are exact: any order of the values gives the same bits)
            if let Some(elements) = &probe.consecutive {
                let run = &values[first + elements.start..first + elements.end];
                return extreme_of_run(run, probe.statistic == Statistic::Max);
            }
            return probe.combine(|members| members.iter().map(move |&e| values[first + e]));
        }
        let points_per_element = self.points_per_element;
        probe.combine(|members| {
            members.iter().flat_map(move |&e| {
                let element = &values[(first + e) * distinct..(first + e + 1) * distinct];
                (0..points_per_element).map(move |q| element[if distinct == 1 { 0 } else { q }])
            })
        })
    }
}

/// The statistic of point probe `probe` over `layout`'s elements (see `KernelPoints`); None
/// for a body the kernel does not hold or a nodal quantity.
pub(super) fn point_statistic<P: Fn(usize, usize) -> PointState + Sync>(
    layout: &Layout,
    model: &Model,
    probe: &Probe,
    (distinct, scalars): (usize, [&[f64]; 2]),
    point: P,
) -> Option<f64> {
    let first = layout.first_of_body.get(probe.body).copied().flatten()?;
    probe.fold_points(KernelPoints {
        probe,
        first,
        points_per_element: model.bodies[probe.body].points_per_element(),
        distinct,
        point,
        scalars,
    })
}

/// The mass scaling `rule` of `layout`'s elements with their lumped masses `masses`, every
/// element unscaled.
pub(super) fn element_scaling(
    rule: MassScaling,
    model: &Model,
    layout: &Layout,
    masses: &ElementMasses,
) -> ElementScaling {
    let nodal = layout
        .origin
        .iter()
        .map(|&(b, e)| {
            let m = masses.of(model, b, e);
            [m[0], m[1], m[2], m[3]]
        })
        .collect();
    ElementScaling::new(rule, nodal, layout.nodes.clone())
}

/// The stable step of a kernel's elements on the positions `x`: the largest of their bounds
/// `bound(e)`, made tight by `tightness` (when on; `damping` each bound's undamped value
/// over it) with their exact frequencies `exact(nodes, e)` (`tight`).
pub(super) fn kernel_stable_step(
    layout: &Layout,
    x: &[[f64; 2]],
    (tightness, damping): (Option<&tight::Tightness>, &[f64]),
    bound: impl Fn(usize) -> Result<f64, ElementFailure>,
    exact: impl Fn(&Nodes, usize) -> Option<tight::ElementStiffness> + Sync,
) -> Result<StableStep, ElementFailure> {
    let mut worst = StepWork::default();
    let mut bounds = Vec::with_capacity(layout.nodes.len());
    for e in 0..layout.nodes.len() {
        let omega_squared = bound(e)?;
        worst.observe(omega_squared, e);
        bounds.push(omega_squared);
    }
    if let Some(tight) = tightness {
        let nodes = |e: usize| layout.nodes[e].map(|n| x[n as usize]);
        (worst.omega_squared, worst.critical_element) =
            tight.peek(&bounds, damping, &layout.nodes, |e| exact(&nodes(e), e));
    }
    Ok(stable_step_of(layout, &worst))
}

/// The stable step of a step's sums, its element as the model names it.
pub(super) fn stable_step_of(layout: &Layout, work: &StepWork) -> StableStep {
    let (body, element) = layout
        .origin
        .get(work.critical_element)
        .copied()
        .unwrap_or((0, 0));
    StableStep::of_frequency(work.omega_squared, body, element)
}

/// The element loop of a central-difference run: the one-point kernel (`reduced`), the 2x2
/// rate-form kernel on finite-strain Quad4 models, or none (rods, small strain: the general
/// assembly). With the mass
/// scaling of `spec` the elements below its target on the configuration of `state` are
/// scaled (their added mass pending for the run's nodal masses).
pub fn kernel_for<'a>(
    model: &'a Model,
    spec: &DynamicAnalysis,
    state: &State,
    masses: &ElementMasses,
) -> Box<dyn ExplicitKernel + 'a> {
    let quads_only = model.bodies.iter().all(|b| !b.kind.is_rod());
    match spec.quadrature {
        Quadrature::Reduced => Box::new(
            Reduced::new(model, state, spec.hourglass, masses)
                .with_stable_step(spec.stable_estimate())
                .with_bulk_viscosity(spec.bulk_viscosity)
                .with_mass_scaling(spec.mass_scaling, model, masses, &state.coordinates),
        ),
        Quadrature::Full if quads_only && spec.geometry == Strain::Finite => Box::new(
            Full::new(model, state, masses)
                .with_stable_step(spec.stable_estimate())
                .with_bulk_viscosity(spec.bulk_viscosity)
                .with_mass_scaling(spec.mass_scaling, model, masses, &state.coordinates),
        ),
        Quadrature::Full => Box::new(General::new(
            model,
            state,
            masses,
            spec.geometry,
            spec.newton.tangent,
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::cut;

    /// The parts of `cut` hold the elements from each start to the next (the last to the
    /// end), `width` values each, and none before the first start: checked against the
    /// element number written into each value.
    #[test]
    fn cut_parts_hold_their_elements() {
        let width = 3;
        let mut data: Vec<f64> = (0..10 * width).map(|k| (k / width) as f64).collect();
        let parts: Vec<&mut [f64]> = cut(&mut data, width, &[2, 3, 7]).collect();
        let elements: Vec<Vec<f64>> = parts
            .iter()
            .map(|p| p.iter().step_by(width).copied().collect())
            .collect();
        assert_eq!(
            elements,
            vec![vec![2.0], vec![3.0, 4.0, 5.0, 6.0], vec![7.0, 8.0, 9.0]]
        );
        assert!(parts.iter().all(|p| p.len() % width == 0));
        assert_eq!(cut(&mut data, width, &[]).count(), 0);
    }
}
