//! Static load stepping with full, modified or initial-tangent Newton-Raphson (Erklig 2.1.2).
//!
//! Legend
//! ```text
//! t, dt      pseudo time and its increment; loads follow their curves in t
//! d          displacement increment since the last converged configuration
//! ```
//! An increment that does not converge in `max_iterations` (or meets an inverted element or a
//! singular tangent) is halved, at most `max_cuts` times in a row; then the run stops
//! `diverged` with its output so far kept. After a cut the length is kept, and grows by half
//! after two increments in a row succeed (`StepControl::accept_patiently`). An
//! event inside an increment ends it early (Erklig 2.1.4: alpha brings the next node exactly
//! into contact before the boundary conditions change).

use super::carry::{Carry, StaticCarry};
use super::control::{StepControl, snap};
use super::energies::{Energies, Motion};
use super::newton::{Constraints, Counters, SINGULAR_STIFFNESS, Step, StepFailure};
use super::{About, Report, Resume, StepError, Stepper, loads};
use crate::assembly::{self, State, System};
use crate::contact::{ContactResult, ContactState, Interfaces, Pass};
use crate::integrator::StepForm;
use crate::output::readable;
use crate::scene::Model;
use crate::scene::StaticAnalysis;
use crate::scene::spec::Strategy;
use crate::solver::Solver;

/// The step form of statics: no inertia, equilibrium at the end of the increment.
fn static_form(n: usize) -> StepForm {
    StepForm {
        solve_fraction: 1.0,
        load_fraction: 1.0,
        mass_coefficient: 0.0,
        acceleration_offset: vec![0.0; n],
        damping_coefficient: 0.0,
        velocity_offset: vec![0.0; n],
        internal_weight: 1.0,
    }
}

/// Static load stepping: the state, the solver and what the loop carries.
pub struct Statics<'a> {
    model: &'a Model,
    spec: &'a StaticAnalysis,
    interfaces: Interfaces,
    initial: Vec<[f64; 2]>,
    system: System,
    solver: Solver,
    form: StepForm,
    zeros: Vec<f64>,
    dt: f64,
    state: State,
    energies: Energies,
    /// The internal force of the committed state (all DOFs).
    last_force: Vec<f64>,
    control: StepControl,
    increments: usize,
    contact: ContactState,
    /// The next increment factors K* afresh (after a checkpoint: a resumed run has none).
    refresh: bool,
    /// The length of the last increment.
    last_step: f64,
    /// ||d|| / dt of the first increment of this run (or since a resume) and of the last:
    /// how far the path has flattened, for the message of a run that stops at a limit load.
    first_rate: Option<f64>,
    last_rate: f64,
    /// The last increment's displacement increment and length, from which the next one
    /// starts (`NewtonSpec::extrapolates`).
    previous: Option<(Vec<f64>, f64)>,
    /// The bands of resting slaves a held body's first increment has closed
    /// (`widen_resting`).
    bands_tried: usize,
}

impl<'a> Statics<'a> {
    pub fn new(model: &'a Model, spec: &'a StaticAnalysis) -> Result<Statics<'a>, String> {
        let system = System::new(model, &model.constrained_dofs());
        let solver = Solver::new(&system.pattern).map_err(|e| e.to_string())?;
        let dt = spec.end_time / spec.steps as f64;
        Ok(Statics {
            model,
            spec,
            interfaces: model.interfaces(),
            initial: model.coordinates(),
            form: static_form(model.dofs()),
            zeros: vec![0.0; model.dofs()],
            dt,
            state: State::initial(model),
            energies: Energies::default(),
            last_force: vec![0.0; model.dofs()],
            control: StepControl::new(dt, spec.newton.max_cuts),
            increments: 0,
            contact: ContactState::new(&model.contacts),
            refresh: model.checkpoint_every > 0,
            last_step: 0.0,
            first_rate: None,
            last_rate: 0.0,
            previous: None,
            bands_tried: 0,
            system,
            solver,
        })
    }
}

/// What an increment's attempts share: the committed state and the increment's settings.
struct Increment<'s> {
    model: &'s Model,
    spec: &'s StaticAnalysis,
    form: &'s StepForm,
    initial: &'s [[f64; 2]],
    state: &'s State,
    last_force: &'s [f64],
    positions: &'s [[f64; 2]],
    target: f64,
    factor_first: bool,
    /// The last increment's displacement increment and length, to start from.
    previous: Option<(&'s [f64], f64)>,
}

