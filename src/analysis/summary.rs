//! How a run ended and what it says of itself: summary.json (the output contract of
//! docs/user-guide.md, read by other tools: fields are only ever added), the status, the
//! error of a step that could not be taken and the error of a run. The ground floor of the
//! analyses: the steppers and the run scaffold both speak it.

use crate::assembly::StableStep;
use crate::assembly::mass_scaling::MassScalingReport;
use crate::output::OutputError;
use crate::scene::{InputError, Model};
use serde::{Deserialize, Serialize};

pub use crate::contact::ContactSummary;

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

impl Status {
    /// The status as summary.json writes it.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Diverged => "diverged",
            Status::Unstable => "unstable",
            Status::Interrupted => "interrupted",
        }
    }
}

#[derive(Debug, Clone, Default, Deserialize)]
pub struct EnergySummary {
    pub initial: f64,
    #[serde(rename = "final")]
    pub final_: f64,
    /// max over the steps of |KE + W_elastic + W_plastic + W_contact + W_visc - KE_0 - W_ext|
    /// / max(KE_0, |W_ext|, |W_elastic|).
    pub max_relative_drift: f64,
    /// max over the steps of the balance's signed residual over the same scale, and 0: the
    /// largest share of the energy in play the run created (the drift's gains alone).
    #[serde(default)]
    pub max_relative_gain: f64,
    pub plastic_dissipation: f64,
    /// The work of the bulk viscosity's pressure over the run (history.csv
    /// `bulk_viscosity_work`); only with `analysis.bulk_viscosity`, and summary.json has the
    /// field only then.
    #[serde(default)]
    pub bulk_viscosity_work: Option<f64>,
    /// The kinetic energy lost as the mass scaling's added mass joined the moving nodes
    /// (history.csv `mass_scaling_loss`); only with `analysis.mass_scaling`, and summary.json
    /// has the field only then.
    #[serde(default)]
    pub mass_scaling_loss: Option<f64>,
    /// The kinetic energy the ALE remaps took out of the motion (history.csv
    /// `remap_loss`); only with `analysis.ale`, and summary.json has the field only then.
    #[serde(default)]
    pub remap_loss: Option<f64>,
    /// The energy Coulomb friction dissipated (history.csv `friction_work`); only under
    /// central difference with a friction pair, and summary.json has the field only then.
    #[serde(default)]
    pub friction_work: Option<f64>,
}

/// summary.json (a human-readable format) leaves `bulk_viscosity_work`, `mass_scaling_loss`,
/// `remap_loss` and `friction_work` out when there are none, so the scenes without them keep their file
/// as it was; a checkpoint (a binary format whose fields are positional) always stores them.
impl Serialize for EnergySummary {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let binary = !serializer.is_human_readable();
        let viscosity = self.bulk_viscosity_work.is_some() || binary;
        let scaling = self.mass_scaling_loss.is_some() || binary;
        let remap = self.remap_loss.is_some() || binary;
        let friction = self.friction_work.is_some() || binary;
        let fields = 5
            + usize::from(viscosity)
            + usize::from(scaling)
            + usize::from(remap)
            + usize::from(friction);
        let mut s = serializer.serialize_struct("EnergySummary", fields)?;
        s.serialize_field("initial", &self.initial)?;
        s.serialize_field("final", &self.final_)?;
        s.serialize_field("max_relative_drift", &self.max_relative_drift)?;
        s.serialize_field("max_relative_gain", &self.max_relative_gain)?;
        s.serialize_field("plastic_dissipation", &self.plastic_dissipation)?;
        if viscosity {
            s.serialize_field("bulk_viscosity_work", &self.bulk_viscosity_work)?;
        } else {
            s.skip_field("bulk_viscosity_work")?;
        }
        if scaling {
            s.serialize_field("mass_scaling_loss", &self.mass_scaling_loss)?;
        } else {
            s.skip_field("mass_scaling_loss")?;
        }
        if remap {
            s.serialize_field("remap_loss", &self.remap_loss)?;
        } else {
            s.skip_field("remap_loss")?;
        }
        if friction {
            s.serialize_field("friction_work", &self.friction_work)?;
        } else {
            s.skip_field("friction_work")?;
        }
        s.end()
    }
}

/// summary.json `mass_scaling` (only with `analysis.mass_scaling`): the target, the mass
/// added over the run and its share of the model's mass, the elements scaled, and per body
/// the same (docs/theory.md 8.7b).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MassScalingSummary {
    pub target: f64,
    pub added_mass: f64,
    /// 100 added_mass / the model's unscaled mass.
    pub added_mass_percent: f64,
    pub elements_scaled: usize,
    /// The largest of the bodies' `added_mass_percent`, and its body.
    pub max_body_added_mass_percent: f64,
    pub max_body: String,
    pub bodies: Vec<BodyMassScaling>,
}

