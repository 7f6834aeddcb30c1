//! Plausibility: what the scene alone says about the run it asks for ([`setup_warnings`],
//! printed by `impact check` and repeated by the run), and what a finished run can say about
//! its own answer ([`warnings`]). Each warning is a sentence in summary.json `warnings` and
//! on the closing lines; a warning never changes the exit code (`--strict` makes any warning
//! exit 3). Each names the likely cause. The scene's own in `setup` (with the slave sets of
//! `slaves` and the unit hints of `units`), the pairs' after a run in `contact`, the rest
//! (step cuts, energies, the step, axis crossings, hourglass, mass scaling) here; a failed
//! run's message gets [`failure_hint`].
//!
//! Legend
//! ```text
//! n_steps      end_time / dt, dt the fixed step or, with dt = "auto", time_step_scale times
//!              the central-difference limit of the initial mesh (the run's first step)
//! c            a body's dilatational wave speed (stable::wave_speed)
//! L            a body's size: the shorter side of its bounding box (a rod: its length)
//! t_transit    L / c, the time a wave takes to cross the body once
//! ```

mod contact;
mod crossings;
mod initial;
mod setup;
mod slaves;
mod units;

pub use contact::{COARSE_CONTACT_NODES, PENETRATION_SHARE, STILL_APPROACHING, past_end_text};
pub use setup::{
    AXIS_TOLERANCE, FRAME_BYTES_PER_NODE, MANY_FRAMES, MIN_STEPS, expected_frames, setup_warnings,
};
pub use slaves::SLAVE_SHARE;
pub use units::{MAX_STEPS, SPEED_SHARE, YIELD_STRAIN_RANGE, failure_hint};

use super::Summary;
use super::steppers::energies::Energies;
use crate::assembly::mass_scaling::MassScalingReport;
use crate::assembly::{self, State};
use crate::contact::Master;
use crate::output::readable;
use crate::scene::Model;
use crate::scene::model::Analysis;
use crate::scene::spec::{IntegratorKind, TimeStep};

/// The energy balance error (summary.energy.max_relative_drift) above which a run warns:
/// a conserving integrator stays within a few 1e-3 on the shipped scenes; more means
/// numerical damping, step cuts or a contact that works or leaks energy.
pub const BALANCE_WARNING: f64 = 0.05;

/// The share of the energy in play the balance may gain (energy created) before a guarded
/// run (`analysis.energy_gain_limit`) warns: numerical damping loses energy, a consistent
/// run gains none; the shipped scenes gain at most 0.61 % (conical_bar), the d'Alembert
/// strip at Courant 0.98 aside (2.7 %).
pub const GAIN_WARNING: f64 = 0.01;

/// An implicit step longer than this many explicit stable steps of the median element, on a
/// run whose contact force rose to its peak in fewer than [`RISE_STEPS`] steps, warns: the
/// impact is then drawn with too few points (an accuracy warning; the implicit methods are
/// stable). A step of two crossings of a typical element by the wave: the seeds' bars close
/// in one or two steps at 0.7 of it (their impact conditions make the wave front's jump, as
/// the closed form has it), while a beam struck by a block at five to ten of it (the old
/// advice of the user guide) rose in about three steps to 1.4 times the converged peak
/// force. The median, not the smallest element: a graded mesh's few small elements (a
/// sphere's pole) do not set the resolution of the impact.
pub const IMPACT_STEP_RATIO: f64 = 2.0;

/// See [`IMPACT_STEP_RATIO`]: a force that rises over ten steps or more is drawn by them,
/// whatever the waves do (Hertz's on sphere_wall rises over 12.7 steps of 67 stable steps
/// each; the shipped implicit scenes otherwise rise over 20 to 220).
pub const RISE_STEPS: f64 = 10.0;

