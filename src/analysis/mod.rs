//! The drivers: static load stepping (dynamic time stepping plugs in beside it), with the
//! run's bookkeeping and its output (VTK frames, history.csv, summary.json).

pub mod loads;
pub mod record;
pub mod statics;

use crate::assembly::State;
use crate::output::OutputError;
use crate::scene::{InputError, Model};
use serde::Serialize;
use std::path::Path;

/// How a run ended (summary.json `status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Ok,
    Diverged,
    Unstable,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct ContactSummary {
    pub first_contact_time: Option<f64>,
    pub last_release_time: Option<f64>,
    pub peak_force: f64,
    pub peak_contact_radius: f64,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct EnergySummary {
    pub initial: f64,
    #[serde(rename = "final")]
    pub final_: f64,
    /// max over the steps of |W_int + KE - KE_0 - W_ext| / max(|W_ext|, KE_0, W_int).
    pub max_relative_drift: f64,
    pub plastic_dissipation: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct BucklingSummary {
    pub critical_load_factor: f64,
}

/// summary.json (DESIGN section 5): other tools read it; fields are only ever added.
#[derive(Debug, Clone, Serialize)]
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
    pub contact: ContactSummary,
    pub energy: EnergySummary,
    pub buckling: Option<BucklingSummary>,
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
}

impl RunError {
    pub fn exit_code(&self) -> i32 {
        match self {
            RunError::Input(_) => 2,
            RunError::Numerical { .. } => 3,
            RunError::Output(_) => 1,
        }
    }
}

/// Options of a run that are not part of the scene.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// Show a progress bar (on a terminal).
    pub progress: bool,
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
    match &model.analysis {
        crate::scene::model::Analysis::Static(spec) => statics::run(model, spec, out_dir, options),
    }
}