/// summary.json `ale` (only with `analysis.ale`; docs/theory.md 8.11): the remaps, the nodes
/// they moved, the largest share of an element's volume one remap swept out of it, and the
/// mass the sliding boundary nodes' chords took from the bodies' volume (the mass stays; its
/// density rises) as a share of the volume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AleSummary {
    pub remaps: u64,
    pub node_moves: u64,
    pub largest_courant: f64,
    pub boundary_volume_change: f64,
}

/// summary.json `arc_length` (only with `analysis.arc_length`; docs/theory.md 5b): the
/// increments taken, the highest load factor on the path and the last, and whether the path
/// reached the scene's load (factor 1) or stopped where its tangent turned singular (a
/// collapse: a perfectly plastic mechanism, or a limit point met exactly).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArcLengthSummary {
    pub increments: usize,
    pub peak_load_factor: f64,
    pub final_load_factor: f64,
    pub reached_load: bool,
    pub collapsed: bool,
    /// How far the load factor moved over the path's last `RECENT` increments (fewer on a
    /// shorter path), (largest - smallest) / |last|: small on a plateau at a limit load that
    /// the collapse test does not see (it asks the load to stand still).
    #[serde(default)]
    pub recent_change: f64,
}

/// The increments `ArcLengthSummary::recent_change` looks back over.
pub const RECENT: usize = 10;

/// summary.json `subcycling` (only with `analysis.subcycling`; docs/theory.md 8.7c): the
/// substeps of the finest level, the element steps taken and what stepping every element at
/// every substep would have taken, the levels of the last major step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubcyclingSummary {
    pub substeps: u64,
    pub element_updates: u64,
    /// elements x substeps.
    pub single_step_updates: u64,
    /// The largest level of the last major step (its step 2^levels substeps).
    pub levels: u32,
    /// Elements per level in the last major step, finest first.
    pub elements_per_level: Vec<usize>,
    /// The largest ratio of an element's step to its own stable step on the configuration
    /// the step ended in, over the run: the automatic step's scale (0.9) while the levels
    /// keep up with the mesh, above 1 where an element outgrew its level within a major step.
    pub largest_step_ratio: f64,
}

/// One body in summary.json `mass_scaling.bodies`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyMassScaling {
    pub body: String,
    /// The body's unscaled mass and the mass added to it.
    pub mass: f64,
    pub added_mass: f64,
    /// 100 added_mass / mass.
    pub added_mass_percent: f64,
    pub elements_scaled: usize,
}

impl MassScalingSummary {
    pub fn of(report: &MassScalingReport, model: &Model) -> MassScalingSummary {
        let percent = |added: f64, mass: f64| {
            if mass > 0.0 {
                100.0 * added / mass
            } else {
                0.0
            }
        };
        let bodies: Vec<BodyMassScaling> = report
            .bodies
            .iter()
            .zip(&model.bodies)
            .map(|(b, body)| BodyMassScaling {
                body: body.name.clone(),
                mass: b.mass,
                added_mass: b.added_mass,
                added_mass_percent: percent(b.added_mass, b.mass),
                elements_scaled: b.elements_scaled,
            })
            .collect();
        // the first of the largest
        let max = bodies
            .iter()
            .fold(None::<&BodyMassScaling>, |best, b| match best {
                Some(best) if best.added_mass_percent >= b.added_mass_percent => Some(best),
                _ => Some(b),
            });
        MassScalingSummary {
            target: report.target,
            added_mass: report.added_mass,
            added_mass_percent: percent(report.added_mass, report.model_mass()),
            elements_scaled: report.scaled.len(),
            max_body_added_mass_percent: max.map_or(0.0, |b| b.added_mass_percent),
            max_body: max.map_or_else(String::new, |b| b.body.clone()),
            bodies,
        }
    }
}

/// One body in summary.json `bodies`: its mass, and its energies at the end (its shares
/// of `energy`'s totals, as history.csv's per-body columns give them over time).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyMass {
    pub name: String,
    pub mass: f64,
    /// 1/2 v . M v over the body's nodes.
    #[serde(default)]
    pub kinetic_energy: f64,
    /// The work its elements' stresses did less the plastic work: the energy they store.
    #[serde(default)]
    pub internal_energy: f64,
    #[serde(default)]
    pub plastic_work: f64,
}

