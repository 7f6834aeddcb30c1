//! Explicit central difference with the lumped mass: no matrix, no factorization.
//!
//! Legend (velocity-Verlet form, identical displacements to the classical central difference)
//! ```text
//! v_{n+1/2} = v_n + dt/2 a_n
//! u_{n+1}   = u_n + dt v_{n+1/2}                 (prescribed DOFs: their curve value)
//! a_{n+1}   = (f_ext(t_{n+1}) - f_int(u_{n+1}) - a_R m v_{n+1/2}) / m
//! v_{n+1}   = v_{n+1/2} + dt/2 a_{n+1}
//! dt_crit   = 2 / omega_max,  omega_max^2 <= max_e lambda_max(M_e^-1 K_e)
//! ```
//! A dt above dt_crit is refused unless `allow_unstable`; then the run goes on and stops with
//! status `unstable` once the energy exceeds 100 times its reference (the initial kinetic
//! energy, the external work, or the internal energy at the first step, whichever is largest).

mod ale;
mod awake;
mod folds;
mod projectiles;
mod start;
mod subcycling;
mod vectors;

pub use ale::MeshMotion;
pub use start::Start;
pub use subcycling::Levels;

use vectors::{
    DOF_CHUNK, Dof, DofArrays, StateMotion, StepEnd, chunked_sum, commit_kernel_step, end_motion,
    predict, total_at, total_force,
};

use super::carry::{Carry, ExplicitCarry};
use super::clock::Clock;
use super::energies::{Energies, Motion};
use super::newton::Counters;
use super::{
    About, Report, Resume, RowFeatures, RunFeatures, StepError, Stepper, TimeStepReport, loads,
};
use crate::analysis::summary::{RunError, Status};
use crate::assembly::explicit::{ExplicitKernel, PartialKernel, kernel_for};
use crate::assembly::mass_scaling::{AddedAtRest, NodalMotion};
use crate::assembly::{ElementFailure, ElementMasses, Mass, StableStep, State, check_mass};
use crate::contact::explicit::{Predicted, moving_obstacle_steps};
use crate::contact::{ContactState, Interfaces};
use crate::output::readable;
use crate::scene::DynamicAnalysis;
use crate::scene::model::Probe;
use crate::scene::spec::MassKind;
use crate::scene::{InputError, Model};
use std::time::Instant;

/// Central difference: the state, the motion, the one-point kernel when asked, and what the
/// loop carries.
pub struct Explicit<'a> {
    model: &'a Model,
    spec: &'a DynamicAnalysis,
    interfaces: Interfaces,
    /// The nodes of the contact surfaces, ascending: the only ones a contact correction
    /// writes.
    surface_nodes: Vec<u32>,
    initial: Vec<[f64; 2]>,
    free: Vec<bool>,
    /// The lumped mass per DOF, and its inverse (zero on prescribed DOFs: contact
    /// corrections never move them).
    mass: Vec<f64>,
    inverse_mass: Vec<f64>,
    /// The stability limit of the initial configuration (None: not found, the automatic
    /// step; `initial_limit` finds it when an instability names it).
    dt_crit: Option<f64>,
    /// The one-point kernel keeps its element state in its own arrays (copied into `state`
    /// only when output reads stresses).
    kernel: Box<dyn ExplicitKernel + 'a>,
    synced: bool,
    state: State,
    v: Vec<f64>,
    a: Vec<f64>,
    internal: Vec<f64>,
    energies: Energies,
    initial_kinetic: f64,
    last_total: Vec<f64>,
    energy_reference: f64,
    /// Steps taken (with a fixed step the last one is shorter to end at end_time).
    step: usize,
    /// The step rule and the stable step of the committed configuration.
    clock: Clock,
    masses: ElementMasses,
    contact: ContactState,
    forces_applied: bool,
    /// Subcycling's levels and counts (None: every element steps together).
    subcycler: Option<subcycling::Subcycler>,
    /// The ALE steps (None: Lagrangian).
    mesh_motion: Option<ale::MeshMotion>,
    /// The rigid projectiles, whose carrier nodes' DOFs follow the model's in the driver's
    /// vectors (`projectiles`).
    carriers: projectiles::Carriers,
    /// The pool's other threads kept awake between the step's parallel loops (None: one
    /// thread).
    awake: Option<awake::Awake>,
    // the step's vectors, allocated once
    v_half: Vec<f64>,
    du: Vec<f64>,
    external: Vec<f64>,
    total: Vec<f64>,
}

