//! The analyses: one run scaffold (`run`: recording, summary, checkpoints, resume,
//! interruption, failure) around the steppers that advance the state: static load stepping
//! (`statics`), implicit time stepping (`dynamics`) and explicit central difference
//! (`explicit`); their output is VTK frames, history.csv and summary.json (`record`).

pub mod buckling;
pub mod check;
pub mod checkpoint;
pub mod clock;
pub mod dynamics;
pub mod explicit;
pub mod loads;
pub mod newton;
pub mod plausibility;
pub mod progress;
pub mod record;
pub mod run;
pub mod stable;
pub mod statics;

use crate::assembly::{StableStep, State};
use crate::output::{OutputError, readable};
use crate::scene::{InputError, Model};
use newton::Counters;
use record::Energies;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// A step that could not be taken: the run ends with this status and message.
#[derive(Debug, Clone)]
pub struct StepError {
    pub status: Status,
    pub message: String,
    /// Write a frame of the state reached (the explicit blow-up shows what blew up).
    pub frame: bool,
}

impl StepError {
    pub fn diverged(message: String) -> StepError {
        StepError {
            status: Status::Diverged,
            message,
            frame: false,
        }
    }
}

/// How a run ended (summary.json `status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Ok,
    Diverged,
    Unstable,
    /// Stopped by SIGINT or SIGTERM after a whole step; `impact resume DIR` continues it.
    Interrupted,
}

pub use crate::contact::ContactSummary;

/// The contact problem of `model` as contact sees it: the pairs, and per body its section
/// and plane-wave impedance for the impact and release conditions.
pub fn interfaces(model: &Model) -> crate::contact::Interfaces {
    use crate::contact::{BodySurface, Section};
    use crate::element::Formulation;
    use crate::scene::BodyKind;
    let bodies = model
        .bodies
        .iter()
        .map(|b| {
            let section = match b.kind {
                BodyKind::Rod { area } => Section::Rod { area },
                BodyKind::Continuum {
                    formulation,
                    thickness,
                    ..
                } => match formulation {
                    Formulation::PlaneStrain => Section::Plane { thickness: 1.0 },
                    Formulation::PlaneStress => Section::Plane { thickness },
                    Formulation::Axisymmetric => Section::Axisymmetric,
                },
            };
            BodySurface {
                section,
                impedance_per_area: (b.p_wave_modulus() * b.material.density).sqrt(),
                boundary_at_node: b
                    .boundary_at_node
                    .iter()
                    .map(|edges| edges.iter().map(|e| e.map(|n| b.global(n))).collect())
                    .collect(),
                boundary: (b.mesh.boundary_edges().iter())
                    .map(|e| e.map(|n| b.global(n)))
                    .collect(),
                node_offset: b.node_offset,
            }
        })
        .collect();
    crate::contact::Interfaces {
        pairs: model.contacts.clone(),
        bodies,
    }
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct EnergySummary {
    pub initial: f64,
    #[serde(rename = "final")]
    pub final_: f64,
    /// max over the steps of |KE + W_elastic + W_plastic + W_contact - KE_0 - W_ext| /
    /// max(KE_0, |W_ext|, |W_elastic|).
    pub max_relative_drift: f64,
    pub plastic_dissipation: f64,
}

pub use buckling::BucklingSummary;

/// summary.json's form of a [`StableStep`] (the stable step of the last
/// configuration, from the element bound, before the scale): the body by name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DtLimit {
    pub dt: f64,
    pub body: String,
    pub element: usize,
}

impl DtLimit {
    pub fn of(step: StableStep, model: &Model) -> DtLimit {
        DtLimit {
            dt: step.dt,
            body: model.bodies[step.body].name.clone(),
            element: step.element,
        }
    }
}

