//! The explicit Quad4 element loop, written once: the element state as columns (structure of
//! arrays), the step of every element (or of a subcycled level's) over fixed chunks in
//! parallel, the work sums in chunk order, the frequency bounds the stable step takes (made
//! tight by `tight`, damped by the bulk viscosity, kept by the mass scaling), the nodal forces
//! gathered in element order. The bits do not depend on the thread count.
//!
//! The two Quad4 kernels are rules of this loop: `full::TwoByTwo` (four Gauss points, B-bar by
//! option) and `one_point::OnePoint` (one point and hourglass forces). A rule supplies what
//! differs: the points it keeps per element, its element step (strain, material update,
//! stress, forces, work, frequency bound), the bound and the forces of a stored state, and how
//! an element's state is read from and written into the columns.
//!
//! ```text
//! P          the rule's points per element (2x2: 4; one point: 1); H its hourglass values (0; 2)
//! columns    stress, back stress 4 P per element; plastic strain, temperature, thickness,
//!            viscous pressure P; hourglass forces H (element-major)
//! m          the lumped masses of the element's nodes, times its mass factor s (mass scaling)
//! omega^2    the rule's bound on the end configuration, damped by the bulk viscosity
//! ```

use super::tight::{
    ElementStiffness, Tightness, end_nodes, shortest_edge, stiffness_by_differences,
};
use super::{
    BodyParameters, CHUNK, ChunkResult, ExplicitKernel, Layout, NodeGather, PartialKernel,
    StepWork, cut, element_motion, element_scaling, fold_chunks, kept_bound, kernel_stable_step,
    point_statistic,
};
use crate::assembly::mass_scaling::ElementScaling;
use crate::assembly::{ElementFailure, ElementMasses, StableStep, State};
use crate::element::bulk_viscosity::{BulkViscosity, damped_frequency_squared, damping_factor};
use crate::element::mass_scaling::MassScaling;
use crate::element::quad4_one_point::Nodes;
use crate::element::{KernelError, Voigt};
use crate::material::PointState;
use crate::scene::Model;
use crate::scene::model::Probe;
use crate::scene::spec::StableStepKind;
use multiversion::multiversion;
use rayon::prelude::*;
use std::marker::PhantomData;
use std::ops::Deref;

/// The element state columns of a kernel (see the legend for their widths): owned
/// (`Vec<f64>`), read (`&[f64]`) or one chunk's to write (`&mut [f64]`).
pub struct Columns<S> {
    pub stress: S,
    pub back: S,
    pub eps_p: S,
    pub temperature: S,
    pub thickness: S,
    /// The bulk viscosity's pressure of the step that ended here (0 without it).
    pub viscous: S,
    pub hourglass: S,
}

/// One element after a step of a rule.
pub struct ElementStep<S> {
    pub state: S,
    /// Internal force [f1x f1y ... f4x f4y] on the end configuration.
    pub force: [f64; 8],
    /// Work of the stresses (hourglass excluded).
    pub work: f64,
    pub plastic_work: f64,
    /// Work of the hourglass forces (0 for a rule without them).
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

/// What a Quad4 kernel supplies to the loop: its quadrature and stabilization.
pub trait Rule {
    /// The points the kernel keeps per element.
    const POINTS: usize;
    /// The hourglass values it keeps per element (0: none).
    const HOURGLASS: usize;
    /// One element's committed state.
    type State: Copy;
    /// What the element step reads of the element's lumped masses.
    type Mass: Copy + Send + Sync;

