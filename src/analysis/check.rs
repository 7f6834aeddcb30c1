//! What `impact check` says about a valid scene besides its size: per body the wave speed
//! of its formulation and the yield strain of its material, and the time step against the
//! stability limit of the chosen integrator (with the same refusal as a run).
//!
//! Legend
//! ```text
//! c            dilatational wave speed: sqrt(M / rho) with the constrained modulus M of the
//!              formulation: lambda + 2 mu (plane strain, axisymmetric), E / (1 - nu^2)
//!              (plane stress), E (rod)
//! eps_y        yield strain sigma_y / E (the initial yield stress)
//! dt_crit      central difference: 2 / omega_max (element eigenvalue bound);
//!              Newmark (gamma >= 1/2, beta < gamma / 2): Omega_crit / omega_max with
//!              Omega_crit = 1 / sqrt(gamma / 2 - beta) (Hughes 1987, section 9.1; 2 sqrt 3 for
//!              linear acceleration); beta >= gamma / 2 >= 1/4: unconditionally stable;
//!              Wilson-theta: unconditionally stable for theta >= 1.37 only
//! ```

use super::steppers::explicit::Start;
use super::steppers::stable::{critical_time_step, implicit_first_step, initial_limit, wave_speed};
use crate::output::readable;
use crate::scene::DynamicAnalysis;
use crate::scene::spec::{IntegratorKind, MassKind};
use crate::scene::{InputError, Model};

/// How the time step of a dynamic analysis stands against its integrator's limit.
#[derive(Debug, Clone, PartialEq)]
pub enum StepStability {
    /// The integrator has no limit: dt over the central-difference limit tells how many
    /// shortest-element transits a step spans (accuracy, not stability).
    Unconditional { dt: f64, dt_crit_explicit: f64 },
    /// A limit dt_crit (central difference, linear acceleration, a conditional Newmark).
    Conditional { dt: Option<f64>, dt_crit: f64 },
    /// Newmark with gamma < 1/2: unstable at any dt.
    Unstable,
    /// Wilson-theta with theta < 1.37: conditionally stable, its limit not computed here.
    WilsonBelowLimit { dt: f64, dt_crit_explicit: f64 },
}

/// Per contact pair between two bodies, which surface is the slave and why: the code's
/// choice (`scene::roles`) or a balanced pair's two passes.
pub fn roles(model: &Model) -> Vec<String> {
    (model.contacts.iter())
        .filter_map(|pair| match &pair.chosen_roles {
            Some(why) => Some(format!("contact `{}`: {why}", pair.name)),
            None if pair.options.balanced && pair.balances.is_none() => Some(format!(
                "contact `{}`: balanced, each surface the slave of the other (docs/theory.md 8.3d)",
                pair.name
            )),
            None => None,
        })
        .collect()
}

/// Element updates per second per core of the explicit kernels through the whole driver,
/// as `impact bench` measured them on the 2-core development machine (docs/performance.md:
/// one-point 5.2-5.9e6 on the rod pair and rod, 2x2 with J2 1.9e6; Johnson-Cook is slower):
/// a rough scale for the wall-time estimate of `check`, not a promise.
const ONE_POINT_RATE: f64 = 5.0e6;
const FULL_RATE: f64 = 1.5e6;

/// How many steps of `dt` the run takes to its end time (exactly for a fixed step, at least
/// for the automatic one: the stable step falls as elements crush), and a rough wall time
/// for central difference from the kernel's element rate.
fn step_count(model: &Model, spec: &DynamicAnalysis, dt: f64) -> String {
    let steps = (spec.end_time / dt).ceil();
    let count = match spec.step {
        crate::scene::spec::TimeStep::Fixed(_) => format!("{steps:.0} steps to end_time"),
        crate::scene::spec::TimeStep::Auto { .. } if global_step(spec) => {
            format!(
                "about {steps:.0} steps of the first step to end_time (the global estimate is taken \
             again as the mesh deforms; the step falls as elements crush)"
            )
        }
        crate::scene::spec::TimeStep::Auto { .. } => format!(
            "at least {steps:.0} steps to end_time (the automatic step falls as elements deform)"
        ),
        crate::scene::spec::TimeStep::Adaptive(adaptive) => format!(
            "{steps:.0} steps of the first step to end_time; the error control (tolerance {}) lengthens or shortens them",
            readable(adaptive.tolerance)
        ),
    };
    if spec.integrator != IntegratorKind::CentralDifference {
        return count;
    }
    let rate = match spec.quadrature {
        crate::scene::spec::Quadrature::Reduced => ONE_POINT_RATE,
        _ => FULL_RATE,
    };
    let seconds = steps * model.elements() as f64 / rate;
    format!(
        "{count}; about {} s of element updates for those steps on one core at {} element \
         updates/s (impact bench measures this machine's rate)",
        readable(seconds),
        readable(rate)
    )
}

