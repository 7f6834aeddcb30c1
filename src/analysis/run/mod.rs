//! The run scaffold: one type owns a run's bookkeeping (recorder, summary, counters,
//! progress, the buckling monitor, checkpoints, resume, interruption and failure) around a
//! [`Stepper`] that only advances the state. Every analysis (static load stepping, implicit
//! and explicit time stepping) is a stepper; the summary and the [`Outcome`] are filled
//! here, in one place, whatever the stepper.
//!
//! The life of a run
//! ```text
//! set up the stepper (bad input: exit 2, nothing written)
//! create the output (or resume it from a checkpoint, with the stepper's carry)
//! start the stepper at t = 0 and record that state        (not when resuming)
//! while the stepper is not done:
//!     advance one converged step (the stepper cuts and retries inside)
//!     count it, update the energy drift, judge it (explicit: blow-up)
//!     observe buckling, record a history row (and a frame when due)
//!     stop on a runaway penetration, a critical state asked to stop, or a signal
//!     write a checkpoint when due
//! finish: summary.json, the outcome
//! ```

pub mod buckling;
pub mod checkpoint;
pub mod columns;
pub mod contact_record;
mod energy_guard;
mod frame;
mod probes;
pub mod progress;
pub mod record;
pub mod tally;

use super::plausibility;
use super::steppers::Stepper;
use super::steppers::energies::{Energies, relative_gain};
use super::steppers::newton::Counters;
use super::summary::{DtLimit, MassScalingSummary, RunError, Status, StepError, Summary};
use super::units;
use crate::assembly::State;
use crate::output::readable;
use crate::profile::{self, Phase};
use crate::scene::model::Analysis;
use crate::scene::{InputError, Model};
use buckling::Monitor;
use checkpoint::Checkpoint;
use energy_guard::negative_plastic_work;
use progress::Progress;
use record::{Recorder, Snapshot};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use tally::StepIterations;

/// Options of a run that are not part of the scene.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// How the run shows its progress (a bar, plain lines, nothing).
    pub progress: progress::Mode,
    /// Set (by a signal handler) to stop the run after the step in progress.
    pub interrupt: Option<&'static AtomicBool>,
    /// For tests: stop dead after this many converged steps, writing nothing more (as a
    /// SIGKILL would), returning `RunError::Interrupted`.
    pub halt_after_steps: Option<usize>,
    /// Write no VTK frames, whatever the scene asks (`impact sweep` without `--frames`); the
    /// frame times still end steps, so the numbers are those of `impact run`.
    pub no_frames: bool,
}

impl RunOptions {
    fn interrupted(&self) -> bool {
        self.interrupt.is_some_and(|f| f.load(Ordering::SeqCst))
    }

    /// The test hook `halt_after_steps`: the error to return after `steps` steps.
    fn halt(&self, summary: &Summary) -> Result<(), RunError> {
        if self.halt_after_steps == Some(summary.steps) {
            return Err(RunError::Interrupted {
                message: format!("halted after {} steps (test hook)", summary.steps),
                summary: Box::new(summary.clone()),
            });
        }
        Ok(())
    }
}

/// What a run leaves besides its files: the summary, the final committed state and the
/// final nodal contact forces (all DOFs; zero without contact).
pub struct Outcome {
    pub summary: Summary,
    pub state: State,
    pub contact_force: Vec<f64>,
}

/// What the run does after a step that went well.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Next {
    Continue,
    /// The buckling check asked to stop (`on_critical = "stop"`): the run ends here, its
    /// output complete.
    Stop,
}

/// A run in progress: the stepper and its bookkeeping.
struct Run<'a, S: Stepper> {
    model: &'a Model,
    options: RunOptions,
    stepper: S,
    recorder: Recorder,
    summary: Summary,
    counters: Counters,
    step_iterations: StepIterations,
    monitor: Option<Monitor>,
    start: Instant,
    progress: Progress,
    penetration_limits: Vec<f64>,
    /// The energies of the last row recorded: what the summary reports of a run whose last
    /// step was committed and then refused (negative plastic work is no row of history).
    recorded: Energies,
    refused_step: bool,
}