    /// The element's mass from its nodes' lumped masses.
    fn mass(lumped: &[f64; 4]) -> Self::Mass;
    /// `mass` times the mass factor `factor`.
    fn scaled(mass: Self::Mass, factor: f64) -> Self::Mass;
    /// Element i of `columns`.
    fn read<S: Deref<Target = [f64]>>(columns: &Columns<S>, i: usize) -> Self::State;
    /// Writes `state` as element i of `columns`.
    fn write(columns: &mut Columns<&mut [f64]>, i: usize, state: &Self::State);
    /// `state` without its stresses, plastic strain, hourglass forces and viscous pressure
    /// (what the tight step's stiffness is taken from).
    fn fresh(state: &Self::State) -> Self::State;
    /// One element over one step of length dt: positions x at the start, increment u, with
    /// the bulk viscosity `viscosity` when on.
    fn step(
        p: &BodyParameters,
        motion: (&Nodes, &Nodes),
        committed: &Self::State,
        mass: Self::Mass,
        step: (f64, Option<&BulkViscosity>),
    ) -> Result<ElementStep<Self::State>, KernelError>;
    /// The undamped frequency bound squared of an element in `state` at the nodes `x`.
    fn bound(
        p: &BodyParameters,
        x: &Nodes,
        state: &Self::State,
        mass: Self::Mass,
    ) -> Result<f64, KernelError>;
    /// The nodal forces of an element in `state` at the nodes `x` (`viscous`: its stored
    /// viscous pressure taken off the stress).
    fn force(
        p: &BodyParameters,
        x: &Nodes,
        state: &Self::State,
        viscous: bool,
    ) -> Result<[f64; 8], KernelError>;
}

/// An explicit Quad4 kernel: the loop over the elements of a model's Quad4 bodies with the
/// rule `R`.
pub struct Skeleton<R: Rule> {
    layout: Layout,
    /// The lumped masses of each element's nodes (unscaled), and the rule's mass of them.
    lumped: Vec<[f64; 4]>,
    mass: Vec<R::Mass>,
    columns: Columns<Vec<f64>>,
    /// The bulk viscosity (None: off).
    viscosity: Option<BulkViscosity>,
    /// Element forces of the last evaluation, 8 per element.
    element_forces: Vec<f64>,
    gather: NodeGather,
    /// Accumulated hourglass work (0 for a rule without it).
    hourglass_energy: f64,
    /// The mass scaling (None: off).
    scaling: Option<ElementScaling>,
    /// Each element's frequency bound of the last step, and the ratios that make them tight
    /// (`tight`; None: the bounds stand, the default).
    bounds: Vec<f64>,
    /// Each element's `ElementStep::damping` of the last step (the bulk viscosity's at rest
    /// before the first): the tight ratios are taken against the undamped bounds.
    damping: Vec<f64>,
    tightness: Option<Tightness>,
    /// Every kernel element, in order (the list a whole step walks).
    all: Vec<u32>,
    rule: PhantomData<fn() -> R>,
}

/// What an element loop reads besides the element columns.
struct Reads<'a, M> {
    layout: &'a Layout,
    mass: &'a [M],
    scaling: Option<&'a ElementScaling>,
    viscosity: Option<&'a BulkViscosity>,
}

/// The arrays one chunk of an element loop writes: element `first + i` at entry i.
struct Chunk<'a> {
    first: usize,
    columns: Columns<&'a mut [f64]>,
    forces: &'a mut [f64],
    /// The frequency bounds the loop writes.
    bounds: &'a mut [f64],
    damping: &'a mut [f64],
}

impl<R: Rule> Skeleton<R> {
    /// The kernel for the Quad4 bodies of `model` (the scene refuses rods with it), starting
    /// from the committed `state`; `kappa` is the hourglass coefficient (one-point rule).
    pub(super) fn build(
        model: &Model,
        state: &State,
        masses: &ElementMasses,
        kappa: f64,
    ) -> Skeleton<R> {
        let layout = Layout::new(model, kappa);
        let count = layout.body.len();
        let points = R::POINTS * count;
        let mut columns = Columns {
            stress: Vec::with_capacity(4 * points),
            back: Vec::with_capacity(4 * points),
            eps_p: Vec::with_capacity(points),
            temperature: Vec::with_capacity(points),
            thickness: Vec::with_capacity(points),
            viscous: vec![0.0; points],
            hourglass: vec![0.0; R::HOURGLASS * count],
        };
        let (mut lumped, mut mass) = (Vec::with_capacity(count), Vec::with_capacity(count));
        for &(b, e) in &layout.origin {
            let committed = &state.bodies[b];
            for q in 0..R::POINTS {
                let p = &committed.points[4 * e + q];
                columns.stress.extend(p.stress.iter());
                columns.back.extend(p.back_stress.iter());
                columns.eps_p.push(p.eq_plastic_strain);
                columns.temperature.push(p.temperature);
                columns.thickness.push(committed.thickness[4 * e + q]);
            }
            let m = masses.of(model, b, e);
            let nodal = [m[0], m[1], m[2], m[3]];
            lumped.push(nodal);
            mass.push(R::mass(&nodal));
        }
        Skeleton {
            gather: NodeGather::new(&layout.nodes, state.coordinates.len()),
            layout,
            lumped,
            mass,
            columns,
            viscosity: None,
            element_forces: vec![0.0; 8 * count],
            hourglass_energy: 0.0,
            scaling: None,
            bounds: vec![0.0; count],
            damping: vec![1.0; count],
            tightness: None,
            all: (0..count as u32).collect(),
            rule: PhantomData,
        }
    }

