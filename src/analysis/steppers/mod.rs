//! The steppers: what advances a model's state by one converged step. Static load stepping
//! (`statics`), implicit time stepping (`dynamics`, with Newton in `newton`) and explicit
//! central difference (`explicit`, its step rule in `clock`, the stable step in `stable`);
//! the loads and prescribed motions they apply (`loads`); the step control of the implicit
//! steppers (`control`). The run scaffold (`analysis::run`) drives a [`Stepper`], reads
//! its [`Report`] and checkpoints it through [`Resume`]; no stepper knows the scaffold.

pub mod arc_length;
pub mod carry;
pub mod clock;
pub mod control;
pub mod dynamics;
pub mod energies;
pub mod explicit;
pub mod loads;
pub mod newton;
pub mod stable;
pub mod statics;

use crate::assembly::{StableStep, State};
use crate::contact::ContactState;
use crate::scene::Model;
use crate::scene::model::Probe;
use crate::solver::Solver;
use carry::Carry;
use control::ErrorWatch;
use energies::{Energies, Motion};
use newton::Counters;

pub use crate::analysis::summary::StepError;

/// One kind of analysis as the run drives it: it advances the state by converged steps.
/// What it says of itself is its [`Report`]; what a checkpoint keeps of it, its [`Resume`].
pub trait Stepper: Report + Resume {
    /// What the stepper computes at t = 0 before the first row (a numerical failure here
    /// ends the run `diverged` with the message).
    fn start(&mut self) -> Result<(), String>;
    fn done(&self) -> bool;
    /// One converged step, cutting and retrying inside as the analysis allows.
    fn advance(&mut self, counters: &mut Counters) -> Result<(), StepError>;
    /// A judgement of the step just counted (explicit: the energy has not blown up).
    fn verdict(&self) -> Result<(), StepError> {
        Ok(())
    }
    /// Makes the state's material points current before output reads them (the one-point
    /// kernel keeps its own arrays).
    fn sync_points(&mut self) {}
}

/// What a stepper says of its run and its state: summary.json, history.csv and the frames
/// read it. What is fixed for the run is one struct ([`About`]), and so are what the
/// optional features add to a history row ([`RowFeatures`]) and to summary.json at the end
/// ([`RunFeatures`]): a new feature is a field there, filled by the steppers that have it.
pub trait Report {
    /// The integrator's name, the nominal step, the end time, the free DOFs and whether the
    /// run carries the buckling check.
    fn about(&self) -> About;
    fn state(&self) -> &State;
    fn motion(&self) -> Motion<'_>;
    fn energies(&self) -> &Energies;
    /// Each body's kinetic energy, 1/2 v . M v over its nodes (model order): by default with
    /// the lumped mass of `motion` (none in statics: zeros).
    fn body_kinetic(&self, model: &Model) -> Vec<f64> {
        let Motion { velocity, mass, .. } = self.motion();
        crate::assembly::body_sums(model, |dof| {
            0.5 * mass.get(dof).copied().unwrap_or(0.0) * velocity[dof] * velocity[dof]
        })
    }
    /// The kinetic energy at t = 0: summary.json `energy.initial` and the drift's reference.
    fn initial_kinetic(&self) -> f64;
    fn contact(&self) -> &ContactState;
    /// The linear solver, for its counters (None: explicit, no solver).
    fn solver(&self) -> Option<&Solver> {
        None
    }
    /// The statistic of the point probe `probe` from the stepper's own point values, where
    /// they are newer than the state's points (an explicit kernel between copies): spares the
    /// copy of every point for a history row. None: read the state's points.
    fn point_probe(&self, _probe: &Probe) -> Option<f64> {
        None
    }
    /// The length of the last step (0 before the first).
    fn last_step(&self) -> f64;
    /// The share by which the run raises its tangents' diagonal (`System::held`): 0 but
    /// where a static body is held by its contact alone (theory 5c).
    fn held(&self) -> f64 {
        0.0
    }
    /// What the optional features add to a history row (none by default).
    fn row_features(&self) -> RowFeatures {
        RowFeatures::default()
    }
    /// What the optional features add to summary.json at the end (none by default).
    fn run_features(&self) -> RunFeatures {
        RunFeatures::default()
    }
}