impl<'a> Explicit<'a> {
    /// The stability limit of the initial configuration: the one a fixed step was checked
    /// against, or (the automatic step) found now (NaN where an element cannot give it).
    fn initial_limit(&self) -> f64 {
        self.dt_crit.unwrap_or_else(|| {
            super::stable::initial_limit(self.model, self.spec).map_or(f64::NAN, |s| s.dt)
        })
    }

    /// Refuses a fixed dt above the stability limit of the initial configuration (the
    /// element eigenvalues), unless the scene asks to watch it blow up.
    pub fn new(model: &'a Model, spec: &'a DynamicAnalysis) -> Result<Explicit<'a>, RunError> {
        let Start {
            dt_crit,
            masses,
            state,
            mut kernel,
            clock,
            subcycler,
        } = Start::new(model, spec)?;
        // the free DOFs (no equations: central difference assembles no matrix)
        let mut free = vec![true; model.dofs()];
        for c in model.constrained_dofs() {
            free[c] = false;
        }
        let mass = Mass::new(model, MassKind::Lumped)
            .map_err(|err| InputError::new(&model.file, err.to_string()))?;
        check_mass(model, &mass, &free)?;
        let mut m = mass.lumped;
        if let Some(scaling) = kernel.mass_scaling_mut() {
            // the elements below the target at the start: the initial velocities move them
            scaling.add_pending(&mut m);
        }
        let carriers = projectiles::Carriers::of(model);
        carriers.extend_masses(&mut free, &mut m);
        let dofs = free.len();
        let inverse_mass = (0..dofs)
            .map(|i| if free[i] { 1.0 / m[i] } else { 0.0 })
            .collect();
        let mut interfaces = model.interfaces();
        carriers.attach(&mut interfaces);
        let mut contact = ContactState::new(&model.contacts);
        contact.flights = carriers.initial_flights();
        Ok(Explicit {
            model,
            spec,
            interfaces,
            surface_nodes: (model.contact_surface_nodes().iter().enumerate())
                .filter_map(|(n, on)| on.then_some(n as u32))
                .chain(carriers.nodes())
                .collect(),
            initial: model.coordinates(),
            free,
            mass: m,
            inverse_mass,
            dt_crit,
            kernel,
            synced: false,
            state,
            v: vec![0.0; dofs],
            a: vec![0.0; dofs],
            internal: vec![0.0; dofs],
            energies: Energies::default(),
            initial_kinetic: 0.0,
            last_total: vec![0.0; dofs],
            energy_reference: 0.0,
            step: 0,
            clock,
            masses,
            contact,
            forces_applied: loads::has_external_force(model),
            subcycler,
            mesh_motion: spec.ale.map(|a| ale::MeshMotion::new(model, a)),
            carriers,
            awake: awake::Awake::new(),
            v_half: vec![0.0; dofs],
            du: vec![0.0; dofs],
            external: vec![0.0; dofs],
            total: vec![0.0; dofs],
        })
    }

    /// The contact correction of the predicted increment (forward-increment multipliers) of a
    /// step of length `h` after one of length `last`; `moving`: the nodes that step (None:
    /// all; a subcycled substep moves its finest level's, among them every contact node).
    fn contact_correction(&mut self, (h, last): (f64, f64), time: f64, moving: Option<&[u32]>) {
        self.interfaces.place_obstacles(time);
        let obstacle_steps = moving_obstacle_steps(&self.interfaces, (time - h, time));
        let mut positions = self.state.positions(self.spec.geometry);
        (self.carriers).extend_positions(&mut positions, &self.contact.flights);
        let predicted = Predicted {
            interfaces: &self.interfaces,
            start: &positions,
            du: &self.du,
            inverse_mass: &self.inverse_mass,
            acceleration: &self.a,
            obstacle_steps: &obstacle_steps,
        };
        let step = self.contact.explicit_step(&predicted, h, last, time);
        // the contact work that closes the discrete balance of the step (theory 7): with f =
        // M delta / h^2, du the predicted increment and F_n = M a_n the other forces at its
        // start, f . (du + delta / 2) - delta . F_n / 2. A node the correction stops loses
        // m v^2 / 2 (a_n = 0 at first touch); a node held on a surface, F_n = -f, none. (f . du
        // at the end of the step, used before, booked neither: 1 % of a Taylor rod's energy
        // went missing at first touch, the mass of its face nodes.)
        // The sums run over the DOFs the contact touched: elsewhere f and delta are zero and
        // so is every term, which leaves each sum as it was (a zero term changes a sum at most
        // by the sign of a zero total); a sum in DOF order is a chain of dependent additions
        // that cost the rod pair a fifth of its contact phase over all DOFs. f and delta are
        // zero off the contact surfaces, so only their nodes are looked at (subcycled: the
        // moving ones, among them all of the surfaces'); a scan of every DOF was a serial
        // pass per step that the threads could not share.
        let nodes = moving.unwrap_or(&self.surface_nodes);
        let touched: Vec<usize> = nodes
            .iter()
            .flat_map(|n| [2 * *n as usize, 2 * *n as usize + 1])
            .filter(|i| step.step_force[*i] != 0.0 || step.correction[*i] != 0.0)
            .collect();
        let (mass, a) = (&self.mass, &self.a);
        let held = touched
            .iter()
            .map(|i| step.correction[*i] * mass[*i] * a[*i])
            .sum::<f64>();
        let work = chunked_sum(&touched, &step.step_force, &self.du, |f, u| f * u)
            + 0.5 * chunked_sum(&touched, &step.step_force, &step.correction, |f, c| f * c)
            - 0.5 * held;
        let held_at = |i: usize| step.correction[i] * mass[i] * a[i];
        (self.contact).book_explicit_work(&step, (&self.interfaces, &touched), &self.du, &held_at);
        // du += delta and v_half += delta / h at the touched DOFs (the division left to
        // them: elsewhere delta is zero)
        for &i in &touched {
            let c = step.correction[i];
            self.du[i] += c;
            if c != 0.0 {
                self.v_half[i] += c / h;
            }
        }
        // the friction's share is the energy it dissipates, booked apart (theory 7); a moving
        // obstacle's share is work done on the bodies, an external work
        let friction_work: f64 = step.friction_work.iter().sum();
        let obstacle_work: f64 = step.obstacle_work.iter().sum();
        self.energies.contact_work -= work - friction_work - obstacle_work;
        self.energies.friction_work -= friction_work;
        self.energies.external_work += obstacle_work;
        self.contact.recycle(step, &self.interfaces, &touched);
    }

    /// The energies at the end of step `self.step + 1`: the step's external work added, the
    /// kinetic energy and its shadow, the internal and plastic work of the state; the
    /// reference the blow-up check compares with.
    fn close_step_energies(&mut self, external_work: f64, (kinetic, shadow): (f64, f64)) {
        let energies = &mut self.energies;
        energies.external_work += external_work;
        energies.kinetic = kinetic;
        energies.kinetic_shadow = shadow;
        energies.internal = self.state.internal_work - self.state.plastic_work;
        energies.plastic_work = self.state.plastic_work;
        if self.step == 0 {
            self.energy_reference = self.energy_reference.max(energies.internal.abs());
        }
        self.energy_reference = self.energy_reference.max(energies.external_work.abs());
    }

    /// What F reads at DOF `d`.
    fn dof(&self, d: usize) -> Dof {
        Dof {
            free: self.free[d],
            external: self.external[d],
            internal: self.internal[d],
            m: self.mass[d],
            a: self.a[d],
            v: self.v[d],
        }
    }

    /// The mass the mass scaling added in the step just taken joins the nodes at rest
    /// (docs/theory.md 8.7b): the nodal masses, velocities and accelerations of the end of
    /// the step change with it.
    fn add_scaled_mass(&mut self) -> AddedAtRest {
        match self.kernel.mass_scaling_mut() {
            Some(scaling) => scaling.add_pending_at_rest(NodalMotion {
                mass: &mut self.mass,
                inverse_mass: &mut self.inverse_mass,
                free: &self.free,
                velocity: &mut self.v,
                acceleration: &mut self.a,
            }),
            None => AddedAtRest::default(),
        }
    }

    /// The internal force at u_{n+1} (a step of length `h`), the committed element state and
    /// the stable step of the new configuration; the message of an element that failed.
    /// `move_state`: the displacements and positions move by du here (else the caller moves
    /// them, in the pass of the step's end).
    fn internal_force(&mut self, h: f64, move_state: bool) -> Result<StableStep, String> {
        // the model's DOFs: the carriers' follow them (`projectiles`)
        let n = self.model.dofs();
        let (du, kernel) = (&self.du[..n], &mut self.kernel);
        let work = crate::profile::time(crate::profile::Phase::Assembly, || {
            crate::profile::count_elements(kernel.elements());
            kernel.step(&self.state.coordinates, du, h, &mut self.internal[..n])
        })
        .map_err(|failure| element_failure_text(self.model, &self.state, du, &failure))?;
        if move_state {
            commit_kernel_step(&mut self.state, du, self.spec.geometry);
        }
        self.state.internal_work += work.internal;
        self.state.plastic_work += work.plastic;
        work.commit_bodies(&mut self.state);
        self.energies.bulk_viscosity_work += work.viscous;
        let (body, element) = kernel.locate(work.critical_element);
        Ok(StableStep::of_frequency(work.omega_squared, body, element))
    }
}