    /// The kernel whose stable step follows the estimate `kind`: its elements' bounds
    /// (`Bound`), each bound times its ratio to the element's exact frequency (`Tight`,
    /// `tight.rs`), or the mesh's estimate over those (`Global`, `global.rs`).
    pub fn with_stable_step(self, kind: StableStepKind) -> Skeleton<R> {
        let tightness = Tightness::of(kind, self.bounds.len());
        Skeleton { tightness, ..self }
    }

    /// The kernel with the bulk viscosity `viscosity` (None: off). Its damping folds into the
    /// bounds; the tight ratios are taken against the undamped ones (`damping`, at rest
    /// until the first step).
    pub fn with_bulk_viscosity(self, viscosity: Option<BulkViscosity>) -> Skeleton<R> {
        let at_rest = viscosity.map_or(1.0, |v| damping_factor(v.damping_fraction_at_rest()));
        let damping = vec![at_rest; self.bounds.len()];
        Skeleton {
            viscosity,
            damping,
            ..self
        }
    }

    /// The kernel with the mass scaling `rule` (None: off), the elements below its target
    /// on the positions `x` scaled (`masses`: the lumped masses the kernel was made with).
    pub fn with_mass_scaling(
        mut self,
        rule: Option<MassScaling>,
        model: &Model,
        masses: &ElementMasses,
        x: &[[f64; 2]],
    ) -> Skeleton<R> {
        if let Some(rule) = rule {
            let mut scaling = element_scaling(rule, model, &self.layout, masses);
            scaling.scale_at_start(|e| self.frequency(x, e).ok());
            self.scaling = Some(scaling);
        }
        self
    }

    fn parameters(&self, e: usize) -> &BodyParameters {
        &self.layout.bodies[self.layout.body[e] as usize]
    }

    fn state_of(&self, e: usize) -> R::State {
        R::read(&self.columns, e)
    }

    /// The rule's mass of element `e` (scaled by its factor with the mass scaling).
    fn mass_of(&self, e: usize) -> R::Mass {
        mass_of::<R>(&self.mass, self.scaling.as_ref(), e)
    }

    /// The lumped masses of element `e` (scaled by its factor with the mass scaling).
    fn lumped_of(&self, e: usize) -> [f64; 4] {
        match &self.scaling {
            Some(scaling) => self.lumped[e].map(|m| m * scaling.factor(e)),
            None => self.lumped[e],
        }
    }

    /// The stiffness and lumped masses of element `e` at the nodes `xe` (its exact highest
    /// frequency squared their largest eigenvalue): the kernel's stiffness (hourglass and
    /// hoop included) from a stress-free state (`tight`).
    fn exact_stiffness(&self, xe: &Nodes, e: usize) -> Option<ElementStiffness> {
        let p = self.parameters(e);
        let fresh = R::fresh(&self.state_of(e));
        let mass = self.mass_of(e);
        let k = stiffness_at::<R>(p, xe, &fresh, mass)?;
        Some(ElementStiffness {
            k,
            lumped: self.lumped_of(e),
        })
    }

    /// The frequency bound squared of element `e` on the positions `x` from the stored
    /// state, with its masses and (at rest: no step yet) the damping of the bulk
    /// viscosity's linear term.
    fn frequency(&self, x: &[[f64; 2]], e: usize) -> Result<f64, ElementFailure> {
        let xe: Nodes = self.layout.nodes[e].map(|n| x[n as usize]);
        let omega_squared = R::bound(self.parameters(e), &xe, &self.state_of(e), self.mass_of(e))
            .map_err(|err| self.layout.failure(e, err))?;
        Ok(match &self.viscosity {
            Some(v) => damped_frequency_squared(omega_squared, v.damping_fraction_at_rest()),
            None => omega_squared,
        })
    }

