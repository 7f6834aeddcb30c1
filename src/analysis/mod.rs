//! The analyses, in three rooms: the [`steppers`] that advance a model's state (static load
//! stepping, implicit and explicit time stepping), the [`run`] scaffold that drives a stepper
//! and writes what it does (frames, history.csv, checkpoints, progress, the buckling check),
//! and the [`summary`] both speak (summary.json, the status, the errors). Beside them the
//! set-up checks of `impact check` ([`check`], [`plausibility`]). This file is the entry: a
//! run from the start or from a checkpoint, dispatched to the stepper the scene names.

pub mod check;
pub mod plausibility;
pub mod run;
pub mod steppers;
pub mod summary;
pub mod units;

use crate::assembly::State;
use crate::scene::{InputError, Model};
use run::checkpoint;
use std::path::Path;
use steppers::{arc_length, dynamics, explicit, statics};

pub use run::{Outcome, RunOptions, progress};
pub use summary::{RunError, Status, StepError, Summary};

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
    let imperfect = run::buckling::with_imperfection(model).map_err(|e| {
        InputError::new(
            &model.file,
            format!("analysis.buckling.imperfection: the mode cannot be computed: {e}"),
        )
    })?;
    let model = imperfect.as_ref().unwrap_or(model);
    // a small model pays more for handing work to threads than the threads give back: it
    // runs on the calling thread, and an explicit one of a few thousand elements on as many
    // threads as its points keep busy (the results are the same bits either way)
    let threads = run_threads(model);
    if threads < rayon::current_num_threads() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| RunError::setup(out_dir, e))?;
        return pool.install(|| dispatch(model, out_dir, options, resume));
    }
    // on a worker of the pool: a parallel loop started from outside it hands its work over
    // and puts the calling thread to sleep until it is done, at every loop (two context
    // switches each; 15 % of a 4000-element rod's run on one thread went to the scheduler)
    rayon::scope(|_| dispatch(model, out_dir, options, resume))
}

/// Below this many elements an implicit or static run uses one thread (measured with `impact
/// bench`: a 150-element explicit scene took 2.2 times as long on two threads as on one; the
/// implicit timings of docs/performance.md were taken under this rule).
pub const PARALLEL_FROM_ELEMENTS: usize = 4000;

/// The same for central difference, whose step hands its element loop over once and keeps
/// short vector loops on its own thread (docs/performance.md, "Fewer hand-overs per step": a
/// 1000-element rod 1.3-1.5 times faster on two threads than on one).
pub const PARALLEL_FROM_ELEMENTS_EXPLICIT: usize = 1000;

/// Material points per thread from which central difference keeps a thread busy: on a
/// 16-core machine (docs/performance.md, "Fewer hand-overs per step") the one-point
/// aluminium rod of 2400 elements ran fastest on 8 threads (9.65 s against 10.9 s on 16),
/// while its 2x2 form (9600 points) and the 4000-element Johnson-Cook rod gained up to 16.
pub const POINTS_PER_THREAD_EXPLICIT: usize = 300;

/// The threads a run of `model` started here steps on ([`threads_for`] of this pool), as
/// summary.json's `timing.threads` then reports them and `impact check` tells beforehand.
pub fn run_threads(model: &Model) -> usize {
    threads_for(model, rayon::current_num_threads(), user_set_threads())
}

/// Whether the user chose the thread count (`RAYON_NUM_THREADS`).
fn user_set_threads() -> bool {
    std::env::var_os("RAYON_NUM_THREADS").is_some_and(|v| !v.is_empty())
}

/// The threads a run of `model` uses out of the pool's `available`: one below
/// [`parallel_from`]'s element count; an explicit run the user has not given a thread count
/// (`user_set`) at most one per [`POINTS_PER_THREAD_EXPLICIT`] material points (Quad4 2x2
/// counts 4 points an element, one-point and rods 1), and at least 2; otherwise all.
pub fn threads_for(model: &Model, available: usize, user_set: bool) -> usize {
    if model.elements() < parallel_from(model) {
        return 1;
    }
    if !model.is_explicit() || user_set {
        return available;
    }
    let one_point = model.analysis.one_point();
    let points: usize = (model.bodies.iter())
        .map(|b| b.elements() * if one_point { 1 } else { b.points_per_element() })
        .sum();
    (points / POINTS_PER_THREAD_EXPLICIT).max(2).min(available)
}

/// The element count from which `model` runs on the pool.
pub fn parallel_from(model: &Model) -> usize {
    if model.is_explicit() {
        PARALLEL_FROM_ELEMENTS_EXPLICIT
    } else {
        PARALLEL_FROM_ELEMENTS
    }
}

/// Runs the scene's analysis with the stepper it names.
fn dispatch(
    model: &Model,
    out_dir: &Path,
    options: RunOptions,
    resume: Option<checkpoint::Checkpoint>,
) -> Result<Outcome, RunError> {
    let start = std::time::Instant::now();
    match &model.analysis {
        crate::scene::model::Analysis::Static(spec) => match spec.arc_length {
            Some(settings) => {
                let stepper = arc_length::ArcLength::new(model, spec, settings)
                    .map_err(|e| RunError::setup(out_dir, e))?;
                run::execute(model, out_dir, options, resume, (stepper, start))
            }
            None => {
                let stepper =
                    statics::Statics::new(model, spec).map_err(|e| RunError::setup(out_dir, e))?;
                run::execute(model, out_dir, options, resume, (stepper, start))
            }
        },
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
