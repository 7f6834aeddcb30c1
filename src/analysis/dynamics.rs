//! Implicit direct time integration: any `Integrator` in effective-stiffness form, each step
//! solved by Newton (see `newton`), K* factored once while dt and the strategy allow.
//!
//! Legend
//! ```text
//! u, v, a      committed displacement (total), velocity, acceleration, all DOFs
//! D            the step's solved increment (at t_n + s dt; s = 1 except for Wilson)
//! f_int,n      internal force of the committed state
//! F            total external force: f_ext on free DOFs, reactions M a + C v + f_int on
//!              prescribed ones (so W_ext includes the work of supports and prescribed motion)
//! ```
//! Prescribed DOFs follow their curves; their velocity and acceleration come from the same
//! integrator formulas as the free ones.

use super::checkpoint::{Carry, Checkpoint, DynamicCarry};
use super::newton::{Constraints, Counters, Inertia, Step, StepFailure};
use super::record::{Energies, Motion, Recorder};
use super::{Outcome, RunError, RunOptions, Status, Summary, loads};
use crate::assembly::{self, Mass, State, System};
use crate::contact::{ContactState, Tangential};
use crate::integrator::{GeneralizedAlpha, Houbolt, Integrator, MotionState, Wilson};
use crate::scene::spec::{DynamicSpec, IntegratorKind, Strategy};
use crate::scene::{InputError, Model};
use crate::solver::Solver;
use std::path::Path;
use std::time::Instant;

/// The integrator a scene asks for (implicit ones).
pub fn integrator(spec: &DynamicSpec) -> Box<dyn Integrator> {
    match spec.integrator {
        IntegratorKind::Average => Box::new(GeneralizedAlpha::newmark("average", 0.25, 0.5)),
        IntegratorKind::Linear => Box::new(GeneralizedAlpha::newmark("linear", 1.0 / 6.0, 0.5)),
        IntegratorKind::Hu => Box::new(GeneralizedAlpha::newmark("hu", 1.0, 1.5)),
        IntegratorKind::Newmark => {
            Box::new(GeneralizedAlpha::newmark("newmark", spec.beta, spec.gamma))
        }
        IntegratorKind::Wilson => Box::new(Wilson { theta: spec.theta }),
        IntegratorKind::Houbolt => Box::new(Houbolt::default()),
        IntegratorKind::Hht => Box::new(GeneralizedAlpha::hht(spec.alpha)),
        IntegratorKind::GeneralizedAlpha => {
            Box::new(GeneralizedAlpha::chung_hulbert(spec.rho_infinity))
        }
        IntegratorKind::CentralDifference => {
            unreachable!("the explicit driver runs central difference")
        }
    }
}

/// Refuses a dynamic model without mass on some free DOF (zero density).
pub fn check_mass(model: &Model, mass: &Mass, system: &System) -> Result<(), InputError> {
    for (dof, eq) in system.equation.iter().enumerate() {
        if eq.is_some() && !(mass.lumped[dof] > 0.0) {
            let node = dof / 2;
            let body = model
                .bodies
                .iter()
                .rev()
                .find(|b| b.node_offset <= node)
                .expect("node in a body");
            return Err(InputError::new(
                &model.file,
                format!(
                    "material `{}`.density: a dynamic analysis needs density > 0 (body `{}`)",
                    body.material.name, body.name
                ),
            ));
        }
    }
    Ok(())
}

/// The initial acceleration M a_0 = f_ext(0) - f_int(0) - C v_0 on the free DOFs (zero on
/// prescribed DOFs); solved with the mass matrix only when the right side is not zero.
fn initial_acceleration(
    model: &Model,
    state: &State,
    mass: &Mass,
    system: &mut System,
    solver: &mut Solver,
    velocity: &[f64],
    spec: &DynamicSpec,
) -> Result<(Vec<f64>, Vec<f64>), String> {
    let initial = model.coordinates();
    let external = loads::external_force(model, state, &initial, 0.0);
    let evaluation = assembly::evaluate(
        model,
        state,
        &vec![0.0; model.dofs()],
        spec.geometry,
        None,
        spec.newton.tangent,
    )
    .map_err(|e| e.to_string())?;
    let damping = mass.product(model, velocity);
    let rhs: Vec<f64> = external
        .iter()
        .zip(evaluation.force.iter().zip(&damping))
        .map(|(f, (fi, c))| f - fi - spec.rayleigh[0] * c)
        .collect();
    let mut free = system.gather(&rhs);
    let mut a = vec![0.0; model.dofs()];
    if free.iter().any(|v| *v != 0.0) {
        system.values.iter_mut().for_each(|v| *v = 0.0);
        mass.add_to(model, system, 1.0);
        solver.factor(&system.values).map_err(|e| e.to_string())?;
        solver.solve(&mut free);
        system.scatter_add(&free, &mut a);
    }
    Ok((a, evaluation.force))
}