/// The step of `spec` against the stability limit of its integrator; a central-difference
/// fixed dt above its limit is refused exactly as a run refuses it.
pub fn step_stability(model: &Model, spec: &DynamicAnalysis) -> Result<StepStability, InputError> {
    let has_mass = model.bodies.iter().all(|b| b.material.density > 0.0);
    if spec.integrator == IntegratorKind::CentralDifference {
        let start = Start::new(model, spec)?;
        return explicit_stability(model, spec, &start);
    }
    let dt = implicit_first_step(model, spec)?;
    let newmark = matches!(
        spec.integrator,
        IntegratorKind::Average | IntegratorKind::Linear | IntegratorKind::Newmark
    );
    if newmark && spec.gamma < 0.5 {
        return Ok(StepStability::Unstable);
    }
    let explicit = if has_mass {
        critical_time_step(model)?.dt
    } else {
        f64::NAN
    };
    if spec.integrator == IntegratorKind::Wilson && spec.theta < 1.37 {
        return Ok(StepStability::WilsonBelowLimit {
            dt,
            dt_crit_explicit: explicit,
        });
    }
    if newmark && spec.beta < 0.5 * spec.gamma {
        // omega_max = 2 / dt_crit(central difference)
        let omega_crit = 1.0 / (0.5 * spec.gamma - spec.beta).sqrt();
        return Ok(StepStability::Conditional {
            dt: Some(dt),
            dt_crit: 0.5 * omega_crit * explicit,
        });
    }
    Ok(StepStability::Unconditional {
        dt,
        dt_crit_explicit: explicit,
    })
}

/// The element-eigenvalue limit of a central-difference run and the step it will take (the
/// automatic step scales the explicit kernel's conservative bound, below the limit).
fn explicit_stability(
    model: &Model,
    spec: &DynamicAnalysis,
    start: &Start,
) -> Result<StepStability, InputError> {
    // the automatic step's run does not find the limit; the check does
    let dt_crit = match start.dt_crit {
        Some(dt_crit) => dt_crit,
        None => initial_limit(model, spec)?.dt,
    };
    Ok(StepStability::Conditional {
        dt: Some(start.first_step()),
        dt_crit,
    })
}

/// The lines `impact check` prints after the model's size.
pub fn report(model: &Model) -> Result<Vec<String>, InputError> {
    let mut lines = Vec::new();
    let masses = super::summary::body_masses(model);
    for (b, body) in model.bodies.iter().enumerate() {
        let m = &body.material;
        let mut parts = Vec::new();
        if let Some(mass) = masses.get(b).filter(|_| m.density > 0.0) {
            parts.push(format!(
                "mass {} ({})",
                readable(mass.mass),
                body.kind.mass_in_words()
            ));
        }
        if let Some(c) = wave_speed(body) {
            parts.push(format!(
                "wave speed c = sqrt(M / rho) = {} with M = {} = {}",
                readable(c.speed),
                c.modulus_name,
                readable(c.modulus)
            ));
        }
        if let Some(j2) = &m.plasticity {
            parts.push(format!(
                "yield strain sigma_y / E = {}",
                readable(j2.yield_stress / m.elastic.young)
            ));
        } else {
            parts.push("elastic".into());
        }
        lines.push(format!(
            "body `{}` (material `{}`): {}",
            body.name,
            m.name,
            parts.join("; ")
        ));
    }
    let total: f64 = masses.iter().map(|m| m.mass).sum();
    lines.extend(projectile_lines(model, total));
    if let crate::scene::model::Analysis::Dynamic(spec) = &model.analysis {
        // a central-difference run's start, formed once as the run forms it
        let start = match spec.integrator {
            IntegratorKind::CentralDifference => Some(Start::new(model, spec)?),
            _ => None,
        };
        let stability = match &start {
            Some(start) => explicit_stability(model, spec, start)?,
            None => step_stability(model, spec)?,
        };
        let dt = match stability {
            StepStability::Conditional { dt, .. } => dt,
            StepStability::Unconditional { dt, .. }
            | StepStability::WilsonBelowLimit { dt, .. } => Some(dt),
            StepStability::Unstable => None,
        };
        lines.push(stability_line(model, spec, stability));
        lines.push(history_line(model, spec.end_time, dt));
        if let Some(report) = start.as_ref().and_then(|s| s.mass_scaling(model)) {
            let model_mass = report.model_mass();
            lines.push(format!(
                "mass scaling: target stable step {}; {} element(s) below it on the initial mesh \
                 scaled, adding {} ({} % of the model's mass {}), so dt above is the scaled \
                 model's (dt_crit the unscaled one's); elements that fall below the target as \
                 they deform gain mass during the run (summary.json `mass_scaling`)",
                readable(report.target),
                report.scaled.len(),
                readable(report.added_mass),
                readable(100.0 * report.added_mass / model_mass),
                readable(model_mass)
            ));
        }
        if let Some(levels) = start.as_ref().and_then(Start::levels) {
            lines.push(subcycling_line(levels));
        }
        if let Some(ale) = &spec.ale {
            lines.push(ale_line(model, ale));
        }
    }
    Ok(lines)
}

