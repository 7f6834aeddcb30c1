//! What each stepper carries from step to step, and so what a checkpoint stores of it
//! (run/checkpoint.rs writes it whole; a resumed stepper takes it back).

use super::clock::Clock;
use super::control::{ErrorWatch, StepControl};
use super::energies::Energies;
use crate::assembly::State;
use crate::assembly::mass_scaling::ScalingCarry;
use crate::contact::ContactState;
use crate::integrator::{MethodHistory, MotionState};
use serde::{Deserialize, Serialize};

/// What each driver's loop carries from step to step.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum Carry {
    Static(StaticCarry),
    ArcLength(ArcLengthCarry),
    Dynamic(DynamicCarry),
    Explicit(ExplicitCarry),
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StaticCarry {
    pub state: State,
    pub energies: Energies,
    pub last_force: Vec<f64>,
    pub control: StepControl,
    pub increments: usize,
    pub contact: ContactState,
    /// The last increment's displacement increment and length (the next one's start).
    pub previous: Option<(Vec<f64>, f64)>,
    /// `System::held`: the diagonal shift of a body held by its contact alone.
    #[serde(default)]
    pub held: f64,
}

/// Where an arc-length path has got to (theory 5b): the state, the load factor and the
/// highest so far, the next arc, the first arc and share (the pseudo time's unit), the last
/// increment's direction (which way the next one goes), the counts of flat increments.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ArcLengthCarry {
    pub state: State,
    pub energies: Energies,
    pub last_force: Vec<f64>,
    pub contact: ContactState,
    pub factor: f64,
    pub peak: f64,
    pub arc: Option<f64>,
    pub first_arc: f64,
    pub first_share: f64,
    pub direction: Vec<f64>,
    pub increments: usize,
    pub last_step: f64,
    pub flat_in_a_row: usize,
    pub collapsed: bool,
    /// `System::held`: the diagonal shift of a body held by its contact alone.
    #[serde(default)]
    pub held: f64,
    /// The load factors of the last increments (`ArcLengthSummary::recent_change`).
    #[serde(default)]
    pub recent: Vec<f64>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DynamicCarry {
    pub state: State,
    pub kinematics: MotionState,
    pub method: MethodHistory,
    pub energies: Energies,
    pub initial_kinetic: f64,
    pub last_total: Vec<f64>,
    pub last_internal: Vec<f64>,
    pub last_contact: Vec<f64>,
    pub control: StepControl,
    pub increments: usize,
    pub contact: ContactState,
    /// The last step's mean velocity, the next step's predictor (None before the first).
    pub mean_velocity: Option<Vec<f64>>,
    /// The local error estimates so far (the top speed, the last and largest estimate).
    pub watch: ErrorWatch,
    /// The acceleration at the start of the last step and that step's length: the error
    /// estimate reads the change of a over two steps.
    pub previous_acceleration: Option<Vec<f64>>,
    pub last_step: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ExplicitCarry {
    pub state: State,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    pub energies: Energies,
    pub initial_kinetic: f64,
    pub last_total: Vec<f64>,
    pub energy_reference: f64,
    /// The last step taken (the loop goes on with step + 1).
    pub step: usize,
    pub contact: ContactState,
    pub clock: Clock,
    /// The bulk viscosity's pressure of the last step at the kernel's points (empty without
    /// it).
    pub viscous_pressure: Vec<f64>,
    /// The mass scaling's factors, added mass and the nodal masses (None without it).
    pub mass_scaling: Option<ScalingCarry>,
    /// The subcycling's element bounds and counts (None without it).
    pub subcycling: Option<SubcyclingCarry>,
    /// The tight stable step's ratios and the bounds they were taken at (None: the kernel's
    /// bounds stand).
    pub tightness: Option<crate::assembly::explicit::tight::Tightness>,
    /// The ALE steps' element masses (remapped) and counts (None without ALE).
    pub ale: Option<AleCarry>,
    /// The one-point kernel's hourglass forces (2 per element) and their work so far: the
    /// element state `State` does not hold (None: the 2x2 kernel, which has none).
    pub hourglass: Option<(Vec<f64>, f64)>,
}

/// What a run with ALE steps carries: the element masses as the remaps left them (the nodal
/// masses and the kernel are formed from them) and the counts of summary.json `ale`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AleCarry {
    pub masses: crate::assembly::ElementMasses,
    pub summary: crate::analysis::summary::AleSummary,
}

/// What a subcycled run carries past a major step: the frequency bound squared of every
/// element's last step (the next levels are formed from them), the step ratios the current
/// levels' interfaces were graded with (they were formed at an earlier step), the last
/// substep's length, the substeps and element updates so far.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SubcyclingCarry {
    pub omega_squared: Vec<f64>,
    pub ratios: Vec<f64>,
    pub last_substep: f64,
    pub substeps: u64,
    pub element_updates: u64,
    pub largest_step_ratio: f64,
}
