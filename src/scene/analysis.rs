//! `[analysis]`: the kind of run (static or dynamic), the integrator and its parameters, the
//! mass, damping and quadrature, the Newton iteration and the buckling check.

use super::InputError;
use super::context::{Context, positive};
use super::model::Analysis;
use super::model::{Ale, ArcLength, DynamicAnalysis, StaticAnalysis, Subcycling};
use super::spec::{
    AdaptiveStep, AleSmoother, AnalysisKind, AnalysisSpec, ArcLengthSpec, BucklingSpec,
    BulkViscositySetting, BulkViscositySpec, ContactDynamics, DEFAULT_SUBCYCLING_LEVELS,
    IntegratorKind, MassKind, NewtonSpec, Quadrature, StableStepKind, StepSpec, TimeStep,
};
use crate::element::Strain;
use crate::element::bulk_viscosity::{self, BulkViscosity};
use crate::element::mass_scaling::MassScaling;

/// `[analysis]`: a static analysis (load steps) or a dynamic one (time steps), checked
/// against the keys that apply to it.
/// `rods`: whether a body is a rod (the explicit Quad4 kernels' options are off by default
/// there).
pub(super) fn analysis(
    cx: &Context,
    spec: &AnalysisSpec,
    rods: bool,
) -> Result<Analysis, InputError> {
    let given = |present: bool, key: &str, kind: &str| {
        if present {
            Err(cx.err(format!(
                "analysis.{key}: does not apply to a {kind} analysis"
            )))
        } else {
            Ok(())
        }
    };
    newton(cx, &spec.newton)?;
    match spec.kind {
        AnalysisKind::Static => {
            given(spec.dt.is_some(), "dt", "static")?;
            given(spec.time_step_scale.is_some(), "time_step_scale", "static")?;
            given(spec.stable_step.is_some(), "stable_step", "static")?;
            given(spec.dt_min.is_some(), "dt_min", "static")?;
            given(spec.dt_max.is_some(), "dt_max", "static")?;
            given(spec.error_tolerance.is_some(), "error_tolerance", "static")?;
            given(spec.integrator.is_some(), "integrator", "static")?;
            for (present, key) in [
                (spec.beta.is_some(), "beta"),
                (spec.gamma.is_some(), "gamma"),
                (spec.theta.is_some(), "theta"),
                (spec.alpha.is_some(), "alpha"),
                (spec.rho_infinity.is_some(), "rho_infinity"),
                (spec.mass.is_some(), "mass"),
                (spec.contact_dynamics.is_some(), "contact_dynamics"),
                (spec.rayleigh.is_some(), "rayleigh"),
                (spec.allow_unstable, "allow_unstable"),
                (spec.energy_gain_limit.is_some(), "energy_gain_limit"),
                (spec.quadrature.is_some(), "quadrature"),
                (spec.hourglass.is_some(), "hourglass"),
                (spec.bulk_viscosity.is_some(), "bulk_viscosity"),
                (spec.mass_scaling.is_some(), "mass_scaling"),
                (spec.subcycling.is_some(), "subcycling"),
                (spec.ale.is_some(), "ale"),
            ] {
                given(present, key, "static")?;
            }
            let steps = spec.steps.ok_or_else(|| {
                cx.err("analysis.steps: a static analysis needs its number of load steps")
            })?;
            if steps == 0 {
                return Err(cx.err("analysis.steps: must be at least 1"));
            }
            let end_time = positive(cx, "analysis.end_time", spec.end_time.unwrap_or(1.0))?;
            Ok(Analysis::Static(StaticAnalysis {
                steps,
                end_time,
                geometry: spec.geometry,
                newton: spec.newton.clone(),
                buckling: buckling(cx, spec)?,
                arc_length: arc_length(cx, spec.arc_length.as_ref(), steps)?,
            }))
        }
        AnalysisKind::Dynamic => dynamic(cx, spec, rods).map(Analysis::Dynamic),
    }
}