impl Stepper for Explicit<'_> {
    fn start(&mut self) -> Result<(), String> {
        let model = self.model;
        let n = model.dofs();
        self.kernel
            .internal_force(&self.state.coordinates, &mut self.internal[..n])
            .map_err(|err| err.to_string())?;
        let system_free = &self.free;
        let (m, a_r) = (&self.mass, self.spec.rayleigh[0]);
        let mut v = super::initial_velocity(model, &system_free[..n], self.clock.dt0);
        self.carriers.extend_velocity(&mut v);
        let mut external = loads::external_force(model, &self.state, &self.initial, 0.0);
        external.resize(v.len(), 0.0);
        self.a = (0..v.len())
            .map(|i| {
                if system_free[i] {
                    (external[i] - self.internal[i] - a_r * m[i] * v[i]) / m[i]
                } else {
                    0.0
                }
            })
            .collect();
        self.v = v;
        self.energies.kinetic = 0.5 * self.v.iter().zip(m).map(|(v, m)| m * v * v).sum::<f64>();
        self.initial_kinetic = self.energies.kinetic;
        let dofs = DofArrays {
            free: &self.free,
            external: &external,
            internal: &self.internal,
            m,
            a: &self.a,
            v: &self.v,
        };
        self.last_total = total_force(&dofs, a_r);
        self.energy_reference = self.initial_kinetic;
        Ok(())
    }

    fn done(&self) -> bool {
        self.state.time >= self.spec.end_time * (1.0 - 1e-12)
    }

    fn advance(&mut self, _: &mut Counters) -> Result<(), StepError> {
        let (model, spec) = (self.model, self.spec);
        let step = self.step + 1;
        if let Some(awake) = &self.awake {
            awake.keep();
        }
        let clock_step = self.clock.next(model, spec, self.state.time, step)?;
        if let Some(sub) = self.subcycler.take() {
            return self.advance_subcycled(sub, clock_step);
        }
        let (time, h) = (clock_step.end, clock_step.length);
        predict(&self.v, &self.a, h, &mut self.v_half, &mut self.du);
        for (dof, value) in loads::prescribed(model, &self.initial, time) {
            self.du[dof] = value - self.state.displacement[dof];
        }
        if !model.contacts.is_empty() {
            let start = Instant::now();
            self.contact_correction((h, self.clock.last), time, None);
            crate::profile::add(crate::profile::Phase::Contact, start);
        }
        // without external forces (which read the moved state) the state moves by du in the
        // pass that ends the step: one parallel loop fewer a step
        let fused = !self.forces_applied;
        let bound = match self.internal_force(h, !fused) {
            Ok(bound) => bound,
            Err(err) => {
                let status = if self.clock.fixed_above_limit() {
                    Status::Unstable
                } else {
                    Status::Diverged
                };
                return Err(StepError {
                    status,
                    message: format!("at t = {}: {err}", readable(time)),
                    frame: false,
                });
            }
        };
        self.state.time = time;
        self.synced = false;
        if self.forces_applied {
            self.external.fill(0.0);
            loads::add_external_force(model, &self.state, &self.initial, time, &mut self.external);
        }
        let (work, kinetic_energy, shadow) = StepEnd {
            free: &self.free,
            external: &self.external,
            internal: &self.internal,
            m: &self.mass,
            v_half: &self.v_half,
            du: &self.du,
            last_total: &self.last_total,
            h,
            a_r: spec.rayleigh[0],
        }
        .apply(
            (&mut self.a, &mut self.v, &mut self.total),
            fused.then(|| StateMotion::of(&mut self.state, spec.geometry)),
        );
        if !self.carriers.is_empty() {
            (self.carriers).track(&mut self.contact.flights, &self.du, &self.v);
        }
        let added = self.add_scaled_mass();
        self.energies.mass_scaling_loss += added.loss;
        std::mem::swap(&mut self.last_total, &mut self.total);
        let kinetic = kinetic_energy + added.kinetic_energy_change;
        self.close_step_energies(work + added.support_work, (kinetic, shadow));
        self.step = step;
        self.clock.took(clock_step, bound);
        if self.mesh_motion.as_ref().is_some_and(|m| m.due(step)) {
            self.ale_step().map_err(|err| StepError {
                status: Status::Diverged,
                message: format!("at t = {}, ALE step: {err}", readable(time)),
                frame: false,
            })?;
        }
        Ok(())
    }

    fn verdict(&self) -> Result<(), StepError> {
        let energy = self.energies.kinetic + self.energies.internal;
        // a reference of zero (a body at rest, loads starting from zero) is no reference: the
        // first loaded step's kinetic energy precedes the external work that books it (the
        // work of a step is its force times the increment taken before that force acted)
        let grown = self.energy_reference > 0.0 && energy > 100.0 * self.energy_reference;
        if !energy.is_finite() || grown {
            return Err(StepError {
                status: Status::Unstable,
                message: format!(
                    "the energy grew to {} (reference {}) at t = {}: dt = {} is above the stability limit {}",
                    readable(energy),
                    readable(self.energy_reference),
                    readable(self.state.time),
                    readable(self.clock.last),
                    readable(self.initial_limit())
                ),
                frame: true,
            });
        }
        Ok(())
    }
    fn sync_points(&mut self) {
        if !self.synced {
            self.kernel.write_points(self.model, &mut self.state);
            self.synced = true;
        }
    }
}

