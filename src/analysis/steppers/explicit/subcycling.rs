//! Multi-time-step central difference (subcycling; docs/theory.md 8.7c): each element steps
//! with its own stable step rounded down to a power of two of the shortest, each node with
//! the finest of its elements (Belytschko, Yen & Mullen 1979, nodal partition with linear
//! interpolation).
//!
//! Legend
//! ```text
//! dt_e     element e's own stable step 2 / omega_e (its bound where the levels were formed)
//! k_e      floor(log2(dt_e / dt_min)), at most `levels`
//! k_n      min of k_e over node n's elements; 0 on the contact surfaces and for the nodes
//!          of moving prescribed displacements; then graded: across an element, levels at
//!          most one apart, the coarser within INTERFACE_MARGIN of the element's own step
//! l_e      min of k_n over element e's nodes: the level e steps at (l_e <= k_e)
//! H, h     the major step (the clock's rule on 2^K dt_min, K the largest k_n), h = H / 2^K
//! node n   velocity Verlet over its own step D_n = 2^k_n h from t_s: v_1/2 = v + D_n/2 a,
//!          x(t) = x_s + (t - t_s) v_1/2 in between (what a finer element reads),
//!          at t_s + D_n: a = (f_ext - f_int - a_R m v_1/2) / m, v = v_1/2 + D_n/2 a
//! element  at substep j with 2^l_e | j: from x(t_{j - 2^l_e}) by x(t_j) - x(t_{j - 2^l_e});
//!          every element of a node steps at the node's ends (l_e <= k_n), so f_int there is
//!          whole
//! ```
//! The levels are formed again at every major step from the frequency bounds of the
//! elements' last steps (all of them end there). With every element at level 0 this is the
//! single-step central difference, operation for operation.

use super::{DOF_CHUNK, Explicit, end_motion, partial_of, total_at};
use crate::analysis::steppers::carry::SubcyclingCarry;
use crate::analysis::steppers::clock::Step;
use crate::analysis::steppers::{StepError, loads};
use crate::analysis::summary::{Status, SubcyclingSummary};
use crate::assembly::StableStep;
use crate::assembly::explicit::{ExplicitKernel, PartialKernel, StepWork};
use crate::contact::Interfaces;
use crate::contact::geometry::Master;
use crate::element::Strain;
use crate::output::readable;
use crate::scene::model::Subcycling;
use crate::scene::{InputError, Load, Model};
use std::time::Instant;

/// The levels of a major step.
#[derive(Debug, Clone, PartialEq)]
pub struct Levels {
    /// k_n of every node.
    pub node: Vec<u8>,
    /// Per level k: the elements stepped at k, the nodes stepping at k, and the nodes the
    /// elements of k read (each ascending).
    pub elements: Vec<Vec<u32>>,
    pub nodes: Vec<Vec<u32>>,
    pub touched: Vec<Vec<u32>>,
    /// The largest node level K.
    pub top: u32,
    /// The elements' own levels k_e the levels were formed from.
    pub own: Vec<u8>,
    /// The elements' own steps over the shortest, dt_e / dt_min, the interfaces were graded
    /// with (`grade_interfaces`).
    pub ratios: Vec<f64>,
}

impl Levels {
    /// The levels of elements with the frequency bounds squared `omega_squared` and nodes
    /// `element_nodes` (over `node_count` nodes), the nodes `pinned` at level 0, at most
    /// `levels` above it.
    pub fn form(
        omega_squared: &[f64],
        element_nodes: &[[u32; 4]],
        pinned: &[bool],
        levels: u32,
    ) -> Levels {
        let own = own_levels(omega_squared, levels);
        let ratios = step_ratios(omega_squared);
        Levels::of_element_levels(own, &ratios, element_nodes, pinned)
    }