/// The share of the energy in play a dynamic run's balance may gain before it ends
/// (`analysis.energy_gain_limit`): the scene's, else [`ENERGY_GAIN_LIMIT`] where the
/// integrator's balance is an energy the scheme conserves or dissipates, else none.
fn energy_gain_limit(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<Option<f64>, InputError> {
    match spec.energy_gain_limit {
        Some(limit) => positive(cx, "analysis.energy_gain_limit", limit).map(Some),
        None => Ok(guarded(integrator).then_some(ENERGY_GAIN_LIMIT)),
    }
}

/// Whether a run of `integrator` is guarded against energy gained by default: central
/// difference (its balance takes the kinetic shadow, the energy velocity Verlet conserves)
/// and the Newmark members whose balance the scheme conserves or dissipates (average
/// acceleration, HHT, generalized-alpha, Hu's, the scene's beta and gamma). Not the linear
/// acceleration method, Wilson-theta or Houbolt: the full-step energy is not their invariant
/// (a linear oscillator under linear acceleration at h / T = 0.1 rings 1.1 % above its
/// energy; Wilson books the contact's work on its interpolated step, theory 7), so a gain
/// there is not energy created. The scene's `energy_gain_limit` guards them too.
fn guarded(integrator: IntegratorKind) -> bool {
    !matches!(
        integrator,
        IntegratorKind::Linear | IntegratorKind::Wilson | IntegratorKind::Houbolt
    )
}

/// The default of `analysis.energy_gain_limit`: 1 % of the energy in play. The shipped
/// dynamic scenes gain at most 0.61 % at any step (conical_bar, Newmark), but for the
/// d'Alembert strip at Courant 0.98 (2.7 %, which sets its own limit).
pub const ENERGY_GAIN_LIMIT: f64 = 0.01;

/// A dynamic analysis: its time step, end time and integrator with that integrator's
/// parameters, mass, damping and quadrature.
/// `analysis.arc_length`, its defaults filled in (what it may not meet, contact pairs and
/// prescribed motion, the model checks once it is whole).
fn arc_length(
    cx: &Context,
    spec: Option<&ArcLengthSpec>,
    steps: usize,
) -> Result<Option<ArcLength>, InputError> {
    let Some(spec) = spec else {
        return Ok(None);
    };
    let max_increments = spec.max_increments.unwrap_or(10 * steps);
    if max_increments == 0 {
        return Err(cx.err("analysis.arc_length.max_increments: must be at least 1"));
    }
    let iterations = spec.iterations.unwrap_or(5);
    if iterations == 0 {
        return Err(cx.err("analysis.arc_length.iterations: must be at least 1"));
    }
    Ok(Some(ArcLength {
        max_increments,
        iterations,
    }))
}

fn dynamic(cx: &Context, spec: &AnalysisSpec, rods: bool) -> Result<DynamicAnalysis, InputError> {
    if spec.steps.is_some() {
        return Err(cx.err("analysis.steps: a dynamic analysis takes `dt` and `end_time`"));
    }
    if spec.arc_length.is_some() {
        return Err(cx.err(
            "analysis.arc_length: does not apply to a dynamic analysis (arc length traces a \
             static equilibrium path)",
        ));
    }
    if spec.newton.extrapolate.is_some() {
        return Err(cx.err(
            "analysis.newton.extrapolate: does not apply to a dynamic analysis (a time step \
             starts from its integrator's prediction)",
        ));
    }
    let end_time = positive(
        cx,
        "analysis.end_time",
        spec.end_time
            .ok_or_else(|| cx.err("analysis.end_time: a dynamic analysis needs its end time"))?,
    )?;
    let integrator = spec.integrator.unwrap_or(IntegratorKind::Average);
    check_integrator_keys(cx, spec, integrator)?;
    let step = time_step(cx, spec, integrator)?;
    let (beta, gamma) = newmark_coefficients(cx, spec, integrator)?;
    let (theta, alpha, rho_infinity) = integrator_parameters(cx, spec)?;
    let (mass, rayleigh) = mass_and_damping(cx, spec, integrator)?;
    let (quadrature, hourglass) = quadrature(cx, spec, integrator)?;
    Ok(DynamicAnalysis {
        quadrature,
        hourglass,
        bulk_viscosity: bulk_viscosity(cx, spec, integrator, rods)?,
        mass_scaling: mass_scaling(cx, spec, integrator, &step)?,
        subcycling: subcycling(cx, spec, integrator, &step)?,
        ale: ale(cx, spec, integrator)?,
        step,
        end_time,
        integrator,
        beta,
        gamma,
        theta,
        alpha,
        rho_infinity,
        mass,
        contact_dynamics: contact_dynamics(cx, spec, integrator)?,
        rayleigh,
        allow_unstable: spec.allow_unstable,
        energy_gain_limit: energy_gain_limit(cx, spec, integrator)?,
        geometry: spec.geometry,
        newton: spec.newton.clone(),
        buckling: buckling(cx, spec)?,
    })
}

/// `analysis.dt` (a number, or `auto`: central difference's default, the stable step with
/// `time_step_scale` and `dt_min`; for the implicit integrators the error-controlled step
/// with `error_tolerance`, `dt_min` and `dt_max`).
fn time_step(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<TimeStep, InputError> {
    let explicit = integrator == IntegratorKind::CentralDifference;
    let given = spec.dt.or(explicit.then_some(StepSpec::Auto));
    match given {
        None => Err(cx.err("analysis.dt: a dynamic analysis needs its time step")),
        Some(StepSpec::Fixed(dt)) => {
            for (present, key) in [
                (spec.time_step_scale.is_some(), "time_step_scale"),
                (spec.stable_step.is_some(), "stable_step"),
                (spec.dt_min.is_some(), "dt_min"),
                (spec.dt_max.is_some(), "dt_max"),
                (spec.error_tolerance.is_some(), "error_tolerance"),
            ] {
                if present {
                    return Err(cx.err(format!(
                        "analysis.{key}: applies to dt = \"auto\" only (dt is {dt})"
                    )));
                }
            }
            Ok(TimeStep::Fixed(positive(cx, "analysis.dt", dt)?))
        }
        Some(StepSpec::Auto) if !explicit => adaptive(cx, spec, integrator),
        Some(StepSpec::Auto) => {
            for (present, key) in [
                (spec.dt_max.is_some(), "dt_max"),
                (spec.error_tolerance.is_some(), "error_tolerance"),
            ] {
                if present {
                    return Err(cx.err(format!(
                        "analysis.{key}: applies to the implicit integrators' dt = \"auto\" (central difference takes the stable step)"
                    )));
                }
            }
            let scale = spec.time_step_scale.unwrap_or(0.9);
            if !(scale > 0.0 && scale <= 1.0) {
                return Err(cx.err(format!(
                    "analysis.time_step_scale: must lie in (0, 1], got {scale}"
                )));
            }
            if spec.allow_unstable {
                return Err(cx.err(
                    "analysis.allow_unstable: applies to a fixed dt (dt = \"auto\" stays below the stability limit)",
                ));
            }
            let min = spec
                .dt_min
                .map(|m| positive(cx, "analysis.dt_min", m))
                .transpose()?;
            // the mesh's estimate by default; the elements' own under the subcycling, whose
            // levels are the elements' steps; the bounds under the mass scaling, whose
            // target is a bound's step (docs/theory.md 8.7)
            let stable = spec.stable_step.unwrap_or(
                match (spec.subcycling.is_some(), spec.mass_scaling.is_some()) {
                    (true, _) => StableStepKind::Tight,
                    (false, true) => StableStepKind::Bound,
                    (false, false) => StableStepKind::Global,
                },
            );
            if stable == StableStepKind::Global && spec.subcycling.is_some() {
                return Err(cx.err(
                    "analysis.stable_step: \"global\" estimates one step for the whole mesh, and analysis.subcycling \
                     steps each element at its own: use stable_step = \"tight\" with the subcycling",
                ));
            }
            Ok(TimeStep::Auto { scale, min, stable })
        }
    }
}

/// Implicit `dt = "auto"`: the error-controlled step (Zienkiewicz & Xie 1991), for the
/// Newmark family (average, Hu, newmark with beta != 1/6, HHT, generalized-alpha) only.
fn adaptive(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<TimeStep, InputError> {
    let why = match integrator {
        IntegratorKind::Wilson => Some(
            "Wilson-theta solves at t + theta dt and interpolates back: the one-step estimate of Zienkiewicz & Xie (1991) is for the Newmark family",
        ),
        IntegratorKind::Houbolt => {
            Some("Houbolt is a multistep method whose formulas assume equal steps")
        }
        IntegratorKind::Linear => Some(
            "with beta = 1/6 the leading error term, dt^2 (beta - 1/6) (a_{n+1} - a_n), vanishes",
        ),
        IntegratorKind::Newmark if (spec.beta.unwrap_or(0.25) - 1.0 / 6.0).abs() <= 1e-3 => Some(
            "with beta = 1/6 the leading error term, dt^2 (beta - 1/6) (a_{n+1} - a_n), vanishes",
        ),
        _ => None,
    };
    if let Some(why) = why {
        return Err(cx.err(format!(
            "analysis.dt: \"auto\" for integrator {} has no error estimate ({why}); give a time step, or use average, hu, hht or generalized_alpha",
            integrator.name()
        )));
    }
    if spec.time_step_scale.is_some() {
        return Err(cx.err(
            "analysis.time_step_scale: applies to central difference's dt = \"auto\" (the implicit step follows error_tolerance)",
        ));
    }
    if spec.stable_step.is_some() {
        return Err(cx.err(
            "analysis.stable_step: applies to central difference's dt = \"auto\" (the implicit step follows error_tolerance)",
        ));
    }
    let tolerance = spec
        .error_tolerance
        .unwrap_or(crate::scene::spec::DEFAULT_ERROR_TOLERANCE);
    if !(tolerance > 0.0 && tolerance < 1.0) {
        return Err(cx.err(format!(
            "analysis.error_tolerance: must lie in (0, 1), got {tolerance}"
        )));
    }
    let min = spec
        .dt_min
        .map(|m| positive(cx, "analysis.dt_min", m))
        .transpose()?;
    let max = spec
        .dt_max
        .map(|m| positive(cx, "analysis.dt_max", m))
        .transpose()?;
    if let (Some(low), Some(high)) = (min, max)
        && low > high
    {
        return Err(cx.err(format!("analysis.dt_min: {low} is above dt_max {high}")));
    }
    Ok(TimeStep::Adaptive(AdaptiveStep {
        tolerance,
        min,
        max,
    }))
}

/// The keys that belong to one integrator only are absent for the others.
fn check_integrator_keys(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<(), InputError> {
    let only_for = |present: bool, key: &str, kinds: &[IntegratorKind]| {
        if present && !kinds.contains(&integrator) {
            Err(cx.err(format!(
                "analysis.{key}: does not apply to integrator {}",
                integrator.name()
            )))
        } else {
            Ok(())
        }
    };
    use IntegratorKind as I;
    only_for(spec.beta.is_some(), "beta", &[I::Newmark])?;
    only_for(spec.gamma.is_some(), "gamma", &[I::Newmark])?;
    only_for(spec.theta.is_some(), "theta", &[I::Wilson])?;
    only_for(spec.alpha.is_some(), "alpha", &[I::Hht])?;
    only_for(
        spec.rho_infinity.is_some(),
        "rho_infinity",
        &[I::GeneralizedAlpha],
    )?;
    only_for(
        spec.allow_unstable,
        "allow_unstable",
        &[I::CentralDifference],
    )
}

/// Newmark's (beta, gamma): fixed by the named members of the family, given for `newmark`.
fn newmark_coefficients(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<(f64, f64), InputError> {
    use IntegratorKind as I;
    let (beta, gamma) = match integrator {
        I::Average => (0.25, 0.5),
        I::Linear => (1.0 / 6.0, 0.5),
        I::Hu => (1.0, 1.5),
        I::Newmark => (
            spec.beta
                .ok_or_else(|| cx.err("analysis.beta: integrator newmark needs beta"))?,
            spec.gamma
                .ok_or_else(|| cx.err("analysis.gamma: integrator newmark needs gamma"))?,
        ),
        _ => (0.25, 0.5),
    };
    if integrator == I::Newmark && !(beta > 0.0 && gamma >= 0.0) {
        return Err(cx.err(format!(
            "analysis.beta, gamma: need beta > 0 and gamma >= 0, got {beta}, {gamma}"
        )));
    }
    Ok((beta, gamma))
}

/// (theta, alpha, rho_infinity): Wilson's theta, HHT's alpha and the generalized-alpha
/// spectral radius, each with its default and range.
fn integrator_parameters(cx: &Context, spec: &AnalysisSpec) -> Result<(f64, f64, f64), InputError> {
    let theta = spec.theta.unwrap_or(1.4);
    if !(theta >= 1.0) {
        return Err(cx.err(format!(
            "analysis.theta: Wilson's theta must be >= 1, got {theta}"
        )));
    }
    let alpha = spec.alpha.unwrap_or(-0.05);
    if !(-1.0 / 3.0..=0.0).contains(&alpha) {
        return Err(cx.err(format!(
            "analysis.alpha: HHT's alpha must lie in [-1/3, 0], got {alpha}"
        )));
    }
    let rho_infinity = spec.rho_infinity.unwrap_or(0.8);
    if !(0.0..=1.0).contains(&rho_infinity) {
        return Err(cx.err(format!(
            "analysis.rho_infinity: must lie in [0, 1], got {rho_infinity}"
        )));
    }
    Ok((theta, alpha, rho_infinity))
}

/// The mass matrix (lumped for central difference) and the Rayleigh coefficients [a, b].
fn mass_and_damping(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<(MassKind, [f64; 2]), InputError> {
    use IntegratorKind as I;
    let mass = match (integrator, spec.mass) {
        (I::CentralDifference, Some(MassKind::Consistent | MassKind::DispersionFree)) => {
            return Err(cx.err("analysis.mass: central difference uses the lumped mass"));
        }
        (I::CentralDifference, _) => MassKind::Lumped,
        (_, m) => m.unwrap_or_default(),
    };
    let rayleigh = spec.rayleigh.unwrap_or([0.0, 0.0]);
    if integrator == I::CentralDifference && rayleigh[1] != 0.0 {
        return Err(cx.err(
            "analysis.rayleigh: central difference takes mass-proportional damping only (b = 0)",
        ));
    }
    if rayleigh.iter().any(|c| !(*c >= 0.0 && c.is_finite())) {
        return Err(cx.err(format!(
            "analysis.rayleigh: coefficients must be >= 0, got {rayleigh:?}"
        )));
    }
    Ok((mass, rayleigh))
}

/// `analysis.contact_dynamics`: the implicit integrators' contact treatment; central
/// difference has its own (forward-increment multipliers).
fn contact_dynamics(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<ContactDynamics, InputError> {
    match spec.contact_dynamics {
        Some(c) if c != ContactDynamics::Hughes && integrator == IntegratorKind::CentralDifference => {
            Err(cx.err(
                "analysis.contact_dynamics: applies to the implicit integrators; central difference enforces contact by forward-increment multipliers",
            ))
        }
        c => Ok(c.unwrap_or_default()),
    }
}

/// The Quad4 quadrature and its hourglass coefficient: `reduced` is the explicit,
/// finite-strain fast path without checkpoints; the coefficient belongs to it alone.
fn quadrature(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<(Quadrature, f64), InputError> {
    let quadrature = spec.quadrature.unwrap_or_default();
    if quadrature == Quadrature::Reduced {
        if integrator != IntegratorKind::CentralDifference {
            return Err(cx.err(format!(
                "analysis.quadrature: `reduced` (one-point Quad4 with hourglass control) is the explicit fast path; \
                 integrator {} needs the tangent of the full 2x2 kernel: use quadrature = \"full\" or integrator = \"central_difference\"",
                integrator.name()
            )));
        }
        if spec.geometry == Strain::Small {
            return Err(cx.err(
                "analysis.quadrature: `reduced` runs the updated-Lagrangian (finite-strain) kernel only; use geometry = \"nonlinear\" or quadrature = \"full\"",
            ));
        }
    }
    let hourglass = match (quadrature, spec.hourglass) {
        (Quadrature::Full, Some(_)) => {
            return Err(cx.err(
                "analysis.hourglass: applies to quadrature = \"reduced\" only (the full 2x2 kernel has no hourglass modes)",
            ));
        }
        (_, Some(k)) if !(0.0..=1.0).contains(&k) => {
            return Err(cx.err(format!(
                "analysis.hourglass: the hourglass coefficient must lie in [0, 1], got {k}"
            )));
        }
        (_, k) => k.unwrap_or(0.1),
    };
    Ok((quadrature, hourglass))
}

/// `analysis.bulk_viscosity`: central difference at finite strain only (it acts in the
/// explicit Quad4 kernels; the scene's checks refuse it with rod bodies), coefficients >= 0.
/// Not given, it is on with Abaqus/Explicit's coefficients wherever it applies (central
/// difference at finite strain without rods: `rods`), as in Abaqus/Explicit and LS-DYNA;
/// `"off"` turns it off.
fn bulk_viscosity(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
    rods: bool,
) -> Result<Option<BulkViscosity>, InputError> {
    let given = match spec.bulk_viscosity {
        Some(BulkViscositySetting::Off) => return Ok(None),
        Some(BulkViscositySetting::On(given)) => given,
        None if integrator == IntegratorKind::CentralDifference
            && spec.geometry != Strain::Small
            && !rods =>
        {
            BulkViscositySpec::default()
        }
        None => return Ok(None),
    };
    if integrator != IntegratorKind::CentralDifference {
        return Err(cx.err(format!(
            "analysis.bulk_viscosity: applies to integrator central_difference (it acts in the explicit Quad4 kernels); \
             integrator {} is implicit (for numerical damping there use hht or generalized_alpha): \
             remove bulk_viscosity or use integrator = \"central_difference\"",
            integrator.name()
        )));
    }
    if spec.geometry == Strain::Small {
        return Err(cx.err(
            "analysis.bulk_viscosity: acts in the finite-strain explicit Quad4 kernels; use geometry = \"nonlinear\" or remove bulk_viscosity",
        ));
    }
    let coefficient = |key: &str, value: Option<f64>, default: f64| {
        let value = value.unwrap_or(default);
        if value >= 0.0 && value.is_finite() {
            Ok(value)
        } else {
            Err(cx.err(format!(
                "analysis.bulk_viscosity.{key}: a coefficient >= 0, got {value}"
            )))
        }
    };
    Ok(Some(BulkViscosity {
        linear: coefficient("linear", given.linear, bulk_viscosity::DEFAULT_LINEAR)?,
        quadratic: coefficient(
            "quadratic",
            given.quadratic,
            bulk_viscosity::DEFAULT_QUADRATIC,
        )?,
    }))
}

/// `analysis.mass_scaling`: central difference at finite strain with the automatic step (it
/// acts in the explicit Quad4 kernels; the scene's checks refuse it with rod bodies), a
/// target step > 0.
fn mass_scaling(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
    step: &TimeStep,
) -> Result<Option<MassScaling>, InputError> {
    let Some(given) = spec.mass_scaling else {
        return Ok(None);
    };
    if integrator != IntegratorKind::CentralDifference {
        return Err(cx.err(format!(
            "analysis.mass_scaling: applies to integrator central_difference (it raises the masses of the elements that \
             limit the explicit stable step); integrator {} is implicit and has no such limit: remove mass_scaling or use \
             integrator = \"central_difference\"",
            integrator.name()
        )));
    }
    if spec.geometry == Strain::Small {
        return Err(cx.err(
            "analysis.mass_scaling: acts in the finite-strain explicit Quad4 kernels; use geometry = \"nonlinear\" or remove mass_scaling",
        ));
    }
    if let TimeStep::Fixed(dt) = step {
        return Err(cx.err(format!(
            "analysis.mass_scaling: scales the elements below its target so that the automatic step can be longer; \
             with the fixed analysis.dt = {dt} nothing would use the added mass: set dt = \"auto\" (central \
             difference's default) or remove mass_scaling"
        )));
    }
    let target = given.target;
    if !(target > 0.0 && target.is_finite()) {
        return Err(cx.err(format!(
            "analysis.mass_scaling.target: a stable step (a time) > 0, got {target}"
        )));
    }
    Ok(Some(MassScaling { target }))
}

/// `analysis.subcycling`: central difference in the finite-strain explicit Quad4 kernels
/// (their element loops step a subset of the elements; the scene's checks refuse rods with
/// them), the automatic step (the levels follow the elements'
/// own stable steps), no mass scaling (the two answer the same short elements: one at a
/// time), at most 10 levels (steps up to 1024 times the shortest).
fn subcycling(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
    step: &TimeStep,
) -> Result<Option<Subcycling>, InputError> {
    let Some(given) = spec.subcycling else {
        return Ok(None);
    };
    if integrator != IntegratorKind::CentralDifference {
        return Err(cx.err(format!(
            "analysis.subcycling: steps each element of central_difference with its own stable step; integrator {} \
             is implicit and has no stable step: remove subcycling or use integrator = \"central_difference\"",
            integrator.name()
        )));
    }
    if spec.geometry == Strain::Small {
        return Err(cx.err(
            "analysis.subcycling: runs in the finite-strain explicit Quad4 kernels; use geometry = \"nonlinear\" or remove subcycling",
        ));
    }
    if let TimeStep::Fixed(dt) = step {
        return Err(cx.err(format!(
            "analysis.subcycling: groups the elements by their own stable steps, which the automatic step follows; \
             with the fixed analysis.dt = {dt} set dt = \"auto\" (central difference's default) or remove subcycling"
        )));
    }
    if spec.mass_scaling.is_some() {
        return Err(cx.err(
            "analysis.subcycling: and analysis.mass_scaling both answer the elements with the shortest steps; \
             use one of them",
        ));
    }
    let levels = given.levels.unwrap_or(DEFAULT_SUBCYCLING_LEVELS);
    if levels > MAX_SUBCYCLING_LEVELS {
        return Err(cx.err(format!(
            "analysis.subcycling.levels: at most {MAX_SUBCYCLING_LEVELS} (steps up to {} times the shortest), got {levels}",
            1u32 << MAX_SUBCYCLING_LEVELS
        )));
    }
    Ok(Some(Subcycling { levels }))
}

/// `analysis.ale`: central difference in the finite-strain explicit Quad4 kernels (the
/// scene's checks refuse rods with it), without the subcycling and the mass scaling (their
/// element levels and factors belong to the Lagrangian elements); `every` >= 1, `max_move` in (0, 0.5], `slide_angle` in
/// [0, 45] degrees.
fn ale(
    cx: &Context,
    spec: &AnalysisSpec,
    integrator: IntegratorKind,
) -> Result<Option<Ale>, InputError> {
    let Some(given) = spec.ale else {
        return Ok(None);
    };
    if integrator != IntegratorKind::CentralDifference {
        return Err(cx.err(format!(
            "analysis.ale: smooths and remaps the mesh of central_difference's explicit kernels; integrator {} \
             is implicit: remove ale or use integrator = \"central_difference\"",
            integrator.name()
        )));
    }
    if spec.geometry == Strain::Small {
        return Err(cx.err(
            "analysis.ale: runs in the finite-strain explicit Quad4 kernels; use geometry = \"nonlinear\" or remove ale",
        ));
    }
    for (on, key) in [
        (spec.subcycling.is_some(), "subcycling"),
        (spec.mass_scaling.is_some(), "mass_scaling"),
    ] {
        if on {
            return Err(cx.err(format!(
                "analysis.ale: is not combined with analysis.{key} (its state belongs to the Lagrangian elements); use one of them"
            )));
        }
    }
    let every = given.every.unwrap_or(10);
    if every == 0 {
        return Err(cx.err("analysis.ale.every: smooth every N steps, N >= 1; got 0"));
    }
    let max_move = given.max_move.unwrap_or(0.25);
    if !(max_move > 0.0 && max_move <= 0.5) {
        return Err(cx.err(format!(
            "analysis.ale.max_move: the share of an element's area a node's move may sweep in one ALE step, in (0, 0.5], got {max_move}"
        )));
    }
    let slide = given.slide_angle.unwrap_or(30.0);
    if !(0.0..=45.0).contains(&slide) {
        return Err(cx.err(format!(
            "analysis.ale.slide_angle: degrees in [0, 45], got {slide}"
        )));
    }
    let smoother = match given.smoother.unwrap_or(AleSmoother::Equipotential) {
        AleSmoother::Volume => crate::ale::Smoother::Volume,
        AleSmoother::Laplace => crate::ale::Smoother::Laplace,
        AleSmoother::Equipotential => crate::ale::Smoother::Equipotential,
    };
    Ok(Some(Ale {
        every,
        rules: crate::ale::Rules {
            smoother,
            max_move,
            slide_angle: slide.to_radians(),
        },
    }))
}

/// The most subcycling levels a scene may ask for.
const MAX_SUBCYCLING_LEVELS: u32 = 10;

/// `[analysis.buckling]`, which needs an implicit tangent.
fn buckling(cx: &Context, spec: &AnalysisSpec) -> Result<Option<BucklingSpec>, InputError> {
    let Some(b) = &spec.buckling else {
        return Ok(None);
    };
    if spec.integrator == Some(IntegratorKind::CentralDifference) {
        return Err(cx.err(
            "analysis.buckling: the explicit method assembles no tangent; use an implicit integrator",
        ));
    }
    if let Some(imperfection) = &b.imperfection {
        if imperfection.mode == 0 {
            return Err(cx.err("analysis.buckling.imperfection.mode: modes count from 1"));
        }
        if !(imperfection.amplitude.is_finite() && imperfection.amplitude != 0.0) {
            return Err(cx.err(format!(
                "analysis.buckling.imperfection.amplitude: a finite, non-zero length, got {}",
                imperfection.amplitude
            )));
        }
    }
    Ok(Some(b.clone()))
}

/// `[analysis.newton]`: counts at least 1, tolerances positive, contraction in (0, 1].
fn newton(cx: &Context, n: &NewtonSpec) -> Result<(), InputError> {
    if n.refactor_every == Some(0) {
        return Err(cx.err("analysis.newton.refactor_every: must be at least 1"));
    }
    if n.max_iterations == 0 {
        return Err(cx.err("analysis.newton.max_iterations: must be at least 1"));
    }
    positive(cx, "analysis.newton.tol_displacement", n.tol_displacement)?;
    positive(cx, "analysis.newton.tol_force", n.tol_force)?;
    if !(n.contraction > 0.0 && n.contraction <= 1.0) {
        return Err(cx.err(format!(
            "analysis.newton.contraction: must lie in (0, 1], got {}",
            n.contraction
        )));
    }
    Ok(())
}
