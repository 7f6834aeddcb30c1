//! Static load stepping with full, modified or initial-tangent Newton-Raphson (Erklig 2.1.2).
//!
//! Legend
//! ```text
//! t, dt      pseudo time and its increment; loads follow their curves in t
//! d          displacement increment since the last converged configuration
//! ```
//! An increment that does not converge in `max_iterations` (or meets an inverted element or a
//! tangent that is not positive definite) is halved, at most `max_cuts` times in a row; then
//! the run stops `diverged` with its output so far kept. After a cut the step grows back.

use super::checkpoint::{Carry, Checkpoint, StaticCarry};
use super::newton::{Constraints, Counters, Step, StepFailure};
use super::record::{Energies, Motion, Recorder};
use super::{Outcome, RunError, RunOptions, Status, Summary, loads};
use crate::assembly::{self, State, System};
use crate::contact::{ContactState, Tangential};
use crate::integrator::StepForm;
use crate::scene::Model;
use crate::scene::spec::{StaticSpec, Strategy};
use crate::solver::Solver;
use std::path::Path;
use std::time::Instant;

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

/// Runs a static analysis and writes its output into `dir`.
pub fn run(
    model: &Model,
    spec: &StaticSpec,
    dir: &Path,
    options: RunOptions,
    resume: Option<Checkpoint>,
) -> Result<Outcome, RunError> {
    let mut start = Instant::now();
    let (mut recorder, resume) = match resume {
        Some(c) => {
            let Carry::Static(carry) = c.carry.clone() else {
                return Err(super::wrong_carry(dir, "static"));
            };
            (
                Recorder::resume(model, dir, c.recorder.clone())?,
                Some((c, carry)),
            )
        }
        None => (Recorder::create(model, dir)?, None),
    };
    let initial = model.coordinates();
    let mut system = System::new(model, &loads::constrained_dofs(model));
    let mut solver = Solver::new(&system.pattern).map_err(|e| super::setup_error(dir, e))?;
    let mut state = State::initial(model);
    let zeros = vec![0.0; model.dofs()];
    let motion = Motion {
        velocity: &zeros,
        acceleration: &zeros,
        mass: &[],
    };
    let mut energies = Energies::default();
    let mut last_force = vec![0.0; model.dofs()];
    let mut monitor =
        super::buckling::Monitor::new(model, dir).map_err(|e| super::monitor_error(model, e))?;
    let dt = spec.end_time / spec.steps as f64;
    let mut summary = Summary::new(model, "static", dt, spec.end_time, system.free);
    let form = static_form(model.dofs());
    let mut counters = Counters::default();
    let mut control = super::StepControl::new(dt, spec.newton.max_cuts);
    let mut increments = 0usize;
    let interfaces = super::interfaces(model);
    let mut contact = ContactState::new(&model.contacts);
    let penetration_limits = crate::contact::penetration_limits(&model.contacts, &initial);
    match resume {
        Some((checkpoint, carry)) => {
            state = carry.state;
            energies = carry.energies;
            last_force = carry.last_force;
            control = carry.control;
            increments = carry.increments;
            contact = carry.contact;
            summary = checkpoint.summary;
            counters = checkpoint.counters;
            solver.factorizations = checkpoint.factorizations;
            solver.solves = checkpoint.back_substitutions;
            start = super::resumed_start(checkpoint.wall_seconds);
            if let (Some(m), Some(b)) = (&mut monitor, checkpoint.buckling) {
                m.summary = b;
            }
        }
        None => {
            if let Some(m) = &mut monitor {
                recorder.negative_pivots = m
                    .observe(model, &state)
                    .map_err(|e| super::monitor_error(model, e.into()))?
                    .0;
            }
            recorder.step(model, &state, &motion, &energies, true)?;
        }
    }
    let progress = super::progress_bar(options.progress, spec.steps);
    // the step after a checkpoint factors K* afresh (a resumed run has no factorization)
    let mut refresh = model.checkpoint_every > 0;
    let save = |recorder: &Recorder,
                summary: &Summary,
                counters: &Counters,
                solver: &Solver,
                monitor: &Option<super::buckling::Monitor>,
                carry: StaticCarry| {
        super::Bookkeeping {
            model,
            recorder,
            summary,
            counters,
            solver: Some(solver),
            start,
            buckling: monitor.as_ref().map(|m| &m.summary),
        }
        .save(Carry::Static(carry))
    };
    if summary.steps == 0 && model.checkpoint_every > 0 {
        let carry = StaticCarry {
            state: state.clone(),
            energies,
            last_force: last_force.clone(),
            control: control.clone(),
            increments,
            contact: contact.clone(),
        };
        save(&recorder, &summary, &counters, &solver, &monitor, carry)?;
    }
    while state.time < spec.end_time * (1.0 - 1e-12) {
        let target = super::snap((state.time + control.length).min(spec.end_time), dt);
        let positions = state.positions(spec.geometry);
        let refresh_now = std::mem::take(&mut refresh);
        let factor_first = refresh_now
            || match spec.newton.strategy {
                Strategy::Full => true,
                Strategy::Modified => {
                    increments.is_multiple_of(spec.newton.refactor_every) || control.after_cut()
                }
                Strategy::Initial => !solver.is_factored() || control.after_cut(),
            };
        // one attempt of the increment with a given length and active contact set
        let attempt =
            |h: f64, active: &[(usize, usize)], forces: Vec<f64>, tangential: &[Tangential]| {
                let end = if state.time + h >= target {
                    target
                } else {
                    state.time + h
                };
                let mut d = vec![0.0; model.dofs()];
                for (dof, value) in loads::prescribed(model, &initial, end) {
                    d[dof] = value - state.displacement[dof];
                }
                let external = loads::external_force(model, &state, &initial, end);
                let step = Step {
                    model,
                    geometry: spec.geometry,
                    newton: &spec.newton,
                    inertia: None,
                    form: &form,
                    external: &external,
                    internal_start: &last_force,
                    factor_first,
                    contact: Some(Constraints {
                        pairs: &model.contacts,
                        active,
                        start: &positions,
                        forces,
                        tangential,
                    }),
                };
                step.solve(&state, d, &mut system, &mut solver, &mut counters)
            };
        // an event inside the increment ends it early (Erklig 2.1.4: alpha brings the next
        // node exactly into contact before the boundary conditions change)
        match contact.step(&model.contacts, &positions, target - state.time, attempt) {
            Ok(mut step) => {
                let end = if state.time + step.length >= target {
                    target
                } else {
                    state.time + step.length
                };
                let d = std::mem::take(&mut step.solution.d);
                let evaluation = std::mem::take(&mut step.solution.evaluation);
                let force = evaluation.force.clone();
                assembly::commit(model, &mut state, &d, evaluation, spec.geometry);
                state.time = end;
                contact.commit(
                    &interfaces,
                    &step,
                    state.time,
                    &state.positions(spec.geometry),
                );
                // the work of all nodal forces (loads, reactions and contact forces)
                energies.external_work += super::trapezoid_work(&d, &force, &last_force);
                energies.internal = state.internal_work - state.plastic_work;
                energies.plastic_work = state.plastic_work;
                summary.energy.max_relative_drift = summary
                    .energy
                    .max_relative_drift
                    .max(super::balance_error(&energies, 0.0));
                last_force = force;
                summary.steps += 1;
                increments += 1;
                let mut stop = false;
                if let Some(m) = &mut monitor {
                    match m.observe(model, &state) {
                        Ok((count, halt)) => {
                            recorder.negative_pivots = count;
                            stop = halt;
                        }
                        Err(e) => {
                            progress.abandon();
                            summary.finish(&energies, &counters, Some(&solver), start);
                            summary.buckling = Some(m.summary.clone());
                            let message = format!("buckling check at t = {}: {e}", state.time);
                            return Err(super::fail(&recorder, summary, Status::Diverged, message));
                        }
                    }
                }
                let last = stop || state.time >= spec.end_time * (1.0 - 1e-12);
                recorder.step_with_contact(
                    model,
                    &state,
                    &motion,
                    &energies,
                    Some(&contact),
                    last,
                )?;
                if let Some(message) = crate::contact::runaway_penetration(
                    &model.contacts,
                    &state.positions(spec.geometry),
                    &penetration_limits,
                ) {
                    progress.abandon();
                    summary.finish(&energies, &counters, Some(&solver), start);
                    summary.contact = contact.summary();
                    let message = format!("at t = {}: {message}", state.time);
                    return Err(super::fail(&recorder, summary, Status::Diverged, message));
                }
                progress.set_position((state.time / dt).round() as u64);
                control.accept(end == target);
                if stop {
                    summary.message = Some(stop_message(&state, &recorder));
                    break;
                }
                let interrupted = !last && options.interrupted();
                if interrupted {
                    recorder.frame(model, &state, &motion, Some(&contact))?;
                }
                if interrupted || (!last && super::checkpoint_due(model, summary.steps)) {
                    let carry = StaticCarry {
                        state: state.clone(),
                        energies,
                        last_force: last_force.clone(),
                        control: control.clone(),
                        increments,
                        contact: contact.clone(),
                    };
                    save(&recorder, &summary, &counters, &solver, &monitor, carry)?;
                    refresh = true;
                }
                options.halt(&summary)?;
                if interrupted {
                    progress.abandon();
                    summary.finish(&energies, &counters, Some(&solver), start);
                    summary.contact = contact.summary();
                    summary.buckling = monitor.as_ref().map(|m| m.summary.clone());
                    return Err(super::interrupted(&recorder, summary, state.time));
                }
            }
            Err(StepFailure(reason)) => {
                if let Err(why) = control.reject(target - state.time, &mut counters) {
                    progress.abandon();
                    let message = format!("increment to t = {target} {why}: {reason}");
                    summary.finish(&energies, &counters, Some(&solver), start);
                    summary.contact = contact.summary();
                    summary.buckling = monitor.as_ref().map(|m| m.summary.clone());
                    return Err(super::fail(&recorder, summary, Status::Diverged, message));
                }
            }
        }
    }
    progress.finish_and_clear();
    summary.finish(&energies, &counters, Some(&solver), start);
    summary.contact = contact.summary();
    summary.buckling = monitor.map(|m| m.summary);
    recorder.write_summary(&summary)?;
    let contact_force = contact.nodal_forces(&model.contacts, &state.positions(spec.geometry));
    Ok(Outcome {
        summary,
        state,
        contact_force,
    })
}

/// summary.json `message` of a run stopped by `on_critical = "stop"`.
pub(super) fn stop_message(state: &State, recorder: &Recorder) -> String {
    format!(
        "stopped by analysis.buckling.on_critical at t = {}: K_T has {} negative pivot(s)",
        state.time,
        recorder.negative_pivots.unwrap_or(0)
    )
}