impl Report for Explicit<'_> {
    fn about(&self) -> About {
        About {
            integrator: "central_difference".into(),
            dt: self.clock.dt0,
            end_time: self.spec.end_time,
            free_dofs: self.free.iter().filter(|f| **f).count(),
            checks_buckling: false,
        }
    }
    fn state(&self) -> &State {
        &self.state
    }
    fn motion(&self) -> Motion<'_> {
        // the model's DOFs (the projectiles' carriers follow them)
        let n = self.model.dofs();
        Motion {
            velocity: &self.v[..n],
            acceleration: &self.a[..n],
            mass: &self.mass[..n],
            internal_force: &self.internal[..n],
        }
    }
    fn energies(&self) -> &Energies {
        &self.energies
    }
    fn initial_kinetic(&self) -> f64 {
        self.initial_kinetic
    }
    fn contact(&self) -> &ContactState {
        &self.contact
    }
    fn point_probe(&self, probe: &Probe) -> Option<f64> {
        if self.synced {
            return None;
        }
        self.kernel.point_probe(self.model, probe)
    }
    fn last_step(&self) -> f64 {
        self.clock.last
    }
    fn row_features(&self) -> RowFeatures {
        RowFeatures {
            hourglass_energy: self.kernel.hourglass_energy(),
            added_mass: self.kernel.mass_scaling().map(|s| s.added()),
            ..RowFeatures::default()
        }
    }
    fn run_features(&self) -> RunFeatures {
        let kernel = &self.kernel;
        let mass_scaling = kernel
            .mass_scaling()
            .map(|scaling| scaling.report(self.model.bodies.len(), |e| kernel.locate(e)));
        let time_step = self.clock.range().map(|range| TimeStepReport {
            shortest: range.shortest,
            longest: range.longest,
            limit: self.clock.limit,
            first: self.clock.dt0,
        });
        RunFeatures {
            time_step,
            mass_scaling,
            ale: self.mesh_motion.as_ref().map(ale::MeshMotion::summary),
            arc_length: None,
            subcycling: (self.subcycler.as_ref()).map(|sub| sub.summary(kernel.elements())),
        }
    }
}

