//! The stability limit of central difference and the wave speeds it comes from: one place
//! that the run, `impact check` and the end-of-run warnings read (docs/theory.md 8.7).
//!
//! Legend
//! ```text
//! c          dilatational wave speed sqrt(M / rho), M the constrained modulus of the
//!            formulation: lambda + 2 mu (plane strain, axisymmetric), E / (1 - nu^2) (plane
//!            stress), E (rod)
//! dt_crit    2 / omega_max, omega_max^2 the largest element eigenvalue of M_e^-1 K_e of the
//!            initial configuration
//! ```

use crate::assembly::{self, State};
use crate::element::Formulation;
use crate::output::readable;
use crate::scene::spec::{AdaptiveStep, DynamicSpec};
use crate::scene::{BodyKind, InputError, Model};

/// A central-difference stability limit and the element that sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StableStep {
    /// dt_crit = 2 / omega_max.
    pub dt: f64,
    pub body: usize,
    pub element: usize,
}

/// The central-difference stability limit of the model in its initial state, with the
/// element that sets it.
pub fn critical_time_step(model: &Model) -> Result<StableStep, InputError> {
    let state = State::initial(model);
    let bound = assembly::max_frequency_squared(model, &state, model.analysis.geometry())
        .map_err(|err| InputError::new(&model.file, err.to_string()))?;
    Ok(StableStep {
        dt: 2.0 / bound.omega_squared.sqrt(),
        body: bound.body,
        element: bound.element,
    })
}

/// The stability limit of `model`, or the refusal of a fixed dt above it (unless the scene
/// sets `allow_unstable` to watch it blow up): the one check `impact check` and a run share.
pub fn checked_step(model: &Model, spec: &DynamicSpec) -> Result<StableStep, InputError> {
    let limit = critical_time_step(model)?;
    if let Some(dt) = spec.fixed_dt()
        && dt > limit.dt
        && !spec.allow_unstable
    {
        return Err(InputError::new(
            &model.file,
            format!(
                "analysis.dt = {} exceeds the central-difference stability limit {} (dt / dt_crit = {}; set by body `{}`, element {}); \
                 lower dt, use dt = \"auto\", or set analysis.allow_unstable = true to watch it blow up",
                readable(dt),
                readable(limit.dt),
                readable(dt / limit.dt),
                model.bodies[limit.body].name,
                limit.element
            ),
        ));
    }
    Ok(limit)
}

/// The step an implicit run starts with: the fixed `dt`, or for `dt = "auto"` the time a
/// dilatational wave takes to cross the smallest element (the critical step of central
/// difference, [`critical_time_step`]): a step that resolves the fastest wave the mesh can
/// carry, from which the error control grows or shrinks it; within `dt_min`, `dt_max`.
pub fn implicit_first_step(model: &Model, spec: &DynamicSpec) -> Result<f64, InputError> {
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
    let modulus_name = match body.kind {
        BodyKind::Rod { .. } => "E (rod)",
        BodyKind::Continuum { formulation, .. } => match formulation {
            Formulation::PlaneStrain => "lambda + 2 mu (plane strain)",
            Formulation::Axisymmetric => "lambda + 2 mu (axisymmetric)",
            Formulation::PlaneStress => "E / (1 - nu^2) (plane stress)",
        },
    };
    Some(WaveSpeed {
        speed: (modulus / m.density).sqrt(),
        modulus,
        modulus_name,
    })
}