/// The hourglass energy above this share of the internal energy (stored elastic energy
/// plus plastic work, both including the hourglass work) at the end of a run warns.
///
/// The base is the whole work of deformation, as LS-DYNA's internal energy and Abaqus'
/// ALLIE count it (plastic dissipation included): the rule of thumb of both codes' guidance,
/// after Flanagan & Belytschko (1981) and Belytschko et al. (Nonlinear Finite Elements for
/// Continua and Structures), is hourglass (artificial strain) energy below about 10 % of the
/// internal energy, beyond which the hourglass forces carry a visible part of the answer.
/// Compared with the stored elastic energy alone the share means nothing after yield: the
/// Taylor rod holds 7.3 J of hourglass energy against 7.6 J stored but 315 J of plastic work
/// (2.3 % of the internal energy).
pub const HOURGLASS_SHARE: f64 = 0.10;

/// A body to which the mass scaling added more than this share of its mass warns: the
/// added inertia then carries a visible part of its answer (the wave speed in a scaled
/// element falls by sqrt(s), its kinetic energy grows by s). LS-DYNA users hold the added
/// mass of a part below about 5 % in dynamic runs; an impact whose answer is a shape (the
/// Taylor rods) moves by more than its tolerance well before that (docs/validation.md
/// 10.6), so the warning comes at 1 %.
pub const ADDED_MASS_SHARE: f64 = 0.01;

/// What a run has at its end, for [`final_warnings`].
pub struct EndOfRun<'a> {
    /// Node positions of the final configuration.
    pub positions: &'a [[f64; 2]],
    /// The energies at the end.
    pub energies: &'a Energies,
    /// The hourglass work of the one-point kernel (None without it).
    pub hourglass_energy: Option<f64>,
    /// The mass scaling per body (None without it).
    pub mass_scaling: Option<&'a MassScalingReport>,
    /// The nodal velocities and lumped masses at the end (per DOF; empty in statics).
    pub velocity: &'a [f64],
    pub mass: &'a [f64],
    /// The contact pairs closed at the end (summary.json `contact.closed_at_end`), and
    /// whether the run reached its end time (a failed or stopped run ended early).
    pub closed_at_end: &'a [String],
    pub finished: bool,
    /// The contact status at the end (where its projectiles are; None in statics).
    pub contact: Option<&'a crate::contact::ContactState>,
}

/// What the end of a run shows: nodes of an axisymmetric body that ended across the axis
/// (r < 0), where the hoop strain u_r / r has no meaning; a body whose boundary crosses
/// itself (it passed through itself: `crossings`); hourglass energy above
/// [`HOURGLASS_SHARE`] of the internal energy; mass scaling that added more than
/// [`ADDED_MASS_SHARE`] of a body's mass or scaled an element on a contact surface.
pub fn final_warnings(model: &Model, end: &EndOfRun) -> Vec<String> {
    let mut out = setup::axis_crossings(model, end.positions);
    out.extend(crossings::self_crossing_warnings(model, end.positions));
    if end.finished {
        out.extend(contact::still_closed_warnings(
            model,
            end.closed_at_end,
            (end.positions, end.velocity, end.mass),
            end.contact,
        ));
    }
    if let Some(report) = end.mass_scaling {
        out.extend(mass_scaling_warnings(model, report));
    }
    let internal = end.energies.internal + end.energies.plastic_work;
    if let Some(hourglass) = end.hourglass_energy
        && internal > 0.0
        && hourglass > HOURGLASS_SHARE * internal
    {
        out.push(format!(
            "the hourglass energy {} is {:.1} % of the internal energy {} (stored plus plastic \
             work) at the end, above {} %: the one-point elements' hourglass modes carry part \
             of the answer; refine the mesh where loads or contacts are concentrated, raise \
             analysis.hourglass (default 0.1), or use analysis.quadrature = \"full\"",
            readable(hourglass),
            100.0 * hourglass / internal,
            readable(internal),
            100.0 * HOURGLASS_SHARE
        ));
    }
    out
}

