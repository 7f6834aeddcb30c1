//! Plausibility: what the scene alone says about the run it asks for ([`setup_warnings`],
//! printed by `impact check` and repeated by the run), and what a finished run can say about
//! its own answer ([`warnings`]). Each warning is a sentence in summary.json `warnings` and
//! on the closing lines; a warning never changes the exit code (`--strict` makes any warning
//! exit 3).
//!
//! Legend
//! ```text
//! n_steps      end_time / dt, dt the fixed step or, with dt = "auto", time_step_scale times
//!              the central-difference limit of the initial mesh (the run's first step)
//! c            a body's dilatational wave speed (stable::wave_speed)
//! L            a body's size: the shorter side of its bounding box (a rod: its length)
//! t_transit    L / c, the time a wave takes to cross the body once
//! ```

use super::Summary;
use super::steppers::energies::Energies;
use super::steppers::explicit::Start;
use super::steppers::stable::{implicit_first_step, wave_speed};
use crate::assembly::mass_scaling::MassScalingReport;
use crate::assembly::{self, State};
use crate::contact::{ContactPair, Master, penetration_limits};
use crate::output::readable;
use crate::scene::model::Analysis;
use crate::scene::spec::{IntegratorKind, TimeStep};
use crate::scene::{Body, Model};

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

/// A dynamic run of fewer steps than this warns: a central-difference or Newmark step
/// resolves a period of at least about ten steps (the period error of the trapezoidal rule
/// is (omega dt)^2 / 12: 3 % at ten steps per period, 33 % at three), and an impact needs
/// steps for the force to rise and fall. Far fewer steps than that is mostly a sign of
/// mixed units: the step comes from the wave speed, the end time from the user.
pub const MIN_STEPS: f64 = 10.0;

/// The warnings the scene alone gives, before a step is taken: `impact check` prints them and
/// a run repeats them in summary.json. A dynamic run of fewer than [`MIN_STEPS`] steps, and
/// one shorter than a wave transit of its smallest body, each with the likely unit mistake.
pub fn setup_warnings(model: &Model) -> Vec<String> {
    let mut out = Vec::new();
    for obstacle in &model.obstacles {
        let used = model
            .contacts
            .iter()
            .any(|pair| matches!(&pair.master, Master::Obstacle(o) if o.name == obstacle.name));
        if !used {
            out.push(format!(
                "obstacle `{0}` is used by no contact pair: it stops nothing, and bodies pass \
                 through it; add a [[contact]] with obstacle = \"{0}\" and the slave set that \
                 meets it (or remove the obstacle)",
                obstacle.name
            ));
        }
    }
    out.extend(axis_warnings(model));
    out.extend(frames_warning(model));
    let Analysis::Dynamic(d) = &model.analysis else {
        return out;
    };
    let step = match d.step {
        TimeStep::Fixed(dt) => Some((dt, "analysis.dt".to_string())),
        TimeStep::Auto { scale, .. } => explicit_first_step(model, d).map(|dt| {
            (
                dt,
                format!(
                    "the automatic step (time_step_scale = {} x the stable step of the initial mesh)",
                    readable(scale)
                ),
            )
        }),
        // the error control lengthens the steps as far as the answer allows: no count
        TimeStep::Adaptive(_) => None,
    };
    if let Some((dt, what)) = step {
        let steps = d.end_time / dt;
        if steps < MIN_STEPS {
            let change = match d.step {
                TimeStep::Fixed(_) => "lower analysis.dt",
                TimeStep::Auto { .. } | TimeStep::Adaptive(_) => "lengthen analysis.end_time",
            };
            out.push(format!(
                "analysis.end_time = {} spans {} step(s) of {what} = {}: fewer than {} \
                steps cannot follow a wave or an impact (a step clipped to end_time or to a \
                frame time hides it: the run still ends on time); {change}, or check the \
                units: {}",
                readable(d.end_time),
                readable(steps),
                readable(dt),
                MIN_STEPS,
                unit_hint(model)
            ));
        }
    }
    let transit = model
        .bodies
        .iter()
        .filter_map(|b| wave_speed(b).map(|c| (b, body_size(b), c.speed)))
        .filter(|(_, size, c)| *size > 0.0 && *c > 0.0)
        .map(|(b, size, c)| (b, size, c, size / c))
        .min_by(|x, y| x.3.total_cmp(&y.3));
    if let Some((body, size, c, time)) = transit
        && d.end_time < time
    {
        out.push(format!(
            "analysis.end_time = {} is shorter than one wave transit of the smallest body, \
                `{}` (size {} / wave speed {} = {}): no wave crosses any body in the run; lengthen \
                analysis.end_time, or check the units: {}",
            readable(d.end_time),
            body.name,
            readable(size),
            readable(c),
            readable(time),
            unit_hint(model)
        ));
    }
    out
}