    /// The levels of elements whose own levels are `own` (k_e) and own steps `ratios` times
    /// the shortest: the nodes take the finest of their elements (pinned and element-less
    /// nodes 0), graded at the interfaces (`grade_interfaces`), the elements the finest of
    /// their nodes.
    pub fn of_element_levels(
        own: Vec<u8>,
        ratios: &[f64],
        element_nodes: &[[u32; 4]],
        pinned: &[bool],
    ) -> Levels {
        let mut node = vec![u8::MAX; pinned.len()];
        for (nodes, k) in element_nodes.iter().zip(&own) {
            for n in nodes {
                let n = *n as usize;
                node[n] = node[n].min(*k);
            }
        }
        for (k, pinned) in node.iter_mut().zip(pinned) {
            if *pinned || *k == u8::MAX {
                *k = 0;
            }
        }
        grade_interfaces(&mut node, ratios, element_nodes);
        let top = node.iter().copied().max().unwrap_or(0) as u32;
        let count = top as usize + 1;
        let (mut elements, mut nodes, mut touched) = (
            vec![Vec::new(); count],
            vec![Vec::new(); count],
            vec![Vec::new(); count],
        );
        // the levels whose elements read each node, as bits
        let mut reads = vec![0u32; node.len()];
        for (e, element) in element_nodes.iter().enumerate() {
            let level = element.iter().map(|n| node[*n as usize]).min().unwrap_or(0);
            elements[level as usize].push(e as u32);
            for n in element {
                reads[*n as usize] |= 1 << level;
            }
        }
        for (n, (k, reads)) in node.iter().zip(&reads).enumerate() {
            nodes[*k as usize].push(n as u32);
            for (level, list) in touched.iter_mut().enumerate() {
                if reads & (1 << level) != 0 {
                    list.push(n as u32);
                }
            }
        }
        Levels {
            node,
            elements,
            nodes,
            touched,
            top,
            own,
            ratios: ratios.to_vec(),
        }
    }
}

/// How far below its own step an element between two levels keeps its coarser nodes' step:
/// the coarser level's 2^k dt_min at most INTERFACE_MARGIN dt_e (docs/theory.md 8.7c,
/// "Which layouts grow": stable at 0.8 on every layout tried, not at 0.9).
pub const INTERFACE_MARGIN: f64 = 0.8;

