//! Static load stepping with full or modified Newton-Raphson (Erklig 2.1.2).
//!
//! Legend
//! ```text
//! t, dt      pseudo time and its increment; loads follow their curves in t
//! d          displacement increment since the last converged configuration
//! R          F_ext(t) - f_int(d) on the free DOFs (Erklig 2.1.2 (vii))
//! eps_1      ||delta d|| / ||d||         (Erklig 2.1.2 (viii), first measure)
//! eps_2      ||R|| / ||F||, F = the larger of ||F_ext|| and ||f_int|| over all DOFs (the
//!            reactions stand in for F_ext when only displacements are prescribed)
//! ```
//! An increment that does not converge in `max_iterations` (or meets an inverted element or a
//! tangent that is not positive definite) is halved, at most `max_cuts` times in a row; then
//! the run stops `diverged` with its output so far kept.

use super::record::{Energies, Motion, Recorder};
use super::{EnergySummary, RunError, RunOptions, Status, Summary, loads};
use crate::assembly::{self, State, System};
use crate::scene::Model;
use crate::scene::spec::{NewtonSpec, StaticSpec, Strategy};
use crate::solver::Solver;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::time::Instant;

/// Counters of the nonlinear solution.
#[derive(Debug, Clone, Copy, Default)]
pub struct Counters {
    pub iterations: usize,
    pub cuts: usize,
}

/// The increment failed to converge: why (for the message after the last cut).
#[derive(Debug, Clone)]
pub struct IncrementFailure(pub String);

/// Runs a static analysis and writes its output into `dir`.
pub fn run(
    model: &Model,
    spec: &StaticSpec,
    dir: &Path,
    options: RunOptions,
) -> Result<(Summary, State), RunError> {
    let start = Instant::now();
    let mut recorder = Recorder::create(model, dir)?;
    let initial = model.coordinates();
    let constrained = loads::constrained_dofs(model);
    let mut system = System::new(model, &constrained);
    let mut solver = Solver::new(&system.pattern).map_err(|e| {
        RunError::Output(crate::output::OutputError::Invalid {
            path: dir.to_path_buf(),
            reason: e.to_string(),
        })
    })?;
    let mut state = State::initial(model);
    let zeros = vec![0.0; model.dofs()];
    let motion = Motion {
        velocity: &zeros,
        acceleration: &zeros,
    };
    let mut energies = Energies::default();
    let mut last_force = vec![0.0; model.dofs()];
    recorder.step(model, &state, &motion, &energies, true)?;

    let dt = spec.end_time / spec.steps as f64;
    let mut summary = Summary {
        scene: model.file.display().to_string(),
        title: model.title.clone(),
        status: Status::Ok,
        message: None,
        integrator: "static".into(),
        dt,
        steps: 0,
        end_time: spec.end_time,
        nodes: model.node_count,
        elements: model.elements(),
        dofs: model.dofs(),
        free_dofs: system.free,
        wall_seconds: 0.0,
        newton_iterations: 0,
        factorizations: 0,
        back_substitutions: 0,
        step_cuts: 0,
        contact: Default::default(),
        energy: EnergySummary::default(),
        buckling: None,
    };
    let progress = progress_bar(options.progress, spec.steps);
    let mut counters = Counters::default();
    let mut step_dt = dt;
    let mut cuts_in_a_row = 0;
    while state.time < spec.end_time * (1.0 - 1e-12) {
        let target = snap((state.time + step_dt).min(spec.end_time), dt);
        match increment(
            model,
            spec,
            &state,
            &initial,
            target,
            &mut system,
            &mut solver,
            &mut counters,
        ) {
            Ok((d, evaluation)) => {
                let force = evaluation.force.clone();
                assembly::commit(model, &mut state, &d, evaluation, spec.geometry);
                state.time = target;
                energies.external_work += 0.5
                    * d.iter()
                        .zip(force.iter().zip(&last_force))
                        .map(|(u, (f1, f0))| u * (f1 + f0))
                        .sum::<f64>();
                energies.internal = state.internal_work;
                last_force = force;
                summary.steps += 1;
                let last = state.time >= spec.end_time * (1.0 - 1e-12);
                recorder.step(model, &state, &motion, &energies, last)?;
                progress.set_position((state.time / dt).round() as u64);
                cuts_in_a_row = 0;
            }
            Err(IncrementFailure(reason)) => {
                if cuts_in_a_row >= spec.newton.max_cuts {
                    progress.abandon();
                    let message = format!(
                        "increment to t = {target} did not converge after {cuts_in_a_row} cuts (dt = {step_dt:e}): {reason}"
                    );
                    finish(&mut summary, &energies, &counters, &solver, start);
                    summary.status = Status::Diverged;
                    summary.message = Some(message.clone());
                    recorder.write_summary(&summary)?;
                    return Err(RunError::Numerical {
                        message,
                        summary: Box::new(summary),
                    });
                }
                step_dt *= 0.5;
                cuts_in_a_row += 1;
                counters.cuts += 1;
                continue;
            }
        }
        // after a cut the step grows back towards the nominal one
        step_dt = (step_dt * 2.0).min(dt);
    }
    progress.finish_and_clear();
    finish(&mut summary, &energies, &counters, &solver, start);
    recorder.write_summary(&summary)?;
    Ok((summary, state))
}

