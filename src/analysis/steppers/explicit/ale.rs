//! Central difference's ALE step (docs/theory.md 8.11): every `analysis.ale.every` steps the
//! nodes move by the smoother (`crate::ale::smooth`) and the element state, the element
//! masses and the nodal velocities follow them by the conservative remap
//! (`crate::ale::remap`). Which nodes may move is decided once: a node stays where a load,
//! a prescribed motion or a deformable contact surface acts on it or where a frictional
//! obstacle holds it; a support's components stay; boundary nodes slide along the boundary
//! (the frictionless wall included) where it turns by less than `slide_angle`.
//!
//! The element quantities remapped are the means of the element's points (stress, back
//! stress, equivalent plastic strain, temperature, thickness); each point then takes the
//! change of its element's mean, so the 2x2 kernel keeps its points' spread.

use crate::ale::{self, Freedom, Sweep, Topology};
use crate::analysis::summary::AleSummary;
use crate::assembly::{ElementMasses, Kernel, State};
use crate::contact::geometry::{Friction, Master};
use crate::element::Voigt;
use crate::material::{PointState, StressCondition, UpdateContext};
use crate::mesh::Cells;
use crate::scene::Model;
use crate::scene::model::{Ale, Body, Load};

/// The fields remapped per element: stress (4), back stress (4), equivalent plastic strain,
/// temperature, thickness.
const FIELDS: usize = 11;

/// The ALE steps of a run: the topology and freedom of each body's nodes, and the counts.
pub struct MeshMotion {
    spec: Ale,
    bodies: Vec<BodyMotion>,
    summary: AleSummary,
}

struct BodyMotion {
    topology: Topology,
    held: Vec<bool>,
    fixed: Vec<[bool; 2]>,
    axisymmetric: bool,
}

/// What one ALE step changed of the run's totals.
#[derive(Debug, Clone, Copy, Default)]
pub struct Remapped {
    pub nodes_moved: usize,
}

impl MeshMotion {
    /// The motion of `model`'s Quad4 bodies (the scene refuses rods with `analysis.ale`).
    pub fn new(model: &Model, spec: Ale) -> MeshMotion {
        let held = held_nodes(model);
        let mut fixed = vec![[false; 2]; model.node_count];
        for d in &model.fixed_dofs {
            fixed[d / 2][d % 2] = true;
        }
        let bodies = model
            .bodies
            .iter()
            .map(|body| {
                let Cells::Quad4(cells) = &body.mesh.cells else {
                    unreachable!("the scene refuses rods with analysis.ale")
                };
                let range = body.node_offset..body.node_offset + body.mesh.nodes.len();
                BodyMotion {
                    topology: Topology::new(cells, body.mesh.nodes.len()),
                    held: held[range.clone()].to_vec(),
                    fixed: fixed[range].to_vec(),
                    axisymmetric: body.is_axisymmetric(),
                }
            })
            .collect();
        MeshMotion {
            spec,
            bodies,
            summary: AleSummary {
                remaps: 0,
                node_moves: 0,
                largest_courant: 0.0,
                boundary_volume_change: 0.0,
            },
        }
    }

    /// Whether step `step` (counted from 1) ends with an ALE step.
    pub fn due(&self, step: usize) -> bool {
        step % self.spec.every == 0
    }

    pub fn summary(&self) -> AleSummary {
        self.summary.clone()
    }

    /// The counts of a resumed run as its checkpoint had them.
    pub fn restore(&mut self, summary: AleSummary) {
        self.summary = summary;
    }

    /// Per body, the nodes held, sliding along the boundary and free inside (`impact check`).
    pub fn node_classes(&self) -> Vec<[usize; 3]> {
        self.bodies
            .iter()
            .map(|b| {
                let t = &b.topology;
                let held = b.held.iter().filter(|h| **h).count();
                let boundary = (0..t.nodes)
                    .filter(|n| !b.held[*n] && t.on_boundary[*n])
                    .count();
                [held, boundary, t.nodes - held - boundary]
            })
            .collect()
    }