/// The mass scaling's warnings: per body, added mass above [`ADDED_MASS_SHARE`] of its
/// mass; per contact pair, scaled elements with a node on its surfaces (its slave nodes or
/// its master segments and nodes), whose added mass the contact then stops and throws.
fn mass_scaling_warnings(model: &Model, report: &MassScalingReport) -> Vec<String> {
    let mut out = Vec::new();
    for (body, scaled) in model.bodies.iter().zip(&report.bodies) {
        if scaled.mass > 0.0 && scaled.added_mass > ADDED_MASS_SHARE * scaled.mass {
            out.push(format!(
                "mass scaling (analysis.mass_scaling.target = {}) added {} to body `{}`, {:.2} % \
                 of its mass {} ({} element(s) scaled), above {} %: the added inertia changes \
                 the answer (waves cross a scaled element sqrt(s) times slower); lower the \
                 target, or compare with a run without it",
                readable(report.target),
                readable(scaled.added_mass),
                body.name,
                100.0 * scaled.added_mass / scaled.mass,
                readable(scaled.mass),
                scaled.elements_scaled,
                100.0 * ADDED_MASS_SHARE
            ));
        }
    }
    for pair in &model.contacts {
        let mut surface = pair.slaves.clone();
        match &pair.master {
            Master::Segments { edges, .. } => surface.extend(edges.iter().flatten()),
            Master::Nodes { nodes, .. } => surface.extend(nodes),
            Master::Obstacle(_) => {}
        }
        surface.sort_unstable();
        let touching: Vec<(usize, usize)> = report
            .scaled
            .iter()
            .copied()
            .filter(|&(b, e)| {
                let body = &model.bodies[b];
                body.mesh
                    .cells
                    .nodes_of(e)
                    .iter()
                    .any(|n| surface.binary_search(&body.global(*n)).is_ok())
            })
            .collect();
        if let Some(&(first_body, _)) = touching.first() {
            let elements: Vec<usize> = touching
                .iter()
                .filter(|(b, _)| *b == first_body)
                .map(|(_, e)| *e)
                .collect();
            out.push(format!(
                "mass scaling (analysis.mass_scaling.target = {}) scaled {} element(s) with a \
                 node on the surface of contact pair `{}` (body `{}`, elements {}): the \
                 contact stops and throws their added mass with the body, so the impact \
                 force and the rebound see it; lower the target below these elements' \
                 stable step, or compare with a run without it",
                readable(report.target),
                touching.len(),
                pair.name,
                model.bodies[first_body].name,
                some_nodes(&elements)
            ));
        }
    }
    out
}

/// Why an arc-length path ended short of the scene's load: a collapse (the load stood
/// still, or the tangent turned singular) or the increments ran out.
fn arc_length_end(arc: &crate::analysis::summary::ArcLengthSummary) -> String {
    if arc.collapsed {
        format!(
            "the load cannot exceed {} times the scene's load: the path reached a collapse (the \
             load stood still along it, a plastic mechanism) after {} increments",
            readable(arc.peak_load_factor),
            arc.increments
        )
    } else {
        format!(
            "the arc-length path ended after analysis.arc_length.max_increments = {} \
             increments at load factor {} (highest {}), short of the scene's load, its load \
             factor having moved by {:.2} % over its last {} increments (where that is small \
             the path is on a plateau near its limit load, which the collapse test, the load \
             standing still, misses where it moves a little, as when surface nodes slide off \
             an edge one at a time); more increments, or fewer analysis.steps (longer arcs), \
             take it further",
            arc.increments,
            readable(arc.final_load_factor),
            readable(arc.peak_load_factor),
            100.0 * arc.recent_change,
            arc.increments.min(crate::analysis::summary::RECENT)
        )
    }
}

/// A subcycled run that took at least this share of the single step's element steps is
/// warned about: its bookkeeping (a fifth of the aluminium Taylor rod's subcycled run,
/// docs/performance.md) eats a saving below a tenth.
const SUBCYCLING_GAIN: f64 = 0.9;