/// summary.json (the output contract of docs/user-guide.md): other tools read it; fields
/// are only ever added.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Summary {
    pub scene: String,
    pub title: String,
    pub status: Status,
    /// Set when status is not `ok`: what failed, where and when.
    pub message: Option<String>,
    pub integrator: String,
    /// The (nominal) time or pseudo-time step.
    pub dt: f64,
    /// Converged increments (sub-increments count one each).
    pub steps: usize,
    pub end_time: f64,
    pub nodes: usize,
    pub elements: usize,
    pub dofs: usize,
    pub free_dofs: usize,
    pub wall_seconds: f64,
    pub newton_iterations: usize,
    pub factorizations: usize,
    pub back_substitutions: usize,
    pub step_cuts: usize,
    /// Implicit `dt = "auto"`: steps taken again shorter because their error estimate was
    /// above `error_tolerance` (apart from `step_cuts`, the cuts after a failed Newton).
    #[serde(default)]
    pub rejected_steps: usize,
    /// Implicit integrators with an error estimate (the Newmark family): the largest local
    /// error estimate of an accepted step (history.csv `error_estimate`); null otherwise.
    #[serde(default)]
    pub max_error_estimate: Option<f64>,
    pub contact: ContactSummary,
    pub energy: EnergySummary,
    pub buckling: Option<BucklingSummary>,
    /// Central difference: the shortest and the longest step the step rule set (steps
    /// clipped to a frame time or the end time not counted).
    pub dt_min: Option<f64>,
    pub dt_max: Option<f64>,
    /// Central difference: the stable step of the final configuration and the element that
    /// sets it.
    pub dt_limit: Option<DtLimit>,
    /// Seconds per phase and element updates (see `profile`); process-wide counters, so
    /// only meaningful for one run per process (as `impact run` and `impact bench` do).
    #[serde(default)]
    pub timing: crate::profile::Timing,
    /// The highest point temperature at the end (the run's highest: adiabatic heating never
    /// cools), when some material carries a temperature. summary.json writes it last and
    /// only then (`record::Recorder::write_summary`); a checkpoint does not store it (the
    /// end state gives it).
    #[serde(skip)]
    pub max_temperature: Option<f64>,
    /// What the scene and the finished run say about the answer (analysis::plausibility):
    /// the scene's own warnings (too few steps, a run shorter than a wave transit, an unused
    /// obstacle, an axis not held, too many frames), then step cuts, the energy balance,
    /// plastic work above the energy supplied, a step too long for the impact, a pair that
    /// never closed, a contact penetration beyond TOL, nodes across the axis, hourglass
    /// energy. Empty when none.
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl Summary {
    /// A summary before the run: status `ok`, counters zero.
    pub fn new(
        model: &Model,
        integrator: &str,
        dt: f64,
        end_time: f64,
        free_dofs: usize,
    ) -> Summary {
        Summary {
            scene: model.file.display().to_string(),
            title: model.title.clone(),
            status: Status::Ok,
            message: None,
            integrator: integrator.to_string(),
            dt,
            steps: 0,
            end_time,
            nodes: model.node_count,
            elements: model.elements(),
            dofs: model.dofs(),
            free_dofs,
            wall_seconds: 0.0,
            newton_iterations: 0,
            factorizations: 0,
            back_substitutions: 0,
            step_cuts: 0,
            rejected_steps: 0,
            max_error_estimate: None,
            contact: ContactSummary::default(),
            energy: EnergySummary::default(),
            buckling: None,
            dt_min: None,
            dt_max: None,
            dt_limit: None,
            timing: Default::default(),
            max_temperature: None,
            warnings: Vec::new(),
        }
    }
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

/// The local error of the steps (theory 8.2a): with c the method's error constant,
/// ```text
/// e   = c dt^2 (a_{n+1} - a_n)                       (Zienkiewicz & Xie 1991)
/// eta = max_i |e_i| / (dt V),   V = the run's top nodal speed so far
/// ```
/// the error of the step's displacement relative to the distance the fastest node covers in
/// it. Carried through checkpoints.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct ErrorWatch {
    pub speed: f64,
    /// The last accepted step's estimate, and the largest of the run.
    pub last: f64,
    pub largest: f64,
}

/// The step length of a driver: halved when a step fails (at most `max_cuts` times in a
/// row), grown back towards the nominal length after each success.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StepControl {
    nominal: f64,
    length: f64,
    cuts_in_a_row: usize,
    max_cuts: usize,
}

impl StepControl {
    fn new(nominal: f64, max_cuts: usize) -> StepControl {
        StepControl {
            nominal,
            length: nominal,
            cuts_in_a_row: 0,
            max_cuts,
        }
    }

    /// A step ending at its target succeeded (`grow`: it was not ended early by an event).
    fn accept(&mut self, grow: bool) {
        self.cuts_in_a_row = 0;
        if grow {
            self.length = (2.0 * self.length).min(self.nominal);
        }
    }

    /// An adaptive run's next step: `length` (the nominal too, so the floor of the cuts
    /// follows it).
    fn propose(&mut self, length: f64) {
        self.nominal = length;
        self.length = length;
    }

    /// A step whose error estimate was too large: take it again with `length`.
    fn retry(&mut self, length: f64) {
        self.length = length;
    }