pub fn run(
    model: &Model,
    spec: &DynamicSpec,
    dir: &Path,
    options: RunOptions,
    resume: Option<Checkpoint>,
) -> Result<Outcome, RunError> {
    let mut start = Instant::now();
    let setup_start = start;
    let initial = model.coordinates();
    let mut system = System::new(model, &loads::constrained_dofs(model));
    let mass =
        Mass::new(model, spec.mass).map_err(|e| InputError::new(&model.file, e.to_string()))?;
    check_mass(model, &mass, &system)?;
    let mut solver = Solver::new(&system.pattern).map_err(|e| super::setup_error(dir, e))?;
    let (mut recorder, resume) = match resume {
        Some(c) => {
            let Carry::Dynamic(carry) = c.carry.clone() else {
                return Err(super::wrong_carry(dir, "implicit dynamic"));
            };
            (
                Recorder::resume(model, dir, c.recorder.clone())?,
                Some((c, carry)),
            )
        }
        None => (Recorder::create(model, dir)?, None),
    };
    let mut state = State::initial(model);
    let mut method = integrator(spec);
    let steps = (spec.end_time / spec.dt).round().max(1.0) as usize;
    let mut summary = Summary::new(model, &method.name(), spec.dt, spec.end_time, system.free);
    let velocity = super::initial_velocity(model, &system, spec.dt);
    let (acceleration, mut last_internal) = match initial_acceleration(
        model,
        &state,
        &mass,
        &mut system,
        &mut solver,
        &velocity,
        spec,
    ) {
        Ok(x) => x,
        Err(reason) => {
            let message = format!("initial acceleration: {reason}");
            return Err(super::fail(&recorder, summary, Status::Diverged, message));
        }
    };
    let mut kin = MotionState {
        displacement: vec![0.0; model.dofs()],
        velocity,
        acceleration,
    };
    let mut energies = Energies {
        kinetic: mass.kinetic_energy(model, &kin.velocity),
        ..Default::default()
    };
    let mut initial_kinetic = energies.kinetic;
    summary.energy.initial = initial_kinetic;
    let mut monitor =
        super::buckling::Monitor::new(model, dir).map_err(|e| super::monitor_error(model, e))?;
    let mut last_total = total_force(
        model,
        &system,
        &mass,
        spec,
        &kin,
        &last_internal,
        &state,
        &initial,
    );
    let mut counters = Counters::default();
    let mut control = super::StepControl::new(spec.dt, spec.newton.max_cuts);
    // K* = ca M + cv C + w K_T: a factorization serves while these coefficients stay (the
    // step after a checkpoint factors afresh: a resumed run has no factorization)
    let mut factored_for: Option<[f64; 3]> = None;
    let mut increments = 0usize;
    let interfaces = super::interfaces(model);
    let mut contact = ContactState::new(&model.contacts);
    let penetration_limits = crate::contact::penetration_limits(&model.contacts, &initial);
    let mut last_contact = vec![0.0; model.dofs()];
    match resume {
        Some((checkpoint, carry)) => {
            state = carry.state;
            kin = carry.kinematics;
            method.restore(carry.method);
            energies = carry.energies;
            initial_kinetic = carry.initial_kinetic;
            last_total = carry.last_total;
            last_internal = carry.last_internal;
            last_contact = carry.last_contact;
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
            recorder.step(
                model,
                &state,
                &Motion {
                    velocity: &kin.velocity,
                    acceleration: &kin.acceleration,
                    mass: &mass.lumped,
                },
                &energies,
                true,
            )?;
        }
    }
    let progress = super::progress_bar(options.progress, steps);
    macro_rules! save {
        () => {{
            let carry = DynamicCarry {
                state: state.clone(),
                kinematics: kin.clone(),
                method: method.history(),
                energies,
                initial_kinetic,
                last_total: last_total.clone(),
                last_internal: last_internal.clone(),
                last_contact: last_contact.clone(),
                control: control.clone(),
                increments,
                contact: contact.clone(),
            };
            super::Bookkeeping {
                model,
                recorder: &recorder,
                summary: &summary,
                counters: &counters,
                solver: Some(&solver),
                start,
                buckling: monitor.as_ref().map(|m| &m.summary),
            }
            .save(Carry::Dynamic(carry))?;
            factored_for = None;
        }};
    }
    if summary.steps == 0 && model.checkpoint_every > 0 {
        save!();
    }
    crate::profile::add(crate::profile::Phase::Setup, setup_start);
    while state.time < spec.end_time * (1.0 - 1e-12) {
        // steps end at the listed frame times
        let next_frame = model
            .output
            .frame_times
            .iter()
            .copied()
            .find(|t| *t > state.time * (1.0 + 1e-9) + 1e-12 * spec.dt)
            .unwrap_or(f64::INFINITY);
        // a remainder shorter than the shortest step the control takes joins this step: a
        // step of 1e-7 dt (end_time written with a few digits) does not converge
        let stop = spec.end_time.min(next_frame);
        let mut end = (state.time + control.length).min(stop);
        if stop - end < control.shortest() {
            end = stop;
        }
        let target = super::snap(end, spec.dt);
        let nominal = super::step_length(target - state.time, spec.dt);
        let positions = state.positions(spec.geometry);
        let kinetic_before_impact = mass.kinetic_energy(model, &kin.velocity);
        contact.close_touching(
            &interfaces,
            &positions,
            &mass.lumped,
            &mut kin.velocity,
            &mut kin.acceleration,
        );
        energies.contact_work += kinetic_before_impact - mass.kinetic_energy(model, &kin.velocity);
        // one attempt of the step with a given length and active contact set
        let attempt = |h: f64,
                       active: &[(usize, usize)],
                       forces: Vec<f64>,
                       tangential: &[Tangential]| {
            let form = method.form(h, &kin);
            let solve_time = state.time + form.solve_fraction * h;
            let mut d: Vec<f64> = kin
                .velocity
                .iter()
                .map(|v| form.solve_fraction * h * v)
                .collect();
            for (dof, value) in loads::prescribed(model, &initial, solve_time) {
                d[dof] = value - kin.displacement[dof];
            }
            let external =
                loads::external_force(model, &state, &initial, state.time + form.load_fraction * h);
            let coefficients = [
                form.mass_coefficient,
                form.damping_coefficient,
                form.internal_weight,
            ];
            let factor_first = factored_for != Some(coefficients)
                || match spec.newton.strategy {
                    Strategy::Full => true,
                    Strategy::Modified => increments.is_multiple_of(spec.newton.refactor_every),
                    Strategy::Initial => !solver.is_factored(),
                };
            let step = Step {
                model,
                geometry: spec.geometry,
                newton: &spec.newton,
                inertia: Some(Inertia {
                    mass: &mass,
                    rayleigh: spec.rayleigh,
                }),
                form: &form,
                external: &external,
                internal_start: &last_internal,
                factor_first,
                contact: Some(Constraints {
                    pairs: &model.contacts,
                    active,
                    start: &positions,
                    forces,
                    tangential,
                }),
            };
            let result = step.solve(&state, d, &mut system, &mut solver, &mut counters);
            factored_for = if solver.is_factored() {
                Some(coefficients)
            } else {
                None
            };
            result
        };
        let outcome = contact
            .step(&model.contacts, &positions, nominal, attempt)
            .and_then(|mut step| {
                let h = step.length;
                let form = method.form(h, &kin);
                let advance = method.advance(h, &kin, &step.solution.d);
                if form.solve_fraction != 1.0 {
                    // Wilson: the state at t_{n+1} from the interpolated increment
                    let mut du = advance.increment.clone();
                    for (dof, value) in loads::prescribed(model, &initial, state.time + h) {
                        du[dof] = value - kin.displacement[dof];
                    }
                    step.solution.evaluation = assembly::evaluate(
                        model,
                        &state,
                        &du,
                        spec.geometry,
                        None,
                        spec.newton.tangent,
                    )
                    .map_err(|e| StepFailure(e.to_string()))?;
                    step.solution.d = du;
                }
                Ok((step, advance))
            });
        match outcome {
            Ok((mut step, advance)) => {
                let h = step.length;
                let d = std::mem::take(&mut step.solution.d);
                let evaluation = std::mem::take(&mut step.solution.evaluation);
                let internal = evaluation.force.clone();
                assembly::commit(model, &mut state, &d, evaluation, spec.geometry);
                state.time = if h == nominal { target } else { state.time + h };
                let previous_velocity = std::mem::replace(&mut kin.velocity, advance.velocity);
                kin.acceleration = advance.acceleration;
                for (u, du) in kin.displacement.iter_mut().zip(&d) {
                    *u += du;
                }
                let kinetic_before = mass.kinetic_energy(model, &kin.velocity);
                let positions = state.positions(spec.geometry);
                crate::contact::apply_conditions(
                    &interfaces,
                    &mut step,
                    &positions,
                    &mass.lumped,
                    &previous_velocity,
                    &mut kin.velocity,
                    &mut kin.acceleration,
                );
                contact.commit(&interfaces, &step, state.time, &positions);
                let contact_force = contact.nodal_forces(&model.contacts, &positions);
                let total = total_force(
                    model, &system, &mass, spec, &kin, &internal, &state, &initial,
                );
                energies.external_work += super::trapezoid_work(&d, &total, &last_total);
                energies.kinetic = mass.kinetic_energy(model, &kin.velocity);
                // energy taken up by the interface: minus the work of the contact forces on
                // the bodies, plus what the impact/release conditions removed
                energies.contact_work += -super::trapezoid_work(&d, &contact_force, &last_contact)
                    + kinetic_before
                    - energies.kinetic;
                energies.internal = state.internal_work - state.plastic_work;
                energies.plastic_work = state.plastic_work;
                summary.energy.max_relative_drift = summary
                    .energy
                    .max_relative_drift
                    .max(super::balance_error(&energies, initial_kinetic));
                last_total = total;
                last_internal = internal;
                last_contact = contact_force;
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
                let motion = Motion {
                    velocity: &kin.velocity,
                    acceleration: &kin.acceleration,
                    mass: &mass.lumped,
                };
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
                progress.set_position((state.time / spec.dt).round() as u64);
                control.accept(true);
                if stop {
                    summary.message = Some(super::statics::stop_message(&state, &recorder));
                    break;
                }
                let interrupted = !last && options.interrupted();
                if interrupted {
                    let motion = Motion {
                        velocity: &kin.velocity,
                        acceleration: &kin.acceleration,
                        mass: &mass.lumped,
                    };
                    recorder.frame(model, &state, &motion, Some(&contact))?;
                }
                if interrupted || (!last && super::checkpoint_due(model, summary.steps)) {
                    save!();
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
                method.reject();
                if let Err(why) = control.reject(nominal, &mut counters) {
                    progress.abandon();
                    let message = format!("step to t = {target} {why}: {reason}");
                    summary.finish(&energies, &counters, Some(&solver), start);
                    summary.contact = contact.summary();
                    summary.buckling = monitor.as_ref().map(|m| m.summary.clone());
                    return Err(super::fail(&recorder, summary, Status::Diverged, message));
                }
            }
        }
    }
    summary.contact = contact.summary();
    progress.finish_and_clear();
    summary.finish(&energies, &counters, Some(&solver), start);
    summary.buckling = monitor.map(|m| m.summary);
    recorder.write_summary(&summary)?;
    let contact_force = contact.nodal_forces(&model.contacts, &state.positions(spec.geometry));
    Ok(Outcome {
        summary,
        state,
        contact_force,
    })
}

/// F: f_ext on the free DOFs, the reaction M a + a_R M v + f_int on the prescribed ones.
#[allow(clippy::too_many_arguments)]
fn total_force(
    model: &Model,
    system: &System,
    mass: &Mass,
    spec: &DynamicSpec,
    kin: &MotionState,
    internal: &[f64],
    state: &State,
    initial: &[[f64; 2]],
) -> Vec<f64> {
    let external = loads::external_force(model, state, initial, state.time);
    let ma = mass.product(model, &kin.acceleration);
    let mv = mass.product(model, &kin.velocity);
    (0..model.dofs())
        .map(|i| match system.equation[i] {
            Some(_) => external[i],
            None => ma[i] + spec.rayleigh[0] * mv[i] + internal[i],
        })
        .collect()
}