fn finish(
    summary: &mut Summary,
    energies: &Energies,
    counters: &Counters,
    solver: &Solver,
    start: Instant,
) {
    summary.newton_iterations = counters.iterations;
    summary.step_cuts = counters.cuts;
    summary.factorizations = solver.factorizations;
    summary.back_substitutions = solver.solves;
    summary.wall_seconds = start.elapsed().as_secs_f64();
    summary.energy.final_ = energies.internal;
    let scale = energies.external_work.abs().max(energies.internal.abs());
    summary.energy.max_relative_drift = if scale > 0.0 {
        (energies.internal - energies.external_work).abs() / scale
    } else {
        0.0
    };
}

fn progress_bar(show: bool, steps: usize) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(steps as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} steps {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// Rounds a time that is a whole number of nominal steps up to round-off onto that multiple,
/// so history rows fall on k dt exactly.
fn snap(t: f64, dt: f64) -> f64 {
    let k = (t / dt).round();
    if (t - k * dt).abs() <= 1e-9 * dt {
        k * dt
    } else {
        t
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// One load increment to pseudo time `target`: Newton iterations from d = 0 (prescribed DOFs
/// set to their increments). Returns the converged increment and its evaluation.
#[allow(clippy::too_many_arguments)]
fn increment(
    model: &Model,
    spec: &StaticSpec,
    state: &State,
    initial: &[[f64; 2]],
    target: f64,
    system: &mut System,
    solver: &mut Solver,
    counters: &mut Counters,
) -> Result<(Vec<f64>, assembly::Evaluation), IncrementFailure> {
    let newton: &NewtonSpec = &spec.newton;
    let mut d = vec![0.0; model.dofs()];
    for (dof, value) in loads::prescribed(model, initial, target) {
        d[dof] = value - state.displacement[dof];
    }
    let external = loads::external_force(model, state, initial, target);
    let external_norm = norm(&system.gather(&external));
    let mut previous_residual = f64::INFINITY;
    let mut eps_displacement = f64::INFINITY;
    for iteration in 0..=newton.max_iterations {
        let refactor = match newton.strategy {
            Strategy::Full => true,
            Strategy::Modified => iteration == 0,
        };
        let evaluation = evaluate(model, state, &d, spec, refactor.then_some(&mut *system))?;
        let mut residual = system.gather(&external);
        let internal = system.gather(&evaluation.force);
        residual
            .iter_mut()
            .zip(&internal)
            .for_each(|(r, f)| *r -= f);
        let residual_norm = norm(&residual);
        if !residual_norm.is_finite() {
            return Err(IncrementFailure(
                "the residual is not finite (NaN or Inf)".into(),
            ));
        }
        let scale = external_norm.max(norm(&evaluation.force));
        let eps_force = if scale > 0.0 {
            residual_norm / scale
        } else {
            0.0
        };
        if iteration > 0
            && eps_displacement < newton.tol_displacement
            && eps_force < newton.tol_force
        {
            return Ok((d, evaluation));
        }
        if iteration > 0 && residual_norm == 0.0 {
            return Ok((d, evaluation));
        }
        if iteration == newton.max_iterations {
            break;
        }
        let stalled = newton.strategy == Strategy::Modified
            && iteration > 0
            && residual_norm > newton.contraction * previous_residual;
        if stalled {
            // the same state again, now with the tangent assembled
            evaluate(model, state, &d, spec, Some(&mut *system))?;
        }
        if refactor || stalled {
            solver
                .factor(&system.values)
                .map_err(|e| IncrementFailure(e.to_string()))?;
        }
        solver.solve(&mut residual);
        counters.iterations += 1;
        system.scatter_add(&residual, &mut d);
        let d_norm = norm(&d);
        eps_displacement = if d_norm > 0.0 {
            norm(&residual) / d_norm
        } else {
            0.0
        };
        previous_residual = residual_norm;
    }
    Err(IncrementFailure(format!(
        "no convergence in {} iterations",
        newton.max_iterations
    )))
}

fn evaluate(
    model: &Model,
    state: &State,
    d: &[f64],
    spec: &StaticSpec,
    system: Option<&mut System>,
) -> Result<assembly::Evaluation, IncrementFailure> {
    assembly::evaluate(model, state, d, spec.geometry, system)
        .map_err(|e| IncrementFailure(e.to_string()))
}