/// A line for each rigid projectile: its mass against the bodies' `total`, its velocity and
/// kinetic energy, and its rotation where it has one.
fn projectile_lines(model: &Model, total: f64) -> Vec<String> {
    let mut lines = Vec::new();
    for o in &model.obstacles {
        if let Some(p) = &o.projectile {
            let v = p.velocity;
            let (spin, rotation) = match &p.spin {
                Some(s) => (
                    0.5 * s.inertia * s.angular_velocity * s.angular_velocity,
                    format!(
                        "and rotates about its centre ({}, {}) with the moment of inertia {} \
                         from an angular velocity {}",
                        readable(s.centre[0]),
                        readable(s.centre[1]),
                        readable(s.inertia),
                        readable(s.angular_velocity)
                    ),
                ),
                None => (0.0, "without rotating".to_string()),
            };
            lines.push(format!(
                "obstacle `{}`: a rigid projectile of mass {} ({} times the bodies'), velocity \
                 ({}, {}), kinetic energy {}; it translates under the contact forces {rotation}",
                o.name,
                readable(p.mass),
                readable(p.mass / total),
                readable(v[0]),
                readable(v[1]),
                readable(0.5 * p.mass * (v[0] * v[0] + v[1] * v[1]) + spin)
            ));
        }
    }
    lines
}

/// `impact check`'s line on the ALE steps: how often, by which smoother, and per body the nodes
/// held, sliding along the boundary and free inside.
fn ale_line(model: &Model, ale: &crate::scene::model::Ale) -> String {
    let motion = crate::analysis::steppers::explicit::MeshMotion::new(model, *ale);
    let bodies: Vec<String> = model
        .bodies
        .iter()
        .zip(motion.node_classes())
        .map(|(b, [held, boundary, inside])| {
            format!(
                "`{}` {held} held, {boundary} on the boundary (sliding where it turns by less than {} degrees), {inside} inside",
                b.name,
                readable(ale.rules.slide_angle.to_degrees())
            )
        })
        .collect();
    format!(
        "ALE: every {} steps the nodes are smoothed ({}, each move sweeping at most {} of an \
         element's area) and the state remapped conservatively; {} (summary.json `ale`, \
         history.csv `remap_loss`)",
        ale.every,
        ale.rules.smoother.name(),
        readable(ale.rules.max_move),
        bodies.join("; ")
    )
}