/// The bodies of `model` with their masses (empty where the mass cannot be formed: an
/// inverted element, which the run then reports).
pub fn body_masses(model: &Model) -> Vec<BodyMass> {
    let Ok(mass) = crate::assembly::Mass::new(model, crate::scene::spec::MassKind::Lumped) else {
        return Vec::new();
    };
    model
        .bodies
        .iter()
        .zip(mass.of_bodies(model))
        .map(|(body, mass)| BodyMass {
            name: body.name.clone(),
            mass,
            kinetic_energy: 0.0,
            internal_energy: 0.0,
            plastic_work: 0.0,
        })
        .collect()
}

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
    /// The implicit and static paths: the median of the Newton iterations a converged step
    /// (increment) took, its cut attempts' and contact passes' included; null in explicit
    /// runs.
    #[serde(default)]
    pub newton_iterations_median: Option<f64>,
    /// The most Newton iterations a converged step took (as the median counts them).
    #[serde(default)]
    pub newton_iterations_max: Option<usize>,
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
    /// Central difference: the shortest and the longest step the step rule set (a fixed
    /// step's last one, clipped to the end time, not counted; the automatic step's equal
    /// steps to a frame or the end are the rule's).
    pub dt_min: Option<f64>,
    pub dt_max: Option<f64>,
    /// Central difference: the stable step of the final configuration and the element that
    /// sets it.
    pub dt_limit: Option<DtLimit>,
    /// Each body's mass (the sum of its lumped nodal masses, unscaled; per unit depth in
    /// plane strain, the full ring's in axisymmetry), in scene order.
    #[serde(default)]
    pub bodies: Vec<BodyMass>,
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
    /// The mass scaling at the end (with `analysis.mass_scaling`): summary.json writes it
    /// after `max_temperature` and only then; a checkpoint does not store it (the end state
    /// gives it).
    #[serde(skip)]
    pub mass_scaling: Option<MassScalingSummary>,
    /// The subcycling (with `analysis.subcycling`): summary.json writes it after
    /// `mass_scaling` and only then.
    #[serde(skip)]
    pub subcycling: Option<SubcyclingSummary>,
    /// The ALE steps (with `analysis.ale`): summary.json writes it after `subcycling` and
    /// only then.
    #[serde(skip)]
    pub ale: Option<AleSummary>,
    /// The arc-length path (with `analysis.arc_length`): summary.json writes it after `ale`
    /// and only then.
    #[serde(skip)]
    pub arc_length: Option<ArcLengthSummary>,
    /// What the scene and the finished run say about the answer (analysis::plausibility):
    /// the scene's own warnings (too few or too many steps, a run shorter than a wave
    /// transit, mixed units, a slave set that misses the surface facing its master, an
    /// unused obstacle, an axis not held, too many frames), then step cuts, the energy
    /// balance, plastic work above the energy supplied, a step too long for the impact, a
    /// pair that never closed, a contact penetration beyond TOL (with its node and cause), a
    /// plastic contact resolved by too few segments, kinetic energy above what was given,
    /// nodes across the axis, a pair still closed and approaching at the end, hourglass
    /// energy, mass scaling above 1 % of a body's mass or on a contact surface. Empty when
    /// none.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The unit of each history.csv column that has one, as the scene's material data tell
    /// (SI or mm-t-s; `[length]` and the like otherwise; per unit depth in plane strain):
    /// `impact plot` labels its axes with them. Filled by the run (`analysis::units`).
    #[serde(default)]
    pub column_units: std::collections::BTreeMap<String, String>,
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
            newton_iterations_median: None,
            newton_iterations_max: None,
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
            bodies: body_masses(model),
            timing: Default::default(),
            max_temperature: None,
            mass_scaling: None,
            subcycling: None,
            ale: None,
            arc_length: None,
            warnings: Vec::new(),
            column_units: Default::default(),
        }
    }
}

/// summary.json `buckling` (present when the scene has `[analysis.buckling]`).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct BucklingSummary {
    /// lambda_1 of the end loads at the prebuckling state (`modes` > 0), else null.
    pub critical_load_factor: Option<f64>,
    /// lambda_1 .. lambda_modes, ascending.
    pub load_factors: Vec<f64>,
    /// Negative pivots of K_T at the start and after the last converged state (`check`).
    pub initial_negative_pivots: Option<usize>,
    pub final_negative_pivots: Option<usize>,
    /// The first time (load factor in statics with the default ramp) at which the count
    /// differed from the initial one, and the count then.
    pub inertia_change_time: Option<f64>,
    pub negative_pivots_at_change: Option<usize>,
    /// The load factor there, on an arc-length path (whose `time` is the path's pseudo
    /// time, not the load); null elsewhere.
    #[serde(default)]
    pub load_factor_at_change: Option<f64>,
    /// The run stopped there (`on_critical = "stop"`).
    pub stopped: bool,
    /// The file of the mode that crossed zero there (`NAME_critical.pvd`: one frame at that
    /// time, the eigenvector of K_T whose eigenvalue is nearest zero), when it was found.
    #[serde(default)]
    pub critical_mode: Option<String>,
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
    /// The linear solver could not be set up for the model's pattern (the output folder
    /// `dir` named).
    pub fn setup(dir: &std::path::Path, e: impl std::fmt::Display) -> RunError {
        RunError::Output(OutputError::Invalid {
            path: dir.to_path_buf(),
            reason: e.to_string(),
        })
    }

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