/// Runs `stepper` (set up from `start` on) from the beginning or from `resume`, writing
/// into `dir`.
pub fn execute<S: Stepper>(
    model: &Model,
    dir: &Path,
    options: RunOptions,
    resume: Option<Checkpoint>,
    (stepper, start): (S, Instant),
) -> Result<Outcome, RunError> {
    let mut run = Run::open(model, dir, options, resume, (stepper, start))?;
    profile::add(Phase::Setup, start);
    while !run.stepper.done() {
        if run.step()? == Next::Stop {
            break;
        }
    }
    run.finish()
}

impl<'a, S: Stepper> Run<'a, S> {
    /// The output created or resumed, the stepper started or restored, the first row and
    /// checkpoint written.
    fn open(
        model: &'a Model,
        dir: &Path,
        options: RunOptions,
        resume: Option<Checkpoint>,
        (mut stepper, start): (S, Instant),
    ) -> Result<Run<'a, S>, RunError> {
        let about = stepper.about();
        let mut recorder = match &resume {
            Some(c) => Recorder::resume(model, dir, c.recorder.clone())?,
            None => {
                let window = contact_record::window(model, about.dt);
                Recorder::create(model, dir, !options.no_frames, window)?
            }
        };
        let mut summary = Summary::new(
            model,
            &about.integrator,
            about.dt,
            about.end_time,
            about.free_dofs,
        );
        summary.column_units = units::column_units(model, columns::column_names(model));
        let coordinates = model.coordinates();
        let penetration_limits = crate::contact::penetration_limits(&model.contacts, &coordinates);
        let resuming = resume.is_some();
        if !resuming && let Err(message) = stepper.start() {
            let message = with_failure_hint(model, message, stepper.motion().velocity);
            let mut run_summary = summary;
            run_summary.status = Status::Diverged;
            run_summary.message = Some(message.clone());
            recorder.write_summary(model, &run_summary)?;
            return Err(RunError::Numerical {
                message,
                summary: Box::new(run_summary),
            });
        }
        let monitor = if about.checks_buckling {
            Monitor::new(model, dir).map_err(|e| monitor_error(model, e))?
        } else {
            None
        };
        let mut run = Run {
            model,
            options,
            stepper,
            recorder,
            summary,
            counters: Counters::default(),
            step_iterations: StepIterations::default(),
            monitor,
            start,
            progress: Progress::new(
                options.progress,
                &model.name,
                0.0,
                model.analysis.end_time(),
            ),
            penetration_limits,
            recorded: Energies::default(),
            refused_step: false,
        };
        run.summary.energy.initial = run.stepper.initial_kinetic();
        match resume {
            Some(checkpoint) => run.restore(checkpoint, dir)?,
            None => {
                if let Some(m) = &mut run.monitor {
                    let factor = run.stepper.row_features().load_factor;
                    run.recorder.negative_pivots = m
                        .observe(model, run.stepper.state(), factor, run.stepper.held())
                        .map_err(|e| monitor_error(model, e.into()))?
                        .0;
                }
                run.record(true)?;
            }
        }
        // a resumed run measures its rate from the checkpoint's time
        let time = run.stepper.state().time;
        run.progress.start_at(time);
        run.progress.update(time, run.summary.steps);
        if run.summary.steps == 0 && model.checkpoint_every > 0 && run.stepper.carry().is_ok() {
            run.save()?;
        }
        Ok(run)
    }

    /// Takes a checkpoint's bookkeeping and the stepper's carry.
    fn restore(&mut self, checkpoint: Checkpoint, dir: &Path) -> Result<(), RunError> {
        if !self.stepper.restore(checkpoint.carry.clone()) {
            return Err(RunError::Input(InputError::new(
                &checkpoint::path(dir),
                format!(
                    "the checkpoint does not hold the state of the scene's {} analysis",
                    self.stepper.kind()
                ),
            )));
        }
        self.summary = checkpoint.summary;
        self.counters = checkpoint.counters;
        self.step_iterations = checkpoint.step_iterations;
        if let Some(solver) = self.stepper.solver_mut() {
            solver.factorizations = checkpoint.factorizations;
            solver.solves = checkpoint.back_substitutions;
        }
        self.start = resumed_start(checkpoint.wall_seconds);
        if let (Some(m), Some(b)) = (&mut self.monitor, checkpoint.buckling) {
            m.resume(b, self.stepper.held());
        }
        Ok(())
    }

    /// One step and its bookkeeping, and whether the run goes on.
    fn step(&mut self) -> Result<Next, RunError> {
        let before = self.counters.iterations;
        if let Err(e) = self.stepper.advance(&mut self.counters) {
            return Err(self.fail_step(e));
        }
        self.step_iterations
            .record(self.counters.iterations - before);
        self.summary.steps += 1;
        let gain = relative_gain(self.stepper.energies(), self.stepper.initial_kinetic());
        let energy = &mut self.summary.energy;
        energy.max_relative_drift = energy.max_relative_drift.max(gain.abs());
        energy.max_relative_gain = energy.max_relative_gain.max(gain);
        if let Err(e) = self.stepper.verdict() {
            return Err(self.fail_step(e));
        }
        let e = self.stepper.energies();
        let energies = [
            e.kinetic,
            e.internal,
            e.plastic_work,
            e.external_work,
            e.contact_work,
        ];
        if energies.iter().any(|x| !x.is_finite()) {
            let time = self.stepper.state().time;
            let message = format!(
                "at t = {time}: the step left a state that is not finite (kinetic energy {}, \
                 internal {}, contact work {}); nothing of it was recorded",
                e.kinetic, e.internal, e.contact_work
            );
            return Err(self.fail(Status::Diverged, message));
        }
        if let Some(message) =
            negative_plastic_work(self.stepper.energies(), self.stepper.initial_kinetic())
        {
            let time = self.stepper.state().time;
            self.refused_step = true;
            return Err(self.fail(
                Status::Diverged,
                format!("at t = {}: {message}", readable(time)),
            ));
        }
        if let Some(message) = self.energy_created() {
            let time = self.stepper.state().time;
            self.stepper.sync_points();
            return Err(self.fail_with_cause(
                Status::Diverged,
                format!("at t = {}: {message}", readable(time)),
            ));
        }
        let stop = self.observe_buckling()?;
        let last = stop || self.stepper.done();
        self.record(last)?;
        let time = self.stepper.state().time;
        let runaway = profile::time(Phase::Contact, || {
            let positions = self
                .stepper
                .state()
                .positions(self.model.analysis.geometry());
            crate::contact::runaway_penetration(
                &self.stepper.contact().placed(&self.model.contacts, time),
                &positions,
                &self.penetration_limits,
            )
        });
        if let Some(message) = runaway {
            let message = format!("at t = {}: {message}", readable(time));
            return Err(self.fail(Status::Diverged, message));
        }
        self.progress.update(time, self.summary.steps);
        if stop {
            self.summary.message = Some(stop_message(time, &self.recorder));
            return Ok(Next::Stop);
        }
        let interrupted = !last && self.options.interrupted();
        if interrupted {
            self.stepper.sync_points();
            let s = &self.stepper;
            self.recorder
                .frame(self.model, s.state(), &s.motion(), Some(s.contact()))?;
        }
        let due = !last
            && self.model.checkpoint_every > 0
            && self
                .summary
                .steps
                .is_multiple_of(self.model.checkpoint_every);
        if (interrupted || due) && self.stepper.carry().is_ok() {
            self.save()?;
        }
        self.options.halt(&self.summary)?;
        if interrupted {
            return Err(self.interrupted(time));
        }
        Ok(Next::Continue)
    }

    /// The buckling check of the committed state: whether the run must stop here.
    fn observe_buckling(&mut self) -> Result<bool, RunError> {
        let Some(m) = &mut self.monitor else {
            return Ok(false);
        };
        let factor = self.stepper.row_features().load_factor;
        match m.observe(
            self.model,
            self.stepper.state(),
            factor,
            self.stepper.held(),
        ) {
            Ok((count, halt)) => {
                self.recorder.negative_pivots = count;
                Ok(halt)
            }
            Err(e) => {
                let message = format!(
                    "buckling check at t = {}: {e}",
                    readable(self.stepper.state().time)
                );
                Err(self.fail(Status::Diverged, message))
            }
        }
    }

    /// A history row of the committed state (and a frame when due, or when `last`).
    fn record(&mut self, last: bool) -> Result<(), RunError> {
        let time = self.stepper.state().time;
        self.recorder.step_length = self.stepper.last_step();
        // point probes from the stepper's own values, unless the points are copied anyway
        // (a frame, or a probe it cannot answer): then all fold over the copied points
        let s = &self.stepper;
        self.recorder.point_probes = self.model.probes.iter().map(|p| s.point_probe(p)).collect();
        if self.recorder.reads_stresses(self.model, time, last) {
            self.recorder.point_probes.clear();
            self.stepper.sync_points();
        }
        let features = self.stepper.row_features();
        if let Some(energy) = features.hourglass_energy {
            self.recorder.hourglass_energy = energy;
        }
        if let Some(watch) = features.error_watch {
            self.recorder.error_estimate = watch.last;
        }
        if let Some(added) = features.added_mass {
            self.recorder.added_mass = added;
        }
        if let Some(factor) = features.load_factor {
            self.recorder.load_factor = factor;
        }
        if columns::body_columns(self.model) {
            self.recorder.body_kinetic = self.stepper.body_kinetic(self.model);
        }
        let s = &self.stepper;
        let contact = (self.summary.steps > 0).then(|| s.contact());
        let motion = s.motion();
        let snapshot = Snapshot {
            state: s.state(),
            motion: &motion,
            energies: s.energies(),
            contact,
            frame_contact: Some(s.contact()),
        };
        self.recorder.step(self.model, snapshot, last)?;
        self.recorded = *s.energies();
        Ok(())
    }

    /// Writes a checkpoint of the run as it stands.
    fn save(&mut self) -> Result<(), RunError> {
        let carry = self.stepper.carry().expect("checked by the caller");
        let _timer = profile::Timer::new(Phase::Output);
        let solver = self.stepper.solver();
        let checkpoint = Checkpoint {
            // absolute when the file exists, so `impact resume` works from any folder (mesh
            // files are found next to the scene)
            scene_path: std::fs::canonicalize(&self.model.file)
                .unwrap_or_else(|_| self.model.file.clone())
                .display()
                .to_string(),
            source: self.model.source.clone(),
            summary: self.summary.clone(),
            counters: self.counters,
            step_iterations: self.step_iterations.clone(),
            factorizations: solver.map_or(0, |s| s.factorizations),
            back_substitutions: solver.map_or(0, |s| s.solves),
            wall_seconds: self.start.elapsed().as_secs_f64(),
            recorder: self.recorder.position()?,
            buckling: self.monitor.as_ref().map(|m| m.summary.clone()),
            carry,
        };
        checkpoint::write(self.recorder.dir(), &checkpoint)?;
        self.stepper.after_checkpoint();
        Ok(())
    }

    /// Fills the summary's counters, energies, contact and buckling blocks and the highest
    /// temperature: the one place.
    fn fill_summary(&mut self) {
        if self.model.carries_temperature() {
            self.stepper.sync_points();
        }
        let s = &self.stepper;
        let energies = if self.refused_step {
            &self.recorded
        } else {
            s.energies()
        };
        let solver = s.solver();
        let (row, run) = (s.row_features(), s.run_features());
        let summary = &mut self.summary;
        summary.newton_iterations = self.counters.iterations;
        summary.newton_iterations_median = self.step_iterations.median();
        summary.newton_iterations_max = self.step_iterations.max();
        summary.step_cuts = self.counters.cuts;
        summary.rejected_steps = self.counters.rejected;
        summary.max_error_estimate = row.error_watch.map(|w| w.largest);
        summary.factorizations = solver.map_or(0, |s| s.factorizations);
        summary.back_substitutions = solver.map_or(0, |s| s.solves);
        summary.wall_seconds = self.start.elapsed().as_secs_f64();
        summary.timing = profile::snapshot();
        summary.energy.final_ = energies.kinetic + energies.internal;
        summary.energy.plastic_dissipation = energies.plastic_work;
        summary.energy.bulk_viscosity_work = self
            .model
            .analysis
            .bulk_viscosity()
            .map(|_| energies.bulk_viscosity_work);
        summary.energy.mass_scaling_loss = self
            .model
            .analysis
            .mass_scaling()
            .map(|_| energies.mass_scaling_loss);
        summary.energy.remap_loss = self.model.analysis.ale().map(|_| energies.remap_loss);
        summary.energy.friction_work =
            columns::friction_column(self.model).then_some(energies.friction_work);
        let kinetic = s.body_kinetic(self.model);
        for ((entry, body), kinetic) in summary
            .bodies
            .iter_mut()
            .zip(&s.state().bodies)
            .zip(kinetic)
        {
            entry.kinetic_energy = kinetic;
            entry.internal_energy = body.work.internal - body.work.plastic;
            entry.plastic_work = body.work.plastic;
        }
        summary.ale = run.ale;
        summary.arc_length = run.arc_length;
        let mass_scaling = run.mass_scaling;
        summary.mass_scaling = mass_scaling
            .as_ref()
            .map(|r| MassScalingSummary::of(r, self.model));
        summary.subcycling = run.subcycling;
        summary.contact = s.contact().summary(&self.model.contacts);
        if !matches!(self.model.analysis, Analysis::Dynamic(_)) {
            // statics books no energy of its contact
            summary.contact.pairs.clear();
        }
        if let Some(record) = &self.recorder.contact {
            record.fill(self.model, &mut summary.contact, s.contact());
        }
        summary.buckling = self.monitor.as_ref().map(|m| m.summary.clone());
        if let Some(report) = &run.time_step {
            summary.dt_min = Some(report.shortest);
            summary.dt_max = Some(report.longest);
            summary.dt_limit = Some(DtLimit::of(report.limit, self.model));
        }
        summary.max_temperature = record::max_temperature(self.model, s.state());
        let first_step = run.time_step.as_ref().map(|report| report.first);
        let positions = s.state().positions(self.model.analysis.geometry());
        summary.warnings = plausibility::warnings(
            self.model,
            summary,
            energies,
            (first_step, Some(&positions)),
        );
        let motion = s.motion();
        let end = plausibility::EndOfRun {
            positions: &positions,
            energies,
            hourglass_energy: row.hourglass_energy,
            mass_scaling: mass_scaling.as_ref(),
            velocity: motion.velocity,
            mass: motion.mass,
            closed_at_end: &summary.contact.closed_at_end,
            finished: summary.status == Status::Ok && s.done(),
            contact: Some(s.contact()),
        };
        let more = plausibility::final_warnings(self.model, &end);
        summary.warnings.extend(more);
    }

    /// A failed step: its frame when asked, then `fail`.
    fn fail_step(&mut self, e: StepError) -> RunError {
        if e.frame {
            self.stepper.sync_points();
            let s = &self.stepper;
            self.recorder
                .frame(self.model, s.state(), &s.motion(), Some(s.contact()))
                .ok();
        }
        self.fail(e.status, e.message)
    }

    /// A failed run: the summary is written with its status and message, then returned in
    /// the error.
    fn fail(&mut self, status: Status, message: String) -> RunError {
        let message = with_failure_hint(self.model, message, self.stepper.motion().velocity);
        self.fail_with_cause(status, message)
    }

    /// As `fail`, for a failure whose message names its cause already (the state's speeds
    /// would point to units where the run itself made them). A slave that went past the end
    /// of its obstacle before the failure is named in either.
    fn fail_with_cause(&mut self, status: Status, message: String) -> RunError {
        let past_end = (self.recorder.contact.as_ref()).and_then(|r| r.carry.past_end.as_ref());
        let message = match past_end {
            Some(p) => format!("{message}; before it, {}", plausibility::past_end_text(p)),
            None => message,
        };
        self.progress
            .finish(self.stepper.state().time, self.summary.steps);
        // the warnings read how the run ended (a pair that never closed in a run that
        // stopped early is no reason to lengthen the end time)
        self.summary.status = status;
        self.summary.message = Some(message.clone());
        self.fill_summary();
        let summary = self.summary.clone();
        match self.recorder.write_summary(self.model, &summary) {
            Ok(()) => RunError::Numerical {
                message,
                summary: Box::new(summary),
            },
            Err(e) => RunError::Output(e),
        }
    }

    /// A run stopped by a signal after a whole step: summary.json with status `interrupted`.
    fn interrupted(&mut self, time: f64) -> RunError {
        self.progress
            .finish(self.stepper.state().time, self.summary.steps);
        self.fill_summary();
        let what_next = match self.stepper.carry() {
            Ok(_) => format!(
                "`impact resume {}` continues",
                self.recorder.dir().display()
            ),
            Err(reason) => reason.to_string(),
        };
        let message = format!(
            "interrupted by a signal at t = {} after {} steps; {what_next}",
            readable(time),
            self.summary.steps
        );
        let mut summary = self.summary.clone();
        summary.status = Status::Interrupted;
        summary.message = Some(message.clone());
        match self.recorder.write_summary(self.model, &summary) {
            Ok(()) => RunError::Interrupted {
                message,
                summary: Box::new(summary),
            },
            Err(e) => RunError::Output(e),
        }
    }

    /// A run stopped before its end time on purpose (the buckling check's `stop`).
    fn finish(mut self) -> Result<Outcome, RunError> {
        self.progress
            .finish(self.stepper.state().time, self.summary.steps);
        self.end()
    }

    /// The summary written and the outcome of a run that reached its end.
    fn end(&mut self) -> Result<Outcome, RunError> {
        self.stepper.sync_points();
        self.fill_summary();
        self.recorder.write_summary(self.model, &self.summary)?;
        let positions = self
            .stepper
            .state()
            .positions(self.model.analysis.geometry());
        let contact = self.stepper.contact();
        let pairs = contact.placed(&self.model.contacts, self.stepper.state().time);
        let contact_force = contact.nodal_forces(&pairs, &positions);
        Ok(Outcome {
            summary: self.summary.clone(),
            state: self.stepper.state().clone(),
            contact_force,
        })
    }
}