    /// One ALE step on the committed `state` (its points written by the kernel): the nodes
    /// smoothed, the points, the element masses and the velocities `velocity` (all DOFs; the
    /// non-`free` ones kept) remapped.
    pub fn apply(
        &mut self,
        model: &Model,
        state: &mut State,
        masses: &mut ElementMasses,
        (velocity, free): (&mut [f64], &[bool]),
        dt: f64,
    ) -> Remapped {
        let mut remapped = Remapped::default();
        let mut coordinates = state.coordinates.clone();
        let mut sweeps = Vec::with_capacity(self.bodies.len());
        for (body, motion) in model.bodies.iter().zip(&self.bodies) {
            let range = body.node_offset..body.node_offset + body.mesh.nodes.len();
            let old = &state.coordinates[range.clone()];
            let freedom = Freedom {
                held: &motion.held,
                fixed: &motion.fixed,
            };
            let new = ale::smooth(&motion.topology, old, &freedom, &self.spec.rules);
            let moved = old.iter().zip(&new).filter(|(a, b)| a != b).count();
            remapped.nodes_moved += moved;
            coordinates[range].copy_from_slice(&new);
            sweeps.push(
                (moved > 0).then(|| Sweep::new(&motion.topology, old, &new, motion.axisymmetric)),
            );
        }
        for (b, sweep) in sweeps.iter().enumerate() {
            let Some(sweep) = sweep else { continue };
            let motion = &self.bodies[b];
            let t = &motion.topology;
            self.summary.largest_courant = self.summary.largest_courant.max(sweep.courant(t));
            remap_points(t, sweep, state, b);
            return_to_yield(&model.bodies[b], &mut state.bodies[b].points, dt);
            remap_mass_and_motion(model, b, (t, sweep), &coordinates, masses, (velocity, free));
            let geometric: f64 = sweep.new.iter().map(|m| m.volume).sum();
            let carried: f64 = sweep.volume_in(t).iter().sum();
            self.summary.boundary_volume_change += (geometric - carried) / geometric;
        }
        for (n, x) in coordinates.iter().enumerate() {
            let before = state.coordinates[n];
            state.displacement[2 * n] += x[0] - before[0];
            state.displacement[2 * n + 1] += x[1] - before[1];
        }
        state.coordinates = coordinates;
        self.summary.remaps += 1;
        self.summary.node_moves += remapped.nodes_moved as u64;
        remapped
    }
}

/// Body `b`'s element masses moved by the sweep, their corner shares those of the new shapes
/// (`coordinates`: all nodes, new), and its nodal velocities (the non-`free` DOFs kept).
fn remap_mass_and_motion(
    model: &Model,
    b: usize,
    (t, sweep): (&Topology, &Sweep),
    coordinates: &[[f64; 2]],
    masses: &mut ElementMasses,
    (velocity, free): (&mut [f64], &[bool]),
) {
    let body = &model.bodies[b];
    let kernel = Kernel::of(body);
    let old: Vec<[f64; 4]> = (0..body.elements())
        .map(|e| {
            let m = masses.of(model, b, e);
            [m[0], m[1], m[2], m[3]]
        })
        .collect();
    let mut mass: Vec<f64> = old.iter().map(|m| m.iter().sum()).collect();
    let flux = sweep.remap_mass(t, &mut mass);
    // the lumped shares of the new shape; an element that the one-point kernel's steps left
    // folded at a 2x2 Gauss point (its centroid is what that kernel integrates) keeps the
    // shares it had
    let new: Vec<[f64; 4]> = (0..body.elements())
        .map(|e| {
            let shape = kernel
                .lumped_mass(body, coordinates, e)
                .unwrap_or_else(|_| old[e].to_vec());
            let total: f64 = shape.iter().sum();
            [0, 1, 2, 3].map(|a| shape[a] / total * mass[e])
        })
        .collect();
    let range = 2 * body.node_offset..2 * (body.node_offset + t.nodes);
    let mut v = velocity[range.clone()].to_vec();
    ale::remap_velocity(t, sweep, (&old, &new), &flux, &mut v);
    for (i, value) in range.zip(v) {
        if free[i] {
            velocity[i] = value;
        }
    }
    masses.replace(b, new.iter().flatten().copied().collect());
}