impl Resume for Explicit<'_> {
    fn kind(&self) -> &'static str {
        "explicit"
    }

    fn restore(&mut self, carry: Carry) -> bool {
        let Carry::Explicit(carry) = carry else {
            return false;
        };
        self.state = carry.state;
        self.v = carry.velocity;
        self.a = carry.acceleration;
        self.energies = carry.energies;
        self.initial_kinetic = carry.initial_kinetic;
        self.last_total = carry.last_total;
        self.energy_reference = carry.energy_reference;
        self.contact = carry.contact;
        self.step = carry.step;
        self.clock = carry.clock;
        // the remapped element masses, before the kernel and the nodal masses are formed
        match (self.mesh_motion.as_mut(), carry.ale) {
            (Some(motion), Some(ale)) => {
                self.masses = ale.masses;
                motion.restore(ale.summary);
                self.nodal_masses_from_elements();
            }
            (None, None) => {}
            _ => return false,
        }
        // a kernel with its own arrays starts again from the restored points (and the viscous
        // pressures of the last step, which the next step's work needs)
        self.kernel = kernel_for(self.model, self.spec, &self.state, &self.masses);
        if !carry.viscous_pressure.is_empty() {
            self.kernel
                .restore_viscous_pressure(&carry.viscous_pressure);
        }
        // the one-point kernel's hourglass forces and work, which the points do not hold
        match (self.kernel.hourglass_energy().is_some(), carry.hourglass) {
            (true, Some((forces, work))) => {
                if forces.len() != self.kernel.elements() * 2 {
                    return false;
                }
                self.kernel.restore_hourglass_state(forces, work);
            }
            (false, None) => {}
            _ => return false,
        }
        // the tight step's ratios as the run had taken them
        if let Some(tightness) = carry.tightness {
            self.kernel.restore_tightness(tightness);
        }
        // the factors and the nodal masses as the run had grown them
        if let Some(scaling) = self.kernel.mass_scaling_mut()
            && let Some(carried) = &carry.mass_scaling
        {
            scaling.restore(carried, &mut self.mass, &mut self.inverse_mass, &self.free);
        }
        match (self.subcycler.as_mut(), carry.subcycling) {
            (Some(sub), Some(carried)) => {
                let Some(kernel) = self.kernel.partial() else {
                    return false;
                };
                if !sub.restore(carried, kernel) {
                    return false;
                }
            }
            (None, None) => {}
            _ => return false,
        }
        true
    }

    fn carry(&self) -> Result<Carry, &'static str> {
        let mut state = self.state.clone();
        self.kernel.write_points(self.model, &mut state);
        Ok(Carry::Explicit(ExplicitCarry {
            state,
            velocity: self.v.clone(),
            acceleration: self.a.clone(),
            energies: self.energies,
            initial_kinetic: self.initial_kinetic,
            last_total: self.last_total.clone(),
            energy_reference: self.energy_reference,
            step: self.step,
            contact: self.contact.clone(),
            clock: self.clock.clone(),
            viscous_pressure: match &self.spec.bulk_viscosity {
                Some(_) => self.kernel.viscous_pressure().to_vec(),
                None => Vec::new(),
            },
            mass_scaling: self.kernel.mass_scaling().map(|s| s.carry(&self.mass)),
            subcycling: self.subcycler.as_ref().map(|s| s.carry()),
            tightness: self.kernel.tightness().cloned(),
            ale: self.mesh_motion.as_ref().map(|m| super::carry::AleCarry {
                masses: self.masses.clone(),
                summary: m.summary(),
            }),
            hourglass: self.kernel.hourglass_state(),
        }))
    }
}

/// The element loop of a subcycled run: the kernels that have one are the only ones a scene
/// lets subcycle (finite-strain Quad4; `subcycling::start` checks it). A function of the
/// field, so that the driver's other fields stay free.
fn partial_of<'k>(kernel: &'k mut Box<dyn ExplicitKernel + '_>) -> &'k mut dyn PartialKernel {
    kernel
        .partial()
        .expect("a subcycled run has a partial kernel")
}

/// The message of an element that failed in a step's kernel pass, with the cause that a
/// corner of another body sitting on one of its nodes gives it (`folds::fold_hint`),
/// read at the positions the kernel saw (the state moved by the step's `du`).
fn element_failure_text(
    model: &Model,
    state: &State,
    du: &[f64],
    failure: &ElementFailure,
) -> String {
    let mut x = state.positions(model.analysis.geometry()).into_owned();
    for (p, d) in x.iter_mut().zip(du.chunks_exact(2)) {
        p[0] += d[0];
        p[1] += d[1];
    }
    match folds::fold_hint(model, &x, failure) {
        Some(hint) => format!("{failure}; {hint}"),
        None => failure.to_string(),
    }
}
