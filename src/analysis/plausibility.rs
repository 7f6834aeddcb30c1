//! Plausibility at the end of a run: what a finished run can say about its own answer. Each
//! warning is a sentence in summary.json `warnings` and on the closing lines; a warning
//! never changes the exit code (`impact run --strict` makes any warning exit 3).

use super::Summary;
use super::record::Energies;
use crate::assembly::{self, State};
use crate::contact::penetration_limits;
use crate::output::readable;
use crate::scene::Model;
use crate::scene::model::Analysis;
use crate::scene::spec::{IntegratorKind, TimeStep};

/// The energy balance error (summary.energy.max_relative_drift) above which a run warns:
/// a conserving integrator stays within a few 1e-3 on the shipped scenes; more means
/// numerical damping, step cuts or a contact that works or leaks energy.
pub const BALANCE_WARNING: f64 = 0.05;

/// An implicit step longer than this many explicit stable steps of the median element on a
/// run whose contact lasted fewer than [`CONTACT_STEPS`] steps: the contact force then rises
/// over fewer steps than the wave needs to cross a typical element, and the impact is drawn
/// with too few points (an accuracy warning; the implicit methods are stable). The median,
/// not the smallest element: a graded mesh's few small elements (a sphere's pole) do not set
/// the resolution of the impact; and a long contact (Hertz's, over some 25 steps of
/// sphere_wall) is resolved by its own length whatever the waves do.
pub const IMPACT_STEP_RATIO: f64 = 10.0;

/// A penetration deeper than this share of the slave node spacing warns: one-pass
/// node-to-segment contact lets master nodes into the slave body by a geometric error of
/// the discretization (a few per cent of an element at a curved tip: 3.8 % on round_bar),
/// and a body sinking into the other (the roles swapped: more than an element) is far
/// beyond it. Never below the pair's TOL.
pub const PENETRATION_SHARE: f64 = 0.05;

/// See [`IMPACT_STEP_RATIO`].
pub const CONTACT_STEPS: f64 = 20.0;

/// The warnings of a run that ended with `summary` and the last `energies`.
pub fn warnings(model: &Model, summary: &Summary, energies: &Energies) -> Vec<String> {
    let mut out = Vec::new();
    if summary.step_cuts > 0 {
        out.push(format!(
            "{} step cut(s): Newton did not converge in the nominal step there; a smaller \
             analysis.dt (or analysis.newton settings) avoids them",
            summary.step_cuts
        ));
    }
    let drift = summary.energy.max_relative_drift;
    if drift > BALANCE_WARNING {
        out.push(format!(
            "the energy balance is off by {:.3} % of the energy in play at its worst (above \
             {} %): numerical damping of the integrator, step cuts or the contact conditions \
             took or gave that energy",
            100.0 * drift,
            100.0 * BALANCE_WARNING
        ));
    }
    let supplied = summary.energy.initial + energies.external_work.max(0.0);
    if energies.plastic_work > supplied * (1.0 + 1e-6) && energies.plastic_work > 0.0 {
        out.push(format!(
            "the plastic work {} exceeds the energy supplied {} (initial energy and external \
             work): the step is too long for the plastic flow",
            readable(energies.plastic_work),
            readable(supplied)
        ));
    }
    if let Some(problem) = time_step_warning(model, summary) {
        out.push(problem);
    }
    if let Some(depth) = summary.contact.max_penetration {
        let coords = model.coordinates();
        let limits = penetration_limits(&model.contacts, &coords);
        // a pair with one slave (a rod's end) has no spacing: the length of its elements
        let spacing = model
            .contacts
            .iter()
            .zip(&limits)
            .map(|(pair, limit)| match pair.slaves.as_slice() {
                [single] => shortest_edge_at(model, &coords, *single),
                _ => 2.0 * limit,
            })
            .fold(f64::INFINITY, f64::min);
        let tolerance = model
            .contacts
            .iter()
            .map(|c| c.options.tolerance)
            .fold(0.0, f64::max);
        let share = if spacing.is_finite() {
            PENETRATION_SHARE * spacing
        } else {
            0.0
        };
        let bound = tolerance.max(share);
        if depth > bound {
            out.push(format!(
                "contact: a node went {} deep into the other body, beyond {} (the larger of TOL \
                 and {} % of the slave node spacing, or of a lone slave's element); history.csv `penetration` shows when (a \
                 master node sinking into the slave body is not seen by one-pass contact: swap \
                 the roles or refine the slave surface)",
                readable(depth),
                readable(bound),
                100.0 * PENETRATION_SHARE
            ));
        }
    }
    out
}

/// The shortest element edge that ends at global node `node`.
fn shortest_edge_at(model: &Model, coords: &[[f64; 2]], node: usize) -> f64 {
    let mut shortest = f64::INFINITY;
    for body in &model.bodies {
        for e in 0..body.elements() {
            let nodes: Vec<usize> = body
                .mesh
                .cells
                .nodes_of(e)
                .iter()
                .map(|n| body.global(*n))
                .collect();
            for (i, a) in nodes.iter().enumerate() {
                let b = nodes[(i + 1) % nodes.len()];
                if (*a == node || b == node) && *a != b {
                    let (p, q) = (coords[*a], coords[b]);
                    shortest = shortest.min((q[0] - p[0]).hypot(q[1] - p[1]));
                }
            }
        }
    }
    shortest
}

/// A dynamic step longer than the run, or an implicit step far above the explicit stable
/// step on a run with contact.
fn time_step_warning(model: &Model, summary: &Summary) -> Option<String> {
    let Analysis::Dynamic(d) = &model.analysis else {
        return None;
    };
    let TimeStep::Fixed(dt) = d.step else {
        return None;
    };
    if dt > d.end_time {
        return Some(format!(
            "analysis.dt = {} is longer than end_time = {}: the run is one shortened step",
            readable(dt),
            readable(d.end_time)
        ));
    }
    let first = summary.contact.first_contact_time;
    if d.integrator == IntegratorKind::CentralDifference || first.is_none() {
        return None;
    }
    // the contact's length in steps: to the last release, or to the end while still closed
    let last = summary
        .contact
        .last_release_time
        .unwrap_or(summary.end_time);
    let contact_steps = (last - first.unwrap_or(0.0)) / dt;
    if contact_steps >= CONTACT_STEPS {
        return None;
    }
    let typical = median_stable_step(model)?;
    (dt > IMPACT_STEP_RATIO * typical).then(|| {
        format!(
            "analysis.dt = {} is {:.0} times the explicit stable step of the median element \
             ({}) and the contact lasted {contact_steps:.1} steps: stable, but the impact is \
             resolved by too few steps; steps nearer the stable step follow the contact force",
            readable(dt),
            dt / typical,
            readable(typical)
        )
    })
}

/// The central-difference stable step 2 / omega of the median element of the initial mesh.
fn median_stable_step(model: &Model) -> Option<f64> {
    let state = State::initial(model);
    let bounds = assembly::frequency_bounds(model, &state, model.analysis.geometry()).ok()?;
    let mut omega_squared: Vec<f64> = bounds.iter().map(|b| b.omega_squared).collect();
    if omega_squared.is_empty() {
        return None;
    }
    let middle = omega_squared.len() / 2;
    let (_, median, _) = omega_squared.select_nth_unstable_by(middle, f64::total_cmp);
    (*median > 0.0).then(|| 2.0 / median.sqrt())
}