/// The points of body `b` remapped: each element's means of the fields moved by the sweep,
/// each point changed by its element's change.
fn remap_points(t: &Topology, sweep: &Sweep, state: &mut State, b: usize) {
    let body = &mut state.bodies[b];
    let per = body.points.len() / t.cells.len();
    let mut means = vec![0.0; t.cells.len() * FIELDS];
    for e in 0..t.cells.len() {
        let mean = &mut means[e * FIELDS..(e + 1) * FIELDS];
        for k in e * per..(e + 1) * per {
            let p = &body.points[k];
            for i in 0..4 {
                mean[i] += p.stress[i];
                mean[4 + i] += p.back_stress[i];
            }
            mean[8] += p.eq_plastic_strain;
            mean[9] += p.temperature;
            mean[10] += body.thickness[k];
        }
        mean.iter_mut().for_each(|m| *m /= per as f64);
    }
    let mut after = means.clone();
    sweep.remap_intensive(t, &mut after, FIELDS);
    for e in 0..t.cells.len() {
        let change: Vec<f64> = (0..FIELDS)
            .map(|i| after[e * FIELDS + i] - means[e * FIELDS + i])
            .collect();
        for k in e * per..(e + 1) * per {
            let p = &mut body.points[k];
            for i in 0..4 {
                p.stress[i] += change[i];
                p.back_stress[i] += change[4 + i];
            }
            p.eq_plastic_strain = (p.eq_plastic_strain + change[8]).max(0.0);
            p.temperature += change[9];
            body.thickness[k] += change[10];
        }
    }
}

/// Each point's remapped stress and back stress returned to its yield surface: the means of
/// neighbouring points on yield surfaces of different sizes, and a point's own stress moved
/// by its element's change, can lie outside (Benson 1992, section 4.3). The material's own
/// update with no strain does it (`dt` the step, for a rate-dependent flow stress); the
/// remapped equivalent plastic strain and temperature stay as the remap left them (the
/// return is no plastic flow of the material, so no plastic work is booked).
fn return_to_yield(body: &Body, points: &mut [PointState], dt: f64) {
    let Some(formulation) = body.kind.formulation() else {
        return;
    };
    let context = UpdateContext {
        condition: StressCondition::of(formulation),
        dt,
    };
    let zero = Voigt::zeros();
    for p in points.iter_mut() {
        let returned = body.material.step(p, &zero, context).state;
        p.stress = returned.stress;
        p.back_stress = returned.back_stress;
    }
}

/// The nodes that keep their material: those a load or a prescribed motion acts on, those of
/// a deformable contact surface (slaves and masters: the pairs' own state follows the nodes),
/// and the slaves of an obstacle with friction (their stick follows the material).
fn held_nodes(model: &Model) -> Vec<bool> {
    let mut held = vec![false; model.node_count];
    let mut hold = |nodes: &mut dyn Iterator<Item = usize>| {
        for n in nodes {
            held[n] = true;
        }
    };
    for load in &model.loads {
        match load {
            Load::NodalForce { nodes, .. }
            | Load::Displacement { nodes, .. }
            | Load::Rotation { nodes, .. }
            | Load::Affine { nodes, .. } => hold(&mut nodes.iter().copied()),
            Load::Traction { edges, .. } | Load::Pressure { edges, .. } => {
                hold(&mut edges.iter().flatten().copied())
            }
        }
    }
    for pair in &model.contacts {
        match &pair.master {
            Master::Segments { edges, .. } => {
                hold(&mut pair.slaves.iter().copied());
                hold(&mut edges.iter().flatten().copied());
            }
            Master::Nodes { nodes, .. } => {
                hold(&mut pair.slaves.iter().copied());
                hold(&mut nodes.iter().copied());
            }
            Master::Obstacle(_) if pair.options.friction != Friction::None => {
                hold(&mut pair.slaves.iter().copied())
            }
            Master::Obstacle(_) => {}
        }
    }
    held
}