impl Increment<'_> {
    /// Solves the increment with a given length and active contact set.
    fn attempt(
        &self,
        pass: Pass<'_>,
        system: &mut System,
        solver: &mut Solver,
        counters: &mut Counters,
    ) -> Result<super::newton::Solution, StepFailure> {
        let Pass {
            pairs,
            length: h,
            active,
            forces,
            tangential,
            warm,
            inside,
        } = pass;
        let (model, state, target) = (self.model, self.state, self.target);
        let end = if state.time + h >= target {
            target
        } else {
            state.time + h
        };
        // the increment the last active set converged to, or the last increment's scaled to
        // this one's length (linear extrapolation), or zero
        let mut d = match (warm, self.previous) {
            (Some(warm), _) => warm.to_vec(),
            (None, Some((last, length))) => {
                let scale = (end - state.time) / length;
                let free = |dof: usize| system.equation[dof].is_some();
                last.iter()
                    .enumerate()
                    .map(|(dof, v)| if free(dof) { scale * v } else { 0.0 })
                    .collect()
            }
            (None, None) => vec![0.0; model.dofs()],
        };
        for (dof, value) in loads::prescribed(model, self.initial, end) {
            d[dof] = value - state.displacement[dof];
        }
        let external = loads::external_force(model, state, self.initial, end);
        let step = Step {
            model,
            dt: end - state.time,
            geometry: self.spec.geometry,
            newton: &self.spec.newton,
            inertia: None,
            form: self.form,
            external: &external,
            internal_start: self.last_force,
            factor_first: self.factor_first,
            predictor: true,
            error_target: None,
            contact: Some(Constraints {
                pairs,
                active,
                start: self.positions,
                forces,
                tangential,
                targets: Vec::new(),
                inside,
                describe: &|node| model.describe_node(node),
            }),
        };
        step.solve(state, d, system, solver, counters)
    }
}

/// The flattening of the load-displacement path (the last increment's ||d|| / dt over the
/// first's) from which a run stopped by its increments is told it may be at its limit load.
const FLATTENED: f64 = 10.0;

impl Statics<'_> {
    /// Takes the converged increment `step` of an increment aimed at `target` (shorter where
    /// a contact event ended it): the state, the contact status, the energies and the start
    /// of the next increment.
    fn commit(&mut self, mut step: ContactResult<super::newton::Solution>, target: f64) {
        let geometry = self.spec.geometry;
        let end = if self.state.time + step.length >= target {
            target
        } else {
            self.state.time + step.length
        };
        let d = std::mem::take(&mut step.solution.d);
        self.previous = Some((d.clone(), end - self.state.time));
        let evaluation = std::mem::take(&mut step.solution.evaluation);
        let force = evaluation.force.clone();
        assembly::commit(self.model, &mut self.state, &d, evaluation, geometry);
        self.last_step = end - self.state.time;
        self.last_rate = d.iter().map(|v| v * v).sum::<f64>().sqrt() / self.last_step;
        self.first_rate.get_or_insert(self.last_rate);
        self.state.time = end;
        let positions = self.state.positions(geometry);
        self.interfaces.place_obstacles(self.state.time);
        self.contact
            .commit(&self.interfaces, &step, self.state.time, &positions);
        // the work of all nodal forces (loads, reactions and contact forces)
        let energies = &mut self.energies;
        energies.external_work += super::trapezoid_work(&d, &force, &self.last_force);
        energies.internal = self.state.internal_work - self.state.plastic_work;
        energies.plastic_work = self.state.plastic_work;
        self.last_force = force;
        self.increments += 1;
        self.control.accept_patiently(end == target);
    }

    /// Where the path had flattened (`FLATTENED`) under loads, the limit load as the likely
    /// cause, and how to pass it; empty otherwise.
    fn limit_hint(&self) -> String {
        let Some(first) = self.first_rate else {
            return String::new();
        };
        let forced = loads::has_external_force(self.model);
        if !forced || self.last_rate < FLATTENED * first {
            return String::new();
        }
        format!(
            ". The load-displacement path had flattened: the last increment moved {:.0} times \
             as far per unit load as the first. The load cannot go much beyond t = {}: a \
             limit load (collapse or snap-through). analysis.arc_length = {{}} traces the path \
             through it; a prescribed displacement drives the structure past it",
            self.last_rate / first,
            readable(self.state.time)
        )
    }
}

/// The share by which the tangent's diagonal is raised where a body is held by its contact
/// alone (`System::regularize`): far above round-off, so the rigid motion's pivot is
/// resolved, and far below any stiffness, so Newton's contraction hardly changes.
const HELD_SHIFT: f64 = 1e-8;

/// The bands, in multiples of a pair's TOL (1e-9 of the model's size by default: 1e-3, 1e-2
/// and 1e-1 of it), within which a held body's slaves close when its first increment fails
/// with the touching ones alone (`widen_resting`).
const RESTING_BANDS: [f64; 3] = [1e6, 1e7, 1e8];