/// `impact check`'s line on the history rows: the cadence and about how many rows it gives
/// for `dt` (the nominal step).
fn history_line(model: &Model, end_time: f64, dt: Option<f64>) -> String {
    let cadence = model.history_cadence();
    let steps = dt.filter(|dt| *dt > 0.0).map(|dt| (end_time / dt).ceil());
    if cadence.every == Some(1) {
        return "history.csv: a row every step".into();
    }
    // a row when either is due: at most the sum of theirs, at most one a step
    let mut parts = Vec::new();
    let mut rows = 0.0;
    if let Some(n) = cadence.every {
        parts.push(format!("every {n} steps"));
        rows += steps.map_or(0.0, |s| (s / n as f64).ceil());
    }
    if let Some(h) = cadence.interval {
        parts.push(format!("at every multiple of {}", readable(h)));
        rows += (end_time / h).ceil();
    }
    let rows = steps.map(|s| rows.min(s));
    let source = if model.output.history_every.is_some() || model.output.history_interval.is_some()
    {
        "output.history_*"
    } else {
        "central difference's default, end_time / 1e4"
    };
    format!(
        "history.csv: a row {} ({source}){}, and the steps between rows where a column peaks",
        parts.join(" or "),
        rows.map_or(String::new(), |r| format!(", about {r:.0} rows"))
    )
}

/// Whether `spec` is central difference's automatic step scaled from the global estimate.
fn global_step(spec: &DynamicAnalysis) -> bool {
    spec.integrator == IntegratorKind::CentralDifference
        && matches!(spec.step, crate::scene::spec::TimeStep::Auto { .. })
        && spec.stable_estimate() == crate::scene::spec::StableStepKind::Global
}

/// `impact check`'s line on the step of `spec` against its integrator's limit.
fn stability_line(model: &Model, spec: &DynamicAnalysis, stability: StepStability) -> String {
    let name = spec.integrator.name();
    match stability {
        StepStability::Conditional {
            dt: Some(dt),
            dt_crit,
        } => format!(
            "integrator {name}: dt = {}, stability limit dt_crit = {}, dt / dt_crit = {}{}; {}{}",
            readable(dt),
            readable(dt_crit),
            readable(dt / dt_crit),
            if global_step(spec) {
                " (dt_crit from the largest element eigenvalue; the global step scales the \
                 mesh's highest frequency, at or below it by Irons' inequality, so dt may exceed dt_crit)"
            } else {
                ""
            },
            step_count(model, spec, dt),
            if spec.mass == MassKind::Consistent {
                " (from the lumped-mass frequency bound: the consistent mass's highest \
                 frequency is higher, sqrt 3 times for rods, so its limit is lower)"
            } else {
                ""
            }
        ),
        StepStability::Conditional { dt: None, dt_crit } => format!(
            "integrator {name}: stability limit dt_crit = {}",
            readable(dt_crit)
        ),
        StepStability::Unconditional {
            dt,
            dt_crit_explicit,
        } if dt_crit_explicit.is_finite() => format!(
            "integrator {name}: unconditionally stable; dt = {} is {} times the central-difference limit {} (about the number of elements a wave crosses in one step)",
            readable(dt),
            readable(dt / dt_crit_explicit),
            readable(dt_crit_explicit)
        ),
        StepStability::Unconditional { dt, .. } => {
            format!(
                "integrator {name}: unconditionally stable; dt = {}",
                readable(dt)
            )
        }
        StepStability::WilsonBelowLimit {
            dt,
            dt_crit_explicit,
        } => format!(
            "integrator {name}: theta = {} < 1.37 is only conditionally stable; dt = {} is {} times the central-difference limit {}",
            readable(spec.theta),
            readable(dt),
            readable(dt / dt_crit_explicit),
            readable(dt_crit_explicit)
        ),
        StepStability::Unstable => format!(
            "integrator {name}: gamma = {} < 1/2 is unstable at any dt",
            readable(spec.gamma)
        ),
    }
}

/// `impact check`'s line on the levels a subcycled run starts with.
fn subcycling_line(levels: &crate::analysis::steppers::explicit::Levels) -> String {
    let counts: Vec<String> = levels
        .elements
        .iter()
        .map(|l| l.len().to_string())
        .collect();
    if levels.top == 0 {
        return "subcycling: every element on level 0 on the initial mesh (their own stable steps \
                within a factor 2, or the contact surfaces' neighbours): the run steps as one \
                until the elements' steps part as the mesh deforms (summary.json `subcycling`)"
            .to_string();
    }
    format!(
        "subcycling: levels 0 to {} on the initial mesh, {} element(s) per level (finest first); \
         the major step is {} times the step above (the finest level's); the levels follow the mesh as it deforms \
         (summary.json `subcycling`)",
        levels.top,
        counts.join(", "),
        1u64 << levels.top
    )
}