    /// A step of length `attempted` failed: halve it, or say why the run must stop.
    ///
    /// Besides `max_cuts` cuts in a row, the length may not fall below the nominal step over
    /// 2^max_cuts and a tenth (the shortest event split of such a step): cuts and successes
    /// that alternate would otherwise shrink it without end (to 1e-17 and then 0, which
    /// Wilson-theta met on a crushed contact tip).
    fn reject(&mut self, attempted: f64, counters: &mut Counters) -> Result<(), String> {
        if self.cuts_in_a_row >= self.max_cuts {
            return Err(format!(
                "did not converge after {} cuts (dt = {})",
                self.cuts_in_a_row,
                readable(attempted)
            ));
        }
        let floor = self.shortest();
        if 0.5 * attempted < floor {
            return Err(format!(
                "did not converge: repeated cuts brought the step to {}, and halving it would go below dt / 2^{} / 10 = {}",
                readable(attempted),
                self.max_cuts,
                readable(floor)
            ));
        }
        self.length = 0.5 * attempted;
        self.cuts_in_a_row += 1;
        counters.cuts += 1;
        Ok(())
    }

    /// The shortest step the control takes: the nominal over 2^max_cuts and a tenth.
    fn shortest(&self) -> f64 {
        self.nominal * 0.5f64.powi(self.max_cuts as i32) * 0.1
    }

    fn after_cut(&self) -> bool {
        self.cuts_in_a_row > 0
    }
}

/// A step of nominal length up to round-off is given exactly the nominal length, so methods
/// that keep history (Houbolt) or a factorization of K*(dt) see one dt.
fn step_length(h: f64, dt: f64) -> f64 {
    if (h - dt).abs() <= 1e-9 * dt { dt } else { h }
}

/// The scene's initial velocity, with the constrained DOFs (`free` false) moving as their
/// prescriptions do at t = 0 (the slope of the first curve segment; supports at rest): a
/// prescribed motion then starts without a velocity jump the trapezoidal rule would carry as
/// an oscillation.
fn initial_velocity(model: &Model, free: &[bool], dt: f64) -> Vec<f64> {
    let mut v = model.initial_velocity.clone();
    let initial = model.coordinates();
    let eps = 1e-6 * dt;
    let at = |t: f64| {
        let mut u = vec![0.0; model.dofs()];
        for (dof, value) in loads::prescribed(model, &initial, t) {
            u[dof] = value;
        }
        u
    };
    let (u0, u1) = (at(0.0), at(eps));
    for (dof, free) in free.iter().enumerate() {
        if !free {
            v[dof] = (u1[dof] - u0[dof]) / eps;
        }
    }
    v
}

/// Work of the nodal forces over an increment by the trapezoid rule, 1/2 (f_0 + f_1) . d.
fn trapezoid_work(d: &[f64], f1: &[f64], f0: &[f64]) -> f64 {
    0.5 * d
        .iter()
        .zip(f1.iter().zip(f0))
        .map(|(u, (a, b))| u * (a + b))
        .sum::<f64>()
}

/// Relative energy balance error |KE + W_int - W_ext - KE_0| / max(KE_0, |W_ext|, W_int).
fn balance_error(energies: &Energies, initial_kinetic: f64) -> f64 {
    let scale = initial_kinetic
        .max(energies.external_work.abs())
        .max(energies.internal.abs())
        .max(f64::MIN_POSITIVE);
    (energies.kinetic + energies.internal + energies.plastic_work + energies.contact_work
        - energies.external_work
        - initial_kinetic)
        .abs()
        / scale
}

/// Why a run failed; `exit_code` maps it to the CLI's contract.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Input(#[from] InputError),
    /// Divergence, an inverted element, NaN: the partial output and summary.json are kept.
    #[error("numerical failure: {message}")]
    Numerical {
        message: String,
        summary: Box<Summary>,
    },
    #[error("{0}")]
    Output(#[from] OutputError),
    /// SIGINT or SIGTERM: the step in progress was finished and written, with a frame, a
    /// checkpoint and summary.json (status `interrupted`).
    #[error("interrupted: {message}")]
    Interrupted {
        message: String,
        summary: Box<Summary>,
    },
    /// `--strict`: the run finished (status ok, its output complete) with warnings.
    #[error("{count} warning(s) with --strict (summary.json `warnings`)")]
    Warnings { count: usize, summary: Box<Summary> },
}

impl RunError {
    pub fn exit_code(&self) -> i32 {
        match self {
            RunError::Input(_) => 2,
            RunError::Numerical { .. } => 3,
            RunError::Output(_) => 1,
            RunError::Interrupted { .. } => 130,
            RunError::Warnings { .. } => 3,
        }
    }
}

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

/// Continues the run checkpointed in `dir` (DIR/checkpoint.bin), writing into `dir`.
pub fn resume(dir: &Path, options: RunOptions) -> Result<Summary, RunError> {
    let checkpoint = checkpoint::read(dir)?;
    let scene_path = Path::new(&checkpoint.scene_path).to_path_buf();
    let model = crate::scene::from_str(
        &checkpoint.source.text,
        &scene_path,
        &checkpoint.source.overrides,
    )?;
    run_from(&model, dir, options, Some(checkpoint)).map(|o| o.summary)
}