/// Each element's own stable step over the shortest, dt_e / dt_min (infinite for an element
/// that does not vibrate).
pub fn step_ratios(omega_squared: &[f64]) -> Vec<f64> {
    let largest = omega_squared.iter().copied().fold(0.0, f64::max);
    omega_squared
        .iter()
        .map(|w| {
            if *w > 0.0 {
                (largest / w).sqrt()
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

/// Lowers node levels until every element whose nodes step on different levels (an
/// interface) has them on two neighbouring levels, the coarser stepping at most
/// INTERFACE_MARGIN of the element's own step (`ratios`: dt_e / dt_min): with the levels as
/// the nodes' finest elements give them, the nodal partition's linear interpolation grew on
/// some layouts, and graded so it has on none tried (docs/theory.md 8.7c, "Which layouts
/// grow"). Levels only fall, element by element from a work list, so it ends.
fn grade_interfaces(node: &mut [u8], ratios: &[f64], element_nodes: &[[u32; 4]]) {
    // the elements of each node (compressed rows)
    let mut start = vec![0u32; node.len() + 1];
    for nodes in element_nodes {
        for n in nodes {
            start[*n as usize + 1] += 1;
        }
    }
    for i in 0..node.len() {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut elements_of = vec![0u32; start[node.len()] as usize];
    for (e, nodes) in element_nodes.iter().enumerate() {
        for n in nodes {
            elements_of[fill[*n as usize] as usize] = e as u32;
            fill[*n as usize] += 1;
        }
    }
    let mut queued = vec![true; element_nodes.len()];
    let mut work: Vec<u32> = (0..element_nodes.len() as u32).rev().collect();
    while let Some(e) = work.pop() {
        let e = e as usize;
        queued[e] = false;
        let nodes = element_nodes[e];
        let levels = nodes.map(|n| node[n as usize]);
        let (lo, hi) = (*levels.iter().min().unwrap(), *levels.iter().max().unwrap());
        if lo == hi {
            continue;
        }
        // the finest level whose step keeps the margin: floor(log2(margin dt_e / dt_min))
        let margin = INTERFACE_MARGIN * ratios[e];
        let kept = if margin >= 1.0 {
            margin.log2().floor().min(f64::from(u8::MAX)) as u8
        } else {
            0
        };
        let allowed = lo.max((lo + 1).min(kept));
        for n in nodes {
            let n = n as usize;
            if node[n] > allowed {
                node[n] = allowed;
                for f in &elements_of[start[n] as usize..start[n + 1] as usize] {
                    if !queued[*f as usize] {
                        queued[*f as usize] = true;
                        work.push(*f);
                    }
                }
            }
        }
    }
}

/// k_e = floor(log2(dt_e / dt_min)) of every element, at most `levels` (an element that does
/// not vibrate: `levels`).
pub fn own_levels(omega_squared: &[f64], levels: u32) -> Vec<u8> {
    let largest = omega_squared.iter().copied().fold(0.0, f64::max);
    omega_squared
        .iter()
        .map(|w| {
            if *w <= 0.0 {
                return levels as u8;
            }
            // (dt_e / dt_min)^2 = largest / w = m 2^p with m in [1, 2): floor(log2 of its
            // square root) = floor(p / 2), p the binary exponent
            let ratio_squared = largest / w;
            let exponent = ((ratio_squared.to_bits() >> 52) & 0x7ff) as i64 - 1023;
            ((exponent.max(0) / 2) as u32).min(levels) as u8
        })
        .collect()
}

/// What a subcycled run carries besides the single-step state.
pub(super) struct Subcycler {
    rule: Subcycling,
    /// The nodes kept at level 0.
    pinned: Vec<bool>,
    /// Whether the scene prescribes moving displacements (their nodes are pinned and take
    /// the curve's value at every substep).
    moving: bool,
    pub(super) levels: Levels,
    /// The frequency bound squared of every element's last step.
    omega_squared: Vec<f64>,
    /// The start positions and the increments an element step reads (at its nodes).
    x: Vec<[f64; 2]>,
    du: Vec<f64>,
    /// The last substep's length (the contact's impact conditions read it).
    last_substep: f64,
    /// Substeps and element updates so far.
    pub(super) substeps: u64,
    pub(super) element_updates: u64,
    /// The largest ratio of an element's step to its own stable step on the configuration
    /// the step ended in (the level was formed before; above 1 the element outgrew it).
    largest_step_ratio: f64,
}

impl Subcycler {
    /// The subcycling `rule` of `model`, its levels formed on the initial positions `x`;
    /// refuses loads it cannot follow (forces between the nodes' steps).
    pub(super) fn new(
        model: &Model,
        rule: Subcycling,
        kernel: &mut dyn ExplicitKernel,
        x: &[[f64; 2]],
    ) -> Result<Subcycler, InputError> {
        let Start {
            levels,
            omega_squared,
            pinned,
            moving,
        } = start(model, rule, kernel, x)?;
        Ok(Subcycler {
            rule,
            pinned,
            moving,
            levels,
            omega_squared,
            x: vec![[0.0; 2]; x.len()],
            du: vec![0.0; 2 * x.len()],
            last_substep: 0.0,
            substeps: 0,
            element_updates: 0,
            largest_step_ratio: 0.0,
        })
    }

    /// The stable step of the finest level (the clock's limit: the major step is 2^K of its
    /// steps, `Clock::take_together`), named by its element.
    pub(super) fn bound(&self, kernel: &dyn ExplicitKernel) -> StableStep {
        let mut worst = StepWork::default();
        for (e, w) in self.omega_squared.iter().enumerate() {
            worst.observe(*w, e);
        }
        let (body, element) = kernel.locate(worst.critical_element);
        StableStep::of_frequency(worst.omega_squared, body, element)
    }

    /// The substeps of a major step, 2^K.
    pub(super) fn substeps_per_step(&self) -> u64 {
        1u64 << self.levels.top
    }

    /// What a checkpoint keeps.
    pub(super) fn carry(&self) -> SubcyclingCarry {
        SubcyclingCarry {
            omega_squared: self.omega_squared.clone(),
            ratios: self.levels.ratios.clone(),
            last_substep: self.last_substep,
            substeps: self.substeps,
            element_updates: self.element_updates,
            largest_step_ratio: self.largest_step_ratio,
        }
    }

    /// Takes a checkpoint's carry back: the levels are those its bounds' own levels and its
    /// graded ratios form, as they were. False when the carry is not of this kernel's
    /// elements (a mesh changed since the checkpoint).
    pub(super) fn restore(
        &mut self,
        carry: SubcyclingCarry,
        kernel: &mut dyn PartialKernel,
    ) -> bool {
        let elements = self.omega_squared.len();
        if carry.omega_squared.len() != elements || carry.ratios.len() != elements {
            return false;
        }
        self.omega_squared = carry.omega_squared;
        self.last_substep = carry.last_substep;
        self.substeps = carry.substeps;
        self.element_updates = carry.element_updates;
        self.largest_step_ratio = carry.largest_step_ratio;
        let own = own_levels(&self.omega_squared, self.rule.levels);
        self.levels =
            Levels::of_element_levels(own, &carry.ratios, kernel.element_nodes(), &self.pinned);
        true
    }

    /// summary.json `subcycling` of a kernel of `elements` elements.
    pub(super) fn summary(&self, elements: usize) -> SubcyclingSummary {
        SubcyclingSummary {
            substeps: self.substeps,
            element_updates: self.element_updates,
            single_step_updates: self.substeps * elements as u64,
            levels: self.levels.top,
            elements_per_level: self.levels.elements.iter().map(Vec::len).collect(),
            largest_step_ratio: self.largest_step_ratio,
        }
    }

    /// The levels of the next major step, from the elements' last bounds (formed again only
    /// when an element's own level changed).
    fn reform(&mut self, kernel: &mut dyn PartialKernel) {
        let own = own_levels(&self.omega_squared, self.rule.levels);
        if own != self.levels.own {
            let ratios = step_ratios(&self.omega_squared);
            self.levels =
                Levels::of_element_levels(own, &ratios, kernel.element_nodes(), &self.pinned);
        }
    }
}

/// What a subcycled run starts with: its levels, the elements' frequency bounds they come
/// from, the nodes kept on level 0 and whether prescribed displacements move (`pinned_nodes`).
pub struct Start {
    pub levels: Levels,
    pub omega_squared: Vec<f64>,
    pinned: Vec<bool>,
    moving: bool,
}

/// The start of a subcycled run of `model` (`rule`, the kernel `kernel` on the positions
/// `x`); refuses loads it cannot follow (forces between the nodes' steps). What `impact
/// check` reports.
pub fn start(
    model: &Model,
    rule: Subcycling,
    kernel: &mut dyn ExplicitKernel,
    x: &[[f64; 2]],
) -> Result<Start, InputError> {
    let refuse = |message: String| InputError::new(&model.file, message);
    if super::loads::has_external_force(model) {
        return Err(refuse(
            "analysis.subcycling: steps the nodes at different times, and the scene's forces, tractions or \
             pressures would act on nodes between their steps; remove subcycling or the loads"
                .into(),
        ));
    }
    let elements = kernel.elements();
    let Some(partial) = kernel.partial() else {
        return Err(refuse(
            "analysis.subcycling: runs in the finite-strain explicit Quad4 kernels".into(),
        ));
    };
    let mut omega_squared = vec![0.0; elements];
    partial
        .frequencies(x, &mut omega_squared)
        .map_err(|err| refuse(err.to_string()))?;
    let (pinned, moving) = pinned_nodes(model, &model.interfaces());
    let levels = Levels::form(
        &omega_squared,
        partial.element_nodes(),
        &pinned,
        rule.levels,
    );
    Ok(Start {
        levels,
        omega_squared,
        pinned,
        moving,
    })
}

/// The nodes subcycling keeps at level 0: those of the contact surfaces (both sides, so the
/// correction sees every node it moves at the substep; with a deformable master the whole
/// outlines of both bodies, which its inside tests and penetration checks read at the
/// substep), and of prescribed displacements (Displacement, Rotation and Affine loads); and
/// whether there are such displacements.
fn pinned_nodes(model: &Model, interfaces: &Interfaces) -> (Vec<bool>, bool) {
    let mut pinned = vec![false; model.node_count];
    for pair in &interfaces.pairs {
        for n in &pair.slaves {
            pinned[*n] = true;
        }
        match &pair.master {
            Master::Segments {
                edges, boundary, ..
            } => {
                // a deformable master: its body's outline (the corner tests) and the slave
                // body's (the penetration checks) are read where the correction is made
                let slave_outline = &interfaces.bodies[pair.slave_body].boundary;
                for n in edges.iter().chain(boundary).chain(slave_outline).flatten() {
                    pinned[*n] = true;
                }
            }
            Master::Nodes { nodes, .. } => {
                for n in nodes {
                    pinned[*n] = true;
                }
            }
            Master::Obstacle(_) => {}
        }
    }
    let mut moving = false;
    for load in &model.loads {
        if let Load::Displacement { nodes, .. }
        | Load::Rotation { nodes, .. }
        | Load::Affine { nodes, .. } = load
        {
            moving = true;
            for n in nodes {
                pinned[*n] = true;
            }
        }
    }
    (pinned, moving)
}

/// The sums of a major step's node updates, per `DOF_CHUNK` DOFs (added in chunk order at
/// the end, as the single step adds its chunks: one level gives its bits).
struct NodeSums {
    /// du . (F_{n+1} + F_n) over every node step (half of it is the external work).
    work: Vec<f64>,
}

impl NodeSums {
    fn new(dofs: usize) -> NodeSums {
        NodeSums {
            work: vec![0.0; dofs.div_ceil(DOF_CHUNK).max(1)],
        }
    }
}

impl Explicit<'_> {
    /// One major step of the subcycled run (see the legend): the clock's step over 2^K
    /// substeps, the history row at its end.
    pub(super) fn advance_subcycled(
        &mut self,
        mut sub: Subcycler,
        clock_step: Step,
    ) -> Result<(), StepError> {
        let result = self.major_step(&mut sub, clock_step);
        self.subcycler = Some(sub);
        result
    }

    fn major_step(&mut self, sub: &mut Subcycler, clock_step: Step) -> Result<(), StepError> {
        let (t0, time) = (self.state.time, clock_step.end);
        let count = sub.substeps_per_step();
        let h = clock_step.length / count as f64;
        // every node starts a step
        for (n, k) in sub.levels.node.iter().enumerate() {
            let span = (1u64 << k) as f64 * h;
            for d in [2 * n, 2 * n + 1] {
                self.v_half[d] = self.v[d] + 0.5 * span * self.a[d];
            }
        }
        let mut sums = NodeSums::new(self.v.len());
        for j in 1..=count {
            let t = if j == count { time } else { t0 + j as f64 * h };
            self.substep(sub, (j, h, t), &mut sums)?;
        }
        self.state.time = time;
        self.synced = false;
        self.end_major_step(sub, &sums, h);
        let kernel = partial_of(&mut self.kernel);
        sub.reform(kernel);
        let bound = sub.bound(self.kernel.as_ref());
        self.step += 1;
        self.clock.took(clock_step, bound);
        self.clock.take_together(sub.substeps_per_step());
        Ok(())
    }

    /// Substep j (length h, ending at t): the level-0 increments and the contact, the
    /// elements of every level whose step ends here, then its nodes.
    fn substep(
        &mut self,
        sub: &mut Subcycler,
        (j, h, t): (u64, f64, f64),
        sums: &mut NodeSums,
    ) -> Result<(), StepError> {
        let finest = (j.trailing_zeros()).min(sub.levels.top);
        for n in &sub.levels.nodes[0] {
            let n = *n as usize;
            for d in [2 * n, 2 * n + 1] {
                self.du[d] = h * self.v_half[d];
            }
        }
        if sub.moving {
            for (dof, value) in loads::prescribed(self.model, &self.initial, t) {
                if sub.levels.node[dof / 2] == 0 {
                    self.du[dof] = value - self.state.displacement[dof];
                }
            }
        }
        if !self.model.contacts.is_empty() {
            let start = Instant::now();
            self.contact_correction((h, sub.last_substep), t, Some(&sub.levels.nodes[0]));
            crate::profile::add(crate::profile::Phase::Contact, start);
        }
        for k in 0..=finest {
            self.step_level(sub, (j, k, h), t)?;
        }
        for k in 0..=finest {
            self.finish_nodes(sub, (j, k, h), sums);
        }
        sub.last_substep = h;
        sub.substeps += 1;
        Ok(())
    }

    /// The elements of level k over their step ending at substep j.
    fn step_level(
        &mut self,
        sub: &mut Subcycler,
        (j, k, h): (u64, u32, f64),
        t: f64,
    ) -> Result<(), StepError> {
        let span = (1u64 << k) as f64 * h;
        let levels = &sub.levels;
        for n in &levels.touched[k as usize] {
            let n = *n as usize;
            let level = levels.node[n] as u32;
            // the node's step began at substep s; the element's at j - 2^k
            let s = ((j - 1) >> level) << level;
            let offset = j - (1u64 << k) - s;
            let x = self.state.coordinates[n];
            for c in 0..2 {
                let d = 2 * n + c;
                sub.x[n][c] = if offset == 0 {
                    x[c]
                } else {
                    x[c] + (offset as f64 * h) * self.v_half[d]
                };
                sub.du[d] = if level == 0 {
                    self.du[d]
                } else {
                    span * self.v_half[d]
                };
            }
        }
        let elements = &levels.elements[k as usize];
        let kernel = partial_of(&mut self.kernel);
        let work = crate::profile::time(crate::profile::Phase::Assembly, || {
            crate::profile::count_elements(elements.len());
            kernel.step_elements(elements, (&sub.x, &sub.du), span, &mut sub.omega_squared)
        })
        .map_err(|err| StepError {
            status: Status::Diverged,
            message: format!("at t = {}: {err}", readable(t)),
            frame: false,
        })?;
        sub.element_updates += elements.len() as u64;
        // the step against the stable step the elements ended with (2 / omega)
        sub.largest_step_ratio = sub
            .largest_step_ratio
            .max(0.5 * span * work.omega_squared.sqrt());
        self.state.internal_work += work.internal;
        self.state.plastic_work += work.plastic;
        work.commit_bodies(&mut self.state);
        self.energies.bulk_viscosity_work += work.viscous;
        Ok(())
    }

    /// The nodes of level k at the end of their step (substep j): the internal force of
    /// their elements' steps just taken, the motion, the work; then the next step begins
    /// unless the major step ends.
    fn finish_nodes(&mut self, sub: &Subcycler, (j, k, h): (u64, u32, f64), sums: &mut NodeSums) {
        let span = (1u64 << k) as f64 * h;
        let nodes = &sub.levels.nodes[k as usize];
        let kernel = partial_of(&mut self.kernel);
        kernel.gather_nodes(nodes, &mut self.internal);
        let a_r = self.spec.rayleigh[0];
        let last = j == 1u64 << sub.levels.top;
        let finite = self.spec.geometry == Strain::Finite;
        for n in nodes {
            let n = *n as usize;
            for c in 0..2 {
                let d = 2 * n + c;
                let du = if k == 0 {
                    self.du[d]
                } else {
                    span * self.v_half[d]
                };
                if finite {
                    self.state.coordinates[n][c] += du;
                }
                self.state.displacement[d] += du;
                let forces = (self.mass[d], (self.external[d], self.internal[d]));
                let motion = (self.v_half[d], self.v[d], du);
                (self.a[d], self.v[d]) = end_motion(self.free[d], forces, motion, (span, a_r));
                let total = total_at(self.dof(d), a_r);
                sums.work[d / DOF_CHUNK] += du * (total + self.last_total[d]);
                self.last_total[d] = total;
                if !last {
                    self.v_half[d] = self.v[d] + 0.5 * span * self.a[d];
                }
            }
        }
    }

    /// The energies at the end of a major step (every node has ended a step there).
    fn end_major_step(&mut self, sub: &Subcycler, sums: &NodeSums, h: f64) {
        let (v, m, a, free) = (&self.v, &self.mass, &self.a, &self.free);
        // sums over all DOFs per `DOF_CHUNK` chunk, the chunks added in order (as the single
        // step adds them)
        let chunked = |term: &dyn Fn(usize) -> f64| {
            (0..v.len())
                .step_by(DOF_CHUNK)
                .map(|start| {
                    let mut sum = 0.0;
                    for d in start..(start + DOF_CHUNK).min(v.len()) {
                        sum += term(d);
                    }
                    sum
                })
                .fold(0.0, |total, chunk| total + chunk)
        };
        let kinetic = chunked(&|d| m[d] * v[d] * v[d]);
        let free_term = |d: usize| if free[d] { m[d] * a[d] * a[d] } else { 0.0 };
        // the shadow h^2 / 8 a.M a with each node's own step: on one level as the single
        // step sums it, on several per level
        let shadow = if sub.levels.top == 0 {
            0.125 * h * h * chunked(&free_term)
        } else {
            let mut shadow = 0.0;
            for (k, nodes) in sub.levels.nodes.iter().enumerate() {
                let mut sum = 0.0;
                for n in nodes {
                    let d = 2 * *n as usize;
                    sum += free_term(d) + free_term(d + 1);
                }
                let span = (1u64 << k) as f64 * h;
                shadow += 0.125 * span * span * sum;
            }
            shadow
        };
        let work = sums.work.iter().fold(0.0, |total, chunk| total + chunk);
        self.close_step_energies(0.5 * work, (0.5 * kinetic, shadow));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The level each element steps at (l_e) in `levels`.
    fn element_levels(levels: &Levels, elements: usize) -> Vec<u8> {
        let mut level = vec![0u8; elements];
        for (k, list) in levels.elements.iter().enumerate() {
            for e in list {
                level[*e as usize] = k as u8;
            }
        }
        level
    }

    /// A strip of 4 elements in a row (nodes 0-4 bottom, 5-9 top).
    fn strip() -> Vec<[u32; 4]> {
        (0..4u32).map(|e| [e, e + 1, e + 6, e + 5]).collect()
    }

    /// Levels: an element twice as stiff as the rest takes level 0 and drags its nodes'
    /// other elements to it; a pinned node does the same; nodes take the finest of their
    /// elements, then the interfaces are graded: across an element its nodes' levels differ
    /// by at most one, the coarser within INTERFACE_MARGIN of the element's own step.
    #[test]
    fn levels_follow_the_finest_element_of_each_node() {
        // dt_e: 1, 4, 4, 8 (omega^2 ~ 1 / dt^2)
        let omega: Vec<f64> = [1.0, 4.0, 4.0, 8.0]
            .iter()
            .map(|dt| 1.0 / (dt * dt))
            .collect();
        let own = own_levels(&omega, 5);
        assert_eq!(own, vec![0, 2, 2, 3]);
        let levels = Levels::form(&omega, &strip(), &[false; 10], 5);
        // the finest of their elements: nodes 0, 1 (5, 6) level 0; 2 (7): min(2, 2) = 2;
        // 3 (8): 2; 4 (9): 3. Graded: element 1 (dt_e 4: its margin's level is
        // floor(log2(0.8 * 4)) = 1) joins levels 0 and 2, so node 2 falls to min(0 + 1, 1);
        // element 2 (margin level 1) then joins 1 and 2: node 3 to 1; element 3 (dt_e 8:
        // floor(log2 6.4) = 2) joins 1 and 3: node 4 to min(1 + 1, 2) = 2
        assert_eq!(levels.node, vec![0, 0, 1, 1, 2, 0, 0, 1, 1, 2]);
        // element 1 has nodes 1 and 2: level 0; element 2: 1; element 3: nodes 3, 4: 1
        assert_eq!(element_levels(&levels, 4), vec![0, 0, 1, 1]);
        assert_eq!(levels.top, 2);
        // where the margin binds: dt_e 1, 2, 8, 8 (own 0, 1, 3, 3): node 2, level 1 by its
        // elements, sits on element 1 (dt_e 2: floor(log2 1.6) = 0) beside level 0, so it
        // falls to 0; node 3 (3) beside it on element 2 to 0 + 1; node 4 (3) to 1 + 1
        let omega: Vec<f64> = [1.0, 2.0, 8.0, 8.0]
            .iter()
            .map(|dt| 1.0 / (dt * dt))
            .collect();
        assert_eq!(own_levels(&omega, 5), vec![0, 1, 3, 3]);
        let graded = Levels::form(&omega, &strip(), &[false; 10], 5);
        assert_eq!(graded.node, vec![0, 0, 0, 1, 2, 0, 0, 0, 1, 2]);
        let omega: Vec<f64> = [1.0, 4.0, 4.0, 8.0]
            .iter()
            .map(|dt| 1.0 / (dt * dt))
            .collect();
        let mut pinned = [false; 10];
        pinned[3] = true;
        let levels = Levels::form(&omega, &strip(), &pinned, 5);
        assert_eq!(element_levels(&levels, 4), vec![0, 0, 0, 0]);
        // capped
        assert_eq!(own_levels(&omega, 1), vec![0, 1, 1, 1]);
        // against the logarithm: ratios just below and above the powers of two
        for ratio in [1.0, 1.999, 2.0, 2.001, 3.99, 4.0, 7.9, 8.1, 1000.0] {
            let omega = [1.0, 1.0 / (ratio * ratio)];
            let expected = (ratio as f64).log2().floor() as u8;
            assert_eq!(own_levels(&omega, 20)[1], expected, "ratio {ratio}");
        }
    }
}