    /// The steps of the elements `elements` (ascending, each once) in chunks of `CHUNK`
    /// entries, in parallel, each chunk writing its elements' state, forces and frequency
    /// bounds (into `omega_squared`, over all elements) where they lie: the arrays are cut
    /// at the chunks' first elements. The chunk sums are added in chunk order, so the bits
    /// do not depend on the thread count. With `grow` (a whole step) the mass scaling raises
    /// the factors of the elements below its target.
    fn step_list(
        &mut self,
        elements: &[u32],
        motion: (&[[f64; 2]], &[f64]),
        dt: f64,
        (omega_squared, grow): (&mut [f64], bool),
    ) -> Result<StepWork, ElementFailure> {
        let reads = Reads {
            layout: &self.layout,
            mass: &self.mass,
            scaling: self.scaling.as_ref(),
            viscosity: self.viscosity.as_ref(),
        };
        let starts: Vec<usize> = elements.chunks(CHUNK).map(|c| c[0] as usize).collect();
        let chunks = chunks_at::<R>(
            &mut self.columns,
            (&mut self.element_forces, omega_squared, &mut self.damping),
            &starts,
        );
        let results: Vec<ChunkResult> = chunks
            .into_par_iter()
            .zip(elements.par_chunks(CHUNK))
            .with_max_len(1)
            .map(|(mut chunk, list)| step_chunk::<R>(&reads, &mut chunk, list, motion, (dt, grow)))
            .collect();
        let scaling = self.scaling.as_mut().filter(|_| grow);
        fold_chunks(results, &self.layout, scaling)
    }

    /// A whole step of every element: their new states, forces and frequency bounds
    /// (`bounds`), made tight when on; the sums with the largest bound.
    fn step_all(
        &mut self,
        x: &[[f64; 2]],
        du: &[f64],
        dt: f64,
    ) -> Result<StepWork, ElementFailure> {
        // the list and the bounds lent out of the kernel for the loop that writes the rest
        // of it (put back before an error returns)
        let (all, mut bounds) = (
            std::mem::take(&mut self.all),
            std::mem::take(&mut self.bounds),
        );
        let stepped = self.step_list(&all, (x, du), dt, (&mut bounds, true));
        (self.all, self.bounds) = (all, bounds);
        let mut total = stepped?;
        if let Some(mut tight) = self.tightness.take() {
            let end = |e: usize| end_nodes(self.layout.nodes[e], x, du);
            (total.omega_squared, total.critical_element) =
                tight.apply(&self.bounds, &self.damping, &self.layout.nodes, |e| {
                    self.exact_stiffness(&end(e), e)
                });
            self.tightness = Some(tight);
        }
        self.hourglass_energy += total.hourglass;
        Ok(total)
    }

    /// The state of point q of element e as the state's points hold it.
    fn point(&self, e: usize, q: usize) -> PointState {
        let k = R::POINTS * e + q;
        let c = &self.columns;
        PointState {
            stress: Voigt::from(std::array::from_fn(|i| c.stress[4 * k + i])),
            eq_plastic_strain: c.eps_p[k],
            back_stress: Voigt::from(std::array::from_fn(|i| c.back[4 * k + i])),
            temperature: c.temperature[k],
        }
    }
}

/// The rule's mass of element `e` of `mass` (scaled by its factor under `scaling`).
#[inline(always)]
fn mass_of<R: Rule>(mass: &[R::Mass], scaling: Option<&ElementScaling>, e: usize) -> R::Mass {
    match scaling {
        Some(scaling) => R::scaled(mass[e], scaling.factor(e)),
        None => mass[e],
    }
}