/// What a stepper is, fixed for its run: the head of summary.json.
#[derive(Debug, Clone)]
pub struct About {
    /// The integrator's name in summary.json.
    pub integrator: String,
    /// The nominal step and the end time.
    pub dt: f64,
    pub end_time: f64,
    pub free_dofs: usize,
    /// Whether the run carries the buckling check of `[analysis.buckling]`.
    pub checks_buckling: bool,
}

/// The optional features' values of a history row; None: the feature is off (its column
/// keeps its default).
#[derive(Debug, Clone, Default)]
pub struct RowFeatures {
    /// The accumulated hourglass work of the one-point kernel.
    pub hourglass_energy: Option<f64>,
    /// The local error estimates of the implicit steps (`dt = "auto"`).
    pub error_watch: Option<ErrorWatch>,
    /// The mass the mass scaling has added so far.
    pub added_mass: Option<f64>,
    /// The share of the scene's loads at end_time that the state carries, where it is not
    /// the pseudo time's (arc length: the history's `load_factor`).
    pub load_factor: Option<f64>,
}

/// The optional features' blocks of summary.json at the end of a run; None: off.
#[derive(Debug, Clone, Default)]
pub struct RunFeatures {
    /// What the time step did (central difference): `dt_min`, `dt_max`, `dt_limit`.
    pub time_step: Option<TimeStepReport>,
    /// The mass scaling per body: `mass_scaling` and its warnings.
    pub mass_scaling: Option<crate::assembly::mass_scaling::MassScalingReport>,
    /// The ALE steps' counts: `ale`.
    pub ale: Option<crate::analysis::summary::AleSummary>,
    /// The arc-length path: `arc_length`.
    pub arc_length: Option<crate::analysis::summary::ArcLengthSummary>,
    /// The subcycling's counts: `subcycling`.
    pub subcycling: Option<crate::analysis::summary::SubcyclingSummary>,
}

/// What a checkpoint keeps of a stepper, and how a resumed stepper takes it back.
pub trait Resume {
    /// What a checkpoint stores of the stepper; an error when it writes none, the reason.
    fn carry(&self) -> Result<Carry, &'static str>;
    /// Takes over the carry of a checkpoint; false when it is another analysis' carry.
    fn restore(&mut self, carry: Carry) -> bool;
    /// The analysis' name in the message of a wrong carry.
    fn kind(&self) -> &'static str;
    /// Called after a checkpoint is written (the step after it factors afresh, as the
    /// resumed run must).
    fn after_checkpoint(&mut self) {}
    /// The linear solver, whose counters a checkpoint carries (None: no solver).
    fn solver_mut(&mut self) -> Option<&mut Solver> {
        None
    }
}

/// The steps a central-difference run took and what limits them at the end.
#[derive(Debug, Clone)]
pub struct TimeStepReport {
    /// The shortest and the longest step the step rule set (`Clock::range`: steps clipped to
    /// a frame time or the end time are not counted).
    pub shortest: f64,
    pub longest: f64,
    /// The stable step of the last configuration.
    pub limit: StableStep,
    /// The step the rule started with (the fixed dt, or the automatic step of the initial
    /// mesh): what the set-up warnings count the run's steps by.
    pub first: f64,
}

/// The scene's initial velocity, with the constrained DOFs (`free` false) moving as their
/// prescriptions do at t = 0 (the slope of the first curve segment; supports at rest): a
/// prescribed motion then starts without a velocity jump the trapezoidal rule would carry as
/// an oscillation.
pub(super) fn initial_velocity(model: &Model, free: &[bool], dt: f64) -> Vec<f64> {
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
pub(super) fn trapezoid_work(d: &[f64], f1: &[f64], f0: &[f64]) -> f64 {
    0.5 * d
        .iter()
        .zip(f1.iter().zip(f0))
        .map(|(u, (a, b))| u * (a + b))
        .sum::<f64>()
}