/// A held body's first increment that failed with only its touching slaves closed (a
/// sphere at its pole: at finite strain the one node's load turns the elements around it
/// inside out before the pass can close the others): the open slaves within the next of
/// `RESTING_BANDS` of their master close too, those that then pull opening again in the
/// passes (theory 5c). `tried`: the bands tried so far. Whether any slave closed.
pub(super) fn widen_resting(
    (model, state, geometry): (&Model, &State, crate::element::Strain),
    contact: &mut ContactState,
    tried: &mut usize,
) -> bool {
    let positions = state.positions(geometry);
    while let Some(band) = RESTING_BANDS.get(*tried) {
        *tried += 1;
        let closed = contact.close_resting(&model.contacts, &|n| positions[n], *band);
        if closed > 0 {
            crate::output::console::iteration(format_args!(
                "  the first increment failed with the touching slaves alone: {closed} more \
                 within {band:e} TOL of their master start closed"
            ));
            return true;
        }
    }
    false
}

/// What a run that stopped should know when its body is held by its contact alone.
pub(super) fn held_hint(system: &System) -> &'static str {
    match system.held > 0.0 {
        true => {
            ". The body is held by its contact alone (its resting slaves closed at the \
                 start, theory 5c); a motion the contact does not hold, such as sliding on a \
                 frictionless support under a load along it, has no equilibrium: support the \
                 body there"
        }
        false => "",
    }
}

/// What `hold_by_contact` found of the committed state's tangent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Hold {
    /// Regular: it is factored now, at no increment.
    Regular,
    /// Singular, and resting slaves closed to hold the body.
    Closed,
    /// Singular with nothing resting on a master (a mechanism), or not evaluable.
    Unheld,
}

/// A body that its contact alone holds (docs/theory.md 5c): where the tangent of the
/// committed `state` is singular (a mechanism at the solver's usual threshold) and open
/// slaves touch their masters, those slaves close and `system` raises the diagonal of every
/// tangent it factors from then on (`HELD_SHIFT`). Without contact pairs, or where the
/// system holds already, nothing is evaluated (`Unheld`).
pub(super) fn hold_by_contact(
    (model, state, dt): (&Model, &State, f64),
    (geometry, tangent): (crate::element::Strain, crate::scene::spec::Tangent),
    (system, solver): (&mut System, &mut Solver),
    contact: &mut ContactState,
) -> Hold {
    if model.contacts.is_empty() || system.held > 0.0 {
        return Hold::Unheld;
    }
    let zero = vec![0.0; model.dofs()];
    let step = assembly::StepIncrement {
        d: &zero,
        dt,
        geometry,
    };
    if assembly::evaluate(model, state, step, Some(&mut *system), tangent).is_err() {
        return Hold::Unheld;
    }
    match solver.factor_indefinite(&system.values) {
        Ok(()) => return Hold::Regular,
        Err(crate::solver::SolverError::Singular { .. }) => {}
        Err(_) => return Hold::Unheld,
    }
    let positions = state.positions(geometry);
    let closed = contact.close_resting(&model.contacts, &|n| positions[n], 1.0);
    if closed == 0 {
        return Hold::Unheld;
    }
    system.held = HELD_SHIFT;
    crate::output::console::iteration(format_args!(
        "  the tangent is singular and {closed} slave(s) touch their master: they start \
         closed and hold the body (its diagonal raised by {HELD_SHIFT:e} of itself)"
    ));
    Hold::Closed
}