/// The stiffness of an element of body `p` at the nodes `xe` in the stress-free state
/// `fresh` (`Skeleton::exact_stiffness`): the rule's forces differenced. Compiled twice
/// (module `explicit`, "Wider registers").
#[multiversion(targets("x86_64+avx2+fma"))]
fn stiffness_at<R: Rule>(
    p: &BodyParameters,
    xe: &Nodes,
    fresh: &R::State,
    mass: R::Mass,
) -> Option<[[f64; 8]; 8]> {
    let h = 1e-7 * shortest_edge(xe);
    stiffness_by_differences(h, |u| {
        R::step(p, (xe, u), fresh, mass, (1.0, None))
            .ok()
            .map(|r| r.force)
    })
}

/// The columns and the element forces, bounds and damping cut into chunks at the elements
/// `starts`.
fn chunks_at<'a, R: Rule>(
    columns: &'a mut Columns<Vec<f64>>,
    (forces, bounds, damping): (&'a mut [f64], &'a mut [f64], &'a mut [f64]),
    starts: &[usize],
) -> Vec<Chunk<'a>> {
    let p = R::POINTS;
    let mut stress = cut(&mut columns.stress, 4 * p, starts);
    let mut back = cut(&mut columns.back, 4 * p, starts);
    let mut eps_p = cut(&mut columns.eps_p, p, starts);
    let mut temperature = cut(&mut columns.temperature, p, starts);
    let mut thickness = cut(&mut columns.thickness, p, starts);
    let mut viscous = cut(&mut columns.viscous, p, starts);
    let mut hourglass = cut(&mut columns.hourglass, R::HOURGLASS, starts);
    let (mut forces, mut bounds, mut damping) = (
        cut(forces, 8, starts),
        cut(bounds, 1, starts),
        cut(damping, 1, starts),
    );
    starts
        .iter()
        .map_while(|&first| {
            Some(Chunk {
                first,
                columns: Columns {
                    stress: stress.next()?,
                    back: back.next()?,
                    eps_p: eps_p.next()?,
                    temperature: temperature.next()?,
                    thickness: thickness.next()?,
                    viscous: viscous.next()?,
                    hourglass: hourglass.next()?,
                },
                forces: forces.next()?,
                bounds: bounds.next()?,
                damping: damping.next()?,
            })
        })
        .collect()
}

/// Steps the elements `elements` of `chunk` from the positions and increments `(x, du)`:
/// their sums in element order, the first that failed, and (with `grow`, under the mass
/// scaling) the elements whose mass factor grew. Compiled twice (module `explicit`, "Wider
/// registers").
#[multiversion(targets("x86_64+avx2+fma"))]
fn step_chunk<R: Rule>(
    reads: &Reads<R::Mass>,
    chunk: &mut Chunk,
    elements: &[u32],
    (x, du): (&[[f64; 2]], &[f64]),
    (dt, grow): (f64, bool),
) -> ChunkResult {
    let layout = reads.layout;
    let mut sums = StepWork::default();
    let mut grown = Vec::new();
    for e in elements.iter().map(|&e| e as usize) {
        let (xe, ue) = element_motion(layout.nodes[e], x, du);
        let p = &layout.bodies[layout.body[e] as usize];
        let mass = mass_of::<R>(reads.mass, reads.scaling, e);
        let i = e - chunk.first;
        let committed = R::read(&chunk.columns, i);
        let r = match R::step(p, (&xe, &ue), &committed, mass, (dt, reads.viscosity)) {
            Ok(r) => r,
            Err(err) => return (sums, Some((e, err)), grown),
        };
        let scaling = reads.scaling.filter(|_| grow);
        let omega_squared = kept_bound(scaling, e, r.omega_squared, &mut grown);
        sums.observe(omega_squared, e);
        chunk.bounds[i] = omega_squared;
        chunk.damping[i] = r.damping;
        R::write(&mut chunk.columns, i, &r.state);
        chunk.forces[8 * i..8 * i + 8].copy_from_slice(&r.force);
        sums.internal += r.work + r.hourglass_work;
        sums.plastic += r.plastic_work;
        sums.book(p.model_body, r.work + r.hourglass_work, r.plastic_work);
        sums.hourglass += r.hourglass_work;
        sums.viscous += r.viscous_work;
    }
    (sums, None, grown)
}