/// The first step of a central-difference run of `model` (None: the run would refuse it).
fn explicit_first_step(model: &Model, spec: &crate::scene::DynamicAnalysis) -> Option<f64> {
    Start::new(model, spec).ok().map(|start| start.first_step())
}

/// A node of an axisymmetric body counts as on the axis, or across it, beyond this share of
/// the body's size from r = 0: round-off of coordinates written in decimal, not geometry.
pub const AXIS_TOLERANCE: f64 = 1e-9;

/// The nodes of the axisymmetric bodies at positions `x`: per body, those at r < 0 beyond
/// the tolerance and those on the axis, r = 0 within it.
struct AxisNodes<'a> {
    body: &'a Body,
    across: Vec<usize>,
    on_axis: Vec<usize>,
    /// The smallest r of the body.
    min_r: f64,
}

fn axis_nodes<'a>(model: &'a Model, x: &[[f64; 2]]) -> Vec<AxisNodes<'a>> {
    model
        .bodies
        .iter()
        .filter(|b| b.is_axisymmetric())
        .map(|body| {
            let tolerance = AXIS_TOLERANCE * body_extent(body);
            let nodes = (0..body.mesh.nodes.len()).map(|n| body.global(n));
            let r = |n: usize| x[n][0];
            AxisNodes {
                body,
                across: nodes.clone().filter(|n| r(*n) < -tolerance).collect(),
                on_axis: nodes.clone().filter(|n| r(*n).abs() <= tolerance).collect(),
                min_r: nodes.map(r).fold(f64::INFINITY, f64::min),
            }
        })
        .collect()
}

/// The first few of `nodes` (global node ids, or element numbers) in words: `12, 14, 17 and
/// 3 more`.
fn some_nodes(nodes: &[usize]) -> String {
    let shown: Vec<String> = nodes.iter().take(5).map(|n| n.to_string()).collect();
    if nodes.len() > 5 {
        format!("{} and {} more", shown.join(", "), nodes.len() - 5)
    } else {
        shown.join(", ")
    }
}

/// Axisymmetric bodies in the initial mesh: nodes at r < 0, and axis nodes free in x (the
/// hoop strain u_r / r needs u_r = 0 on the axis; nothing else keeps them there).
fn axis_warnings(model: &Model) -> Vec<String> {
    let coords = model.coordinates();
    let constrained = model.constrained_dofs();
    let mut out = Vec::new();
    for a in axis_nodes(model, &coords) {
        let name = &a.body.name;
        if !a.across.is_empty() {
            out.push(format!(
                "axisymmetric body `{name}` has {} node(s) at r = x < 0 (down to {}; global \
                 nodes {}): the axis is x = 0 and the body must lie at x >= 0; move its mesh",
                a.across.len(),
                readable(a.min_r),
                some_nodes(&a.across)
            ));
        }
        let free: Vec<usize> = a
            .on_axis
            .iter()
            .copied()
            .filter(|n| constrained.binary_search(&(2 * n)).is_err())
            .collect();
        if !free.is_empty() {
            // the body's own set of exactly its axis nodes, when it has one (`axis`, `left`)
            let mut on_axis: Vec<usize> =
                a.on_axis.iter().map(|n| n - a.body.node_offset).collect();
            on_axis.sort_unstable();
            let set = a.body.mesh.node_sets.iter().find_map(|(set, nodes)| {
                let mut nodes = nodes.clone();
                nodes.sort_unstable();
                nodes.dedup();
                (nodes == on_axis).then_some(set)
            });
            let support = match set {
                Some(set) => format!(
                    "add a [[support]] with body = \"{name}\", set = \"{set}\", fix = [\"x\"]"
                ),
                None => "add a [[support]] with fix = [\"x\"] on a set of the axis nodes".into(),
            };
            out.push(format!(
                "axisymmetric body `{name}` has {} node(s) on the axis (r = 0) free in x (global \
                 nodes {}): nothing holds them on the axis, and they can cross it to r < 0; \
                 {support}",
                free.len(),
                some_nodes(&free)
            ));
        }
    }
    out
}

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
}