impl Stepper for Statics<'_> {
    fn start(&mut self) -> Result<(), String> {
        Ok(())
    }

    fn done(&self) -> bool {
        self.state.time >= self.spec.end_time * (1.0 - 1e-12)
    }

    fn advance(&mut self, counters: &mut Counters) -> Result<(), StepError> {
        // an increment that ran out of iterations from the extrapolated start is tried again
        // from zero before it is cut
        let mut from_zero = false;
        loop {
            let spec = self.spec;
            let target = snap(
                (self.state.time + self.control.length).min(spec.end_time),
                self.dt,
            );
            let positions = self.state.positions(spec.geometry).into_owned();
            let refresh_now = std::mem::take(&mut self.refresh);
            let factor_first = refresh_now
                || from_zero
                || match spec.newton.strategy {
                    Strategy::Full => true,
                    Strategy::Modified => {
                        spec.newton
                            .refactor_every
                            .is_some_and(|n| self.increments.is_multiple_of(n))
                            || self.control.after_cut()
                    }
                    Strategy::Initial => !self.solver.is_factored() || self.control.after_cut(),
                };
            let increment = Increment {
                model: self.model,
                spec,
                form: &self.form,
                initial: &self.initial,
                state: &self.state,
                last_force: &self.last_force,
                positions: &positions,
                target,
                factor_first,
                previous: self
                    .previous
                    .as_ref()
                    .filter(|_| spec.newton.extrapolates() && !from_zero)
                    .filter(|_| !self.control.after_cut())
                    .map(|(d, h)| (&d[..], *h)),
            };
            let extrapolated = increment.previous.is_some();
            let (system, solver) = (&mut self.system, &mut self.solver);
            let solve = |pass: Pass<'_>| increment.attempt(pass, system, solver, counters);
            let pairs = (&self.model.contacts[..], self.state.time);
            let length = target - self.state.time;
            let outcome = if super::newton::active_set_inside(self.model, &spec.newton) {
                self.contact.step_inside(pairs, &positions, length, solve)
            } else {
                self.contact.step(pairs, &positions, length, solve)
            };
            match outcome {
                Ok(step) => {
                    self.commit(step, target);
                    return Ok(());
                }
                // (not after an inverted element: on the finest finite-strain punch, the
                // retry from zero failed there too, and cut more often than the cut alone)
                Err(failure) if extrapolated && failure.ran_out() => {
                    crate::output::console::iteration(format_args!(
                        "  newton: {} from the extrapolated start: the increment again from zero",
                        failure.0
                    ));
                    from_zero = true;
                }
                Err(StepFailure(reason)) => {
                    // a first increment on a singular tangent: a body its contact alone holds?
                    if self.increments == 0
                        && reason.starts_with(SINGULAR_STIFFNESS)
                        && matches!(
                            hold_by_contact(
                                (self.model, &self.state, self.dt),
                                (spec.geometry, spec.newton.tangent),
                                (&mut self.system, &mut self.solver),
                                &mut self.contact,
                            ),
                            Hold::Closed
                        )
                    {
                        continue;
                    }
                    // held, but not by the touching slaves alone
                    if self.increments == 0
                        && self.system.held > 0.0
                        && widen_resting(
                            (self.model, &self.state, spec.geometry),
                            &mut self.contact,
                            &mut self.bands_tried,
                        )
                    {
                        continue;
                    }
                    crate::output::console::iteration(format_args!(
                        "  newton: the increment to t = {} is cut: {reason}",
                        readable(target)
                    ));
                    if let Err(why) = self.control.reject(target - self.state.time, counters) {
                        // a limit load is the likelier cause where the path had flattened
                        let mut hint = self.limit_hint();
                        if hint.is_empty() {
                            hint = held_hint(&self.system).to_string();
                        }
                        let message = format!(
                            "increment to t = {} {why}: {reason}{hint}",
                            readable(target)
                        );
                        return Err(StepError::diverged(message));
                    }
                }
            }
        }
    }
}

impl Report for Statics<'_> {
    fn about(&self) -> About {
        About {
            integrator: "static".into(),
            dt: self.dt,
            end_time: self.spec.end_time,
            free_dofs: self.system.free,
            checks_buckling: true,
        }
    }
    fn state(&self) -> &State {
        &self.state
    }
    fn motion(&self) -> Motion<'_> {
        Motion {
            velocity: &self.zeros,
            acceleration: &self.zeros,
            mass: &[],
            internal_force: &self.last_force,
        }
    }
    fn energies(&self) -> &Energies {
        &self.energies
    }
    fn initial_kinetic(&self) -> f64 {
        0.0
    }
    fn contact(&self) -> &ContactState {
        &self.contact
    }
    fn solver(&self) -> Option<&Solver> {
        Some(&self.solver)
    }
    fn last_step(&self) -> f64 {
        self.last_step
    }
    fn held(&self) -> f64 {
        self.system.held
    }
}

impl Resume for Statics<'_> {
    fn kind(&self) -> &'static str {
        "static"
    }

    fn restore(&mut self, carry: Carry) -> bool {
        let Carry::Static(carry) = carry else {
            return false;
        };
        self.state = carry.state;
        self.energies = carry.energies;
        self.last_force = carry.last_force;
        self.control = carry.control;
        self.increments = carry.increments;
        self.contact = carry.contact;
        self.previous = carry.previous;
        self.system.held = carry.held;
        true
    }

    fn carry(&self) -> Result<Carry, &'static str> {
        Ok(Carry::Static(StaticCarry {
            state: self.state.clone(),
            energies: self.energies,
            last_force: self.last_force.clone(),
            control: self.control.clone(),
            increments: self.increments,
            contact: self.contact.clone(),
            previous: self.previous.clone(),
            held: self.system.held,
        }))
    }

    fn after_checkpoint(&mut self) {
        self.refresh = true;
    }
    fn solver_mut(&mut self) -> Option<&mut Solver> {
        Some(&mut self.solver)
    }
}
