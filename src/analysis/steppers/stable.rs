//! The stable step of central difference and the wave speeds it comes from: one place that
//! the run, its clock and start (`explicit::Start`), `impact check`, the set-up warnings and
//! the sweep read (docs/theory.md 8.7). Its one type is [`StableStep`] (dt, body, element).
//!
//! Legend
//! ```text
//! c          dilatational wave speed sqrt(M / rho), M the constrained modulus of the
//!            formulation: lambda + 2 mu (plane strain, axisymmetric), E / (1 - nu^2) (plane
//!            stress), E (rod)
//! dt_crit    2 / omega_max, omega_max^2 the largest element eigenvalue of M_e^-1 K_e of the
//!            initial configuration (the limit a fixed dt is checked against); with the
//!            bulk viscosity of central difference times sqrt(1 + xi^2) - xi, xi = b_1 its
//!            damping at rest (element::bulk_viscosity::damped_step_factor)
//! dt_bound   2 / sqrt(max_e omega^2_e), omega^2_e the closed-form frequency bound of the
//!            kernel that steps the run (<= dt_crit): the run's automatic step is
//!            time_step_scale dt_bound, re-evaluated every step (clock.rs)
//! ```
//!
//! From the scene key to the step (`analysis.stable_step`, default `global`):
//! `scene::spec::StableStepKind` -> `DynamicAnalysis::stable_estimate` ->
//! `assembly::explicit::kernel_for` -> `Skeleton::with_stable_step` (the one Quad4 loop,
//! `assembly/explicit/skeleton.rs`: each element's bound from its rule, damped by the bulk
//! viscosity; made tight by `tight::Tightness`, the mesh's estimate `global::Global`; every
//! exact element frequency from `element::highest_frequency_squared`) -> the kernel's
//! `stable_step` (the start) and `step` (each step's largest omega^2) -> [`explicit_clock`] ->
//! `Clock` (clock.rs): dt = time_step_scale 2 / omega_max. dt_crit (`critical_time_step`) is
//! the element eigenvalues of the assembly's own kernels, through the same routine.

use super::clock::Clock;
use crate::assembly::explicit::ExplicitKernel;
use crate::assembly::{self, State};
use crate::element::bulk_viscosity::damped_step_factor;
use crate::output::readable;
use crate::scene::DynamicAnalysis;
use crate::scene::spec::AdaptiveStep;
use crate::scene::{InputError, Model};

pub use crate::assembly::StableStep;

/// The central-difference stability limit dt_crit of the model in its initial state, with
/// the element that sets it.
pub fn critical_time_step(model: &Model) -> Result<StableStep, InputError> {
    let state = State::initial(model);
    assembly::eigenvalue_stable_step(model, &state, model.analysis.geometry())
        .map_err(|err| InputError::new(&model.file, err.to_string()))
}

/// The clock of a central-difference run that starts from `state`: dt_crit `exact` (from
/// [`checked_step`]) for a fixed step's check, and the stable step of `kernel` (the one-point
/// or the 2x2 kernel, or the general element loop) that an automatic step scales.
pub fn explicit_clock(
    model: &Model,
    spec: &DynamicAnalysis,
    exact: f64,
    state: &State,
    kernel: &dyn ExplicitKernel,
) -> Result<Clock, InputError> {
    let limit = kernel
        .stable_step(&state.coordinates)
        .map_err(|err| InputError::new(&model.file, err.to_string()))?;
    Ok(Clock::new(spec, exact, limit))
}

/// The stability limit of `model` under `spec` (the bulk viscosity's damping at rest taken
/// into account), or the refusal of a fixed dt above it (unless the scene sets
/// `allow_unstable` to watch it blow up): the one check `impact check` and a run share.
pub fn checked_step(model: &Model, spec: &DynamicAnalysis) -> Result<StableStep, InputError> {
    let limit = initial_limit(model, spec)?;
    if let Some(dt) = spec.fixed_dt()
        && dt > limit.dt
        && !spec.allow_unstable
    {
        return Err(InputError::new(
            &model.file,
            format!(
                "analysis.dt = {} exceeds the central-difference stability limit {}{} (dt / dt_crit = {}; set by body `{}`, element {}); \
                 lower dt, use dt = \"auto\", or set analysis.allow_unstable = true to watch it blow up",
                readable(dt),
                readable(limit.dt),
                if spec.bulk_viscosity.is_some() {
                    " with the bulk viscosity's damping"
                } else {
                    ""
                },
                readable(dt / limit.dt),
                model.bodies[limit.body].name,
                limit.element
            ),
        ));
    }
    Ok(limit)
}

/// The stability limit of `model`'s initial configuration under `spec` (the element
/// eigenvalues; the bulk viscosity's damping at rest taken into account).
pub fn initial_limit(model: &Model, spec: &DynamicAnalysis) -> Result<StableStep, InputError> {
    Ok(damped_at_rest(critical_time_step(model)?, spec))
}

/// The stability limit `limit` shortened by the damping of `spec`'s bulk viscosity at rest
/// (every element has the same, b_1: element::bulk_viscosity); unchanged without it.
fn damped_at_rest(limit: StableStep, spec: &DynamicAnalysis) -> StableStep {
    match &spec.bulk_viscosity {
        Some(viscosity) => StableStep {
            dt: limit.dt * damped_step_factor(viscosity.damping_fraction_at_rest()),
            ..limit
        },
        None => limit,
    }
}

/// The step an implicit run starts with: the fixed `dt`, or for `dt = "auto"` the time a
/// dilatational wave takes to cross the smallest element (the critical step of central
/// difference, [`critical_time_step`]): a step that resolves the fastest wave the mesh can
/// carry, from which the error control grows or shrinks it; within `dt_min`, `dt_max`.
pub fn implicit_first_step(model: &Model, spec: &DynamicAnalysis) -> Result<f64, InputError> {
    match spec.adaptive() {
        None => Ok(spec
            .fixed_dt()
            .expect("an implicit step is fixed or adaptive (checked by the scene)")),
        Some(AdaptiveStep { min, max, .. }) => {
            let courant = critical_time_step(model)?.dt;
            let step = courant.min(max.unwrap_or(f64::INFINITY)).min(spec.end_time);
            Ok(step.max(min.unwrap_or(0.0)))
        }
    }
}

/// A body's wave speed and the modulus it comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct WaveSpeed {
    /// sqrt(modulus / rho).
    pub speed: f64,
    pub modulus: f64,
    /// The modulus in words: `lambda + 2 mu (plane strain)`, ...
    pub modulus_name: &'static str,
}

/// The dilatational wave speed of `body`'s material in its formulation (None without
/// density: a static scene may leave it out).
pub fn wave_speed(body: &crate::scene::Body) -> Option<WaveSpeed> {
    let m = &body.material;
    if m.density <= 0.0 {
        return None;
    }
    let modulus = body.p_wave_modulus();
    let modulus_name = body.kind.modulus_name();
    Some(WaveSpeed {
        speed: (modulus / m.density).sqrt(),
        modulus,
        modulus_name,
    })
}