/// What the end of a run shows: nodes of an axisymmetric body that ended across the axis
/// (r < 0), where the hoop strain u_r / r has no meaning; hourglass energy above
/// [`HOURGLASS_SHARE`] of the internal energy; mass scaling that added more than
/// [`ADDED_MASS_SHARE`] of a body's mass or scaled an element on a contact surface.
pub fn final_warnings(model: &Model, end: &EndOfRun) -> Vec<String> {
    let mut out = axis_crossings(model, end.positions);
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

/// Nodes of an axisymmetric body at r < 0 in `positions`, a warning per body.
fn axis_crossings(model: &Model, positions: &[[f64; 2]]) -> Vec<String> {
    axis_nodes(model, positions)
        .into_iter()
        .filter(|a| !a.across.is_empty())
        .map(|a| {
            format!(
                "axisymmetric body `{}` ends with {} node(s) at r = x < 0 (down to {}; global \
                 nodes {}): they crossed the axis; hold the axis nodes in x (a [[support]] with \
                 fix = [\"x\"] on them)",
                a.body.name,
                a.across.len(),
                readable(a.min_r),
                some_nodes(&a.across)
            )
        })
        .collect()
}

/// The larger side of the body's bounding box.
fn body_extent(body: &Body) -> f64 {
    model_size(&body.mesh.nodes)
}

/// A run that writes more frames than this warns (check and run): each frame is a file and
/// an entry of the .pvd, which is rewritten after every frame so that a crash leaves a
/// valid series, so the writing grows with the square of the count; and a series of
/// thousands of frames is more than one looks at in ParaView. The shipped scenes write at
/// most 131 (taylor_aluminum).
pub const MANY_FRAMES: f64 = 1000.0;

/// The size of an uncompressed frame per node of the model (measured: 335 to 536 bytes on
/// the last frames of the shipped scenes, most near 370; the point fields, the cell fields
/// and the connectivity of a Quad4 mesh). `lz4` and `zlib` compression write less.
pub const FRAME_BYTES_PER_NODE: f64 = 400.0;

/// The frames a run of `model` writes, estimated before it starts: the listed frame times
/// (`frame_times` and the multiples of `frame_interval`), the first, and one every
/// `frame_every` steps of the nominal step (the fixed step, or the automatic step of the
/// initial mesh; the steps of a static analysis).
pub fn expected_frames(model: &Model) -> f64 {
    let output = &model.output;
    let steps = match &model.analysis {
        Analysis::Static(s) => s.steps as f64,
        Analysis::Dynamic(d) => match d.step {
            TimeStep::Fixed(dt) => d.end_time / dt,
            TimeStep::Auto { .. } => explicit_first_step(model, d)
                .map(|dt| d.end_time / dt)
                .unwrap_or(0.0),
            // the first step's count: the error control may lengthen them
            TimeStep::Adaptive(_) => implicit_first_step(model, d)
                .map(|dt| d.end_time / dt)
                .unwrap_or(0.0),
        },
    };
    let every = if output.frame_every > 0 {
        (steps / output.frame_every as f64).ceil()
    } else {
        0.0
    };
    1.0 + output.frame_times.len() as f64 + every
}

/// More than [`MANY_FRAMES`] frames, with the disk they will take.
fn frames_warning(model: &Model) -> Option<String> {
    let frames = expected_frames(model);
    if frames <= MANY_FRAMES {
        return None;
    }
    let bytes = frames * FRAME_BYTES_PER_NODE * model.node_count as f64;
    Some(format!(
        "the run will write about {} VTK frames (output.frame_interval, output.frame_times and \
         output.frame_every together), some {} on disk uncompressed ({} nodes): more than {} \
         frames is more than ParaView shows usefully, and every frame rewrites the .pvd; \
         lengthen output.frame_interval (or raise output.frame_every)",
        readable(frames.round()),
        bytes_in_words(bytes),
        model.node_count,
        MANY_FRAMES
    ))
}

/// `12 kB`, `3.4 MB`, `1.2 GB`, `5 TB` (powers of 1000).
fn bytes_in_words(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1000.0 && unit + 1 < units.len() {
        value /= 1000.0;
        unit += 1;
    }
    format!("{value:.1} {}", units[unit])
}

/// The size a wave crosses: the shorter side of the body's bounding box (a rod: its length,
/// the longer side).
fn body_size(body: &Body) -> f64 {
    let mut low = [f64::INFINITY; 2];
    let mut high = [f64::NEG_INFINITY; 2];
    for p in &body.mesh.nodes {
        for k in 0..2 {
            low[k] = low[k].min(p[k]);
            high[k] = high[k].max(p[k]);
        }
    }
    let sides = [high[0] - low[0], high[1] - low[1]];
    if body.kind.is_rod() {
        sides[0].max(sides[1])
    } else {
        sides[0].min(sides[1])
    }
}

/// The unit mistake the model's numbers point to, in words. Two are common: a density in
/// kg/m^3 beside moduli in MPa (lengths in mm: the density must be in t/mm^3), which makes
/// waves some 3e4 times slower than in any solid; and a geometry in mm beside SI material
/// data, which makes the bodies 1000 times too large for their m/s wave speed.
fn unit_hint(model: &Model) -> String {
    const CONSISTENT: &str = "consistent units are m, kg, s, Pa (steel: 7850, 210e9) or mm, t, \
                s, MPa (steel: 7.85e-9, 210e3)";
    for body in &model.bodies {
        let m = &body.material;
        if m.density > 100.0 && m.elastic.young < 1e7 {
            return format!(
                "material `{}` has density = {} (kg/m^3?) with young = {} (MPa?): with moduli in \
                MPa and lengths in mm the density is in t/mm^3 (7850 kg/m^3 = 7.85e-9 t/mm^3); {CONSISTENT}",
                m.name,
                readable(m.density),
                readable(m.elastic.young)
            );
        }
    }
    for body in &model.bodies {
        if let Some(c) = wave_speed(body)
            && (1e3..=2e4).contains(&c.speed)
            && body_size(body) >= 1.0
        {
            return format!(
                "body `{}` has a wave speed of {} (a solid's in m/s) and a size of {} (m, then): \
                a geometry meant in mm must be given in m with SI material data; {CONSISTENT}",
                body.name,
                readable(c.speed),
                readable(body_size(body))
            );
        }
    }
    CONSISTENT.to_string()
}

/// A subcycled run that took at least this share of the single step's element steps is
/// warned about: its bookkeeping (a fifth of the aluminium Taylor rod's subcycled run,
/// docs/performance.md) eats a saving below a tenth.
const SUBCYCLING_GAIN: f64 = 0.9;

/// The warnings of a run that ended with `summary` and the last `energies`.
pub fn warnings(model: &Model, summary: &Summary, energies: &Energies) -> Vec<String> {
    let mut out = setup_warnings(model);
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
    let moved = summary.energy.initial > 0.0 || energies.external_work.abs() > 0.0;
    if moved {
        for name in &summary.contact.never_closed {
            if let Some(pair) = model.contacts.iter().find(|p| &p.name == name) {
                out.push(never_closed_warning(model, pair));
            }
        }
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

/// A pair that never closed in a run where something moved, with the way its slaves moved
/// relative to the master at the start: the gap rate dg/dt of the slave nearest the master
/// under the initial velocities (a small advance of every node along its velocity, master
/// nodes included, so the rate is the relative one).
fn never_closed_warning(model: &Model, pair: &ContactPair) -> String {
    let coords = model.coordinates();
    let velocity = |n: usize| {
        [
            model.initial_velocity[2 * n],
            model.initial_velocity[2 * n + 1],
        ]
    };
    let speed = (0..model.node_count)
        .map(|n| velocity(n)[0].hypot(velocity(n)[1]))
        .fold(0.0, f64::max);
    let at = |x: &dyn Fn(usize) -> [f64; 2]| {
        pair.slaves
            .iter()
            .filter_map(|s| pair.gap(*s, x).map(|g| (*s, g.gap)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    };
    let start = at(&|n: usize| coords[n]);
    let name = &pair.name;
    let Some((slave, gap)) = start else {
        return format!(
            "contact `{name}` never closed: no slave node came within its search distance of \
             the master at the start; check the pair's slave and master sets (or obstacle) and \
             where the bodies are"
        );
    };
    // an advance of a millionth of the gap (or of the model's size) along the velocities
    let size = model_size(&coords);
    let h = if speed > 0.0 {
        1e-6 * gap.abs().max(1e-3 * size) / speed
    } else {
        0.0
    };
    let rate = if h > 0.0 {
        pair.gap(slave, &|n: usize| {
            let v = velocity(n);
            [coords[n][0] + h * v[0], coords[n][1] + h * v[1]]
        })
        .map(|g| (g.gap - gap) / h)
        .unwrap_or(0.0)
    } else {
        0.0
    };
    if rate > 0.0 {
        format!(
            "contact `{name}` never closed: at the start its slaves move away from the master \
             (gap {} opening at {}): check the sign of the body's velocity (or which side of \
             the master the slaves are on)",
            readable(gap),
            readable(rate)
        )
    } else if rate < 0.0 {
        format!(
            "contact `{name}` never closed although its slaves approach the master at the start \
             (gap {} closing at {}): the run ended before they met (lengthen analysis.end_time) \
             or they passed beside it (check the pair's sets and the master's extent)",
            readable(gap),
            readable(-rate)
        )
    } else {
        format!(
            "contact `{name}` never closed (gap {} at the start, no initial motion towards or \
             away from the master): the loads never brought the slaves onto it; check the \
             loads, analysis.end_time and the pair's sets",
            readable(gap)
        )
    }
}

/// The larger side of the bounding box of `coords`.
fn model_size(coords: &[[f64; 2]]) -> f64 {
    let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in coords {
        for k in 0..2 {
            low[k] = low[k].min(p[k]);
            high[k] = high[k].max(p[k]);
        }
    }
    (high[0] - low[0]).max(high[1] - low[1])
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

/// An implicit step far above the explicit stable step on a run with contact.
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