impl<R: Rule> ExplicitKernel for Skeleton<R> {
    fn elements(&self) -> usize {
        self.layout.body.len()
    }

    fn locate(&self, element: usize) -> (usize, usize) {
        self.layout.origin[element]
    }

    fn internal_force(&mut self, x: &[[f64; 2]], force: &mut [f64]) -> Result<(), ElementFailure> {
        let mut forces = std::mem::take(&mut self.element_forces);
        let this = &*self;
        let viscous = this.viscosity.is_some();
        let error = forces
            .par_chunks_mut(8 * CHUNK)
            .enumerate()
            .map(|(k, chunk)| {
                for (i, f) in chunk.chunks_exact_mut(8).enumerate() {
                    let e = k * CHUNK + i;
                    let xe: Nodes = this.layout.nodes[e].map(|n| x[n as usize]);
                    match R::force(this.parameters(e), &xe, &this.state_of(e), viscous) {
                        Ok(v) => f.copy_from_slice(&v),
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
        let total = self.step_all(x, du, dt)?;
        self.gather.gather(&self.element_forces, force);
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
                    // a one-point element's one state stands for its four points
                    for q in 0..4 {
                        let kept = q % R::POINTS;
                        points[q] = this.point(start + e, kept);
                        thickness[q] = this.columns.thickness[R::POINTS * (start + e) + kept];
                    }
                });
            start += count;
        }
    }

    fn hourglass_energy(&self) -> Option<f64> {
        (R::HOURGLASS > 0).then_some(self.hourglass_energy)
    }

    fn viscous_pressure(&self) -> &[f64] {
        &self.columns.viscous
    }

    fn restore_viscous_pressure(&mut self, values: &[f64]) {
        self.columns.viscous.copy_from_slice(values);
    }

    fn hourglass_state(&self) -> Option<(Vec<f64>, f64)> {
        (R::HOURGLASS > 0).then(|| (self.columns.hourglass.clone(), self.hourglass_energy))
    }

    fn restore_hourglass_state(&mut self, forces: Vec<f64>, work: f64) {
        if R::HOURGLASS > 0 {
            self.columns.hourglass = forces;
            self.hourglass_energy = work;
        }
    }

    fn point_probe(&self, model: &Model, probe: &Probe) -> Option<f64> {
        let scalars = [&self.columns.eps_p[..], &self.columns.temperature[..]];
        point_statistic(&self.layout, model, probe, (R::POINTS, scalars), |e, q| {
            self.point(e, q)
        })
    }

    fn eq_plastic_strain(&self) -> Vec<f64> {
        self.columns.eps_p.clone()
    }

    fn mass_scaling(&self) -> Option<&ElementScaling> {
        self.scaling.as_ref()
    }

    fn mass_scaling_mut(&mut self) -> Option<&mut ElementScaling> {
        self.scaling.as_mut()
    }

    fn tightness(&self) -> Option<&Tightness> {
        self.tightness.as_ref()
    }

    fn restore_tightness(&mut self, tightness: Tightness) {
        if self.tightness.is_some() {
            self.tightness = Some(tightness);
        }
    }

    fn partial(&mut self) -> Option<&mut dyn PartialKernel> {
        Some(self)
    }
}

impl<R: Rule> PartialKernel for Skeleton<R> {
    fn element_nodes(&self) -> &[[u32; 4]] {
        &self.layout.nodes
    }

    fn frequency_of(&self, x: &[[f64; 2]], e: usize) -> Result<f64, ElementFailure> {
        let bound = self.frequency(x, e)?;
        Ok(match &self.tightness {
            Some(tight) => {
                // the ratio against the undamped bound scales the damped one, as `apply`
                let nodes = self.layout.nodes[e].map(|n| x[n as usize]);
                let undamped = bound * self.damping[e];
                bound * tight.ratio_for(e, undamped, || self.exact_stiffness(&nodes, e))
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
        let mut total = self.step_list(elements, (x, du), dt, (omega_squared, false))?;
        if let Some(mut tight) = self.tightness.take() {
            let end = |e: usize| end_nodes(self.layout.nodes[e], x, du);
            (total.omega_squared, total.critical_element) =
                tight.apply_subset(elements, (omega_squared, &self.damping), |e| {
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