impl super::Explicit<'_> {
    /// The nodal masses (and their inverses on the free DOFs) as the sums of the element
    /// masses the remaps left: after an ALE step, and on resuming a run with them.
    pub(super) fn nodal_masses_from_elements(&mut self) {
        self.mass = self.masses.lumped(self.model);
        for (i, m) in self.mass.iter().enumerate() {
            self.inverse_mass[i] = if self.free[i] { 1.0 / m } else { 0.0 };
        }
    }

    /// The ALE step at the end of a step: the kernel's points into the state, the nodes
    /// smoothed and the state remapped, then the nodal masses, the kernel (its hourglass
    /// forces and viscous pressures kept), the internal force, the accelerations and the
    /// stable step of the new mesh. The kinetic energy the remap changes, with its shadow, is
    /// booked as `remap_loss`, so the balance of the step stays as it was.
    pub(super) fn ale_step(&mut self) -> Result<(), String> {
        let model = self.model;
        let Some(motion) = self.mesh_motion.as_mut() else {
            return Ok(());
        };
        self.kernel.write_points(model, &mut self.state);
        let before = self.energies.kinetic - self.energies.kinetic_shadow;
        let remapped = motion.apply(
            model,
            &mut self.state,
            &mut self.masses,
            (&mut self.v, &self.free),
            self.clock.last,
        );
        if remapped.nodes_moved == 0 {
            self.synced = true;
            return Ok(());
        }
        self.nodal_masses_from_elements();
        let hourglass = self.kernel.hourglass_state();
        let viscous = self.kernel.viscous_pressure().to_vec();
        // the tight step's ratios: each is taken again when its element's bound has moved by
        // 2 % (8.7), as the smoothed elements' have; the others stand
        let tightness = self.kernel.tightness().cloned();
        self.kernel = super::kernel_for(model, self.spec, &self.state, &self.masses);
        if let Some((forces, work)) = hourglass {
            // the hourglass forces resisted the hourglass shape of the old mesh, which the
            // smoother took out: kept, they push the material back into it (a rod's foot
            // curled into a cup at 400 m/s); the elements start again without them, as
            // LS-DYNA's ALE elements with viscous hourglass control do. Their work so far stays.
            self.kernel
                .restore_hourglass_state(vec![0.0; forces.len()], work);
        }
        if !viscous.is_empty() {
            self.kernel.restore_viscous_pressure(&viscous);
        }
        if let Some(tightness) = tightness {
            self.kernel.restore_tightness(tightness);
        }
        self.synced = true;
        self.kernel
            .internal_force(&self.state.coordinates, &mut self.internal)
            .map_err(|e| e.to_string())?;
        let a_r = self.spec.rayleigh[0];
        let (mut kinetic, mut shadow) = (0.0, 0.0);
        for i in 0..self.a.len() {
            let (m, v) = (self.mass[i], self.v[i]);
            if self.free[i] {
                self.a[i] = (self.external[i] - self.internal[i] - a_r * m * v) / m;
                shadow += m * self.a[i] * self.a[i];
            }
            kinetic += m * v * v;
        }
        let (kinetic, h) = (0.5 * kinetic, self.clock.last);
        let shadow = 0.125 * h * h * shadow;
        let dofs = super::DofArrays {
            free: &self.free,
            external: &self.external,
            internal: &self.internal,
            m: &self.mass,
            a: &self.a,
            v: &self.v,
        };
        self.last_total = super::total_force(&dofs, a_r);
        self.energies.remap_loss += before - (kinetic - shadow);
        self.energies.kinetic = kinetic;
        self.energies.kinetic_shadow = shadow;
        self.clock.limit = self
            .kernel
            .stable_step(&self.state.coordinates)
            .map_err(|e| e.to_string())?;
        Ok(())
    }
}