/// Runs the scene's analysis, writing into `out_dir`.
pub fn run(model: &Model, out_dir: &Path, options: RunOptions) -> Result<Summary, RunError> {
    run_to_state(model, out_dir, options).map(|(summary, _)| summary)
}

/// As [`run`], also returning the final committed state (for tests and studies).
pub fn run_to_state(
    model: &Model,
    out_dir: &Path,
    options: RunOptions,
) -> Result<(Summary, State), RunError> {
    run_outcome(model, out_dir, options).map(|o| (o.summary, o.state))
}

/// What a run leaves besides its files: the summary, the final committed state and the
/// final nodal contact forces (all DOFs; zero without contact).
pub struct Outcome {
    pub summary: Summary,
    pub state: State,
    pub contact_force: Vec<f64>,
}

/// As [`run`], returning the whole [`Outcome`].
pub fn run_outcome(
    model: &Model,
    out_dir: &Path,
    options: RunOptions,
) -> Result<Outcome, RunError> {
    run_from(model, out_dir, options, None)
}

/// Creates the output folder `dir` (and its parents); a folder that cannot be made (a file
/// in the way, no permission) is bad input: the user names another with `--out`.
pub fn create_output_folder(dir: &Path) -> Result<(), InputError> {
    std::fs::create_dir_all(dir).map_err(|e| {
        InputError::new(
            dir,
            format!("cannot create the output folder (choose another with --out): {e}"),
        )
    })
}

/// A run from the start, or from a checkpoint of the same scene.
fn run_from(
    model: &Model,
    out_dir: &Path,
    options: RunOptions,
    resume: Option<checkpoint::Checkpoint>,
) -> Result<Outcome, RunError> {
    crate::profile::reset();
    create_output_folder(out_dir)?;
    let imperfect = buckling::with_imperfection(model).map_err(|e| {
        InputError::new(
            &model.file,
            format!("analysis.buckling.imperfection: the mode cannot be computed: {e}"),
        )
    })?;
    let model = imperfect.as_ref().unwrap_or(model);
    // a small model pays more for handing work to threads than the threads give back: it
    // runs on the calling thread (the results are the same bits either way)
    if model.elements() < PARALLEL_FROM_ELEMENTS && rayon::current_num_threads() > 1 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| setup_error(out_dir, e))?;
        return pool.install(|| dispatch(model, out_dir, options, resume));
    }
    dispatch(model, out_dir, options, resume)
}

/// Below this many elements a run uses one thread (measured with `impact bench`: a
/// 150-element explicit scene took 2.2 times as long on two threads as on one).
pub const PARALLEL_FROM_ELEMENTS: usize = 4000;

/// Runs the scene's analysis with the stepper it names.
fn dispatch(
    model: &Model,
    out_dir: &Path,
    options: RunOptions,
    resume: Option<checkpoint::Checkpoint>,
) -> Result<Outcome, RunError> {
    let start = std::time::Instant::now();
    match &model.analysis {
        crate::scene::model::Analysis::Static(spec) => {
            let stepper =
                statics::Statics::new(model, spec).map_err(|e| setup_error(out_dir, e))?;
            run::execute(model, out_dir, options, resume, (stepper, start))
        }
        crate::scene::model::Analysis::Dynamic(spec) => {
            if spec.integrator == crate::scene::spec::IntegratorKind::CentralDifference {
                let stepper = explicit::Explicit::new(model, spec)?;
                run::execute(model, out_dir, options, resume, (stepper, start))
            } else {
                let stepper = dynamics::Dynamics::new(model, spec, out_dir)?;
                run::execute(model, out_dir, options, resume, (stepper, start))
            }
        }
    }
}

/// The linear solver could not be set up for the model's pattern.
fn setup_error(dir: &Path, e: impl std::fmt::Display) -> RunError {
    RunError::Output(OutputError::Invalid {
        path: dir.to_path_buf(),
        reason: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: cuts that alternate with successes cannot shrink the step without end (the
    /// cuts-in-a-row limit never trips then). Reference: the floor dt / 2^max_cuts / 10.
    #[test]
    fn alternating_cuts_stop_at_the_floor() {
        let mut control = StepControl::new(1e-3, 6);
        let mut counters = Counters::default();
        let floor = 1e-3 / 64.0 / 10.0;
        let mut error = None;
        // two cuts, one success (which doubles back once): the length halves per round
        for _ in 0..100 {
            let mut round = || -> Result<(), String> {
                control.reject(control.length, &mut counters)?;
                control.reject(control.length, &mut counters)?;
                control.accept(true);
                Ok(())
            };
            if let Err(e) = round() {
                error = Some(e);
                break;
            }
            assert!(control.length >= floor, "length {}", control.length);
        }
        let error = error.expect("the floor stops the run");
        assert!(error.contains("below dt / 2^6 / 10"), "{error}");
    }
}