/// The warnings of a run that ended with `summary` and the last `energies`; `first_step` is
/// the step the run started with where it reports it (the set-up warnings find it otherwise);
/// `end` the node positions at the end, where the caller has them (the penetration's cause
/// reads them).
pub fn warnings(
    model: &Model,
    summary: &Summary,
    energies: &Energies,
    (first_step, end): (Option<f64>, Option<&[[f64; 2]]>),
) -> Vec<String> {
    let mut out = setup::setup_warnings_given(model, first_step);
    if summary.step_cuts > 0 {
        // statics takes its increments as a count, dynamics as a length
        let shorter = match model.analysis {
            Analysis::Static(_) => "more analysis.steps",
            Analysis::Dynamic(_) => "a smaller analysis.dt",
        };
        out.push(format!(
            "{} step cut(s): Newton did not converge in the nominal step there; {shorter} (or \
             analysis.newton settings) avoids them",
            summary.step_cuts
        ));
    }
    if let Some(arc) = &summary.arc_length
        && !arc.reached_load
    {
        out.push(arc_length_end(arc));
    }
    if let Some(b) = &summary.buckling
        && let (Some(t), Some(from), Some(to), false) = (
            b.inertia_change_time,
            b.initial_negative_pivots,
            b.negative_pivots_at_change,
            b.stopped,
        )
    {
        let mode = b.critical_mode.as_ref().map_or(String::new(), |file| {
            format!(" (the mode that crossed zero: {file}, one frame at that time)")
        });
        let at = match b.load_factor_at_change {
            Some(factor) => format!("load factor {} (t = {})", readable(factor), readable(t)),
            None => format!("t = {}", readable(t)),
        };
        out.push(format!(
            "the tangent's negative pivots went from {from} to {to} at {at}{mode}: the \
             structure passed a buckling or limit point there, and the run went on along the \
             path it was on (a perfect structure stays on its unstable primary path; an \
             imperfection, [analysis.buckling] imperfection, finds the buckled one; \
             on_critical = \"stop\" ends the run there)"
        ));
    }
    let (drift, gain) = (
        summary.energy.max_relative_drift,
        summary.energy.max_relative_gain,
    );
    let guarded = matches!(&model.analysis, Analysis::Dynamic(d) if d.energy_gain_limit.is_some());
    if guarded && gain > GAIN_WARNING {
        out.push(format!(
            "the energy balance gained {:.3} % of the energy in play at its worst (above {} %): \
             the run created energy (a step too long for the motion or the contact)",
            100.0 * gain,
            100.0 * GAIN_WARNING
        ));
    } else if drift > BALANCE_WARNING {
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
    if let Some(sub) = &summary.subcycling
        && sub.largest_step_ratio > 1.0
    {
        out.push(format!(
            "analysis.subcycling: an element stepped at up to {} times its own stable step: it \
             stiffened within a major step, after its level was formed; lower \
             analysis.time_step_scale or analysis.subcycling.levels (fewer substeps between the \
             levels' re-forming)",
            readable(sub.largest_step_ratio)
        ));
    }
    if let Some(sub) = &summary.subcycling
        && (sub.element_updates as f64) >= SUBCYCLING_GAIN * sub.single_step_updates as f64
    {
        out.push(format!(
            "analysis.subcycling saved {:.1} % of the element steps ({} of {}): the elements' own \
             stable steps stayed within a factor 2 of the shortest (or their neighbours on the \
             finest level, the contact surfaces' among them, held them there), so the run paid \
             the single step's element work and the levels' bookkeeping; remove subcycling",
            100.0 * (1.0 - sub.element_updates as f64 / sub.single_step_updates.max(1) as f64),
            sub.element_updates,
            sub.single_step_updates
        ));
    }
    out.extend(contact::never_closed_warnings(model, summary, energies));
    out.extend(contact::penetration_warning(model, summary, end));
    out.extend(
        summary
            .contact
            .past_end
            .as_ref()
            .map(contact::past_end_text),
    );
    out.extend(contact::coarse_contact_warnings(model, summary));
    out.extend(energy_created_warning(model, summary, energies));
    out
}

/// The kinetic energy at the end above this share more than the energy the run was given
/// (initial kinetic energy and positive external work) warns: nothing in a run without
/// loads gives energy back beyond what came in (an elastic rebound returns at most all of
/// it); the shipped scenes end at most 1 + 5e-13 of it (two_bars_smooth's rebound), a
/// coarse implicit step on a sphere striking a wall 1.16 of it.
pub const KINETIC_GAIN: f64 = 0.01;

/// The bodies left with more kinetic energy than they were given (see [`KINETIC_GAIN`]),
/// with the likely cause.
fn energy_created_warning(model: &Model, summary: &Summary, energies: &Energies) -> Option<String> {
    let given = summary.energy.initial + energies.external_work.max(0.0);
    if given <= 0.0 || energies.kinetic <= (1.0 + KINETIC_GAIN) * given {
        return None;
    }
    Some(format!(
        "the bodies end with {} of kinetic energy, {:.1} % more than they were given ({}: the \
         initial kinetic energy and the work of the loads): the run created energy, which no \
         rebound can; a step too long for the contact (analysis.dt), or mixed units: {}",
        readable(energies.kinetic),
        100.0 * (energies.kinetic / given - 1.0),
        readable(given),
        units::unit_hint(model)
    ))
}

/// The first few of `nodes` (global node ids, or element numbers) in words: `12, 14, 17 and
/// 3 more`.
pub(super) fn some_nodes(nodes: &[usize]) -> String {
    let shown: Vec<String> = nodes.iter().take(5).map(|n| n.to_string()).collect();
    if nodes.len() > 5 {
        format!("{} and {} more", shown.join(", "), nodes.len() - 5)
    } else {
        shown.join(", ")
    }
}

/// The larger side of the bounding box of `coords`.
pub(super) fn model_size(coords: &[[f64; 2]]) -> f64 {
    let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in coords {
        for k in 0..2 {
            low[k] = low[k].min(p[k]);
            high[k] = high[k].max(p[k]);
        }
    }
    (high[0] - low[0]).max(high[1] - low[1])
}

/// An implicit step above [`IMPACT_STEP_RATIO`] explicit stable steps of the median element
/// on a run whose contact force rose in fewer than [`RISE_STEPS`] steps.
fn time_step_warning(model: &Model, summary: &Summary) -> Option<String> {
    let Analysis::Dynamic(d) = &model.analysis else {
        return None;
    };
    let TimeStep::Fixed(dt) = d.step else {
        return None;
    };
    // a step longer than the run is one of the runs of too few steps of `setup_warnings`
    if dt > d.end_time {
        return None;
    }
    if d.integrator == IntegratorKind::CentralDifference {
        return None;
    }
    // the force's rise in steps: from the closing to the peak, the closing step counted
    let (Some(first), Some(peak)) = (
        summary.contact.first_contact_time,
        summary.contact.peak_force_time,
    ) else {
        return None;
    };
    let rise = (peak - first).max(0.0) / dt + 1.0;
    if rise >= RISE_STEPS {
        return None;
    }
    let typical = median_stable_step(model)?;
    (dt > IMPACT_STEP_RATIO * typical).then(|| {
        format!(
            "analysis.dt = {} is {:.1} times the explicit stable step of the median element \
             ({}) and the contact force rose to its peak in {rise:.1} steps: stable, but the \
             impact is drawn by too few steps (its peak force and rebound follow the step); \
             a step that resolves the rise in ten or more, or dt = \"auto\", follows it",
            readable(dt),
            dt / typical,
            readable(typical)
        )
    })
}

/// The central-difference stable step 2 / omega of the median element of the initial mesh
/// (of n elements the one at n / 2 in ascending omega, so at n - 1 - n / 2 in ascending dt).
fn median_stable_step(model: &Model) -> Option<f64> {
    let state = State::initial(model);
    let steps = assembly::element_stable_steps(model, &state, model.analysis.geometry()).ok()?;
    let mut dt: Vec<f64> = steps.iter().map(|s| s.dt).collect();
    if dt.is_empty() {
        return None;
    }
    let middle = dt.len() - 1 - dt.len() / 2;
    let (_, median, _) = dt.select_nth_unstable_by(middle, f64::total_cmp);
    median.is_finite().then_some(*median)
}