/// The buckling check could not be set up: its modes (bad input: nothing to buckle, missing
/// supports) or its frames.
fn monitor_error(model: &Model, e: buckling::MonitorError) -> RunError {
    match e {
        buckling::MonitorError::Modes(e) => RunError::Input(InputError::new(
            &model.file,
            format!("analysis.buckling: {e}"),
        )),
        buckling::MonitorError::Output(e) => RunError::Output(e),
    }
}

/// The message of a numerical failure, with what the state says of mixed units or of a
/// local blow-up when it says something (`plausibility::failure_hint`).
fn with_failure_hint(model: &Model, message: String, velocity: &[f64]) -> String {
    match plausibility::failure_hint(model, velocity) {
        Some(hint) => format!("{message}; {hint}"),
        None => message,
    }
}

/// The start instant of a resumed run: as if it had been running for `wall_seconds`.
fn resumed_start(wall_seconds: f64) -> Instant {
    let now = Instant::now();
    now.checked_sub(std::time::Duration::from_secs_f64(wall_seconds.max(0.0)))
        .unwrap_or(now)
}

/// summary.json `message` of a run stopped by `on_critical = "stop"`.
fn stop_message(time: f64, recorder: &Recorder) -> String {
    format!(
        "stopped by analysis.buckling.on_critical at t = {}: K_T has {} negative pivot(s)",
        readable(time),
        recorder.negative_pivots.unwrap_or(0)
    )
}
